//! The blends of `blends.rs` and the features: sampled slopes within the recorded L, the
//! formulas of chamfers and features, and hg_sdf's columns evaluated everywhere.

use super::{f, point, program, slope};
use crate::rng::Rng;

/// The operands of the blend tests: two boxes crossing at right angles and a sphere.
const A: &str = "box((0.8, 0.3, 0.5))";
const B: &str = "sphere(0.5).translate(0.3, 0.3, 0)";

#[test]
fn blends_stay_within_their_recorded_lipschitz_bound() {
    let mut rng = Rng::new(5);
    let mut shapes = Vec::new();
    for op in ["smooth_union", "smooth_intersect", "smooth_subtract"] {
        for v in ["chamfer", "round", "stairs", "columns"] {
            for steps in [1, 2, 5] {
                shapes.push(format!(
                    "{op}(0.3, {A}, {B}, variant: \"{v}\", steps: {steps})"
                ));
            }
        }
    }
    for feature in [
        "engrave(A, B, 0.1)",
        "groove(A, B, 0.2, 0.1)",
        "tongue(A, B, 0.2, 0.1)",
        "pipe(A, B, 0.08)",
    ] {
        shapes.push(feature.replace('A', A).replace('B', B));
    }
    for shape in &shapes {
        let (p, l) = program(shape);
        let s = slope(&p, &mut rng, 1.5);
        assert!(s <= l * (1.0 + 1e-9), "{shape}: slope {s} above L = {l}");
    }
}

#[test]
fn chamfer_and_features_follow_their_formulas() {
    // At points where the operands are known: the box's face x = 0.8 and the sphere.
    type Formula = fn(f64, f64) -> f64;
    let cases: [(&str, Formula); 4] = [
        ("smooth_union(0.3, A, B, variant: \"chamfer\")", |a, b| {
            a.min(b)
                .min((a + b - 0.3) * std::f64::consts::FRAC_1_SQRT_2)
        }),
        ("smooth_intersect(0.3, A, B, variant: \"round\")", |a, b| {
            let u = ((0.3 + a).max(0.0)).hypot((0.3 + b).max(0.0));
            (-0.3f64).min(a.max(b)) + u
        }),
        ("groove(A, B, 0.2, 0.1)", |a, b| {
            a.max((a + 0.1).min(0.1 - b.abs()))
        }),
        ("tongue(A, B, 0.2, 0.1)", |a, b| {
            a.min((a - 0.1).max(b.abs() - 0.1))
        }),
    ];
    let (pa, _) = program(A);
    let (pb, _) = program(B);
    let mut rng = Rng::new(9);
    for (shape, formula) in cases {
        let shape = shape.replace('A', A).replace('B', B);
        let (p, l) = program(&shape);
        for _ in 0..500 {
            let x = point(&mut rng, 1.5);
            let want = formula(f(&pa, x), f(&pb, x));
            let got = f(&p, x);
            // A field of L > 1 is divided by L (and raised to its bound's distance) where only
            // its zero set matters: the sign is kept.
            if l <= 1.0 {
                assert!((got - want).abs() < 1e-9, "{shape} at {x:?}: {got} {want}");
            } else if want.abs() > 1e-9 {
                assert_eq!(got < 0.0, want < 0.0, "{shape} at {x:?}: {got} {want}");
            }
        }
    }
}

/// hg_sdf's `fOpUnionColumns`, with its restriction to a < r, b < r, in f64: what
/// `blends.rs` evaluates everywhere must have the same sign, and never be above it.
fn mercury_columns(a: f64, b: f64, r: f64, n: f64) -> f64 {
    let s2 = std::f64::consts::SQRT_2;
    if !(a < r && b < r) {
        return a.min(b);
    }
    let c = r * s2 / ((n - 1.0) * 2.0 + s2);
    let (mut px, mut py) = ((a + b) / s2, (b - a) / s2);
    px += -s2 / 2.0 * r + c * s2;
    if n % 2.0 == 1.0 {
        py += c;
    }
    let size = 2.0 * c;
    let y = py + size * 0.5;
    let py = y - size * (y / size).floor() - size * 0.5;
    (px.hypot(py) - c).min(px).min(a).min(b)
}

#[test]
fn columns_everywhere_keep_the_surface_of_the_restricted_form() {
    let mut rng = Rng::new(11);
    for n in [1u32, 2, 3, 6] {
        // The blend of the planes x = 0 and y = 0 as its operands a = x, b = y.
        let shape = format!(
            "smooth_union(0.4, plane((1, 0, 0), 0), plane((0, 1, 0), 0), variant: \"columns\", steps: {n})"
        );
        let (p, _) = program(&shape);
        for _ in 0..4000 {
            let x = point(&mut rng, 1.5);
            let want = mercury_columns(x[0], x[1], 0.4, f64::from(n));
            let got = f(&p, x);
            if want.abs() > 1e-9 && got.abs() > 1e-9 {
                assert_eq!(got < 0.0, want < 0.0, "{shape} at {x:?}: {got} {want}");
            }
            // (The program divides the field by its L = √2: compare outside only.)
            assert!(
                want < 0.0 || got <= want + 1e-9,
                "{shape} at {x:?}: {got} {want}"
            );
        }
    }
}
