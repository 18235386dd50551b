//! Checker tests of inputs built to reach the limits early: chains of functions, cycles,
//! literal lists.

use super::{check_str, ok};
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

/// A chain of 1 000 functions stops at `call_depth`: the body of each is checked at its own
/// first call, not from within its caller's (which nested as deep as the chain, and reported
/// the `nesting` limit after seconds), and recursion is looked for in linear time (a search
/// from every function took 130 s for 2 000).
#[test]
fn a_chain_of_functions_stops_at_the_call_depth() {
    let (_, diags, _) = check_str("t.sdf", &chain(1000, "1.0"));
    let errors: Vec<_> = diags.iter().filter(|d| d.is_error()).collect();
    assert_eq!(errors.len(), 1, "{diags:#?}");
    assert_eq!(errors[0].code, "E0507");
    assert_eq!(errors[0].message, "calls nest deeper than 256");
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
    assert_eq!(
        scene.graph.node(scene.root.expect("root")),
        &Node::Sphere { radius: 0.5 }
    );
}

/// A cycle through 100 000 functions is one E0502 at its first function, the chain shown by
/// its ends; the search for it is linear and needs no stack of the chain's depth.
#[test]
fn a_cycle_through_a_hundred_thousand_functions_is_one_error() {
    let (_, diags, _) = check_str("t.sdf", &chain(100_000, "f0()"));
    let errors: Vec<_> = diags.iter().filter(|d| d.is_error()).collect();
    assert_eq!(errors.len(), 1, "{errors:#?}");
    assert_eq!(errors[0].message, "function `f0` calls itself");
    assert!(
        errors[0]
            .notes
            .iter()
            .any(|n| n == "the call chain is f0 → f1 → f2 → f3 → … 99994 more … → f99998 → f99999 → f100000 → f0"),
        "{:?}",
        errors[0].notes
    );
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
    assert_eq!(
        s.graph.node(s.root.expect("root")),
        &Node::Sphere { radius: 100_000.0 }
    );
    // A loop past the limit suggests its count too.
    let (_, diags, _) = check_str("t.sdf", "scene { for i in 0..250000 { sphere(1); } }");
    assert!(
        diags[0].notes[0].ends_with("`--limit objects=250000`"),
        "{diags:#?}"
    );
}
