//! The parser's errors as diagnostics: what was found and expected, said where it belongs (a
//! missing `;` just after the token it should follow), with help for the usual mistakes (a
//! keyword used as a name, `.5`, a material without its `@`).

use super::lexer::Token;
use crate::diagnostics::Diagnostic;
use crate::span::{FileId, Span};
use chumsky::error::Rich;
use chumsky::span::SimpleSpan;

/// The keywords: reserved, they cannot be names.
pub(super) fn is_keyword(t: &Token) -> bool {
    matches!(
        t,
        Token::Import
            | Token::Let
            | Token::Fn
            | Token::Material
            | Token::Camera
            | Token::Light
            | Token::Render
            | Token::Scene
            | Token::If
            | Token::Else
            | Token::For
            | Token::In
    )
}

/// A syntax error as a diagnostic: E0100, or E0101 for a missing `;`, `,` or closing
/// delimiter.
pub(super) fn syntax_error(
    file: FileId,
    e: Rich<'_, Token, SimpleSpan>,
    tokens: &[(Token, Span)],
    materials: &[&str],
) -> Diagnostic {
    use chumsky::error::RichPattern;
    let span = Span::new(file, e.span().into_range());
    let found = match e.found() {
        Some(t) => t.to_string(),
        None => "end of file".to_string(),
    };
    let mut expected: Vec<String> = e
        .expected()
        .filter_map(|p| match p {
            RichPattern::Token(t) => Some(t.to_string()),
            RichPattern::Label(l) => Some(l.to_string()),
            RichPattern::EndOfInput => Some("end of file".to_string()),
            _ => None,
        })
        .collect();
    expected.sort();
    expected.dedup();
    if let chumsky::error::RichReason::Custom(msg) = e.reason() {
        return Diagnostic::error("E0100", msg.to_string(), span);
    }
    if let Some(t) = e.found().filter(|t| is_keyword(t)) {
        if expected.iter().any(|x| x == "name") {
            return Diagnostic::error(
                "E0100",
                format!("{found} is a keyword, not a name"),
                span,
            )
            .with_label("a keyword cannot be used as a name")
            .with_note("the keywords are import, let, fn, material, camera, light, render, scene, if, else, for and in")
            .with_help(format!("choose another name, such as `{}1`", t.to_string().trim_matches('`')));
        }
    }
    // `.5`: a number written without its leading zero (the digits as written: `.05` is the
    // integer 5 in two digits).
    let leading_dot = match (e.found(), tokens.iter().find(|(_, s)| s.start >= span.end)) {
        (Some(Token::Dot), Some((Token::Int(n), s))) if s.start == span.end => {
            let digits = format!("{n:0width$}", width = s.range().len());
            Some(format!("write `0.{digits}`: a number starts with a digit"))
        }
        _ => None,
    };
    // A missing `;`, `,` or closing delimiter is reported just after the previous token, where
    // it belongs, rather than at the next token.
    let closers: Vec<&str> = ["`;`", "`,`", "`)`", "`}`"]
        .into_iter()
        .filter(|c| expected.iter().any(|x| x == c))
        .collect();
    if !closers.is_empty() && e.found().is_some() {
        if let Some(prev) = tokens.iter().rev().find(|(_, s)| s.end <= span.start) {
            let at = Span {
                file,
                start: prev.1.end,
                end: prev.1.end,
            };
            let list = closers.join(" or ");
            let mut d = Diagnostic::error("E0101", format!("expected {list}, found {found}"), at)
                .with_label("something is missing here")
                .with_secondary(span, format!("found {found}"));
            let after_call = matches!(prev.0, Token::RParen);
            if let Some(help) = &leading_dot {
                d = d.with_help(help.clone());
            }
            match e.found() {
                Some(Token::Ident(u)) if u == "deg" || u == "rad" => {
                    d = d.with_help("write an angle's unit right after the number, as in `90deg`");
                }
                // `sphere(1) red;`: the `@` before a material is missing.
                Some(Token::Ident(name))
                    if closers.contains(&"`;`")
                        && expected.iter().any(|x| x == "`@`")
                        && (materials.contains(&name.as_str()) || after_call) =>
                {
                    d = d.with_help(format!(
                        "did you mean `@ {name}`? A shape is painted with `shape @ material`"
                    ));
                    if materials.contains(&name.as_str()) {
                        d = d.with_note(format!("`{name}` is a material declared in this file"));
                    }
                }
                _ => {}
            }
            return d;
        }
    }
    let mut d = Diagnostic::error("E0100", format!("unexpected {found}"), span)
        .with_label(format!("unexpected {found}"));
    if let Some(help) = leading_dot {
        d = d.with_help(help);
    }
    if matches!(e.found(), Some(Token::For)) && !expected.iter().any(|x| x == "`for`") {
        d = d.with_help(
            "a `for` statement belongs in the `scene` block; in an expression, such as a function's body, build a list with `[for i in 0..n { ... }]` and combine it with `union(...)`",
        );
    }
    if !expected.is_empty() {
        let list = if expected.len() > 8 {
            format!("{}, …", expected[..8].join(", "))
        } else {
            expected.join(", ")
        };
        d = d.with_note(format!("expected {list}"));
    }
    d
}
