//! Robustness of the front end: deep nesting, huge expressions and endless evaluation are
//! errors, not crashes or hangs; every fuzz regression case and thousands of mutated inputs
//! go through the whole front end without a panic.

use sdfc_compiler::{check_str, check_with, lower_within, LowerOptions, NoImports, Rng};

/// The codes of the diagnostics of `text`, but for W0008: these scenes have no lights.
fn codes(text: &str) -> Vec<&'static str> {
    let (_, diags, _) = check_str("t.sdf", text);
    diags
        .iter()
        .map(|d| d.code)
        .filter(|c| *c != "W0008")
        .collect()
}

/// Runs `f` on a thread with a small stack, as a test harness or an editor might.
fn on_small_stack(f: impl FnOnce() + Send + 'static) {
    std::thread::Builder::new()
        .stack_size(2 << 20)
        .spawn(f)
        .expect("thread")
        .join()
        .expect("no panic");
}

#[test]
fn deep_nesting_is_an_error_not_a_crash() {
    on_small_stack(|| {
        let depth = 10_000;
        // Parentheses count towards the limit like any bracket (issue 37, item 4).
        let parens = format!(
            "let x = {}1{};\nscene {{ sphere(); }}",
            "(".repeat(depth),
            ")".repeat(depth)
        );
        assert!(codes(&parens).contains(&"E0507"), "{:?}", codes(&parens));
        let calls = format!(
            "let x = {}1{};\nscene {{ sphere(); }}",
            "abs(".repeat(depth),
            ")".repeat(depth)
        );
        assert!(codes(&calls).contains(&"E0507"), "{:?}", codes(&calls));
        let shapes = format!(
            "scene {{ {}sphere(){}; }}",
            "union(sphere(), ".repeat(depth),
            ")".repeat(depth)
        );
        assert!(codes(&shapes).contains(&"E0507"), "{:?}", codes(&shapes));
    });
}

#[test]
fn long_sums_and_unary_chains_are_errors_not_crashes() {
    on_small_stack(|| {
        // A chain is not nesting, but is bounded at ten times the limit (10 000 links).
        let sum = format!("let x = 1{};\nscene {{ sphere(); }}", " + 1".repeat(20_000));
        assert!(codes(&sum).contains(&"E0507"));
        let neg = format!("let x = {}1;\nscene {{ sphere(); }}", "-".repeat(20_000));
        assert!(codes(&neg).contains(&"E0507"));
    });
}

#[test]
fn endless_evaluation_is_bounded() {
    let start = std::time::Instant::now();
    let loops = "scene { for i in 0..100000 { for j in 0..100000 { let k = i * j; } } sphere(); }";
    assert!(codes(loops).contains(&"E0507"));
    // Functions calling each other twice: memoised, so this is fast and correct.
    let mut chain = String::from("fn f0(x: float) -> float { x + 1 }\n");
    for i in 1..40 {
        chain.push_str(&format!(
            "fn f{i}(x: float) -> float {{ f{}(x) + f{}(x) }}\n",
            i - 1,
            i - 1
        ));
    }
    chain.push_str("let big = f39(1);\nscene { sphere(); }");
    assert!(codes(&chain).is_empty(), "{:?}", codes(&chain));
    assert!(start.elapsed().as_secs() < 30, "took {:?}", start.elapsed());
}

fn corpus() -> Vec<String> {
    let mut out = Vec::new();
    for dir in [
        "../examples",
        "tests/in/ok",
        "tests/in/err",
        "tests/in/fuzz",
    ] {
        // A folder that is missing or empty is a failure: the corpus would silently shrink.
        let entries = std::fs::read_dir(dir).unwrap_or_else(|e| panic!("cannot list {dir}: {e}"));
        let mut paths: Vec<_> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
        paths.sort();
        let before = out.len();
        for p in paths {
            if p.extension().is_some_and(|x| x == "sdf") {
                let t = std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
                // Fuzz inputs need not be UTF-8; the front end sees their lossy text.
                out.push(String::from_utf8_lossy(&t).into_owned());
            }
        }
        assert!(out.len() > before, "no .sdf inputs in {dir}");
    }
    out
}

/// The regression inputs of `tests/in/fuzz` (inputs that once crashed or hung a stage, and
/// tricky ones) each check in bounded time without panicking.
#[test]
fn fuzz_regression_inputs_exist_and_check_quickly() {
    let dir = std::path::Path::new("tests/in/fuzz");
    let mut n = 0;
    for entry in std::fs::read_dir(dir).expect("tests/in/fuzz exists") {
        let path = entry.expect("listable").path();
        if path.extension().is_none_or(|x| x != "sdf") {
            continue;
        }
        let text = String::from_utf8_lossy(&std::fs::read(&path).expect("readable")).into_owned();
        let start = std::time::Instant::now();
        front_end(&text);
        assert!(
            start.elapsed().as_secs_f64() < 5.0,
            "{} took {:?}",
            path.display(),
            start.elapsed()
        );
        n += 1;
    }
    assert!(n >= 5, "only {n} inputs in tests/in/fuzz");
}

/// Checks and lowers `text`, within limits small enough that a mutation of an input near
/// a limit (the exponential expansion of `tests/in/err`) cannot make a slow case.
fn front_end(text: &str) {
    use sdfc_compiler::{Limit, Limits, SourceMap};
    let mut limits = Limits::default();
    limits.set(Limit::Expansion, 200_000).expect("valid");
    let mut sources = SourceMap::new();
    let entry = sources.add("t.sdf", text);
    let (scene, diags) = check_with(&mut sources, entry, &mut NoImports, &limits);
    let _ = sdfc_compiler::diagnostics::render(&diags, &sources, false);
    if let Some(scene) = scene {
        let options = LowerOptions::default();
        if let Ok(lowered) = lower_within(&scene, &options, &limits) {
            let _ = lowered.program.dump();
        }
    }
}

const SNIPPETS: &[&str] = &[
    "(",
    ")",
    "{",
    "}",
    ";",
    ",",
    "@",
    "..",
    "-",
    "/*",
    "\"",
    "1e309",
    "0",
    "-1",
    "deg",
    "sphere(",
    "let ",
    "fn ",
    "scene {",
    "for i in 0..3 {",
    "if true {",
    "} else {",
    ".translate(1, 0, 0)",
    "union(",
    "\u{e9}",
    "\n",
];

#[test]
fn fuzz_regressions_and_mutations_do_not_panic() {
    let corpus = corpus();
    assert!(corpus.len() > 50);
    for text in &corpus {
        front_end(text);
    }
    let mut rng = Rng::new(0x5DFC_2026);
    for _ in 0..3_000 {
        let base = &corpus[rng.below(corpus.len())];
        let mut bytes: Vec<char> = base.chars().collect();
        for _ in 0..1 + rng.below(4) {
            let at = rng.below(bytes.len() + 1);
            match rng.below(3) {
                0 if !bytes.is_empty() => {
                    let end = (at + rng.below(8)).min(bytes.len());
                    bytes.drain(at.min(end)..end);
                }
                1 => {
                    let s = SNIPPETS[rng.below(SNIPPETS.len())];
                    for (i, c) in s.chars().enumerate() {
                        bytes.insert((at + i).min(bytes.len()), c);
                    }
                }
                _ => {
                    let other = &corpus[rng.below(corpus.len())];
                    let chars: Vec<char> = other.chars().collect();
                    let from = rng.below(chars.len());
                    let piece: Vec<char> =
                        chars[from..(from + rng.below(40)).min(chars.len())].to_vec();
                    for (i, c) in piece.into_iter().enumerate() {
                        bytes.insert((at + i).min(bytes.len()), c);
                    }
                }
            }
        }
        let text: String = bytes.into_iter().collect();
        front_end(&text);
    }
}

/// Every recursive construct of the grammar, nested to the `nesting` limit (accepted, or
/// refused for another reason than nesting), past it (E0507), and left unclosed; and lines of
/// a megabyte: no panic, no stack overflow on a small stack (issue 37). The fuzz targets
/// start from seeds of the same shapes within their length bound (`fuzz/seeds/front_end`).
#[test]
fn every_construct_deep_and_long_lines_are_diagnosed_not_crashes() {
    on_small_stack(|| {
        // (prefix, suffix) repeated around `1` in `let x = …;`, or around `sphere()` in a
        // scene statement.
        let values: [(&str, &str); 6] = [
            ("(", ")"),
            ("abs(", ")"),
            ("[", "][0]"),
            ("[for i in 0..1 { ", " }][0]"),
            ("if true { ", " } else { 0 }"),
            ("-(", ")"),
        ];
        let shapes: [(&str, &str); 3] = [
            ("union(sphere(), ", ")"),
            ("sphere().translate(", ", 0, 0)"),
            ("smooth_union(0.1, [", "])"),
        ];
        let statements: [(&str, &str); 2] = [("if true { ", " }"), ("for i in 0..1 { ", " }")];
        let nested = |prefix: &str, suffix: &str, depth: usize, core: &str, closed: bool| {
            let tail = if closed {
                suffix.repeat(depth)
            } else {
                String::new()
            };
            format!("{}{core}{tail}", prefix.repeat(depth))
        };
        for depth in [400, 12_000] {
            for closed in [true, false] {
                let mut texts = Vec::new();
                for (p, s) in values {
                    let x = nested(p, s, depth, "1", closed);
                    texts.push(format!("let x = {x};\nscene {{ sphere(); }}"));
                }
                for (p, s) in shapes {
                    let x = nested(p, s, depth, "sphere()", closed);
                    texts.push(format!("scene {{ {x}; }}"));
                }
                for (p, s) in statements {
                    let x = nested(p, s, depth, "sphere();", closed);
                    texts.push(format!("scene {{ {x} }}"));
                }
                for text in &texts {
                    let found = codes(text);
                    let head: String = text.chars().take(40).collect();
                    if depth > 1_000 {
                        assert!(found.contains(&"E0507"), "{head}… ({depth}): {found:?}");
                    } else if closed {
                        assert!(!found.contains(&"E0507"), "{head}… ({depth}): {found:?}");
                    } else {
                        assert!(!found.is_empty(), "{head}… unclosed: no error");
                    }
                }
            }
        }
        // A megabyte on one line: 50 000 statements, a long string, a long comment.
        let statements = "sphere(0.1).translate(1, 2, 3); ".repeat(32_000);
        assert!(statements.len() > 1_000_000);
        let found = codes(&format!("scene {{ {statements} }}"));
        assert!(!found.contains(&"E0507") || found.len() == 1, "{found:?}");
        let string = format!("let s = \"{}\"; scene {{ sphere(); }}", "a".repeat(1 << 20));
        assert!(codes(&string).is_empty(), "{:?}", codes(&string));
        let comment = format!("/* {} */ scene {{ sphere(); }}", "(".repeat(1 << 20));
        assert!(codes(&comment).is_empty(), "{:?}", codes(&comment));
        let unclosed = format!("let s = \"{}", "(".repeat(1 << 20));
        assert!(
            codes(&unclosed).contains(&"E0002"),
            "{:?}",
            codes(&unclosed)
        );
    });
}
