//! The counts of issue 48 that may only fall, checked over the workspace's Rust files: errors
//! that are a bare `String` (`Result<_, String>`), where every error should be an enum variant
//! with its data; files over 800 lines and functions over 150, where each should be one
//! responsibility a reader takes in; and no comment cites the benchmarks page or a GPU model
//! (figures belong to the benchmarks page, with their machine). Each figure is the count today;
//! lower it when a change removes some.

use crate::scan::{located_tokens, root, tokens, workspace_rust_files, Tok};
use std::path::PathBuf;

/// The most `Result<_, String>` types the workspace may write (comments and strings aside).
const STRING_ERRORS: usize = 8;

/// How many `Result<…, String>` types the tokens hold: a `Result` whose last top-level
/// argument is the identifier `String` alone.
fn string_results(toks: &[Tok]) -> usize {
    let mut n = 0;
    for (i, t) in toks.iter().enumerate() {
        if *t != Tok::Ident("Result".into()) || toks.get(i + 1) != Some(&Tok::Punct('<')) {
            continue;
        }
        // The tokens of the last argument at depth 1, up to the matching `>` (a `>` after
        // `-` is an arrow's, not a closing bracket).
        let (mut depth, mut last) = (0usize, Vec::new());
        for (j, t) in toks.iter().enumerate().skip(i + 1) {
            match t {
                Tok::Punct('<') => depth += 1,
                Tok::Punct('>') if toks.get(j - 1) != Some(&Tok::Punct('-')) => {
                    depth -= 1;
                    if depth == 0 {
                        break;
                    }
                }
                Tok::Punct(',') if depth == 1 => {
                    last.clear();
                    continue;
                }
                _ => {}
            }
            if depth >= 1 && j > i + 1 {
                last.push(t.clone());
            }
        }
        if last == [Tok::Ident("String".into())] {
            n += 1;
        }
    }
    n
}

#[test]
fn the_scanner_counts_string_results() {
    let src = "fn a() -> Result<(), String> {}\n\
               fn b() -> Result<Vec<u8>, Error> {}\n\
               fn c() -> Result<HashMap<String, u8>, String> {}\n\
               // Result<(), String> in a comment\n\
               fn d() -> Result<fn(u8) -> u8, String> { \"Result<(), String>\" }\n\
               fn e() -> std::result::Result<String, std::io::Error> {}";
    assert_eq!(string_results(&tokens(src)), 3);
}

/// issue 48, step 2: the workspace's `Result<_, String>` stay at or below [`STRING_ERRORS`].
#[test]
fn string_errors_do_not_grow() {
    let mut files = Vec::new();
    workspace_rust_files(&root(), &mut files);
    let mut counts: Vec<(usize, String)> = files
        .iter()
        .map(|path| {
            let text = std::fs::read_to_string(path).expect("readable");
            let rel = path.strip_prefix(root()).unwrap_or(path);
            (string_results(&tokens(&text)), rel.display().to_string())
        })
        .filter(|(n, _)| *n > 0)
        .collect();
    counts.sort_by(|a, b| b.cmp(a));
    let total: usize = counts.iter().map(|(n, _)| n).sum();
    assert!(
        total <= STRING_ERRORS,
        "{total} `Result<_, String>` in the workspace, more than {STRING_ERRORS}: give the \
         new errors an enum variant with their data. By file: {counts:?}"
    );
}

/// A file's length past which it should be split by responsibility.
const FILE_LINES: usize = 800;
/// A function's length past which it should be split.
const FUNCTION_LINES: usize = 150;

/// The workspace's Rust files, each with its path relative to the root and its text.
fn workspace_sources() -> Vec<(String, String)> {
    let mut files: Vec<PathBuf> = Vec::new();
    workspace_rust_files(&root(), &mut files);
    files
        .iter()
        .map(|path| {
            let text = std::fs::read_to_string(path).expect("readable");
            let rel = path.strip_prefix(root()).unwrap_or(path);
            (rel.display().to_string(), text)
        })
        .collect()
}

/// The functions with a body in the tokens: each one's name, first line and length in lines
/// (from `fn` to its closing brace).
fn functions(toks: &[(Tok, usize)]) -> Vec<(String, usize, usize)> {
    let mut out = Vec::new();
    for (i, (t, first)) in toks.iter().enumerate() {
        let Some((Tok::Ident(name), _)) = toks.get(i + 1) else {
            continue;
        };
        if *t != Tok::Ident("fn".into()) {
            continue;
        }
        // The body's opening brace: the first `{` outside the signature's brackets, unless a
        // `;` ends a declaration first.
        let mut depth = 0i32;
        let mut body = None;
        for (j, (t, _)) in toks.iter().enumerate().skip(i + 2) {
            match t {
                Tok::Punct('(' | '[') => depth += 1,
                Tok::Punct(')' | ']') => depth -= 1,
                Tok::Punct(';') if depth == 0 => break,
                Tok::Punct('{') if depth == 0 => {
                    body = Some(j);
                    break;
                }
                _ => {}
            }
        }
        let Some(open) = body else { continue };
        let mut braces = 0i32;
        for (t, last) in &toks[open..] {
            match t {
                Tok::Punct('{') => braces += 1,
                Tok::Punct('}') => {
                    braces -= 1;
                    if braces == 0 {
                        out.push((name.clone(), *first, last - first + 1));
                        break;
                    }
                }
                _ => {}
            }
        }
    }
    out
}

#[test]
fn the_scanner_measures_functions() {
    let src = "trait T { fn decl(&self) -> u8; }\n\
               fn short(a: [u8; 2]) -> u8 {\n\
                   let s = \"{{\";\n\
                   // } in a comment\n\
                   a[0]\n\
               }\n\
               fn outer() {\n\
                   fn inner() {}\n\
               }\n";
    let found = functions(&located_tokens(src));
    assert_eq!(
        found,
        [
            ("short".to_string(), 2, 5),
            ("outer".to_string(), 7, 3),
            ("inner".to_string(), 8, 1),
        ]
    );
}

/// issue 48, step 5: no Rust file is over [`FILE_LINES`] lines.
/// Fails, saying `what` and naming them longest first, unless there are no `long` places.
#[track_caller]
fn assert_none(mut long: Vec<(usize, String)>, what: &str) {
    long.sort_by(|a, b| b.cmp(a));
    assert!(long.is_empty(), "{what}. They are: {long:?}");
}

#[test]
fn no_file_is_long() {
    let long: Vec<(usize, String)> = workspace_sources()
        .into_iter()
        .map(|(path, text)| (text.lines().count(), path))
        .filter(|(n, _)| *n > FILE_LINES)
        .collect();
    assert_none(
        long,
        &format!("Rust files over {FILE_LINES} lines: split them by responsibility"),
    );
}

/// issue 48, step 5: no function is over [`FUNCTION_LINES`] lines.
#[test]
fn no_function_is_long() {
    let long: Vec<(usize, String)> = workspace_sources()
        .into_iter()
        .flat_map(|(path, text)| {
            functions(&located_tokens(&text))
                .into_iter()
                .filter(|(_, _, n)| *n > FUNCTION_LINES)
                .map(move |(name, line, n)| (n, format!("{path}:{line} {name}")))
        })
        .collect();
    assert_none(
        long,
        &format!("functions over {FUNCTION_LINES} lines: split them into steps"),
    );
}

/// issue 48, step 6: no comment cites the benchmarks page or a GPU model; the figures and the
/// machines they were measured on are that page's alone.
#[test]
fn no_comment_cites_the_benchmarks_or_a_gpu() {
    let cited = ["BENCHMARKS.md", "H100", "H200", "A100", "RTX "];
    let mut found = Vec::new();
    for (path, text) in workspace_sources() {
        for (n, line) in text.lines().enumerate() {
            let Some(comment) = line.trim_start().strip_prefix("//") else {
                continue;
            };
            if let Some(c) = cited.iter().find(|c| comment.contains(*c)) {
                found.push(format!("{path}:{} cites {c}", n + 1));
            }
        }
    }
    assert!(found.is_empty(), "{found:#?}");
}
