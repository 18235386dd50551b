//! Checker tests of hulls: `hull` of points, Minkowski sums with a ball, and the hulls of
//! balls and of parallel cylinders.

use super::{check_str, codes, ok, root};
use crate::scene::Node;

#[test]
fn hulls_of_points_and_minkowski_with_a_ball() {
    let light = "light point { position: (0, 5, 0) }\n";
    let s = ok(&format!(
        "{light}scene {{ hull([for i in 0..8 {{ (hash(i), hash(i + 8), hash(i + 16)) }}]); }}"
    ));
    let Node::Prim { prim, args } = root(&s) else {
        panic!("not a primitive")
    };
    assert_eq!((prim.name, args.list(0).len(), args.f(1)), ("hull", 8, 0.0));
    // Points in one plane have no volume without a radius: said at the call, with the fix.
    let (_, diags, _) = check_str(
        "t.sdf",
        &format!("{light}scene {{ hull([(0, 0, 0), (1, 0, 0), (0, 0, 1), (1, 0, 1)]); }}"),
    );
    let d = diags.iter().find(|d| d.is_error()).expect("an error");
    assert!(
        d.message.contains("one plane") && d.message.contains("radius"),
        "{d:#?}"
    );
    assert_eq!(
        codes(&format!(
            "{light}scene {{ hull([(0, 0, 0), (1, 0, 0), (0, 0, 1)], radius: 0.1); }}"
        )),
        Vec::<&str>::new()
    );
    // minkowski with a ball is the rounding; with anything else it says what it takes.
    let s = ok(&format!(
        "{light}scene {{ minkowski(box((1, 1, 1)), sphere(0.2)); }}"
    ));
    assert!(matches!(
        root(&s),
        Node::Round { radius, .. } if *radius == 0.2
    ));
    let (_, diags, _) = check_str(
        "t.sdf",
        &format!("{light}scene {{ minkowski(box((1, 1, 1)), box((0.1, 0.1, 0.1))); }}"),
    );
    assert!(
        diags
            .iter()
            .any(|d| d.is_error() && d.message.contains("round(r)")),
        "{diags:#?}"
    );
}

#[test]
fn hulls_of_balls_and_of_parallel_cylinders() {
    let light = "light point { position: (0, 5, 0) }\n";
    let balls = |src: &str| {
        let s = ok(&format!("{light}scene {{ {src}; }}"));
        let Node::Prim { prim, args } = root(&s) else {
            panic!("{src}: not a primitive")
        };
        assert_eq!(prim.params[0].name, "balls", "{src}");
        let list = args.list(0);
        list.chunks_exact(2)
            .map(|e| [e[0][0], e[0][1], e[0][2], e[1][0]])
            .collect::<Vec<_>>()
    };
    // Both forms; balls placed, turned, scaled and rounded; a capsule's two ends.
    let got = balls("hull(sphere(1), sphere(0.5).translate(3, 0, 0).scale(2))");
    assert_eq!(got, vec![[0.0, 0.0, 0.0, 1.0], [6.0, 0.0, 0.0, 1.0]]);
    let got = balls("hull([capsule(0.25, 2).rotate_z(90deg).round(0.25)])");
    assert_eq!(got.len(), 2);
    for (b, x) in got.iter().zip([1.0, -1.0]) {
        assert!(
            (b[0] - x).abs() < 1e-12 && b[1].abs() < 1e-12 && b[3] == 0.5,
            "{got:?}"
        );
    }
    // A union, a hull of points with a radius and a hull of balls are balls too; a ball
    // inside another stays (the field drops it).
    let got = balls(
        "hull(union(sphere(1), sphere(0.2)), hull([(0, 2, 0), (0, 3, 0)], radius: 0.1), hull(sphere(0.3).translate(0, 0, 4), segment((1, 0, 0), (2, 0, 0), 0.2)))",
    );
    assert_eq!(got.len(), 7);
    // Parallel cylinders of one span: the extruded hull of their circles, turned and moved.
    let s = ok(&format!(
        "{light}scene {{ hull([for i in 0..3 {{ cylinder(0.2 + 0.1 * i, 1).translate(i, 0, i * i) }}]); }}"
    ));
    let Node::Translate { child, .. } = root(&s) else {
        panic!("not moved")
    };
    let Node::Rotate { child, .. } = s.graph.node(*child) else {
        panic!("not turned")
    };
    assert!(matches!(
        s.graph.node(*child),
        Node::Extrude { half_height, .. } if *half_height == 0.5
    ));
    // What is refused, and said.
    let error = |src: &str| {
        let (_, diags, _) = check_str("t.sdf", &format!("{light}scene {{ {src}; }}"));
        let d = diags.iter().find(|d| d.is_error()).expect("an error");
        d.message.clone()
    };
    for (src, says) in [
        (
            "hull(sphere(1), box(0.5))",
            &["shape 2 of 2 is a `box`", "hull([points"][..],
        ),
        (
            "hull(sphere(1), cylinder(0.5, 1))",
            &["balls and cylinders together"],
        ),
        (
            "hull(cylinder(0.5, 1), cylinder(0.5, 1).rotate_x(10deg))",
            &["cylinder 2 is turned"],
        ),
        (
            "hull(cylinder(0.5, 1), cylinder(0.5, 1).translate(1, 0.5, 0))",
            &["moved along its axis"],
        ),
        (
            "hull(cylinder(0.5, 1), cylinder(0.5, 2).translate(1, 0, 0))",
            &["another height"],
        ),
        (
            "hull(cylinder(0.5, 1).round(0.1), sphere(1))",
            &["rounded cylinder"],
        ),
        ("hull([for i in 0..0 { sphere(1) }])", &["empty list"]),
        (
            "hull([for i in 0..65 { sphere(1).translate(i, 0, 0) }])",
            &["takes 65 balls", "hull_shapes=65"],
        ),
    ] {
        let m = error(src);
        for s in says {
            assert!(m.contains(s), "{src}: {m}");
        }
    }
    // A union of itself doubling 40 times is counted, not walked, and refused.
    let shared = format!(
        "let s0 = sphere(1);\n{}",
        (1..=40)
            .map(|i| format!(
                "let s{i} = union(s{}, s{}.translate(1, 0, 0));\n",
                i - 1,
                i - 1
            ))
            .collect::<String>()
    );
    let (_, diags, _) = check_str("t.sdf", &format!("{light}{shared}scene {{ hull(s40); }}"));
    assert!(
        diags
            .iter()
            .any(|d| d.is_error() && d.message.contains("takes 1099511627776 balls")),
        "{diags:#?}"
    );
}
