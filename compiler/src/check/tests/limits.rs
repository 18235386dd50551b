//! Checker tests of inputs built to reach the limits early: chains of functions, cycles,
//! literal lists, text, polygons.

use super::{check_str, ok, root};
use crate::scene::Node;

/// A chain of functions each calling the next, deeper than `call_depth`.
fn chain(n: usize, last: &str) -> String {
    let mut src: String = (0..n)
        .map(|i| format!("fn f{i}() -> float {{ f{}() }}\n", i + 1))
        .collect();
    src.push_str(&format!(
        "fn f{n}() -> float {{ {last} }}\nscene {{ sphere(f0()); }}\n"
    ));
    src
}

/// Checks that `src` has one error, E0507 at the default `call_depth`.
fn stops_at_the_call_depth(src: &str) {
    let (_, diags, _) = check_str("t.sdf", src);
    let errors: Vec<_> = diags.iter().filter(|d| d.is_error()).collect();
    assert_eq!(errors.len(), 1, "{errors:#?}");
    assert_eq!(errors[0].code, "E0507");
    assert_eq!(errors[0].message, "calls nest deeper than 256");
}

/// A chain of 1 000 functions stops at `call_depth`: the body of each is checked at its own
/// first call, not from within its caller's (which nested as deep as the chain, and reported
/// the `nesting` limit after seconds).
#[test]
fn a_chain_of_functions_stops_at_the_call_depth() {
    stops_at_the_call_depth(&chain(1000, "1.0"));
    // Within the limits (each call nests its body's expressions) the chain evaluates.
    let mut limits = crate::limits::Limits::default();
    for (limit, value) in [
        (crate::limits::Limit::CallDepth, 2000),
        (crate::limits::Limit::Nesting, 5000),
    ] {
        limits.set(limit, value).expect("a valid limit");
    }
    let mut sources = crate::span::SourceMap::new();
    let entry = sources.add("t.sdf", chain(1000, "0.5"));
    let (scene, diags) =
        crate::front::check_with(&mut sources, entry, &mut crate::check::NoImports, &limits);
    assert!(diags.iter().all(|d| !d.is_error()), "{diags:#?}");
    let scene = scene.expect("a scene");
    assert_eq!(root(&scene), &Node::Sphere { radius: 0.5 });
}

/// A cycle through 100 000 functions is evaluated until it meets `call_depth`: one E0507,
/// soon, with no stack of the chain's depth.
#[test]
fn a_cycle_through_a_hundred_thousand_functions_stops_at_the_call_depth() {
    stops_at_the_call_depth(&chain(100_000, "f0()"));
}

/// A literal list longer than the `objects` limit is refused at its `[` before the file is
/// parsed (its tokens past the limit are counted, not kept), and the note gives the value
/// that would do, the list's length (it gave twice the limit).
#[test]
fn a_literal_list_past_the_objects_limit_is_refused_before_parsing() {
    let items = vec!["1.5"; 100_001].join(", ");
    let src = format!("let xs = [{items}];\nscene {{ sphere(1); }}\n");
    let (scene, diags, _) = check_str("t.sdf", &src);
    assert!(scene.is_none());
    assert_eq!(diags.len(), 1, "{diags:#?}");
    assert_eq!(
        diags[0].message,
        "a list has 100001 elements, more than 100000"
    );
    assert_eq!(diags[0].span().start, 9);
    assert_eq!(
        diags[0].notes,
        ["this limit keeps compilation bounded; raise it with `--limit objects=100001`"]
    );
    // A list of exactly the limit, with a trailing comma, and lists nested in its elements,
    // are within it.
    let items = vec!["[1, 2][0]"; 100_000].join(", ");
    let src = format!("let xs = [{items},];\nscene {{ sphere(len(xs)); }}\n");
    let s = ok(&src);
    assert_eq!(root(&s), &Node::Sphere { radius: 100_000.0 });
    // A loop past the limit suggests its count too.
    let (_, diags, _) = check_str("t.sdf", "scene { for i in 0..250000 { sphere(1); } }");
    assert!(
        diags[0].notes[0].ends_with("`--limit objects=250000`"),
        "{diags:#?}"
    );
}

/// Checks `src` within the default limits but for `changes`.
fn check_within(
    src: &str,
    changes: &[(crate::limits::Limit, u64)],
) -> Vec<crate::diagnostics::Diagnostic> {
    let mut limits = crate::limits::Limits::default();
    for &(limit, value) in changes {
        limits.set(limit, value).expect("a valid limit");
    }
    let mut sources = crate::span::SourceMap::new();
    let entry = sources.add("t.sdf", src.to_string());
    crate::front::check_with(&mut sources, entry, &mut crate::check::NoImports, &limits).1
}

/// `text` of more characters than the `text_chars` limit, in all, is E0507 at the string
/// that crosses it, suggesting the sum, before anything is laid out (a string of a million
/// characters took 1.9 GB).
#[test]
fn text_past_the_text_chars_limit_is_refused_at_its_string() {
    let long = "a".repeat(10_001);
    let src = format!("scene {{ extrude(text(\"{long}\"), 0.1); }}\n");
    let (scene, diags, _) = check_str("t.sdf", &src);
    assert!(scene.is_none());
    assert_eq!(diags.len(), 1, "{diags:#?}");
    assert_eq!(diags[0].code, "E0507");
    assert_eq!(
        diags[0].message,
        "this text has 10001 characters, more than the `text_chars` limit of 10000"
    );
    assert_eq!(diags[0].span().start, 21, "at the string");
    assert_eq!(
        diags[0].notes,
        ["this limit keeps compilation bounded; raise it with `--limit text_chars=10001`"]
    );
    // Characters, not bytes; and the limit bounds the scene's text in all, a loop's too.
    let word = "é".repeat(3_000);
    let src = format!(
        "let w = \"{word}\";\nscene {{ for i in 0..4 {{ extrude(text(w), 0.1).translate(i, 0, 0); }} }}\n"
    );
    let (_, diags, _) = check_str("t.sdf", &src);
    assert_eq!(diags.len(), 1, "{diags:#?}");
    assert_eq!(
        diags[0].message,
        "this text has 3000 characters, and the scene's other text 9000, more than the \
         `text_chars` limit of 10000"
    );
    assert!(diags[0].notes[0].ends_with("`--limit text_chars=12000`"));
    // Raised, both check.
    let diags = check_within(&src, &[(crate::limits::Limit::TextChars, 12_000)]);
    assert!(diags.iter().all(|d| !d.is_error()), "{diags:#?}");
}

/// A polygon's edges are tested for crossings over a grid, each step spent as fuel: 100 000
/// points check in a few steps each (every pair was tested: 74 s), and a polygon whose test
/// needs more steps than the fuel left is E0507 at the call.
#[test]
fn a_polygon_is_tested_for_crossings_within_the_fuel() {
    let circle = |n: usize| {
        let points: Vec<String> = (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                format!("({:.9}, {:.9})", a.cos(), a.sin())
            })
            .collect();
        format!(
            "scene {{ extrude(polygon([{}]), 0.1); }}\n",
            points.join(", ")
        )
    };
    let s = ok(&circle(100_000));
    assert!(s.root.is_some());
    // A star of 10 000 thin points has every edge through its middle: 2·10⁸ pairs there.
    let (_, diags, _) = check_str("t.sdf", "scene { extrude(star(10000, 1, 0.000001), 0.1); }");
    let errors: Vec<_> = diags.iter().filter(|d| d.is_error()).collect();
    assert_eq!(errors.len(), 1, "{diags:#?}");
    assert_eq!(errors[0].code, "E0507");
    assert!(
        errors[0].message.contains("more than 50000000 steps"),
        "{errors:#?}"
    );
    assert_eq!(errors[0].span().start, 16, "at the call");
    // A crossing far along is still found, and named.
    let mut src = circle(20_000);
    let (p, q) = ("(0.999955587, 0.009424638)", "(0.999955587, -0.009424638)");
    assert!(src.contains(p) && src.contains(q));
    src = src
        .replacen(p, "X", 1)
        .replacen(q, p, 1)
        .replacen("X", q, 1);
    let (_, diags, _) = check_str("t.sdf", &src);
    assert!(
        diags[0].message.starts_with("the polygon crosses itself"),
        "{diags:#?}"
    );
}

/// A recursion that errs at every call (the tree example with one `level - 1` turned into
/// `level - 0`, found by the fuzzer: each call overflows its integer seed) stops after
/// 1 000 errors, the last saying so, instead of evaluating 160 000 of them for 11 s.
#[test]
fn evaluation_stops_after_a_thousand_errors() {
    let src = "fn f(level: int, seed: int) -> [shape] {\n\
               \x20 let s = [sphere(1.0 + 0.0 * (seed * 3))];\n\
               \x20 if level == 0 { s } else { s + f(level - 1, seed * 3 + 1) + f(level - 0, seed * 3 + 2) }\n\
               }\n\
               scene { union(f(6, 1)); }\n";
    let (_, diags, _) = check_str("t.sdf", src);
    let errors: Vec<_> = diags.iter().filter(|d| d.is_error()).collect();
    assert_eq!(errors.len(), 1_000, "{:#?}", &diags[..3]);
    let last = errors.last().expect("errors");
    assert!(
        last.notes
            .iter()
            .any(|n| n.contains("checking stopped here, after 1000 errors")),
        "{last:#?}"
    );
}
