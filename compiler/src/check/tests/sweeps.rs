//! Checker tests of `sweep` and its paths: what each path accepts, the located error of each
//! bad one with what to write instead, and W0018 where the profile reaches past the path.

use super::{check_str, ok, root};
use crate::diagnostics::Diagnostic;
use crate::scene::Node;

const LIGHT: &str = "light point { position: (0, 5, 0) }\n";

/// The diagnostics of `scene { <shape>; }`.
fn diags(shape: &str) -> Vec<Diagnostic> {
    check_str("t.sdf", &format!("{LIGHT}scene {{ {shape}; }}")).1
}

/// The one error of `shape`, whose label must cover the start of `at` in the source.
fn error(shape: &str, at: &str) -> Diagnostic {
    let src = format!("{LIGHT}scene {{ {shape}; }}");
    let d = diags(shape)
        .into_iter()
        .find(|d| d.is_error())
        .unwrap_or_else(|| panic!("{shape}: no error"));
    let start = src.find(at).expect("in the source");
    let span = d.labels.first().expect("a label").span;
    assert!(
        (span.start as usize) <= start && start < span.end as usize,
        "{shape}: {d:#?} is not at `{at}`"
    );
    d
}

#[test]
fn every_path_makes_a_sweep_node() {
    for path in [
        "polyline([(0, 0, 0), (1, 0, 0), (1, 1, 0)])",
        "helix(0.5, 0.2, 3)",
        "bezier([(0, 0, 0), (0.3, 0.5, 0), (0.7, 0.5, 0), (1, 0, 0)])",
        "arc3((1, 0, 0), (0, 1, 0), (-1, 0, 0))",
    ] {
        let s = ok(&format!("{LIGHT}scene {{ sweep(circle(0.05), {path}); }}"));
        assert!(
            matches!(root(&s), Node::Sweep { folds: false, .. }),
            "{path}"
        );
    }
    // A path is a value: named, passed to a function, swept twice.
    let s = ok(&format!(
        "{LIGHT}let p = helix(0.5, 0.2, 3);\nfn pipe(q: path, r: float) -> shape {{ sweep(circle(r), q) }}\nscene {{ union(pipe(p, 0.05), sweep(rect((0.04, 0.02)), p).translate(0, 1, 0)); }}"
    ));
    assert!(s.root.is_some());
    // Paths in a list, swept in a comprehension.
    let s = ok(&format!(
        "{LIGHT}let ps: [path] = [helix(0.5, 0.2, 3), arc3((0, 0, 0), (1, 1, 0), (2, 0, 0))];\nscene {{ union([for i in 0..len(ps) {{ sweep(circle(0.05), ps[i]) }}]); }}"
    ));
    assert!(matches!(root(&s), Node::Combine { children, .. } if children.len() == 2));
}

#[test]
fn bad_paths_are_located_errors_that_say_what_to_write() {
    // Each shape, where its error is, and what the message says.
    let cases: &[(&str, &str, &[&str])] = &[
        (
            "sweep(circle(0.1), polyline([(0, 0, 0)]))",
            "polyline([(0, 0, 0)])",
            &["at least 2 points"],
        ),
        (
            "sweep(circle(0.1), polyline([(0, 0, 0), (1, 0, 0), (1, 0, 0)]))",
            "polyline(",
            &["points 1 and 2"],
        ),
        (
            "sweep(circle(0.1), polyline([(0, 0, 0), (1, 0, 0), (0.5, 0, 0)]))",
            "polyline(",
            &["turns straight back at point 1"],
        ),
        // A Bézier path says how many control points it needs, near the count given.
        (
            "sweep(circle(0.1), bezier([(0, 0, 0), (1, 0, 0), (1, 1, 0), (2, 1, 0), (3, 1, 0)]))",
            "bezier(",
            &["3k + 1", "has 5", "give 4 or 7"],
        ),
        (
            "sweep(circle(0.1), bezier([(0, 0, 0), (1, 0, 0)]))",
            "bezier(",
            &["give 4"],
        ),
        (
            "sweep(circle(0.1), bezier([(0, 0, 0), (0, 0, 0), (1, 1, 0), (2, 1, 0)]))",
            "bezier(",
            &["control point 1"],
        ),
        // A degenerate helix: each number out of range is refused at its argument.
        (
            "sweep(circle(0.1), helix(0, 0.2, 3))",
            "0, 0.2",
            &["greater than 0"],
        ),
        (
            "sweep(circle(0.1), helix(0.5, 0, 3))",
            "0, 3",
            &["greater than 0"],
        ),
        (
            "sweep(circle(0.1), helix(0.5, 0.2, -1))",
            "-1",
            &["greater than 0"],
        ),
        (
            "sweep(circle(0.1), arc3((0, 0, 0), (1, 1, 1), (2, 2, 2)))",
            "arc3(",
            &["one line", "polyline"],
        ),
        // A profile with no finite extent cannot be swept.
        (
            "sweep(profile { p.x }, helix(0.5, 0.2, 3))",
            "sweep(",
            &["no finite extent"],
        ),
    ];
    for (shape, at, says) in cases {
        let d = error(shape, at);
        for s in *says {
            assert!(d.message.contains(s), "{s}: {d:#?}");
        }
    }
}

#[test]
fn a_profile_wider_than_the_path_allows_is_warned_about_with_the_radius() {
    // helix(0.5, 2, 3) bends with a radius of about 0.70 (r + (pitch/2π)²/r); the turns of
    // helix(0.5, 0.2, 3) are about 0.2 apart.
    let warned = |shape: &str| {
        diags(shape)
            .into_iter()
            .filter(|d| d.code == "W0018")
            .collect::<Vec<_>>()
    };
    let w = warned("sweep(rect((0.8, 0.05)), helix(0.5, 2, 3))");
    assert_eq!(w.len(), 1, "{w:#?}");
    assert!(
        w[0].message.contains("reaches 0.80")
            && w[0].message.contains("bends with a radius of 0.70"),
        "{:#?}",
        w[0]
    );
    let w = warned("sweep(rect((0.05, 0.2)), helix(0.5, 0.2, 3))");
    assert!(w[0].message.contains("comes within"), "{:#?}", w[0]);
    // Within reach, or a disc (whose sweep is a union of balls, exact however wide): none.
    assert!(warned("sweep(rect((0.05, 0.05)), helix(0.5, 0.3, 3))").is_empty());
    assert!(warned("sweep(circle(0.3), helix(0.5, 0.2, 3))").is_empty());
    // The folded sweep is not proven: `check` says so.
    let s = ok(&format!(
        "{LIGHT}scene {{ sweep(rect((0.8, 0.05)), helix(0.5, 2, 3)); }}"
    ));
    let a = crate::scene::analysis::analyse(&s);
    assert_eq!(
        a.root().expect("root").facts.exactness,
        crate::scene::Exactness::Approximate
    );
}
