//! The counts of issue 48 that may only fall, checked over the workspace's Rust files: errors
//! that are a bare `String` (`Result<_, String>`), where every error should be an enum variant
//! with its data. The figure is the count today; lower it when a change removes some.

use crate::tidy::{root, tokens, workspace_rust_files, Tok};

/// The most `Result<_, String>` types the workspace may write (comments and strings aside).
const STRING_ERRORS: usize = 15;

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
