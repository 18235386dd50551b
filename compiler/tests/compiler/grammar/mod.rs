//! The grammar test: `grammar/sdf.ebnf` is read, checked for undefined, unused and misspelt
//! rules and terminals, and used as a recogniser over the lexer's tokens: every example and
//! every file of `tests/in/ok/` must be a sentence of `file`, broken inputs must not be, and on
//! `tests/in/err/` the grammar and the parser must agree. (The editor grammar and the
//! reference in `docs/` are checked against the compiler in `reference.rs`.)
//!
//! The recogniser is a memoised backtracking one that returns every position where a rule can
//! end, so it accepts exactly the sentences of the EBNF read as a context-free grammar (which
//! must not be left-recursive).

use sdfc_compiler::{
    lexer::{lex, Token},
    FileId,
};
use std::collections::{BTreeSet, HashMap, HashSet};
use std::path::{Path, PathBuf};

mod ebnf;
mod recognise;

use ebnf::*;
use recognise::*;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn grammar_text() -> String {
    let path = root().join("grammar/sdf.ebnf");
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
}

fn grammar() -> Grammar {
    read_grammar(&grammar_text())
}

/// The leaves of `e` that `pick` takes (rule names, literals or token classes), in order.
fn leaves(e: &Ebnf, pick: fn(&Ebnf) -> Option<&String>, out: &mut Vec<String>) {
    match e {
        Ebnf::Seq(xs) | Ebnf::Alt(xs) => xs.iter().for_each(|x| leaves(x, pick, out)),
        Ebnf::Rep(x) | Ebnf::Opt(x) => leaves(x, pick, out),
        leaf => out.extend(pick(leaf).cloned()),
    }
}

fn refs(e: &Ebnf, out: &mut Vec<String>) {
    leaves(
        e,
        |e| if let Ebnf::Rule(n) = e { Some(n) } else { None },
        out,
    );
}

fn lits(e: &Ebnf, out: &mut Vec<String>) {
    leaves(
        e,
        |e| if let Ebnf::Lit(s) = e { Some(s) } else { None },
        out,
    );
}

fn classes(e: &Ebnf, out: &mut Vec<String>) {
    leaves(
        e,
        |e| {
            if let Ebnf::Class(c) = e {
                Some(c)
            } else {
                None
            }
        },
        out,
    );
}

/// The backticked snippets of the comments of a Rust source file, with the comment line
/// each was found on (without its `//`, `///` or `//!`).
fn cited(source: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for line in source
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with("//"))
    {
        let text = line.trim_start_matches(['/', '!']).trim();
        let parts: Vec<&str> = text.split('`').collect();
        out.extend(
            parts
                .iter()
                .skip(1)
                .step_by(2)
                .map(|s| (s.to_string(), text.to_string())),
        );
    }
    out
}

fn is_name(s: &str) -> bool {
    s.chars().next().is_some_and(|c| c.is_ascii_lowercase())
        && s.chars().all(|c| c.is_ascii_lowercase() || c == '_')
}

/// The `.sdf` files under `dir`, recursively, in a stable order.
fn sdf_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return out;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            out.extend(sdf_files(&path));
        } else if path.extension().is_some_and(|e| e == "sdf") {
            out.push(path);
        }
    }
    out.sort();
    out
}

// ---- Tests ----

#[test]
fn every_rule_used_is_defined_once_and_reachable() {
    let g = grammar();
    assert!(g.get("file").is_some(), "the start rule `file` is missing");
    let mut seen = HashSet::new();
    for (name, _) in &g.rules {
        assert!(seen.insert(name.clone()), "rule `{name}` is defined twice");
    }
    for (name, rhs) in &g.rules {
        let mut used = Vec::new();
        refs(rhs, &mut used);
        for u in used {
            assert!(
                g.get(&u).is_some(),
                "rule `{name}` uses `{u}`, which is not defined"
            );
        }
    }
    // Every rule is reachable from `file`.
    let mut reached = HashSet::from(["file".to_string()]);
    let mut stack = vec!["file".to_string()];
    while let Some(n) = stack.pop() {
        let mut used = Vec::new();
        refs(&g.rules[g.get(&n).expect("defined")].1, &mut used);
        stack.extend(used.into_iter().filter(|u| reached.insert(u.clone())));
    }
    for (name, _) in &g.rules {
        assert!(
            reached.contains(name),
            "rule `{name}` is not reachable from `file`"
        );
    }
}

#[test]
fn every_terminal_is_one_token_of_the_lexer() {
    let g = grammar();
    for (name, rhs) in &g.rules {
        let mut ts = Vec::new();
        lits(rhs, &mut ts);
        for t in ts {
            let (tokens, diags) = lex(FileId(0), &t);
            assert!(
                diags.is_empty() && tokens.len() == 1,
                "rule `{name}`: \"{t}\" is not one token"
            );
            let is_lit = matches!(terminal(&tokens[0].0), Sym::Lit(s) if s == t);
            assert!(
                is_lit,
                "rule `{name}`: \"{t}\" is a token class, not a quoted terminal"
            );
        }
        let mut cs = Vec::new();
        classes(rhs, &mut cs);
        for c in cs {
            assert!(
                CLASSES.contains(&c.as_str()),
                "rule `{name}`: unknown token class {c}"
            );
        }
    }
}

#[test]
fn rules_cited_by_the_parser_and_lexer_exist() {
    let g = grammar();
    let text = grammar_text();
    let src = root().join("compiler/src/syntax");
    let parser = std::fs::read_to_string(src.join("parser.rs")).expect("parser.rs");
    for (snippet, line) in cited(&parser) {
        // A rule is cited as `name = ...`, or by its bare name at the start of a doc line.
        let (lhs, rhs) = match snippet.split_once(" = ") {
            Some((l, r)) => (l.trim(), r),
            None if line.starts_with(&format!("`{snippet}`")) => (snippet.as_str(), ""),
            None => continue,
        };
        if !is_name(lhs) {
            continue;
        }
        assert!(
            g.get(lhs).is_some(),
            "parser.rs cites rule `{lhs}`, which sdf.ebnf does not define"
        );
        // Every rule name on the right, outside quotes.
        let unquoted: String = rhs.split('"').step_by(2).collect::<Vec<_>>().join(" ");
        for word in unquoted
            .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .filter(|w| is_name(w))
        {
            assert!(
                g.get(word).is_some(),
                "parser.rs cites `{snippet}`; `{word}` is not a rule of sdf.ebnf"
            );
        }
    }
    // The lexer cites the lexical rules, which live in the comment at the top of sdf.ebnf.
    let lexer = std::fs::read_to_string(src.join("lexer.rs")).expect("lexer.rs");
    for (name, _) in cited(&lexer)
        .iter()
        .filter(|(s, line)| is_name(s) && line.starts_with("Grammar rules"))
    {
        let defined = text.lines().any(|l| {
            l.trim_start()
                .strip_prefix(name.as_str())
                .is_some_and(|r| r.trim_start().starts_with('='))
        });
        assert!(
            defined,
            "lexer.rs cites lexical rule `{name}`, which sdf.ebnf does not define"
        );
    }
}

#[test]
fn examples_and_valid_files_are_sentences_of_the_grammar() {
    let mut files = sdf_files(&root().join("examples"));
    let ok = sdf_files(&root().join("compiler/tests/in/ok"));
    assert!(!ok.is_empty(), "tests/in/ok has no .sdf files");
    files.extend(ok);
    with_stack(move || {
        let g = grammar();
        let mut failures = Vec::new();
        for path in &files {
            let text = std::fs::read_to_string(path).expect("readable");
            if let Err(why) = recognise(&g, "file", &text) {
                failures.push(format!("{}: {why}", path.display()));
            }
            // The parser agrees: no lexical or syntax errors.
            let (_, diags) = sdfc_compiler::parse(FileId(0), &text);
            if let Some(d) = diags.first() {
                failures.push(format!(
                    "{}: the parser reports {} {}",
                    path.display(),
                    d.code,
                    d.message
                ));
            }
        }
        assert!(failures.is_empty(), "{}", failures.join("\n"));
    });
}

#[test]
fn small_valid_inputs_are_recognised() {
    let inputs = [
        "",
        "import \"lib/shapes.sdf\";",
        "let a: float = -1 + 2 * 3 % 4 / 5 - !true.x;",
        "let v = (1, 2, 3,);",
        "let b = a < 1 == c >= 2 && d != e || !f;",
        "let s = sphere(radius: 1,).translate(0, 1, 0) @ red @ blue;",
        "let c = if a { let x = 1; x } else if b { 2 } else { 3 };",
        "fn f(a: float, b: vec3 = (0, 1, 0),) -> shape { sphere(a) }",
        "fn g() -> float { 1 }",
        "material m = phong { color: (1, 0, 0), ior: 1.5, };",
        "material m = checker {}",
        "camera { fov: 45deg } render { aa: 2 }; light point { position: (0, 5, 0) }",
        "scene { let k = 2; for i in 0..k { for j in i..(k + 1) { box(); } } sphere(); };",
        "scene {}",
    ];
    with_stack(move || {
        let g = grammar();
        for text in inputs {
            assert_eq!(recognise(&g, "file", text), Ok(()), "{text}");
            let (_, diags) = sdfc_compiler::parse(FileId(0), text);
            assert!(diags.is_empty(), "the parser rejects {text:?}: {diags:?}");
        }
    });
}

#[test]
fn the_grammar_and_the_parser_agree_on_the_error_files() {
    // A file of `tests/in/err` is a sentence of the grammar exactly when the lexer and the
    // parser find nothing wrong with it (its mistake is found by the checker).
    let files = sdf_files(&root().join("compiler/tests/in/err"));
    assert!(!files.is_empty(), "tests/in/err has no .sdf files");
    with_stack(move || {
        let g = grammar();
        let mut disagreements = Vec::new();
        for path in &files {
            let text = std::fs::read_to_string(path).expect("readable");
            let grammar_ok = recognise(&g, "file", &text);
            let (_, diags) = sdfc_compiler::parse(FileId(0), &text);
            if grammar_ok.is_ok() != diags.is_empty() {
                let parser = diags.first().map_or("nothing".to_string(), |d| {
                    format!("{} {}", d.code, d.message)
                });
                disagreements.push(format!(
                    "{}: grammar {grammar_ok:?}, parser reports {parser}",
                    path.display()
                ));
            }
        }
        assert!(disagreements.is_empty(), "{}", disagreements.join("\n"));
    });
}

#[test]
fn broken_inputs_are_rejected() {
    let inputs = [
        "scene { sphere(1) }",                     // missing `;` after a statement
        "let = 1;",                                // missing name
        "let x = 1",                               // missing `;` at the end
        "let x = 1 +;",                            // missing operand
        "let x = (1, 2;",                          // unclosed tuple
        "let x = (,);",                            // empty tuple
        "let x = .5;",                             // a float needs a leading digit
        "let x = if a { 1 };",                     // `if` without `else`
        "let x = if a { 1 } else { let y = 2; };", // body without a value
        "let x = f(a: );",                         // named argument without a value
        "let x = 1 @ ;",                           // `@` without a material
        "let x = a..b;",                           // a range outside `for`
        "fn f(a) -> shape { a }",                  // parameter without a type
        "fn f(a: float) { a }",                    // missing return type
        "fn f(a: float) -> shape a",               // body without braces
        "material m phong { }",                    // missing `=`
        "material m = phong { color: (1, 0, 0) ior: 2 }", // missing `,` between fields
        "light { position: (0, 1, 0) }",           // light without a kind
        "camera ( fov: 45deg )",                   // fields in parentheses
        "import shapes;",                          // import without quotes
        "scene { for i in 0..3 sphere(); }",       // loop body without braces
        "scene { for i 0..3 { sphere(); } }",      // missing `in`
        "scene sphere();",                         // scene without braces
        "sphere();",                               // a statement outside `scene`
        "scene { sphere(1); ",                     // unclosed scene
    ];
    with_stack(move || {
        let g = grammar();
        for text in inputs {
            assert!(
                recognise(&g, "file", text).is_err(),
                "the grammar accepts the broken input {text:?}"
            );
            let (_, diags) = sdfc_compiler::parse(FileId(0), text);
            assert!(
                !diags.is_empty(),
                "the parser accepts the broken input {text:?}"
            );
        }
    });
}

#[test]
fn the_ebnf_reader_reads_its_own_notation() {
    let g = read_grammar("(* c *) a = \"x\" { b | [ C ] } ( \"y\" ) ; b = a ;");
    assert_eq!(g.rules.len(), 2);
    assert_eq!(
        g.rules[0].1,
        Ebnf::Seq(vec![
            Ebnf::Lit("x".into()),
            Ebnf::Rep(Box::new(Ebnf::Alt(vec![
                Ebnf::Rule("b".into()),
                Ebnf::Opt(Box::new(Ebnf::Class("C".into())))
            ]))),
            Ebnf::Lit("y".into()),
        ])
    );
}
