//! The lexer: source text to tokens with spans (logos), and lexical diagnostics.
//!
//! Grammar rules: `token`, `number`, `string`, `comment` in `grammar/sdf.ebnf`.

use crate::diagnostics::Diagnostic;
use crate::span::{FileId, Span};
use logos::Logos;
use std::fmt;

/// One token. Literals carry their parsed value; a number with a unit suffix is an angle in
/// radians.
#[derive(Logos, Debug, Clone, PartialEq)]
#[logos(skip r"[ \t\r\n\f]+")]
#[logos(skip(r"//[^\n]*", allow_greedy = true))]
pub enum Token {
    #[token("import")]
    Import,
    #[token("let")]
    Let,
    #[token("param")]
    Param,
    #[token("fn")]
    Fn,
    #[token("material")]
    Material,
    #[token("camera")]
    Camera,
    #[token("light")]
    Light,
    #[token("render")]
    Render,
    #[token("scene")]
    Scene,
    #[token("if")]
    If,
    #[token("else")]
    Else,
    #[token("for")]
    For,
    #[token("in")]
    In,
    #[token("true", |_| true)]
    #[token("false", |_| false)]
    Bool(bool),
    /// An integer literal.
    #[regex(r"[0-9]+", priority = 3, callback = |lex| lex.slice().parse::<i64>().ok())]
    Int(i64),
    /// A float literal (with a fraction or an exponent).
    #[regex(r"[0-9]+\.[0-9]+([eE][+-]?[0-9]+)?|[0-9]+[eE][+-]?[0-9]+", |lex| lex.slice().parse::<f64>().ok())]
    Float(f64),
    /// An angle literal such as `45deg` or `0.5rad`, in radians.
    #[regex(r"([0-9]+(\.[0-9]+)?([eE][+-]?[0-9]+)?)(deg|rad)", angle)]
    Angle(f64),
    /// A colour written as the web writes it, `#rrggbb`: three sRGB bytes.
    #[regex(r"#[0-9a-fA-F]{6}", colour)]
    Colour([u8; 3]),
    /// A string literal, without its quotes, its escapes resolved: made by [`lex`], which
    /// scans it from its opening [`Token::Quote`].
    Str(String),
    /// The opening quote of a string: [`lex`] scans the rest of the string, `"` then any
    /// characters but `"`, `\` and a line break, or escapes (a backslash and any character
    /// but a line break), then `"`. (A regex of logos would do it with two states that call
    /// each other once per escape, nesting a function call for each; the stack of a debug
    /// build overflows on a string of a few thousand escapes.)
    #[token("\"")]
    Quote,
    #[regex(r"[A-Za-z_][A-Za-z0-9_]*", |lex| lex.slice().to_string())]
    Ident(String),
    #[token("(")]
    LParen,
    #[token(")")]
    RParen,
    #[token("{")]
    LBrace,
    #[token("}")]
    RBrace,
    #[token("[")]
    LBracket,
    #[token("]")]
    RBracket,
    #[token(",")]
    Comma,
    #[token(";")]
    Semi,
    #[token(":")]
    Colon,
    #[token(".")]
    Dot,
    #[token("..")]
    DotDot,
    #[token("@")]
    At,
    #[token("=")]
    Eq,
    #[token("->")]
    Arrow,
    #[token("+")]
    Plus,
    #[token("-")]
    Minus,
    #[token("*")]
    Star,
    #[token("/")]
    Slash,
    #[token("%")]
    Percent,
    #[token("<")]
    Lt,
    #[token("<=")]
    Le,
    #[token(">")]
    Gt,
    #[token(">=")]
    Ge,
    #[token("==")]
    EqEq,
    #[token("!=")]
    Ne,
    #[token("&&")]
    AndAnd,
    #[token("||")]
    OrOr,
    #[token("!")]
    Bang,
    /// The start of a block comment; the lexer driver skips to its end.
    #[token("/*")]
    BlockComment,
}

fn colour(lex: &mut logos::Lexer<Token>) -> Option<[u8; 3]> {
    let hex = lex.slice().get(1..)?;
    let byte = |i: usize| u8::from_str_radix(hex.get(i..i + 2)?, 16).ok();
    Some([byte(0)?, byte(2)?, byte(4)?])
}

fn angle(lex: &mut logos::Lexer<Token>) -> Option<f64> {
    let s = lex.slice();
    let (num, unit) = s.split_at(s.len() - 3);
    let v: f64 = num.parse().ok()?;
    Some(if unit == "deg" { v.to_radians() } else { v })
}

impl fmt::Display for Token {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let s = match self {
            Token::Import => "import",
            Token::Let => "let",
            Token::Param => "param",
            Token::Fn => "fn",
            Token::Material => "material",
            Token::Camera => "camera",
            Token::Light => "light",
            Token::Render => "render",
            Token::Scene => "scene",
            Token::If => "if",
            Token::Else => "else",
            Token::For => "for",
            Token::In => "in",
            Token::Bool(b) => return write!(f, "{b}"),
            Token::Int(_) | Token::Float(_) => "number",
            Token::Angle(_) => "angle",
            Token::Colour(_) => "colour",
            Token::Str(_) | Token::Quote => "string",
            Token::Ident(name) => return write!(f, "identifier `{name}`"),
            Token::LParen => "(",
            Token::RParen => ")",
            Token::LBrace => "{",
            Token::RBrace => "}",
            Token::LBracket => "[",
            Token::RBracket => "]",
            Token::Comma => ",",
            Token::Semi => ";",
            Token::Colon => ":",
            Token::Dot => ".",
            Token::DotDot => "..",
            Token::At => "@",
            Token::Eq => "=",
            Token::Arrow => "->",
            Token::Plus => "+",
            Token::Minus => "-",
            Token::Star => "*",
            Token::Slash => "/",
            Token::Percent => "%",
            Token::Lt => "<",
            Token::Le => "<=",
            Token::Gt => ">",
            Token::Ge => ">=",
            Token::EqEq => "==",
            Token::Ne => "!=",
            Token::AndAnd => "&&",
            Token::OrOr => "||",
            Token::Bang => "!",
            Token::BlockComment => "/*",
        };
        write!(f, "`{s}`")
    }
}

/// Splits `text` into tokens. Lexical errors become diagnostics and the offending bytes are
/// skipped, so the parser still sees every valid token. A byte-order mark at the start (which
/// some editors write) is skipped; spans stay offsets into `text`.
pub fn lex(file: FileId, text: &str) -> (Vec<(Token, Span)>, Vec<Diagnostic>) {
    lex_watched(file, text, |_, _| true)
}

/// [`lex`], showing each token to `keep` as it is lexed: once `keep` returns false, the
/// tokens after it are shown but not kept (a caller that refuses the text at some token
/// still sees the rest, in memory that does not grow with it).
pub fn lex_watched(
    file: FileId,
    text: &str,
    mut keep: impl FnMut(&Token, Span) -> bool,
) -> (Vec<(Token, Span)>, Vec<Diagnostic>) {
    let mut tokens = Vec::new();
    let mut diags = Vec::new();
    let mut lexer = Token::lexer(text);
    if text.starts_with(BOM) {
        lexer.bump(BOM.len_utf8());
    }
    let mut keeping = true;
    let mut push = |tokens: &mut Vec<(Token, Span)>, token: Token, span: Span| {
        keeping &= keep(&token, span);
        if keeping {
            tokens.push((token, span));
        }
    };
    while let Some(result) = lexer.next() {
        let range = lexer.span();
        let span = Span::new(file, range.clone());
        match result {
            Ok(Token::BlockComment) => {
                let rest = &text[range.end..];
                match rest.find("*/") {
                    Some(end) => lexer.bump(end + 2),
                    None => {
                        diags.push(
                            Diagnostic::error("E0003", "unterminated block comment", span)
                                .with_label("this comment is never closed")
                                .with_help("close it with `*/`"),
                        );
                        lexer.bump(rest.len());
                    }
                }
            }
            Ok(Token::Quote) => {
                let rest = &text[range.end..];
                let (len, closed) = string_body(rest);
                let span = Span::new(file, range.start..range.end + len + closed as usize);
                lexer.bump(len + closed as usize);
                if closed {
                    let (text, bad) = unescape(&rest[..len], range.end, file);
                    diags.extend(bad);
                    push(&mut tokens, Token::Str(text), span);
                } else {
                    diags.push(
                        Diagnostic::error("E0002", "unterminated string literal", span)
                            .with_label("this string has no closing quote on its line")
                            .with_help("strings end with `\"` on the same line"),
                    );
                    // The parser sees a string, so the rest of the line is not misread.
                    push(&mut tokens, Token::Str(String::new()), span);
                }
            }
            Ok(tok) => push(&mut tokens, tok, span),
            Err(()) => {
                let d = lex_error(text, range.clone(), span);
                // A malformed number still stands for a number to the parser.
                if d.code == "E0004" {
                    push(&mut tokens, Token::Float(0.0), span);
                }
                diags.push(d);
            }
        }
    }
    (tokens, diags)
}

/// The byte-order mark, U+FEFF, that may start a UTF-8 file.
pub const BOM: char = '\u{feff}';

/// The length in bytes of the body of a string whose opening quote is just before `rest`,
/// and whether a closing quote follows it. The body is characters other than `"`, `\` and
/// a line break, and escapes (a backslash and any character but a line break); an
/// unterminated string ends before the line break, or before a backslash that escapes
/// nothing (which is then lexed on its own, as an unexpected character).
fn string_body(rest: &str) -> (usize, bool) {
    let mut chars = rest.char_indices().peekable();
    while let Some((i, c)) = chars.next() {
        match c {
            '"' => return (i, true),
            '\n' => return (i, false),
            '\\' => match chars.peek() {
                Some(&(_, e)) if e != '\n' => {
                    chars.next();
                }
                _ => return (i, false),
            },
            _ => {}
        }
    }
    (rest.len(), false)
}

/// The escapes of a string: the character after the backslash, and what it stands for
/// (docs/language.md and grammar/sdf.ebnf list the same, a tidy test holds them in step).
pub const ESCAPES: [(char, char); 4] = [('"', '"'), ('\\', '\\'), ('n', '\n'), ('t', '\t')];

/// The note of an unknown escape: ``the escapes are \", \\, \n and \t``.
fn escapes_note() -> String {
    let list = ESCAPES.map(|(k, _)| format!("\\{k}"));
    match list.split_last() {
        Some((last, rest)) => format!("the escapes are {} and {last}", rest.join(", ")),
        None => "a string has no escapes".into(),
    }
}

/// What the escape `\c` stands for, if it is one of the [`ESCAPES`].
fn escaped(c: char) -> Option<char> {
    ESCAPES.iter().find(|&&(k, _)| k == c).map(|&(_, v)| v)
}

/// Resolves the [`ESCAPES`]; any other escape is an error (the character is kept, so
/// nothing after it is misread).
fn unescape(raw: &str, offset: usize, file: FileId) -> (String, Vec<Diagnostic>) {
    let mut out = String::with_capacity(raw.len());
    let mut diags = Vec::new();
    let mut chars = raw.char_indices();
    while let Some((i, c)) = chars.next() {
        if c != '\\' {
            out.push(c);
            continue;
        }
        match chars.next() {
            Some((_, e)) if escaped(e).is_some() => out.extend(escaped(e)),
            Some((j, other)) => {
                let span = Span::new(file, offset + i..offset + j + other.len_utf8());
                diags.push(
                    Diagnostic::error(
                        "E0005",
                        format!("unknown escape `\\{other}` in a string"),
                        span,
                    )
                    .with_label("not an escape")
                    .with_note(escapes_note()),
                );
                out.push(other);
            }
            None => out.push('\\'),
        }
    }
    (out, diags)
}

fn lex_error(text: &str, range: std::ops::Range<usize>, span: Span) -> Diagnostic {
    // (A quote is never an error here: it is a token, and `lex` scans its string.)
    let slice = &text[range.clone()];
    if slice.starts_with(|c: char| c.is_ascii_digit()) {
        return Diagnostic::error("E0004", format!("invalid number literal `{slice}`"), span)
            .with_label("not a valid number")
            .with_note("integers must fit in 64 bits; floats look like `1.5`, `2e-3` or `.5` written as `0.5`");
    }
    let ch = slice.chars().next().unwrap_or('?');
    let shown = if ch.is_control() || ch.is_whitespace() {
        ch.escape_default().to_string()
    } else {
        ch.to_string()
    };
    let d = Diagnostic::error("E0001", format!("unexpected character `{shown}`"), span)
        .with_label("not part of the language");
    match ch {
        '&' => d.with_help(
            "shapes are intersected with `intersect(a, b)`; logical and is written `&&`",
        ),
        '|' => d.with_help("shapes are joined with `union(a, b)`; logical or is written `||`"),
        // `#ff80`: a colour short of its six hex digits.
        '#' if text[range.start + 1..].starts_with(|c: char| c.is_ascii_hexdigit()) => d.with_help(
            "a colour is `#` and six hex digits, as `#ff8800`; comments start with `//`",
        ),
        '#' => d.with_help("comments start with `//`"),
        _ => d,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(r: std::ops::Range<usize>) -> Span {
        Span::new(FileId(0), r)
    }

    /// A string is scanned by a loop: 100 000 escapes lex on a test thread's stack in a debug
    /// build (a regex's states recursed once per escape and overflowed it).
    #[test]
    fn a_string_of_many_escapes_lexes_on_a_small_stack() {
        let text = format!("\"{}\"", "\\n".repeat(100_000));
        let (tokens, diags) = lex(FileId(0), &text);
        assert!(diags.is_empty(), "{diags:?}");
        assert_eq!(
            tokens,
            [(Token::Str("\n".repeat(100_000)), at(0..text.len()))]
        );
    }

    /// Where a string ends, closed or not, and what follows it.
    #[test]
    fn strings_end_at_their_quote_or_their_line() {
        let lexed = |text: &str| {
            let (tokens, diags) = lex(FileId(0), text);
            let codes: Vec<_> = diags.iter().map(|d| (d.code, d.labels[0].span)).collect();
            (tokens, codes)
        };
        let s = |t: &str| Token::Str(t.into());
        let x = Token::Ident("x".into());
        assert_eq!(
            lexed("\"a\\\"b\\\\\" x"),
            (
                vec![(s("a\"b\\"), at(0..8)), (x.clone(), at(9..10))],
                vec![]
            )
        );
        assert_eq!(
            lexed("\"ab\nx"),
            (
                vec![(s(""), at(0..3)), (x.clone(), at(4..5))],
                vec![("E0002", at(0..3))]
            )
        );
        // A backslash before the line's end escapes nothing: the string ends before it, and
        // it is a character of its own.
        assert_eq!(
            lexed("\"ab\\\nx"),
            (
                vec![(s(""), at(0..3)), (x.clone(), at(5..6))],
                vec![("E0002", at(0..3)), ("E0001", at(3..4))]
            )
        );
        assert_eq!(
            lexed("\"ab\\"),
            (
                vec![(s(""), at(0..3))],
                vec![("E0002", at(0..3)), ("E0001", at(3..4))]
            )
        );
        assert_eq!(
            lexed("\"ab"),
            (vec![(s(""), at(0..3))], vec![("E0002", at(0..3))])
        );
        // An unknown escape keeps its character; any character may be escaped, a multi-byte
        // one too.
        assert_eq!(
            lexed("\"é\\q\\é\" x"),
            (
                vec![(s("éqé"), at(0..9)), (x, at(10..11))],
                vec![("E0005", at(3..5)), ("E0005", at(5..8))]
            )
        );
    }
}
