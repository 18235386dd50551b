//! The repository's rules, checked over its files (a tidy test):
//!
//! - the top-level modules of each crate (`compiler/src`, `lsp/src`, `runtime/src`) depend on each other
//!   without cycles, so that each can be read, and tested, on top of the ones below it; and so
//!   do the modules within each folder of `compiler/src` (siblings, the folder's `mod.rs` aside);
//! - every Rust file starts with a `//!` line saying what it holds;
//! - no resource limit is a `const MAX_…` outside `compiler/src/limits.rs`.
//!
//! Module dependencies:
//! The dependencies are read from the text: every `crate::` path (in `use` declarations and in
//! code, braced groups included) and every `super::` path that climbs to the crate root names
//! the top-level module it reaches. Comments and string literals are skipped; code under
//! `#[cfg(test)]` (unit tests, which may use any part of their crate) is left out.

use crate::scan::{root, tokens, workspace_rust_files, Tok};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

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
