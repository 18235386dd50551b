//! The front end's syntax layer: lexing, parsing, the AST and its text dump.

pub mod ast;
mod dump;
mod errors;
pub mod format;
pub mod lexer;
pub mod parser;

pub use dump::dump;

use crate::diagnostics::Diagnostic;
use crate::span::FileId;

/// Lexes and parses one file. Never fails: broken parts become error nodes, and every lexical
/// and syntax error is in the returned diagnostics.
pub fn parse(file: FileId, text: &str) -> (ast::File, Vec<Diagnostic>) {
    parse_within(file, text, None).0
}

/// Stack the parser and the checker's walks of the syntax tree may use per level of nesting
/// (measured well under this in debug builds); a deeper file runs on a stack grown to fit.
pub const STACK_PER_LEVEL: usize = 64 * 1024;

/// Runs `f` with stack for `depth` levels of nesting: on the current stack when enough is
/// left, else on a new one of `depth × STACK_PER_LEVEL` and a margin.
pub fn with_stack_for<R>(depth: usize, f: impl FnOnce() -> R) -> R {
    let need = depth
        .saturating_mul(STACK_PER_LEVEL)
        .saturating_add(256 * 1024);
    stacker::maybe_grow(need, need.saturating_add(4 << 20), f)
}

/// How deeply the tokens nest, and where they first go deeper than `max`: each open
/// bracket (`(`, `[`, `{`) is a level until it closes, and so is each prefix operator (`-`,
/// `!`) of a run of them. A flat sum (`1 + 2 + … + 1001`) or a chain of method calls has no
/// depth; the parser's and the checker's recursion follows this depth.
pub fn nesting(
    tokens: &[(lexer::Token, crate::span::Span)],
    max: usize,
) -> (usize, Option<crate::span::Span>) {
    use lexer::Token;
    let (mut depth, mut run, mut deepest) = (0usize, 0usize, 0usize);
    let mut first_over = None;
    for (t, span) in tokens {
        match t {
            Token::LParen | Token::LBrace | Token::LBracket => {
                depth += 1;
                run = 0;
            }
            Token::RParen | Token::RBrace | Token::RBracket => {
                depth = depth.saturating_sub(1);
                run = 0;
            }
            Token::Minus | Token::Bang => run += 1,
            _ => run = 0,
        }
        let level = depth + run;
        deepest = deepest.max(level);
        if level > max && first_over.is_none() {
            first_over = Some(*span);
        }
    }
    (deepest, first_over)
}

/// The elements of the literal lists of a file's tokens, counted as they are lexed: the
/// first list with more than `max` (the `objects` limit, which bounds every list) and its
/// count, found before anything is parsed, so that a file of millions of elements costs
/// its tokens up to the limit and no syntax tree.
struct Lists {
    max: usize,
    /// The brackets open: a list's `[` (where, its elements so far, whether an element is
    /// to start) or another bracket.
    open: Vec<Option<(crate::span::Span, usize, bool)>>,
    /// The list past the limit: where it opens and its elements (all of them once it closes).
    over: Option<(crate::span::Span, usize)>,
    /// Its depth in `open`, while it is open.
    over_depth: Option<usize>,
}

impl Lists {
    fn new(max: usize) -> Lists {
        Lists {
            max,
            open: Vec::new(),
            over: None,
            over_depth: None,
        }
    }

    /// Sees one token; false once a list is past the limit (the tokens need not be kept).
    fn see(&mut self, t: &lexer::Token, span: crate::span::Span) -> bool {
        use lexer::Token;
        let depth = self.open.len();
        if let Some(Some((at, elements, expecting))) = self.open.last_mut() {
            match t {
                Token::Comma => *expecting = true,
                Token::RBracket | Token::RParen | Token::RBrace => {}
                _ if *expecting => {
                    *expecting = false;
                    *elements += 1;
                    if self.over_depth == Some(depth) {
                        self.over = Some((*at, *elements));
                    } else if *elements > self.max && self.over.is_none() {
                        self.over = Some((*at, *elements));
                        self.over_depth = Some(depth);
                    }
                }
                _ => {}
            }
        }
        match t {
            Token::LBracket => self.open.push(Some((span, 0, true))),
            Token::LParen | Token::LBrace => self.open.push(None),
            Token::RBracket | Token::RParen | Token::RBrace => {
                if self.over_depth == Some(self.open.len()) {
                    self.over_depth = None;
                }
                self.open.pop();
            }
            _ => {}
        }
        self.over.is_none()
    }
}

/// [`parse`] within the `nesting` limit ([`nesting`]; none: no limit): a file that nests deeper is not
/// parsed, and gets one error (E0507) at the first token past the limit, so that neither
/// the parser nor the checker recurses without bound. Also returns the file's depth.
pub fn parse_within(
    file: FileId,
    text: &str,
    limits: Option<&crate::limits::Limits>,
) -> ((ast::File, Vec<Diagnostic>), usize) {
    use crate::limits::Limit;
    let max = limits.map_or(usize::MAX, |l| l.count(Limit::Nesting));
    let mut lists = Lists::new(limits.map_or(usize::MAX, |l| l.count(Limit::Objects)));
    let (tokens, mut diags) = lexer::lex_watched(file, text, |t, span| lists.see(t, span));
    if let Some((at, n)) = lists.over {
        diags.push(
            Diagnostic::error(
                "E0507",
                format!("a list has {n} elements, more than {}", lists.max),
                at,
            )
            .with_label("this list")
            .with_note(format!(
                "this limit keeps compilation bounded; {}",
                limits
                    .map(|l| l.raise_to(Limit::Objects, n as u64))
                    .unwrap_or_default()
            )),
        );
        // Nothing was parsed: the tokens past the limit were counted, not kept.
        return ((ast::File { items: Vec::new() }, diags), 0);
    }
    let (depth, over) = nesting(&tokens, max);
    if let Some(at) = over {
        diags.push(
            Diagnostic::error(
                "E0507",
                format!("brackets and prefix operators nest more than {max} levels deep"),
                at,
            )
            .with_label(format!("level {} starts here", max + 1))
            .with_note(format!(
                "this limit keeps compilation bounded; {}",
                limits.map(|l| l.raise(Limit::Nesting)).unwrap_or_default()
            )),
        );
        // Nothing was parsed: nothing deeper than the limit is walked.
        return ((ast::File { items: Vec::new() }, diags), max);
    }
    let (ast, syntax) = with_stack_for(depth, || parser::parse(file, &tokens, text.len()));
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
    // The parser's recovery can meet one error twice (a block left open inside another
    // unclosed one: both end at the end of the file): each error is reported once.
    let mut seen = std::collections::HashSet::new();
    diags.retain(|d| {
        seen.insert((
            d.code,
            d.message.clone(),
            d.labels.iter().map(|l| l.span).collect::<Vec<_>>(),
        ))
    });
    ((ast, diags), depth)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_error_met_twice_by_the_recovery_is_reported_once() {
        // The first scene is never closed; the second, parsed inside it, ends the file too.
        let (_, diags) = parse(FileId(0), "scene { box(); x y;\nscene { box\n");
        let at_end: Vec<_> = diags.iter().filter(|d| d.code == "E0100").collect();
        assert_eq!(at_end.len(), 1, "{diags:#?}");
        assert_eq!(at_end[0].message, "unexpected end of file");
    }
}
