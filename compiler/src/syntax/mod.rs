//! The front end's syntax layer: lexing, parsing, the AST and its text dump.

pub mod ast;
mod dump;
pub mod lexer;
pub mod parser;

pub use dump::dump;

use crate::diagnostics::Diagnostic;
use crate::span::FileId;

/// Lexes and parses one file. Never fails: broken parts become error nodes, and every lexical
/// and syntax error is in the returned diagnostics.
pub fn parse(file: FileId, text: &str) -> (ast::File, Vec<Diagnostic>) {
    let (tokens, mut diags) = lexer::lex(file, text);
    let (ast, syntax) = parser::parse(file, &tokens, text.len());
    // A character the lexer rejected between two tokens (`a | b`) makes the parser miss an
    // operator there too: the lexer's error says what to write, so the parser's is dropped.
    let rejected: Vec<crate::span::Span> = diags
        .iter()
        .filter(|d| d.code == "E0001")
        .filter_map(|d| d.labels.first().map(|l| l.span))
        .collect();
    diags.extend(syntax.into_iter().filter(|d| {
        let (Some(at), Some(found)) = (d.labels.first(), d.labels.get(1)) else {
            return true;
        };
        d.code != "E0101"
            || !rejected
                .iter()
                .any(|r| at.span.end <= r.start && r.end <= found.span.start)
    }));
    (ast, diags)
}
