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
    diags.extend(syntax);
    (ast, diags)
}
