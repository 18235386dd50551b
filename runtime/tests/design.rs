//! Design rules checked over the sources: the top-level modules of each crate
//! (`compiler/src`, `runtime/src`) depend on each other without cycles, so that each can be
//! read, and tested, on top of the ones below it.
//!
//! The dependencies are read from the text: every `crate::` path (in `use` declarations and in
//! code, braced groups included) and every `super::` path that climbs to the crate root names
//! the top-level module it reaches. Comments and string literals are skipped; code under
//! `#[cfg(test)]` (unit tests, which may use any part of their crate) is left out.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A token of the little lexer below: what dependency paths are made of.
#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Ident(String),
    /// `::`
    Path,
    /// Any other punctuation character.
    Punct(char),
}

/// The identifiers and punctuation of Rust source, without comments, strings, characters
/// and lifetimes.
fn tokens(src: &str) -> Vec<Tok> {
    let s: Vec<char> = src.chars().collect();
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
            out.push(Tok::Ident(s[start..i].iter().collect()));
        } else if c == ':' && next == Some(':') {
            out.push(Tok::Path);
            i += 2;
        } else {
            if !c.is_whitespace() {
                out.push(Tok::Punct(c));
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

/// The first identifiers of the paths at `toks[i..]`: one identifier, or a braced group's
/// elements (`{a::b, c}` gives a and c).
fn heads(toks: &[Tok], i: usize) -> Vec<String> {
    match toks.get(i) {
        Some(Tok::Ident(name)) => vec![name.clone()],
        Some(Tok::Punct('{')) => {
            let mut out = Vec::new();
            let mut depth = 0;
            let mut first = true;
            for t in &toks[i..] {
                match t {
                    Tok::Punct('{') => {
                        depth += 1;
                    }
                    Tok::Punct('}') => {
                        depth -= 1;
                        if depth == 0 {
                            break;
                        }
                    }
                    Tok::Punct(',') if depth == 1 => first = true,
                    Tok::Ident(name) if depth == 1 && first => {
                        out.push(name.clone());
                        first = false;
                    }
                    _ => first = false,
                }
            }
            out
        }
        _ => Vec::new(),
    }
}

/// The module path of a source file below `src` (`check/eval.rs` is `[check, eval]`,
/// `check/mod.rs` and `check.rs` are `[check]`, `lib.rs` is `[]`).
fn module_path(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).expect("below src");
    let mut parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().expect("a file name");
    let stem = last.trim_end_matches(".rs");
    if !matches!(stem, "mod" | "lib" | "main") {
        parts.push(stem.to_string());
    }
    parts
}

/// Every `.rs` file below `dir`.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("a directory entry").path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The modules declared `#[cfg(test)] mod name;` in a file, and the dependencies of the
/// file's code outside `#[cfg(test)]` inline modules: (top-level module reached, the path
/// text for the message).
fn dependencies(module: &[String], toks: &[Tok]) -> (Vec<String>, Vec<(String, String)>) {
    let mut test_files = Vec::new();
    let mut deps = Vec::new();
    // Inline modules open around the current token: (name, brace depth inside, under test).
    let mut open: Vec<(String, usize, bool)> = Vec::new();
    let mut depth = 0;
    let mut pending_test = false;
    let mut i = 0;
    while i < toks.len() {
        let in_test = open.iter().any(|m| m.2);
        match &toks[i] {
            Tok::Punct('#') if toks.get(i + 1) == Some(&Tok::Punct('[')) => {
                let attr: Vec<&Tok> = toks[i + 2..].iter().take(5).collect();
                if attr
                    == [
                        &Tok::Ident("cfg".into()),
                        &Tok::Punct('('),
                        &Tok::Ident("test".into()),
                        &Tok::Punct(')'),
                        &Tok::Punct(']'),
                    ]
                {
                    pending_test = true;
                    i += 7;
                    continue;
                }
            }
            Tok::Ident(k) if k == "mod" => {
                if let Some(Tok::Ident(name)) = toks.get(i + 1) {
                    match toks.get(i + 2) {
                        Some(Tok::Punct('{')) => {
                            depth += 1;
                            open.push((name.clone(), depth, pending_test || in_test));
                            pending_test = false;
                            i += 3;
                            continue;
                        }
                        Some(Tok::Punct(';')) if pending_test || in_test => {
                            test_files.push(name.clone());
                        }
                        _ => {}
                    }
                }
                pending_test = false;
            }
            Tok::Ident(k) if k == "pub" => {}
            Tok::Punct('{') => {
                depth += 1;
                pending_test = false;
            }
            Tok::Punct('}') => {
                if open.last().is_some_and(|m| m.1 == depth) {
                    open.pop();
                }
                depth -= 1;
            }
            Tok::Ident(k) if k == "crate" && toks.get(i + 1) == Some(&Tok::Path) => {
                let previous = i.checked_sub(1).map(|j| &toks[j]);
                if !in_test && previous != Some(&Tok::Punct('$')) {
                    for h in heads(toks, i + 2) {
                        deps.push((h.clone(), format!("crate::{h}")));
                    }
                }
                i += 2;
                continue;
            }
            Tok::Ident(k) if k == "super" && toks.get(i + 1) == Some(&Tok::Path) => {
                let mut here: Vec<String> = module.to_vec();
                here.extend(open.iter().map(|m| m.0.clone()));
                let mut j = i;
                let mut climbed = 0;
                while toks.get(j) == Some(&Tok::Ident("super".into()))
                    && toks.get(j + 1) == Some(&Tok::Path)
                {
                    climbed += 1;
                    j += 2;
                }
                here.truncate(here.len().saturating_sub(climbed));
                if !in_test {
                    let text = "super::".repeat(climbed);
                    match here.first() {
                        Some(top) => deps.push((top.clone(), format!("{text}…"))),
                        None => {
                            for h in heads(toks, j) {
                                deps.push((h.clone(), format!("{text}{h}")));
                            }
                        }
                    }
                }
                i = j;
                continue;
            }
            _ => pending_test = false,
        }
        i += 1;
    }
    (test_files, deps)
}

/// The graph of a crate's top-level modules: for each, the modules it uses, with one
/// example of where (file and path).
fn graph(src: &Path) -> BTreeMap<String, BTreeMap<String, String>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let tops: BTreeSet<String> = files
        .iter()
        .filter_map(|f| module_path(src, f).first().cloned())
        .collect();
    // Files declared under #[cfg(test)], by module path.
    let mut test_modules: BTreeSet<Vec<String>> = BTreeSet::new();
    let mut parsed = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).expect("a readable source");
        let module = module_path(src, file);
        let (tests, deps) = dependencies(&module, &tokens(&text));
        for t in tests {
            let mut m = module.clone();
            m.push(t);
            test_modules.insert(m);
        }
        parsed.push((file, module, deps));
    }
    let mut out: BTreeMap<String, BTreeMap<String, String>> = BTreeMap::new();
    for (file, module, deps) in parsed {
        let Some(top) = module.first() else {
            continue;
        };
        if (1..=module.len()).any(|n| test_modules.contains(&module[..n])) {
            continue;
        }
        let entry = out.entry(top.clone()).or_default();
        for (to, text) in deps {
            if &to != top && tops.contains(&to) {
                let at = file.strip_prefix(src).expect("below src").display();
                entry.entry(to).or_insert(format!("{at}: {text}"));
            }
        }
    }
    out
}

/// The cycles of a graph: for each strongly connected component of more than one module,
/// one cycle through it, as the list of edges with where each is.
fn cycles(graph: &BTreeMap<String, BTreeMap<String, String>>) -> Vec<Vec<String>> {
    let reach = |from: &str| {
        let mut seen = BTreeSet::new();
        let mut stack = vec![from.to_string()];
        while let Some(m) = stack.pop() {
            for to in graph.get(&m).into_iter().flat_map(|e| e.keys()) {
                if seen.insert(to.clone()) {
                    stack.push(to.clone());
                }
            }
        }
        seen
    };
    let mut out = Vec::new();
    let mut reported: BTreeSet<String> = BTreeSet::new();
    for start in graph.keys() {
        if reported.contains(start) || !reach(start).contains(start) {
            continue;
        }
        // The shortest cycle through `start`, by breadth-first search.
        let mut parent: BTreeMap<String, String> = BTreeMap::new();
        let mut queue = std::collections::VecDeque::from([start.clone()]);
        let mut end = None;
        while let Some(m) = queue.pop_front() {
            for to in graph.get(&m).into_iter().flat_map(|e| e.keys()) {
                if to == start {
                    end = Some(m.clone());
                    queue.clear();
                    break;
                }
                if !parent.contains_key(to) {
                    parent.insert(to.clone(), m.clone());
                    queue.push_back(to.clone());
                }
            }
        }
        let mut back = Vec::new();
        let mut m = end.expect("a cycle");
        while &m != start {
            back.push(m.clone());
            m = parent[&m].clone();
        }
        back.reverse();
        let path: Vec<String> = std::iter::once(start.clone())
            .chain(back)
            .chain(std::iter::once(start.clone()))
            .collect();
        let edges = path
            .windows(2)
            .map(|w| format!("{} → {} ({})", w[0], w[1], graph[&w[0]][&w[1]]))
            .collect();
        reported.extend(path);
        out.push(edges);
    }
    out
}

fn check_crate(name: &str) {
    let src = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(name)
        .join("src");
    let graph = graph(&src);
    assert!(
        graph.len() > 3,
        "{name}: too few modules found in {}",
        src.display()
    );
    let found = cycles(&graph);
    let text: Vec<String> = found.iter().map(|c| c.join("\n  ")).collect();
    assert!(
        found.is_empty(),
        "{name}: the top-level modules depend on each other in cycles:\n  {}",
        text.join("\n\n  ")
    );
}

#[test]
fn the_compilers_modules_have_no_cycles() {
    check_crate("compiler");
}

#[test]
fn the_runtimes_modules_have_no_cycles() {
    check_crate("runtime");
}

#[test]
fn the_scanner_finds_paths_and_cycles() {
    let toks = tokens(
        "use crate::{a::X, b}; // crate::c\n\
         fn f() { let s = \"crate::d\"; crate::e::g(); let c = '\"'; }\n\
         #[cfg(test)] mod tests { use crate::h; }\n\
         mod inner { use super::super::k; }",
    );
    let (_, deps) = dependencies(&["m".into()], &toks);
    let found: Vec<&str> = deps.iter().map(|d| d.0.as_str()).collect();
    assert_eq!(found, ["a", "b", "e", "k"]);
    let mut g: BTreeMap<String, BTreeMap<String, String>> = BTreeMap::new();
    for (from, to) in [("a", "b"), ("b", "c"), ("c", "a"), ("c", "d")] {
        g.entry(from.into())
            .or_default()
            .insert(to.into(), "here".into());
    }
    let c = cycles(&g);
    assert_eq!(c.len(), 1, "{c:?}");
    assert_eq!(c[0].len(), 3, "{c:?}");
    g.get_mut("c").expect("c").remove("a");
    assert!(cycles(&g).is_empty());
}
