//! Lofts and screws: sections kept, helices followed, bounds held, bad ones as located errors;
//! a chamfered plate under culling; a left-handed screw.

use super::{f, located_error, point, program, same, within_l};
use crate::lower::{lower, lower_with, LowerOptions};
use crate::rng::Rng;

#[test]
fn lofts_between_profiles_keep_their_sections_and_their_bound() {
    // Concentric circles of radii 0.5 and 0.3 over the height 1: at each height the circle
    // of the mixed radius (the frustum's section).
    let (p, l) = program("loft(circle(0.5), circle(0.3), 1)");
    // spread = 0.5·√2 + 0.3·√2; L = √(1 + (spread / 1)²).
    let spread = 0.8 * 2f64.sqrt();
    assert!((l - spread.hypot(1.0)).abs() < 1e-12, "L {l}");
    let mut rng = Rng::new(5);
    let mut signs = 0;
    for _ in 0..3000 {
        let x = point(&mut rng, 1.0);
        let t = (x[2] + 0.5).clamp(0.0, 1.0);
        let inside = x[0].hypot(x[1]) < 0.5 - 0.2 * t && x[2].abs() < 0.5;
        let d = f(&p, x);
        if d.abs() > 1e-9 {
            assert_eq!(d < 0.0, inside, "sign at {x:?} ({d})");
            signs += 1;
        }
    }
    assert!(signs > 2900);
    // At the ends the sections are the profiles themselves.
    for (z, shape) in [(-0.5, "circle(0.5)"), (0.5, "circle(0.3)")] {
        let (q, _) = program(&format!("extrude({shape}, 100)"));
        for _ in 0..200 {
            let x = point(&mut rng, 1.0);
            let inner = [x[0], x[1], z * (1.0 - 1e-12)];
            let (a, b) = (f(&p, inner), f(&q, [x[0], x[1], 0.0]));
            assert!(b.abs() < 1e-9 || (a < 0.0) == (b < 0.0), "{z}: {a} {b}");
        }
    }
    // Sampled slopes stay within the recorded L, and exceed 1 where the sections move.
    within_l("loft(circle(0.5), circle(0.3), 1)", 1.5);
    let (s, _) = within_l(
        "loft(rect((0.6, 0.3)), circle(0.2).translate(0.5, 0.4), 0.5)",
        1.5,
    );
    assert!(s > 1.05, "slope {s}");
    within_l("loft(star(5, 1, 0.5), regular_polygon(6, 0.6), 0.7)", 1.5);
}

/// The screw of `rect((0.05, 0.1)).translate(0.5, 0)`, pitch 0.4, height 1.6, inside: the
/// point's radius within 0.05 of 0.5 and its height, less 0.4·φ/2π (φ about +y), within 0.1
/// of a multiple of 0.4.
fn in_screw(x: [f64; 3]) -> bool {
    let r = x[0].hypot(x[2]);
    let phi = (-x[2]).atan2(x[0]);
    let v = x[1] - 0.4 * phi / std::f64::consts::TAU;
    let w = v - 0.4 * (v / 0.4).round();
    (r - 0.5).abs() < 0.05 && w.abs() < 0.1 && x[1].abs() < 0.8
}

#[test]
fn screws_follow_their_helix_within_their_bound() {
    let shape = "screw(rect((0.05, 0.1)).translate(0.5, 0), 0.4, 1.6)";
    let (p, l) = program(shape);
    // L = √(1 + (pitch / 2π / (inner / 2))²), inner = 0.45.
    let want = (0.4 / std::f64::consts::TAU / 0.225).hypot(1.0);
    assert!((l - want).abs() < 1e-12, "L {l}, not {want}");
    let mut rng = Rng::new(11);
    let mut inside = 0;
    for i in 0..4000 {
        // Half the points near the thread.
        let x = if i % 2 == 0 {
            let t = rng.range(-std::f64::consts::PI, std::f64::consts::PI);
            let r = rng.range(0.4, 0.6);
            [r * t.cos(), rng.range(-0.9, 0.9), -r * t.sin()]
        } else {
            point(&mut rng, 1.0)
        };
        let d = f(&p, x);
        if d.abs() > 1e-9 {
            assert_eq!(d < 0.0, in_screw(x), "sign at {x:?} ({d})");
            inside += usize::from(d < 0.0);
        }
    }
    assert!(inside > 200, "{inside} inside");
    let (s, _) = within_l(shape, 1.0);
    assert!(s > 1.0 + 1e-3, "slope {s}");
    // A triangular thread of a bolt, and a fine one near the axis.
    within_l(
        "screw(polygon([(0.3, -0.05), (0.4, 0), (0.3, 0.05)]), 0.1, 1)",
        0.6,
    );
    within_l("screw(circle(0.02).translate(0.05, 0), 0.05, 0.5)", 0.2);
}

#[test]
fn bad_lofts_and_screws_are_located_errors() {
    for (src, says, at) in [
        ("loft(circle(1), circle(0.5), 0)", "greater than 0", "0)"),
        (
            "loft(sphere(1), circle(0.5), 1)",
            "expects a `profile`",
            "sphere",
        ),
        (
            "screw(circle(0.1).translate(0.5, 0), 0, 1)",
            "greater than 0",
            "0, 1",
        ),
        (
            "screw(circle(0.1).translate(0.5, 0), -1, 1)",
            "greater than 0",
            "-1",
        ),
        ("screw(rect(0.1), 0.5, 1)", "x > 0", "screw"),
        (
            "extrude(bezier((0, 0), (1, 1), (2, 2)), 1)",
            "segment2",
            "bezier",
        ),
        (
            "extrude(arc(1, 400deg), 1)",
            "between 0deg and 360deg",
            "400deg",
        ),
        (
            "screw(circle(0.3).translate(0.5, 0), 0.5, 1)",
            "half the pitch",
            "screw",
        ),
    ] {
        located_error(src, says, at);
    }
}

/// A plate chamfered by lofts to its inset, as examples/bracket2d.sdf makes one: where the
/// union's cheapest child (a loft, divided by its L and raised to the distance to its
/// volume) gave the union's upper bound, a tie with its own guard once skipped every child
/// (the field 10³⁰ above the plate). Culling keeps the field.
#[test]
fn a_chamfered_plate_keeps_its_field_under_culling() {
    let src = "let l = polygon([(-0.9, -0.6), (0.9, -0.6), (0.9, -0.3), (-0.3, -0.3), (-0.3, 0.7), (-0.9, 0.7)]);
let holes = union(circle(0.1).translate(0.6, -0.45), circle(0.1).translate(-0.6, -0.45), circle(0.1).translate(-0.6, 0.4));
let o = subtract(offset(l, 0.08), holes);
scene { union(extrude(o, 0.2), loft(o, offset(o, -0.05), 0.05).translate(0, 0, 0.125),
              loft(offset(o, -0.05), o, 0.05).translate(0, 0, -0.125)).rotate_x(90deg); }";
    let scene = crate::front::check_str("t.sdf", src).0.expect("scene");
    let culled = lower(&scene);
    // Over the long arm, where the tie was.
    assert!(f(&culled, [0.5, 0.3, -0.45]) < 1.0);
    let options = LowerOptions {
        cull: false,
        ..LowerOptions::default()
    };
    let whole = lower_with(&scene, &options);
    let mut rng = Rng::new(17);
    for i in 0..3000 {
        // Half the points over the plate.
        let mut x = point(&mut rng, 1.2);
        if i % 2 == 0 {
            x[1] = rng.range(0.16, 0.5);
        }
        let (a, b) = (f(&culled, x), f(&whole, x));
        assert!(a.abs() < 10.0, "{x:?}: {a}");
        if b < 0.2 {
            assert!((a - b).abs() < 1e-12, "{x:?}: {a}, not {b}");
        }
    }
}

#[test]
fn a_left_handed_screw_is_the_right_handed_one_reflected() {
    let right = "screw(rect((0.05, 0.1)).translate(0.5, 0), 0.4, 1.6)";
    let left = "screw(rect((0.05, 0.1)).translate(0.5, 0), 0.4, 1.6, hand: \"left\")";
    same(left, &format!("{right}.reflect((1, 0, 0))"));
    let (p, _) = program(left);
    let mut rng = Rng::new(12);
    let mut inside = 0;
    for _ in 0..3000 {
        let t = rng.range(-std::f64::consts::PI, std::f64::consts::PI);
        let r = rng.range(0.4, 0.6);
        let x = [r * t.cos(), rng.range(-0.9, 0.9), -r * t.sin()];
        let d = f(&p, x);
        if d.abs() > 1e-9 {
            // The left-handed thread at x is the right-handed one at x's mirror image.
            assert_eq!(
                d < 0.0,
                in_screw([-x[0], x[1], x[2]]),
                "sign at {x:?} ({d})"
            );
            inside += usize::from(d < 0.0);
        }
    }
    assert!(inside > 200, "{inside} inside");
    // The two hands differ (a chevron would be symmetric).
    let (r, _) = program(right);
    let differ = (0..200)
        .map(|i| {
            let t = f64::from(i) * 0.031;
            [0.5 * t.cos(), 0.05, -0.5 * t.sin()]
        })
        .filter(|x| (f(&r, *x) < 0.0) != (f(&p, *x) < 0.0))
        .count();
    assert!(differ > 20, "{differ}");
}
