//! The formatter (`sdfc fmt`, the language server's formatting): one layout of `.sdf` text,
//! every comment kept where it was written.
//!
//! The layout works on the tokens and the comments between them, so the formatted text has
//! the same tokens in the same order as the original (checked before it is returned) and
//! therefore the same meaning. What it decides:
//!
//! - **Spaces** inside a line: one around binary operators, `=`, `@`, `->` and after `,`,
//!   `;` and `:`; none inside brackets, before `,`, `;`, `:`, around `.`, `..` and after a
//!   prefix `-` or `!`; `{ a }` with spaces inside, `{}` without; none between a name and
//!   the `(` or `[` of its call or index.
//! - **Lines**: the line breaks are the author's, with a few made canonical: each item and
//!   each statement of a `scene` or `for` block starts a line, such a block's `}` stands on a
//!   line of its own, a `,` or `;` never starts a line, at most one blank line in a row and
//!   none just inside a bracket. Long lines are not wrapped.
//! - **Indentation**: [`INDENT`] per bracket left open by an earlier line (several opened on
//!   one line count once), a line starting with a closing bracket at the level of the line
//!   that opened it, and one more for a line that continues an expression (starting with
//!   `.`, `@` or a binary operator, or after a line ending in one, or in `=`).
//! - **Comments** keep their text and their line; a `//` comment after code keeps the column
//!   it was aligned to when it was written more than one space away, else one space.
//!
//! Formatting is idempotent: formatted text formats to itself.

use super::lexer::{self, Token};
use super::{ast, parse_within};
use crate::diagnostics::{Diagnostic, Severity};
use crate::limits::Limits;
use crate::span::{FileId, Span};
use std::collections::HashSet;

/// One level of indentation.
pub(crate) const INDENT: &str = "  ";

/// Why a text was not formatted.
#[derive(Debug, Clone)]
pub enum Error {
    /// The text has lexical or syntax errors (formatting needs the whole tree).
    Syntax(Vec<Diagnostic>),
    /// The formatter would have changed the tokens or comments: a bug, the text left as it is.
    Internal(String),
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            Error::Syntax(d) => write!(
                f,
                "{} syntax error(s): the file is formatted once it parses",
                d.len()
            ),
            Error::Internal(why) => write!(f, "internal error of the formatter: {why}"),
        }
    }
}

/// What a line holds, in order.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Elem {
    /// The token of that index.
    Token(usize),
    /// A comment: its byte range in the text, whether it is a `//` comment, and for one after
    /// code on its line, how many spaces were written before it and at which column (in
    /// characters) it started.
    Comment {
        start: usize,
        end: usize,
        line: bool,
        gap: usize,
        column: usize,
    },
}

/// A line of the output before its indentation and spacing are decided.
#[derive(Debug, Default)]
struct Line {
    elems: Vec<Elem>,
    /// A blank line is kept before this one.
    blank_before: bool,
}

/// Formats `text`, a whole `.sdf` file. A file nested deeper than the default `nesting`
/// limit is refused as the checker refuses it (E0507).
pub fn format(text: &str) -> Result<String, Error> {
    // A byte-order mark at the start is not kept: the formatted text is plain UTF-8.
    let text = text.strip_prefix(lexer::BOM).unwrap_or(text);
    let file = FileId(0);
    let ((tree, diags), _) = parse_within(file, text, Some(&Limits::default()));
    let errors: Vec<Diagnostic> = diags
        .into_iter()
        .filter(|d| d.severity == Severity::Error)
        .collect();
    if !errors.is_empty() {
        return Err(Error::Syntax(errors));
    }
    let (tokens, _) = lexer::lex(file, text);
    let breaks = forced_breaks(&tree, &tokens);
    // What each step no longer needs is dropped before the next (the tree, then the lines):
    // the memory a large file takes is that of one step's data, not of all of them.
    drop(tree);
    let lines = split_lines(text, &tokens, &breaks)?;
    drop(breaks);
    let out = render(text, &tokens, &lines);
    drop(lines);
    same_tokens(text, &tokens, &out)?;
    Ok(out)
}

/// The byte offsets of the tokens that must start a line: every item but the first, every
/// statement of a `scene` or `for` block, and the `}` closing such a block when it holds any.
fn forced_breaks(tree: &ast::File, tokens: &[(Token, Span)]) -> HashSet<u32> {
    let mut at = HashSet::new();
    let item_span = |item: &ast::Item| match item {
        ast::Item::Import { span, .. }
        | ast::Item::Material { span, .. }
        | ast::Item::Scene { span, .. }
        | ast::Item::Error(span) => *span,
        ast::Item::Let(l) => l.span,
        ast::Item::Fn(f) => f.span,
        ast::Item::Block(b) => b.span,
    };
    for item in tree.items.iter().skip(1) {
        at.insert(item_span(item).start);
    }
    // The last `}` at or before `end` (a block's span ends at its `}`, or at the `;` after
    // it).
    let closing = |end: u32| {
        let n = tokens.partition_point(|(_, s)| s.end <= end);
        tokens[..n]
            .iter()
            .rev()
            .take(2)
            .find(|(t, _)| *t == Token::RBrace)
            .map(|(_, s)| s.start)
    };
    fn statements(
        stmts: &[ast::Stmt],
        at: &mut HashSet<u32>,
        closing: &dyn Fn(u32) -> Option<u32>,
    ) {
        for s in stmts {
            match s {
                ast::Stmt::Let(l) => {
                    at.insert(l.span.start);
                }
                ast::Stmt::Object(e) => {
                    at.insert(e.span.start);
                }
                ast::Stmt::Error(span) => {
                    at.insert(span.start);
                }
                ast::Stmt::For { body, span, .. } => {
                    at.insert(span.start);
                    if !body.is_empty() {
                        statements(body, at, closing);
                        if let Some(c) = closing(span.end) {
                            at.insert(c);
                        }
                    }
                }
            }
        }
    }
    for item in &tree.items {
        if let ast::Item::Scene { stmts, span } = item {
            if !stmts.is_empty() {
                statements(stmts, &mut at, &closing);
                if let Some(c) = closing(span.end) {
                    at.insert(c);
                }
            }
        }
    }
    at
}

/// What lies between two tokens: newlines and comments.
enum Gap {
    Newlines(usize),
    Comment {
        start: usize,
        end: usize,
        line: bool,
    },
}

/// The newlines and comments of `text[start..end]`, which the lexer found to hold nothing
/// else.
fn gap(text: &str, start: usize, end: usize) -> Result<Vec<Gap>, Error> {
    let mut out = Vec::new();
    let bytes = text.as_bytes();
    let mut i = start;
    let mut newlines = 0;
    while i < end {
        match bytes[i] {
            b'\n' => {
                newlines += 1;
                i += 1;
            }
            b' ' | b'\t' | b'\r' | 0x0c => i += 1,
            b'/' if text[i..end].starts_with("//") => {
                if newlines > 0 {
                    out.push(Gap::Newlines(newlines));
                    newlines = 0;
                }
                let stop = text[i..end].find('\n').map_or(end, |n| i + n);
                out.push(Gap::Comment {
                    start: i,
                    end: stop,
                    line: true,
                });
                i = stop;
            }
            b'/' if text[i..end].starts_with("/*") => {
                if newlines > 0 {
                    out.push(Gap::Newlines(newlines));
                    newlines = 0;
                }
                let stop = text[i + 2..end]
                    .find("*/")
                    .map(|n| i + 2 + n + 2)
                    .ok_or_else(|| Error::Internal("a block comment without its end".into()))?;
                out.push(Gap::Comment {
                    start: i,
                    end: stop,
                    line: false,
                });
                i = stop;
            }
            _ => {
                return Err(Error::Internal(format!(
                    "unexpected text between tokens at byte {i}"
                )))
            }
        }
    }
    if newlines > 0 {
        out.push(Gap::Newlines(newlines));
    }
    Ok(out)
}

/// The column, in characters, of byte `at` on its line.
fn column(text: &str, at: usize) -> usize {
    let start = text[..at].rfind('\n').map_or(0, |n| n + 1);
    text[start..at].chars().count()
}

/// The tokens and comments of `text` cut into lines.
fn split_lines(
    text: &str,
    tokens: &[(Token, Span)],
    breaks: &HashSet<u32>,
) -> Result<Vec<Line>, Error> {
    let mut lines: Vec<Line> = Vec::new();
    let mut cur = Line::default();
    // Ends the current line (if it holds anything) where the source has `newlines` line
    // breaks: two or more leave a blank line before the next one.
    let newline = |cur: &mut Line, lines: &mut Vec<Line>, newlines: usize| {
        if !cur.elems.is_empty() {
            lines.push(std::mem::take(cur));
        }
        if newlines >= 2 && !lines.is_empty() {
            cur.blank_before = true;
        }
    };
    let mut prev_end = 0usize;
    for i in 0..=tokens.len() {
        let start = tokens.get(i).map_or(text.len(), |(_, s)| s.start as usize);
        let pieces = gap(text, prev_end, start)?;
        let has_comment = pieces.iter().any(|p| matches!(p, Gap::Comment { .. }));
        let joins = !has_comment
            && matches!(
                tokens.get(i).map(|(t, _)| t),
                Some(Token::Comma | Token::Semi)
            );
        let mut broke = false;
        for p in pieces {
            match p {
                Gap::Newlines(n) => {
                    if !joins {
                        newline(&mut cur, &mut lines, n);
                        broke = true;
                    }
                }
                Gap::Comment { start, end, line } => {
                    let trailing = !cur.elems.is_empty();
                    let spaces = text[..start]
                        .chars()
                        .rev()
                        .take_while(|c| *c == ' ' || *c == '\t')
                        .count();
                    cur.elems.push(Elem::Comment {
                        start,
                        end,
                        line,
                        gap: if trailing { spaces } else { 0 },
                        column: column(text, start),
                    });
                    broke = false;
                }
            }
        }
        let Some((_, span)) = tokens.get(i) else {
            break;
        };
        let after_line_comment = matches!(cur.elems.last(), Some(Elem::Comment { line: true, .. }));
        if !broke && (after_line_comment || (breaks.contains(&span.start) && i > 0)) {
            newline(&mut cur, &mut lines, 1);
        }
        cur.elems.push(Elem::Token(i));
        prev_end = span.end as usize;
    }
    if !cur.elems.is_empty() {
        lines.push(cur);
    }
    Ok(lines)
}

/// Tokens that end an operand: a `-` after one is binary.
fn ends_operand(t: &Token) -> bool {
    matches!(
        t,
        Token::Ident(_)
            | Token::Int(_)
            | Token::Float(_)
            | Token::Angle(_)
            | Token::Colour(_)
            | Token::Str(_)
            | Token::Bool(_)
            | Token::RParen
            | Token::RBracket
            | Token::RBrace
    )
}

fn binary_operator(t: &Token) -> bool {
    matches!(
        t,
        Token::Plus
            | Token::Star
            | Token::Slash
            | Token::Percent
            | Token::Lt
            | Token::Le
            | Token::Gt
            | Token::Ge
            | Token::EqEq
            | Token::Ne
            | Token::AndAnd
            | Token::OrOr
    )
}

fn opens(t: &Token) -> bool {
    matches!(t, Token::LParen | Token::LBracket | Token::LBrace)
}

fn closes(t: &Token) -> bool {
    matches!(t, Token::RParen | Token::RBracket | Token::RBrace)
}

/// Whether a space goes between the tokens `a` and `b` (`a_prefix`: `a` is a prefix operator).
fn space(a: &Token, a_prefix: bool, b: &Token) -> bool {
    use Token::*;
    if matches!(b, RParen | RBracket | Comma | Semi | Colon | Dot | DotDot) {
        return false;
    }
    if matches!(a, LParen | LBracket | Dot | DotDot) || a_prefix {
        return false;
    }
    match (a, b) {
        (LBrace, RBrace) => false,
        (_, LBrace) | (LBrace, _) | (_, RBrace) => true,
        (Ident(_), LParen) => false,
        (Ident(_) | RParen | RBracket, LBracket) => false,
        _ => true,
    }
}

/// The lines laid out: indentation, spaces, comments, one newline at the end.
fn render(text: &str, tokens: &[(Token, Span)], lines: &[Line]) -> String {
    let slice = |i: usize| &text[tokens[i].1.range()];
    // Whether the token of index i is a prefix `-` or `!`.
    let prefix = |i: usize| match tokens[i].0 {
        Token::Bang => true,
        Token::Minus => i == 0 || !ends_operand(&tokens[i - 1].0),
        _ => false,
    };
    let mut out = String::new();
    // Open brackets: the indentation of the line that opened each.
    let mut open: Vec<usize> = Vec::new();
    let mut last_token: Option<usize> = None;
    let mut prev_ended_opener = false;
    for (n, line) in lines.iter().enumerate() {
        let first_token = line.elems.iter().find_map(|e| match e {
            Elem::Token(i) => Some(*i),
            _ => None,
        });
        let starts_with_token = matches!(line.elems.first(), Some(Elem::Token(_)));
        let starts_closing = starts_with_token && first_token.is_some_and(|i| closes(&tokens[i].0));
        if line.blank_before && n > 0 && !prev_ended_opener && !starts_closing {
            out.push('\n');
        }
        let base = open.last().map_or(0, |l| l + 1);
        let indent = if starts_closing {
            open.last().copied().unwrap_or(0)
        } else if starts_with_token {
            let i = first_token.unwrap_or(0);
            let t = &tokens[i].0;
            let continues = *t != Token::LBrace
                && last_token.is_some_and(|l| {
                    let lt = &tokens[l].0;
                    binary_operator(lt)
                        || matches!(
                            lt,
                            Token::Minus
                                | Token::Bang
                                | Token::Eq
                                | Token::At
                                | Token::Arrow
                                | Token::Colon
                                | Token::Dot
                                | Token::DotDot
                        )
                })
                || binary_operator(t)
                || matches!(
                    t,
                    Token::Dot | Token::DotDot | Token::At | Token::Arrow | Token::Eq
                )
                || (*t == Token::Minus && !prefix(i));
            base + usize::from(continues)
        } else {
            base
        };
        let mut content = String::new();
        let mut prev: Option<Elem> = None;
        for &e in &line.elems {
            match e {
                Elem::Token(i) => {
                    if let Some(p) = prev {
                        let sp = match p {
                            Elem::Token(j) => space(&tokens[j].0, prefix(j), &tokens[i].0),
                            Elem::Comment { .. } => !matches!(
                                tokens[i].0,
                                Token::RParen | Token::RBracket | Token::Comma | Token::Semi
                            ),
                        };
                        if sp {
                            content.push(' ');
                        }
                    }
                    content.push_str(slice(i));
                    let t = &tokens[i].0;
                    if opens(t) {
                        open.push(indent);
                    } else if closes(t) {
                        open.pop();
                    }
                    last_token = Some(i);
                }
                Elem::Comment {
                    start,
                    end,
                    line: is_line,
                    gap,
                    column,
                } => {
                    let body = text[start..end].trim_end().replace("\r\n", "\n");
                    if let Some(p) = prev {
                        // The column on the output's line: after the last line break of a
                        // block comment earlier on the line, if there is one.
                        let width = match content.rfind('\n') {
                            Some(nl) => content[nl + 1..].chars().count(),
                            None => indent * INDENT.len() + content.chars().count(),
                        };
                        if is_line && gap > 1 && column > width {
                            content.push_str(&" ".repeat(column - width));
                        } else if !matches!(p, Elem::Token(j) if matches!(tokens[j].0, Token::LParen | Token::LBracket))
                        {
                            content.push(' ');
                        }
                    }
                    content.push_str(&body);
                }
            }
            prev = Some(e);
        }
        if !content.is_empty() {
            for _ in 0..indent {
                out.push_str(INDENT);
            }
            out.push_str(&content);
        }
        out.push('\n');
        prev_ended_opener =
            matches!(line.elems.last(), Some(Elem::Token(i)) if opens(&tokens[*i].0));
    }
    out
}

/// Checks that `out` holds the tokens of `tokens` and the comments of `text`, in order.
fn same_tokens(text: &str, tokens: &[(Token, Span)], out: &str) -> Result<(), Error> {
    let (again, diags) = lexer::lex(FileId(0), out);
    if !diags.is_empty() {
        return Err(Error::Internal("the formatted text does not lex".into()));
    }
    if again.len() != tokens.len() || again.iter().zip(tokens).any(|(a, b)| a.0 != b.0) {
        return Err(Error::Internal(
            "the formatted text has other tokens".into(),
        ));
    }
    let comments = |t: &str, toks: &[(Token, Span)]| -> Result<Vec<String>, Error> {
        let mut all = Vec::new();
        let mut prev = 0;
        for i in 0..=toks.len() {
            let start = toks.get(i).map_or(t.len(), |(_, s)| s.start as usize);
            for g in gap(t, prev, start)? {
                if let Gap::Comment { start, end, .. } = g {
                    all.push(t[start..end].trim_end().replace("\r\n", "\n"));
                }
            }
            prev = toks.get(i).map_or(0, |(_, s)| s.end as usize);
        }
        Ok(all)
    };
    if comments(text, tokens)? != comments(out, &again)? {
        return Err(Error::Internal(
            "the formatted text has other comments".into(),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(input: &str, expected: &str) {
        let once = format(input).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(once, expected, "formatting\n{input}");
        let twice = format(&once).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(twice, once, "formatting again");
    }

    #[test]
    fn spaces_inside_lines() {
        check(
            "let  a=-1+2*( 3-4 ) ;let b:[float]=[1,2,3,];\nfn f(x:float=0.5,)->shape{sphere(x).translate( -x,0,0 )}\n",
            "let a = -1 + 2 * (3 - 4);\nlet b: [float] = [1, 2, 3,];\nfn f(x: float = 0.5,) -> shape { sphere(x).translate(-x, 0, 0) }\n",
        );
        check(
            "let v=(1,2,3).x+xs[0]-!true;let c=a-(-b)&&!c||d<=e;\n",
            "let v = (1, 2, 3).x + xs[0] - !true;\nlet c = a - (-b) && !c || d <= e;\n",
        );
        check(
            "material m=phong{color:(1,0,0)}\nmaterial n = checker {}\n",
            "material m = phong { color: (1, 0, 0) }\nmaterial n = checker {}\n",
        );
    }

    #[test]
    fn statements_and_items_start_lines() {
        check(
            "let a = 1; let b = 2;\nscene { sphere(a) @ m; for i in 0..3 { box(b).translate(i, 0, 0); } }",
            "let a = 1;\nlet b = 2;\nscene {\n  sphere(a) @ m;\n  for i in 0..3 {\n    box(b).translate(i, 0, 0);\n  }\n}\n",
        );
        // A one-line function body and an empty scene stay as written.
        check(
            "fn f() -> float { let x = 1; x }\nscene {}\n",
            "fn f() -> float { let x = 1; x }\nscene {}\n",
        );
    }

    #[test]
    fn indentation_follows_brackets_and_continuations() {
        check(
            "scene {\n        smooth_union(0.5,\ntorus(1, 0.3),\n   sphere(0.6)) @ m;\n  if a { b } else { c }\n.translate(1, 0, 0)\n;\n}\n",
            "scene {\n  smooth_union(0.5,\n    torus(1, 0.3),\n    sphere(0.6)) @ m;\n  if a { b } else { c }\n    .translate(1, 0, 0);\n}\n",
        );
        check(
            "let body = polygon([\n(0, -1), (0.5, -1),\n(0, 0.1),\n    ]);\nlet x = 1 +\n2\n+ 3;\n",
            "let body = polygon([\n  (0, -1), (0.5, -1),\n  (0, 0.1),\n]);\nlet x = 1 +\n  2\n  + 3;\n",
        );
    }

    #[test]
    fn comments_stay_where_they_were_written() {
        check(
            "// head\n\n\n\nlet a = 1;   // aligned\nlet bb = 2; // one space\n/* block\n   over lines */\nscene { sphere(a) /* inside */ ; // end\n}\n\n\n",
            "// head\n\nlet a = 1;   // aligned\nlet bb = 2; // one space\n/* block\n   over lines */\nscene {\n  sphere(a) /* inside */; // end\n}\n",
        );
        // A comment before a closing bracket is indented inside it; blank lines just inside
        // brackets go.
        check(
            "scene {\n\n  sphere(1);\n// last\n\n}\n",
            "scene {\n  sphere(1);\n  // last\n}\n",
        );
    }

    #[test]
    fn a_comment_after_a_block_comment_over_lines_keeps_its_column_on_its_own_line() {
        // The column of `// c` is counted from the line break inside the block comment, in
        // the input and in the output alike, so formatting again changes nothing.
        check("let d=/*\n*/1;  // c", "let d = /*\n*/ 1; // c\n");
        check(
            "let d=/*\n*/1;                    // c\n",
            "let d = /*\n*/ 1;                   // c\n",
        );
    }

    #[test]
    fn a_byte_order_mark_is_dropped() {
        check("\u{feff}let a=1;\n", "let a = 1;\n");
    }

    #[test]
    fn numbers_and_strings_keep_their_spelling() {
        check(
            "let a = 1.50e3;let b = 45deg ;let s = \"a\\\"b\";\n",
            "let a = 1.50e3;\nlet b = 45deg;\nlet s = \"a\\\"b\";\n",
        );
    }

    #[test]
    fn text_with_syntax_errors_is_not_formatted() {
        assert!(matches!(format("let a = ;"), Err(Error::Syntax(_))));
        assert!(matches!(
            format("let a = 1; /* open"),
            Err(Error::Syntax(_))
        ));
        assert_eq!(format("").ok().as_deref(), Some(""));
        assert_eq!(format("\n\n// only\n").ok().as_deref(), Some("// only\n"));
    }
}
