//! Checks of `sweep` against brute force: a disc swept along a straight polyline is the
//! cylinder; a disc swept along any path is the distance to the path (a dense polyline of it)
//! less the radius; a rectangle swept along each kind of path lies on the surface sampled
//! from the path with a rotation-minimising frame found here independently (dense double
//! reflection), and its field divided by the L the analysis records never exceeds the
//! distance to that sampled surface.

use crate::eval::eval_point;
use crate::program::Program;
use crate::rng::Rng;
use crate::scene::analysis::analyse;
use crate::scene::path::first_normal;
use crate::scene::{Exactness, Node};
use glam::DVec3;

/// The lowered program of `scene { <shape>; }`, the analysis's exactness and L, and the
/// sweep's path (the root node's).
fn program(shape: &str) -> (Program, Exactness, f64, crate::scene::Path) {
    let src = format!("scene {{ {shape}; }}");
    let (scene, diags, _) = crate::front::check_str("t.sdf", &src);
    assert!(diags.iter().all(|d| !d.is_error()), "{shape}: {diags:#?}");
    assert!(
        diags.iter().all(|d| d.code != "W0018"),
        "{shape}: {diags:#?}"
    );
    let scene = scene.expect("scene");
    let root = scene.root.expect("root");
    let facts = analyse(&scene).root().expect("root").facts;
    let Node::Sweep { path, .. } = scene.graph.node(root) else {
        panic!("{shape}: not a sweep");
    };
    let path = (*path.0).clone();
    (super::lower(&scene), facts.exactness, facts.lipschitz, path)
}

/// A closed chain of four curves round a saddle, smooth where they meet.
const SADDLE: &str = "bezier([(1, 0.3, 0), (1, 0.3, 0.55), (0.55, -0.3, 1), (0, -0.3, 1), (-0.55, -0.3, 1), (-1, 0.3, 0.55), (-1, 0.3, 0), (-1, 0.3, -0.55), (-0.55, -0.3, -1), (0, -0.3, -1), (0.55, -0.3, -1), (1, 0.3, -0.55), (1, 0.3, 0)])";

fn f(p: &Program, x: DVec3) -> f64 {
    eval_point(p, x.to_array()).0
}

/// Checks that `p` is within `tol` of the field of `shape` at 3000 random points (of the
/// generator seeded `seed`) in the cube of half-side `r`.
fn close_to(p: &Program, shape: &str, seed: u64, r: f64, tol: f64) {
    let src = format!("scene {{ {shape}; }}");
    let (scene, _, _) = crate::front::check_str("c.sdf", &src);
    let q = super::lower(&scene.expect("scene"));
    let mut rng = Rng::new(seed);
    for _ in 0..3000 {
        let x = DVec3::from([0; 3].map(|_| rng.range(-r, r)));
        let (a, b) = (f(p, x), f(&q, x));
        assert!((a - b).abs() < tol, "{x}: {a} against {shape}'s {b}");
    }
}

/// The distance from `x` to the polyline through `pts`.
fn to_polyline(pts: &[DVec3], x: DVec3) -> f64 {
    pts.windows(2)
        .map(|w| {
            let e = w[1] - w[0];
            let t = ((x - w[0]).dot(e) / e.length_squared()).clamp(0.0, 1.0);
            x.distance(w[0] + e * t)
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn a_disc_swept_along_a_straight_polyline_is_the_cylinder() {
    let (p, exactness, l, _) = program("sweep(circle(0.3), polyline([(0, -1, 0), (0, 1, 0)]))");
    assert_eq!((exactness, l), (Exactness::Exact, 1.0));
    close_to(&p, "cylinder(0.3, 2)", 5, 1.6, 1e-9);
}

#[test]
fn a_disc_swept_round_a_closed_chain_of_quarter_circles_is_the_torus() {
    // Four cubic curves each within 2.7e-4 of a quarter of the unit circle (k = 0.5523).
    let k = 0.5523;
    let shape = format!(
        "sweep(circle(0.15), bezier([(1, 0, 0), (1, 0, {k}), ({k}, 0, 1), (0, 0, 1), (-{k}, 0, 1), (-1, 0, {k}), (-1, 0, 0), (-1, 0, -{k}), (-{k}, 0, -1), (0, 0, -1), ({k}, 0, -1), (1, 0, -{k}), (1, 0, 0)]))"
    );
    let (p, exactness, _, path) = program(&shape);
    assert!(path.closed && path.twist.abs() < 1e-12, "{path:?}");
    assert_eq!(exactness, Exactness::Exact);
    close_to(&p, "torus(1, 0.15)", 8, 1.5, 3e-4);
}

#[test]
fn a_disc_swept_along_any_path_is_the_distance_to_the_path_less_its_radius() {
    for path in [
        "helix(0.5, 0.4, 2.5)",
        "bezier([(-1, 0, 0), (-0.5, 0.8, 0.2), (0.5, -0.6, 0.3), (1, 0.2, -0.2), (1.5, 0.6, -0.5), (1.2, 1.2, 0), (0.6, 1.0, 0.3)])",
        "arc3((1, 0, 0), (0, 1, 0.3), (-1, 0.2, 0))",
        "polyline([(0, 0, 0), (1, 0, 0), (1, 0.5, 1), (0, 0, 1), (0, 0, 0)])",
        SADDLE,
    ] {
        let shape = format!("sweep(circle(0.1), {path})");
        let (p, exactness, l, path) = program(&shape);
        assert_eq!((exactness, l), (Exactness::Exact, 1.0), "{shape}");
        let dense: Vec<DVec3> = path.samples(4000).into_iter().map(|s| s.0).collect();
        let ends = [dense[0], dense[dense.len() - 1]];
        let (lo, hi) = path.aabb();
        let mut rng = Rng::new(9);
        let mut tested = 0;
        for _ in 0..1500 {
            let x = DVec3::from([0, 1, 2].map(|i| rng.range(lo[i] - 0.5, hi[i] + 0.5)));
            let d = to_polyline(&dense, x);
            // The open ends are capped flat: away from them, the distance to the path.
            if !path.closed && ends.iter().any(|e| x.distance(*e) < d + 0.05) {
                continue;
            }
            let got = f(&p, x);
            assert!((got - (d - 0.1)).abs() < 1e-4, "{shape} at {x}: {got} against {}", d - 0.1);
            tested += 1;
        }
        assert!(tested > 500, "{shape}: {tested}");
    }
}

/// Points on the surface of the rectangle of half-extents `half` swept along the path's dense
/// samples (away from its open ends), with the frame carried by double reflection and the
/// closing twist spread along it.
fn surface(path: &crate::scene::Path, half: [f64; 2], per: usize) -> Vec<DVec3> {
    let s = path.samples(per);
    let mut n = first_normal(s[0].1);
    let mut frames = vec![n];
    let mut arc = vec![0.0];
    for w in s.windows(2) {
        let ((x0, t0), (x1, t1)) = (w[0], w[1]);
        let v1 = x1 - x0;
        let c1 = v1.dot(v1);
        let nl = n - (2.0 / c1) * v1.dot(n) * v1;
        let tl = t0 - (2.0 / c1) * v1.dot(t0) * v1;
        let v2 = t1 - tl;
        let c2 = v2.dot(v2);
        n = if c2 > 1e-30 {
            nl - (2.0 / c2) * v2.dot(nl) * v2
        } else {
            nl
        };
        n = (n - t1 * n.dot(t1)).normalize();
        frames.push(n);
        arc.push(arc[arc.len() - 1] + x0.distance(x1));
    }
    let mut out = Vec::new();
    let skip = if path.closed { 0 } else { s.len() / 50 };
    for i in skip..s.len() - skip {
        let (x, t) = s[i];
        let a = path.twist * arc[i];
        let nn = frames[i] * a.cos() + t.cross(frames[i]) * a.sin();
        let bb = t.cross(nn);
        for k in 0..40 {
            let q = k as f64 / 10.0;
            let (u, v) = match k / 10 {
                0 => (-half[0] + 2.0 * half[0] * (q % 1.0), -half[1]),
                1 => (half[0], -half[1] + 2.0 * half[1] * (q % 1.0)),
                2 => (half[0] - 2.0 * half[0] * (q % 1.0), half[1]),
                _ => (-half[0], half[1] - 2.0 * half[1] * (q % 1.0)),
            };
            out.push(x + nn * u + bb * v);
        }
    }
    out
}

#[test]
fn a_rectangle_swept_lies_on_its_sampled_surface_and_is_a_bound() {
    for (path, tol) in [
        ("helix(0.5, 0.4, 2.5)", 1e-6),
        (
            "bezier([(-1, 0, 0), (-0.5, 0.8, 0.2), (0.5, -0.6, 0.3), (1, 0.2, -0.2)])",
            2e-3,
        ),
        ("arc3((1, 0, 0), (0, 1, 0.3), (-1, 0.2, 0))", 1e-6),
        (SADDLE, 2e-3),
    ] {
        let shape = format!("sweep(rect((0.08, 0.05)), {path})");
        let (p, exactness, l, path) = program(&shape);
        assert_ne!(exactness, Exactness::Approximate, "{shape}");
        let cloud = surface(&path, [0.08, 0.05], 400);
        for x in cloud.iter().step_by(7) {
            let d = f(&p, *x);
            assert!(d.abs() < tol, "{shape}: {d} on the surface at {x}");
        }
        let (lo, hi) = path.aabb();
        let mut rng = Rng::new(3);
        let spacing = 0.02;
        for _ in 0..400 {
            let x = DVec3::from([0, 1, 2].map(|i| rng.range(lo[i] - 0.4, hi[i] + 0.4)));
            let d = f(&p, x);
            if d <= 0.0 {
                continue;
            }
            let near = cloud
                .iter()
                .map(|c| c.distance(x))
                .fold(f64::INFINITY, f64::min);
            assert!(
                d / l <= near + spacing,
                "{shape} at {x}: {d} / {l} beyond {near}"
            );
        }
    }
}

#[test]
fn the_closing_twist_joins_a_closed_path_without_a_seam() {
    // A closed polyline out of one plane: its frame comes back turned, and the twist makes
    // the field continuous across the first point (where the path closes).
    let shape = "sweep(rect((0.1, 0.04)), polyline([(0, 0, 0), (1, 0, 0), (1, 0.5, 1), (0, 0, 1), (0, 0, 0)]))";
    let (p, _, _, path) = program(shape);
    assert!(path.closed && path.twist != 0.0, "{path:?}");
    let mut rng = Rng::new(1);
    for _ in 0..500 {
        let off = DVec3::new(0.0, rng.range(-0.12, 0.12), rng.range(-0.12, 0.12));
        let (a, b) = (
            DVec3::new(-1e-7, 0.0, 0.0) + off,
            DVec3::new(1e-7, 0.0, 0.0) + off,
        );
        let (fa, fb) = (f(&p, a), f(&p, b));
        assert!((fa - fb).abs() < 1e-5, "{off}: {fa} against {fb}");
    }
}
