//! Checks of the primitives of `shapes.rs` and the blends of `blends.rs` written from their
//! source text: each exact primitive is 1-Lipschitz, agrees in sign with an independent
//! inside test, and projects onto its own zero set (so it is the distance); the primitives
//! that generalise older ones equal them; every blend's sampled slope stays within the L
//! the analysis records; hg_sdf's columns, evaluated everywhere, keep the surface of its
//! restricted form. This module holds the helpers the checks share; the checks are by the
//! shapes' families: `solids.rs`, `blends.rs`, `profiles.rs`, `lofts.rs` (and screws),
//! `fields.rs` (profile fields).

use crate::eval::eval_point;
use crate::program::Program;
use crate::rng::Rng;
use crate::scene::analysis::analyse;
use glam::DVec3;

mod blends;
mod fields;
mod lofts;
mod profiles;
mod solids;

/// The lowered program of `scene { <shape>; }` and the L the analysis records for it.
fn program(shape: &str) -> (Program, f64) {
    let src = format!("scene {{ {shape}; }}");
    let (scene, diags, _) = crate::front::check_str("t.sdf", &src);
    assert!(diags.iter().all(|d| !d.is_error()), "{shape}: {diags:#?}");
    let scene = scene.expect("scene");
    let l = analyse(&scene).root().expect("root").facts.lipschitz;
    (super::lower(&scene), l)
}

fn f(p: &Program, x: [f64; 3]) -> f64 {
    eval_point(p, x).0
}

/// A random point in the cube of half-side `r`.
fn point(rng: &mut Rng, r: f64) -> [f64; 3] {
    [0; 3].map(|_| rng.range(-r, r))
}

/// The gradient of `p` at `x` by central differences.
fn gradient(p: &Program, x: [f64; 3]) -> [f64; 3] {
    let h = 1e-6;
    [0, 1, 2].map(|i| {
        let (mut a, mut b) = (x, x);
        a[i] += h;
        b[i] -= h;
        (f(p, a) - f(p, b)) / (2.0 * h)
    })
}

fn len(a: [f64; 3]) -> f64 {
    DVec3::from(a).length()
}

/// The largest |f(p) - f(q)| / |p - q| over random pairs, near (q within 0.05 of p) and far.
fn slope(p: &Program, rng: &mut Rng, r: f64) -> f64 {
    let mut worst = 0.0f64;
    for i in 0..4000 {
        let a = point(rng, r);
        let b = if i % 2 == 0 {
            let d = point(rng, 0.05);
            [a[0] + d[0], a[1] + d[1], a[2] + d[2]]
        } else {
            point(rng, r)
        };
        let d = DVec3::from(a).distance(DVec3::from(b));
        if d > 1e-9 {
            worst = worst.max((f(p, a) - f(p, b)).abs() / d);
        }
    }
    worst
}

/// Checks that `shape` is the exact distance of the solid `inside` describes: 1-Lipschitz,
/// negative exactly inside, and where its gradient is a unit vector (off the medial axis)
/// the point moved by -f along it lies on the surface.
fn exact(shape: &str, inside: impl Fn([f64; 3]) -> bool) {
    let (p, l) = program(shape);
    assert_eq!(l, 1.0, "{shape}: L");
    let mut rng = Rng::new(33);
    let s = slope(&p, &mut rng, 2.0);
    assert!(s <= 1.0 + 1e-9, "{shape}: slope {s}");
    let (mut projected, mut signs) = (0, 0);
    for _ in 0..3000 {
        let x = point(&mut rng, 1.6);
        let d = f(&p, x);
        if d.abs() > 1e-6 {
            assert_eq!(d < 0.0, inside(x), "{shape}: sign at {x:?} ({d})");
            signs += 1;
        }
        let g = gradient(&p, x);
        if (len(g) - 1.0).abs() > 1e-4 {
            continue;
        }
        let y = [0, 1, 2].map(|i| x[i] - d * g[i]);
        let e = f(&p, y);
        assert!(
            e.abs() < 1e-5,
            "{shape}: {x:?} ({d}) projects to {y:?} at {e}"
        );
        projected += 1;
    }
    assert!(
        signs > 2500 && projected > 2000,
        "{shape}: {signs} signs, {projected} projections"
    );
}

/// Checks that `src`, the scene's one statement, is an error whose message holds `says`,
/// its first label starting at the first `at` of the scene's text.
fn located_error(src: &str, says: &str, at: &str) {
    let text = format!("scene {{ {src}; }}");
    let (_, diags, _) = crate::front::check_str("t.sdf", &text);
    let error = diags
        .iter()
        .find(|d| d.is_error())
        .unwrap_or_else(|| panic!("{src}: no error"));
    let all = format!("{error:?}");
    assert!(all.contains(says), "{src}: {all}");
    let start = text.find(at).expect("in the text") as u32;
    assert_eq!(error.labels[0].span.start, start, "{src}: {all}");
}

/// Checks that two shapes have the same field near the origin.
fn same(a: &str, b: &str) {
    let (pa, _) = program(a);
    let (pb, _) = program(b);
    let mut rng = Rng::new(7);
    for _ in 0..2000 {
        let x = point(&mut rng, 2.0);
        let (da, db) = (f(&pa, x), f(&pb, x));
        assert!(
            (da - db).abs() < 1e-9,
            "{a} against {b} at {x:?}: {da} {db}"
        );
    }
}

/// The largest sampled slope of `shape` (over pairs of points, and its gradient by central
/// differences) and the L the analysis records, which neither may exceed.
fn within_l(shape: &str, r: f64) -> (f64, f64) {
    let (_, l) = program(shape);
    // The field as written: with local bounds the program would be divided by L already.
    let src = format!("scene {{ {shape}; }}");
    let scene = crate::front::check_str("t.sdf", &src).0.expect("scene");
    let options = super::LowerOptions {
        local: false,
        ..super::LowerOptions::default()
    };
    let p = super::lower_with(&scene, &options);
    let mut rng = Rng::new(35);
    let mut s = slope(&p, &mut rng, r);
    for _ in 0..4000 {
        let x = point(&mut rng, r);
        let g = gradient(&p, x);
        s = s.max(len(g));
    }
    assert!(s <= l * (1.0 + 1e-6), "{shape}: slope {s} above L = {l}");
    (s, l)
}
