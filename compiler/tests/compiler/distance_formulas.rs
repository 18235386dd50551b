//! Distance conformance: every primitive and operator of the scene IR, lowered and run by the
//! interpreter (f64 reference path and f32/f64 batch paths), against an independent formula
//! written here at random points. Exact fields must match to rounding; bounds must never
//! exceed the true distance.

use crate::common::*;
use sdfc_compiler::{
    eval_point, lower, lower_with, Combine, Float, LowerOptions, Node, Outputs, Program, Rng,
    Scene, Smooth,
};

/// Distance (and material) of a program at many points, in f32 through the batch path.
fn batch<T: Float>(program: &Program, points: &[[f64; 3]]) -> (Vec<f64>, Vec<u32>) {
    let (d, m) = run_batch::<T>(program, Outputs::DistanceAndMaterial, 64, points);
    (d.iter().map(|v| v.to_f64()).collect(), m)
}

fn points(seed: u64, n: usize, extent: f64) -> Vec<[f64; 3]> {
    let mut rng = Rng::new(seed);
    (0..n).map(|_| rng.point(extent)).collect()
}

/// Checks an exact field: the f64 reference evaluation to 1e-9, the f32 batch evaluation to
/// f32 rounding of the coordinates and the operations (relative to the point's size). The
/// field is lowered as written: local bounds (which change its values where L > 1, not its
/// solid) are off.
fn exact(scene: &Scene, reference: impl Fn([f64; 3]) -> f64, extent: f64) {
    let written = LowerOptions {
        local: false,
        ..LowerOptions::default()
    };
    let program = lower_with(scene, &written);
    let pts = points(7, 500, extent);
    let (d32, _) = batch::<f32>(&program, &pts);
    let (d64, _) = batch::<f64>(&program, &pts);
    for (i, &p) in pts.iter().enumerate() {
        let want = reference(p);
        let (one, _) = eval_point::<f64>(&program, p);
        let scale = 1.0 + len3(p) + want.abs();
        assert!(
            (one - want).abs() <= 1e-9 * scale,
            "f64 at {p:?}: {one} vs {want}"
        );
        assert_eq!(
            one.to_bits(),
            d64[i].to_bits(),
            "batch f64 differs from the reference path at {p:?}"
        );
        assert!(
            (d32[i] - want).abs() <= 2e-6 * scale,
            "f32 at {p:?}: {} vs {want}",
            d32[i]
        );
    }
}

/// Checks a bound: never above the true distance outside (and the same sign everywhere).
fn bound(scene: &Scene, truth: impl Fn([f64; 3]) -> f64, extent: f64) {
    let program = lower(scene);
    for p in points(11, 2000, extent) {
        let (d, _) = eval_point::<f64>(&program, p);
        let t = truth(p);
        assert_eq!(d < 0.0, t < 0.0, "sign at {p:?}: {d} vs {t}");
        if t > 0.0 {
            assert!(
                d <= t + 1e-9,
                "bound exceeds the distance at {p:?}: {d} > {t}"
            );
        }
    }
}

// ---- independent reference formulas ----

/// Distance to a solid axis-aligned box by its closest point.
fn box_ref(p: [f64; 3], b: [f64; 3]) -> f64 {
    let inside = (0..3).all(|i| p[i].abs() <= b[i]);
    if inside {
        -(0..3)
            .map(|i| b[i] - p[i].abs())
            .fold(f64::INFINITY, f64::min)
    } else {
        let c = [
            p[0].clamp(-b[0], b[0]),
            p[1].clamp(-b[1], b[1]),
            p[2].clamp(-b[2], b[2]),
        ];
        len3(sub3(p, c))
    }
}

/// Distance to a 2D segment.
fn seg2(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (ab, ap) = ([b[0] - a[0], b[1] - a[1]], [p[0] - a[0], p[1] - a[1]]);
    let t = ((ap[0] * ab[0] + ap[1] * ab[1]) / (ab[0] * ab[0] + ab[1] * ab[1])).clamp(0.0, 1.0);
    len2(ap[0] - t * ab[0], ap[1] - t * ab[1])
}

/// Distance to the solid of revolution about y of the triangle (0,-h), (r,-h), (0,h).
fn cone_ref(p: [f64; 3], r: f64, h: f64) -> f64 {
    let q = [len2(p[0], p[2]), p[1]];
    let d = seg2(q, [0.0, -h], [r, -h]).min(seg2(q, [r, -h], [0.0, h]));
    let inside = q[1] >= -h && q[1] <= h && q[0] <= r * (h - q[1]) / (2.0 * h);
    if inside {
        -d
    } else {
        d
    }
}

/// The true signed distance to an ellipsoid, from the closest-point equation solved by
/// bisection: x_i = r_i² p_i / (r_i² + t) with Σ (x_i / r_i)² = 1.
fn ellipsoid_true(p: [f64; 3], r: [f64; 3]) -> f64 {
    let a = [p[0].abs(), p[1].abs(), p[2].abs()];
    let g = |t: f64| {
        (0..3)
            .map(|i| (r[i] * a[i] / (r[i] * r[i] + t)).powi(2))
            .sum::<f64>()
            - 1.0
    };
    let inside = g(0.0) < 0.0;
    let rmin2 = r.iter().fold(f64::INFINITY, |m, v| m.min(v * v));
    let (mut lo, mut hi) = if inside { (-rmin2, 0.0) } else { (0.0, 1.0) };
    while !inside && g(hi) > 0.0 {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let t = 0.5 * (lo + hi);
    let x = [0, 1, 2].map(|i| r[i] * r[i] * a[i] / (r[i] * r[i] + t));
    let d = len3(sub3(a, x));
    if inside {
        -d
    } else {
        d
    }
}

fn sphere(r: f64) -> Node {
    Node::Sphere { radius: r }
}

// ---- primitives ----

#[test]
fn sphere_is_exact() {
    exact(&single(sphere(1.3)), |p| len3(p) - 1.3, 3.0);
}

#[test]
fn box_is_exact() {
    let b = [0.5, 1.0, 1.5];
    exact(&single(Node::Box { half: b }), |p| box_ref(p, b), 3.0);
}

#[test]
fn round_box_is_exact() {
    let (b, r) = ([0.6, 1.0, 1.4], 0.25);
    exact(
        &single(Node::RoundBox { half: b, radius: r }),
        |p| box_ref(p, [b[0] - r, b[1] - r, b[2] - r]) - r,
        3.0,
    );
}

#[test]
fn plane_is_exact() {
    let n = [0.0, 0.6, 0.8];
    exact(
        &single(Node::Plane {
            normal: n,
            height: 0.5,
        }),
        |p| p[1] * 0.6 + p[2] * 0.8 - 0.5,
        3.0,
    );
}

#[test]
fn torus_is_exact() {
    // Distance to the core circle, minus the tube radius.
    exact(
        &single(Node::Torus {
            major: 1.2,
            minor: 0.3,
        }),
        |p| {
            let rho = len2(p[0], p[2]);
            let c = [1.2 * p[0] / rho, 0.0, 1.2 * p[2] / rho];
            len3(sub3(p, c)) - 0.3
        },
        2.5,
    );
}

#[test]
fn cylinder_is_exact() {
    let (r, h) = (0.7, 1.1);
    exact(
        &single(Node::Cylinder {
            radius: r,
            half_height: h,
        }),
        |p| {
            // A 2D box in (ρ, y): the revolved rectangle [0, r] × [-h, h].
            let q = [len2(p[0], p[2]), p[1], 0.0];
            box_ref(q, [r, h, 1.0])
        },
        3.0,
    );
}

#[test]
fn capsule_is_exact() {
    let (r, h) = (0.4, 0.9);
    exact(
        &single(Node::Capsule {
            radius: r,
            half_height: h,
        }),
        |p| {
            let y = p[1].clamp(-h, h);
            len3(sub3(p, [0.0, y, 0.0])) - r
        },
        2.5,
    );
}

#[test]
fn cone_is_exact() {
    let (r, h) = (0.8, 1.0);
    exact(
        &single(Node::Cone {
            radius: r,
            half_height: h,
        }),
        |p| cone_ref(p, r, h),
        2.5,
    );
}

#[test]
fn ellipsoid_is_a_bound() {
    let r = [1.0, 0.5, 1.5];
    bound(
        &single(Node::Ellipsoid { radii: r }),
        |p| ellipsoid_true(p, r),
        3.0,
    );
}

#[test]
fn mandelbulb_matches_the_iteration() {
    let (power, iterations) = (8.0, 6u32);
    let reference = |p: [f64; 3]| {
        let r0 = len3(p);
        if r0 > 4.0 {
            return r0 - 2.0;
        }
        let (mut z, mut dr) = (p, 1.0f64);
        for _ in 0..iterations {
            let r = len3(z);
            if r > 2.0 {
                break;
            }
            let theta = (z[1] / r).clamp(-1.0, 1.0).acos() * power;
            let phi = z[2].atan2(z[0]) * power;
            dr = power * r.powf(power - 1.0) * dr + 1.0;
            let rn = r.powf(power);
            z = [
                rn * theta.sin() * phi.cos() + p[0],
                rn * theta.cos() + p[1],
                rn * theta.sin() * phi.sin() + p[2],
            ];
        }
        let r = len3(z);
        0.5 * r.ln() * r / dr
    };
    let node = Node::prim("mandelbulb", &[&[power], &[f64::from(iterations)]]);
    let program = lower(&single(
        node.expect("mandelbulb is a primitive of the table"),
    ));
    for p in points(3, 500, 1.6).into_iter().chain(points(4, 100, 6.0)) {
        let (d, _) = eval_point::<f64>(&program, p);
        let want = reference(p);
        assert!(
            (d - want).abs() <= 1e-7 * (1.0 + want.abs()),
            "at {p:?}: {d} vs {want}"
        );
    }
}

// ---- combinations ----

/// Two spheres, one of them translated, combined by `make`.
fn pair(
    make: impl FnOnce(&mut Build, sdfc_compiler::NodeId, sdfc_compiler::NodeId) -> Node,
) -> Scene {
    let mut b = Build::new();
    let s1 = b.add(sphere(1.0));
    let s2 = b.add(sphere(0.7));
    let s2 = b.at(s2, [0.8, 0.3, 0.0]);
    let node = make(&mut b, s1, s2);
    let root = b.add(node);
    b.finish(root)
}

fn da(p: [f64; 3]) -> f64 {
    len3(p) - 1.0
}

fn db(p: [f64; 3]) -> f64 {
    len3(sub3(p, [0.8, 0.3, 0.0])) - 0.7
}

#[test]
fn union_intersection_subtraction() {
    let u = pair(|_, a, b| Node::Combine {
        op: Combine::Union,
        children: vec![a, b],
    });
    exact(&u, |p| da(p).min(db(p)), 3.0);
    let i = pair(|_, a, b| Node::Combine {
        op: Combine::Intersect,
        children: vec![a, b],
    });
    exact(&i, |p| da(p).max(db(p)), 3.0);
    let s = pair(|_, a, b| Node::Combine {
        op: Combine::Subtract,
        children: vec![a, b],
    });
    exact(&s, |p| da(p).max(-db(p)), 3.0);
}

/// Quilez's polynomial smooth minimum in its original "mix" form.
fn smin_mix(a: f64, b: f64, k: f64) -> f64 {
    let h = (0.5 + 0.5 * (b - a) / k).clamp(0.0, 1.0);
    b + (a - b) * h - k * h * (1.0 - h)
}

#[test]
fn smooth_combinations_poly() {
    let k = 0.4;
    let smooth = |op| {
        pair(move |_, a, b| Node::SmoothCombine {
            op,
            k,
            variant: Smooth::Poly,
            a,
            b,
        })
    };
    exact(&smooth(Combine::Union), |p| smin_mix(da(p), db(p), k), 3.0);
    exact(
        &smooth(Combine::Intersect),
        |p| -smin_mix(-da(p), -db(p), k),
        3.0,
    );
    exact(
        &smooth(Combine::Subtract),
        |p| -smin_mix(-da(p), db(p), k),
        3.0,
    );
}

#[test]
fn smooth_combinations_exp() {
    let k = 0.3;
    let smooth = |op| {
        pair(move |_, a, b| Node::SmoothCombine {
            op,
            k,
            variant: Smooth::Exp,
            a,
            b,
        })
    };
    let smin = |a: f64, b: f64| -k * ((-a / k).exp() + (-b / k).exp()).ln();
    exact(&smooth(Combine::Union), |p| smin(da(p), db(p)), 2.0);
    exact(&smooth(Combine::Intersect), |p| -smin(-da(p), -db(p)), 2.0);
    exact(&smooth(Combine::Subtract), |p| -smin(-da(p), db(p)), 2.0);
}

#[test]
fn smooth_union_with_zero_blend_is_the_union() {
    let s = pair(|_, a, b| Node::SmoothCombine {
        op: Combine::Union,
        k: 0.0,
        variant: Smooth::Poly,
        a,
        b,
    });
    exact(&s, |p| da(p).min(db(p)), 3.0);
}

// ---- transforms ----

fn wrap(inner: Node, make: impl FnOnce(sdfc_compiler::NodeId) -> Node) -> Scene {
    let mut b = Build::new();
    let c = b.add(inner);
    let root = b.add(make(c));
    b.finish(root)
}

const BOX: [f64; 3] = [0.5, 0.8, 0.3];

fn boxed() -> Node {
    Node::Box { half: BOX }
}

#[test]
fn translate_and_rotate() {
    exact(
        &wrap(boxed(), |c| Node::Translate {
            offset: [1.0, -0.5, 2.0],
            child: c,
        }),
        |p| box_ref(sub3(p, [1.0, -0.5, 2.0]), BOX),
        3.0,
    );
    // A rotation by θ about y (rows of the matrix that maps the child's points to the world).
    let th: f64 = 0.7;
    let m = [
        [th.cos(), 0.0, th.sin()],
        [0.0, 1.0, 0.0],
        [-th.sin(), 0.0, th.cos()],
    ];
    let inverse = |p: [f64; 3]| {
        [
            th.cos() * p[0] - th.sin() * p[2],
            p[1],
            th.sin() * p[0] + th.cos() * p[2],
        ]
    };
    exact(
        &wrap(boxed(), |c| Node::Rotate {
            matrix: m,
            child: c,
        }),
        |p| box_ref(inverse(p), BOX),
        3.0,
    );
}

#[test]
fn rotate_moves_the_child_by_the_matrix() {
    // A sphere at (1, 0, 0) rotated by a quarter turn about z lands at (0, 1, 0).
    let mut b = Build::new();
    let s = b.add(sphere(0.25));
    let s = b.at(s, [1.0, 0.0, 0.0]);
    let root = b.add(Node::Rotate {
        matrix: [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
        child: s,
    });
    let program = lower(&b.finish(root));
    let (d, _) = eval_point::<f64>(&program, [0.0, 1.0, 0.0]);
    assert!((d + 0.25).abs() < 1e-12, "{d}");
}

#[test]
fn scales() {
    exact(
        &wrap(boxed(), |c| Node::Scale {
            factor: 2.5,
            child: c,
        }),
        |p| 2.5 * box_ref(p.map(|v| v / 2.5), BOX),
        4.0,
    );
    // A unit sphere scaled per axis is an ellipsoid: the field must be a bound of it.
    let f = [1.5, 0.5, 1.0];
    bound(
        &wrap(sphere(1.0), |c| Node::ScaleXyz {
            factors: f,
            child: c,
        }),
        |p| ellipsoid_true(p, f),
        3.0,
    );
}

#[test]
fn infinite_repetition() {
    let s = [2.0, 0.0, 3.0];
    let cell = |v: f64, s: f64| {
        if s == 0.0 {
            v
        } else {
            (v + 0.5 * s).rem_euclid(s) - 0.5 * s
        }
    };
    exact(
        &wrap(boxed(), |c| Node::Repeat {
            period: s,
            count: None,
            child: c,
        }),
        |p| box_ref([cell(p[0], s[0]), p[1], cell(p[2], s[2])], BOX),
        9.0,
    );
}

#[test]
fn finite_repetition() {
    let (s, n) = ([2.0, 1.5, 0.0], [3.0, 2.0, 1.0]);
    // The nearest of the n cell centres along each axis, found by search.
    let local = |v: f64, i: usize| {
        if s[i] == 0.0 {
            return v;
        }
        let centres = (0..n[i] as usize).map(|j| (j as f64 - (n[i] - 1.0) / 2.0) * s[i]);
        let c = centres
            .min_by(|a, b| (v - a).abs().total_cmp(&(v - b).abs()))
            .unwrap_or(0.0);
        v - c
    };
    exact(
        &wrap(boxed(), |c| Node::Repeat {
            period: s,
            count: Some(n),
            child: c,
        }),
        |p| box_ref([local(p[0], 0), local(p[1], 1), local(p[2], 2)], BOX),
        6.0,
    );
}

#[test]
fn mirror_twist_bend() {
    let mut b = Build::new();
    let bx = b.add(boxed());
    let bx = b.at(bx, [1.0, 0.2, 0.0]);
    let root = b.add(Node::Mirror {
        axes: [true, false, false],
        child: bx,
    });
    exact(
        &b.finish(root),
        |p| box_ref(sub3([p[0].abs(), p[1], p[2]], [1.0, 0.2, 0.0]), BOX),
        3.0,
    );
    let k = 0.8;
    let twisted = |p: [f64; 3]| {
        let (c, s) = ((k * p[1]).cos(), (k * p[1]).sin());
        [c * p[0] - s * p[2], p[1], s * p[0] + c * p[2]]
    };
    exact(
        &wrap(boxed(), |c| Node::Twist { rate: k, child: c }),
        |p| box_ref(twisted(p), BOX),
        2.0,
    );
    let bent = |p: [f64; 3]| {
        let (c, s) = ((k * p[0]).cos(), (k * p[0]).sin());
        [c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]]
    };
    exact(
        &wrap(boxed(), |c| Node::Bend { rate: k, child: c }),
        |p| box_ref(bent(p), BOX),
        2.0,
    );
}

#[test]
fn round_shell_elongate() {
    exact(
        &wrap(boxed(), |c| Node::Round {
            radius: 0.2,
            child: c,
        }),
        |p| box_ref(p, BOX) - 0.2,
        3.0,
    );
    exact(
        &wrap(sphere(1.0), |c| Node::Shell {
            half: 0.1,
            child: c,
        }),
        |p| (len3(p) - 1.0).abs() - 0.1,
        3.0,
    );
    let h = [0.5, 0.0, 0.25];
    exact(
        &wrap(sphere(0.5), |c| Node::Elongate { half: h, child: c }),
        |p| len3([0, 1, 2].map(|i| p[i] - p[i].clamp(-h[i], h[i]))) - 0.5,
        3.0,
    );
}

// ---- materials and sharing ----

#[test]
fn union_takes_the_nearer_childs_material_and_inner_paint_wins() {
    let mut b = Build::new();
    let (red, blue, green) = (
        b.material([1.0, 0.0, 0.0], 0.0, 0.0),
        b.material([0.0, 0.0, 1.0], 0.0, 0.0),
        b.material([0.0, 1.0, 0.0], 0.0, 0.0),
    );
    let s1 = b.add(sphere(1.0));
    let s1 = b.paint(s1, red);
    let s2 = b.add(sphere(0.5));
    let s2 = b.at(s2, [3.0, 0.0, 0.0]);
    let s3 = b.add(sphere(0.5));
    let s3 = b.at(s3, [-3.0, 0.0, 0.0]);
    let inner = b.add(Node::Combine {
        op: Combine::Union,
        children: vec![s1, s2],
    });
    let inner = b.paint(inner, blue);
    let root = b.add(Node::Combine {
        op: Combine::Union,
        children: vec![inner, s3],
    });
    let _ = green;
    let program = lower(&b.finish(root));
    let pts = [[0.0, 1.2, 0.0], [3.0, 0.7, 0.0], [-3.0, 0.7, 0.0]];
    let want = [red.0, blue.0, 0];
    for (p, w) in pts.iter().zip(want) {
        assert_eq!(eval_point::<f64>(&program, *p).1, w, "at {p:?}");
    }
    let (_, m32) = batch::<f32>(&program, &pts);
    assert_eq!(m32, want.to_vec());
}

#[test]
fn a_shared_node_is_lowered_once() {
    let mut b = Build::new();
    let s = b.add(Node::Torus {
        major: 1.0,
        minor: 0.25,
    });
    let s = b.at(s, [0.5, 0.0, 0.0]);
    let alone = lower(&b.scene.clone_with_root(s));
    let root = b.add(Node::Combine {
        op: Combine::Union,
        children: vec![s, s],
    });
    let twice = lower(&b.finish(root));
    assert_eq!(twice.len(), alone.len(), "{}", twice.dump());
}

#[test]
fn constant_parts_are_folded_away() {
    // A sphere at the origin, translated by zero, scaled by one: just |p| - r.
    let mut b = Build::new();
    let s = b.add(sphere(1.0));
    let t = b.at(s, [0.0, 0.0, 0.0]);
    let root = b.add(Node::Scale {
        factor: 1.0,
        child: t,
    });
    let program = lower(&b.finish(root));
    let d = program.dump();
    assert_eq!(d.matches(" mul ").count(), 3, "{d}");
    assert!(!d.contains(" select ") && !d.contains(" lt "), "{d}");
}

#[test]
fn dump_is_stable_and_one_instruction_per_line() {
    let s = pair(|_, a, b| Node::SmoothCombine {
        op: Combine::Union,
        k: 0.3,
        variant: Smooth::Poly,
        a,
        b,
    });
    let (p1, p2) = (lower(&s), lower(&s));
    let d = p1.dump();
    assert_eq!(d, p2.dump());
    let lines: Vec<&str> = d.lines().filter(|l| l.starts_with('%')).collect();
    assert_eq!(lines.len(), p1.len());
    assert!(lines
        .iter()
        .enumerate()
        .all(|(i, l)| l.starts_with(&format!("%{i} = "))));
    assert_has(&d, &["; node ", "smooth_union"]);
    assert!(d
        .lines()
        .last()
        .is_some_and(|l| l.starts_with("return distance %")));
}

#[test]
fn empty_scene_is_far_away() {
    let program = lower(&Scene::default());
    let (d, m) = eval_point::<f32>(&program, [0.0, 0.0, 0.0]);
    assert!(d > 1e20 && m == 0);
}

trait WithRoot {
    fn clone_with_root(&self, root: sdfc_compiler::NodeId) -> Scene;
}

impl WithRoot for Scene {
    fn clone_with_root(&self, root: sdfc_compiler::NodeId) -> Scene {
        let mut s = self.clone();
        s.root = Some(root);
        s
    }
}
