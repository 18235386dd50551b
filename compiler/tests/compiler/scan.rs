//! The Rust source scanned as the house's tests read it: a little lexer whose tokens
//! (identifiers, `::` and punctuation, each with its line) leave out comments, strings,
//! characters and lifetimes, and the workspace's `.rs` files.

use std::path::{Path, PathBuf};

/// A token of the little lexer below: what dependency paths are made of.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Tok {
    Ident(String),
    /// `::`
    Path,
    /// Any other punctuation character.
    Punct(char),
}

/// The identifiers and punctuation of Rust source, without comments, strings, characters
/// and lifetimes.
pub(crate) fn tokens(src: &str) -> Vec<Tok> {
    located_tokens(src).into_iter().map(|(t, _)| t).collect()
}

/// [`tokens`], each with the 1-based line it starts on.
pub(crate) fn located_tokens(src: &str) -> Vec<(Tok, usize)> {
    let s: Vec<char> = src.chars().collect();
    // The index of the first character of each line.
    let starts: Vec<usize> = std::iter::once(0)
        .chain(
            s.iter()
                .enumerate()
                .filter(|(_, &c)| c == '\n')
                .map(|(i, _)| i + 1),
        )
        .collect();
    let line = |i: usize| starts.partition_point(|&start| start <= i);
    let mut out = Vec::new();
    let mut i = 0;
    while i < s.len() {
        let c = s[i];
        let next = s.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < s.len() && s[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            let mut depth = 0;
            while i < s.len() {
                if s[i] == '/' && s.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if s[i] == '*' && s.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if c == '"' {
            i = skip_string(&s, i + 1, 0);
        } else if (c == 'r' || c == 'b') && is_raw_string(&s, i) {
            let mut j = i + if c == 'b' { 2 } else { 1 };
            let mut hashes = 0;
            while s[j] == '#' {
                hashes += 1;
                j += 1;
            }
            i = skip_string(&s, j + 1, hashes);
        } else if c == 'b' && next == Some('"') {
            i = skip_string(&s, i + 2, 0);
        } else if c == '\'' {
            // A character literal ('x', '\n', '\u{..}') or a lifetime ('a).
            if next == Some('\\') {
                i += 2;
                while i < s.len() && s[i] != '\'' {
                    i += 1;
                }
                i += 1;
            } else if s.get(i + 2) == Some(&'\'') {
                i += 3;
            } else {
                i += 1;
                while i < s.len() && (s[i].is_alphanumeric() || s[i] == '_') {
                    i += 1;
                }
            }
        } else if c.is_alphabetic() || c == '_' {
            let start = i;
            while i < s.len() && (s[i].is_alphanumeric() || s[i] == '_') {
                i += 1;
            }
            out.push((Tok::Ident(s[start..i].iter().collect()), line(start)));
        } else if c == ':' && next == Some(':') {
            out.push((Tok::Path, line(i)));
            i += 2;
        } else {
            if !c.is_whitespace() {
                out.push((Tok::Punct(c), line(i)));
            }
            i += 1;
        }
    }
    out
}

/// Whether a raw string (`r"`, `r#"`, `br"`, …) starts at `i`.
fn is_raw_string(s: &[char], i: usize) -> bool {
    if i > 0 && (s[i - 1].is_alphanumeric() || s[i - 1] == '_') {
        return false;
    }
    let mut j = i + if s[i] == 'b' { 1 } else { 0 };
    if s.get(j) != Some(&'r') {
        return false;
    }
    j += 1;
    while s.get(j) == Some(&'#') {
        j += 1;
    }
    s.get(j) == Some(&'"')
}

/// The index just past a string whose body starts at `i`, closed by `"` and `hashes` `#`s.
fn skip_string(s: &[char], mut i: usize, hashes: usize) -> usize {
    while i < s.len() {
        if hashes == 0 && s[i] == '\\' {
            i += 2;
            continue;
        }
        if s[i] == '"' && (0..hashes).all(|k| s.get(i + 1 + k) == Some(&'#')) {
            return i + 1 + hashes;
        }
        i += 1;
    }
    i
}

pub(crate) fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The `.rs` files under `dir` (relative to the workspace root), build output left out.
pub(crate) fn workspace_rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("readable").flatten() {
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().into_owned();
        if path.is_dir() {
            if name != "target" && !name.starts_with('.') {
                workspace_rust_files(&path, out);
            }
        } else if name.ends_with(".rs") {
            out.push(path);
        }
    }
}
