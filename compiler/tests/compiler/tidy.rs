//! The repository's rules, checked over its files (a tidy test):
//!
//! - the top-level modules of each crate (`compiler/src`, `lsp/src`, `runtime/src`) depend on each other
//!   without cycles, so that each can be read, and tested, on top of the ones below it; and so
//!   do the modules within each folder of `compiler/src` (siblings, the folder's `mod.rs` aside);
//! - every Rust file starts with a `//!` line saying what it holds;
//! - the editor grammar and the reference in `docs/` name every built-in, record field,
//!   diagnostic code and limit of the compiler;
//! - no resource limit is a `const MAX_…` outside `compiler/src/limits.rs`.
//!
//! Module dependencies:
//! The dependencies are read from the text: every `crate::` path (in `use` declarations and in
//! code, braced groups included) and every `super::` path that climbs to the crate root names
//! the top-level module it reaches. Comments and string literals are skipped; code under
//! `#[cfg(test)]` (unit tests, which may use any part of their crate) is left out.

use crate::common;

use sdfc_compiler::builtins::{self, BUILTINS};
use std::collections::{BTreeMap, BTreeSet};
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

/// The module paths a path names from `toks[i..]` on: its identifiers up to a braced group,
/// then each of the group's elements in turn (`a::{b::c, d}` gives a::b::c and a::d).
fn expand(toks: &[Tok], mut i: usize) -> Vec<Vec<String>> {
    let mut head = Vec::new();
    loop {
        match toks.get(i) {
            Some(Tok::Ident(name)) => {
                head.push(name.clone());
                if toks.get(i + 1) != Some(&Tok::Path) {
                    return vec![head];
                }
                i += 2;
            }
            Some(Tok::Punct('{')) => {
                let mut out = Vec::new();
                let mut depth = 0;
                let mut start = true;
                for (j, t) in toks.iter().enumerate().skip(i) {
                    match t {
                        Tok::Punct('{') => depth += 1,
                        Tok::Punct('}') => {
                            depth -= 1;
                            if depth == 0 {
                                break;
                            }
                        }
                        Tok::Punct(',') if depth == 1 => start = true,
                        _ if depth == 1 && start => {
                            start = false;
                            for tail in expand(toks, j) {
                                out.push(head.iter().cloned().chain(tail).collect());
                            }
                        }
                        _ => {}
                    }
                }
                return out;
            }
            _ => return vec![head],
        }
    }
}

/// A dependency found in a file: the top-level module it reaches, the path text for the
/// message, and the module path it names from the crate root.
type Dependency = (String, String, Vec<String>);

/// The modules declared `#[cfg(test)] mod name;` in a file, and the dependencies of the
/// file's code outside `#[cfg(test)]` inline modules.
fn dependencies(module: &[String], toks: &[Tok]) -> (Vec<String>, Vec<Dependency>) {
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
                    for path in expand(toks, i + 2) {
                        if let Some(h) = path.first() {
                            deps.push((h.clone(), format!("crate::{}", path.join("::")), path));
                        }
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
                    for tail in expand(toks, j) {
                        let path: Vec<String> = here.iter().cloned().chain(tail).collect();
                        if let Some(top) = path.first() {
                            let named = format!("{text}{}", path[here.len()..].join("::"));
                            deps.push((top.clone(), named, path));
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

/// Which modules use which: for each module, the modules it uses, with one example of where
/// (file and path).
type Graph = BTreeMap<String, BTreeMap<String, String>>;

/// The graphs of a crate's modules, one per folder, by the folder's module path (the crate
/// root's is `[]`): an edge from a module of the folder to a sibling it names (the code of
/// files below the module included, the folder's own `mod.rs` left out).
fn graphs(src: &Path) -> BTreeMap<Vec<String>, Graph> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    // Every module a file makes, with the modules above it.
    let modules: BTreeSet<Vec<String>> = files
        .iter()
        .flat_map(|f| {
            let m = module_path(src, f);
            (1..=m.len()).map(move |n| m[..n].to_vec())
        })
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
    let mut out: BTreeMap<Vec<String>, Graph> = BTreeMap::new();
    for (file, module, deps) in parsed {
        if (1..=module.len()).any(|n| test_modules.contains(&module[..n])) {
            continue;
        }
        for (_, text, path) in deps {
            // The folder both are in, and the siblings under it that each is or is inside.
            let k = module.iter().zip(&path).take_while(|(a, b)| a == b).count();
            let (Some(from), Some(to)) = (module.get(k), path.get(k)) else {
                continue;
            };
            if !modules.contains(&path[..=k]) {
                continue;
            }
            let at = file.strip_prefix(src).expect("below src").display();
            out.entry(module[..k].to_vec())
                .or_default()
                .entry(from.clone())
                .or_default()
                .entry(to.clone())
                .or_insert(format!("{at}: {text}"));
        }
    }
    out
}

/// The graph of a crate's top-level modules.
fn graph(src: &Path) -> Graph {
    graphs(src).remove(&Vec::new()).unwrap_or_default()
}

/// The cycles of a graph: for each strongly connected component of more than one module,
/// one cycle through it, as the list of edges with where each is.
fn cycles(graph: &Graph) -> Vec<Vec<String>> {
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
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    assert!(
        files.len() > 3,
        "{name}: too few modules found in {}",
        src.display()
    );
    let graph = graph(&src);
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
fn the_language_servers_modules_have_no_cycles() {
    check_crate("lsp");
}

/// Folders of `compiler/src` whose modules may use each other, and why.
const FOLDER_CYCLES_ALLOWED: &[(&str, &str)] = &[];

#[test]
fn the_modules_of_each_compiler_folder_have_no_cycles() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../compiler/src");
    let all = graphs(&src);
    assert!(all.len() > 5, "too few folders found in {}", src.display());
    let mut found = Vec::new();
    for (folder, graph) in all.iter().filter(|(f, _)| !f.is_empty()) {
        let name = folder.join("/");
        if FOLDER_CYCLES_ALLOWED.iter().any(|(f, _)| *f == name) {
            continue;
        }
        for cycle in cycles(graph) {
            found.push(format!("{name}/:\n  {}", cycle.join("\n  ")));
        }
    }
    assert!(
        found.is_empty(),
        "modules of a folder of compiler/src depend on each other in cycles:\n{}",
        found.join("\n\n")
    );
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
    let paths: Vec<String> = deps.iter().map(|d| d.2.join("::")).collect();
    assert_eq!(paths, ["a::X", "b", "e::g", "k"]);
    let toks = tokens("use super::{x::{Y, z::W}, v}; use crate::p::q;");
    let (_, deps) = dependencies(&["f".into(), "m".into()], &toks);
    let paths: Vec<String> = deps.iter().map(|d| d.2.join("::")).collect();
    assert_eq!(paths, ["f::x::Y", "f::x::z::W", "f::v", "p::q"]);
    let mut g: Graph = BTreeMap::new();
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

pub(crate) fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Every Rust file of the repository (build output and hidden folders left out) starts with
/// a `//!` line saying what it holds.
#[test]
fn every_rust_file_says_what_it_holds() {
    let mut files = Vec::new();
    workspace_rust_files(&root(), &mut files);
    assert!(files.len() > 50, "the sources were not found");
    let missing: Vec<String> = files
        .iter()
        .filter(|path| {
            let text = std::fs::read_to_string(path).expect("readable");
            !text.starts_with("//!")
        })
        .map(|path| path.display().to_string())
        .collect();
    assert!(
        missing.is_empty(),
        "files without a `//!` line: {missing:?}"
    );
}

// ---- The editor grammar and the reference stay in step with the compiler ----

fn read(rel: &str) -> String {
    let path = root().join(rel);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
}

#[test]
fn the_editor_grammar_knows_every_builtin() {
    let tm = read("grammar/sdf.tmLanguage.json");
    assert!(
        tm.contains("\"scopeName\": \"source.sdf\""),
        "the scope name is source.sdf"
    );
    for b in BUILTINS.iter() {
        let listed = [
            format!("|{}|", b.name),
            format!("({}|", b.name),
            format!("|{})", b.name),
        ];
        assert!(
            listed.iter().any(|l| tm.contains(l.as_str())),
            "sdf.tmLanguage.json does not highlight the builtin `{}`",
            b.name
        );
    }
}

/// The escapes docs/language.md's row for strings and grammar/sdf.ebnf's STRING list are the
/// lexer's, and each one lexes to its character (issue 37: the docs named two of four).
#[test]
fn the_string_escapes_in_the_docs_are_the_lexers() {
    use sdfc_compiler::lexer::{lex, Token, ESCAPES};
    let escapes: Vec<String> = ESCAPES.iter().map(|(k, _)| format!("\\{k}")).collect();
    let doc = read("docs/language.md");
    let row = doc
        .lines()
        .find(|l| l.starts_with("| String |"))
        .expect("docs/language.md has a row for strings");
    let listed: Vec<&str> = row
        .split('`')
        .skip(1)
        .step_by(2)
        .filter(|t| t.starts_with('\\'))
        .collect();
    assert_eq!(listed, escapes, "docs/language.md: {row}");
    let ebnf = read("grammar/sdf.ebnf");
    let rule: String = ebnf
        .lines()
        .skip_while(|l| !l.trim_start().starts_with("STRING"))
        .take_while(|l| !l.trim_start().starts_with("punct"))
        .collect();
    for e in &escapes {
        assert!(
            rule.contains(&format!("\"{e}\"")) || (e == "\\\"" && rule.contains("\"\\\" '\"'")),
            "grammar/sdf.ebnf's STRING lacks {e}: {rule}"
        );
    }
    for (k, v) in ESCAPES {
        let text = format!("\"a\\{k}b\"");
        let (tokens, diags) = lex(sdfc_compiler::FileId(0), &text);
        assert!(diags.is_empty(), "{text}: {diags:?}");
        assert_eq!(tokens[0].0, Token::Str(format!("a{v}b")), "{text}");
    }
}

/// The language reference's row of each primitive of the table (`compiler/src/prim/`) is the
/// one the table gives: signature, accepted values, and what it is (with "Exact." where its
/// distance is exact).
#[test]
fn the_language_reference_rows_of_the_primitives_are_the_tables() {
    let doc = read("docs/language.md");
    let mut wrong = Vec::new();
    for prim in sdfc_compiler::prim::all() {
        let b = builtins::builtin(prim.name).expect("every primitive is a builtin");
        let sig = b
            .sigs
            .iter()
            .find(|s| matches!(s.imp, builtins::Imp::Prim(p) if std::ptr::eq(p, prim)))
            .expect("every primitive is an overload of its name");
        let exact = match prim.field {
            sdfc_compiler::prim::Field::Exact => " Exact.",
            sdfc_compiler::prim::Field::Unproven => "",
        };
        let row = format!(
            "| `{}` | {} | {}{exact} |",
            builtins::signature(prim.name, sig),
            prim.accepts,
            prim.doc
        );
        if !doc.lines().any(|l| l == row) {
            wrong.push(row);
        }
    }
    assert!(
        wrong.is_empty(),
        "docs/language.md lacks these rows of the primitives' table (write them as shown):\n{}",
        wrong.join("\n")
    );
}

#[test]
fn the_language_reference_lists_every_signature_and_field() {
    let doc = read("docs/language.md");
    for b in BUILTINS.iter() {
        for sig in b.sigs {
            let text = format!("`{}`", builtins::signature(b.name, sig));
            assert!(doc.contains(&text), "docs/language.md does not list {text}");
        }
    }
    let records = builtins::MATERIALS
        .iter()
        .chain(builtins::LIGHTS)
        .chain([&builtins::CAMERA, &builtins::RENDER]);
    for rec in records {
        assert!(
            doc.contains(&format!("`{}`", rec.name)),
            "docs/language.md does not mention `{}`",
            rec.name
        );
        for f in rec.fields {
            assert!(
                doc.contains(&format!("| `{}` |", f.name)),
                "docs/language.md has no row for the field `{}` of `{}`",
                f.name,
                rec.name
            );
        }
    }
}

#[test]
fn every_diagnostic_code_is_documented_with_an_example() {
    let doc = read("docs/diagnostics.md");
    let mut codes = BTreeSet::new();
    common::codes_in(&root().join("compiler/src"), &mut codes);
    assert!(codes.len() > 10, "no diagnostic codes found");
    for code in codes {
        let row = doc.lines().find(|l| l.starts_with(&format!("| {code} |")));
        let row = row.unwrap_or_else(|| panic!("docs/diagnostics.md has no row for {code}"));
        assert!(
            example_produces(row, &code),
            "the examples column of the row of {code} has no example that produces {code}: {row}"
        );
    }
    // Every example file the table names exists.
    for part in doc.split("](../").skip(1) {
        let rel = part.split(')').next().expect("a link");
        assert!(
            root().join(rel).exists(),
            "docs/diagnostics.md links to {rel}, which does not exist"
        );
    }
}

/// Whether the last column of a table row of docs/diagnostics.md holds an example that
/// produces `code`: a linked `.sdf` file (checked from the file system, so imports work), or
/// an inline snippet, checked as written or as a scene statement (`scene { SNIPPET; }`).
fn example_produces(row: &str, code: &str) -> bool {
    let cells: Vec<&str> = row.trim().trim_matches('|').split(" | ").collect();
    let Some(examples) = cells.last() else {
        return false;
    };
    let produces = |diags: &[sdfc_compiler::Diagnostic]| diags.iter().any(|d| d.code == code);
    for part in examples.split("](../").skip(1) {
        let rel = part.split(')').next().unwrap_or("");
        if rel.ends_with(".sdf") {
            if let Ok(loaded) = common::load(&root().join(rel)) {
                if produces(&loaded.diagnostics) {
                    return true;
                }
            }
        }
    }
    let parts: Vec<&str> = examples.split('`').collect();
    for snippet in parts.iter().skip(1).step_by(2) {
        let snippet = snippet.replace("\\|", "|");
        for text in [snippet.clone(), format!("scene {{ {snippet}; }}")] {
            let (_, diags, _) = sdfc_compiler::check_str("example.sdf", &text);
            if produces(&diags) {
                return true;
            }
        }
    }
    false
}

#[test]
fn the_failure_paths_list_every_limit_with_its_default() {
    let doc = read("docs/failures.md");
    for limit in sdfc_compiler::Limit::ALL {
        let row = doc
            .lines()
            .find(|l| l.starts_with(&format!("| `{}` |", limit.name())))
            .unwrap_or_else(|| panic!("docs/failures.md has no row for the limit {limit}"));
        assert!(
            row.contains(&format!("| {} |", limit.default_value())),
            "docs/failures.md gives the limit {limit} another default than {}",
            limit.default_value()
        );
    }
}

/// Constants named `MAX_…` that are not resource limits, each with the file it lives in and
/// why it is not a limit: thresholds between two equivalent ways of generating code,
/// properties of an analysis, the definition of the reference render, test tolerances.
const NOT_LIMITS: &[(&str, &str, &str)] = &[
    (
        "runtime/src/view/session/mod.rs",
        "MAX_SCALE",
        "how far the viewer lowers the resolution of a frame over its time budget",
    ),
    (
        "compiler/src/check/eval/call.rs",
        "MAX_CALL_SITES",
        "how many calls an error's chain of labels shows; the rest is a note",
    ),
    (
        "compiler/src/check/eval.rs",
        "MAX_ERRORS",
        "errors after which checking stops, saying so: more would be fixed after the first",
    ),
    (
        "compiler/src/scene/analysis.rs",
        "MAX_STEP_LIPSCHITZ",
        "the clamp on the step divisor L (docs/analysis.md), a property of the field",
    ),
    (
        "compiler/src/scene/analysis.rs",
        "MAX_WINDOW_CELLS",
        "neighbouring cells a repetition evaluates; beyond, a warning (W0005)",
    ),
    (
        "compiler/src/back/wgsl/analytic.rs",
        "MAX_UNROLLED",
        "unrolled code or a buffer walk: the same image either way",
    ),
    (
        "compiler/src/back/wgsl/mod.rs",
        "MAX_INSTANCES",
        "instances as code or as a buffer walk: the same image either way",
    ),
    (
        "compiler/src/back/ptx/types.rs",
        "MAX_LEAVES",
        "values kept in registers or in memory by the PTX writer",
    ),
    (
        "runtime/src/cpu/reference.rs",
        "MAX_STEPS",
        "the step budget that defines the reference render",
    ),
    (
        "runtime/tests/render/image_conformance.rs",
        "MAX_DIFFERING",
        "a test tolerance",
    ),
    (
        "runtime/tests/render/analytic.rs",
        "MAX_DIFFERING",
        "a test tolerance",
    ),
    (
        "runtime/tests/render/stability.rs",
        "MAX_MISSED",
        "a test tolerance",
    ),
    (
        "runtime/tests/render/stability.rs",
        "MAX_STEP_RATIO",
        "a test tolerance",
    ),
];

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

/// issue 16, item 2: every resource limit lives in `Limits` (compiler/src/limits.rs), with
/// its `--limit` name; a `const MAX_…` anywhere else is a limit that `--limit` cannot raise,
/// unless it is one of [`NOT_LIMITS`].
#[test]
fn no_limit_is_a_constant_outside_limits_rs() {
    let mut files = Vec::new();
    workspace_rust_files(&root(), &mut files);
    assert!(files.len() > 50, "the sources were not found");
    let mut found = Vec::new();
    for path in files {
        let rel = path
            .strip_prefix(root())
            .expect("under the root")
            .to_string_lossy()
            .replace('\\', "/");
        if rel == "compiler/src/limits.rs" {
            continue;
        }
        let text = std::fs::read_to_string(&path).expect("readable");
        for (at, _) in text.match_indices("const MAX_") {
            let name: String = text[at + 6..]
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            // A declaration (the name, then a colon and its type), not a mention.
            let declared = name.len() > 4 && text[at + 6 + name.len()..].starts_with(':');
            if declared && !NOT_LIMITS.iter().any(|(f, n, _)| *f == rel && *n == name) {
                found.push(format!("{rel}: {name}"));
            }
        }
    }
    assert!(
        found.is_empty(),
        "limits outside compiler/src/limits.rs (move them into `Limits`, or list them in \
         NOT_LIMITS with the reason they are not limits): {found:?}"
    );
}
