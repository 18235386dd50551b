//! Checks of the primitives of `shapes.rs` and the blends of `blends.rs` written from their
//! source text: each exact primitive is 1-Lipschitz, agrees in sign with an independent
//! inside test, and projects onto its own zero set (so it is the distance); the primitives
//! that generalise older ones equal them; every blend's sampled slope stays within the L
//! the analysis records; hg_sdf's columns, evaluated everywhere, keep the surface of its
//! restricted form.

use crate::eval::eval_point;
use crate::program::Program;
use crate::rng::Rng;
use crate::scene::analysis::analyse;

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

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn len(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
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
        let d = len(sub(a, b));
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
        let h = 1e-6;
        let g = [0, 1, 2].map(|i| {
            let (mut a, mut b) = (x, x);
            a[i] += h;
            b[i] -= h;
            (f(&p, a) - f(&p, b)) / (2.0 * h)
        });
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

const S3: f64 = 1.732_050_807_568_877_2;

#[test]
fn capped_cone_is_exact_and_generalises_cylinder_and_cone() {
    exact("capped_cone(1.2, 0.7, 0.3)", |p| {
        let r = 0.5 - p[1] / 1.2 * 0.4;
        p[1].abs() < 0.6 && p[0].hypot(p[2]) < r
    });
    exact("capped_cone(1, 0.2, 0.9)", |p| {
        let r = 0.55 + p[1] * 0.7;
        p[1].abs() < 0.5 && p[0].hypot(p[2]) < r
    });
    same("capped_cone(1.4, 0.6, 0.6)", "cylinder(0.6, 1.4)");
    same("capped_cone(1.4, 0.6, 0)", "cone(0.6, 1.4)");
}

#[test]
fn round_cone_is_exact() {
    exact("round_cone(0.5, 0.2, 1)", |p| {
        // Inside the hull of the two spheres: within the radius interpolated along the
        // tangent cone, or inside either sphere.
        let (r1, r2, h) = (0.5, 0.2, 1.0);
        let q = (p[0].hypot(p[2]), p[1] + 0.5);
        let s = (r1 - r2) / h;
        let c = (1.0f64 - s * s).sqrt();
        let k = -s * q.0 + c * q.1;
        let side = q.0 * c + q.1 * s - r1;
        q.0.hypot(q.1) < r1 || q.0.hypot(q.1 - h) < r2 || (k >= 0.0 && k <= c * h && side < 0.0)
    });
    same("round_cone(0.4, 0.4, 1.2)", "capsule(0.4, 1.2)");
}

#[test]
fn segment_is_a_capsule_between_two_points() {
    same(
        "segment((0, -0.6, 0), (0, 0.6, 0), 0.3)",
        "capsule(0.3, 1.2)",
    );
    same(
        "segment((0.2, -0.1, 0.4), (0.2, 0.9, 0.4), 0.25)",
        "capsule(0.25, 1).translate(0.2, 0.4, 0.4)",
    );
    same(
        "segment((0.3, 0, 0), (0.3, 0, 0), 0.5)",
        "sphere(0.5).translate(0.3, 0, 0)",
    );
    exact("segment((-0.5, -0.3, 0.2), (0.6, 0.4, -0.1), 0.3)", |p| {
        let (a, b) = ([-0.5, -0.3, 0.2], [0.6, 0.4, -0.1]);
        let ba = sub(b, a);
        let pa = sub(p, a);
        let t =
            ((pa[0] * ba[0] + pa[1] * ba[1] + pa[2] * ba[2]) / (len(ba) * len(ba))).clamp(0.0, 1.0);
        len(sub(pa, ba.map(|x| x * t))) < 0.3
    });
}

#[test]
fn rounded_cylinder_is_a_rounded_smaller_cylinder() {
    same("rounded_cylinder(0.6, 0, 1.2)", "cylinder(0.6, 1.2)");
    same(
        "rounded_cylinder(0.6, 0.15, 1.2)",
        "cylinder(0.45, 0.9).round(0.15)",
    );
    exact("rounded_cylinder(0.7, 0.2, 1)", |p| {
        let (x, y) = (p[0].hypot(p[2]) - 0.5, p[1].abs() - 0.3);
        let d = x.max(y).min(0.0) + x.max(0.0).hypot(y.max(0.0));
        d < 0.2
    });
}

#[test]
fn prisms_are_exact() {
    exact("hex_prism(0.6, 1.4)", |p| {
        let (x, z) = (p[0].abs(), p[2].abs());
        p[1].abs() < 0.7 && z < 0.6 && z * 0.5 + x * S3 * 0.5 < 0.6
    });
    exact("tri_prism(0.4, 1)", |p| {
        // Sides 0.4 from the axis: z > -0.4 and the two sides through the corner (0, 0.8).
        let (x, z) = (p[0].abs(), p[2]);
        p[1].abs() < 0.5 && z > -0.4 && x * S3 * 0.5 + z * 0.5 < 0.4
    });
}

#[test]
fn octahedron_pyramid_frame_and_link_are_exact() {
    exact("octahedron(1.1)", |p| {
        p[0].abs() + p[1].abs() + p[2].abs() < 1.1
    });
    exact("pyramid(1.2, 1.5)", |p| {
        // Base y = -0.75 of half-side 0.6, apex at y = 0.75.
        let t = (p[1] + 0.75) / 1.5;
        (0.0..1.0).contains(&t) && p[0].abs().max(p[2].abs()) < 0.6 * (1.0 - t)
    });
    exact("box_frame((0.8, 0.6, 0.5), 0.1)", |p| {
        let q = [p[0].abs(), p[1].abs(), p[2].abs()];
        let h = [0.8, 0.6, 0.5];
        let inside = (0..3).all(|i| q[i] < h[i]);
        let near = (0..3).filter(|&i| q[i] > h[i] - 0.2).count();
        inside && near >= 2
    });
    exact("link(0.6, 0.5, 0.15)", |p| {
        let y = (p[1].abs() - 0.3).max(0.0);
        (p[0].hypot(y) - 0.5).hypot(p[2]) < 0.15
    });
}

#[test]
fn infinite_shapes_equal_huge_finite_ones_near_the_origin() {
    same("slab(0.5)", "box((1e6, 0.25, 1e6))");
    same("slab(0.5, (0, 0, 2))", "box((1e6, 1e6, 0.25))");
    same("infinite_cylinder(0.4)", "cylinder(0.4, 2e6)");
    same(
        "infinite_cylinder(0.4, (1, 0, 0))",
        "cylinder(0.4, 2e6).rotate_z(90deg)",
    );
    exact("infinite_cylinder(0.3, (1, 1, 0))", |p| {
        let t = (p[0] + p[1]) * 0.5;
        len([p[0] - t, p[1] - t, p[2]]) < 0.3
    });
    exact("slab(0.6, (1, 2, -1))", |p| {
        (p[0] + 2.0 * p[1] - p[2]).abs() / 6f64.sqrt() < 0.3
    });
}

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

#[test]
fn profiles_made_solid_equal_the_primitives_they_describe() {
    same("extrude(rect((1, 0.5)), 0.6)", "box((1, 0.5, 0.3))");
    same(
        "extrude(round_rect((1, 0.5), 0.1), 0.6, round: 0.1)",
        "round_box((1, 0.5, 0.3), 0.1)",
    );
    same("revolve(circle(0.3).translate((1, 0)))", "torus(1, 0.3)");
    same("revolve(circle(0.3), offset: 1)", "torus(1, 0.3)");
    same("revolve(rect((0.5, 0.5)))", "cylinder(0.5, 1)");
    same(
        "revolve(segment2((0, -0.4), (0, 0.4), 0.3))",
        "capsule(0.3, 0.8)",
    );
    // A square turned by 45° is the regular polygon of 4 sides with a corner on +y.
    same(
        "extrude(rotate(rect(0.5), 45deg), 1)",
        &format!("extrude(regular_polygon(4, {}), 1)", 0.5 * 2f64.sqrt()),
    );
    same(
        "extrude(polygon([(-1, -0.5), (1, -0.5), (1, 0.5), (-1, 0.5)]), 0.6)",
        "box((1, 0.5, 0.3))",
    );
    // The extrusion is increasing in the profile's distance, so it commutes with min.
    same(
        "extrude(union(circle(0.3).translate(0.5, 0), rect(0.2)), 0.4)",
        "union(extrude(circle(0.3).translate(0.5, 0), 0.4), extrude(rect(0.2), 0.4))",
    );
    same(
        "extrude(mirror(circle(0.3).translate(0.5, 0.2)), 0.4)",
        "union(extrude(circle(0.3).translate(0.5, 0.2), 0.4), extrude(circle(0.3).translate(-0.5, 0.2), 0.4))",
    );
    same(
        "extrude(scale(circle(0.3), 2), 0.4)",
        "cylinder(0.6, 0.4).rotate_x(90deg)",
    );
    same(
        "extrude(offset(rect(0.3), 0.1), 2)",
        "extrude(round_rect((0.4, 0.4), 0.1), 2)",
    );
}

#[test]
fn extruded_and_revolved_profiles_are_exact() {
    let star = |x: f64, y: f64| {
        // The star of 5 points, outer radius 1, inner 0.5, by its polygon's winding.
        let v: Vec<[f64; 2]> = (0..10)
            .map(|i| {
                let r = if i % 2 == 0 { 1.0 } else { 0.5 };
                let t = std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * i as f64 / 5.0;
                [r * t.cos(), r * t.sin()]
            })
            .collect();
        winding(&v, [x, y])
    };
    exact("extrude(star(5, 1, 0.5), 1)", |p| {
        star(p[0], p[1]) && p[2].abs() < 0.5
    });
    exact("revolve(rect((0.3, 0.5)).translate(0.8, 0))", |p| {
        let r = p[0].hypot(p[2]);
        (r - 0.8).abs() < 0.3 && p[1].abs() < 0.5
    });
}

/// Whether `q` is inside the polygon through `v` (an odd number of crossings of the ray
/// along +x).
fn winding(v: &[[f64; 2]], q: [f64; 2]) -> bool {
    let mut inside = false;
    for i in 0..v.len() {
        let (a, b) = (v[i], v[(i + 1) % v.len()]);
        if (a[1] > q[1]) != (b[1] > q[1]) {
            let x = a[0] + (q[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if q[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// The distance from `q` to the segment from `a` to `b`.
fn to_segment(a: [f64; 2], b: [f64; 2], q: [f64; 2]) -> f64 {
    let (e, w) = ([b[0] - a[0], b[1] - a[1]], [q[0] - a[0], q[1] - a[1]]);
    let t = ((w[0] * e[0] + w[1] * e[1]) / (e[0] * e[0] + e[1] * e[1])).clamp(0.0, 1.0);
    (w[0] - t * e[0]).hypot(w[1] - t * e[1])
}

#[test]
fn polygons_are_their_brute_force_distance() {
    let mut rng = Rng::new(0x9011);
    for _ in 0..20 {
        // A random simple polygon: points around the origin at sorted angles, either winding.
        let n = 3 + rng.below(12);
        let mut angles: Vec<f64> = (0..n)
            .map(|_| rng.range(0.0, std::f64::consts::TAU))
            .collect();
        angles.sort_by(f64::total_cmp);
        if rng.uniform() < 0.5 {
            angles.reverse();
        }
        let v: Vec<[f64; 2]> = angles
            .iter()
            .map(|t| {
                let r = rng.range(0.3, 1.5);
                [r * t.cos(), r * t.sin()]
            })
            .collect();
        let list: Vec<String> = v.iter().map(|q| format!("({}, {})", q[0], q[1])).collect();
        // A tall extrusion, read at z = 0, is the profile's distance where |d| < 50.
        let (p, _) = program(&format!("extrude(polygon([{}]), 100)", list.join(", ")));
        let mut near = 0;
        for i in 0..400 {
            // Half the points near an edge or a corner.
            let q = if i % 2 == 0 {
                let k = rng.below(n);
                let (a, b) = (v[k], v[(k + 1) % n]);
                let t = if i % 4 == 0 { 0.0 } else { rng.uniform() };
                near += 1;
                [
                    a[0] + t * (b[0] - a[0]) + rng.range(-0.01, 0.01),
                    a[1] + t * (b[1] - a[1]) + rng.range(-0.01, 0.01),
                ]
            } else {
                [rng.range(-2.0, 2.0), rng.range(-2.0, 2.0)]
            };
            let d = (0..n)
                .map(|k| to_segment(v[k], v[(k + 1) % n], q))
                .fold(f64::INFINITY, f64::min);
            let want = if winding(&v, q) { -d } else { d };
            let got = f(&p, [q[0], q[1], 0.0]);
            assert!(
                (got - want).abs() < 1e-9,
                "{v:?} at {q:?}: {got}, not {want}"
            );
        }
        assert!(near > 0);
    }
}

#[test]
fn bad_profiles_are_located_errors() {
    for (src, says, at) in [
        (
            "extrude(polygon([(0, 0), (1, 0)]), 1)",
            "at least 3 points",
            "polygon",
        ),
        (
            "extrude(polygon([(0, 0), (1, 1), (1, 0), (0, 1)]), 1)",
            "crosses itself",
            "polygon",
        ),
        (
            "extrude(polygon([(0, 0), (1, 1), (2, 2)]), 1)",
            "no area",
            "polygon",
        ),
        (
            "extrude(rect(1), 1, round: 0.6)",
            "more than half the height",
            "extrude",
        ),
        ("circle(1)", "make it a shape with `extrude", "circle"),
    ] {
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
}

#[test]
fn a_loft_of_one_profile_is_its_extrusion() {
    same(
        "loft(rect((1, 0.5)), rect((1, 0.5)), 0.6)",
        "box((1, 0.5, 0.3))",
    );
    same(
        "loft(star(5, 1, 0.5), star(5, 1, 0.5), 0.8)",
        "extrude(star(5, 1, 0.5), 0.8)",
    );
    let (_, l) = program("loft(star(5, 1, 0.5), star(5, 1, 0.5), 0.8)");
    assert_eq!(l, 1.0);
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
        let h = 1e-6;
        let g = [0, 1, 2].map(|i| {
            let (mut a, mut b) = (x, x);
            a[i] += h;
            b[i] -= h;
            (f(&p, a) - f(&p, b)) / (2.0 * h)
        });
        s = s.max(len(g));
    }
    assert!(s <= l * (1.0 + 1e-6), "{shape}: slope {s} above L = {l}");
    (s, l)
}

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
}

#[test]
fn arcs_are_exact_and_a_whole_arc_is_a_ring() {
    // The arc of radius 0.8 over 120° about +y, 0.2 thick.
    let (s, c) = 60f64.to_radians().sin_cos();
    exact("extrude(arc(0.8, 120deg, 0.2), 100)", |p| {
        let (x, y) = (p[0].abs(), p[1]);
        let d = if x.atan2(y) <= 60f64.to_radians() {
            (x.hypot(y) - 0.8).abs()
        } else {
            (x - 0.8 * s).hypot(y - 0.8 * c)
        };
        d < 0.1
    });
    same(
        "extrude(arc(0.8, 360deg, 0.2), 1)",
        "extrude(ring(0.8, 0.2), 1)",
    );
}

/// The distance from `q` to the quadratic Bézier curve through `v`, by dense sampling of its
/// parameter refined by golden-section search around the best sample.
fn to_bezier(v: [[f64; 2]; 3], q: [f64; 2]) -> f64 {
    let at = |t: f64| {
        let s = 1.0 - t;
        let x = s * s * v[0][0] + 2.0 * s * t * v[1][0] + t * t * v[2][0];
        let y = s * s * v[0][1] + 2.0 * s * t * v[1][1] + t * t * v[2][1];
        (x - q[0]).hypot(y - q[1])
    };
    let n = 2000;
    let best = (0..=n)
        .min_by(|&i, &j| at(i as f64 / n as f64).total_cmp(&at(j as f64 / n as f64)))
        .expect("samples");
    let (mut lo, mut hi) = (
        (best as f64 - 1.0).max(0.0) / n as f64,
        (best as f64 + 1.0).min(n as f64) / n as f64,
    );
    let g = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..80 {
        let (a, b) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if at(a) < at(b) {
            hi = b;
        } else {
            lo = a;
        }
    }
    at(0.5 * (lo + hi)).min(at(0.0)).min(at(1.0))
}

#[test]
fn bezier_strokes_are_their_brute_force_distance() {
    let mut rng = Rng::new(0xbe21);
    let mut curves: Vec<[[f64; 2]; 3]> = vec![
        [[-1.0, 0.0], [0.0, 1.5], [1.0, 0.0]],
        // The control point on the line through the ends, beyond one of them.
        [[-0.5, -0.5], [1.0, 1.0], [0.5, 0.5]],
    ];
    for _ in 0..10 {
        curves.push([0; 3].map(|_| [rng.range(-1.2, 1.2), rng.range(-1.2, 1.2)]));
    }
    for v in curves {
        let shape = format!(
            "extrude(bezier(({}, {}), ({}, {}), ({}, {}), 0.05), 100)",
            v[0][0], v[0][1], v[1][0], v[1][1], v[2][0], v[2][1]
        );
        let (p, l) = program(&shape);
        assert_eq!(l, 1.0);
        for i in 0..300 {
            let q = if i % 2 == 0 {
                // Near the curve.
                let t = rng.uniform();
                let s = 1.0 - t;
                [0, 1].map(|k| {
                    s * s * v[0][k] + 2.0 * s * t * v[1][k] + t * t * v[2][k] + rng.range(-0.1, 0.1)
                })
            } else {
                [rng.range(-2.0, 2.0), rng.range(-2.0, 2.0)]
            };
            let want = to_bezier(v, q) - 0.05;
            let got = f(&p, [q[0], q[1], 0.0]);
            assert!(
                (got - want).abs() < 1e-7,
                "{shape} at {q:?}: {got}, not {want}"
            );
        }
    }
}

#[test]
fn polar_repetition_of_a_profile_turns_it_about_the_origin() {
    same(
        "extrude(repeat_polar(circle(0.1).translate(0, 0.5), 4), 0.2)",
        "extrude(union(circle(0.1).translate(0, 0.5), circle(0.1).translate(0.5, 0), circle(0.1).translate(0, -0.5), circle(0.1).translate(-0.5, 0)), 0.2)",
    );
}

#[test]
fn an_inset_is_exact_inside_and_a_bound_outside() {
    let (p, l) = program("extrude(offset(rect(0.5), -0.1), 100)");
    let (q, _) = program("extrude(rect(0.4), 100)");
    assert_eq!(l, 1.0);
    let src = "scene { extrude(offset(rect(0.5), -0.1), 100); }";
    let scene = crate::front::check_str("t.sdf", src).0.expect("scene");
    let facts = analyse(&scene).root().expect("root").facts;
    assert_eq!(facts.exactness, crate::scene::Exactness::Bound);
    let mut rng = Rng::new(3);
    let mut below = 0;
    for _ in 0..2000 {
        let x = point(&mut rng, 1.0);
        let x = [x[0], x[1], 0.0];
        let (d, e) = (f(&p, x), f(&q, x));
        if e <= 0.0 {
            assert!((d - e).abs() < 1e-12, "{x:?}: {d} {e}");
        } else {
            assert!(d > 0.0 && d <= e + 1e-12, "{x:?}: {d} {e}");
            below += usize::from(d < e - 1e-3);
        }
    }
    // Beyond the corners the inset's field is below the distance.
    assert!(below > 100, "{below}");
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
    let culled = super::lower(&scene);
    // Over the long arm, where the tie was.
    assert!(f(&culled, [0.5, 0.3, -0.45]) < 1.0);
    let options = super::LowerOptions {
        cull: false,
        ..super::LowerOptions::default()
    };
    let whole = super::lower_with(&scene, &options);
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
fn profile_fields_made_solid_equal_the_profiles_they_spell() {
    same(
        "extrude(profile { length(p) - 0.5 }, 0.6)",
        "extrude(circle(0.5), 0.6)",
    );
    same(
        "revolve(profile { length(p - vec2(1, 0)) - 0.3 })",
        "torus(1, 0.3)",
    );
    same(
        "extrude(profile { distance(rect((0.5, 0.3)), p) - 0.1 }, 0.4, 0.05)",
        "extrude(offset(rect((0.5, 0.3)), 0.1), 0.4, 0.05)",
    );
    // With the 2D operations, as any profile.
    same(
        "extrude(union(profile { length(p) - 0.5 }, rect((0.2, 0.7))).translate(0.3, 0.1).rotate(30deg), 0.5)",
        "extrude(union(circle(0.5), rect((0.2, 0.7))).translate(0.3, 0.1).rotate(30deg), 0.5)",
    );
    same(
        "loft(intersect(profile { length(p) - 0.5 }, rect(0.5)), circle(0.3), 0.8)",
        "loft(intersect(circle(0.5), rect(0.5)), circle(0.3), 0.8)",
    );
    // A formula of the plane's point reads x and y only: the same solid at every z.
    let (p, l) = program("extrude(profile { max(abs(p.x), abs(p.y)) - 0.5 }, 100)");
    assert_eq!(l, 1.0);
    let mut rng = Rng::new(3);
    for _ in 0..200 {
        let x = point(&mut rng, 1.0);
        let d = f(&p, x);
        assert_eq!(d, f(&p, [x[0], x[1], 0.7 * x[2]]), "{x:?}");
        assert!((d - (x[0].abs().max(x[1].abs()) - 0.5)).abs() < 1e-12);
    }
}

#[test]
fn solids_of_profile_fields_stay_within_their_recorded_bound() {
    // L 2 from the formula, kept by the extrusion and the revolution.
    let (s, l) = within_l("extrude(profile { 2 * (length(p) - 0.5) }, 0.6)", 1.5);
    assert_eq!(l, 2.0);
    assert!(s > 1.9, "slope {s}");
    let (s, l) = within_l(
        "revolve(profile { length(p - vec2(0.8, 0)) - 0.2 + 0.05 * sin(8 * p.y) }, 0.1)",
        1.5,
    );
    assert!(l > 1.0 && s > 1.0, "slope {s}, L {l}");
    within_l(
        "extrude(profile { distance(circle(0.6), p) + 0.1 * noise(p * 3) }, 0.5, 0.05)",
        1.5,
    );
    within_l(
        "extrude(profile { 0.5 * (length(p) - 0.6 + 0.2 * voronoi(p * 2)) }, 0.5)",
        1.5,
    );
    // A screw's bound holds for exact profiles only, and a formula is never known to be
    // exact: its screw has no proven bound (treated like a fractal), and says so.
    let src = "scene { screw(intersect(profile { length(p - vec2(0.5, 0)) - 0.1 }, rect((0.2, 0.15)).translate(0.5, 0)), 0.4, 1); }";
    let scene = crate::front::check_str("t.sdf", src).0.expect("scene");
    assert!(!analyse(&scene).root().expect("root").proven);
    within_l(
        "revolve(offset(profile(lipschitz: 1.5) { 1.5 * (abs(p.x - 0.7) - 0.1) }, 0.05))",
        1.5,
    );
}

#[test]
fn profile_fields_misused_are_located_errors() {
    for (src, says, at) in [
        (
            "extrude(profile { p.z }, 1)",
            "unknown vector component `z`",
            "z }",
        ),
        (
            "extrude(profile { length(p.xyz) }, 1)",
            "unknown vector component `xyz`",
            "xyz",
        ),
        (
            "extrude(field { length(p.xy) - 1 }, 1)",
            "`profile { … }`",
            "field",
        ),
        (
            "union(sphere(1), profile { length(p) - 1 })",
            "profile",
            "profile {",
        ),
        (
            "extrude(profile { vec3(p.x, p.y, 0) }, 1)",
            "not a float",
            "vec3(p.x",
        ),
        (
            "extrude(profile { distance(sphere(1), p) }, 1)",
            "distance(profile: profile, at: vec2)",
            "p) }",
        ),
        (
            "extrude(profile(lipschitz: 0) { length(p) - 1 }, 1)",
            "`lipschitz` of `profile` must be greater than 0",
            "0) {",
        ),
        (
            "screw(profile { length(p - vec2(0.5, 0)) - 0.1 }, 0.5, 1)",
            "no finite extent",
            "screw",
        ),
    ] {
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
}

/// A random formula of the plane's point, from the operations the bound analysis rules.
fn random_plane_expr(rng: &mut Rng, depth: u32) -> String {
    let leaf = |rng: &mut Rng| match rng.below(4) {
        0 => "p.x".to_string(),
        1 => "p.y".to_string(),
        2 => "length(p)".to_string(),
        _ => format!("{:.2}", rng.range(-2.0, 2.0)),
    };
    if depth == 0 {
        return leaf(rng);
    }
    let mut e = || random_plane_expr(rng, depth - 1);
    let (a, b) = (e(), e());
    match rng.below(12) {
        0 => format!("({a} + {b})"),
        1 => format!("({a} - {b})"),
        2 => format!("({a} * 1.3)"),
        3 => format!("sin({a})"),
        4 => format!("abs({a})"),
        5 => format!("min({a}, {b})"),
        6 => format!("max({a}, {b})"),
        7 => format!("sqrt({a} * {a} + 1)"),
        8 => format!("noise(vec2({a}, {b}))"),
        9 => format!("(sin({a}) * cos({b}))"),
        10 => format!("voronoi(vec2({a}, p.y))"),
        _ => format!("distance(star(5, 0.8, 0.4), vec2({a}, {b}))"),
    }
}

/// Random formulas of the plane, extruded and revolved: wherever the analysis proves a
/// bound, sampled slopes of the solid (the field without local bounds) stay within it.
#[test]
fn random_profile_formulas_keep_their_bound_when_made_solid() {
    let mut rng = Rng::new(36);
    let options = super::LowerOptions {
        local: false,
        ..super::LowerOptions::default()
    };
    let mut proven = 0;
    for i in 0..30 {
        let e = random_plane_expr(&mut rng, 3);
        let shape = if i % 2 == 0 {
            format!("extrude(profile {{ {e} }}, 1.2)")
        } else {
            format!("revolve(profile {{ {e} }}, 0.3)")
        };
        let src = format!("scene {{ {shape}; }}");
        let scene = crate::front::check_str("t.sdf", &src).0.expect("scene");
        let root = *analyse(&scene).root().expect("root");
        if !root.proven {
            continue;
        }
        proven += 1;
        let l = root.facts.lipschitz;
        let p = super::lower_with(&scene, &options);
        let mut sample = Rng::new(i);
        let s = slope(&p, &mut sample, 2.0);
        assert!(s <= l * (1.0 + 1e-6), "{shape}: slope {s} above L = {l}");
    }
    assert!(proven > 15, "only {proven} of 30 have a bound");
}

#[test]
fn reflect_is_one_mirror_image_where_mirror_folds() {
    // A sphere at +x reflected across x = 0 is the sphere at -x, and only that one; `mirror`
    // keeps both.
    same(
        "sphere(0.5).translate(1, 0.2, 0).reflect((1, 0, 0))",
        "sphere(0.5).translate(-1, 0.2, 0)",
    );
    let (folded, _) = program("sphere(0.5).translate(1, 0.2, 0).mirror()");
    let (reflected, l) = program("sphere(0.5).translate(1, 0.2, 0).reflect((2, 0, 0))");
    assert_eq!(l, 1.0);
    assert!(f(&folded, [1.0, 0.2, 0.0]) < 0.0 && f(&folded, [-1.0, 0.2, 0.0]) < 0.0);
    assert!(f(&reflected, [1.0, 0.2, 0.0]) > 0.0 && f(&reflected, [-1.0, 0.2, 0.0]) < 0.0);
    // Any plane through the origin: a point goes to p − 2(p·n)n.
    same(
        "box((0.2, 0.3, 0.4)).translate(0.5, 0.1, 0).reflect((1, 1, 0))",
        "box((0.3, 0.2, 0.4)).translate(-0.1, -0.5, 0)",
    );
    exact(
        "box((0.3, 0.2, 0.1)).translate(0.4, 0, 0).reflect((0, 0, 1))",
        |x| (x[0] - 0.4).abs() < 0.3 && x[1].abs() < 0.2 && x[2].abs() < 0.1,
    );
    // Profiles reflect across a line of the plane.
    same(
        "extrude(circle(0.3).translate(0.5, 0.2).reflect((0, 1)), 0.4)",
        "extrude(circle(0.3).translate(0.5, -0.2), 0.4)",
    );
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

#[test]
fn a_warp_written_as_a_field_keeps_the_materials_of_the_shape_it_reads() {
    let src = "material red = phong { color: (0.9, 0.1, 0.1) };\n\
               material grey = phong { color: (0.5, 0.5, 0.5) };\n\
               let s = union(sphere(0.5) @ red, box(0.3).translate(1.5, 0, 0) @ grey);\n\
               scene { field { distance(s, vec3(p.x, p.y + 0.2 * sin(3 * p.x), p.z)) }; }";
    let (scene, diags, _) = crate::front::check_str("t.sdf", src);
    assert!(diags.iter().all(|d| !d.is_error()), "{diags:#?}");
    let scene = scene.expect("scene");
    let program = super::lower(&scene);
    let id = |name: &str| {
        scene
            .materials
            .iter()
            .position(|m| m.name == name)
            .expect("material") as u32
    };
    // Inside the warped sphere (at x = 0 the warp is 0) and inside the warped box (at
    // x = 1.5 it moves y by 0.2·sin 4.5).
    let (d, m) = eval_point(&program, [0.0f64, 0.0, 0.0]);
    assert!(d < 0.0 && m == id("red"), "{d} {m}");
    let y = -0.2 * (4.5f64).sin();
    let (d, m) = eval_point(&program, [1.5, y, 0.0]);
    assert!(d < 0.0 && m == id("grey"), "{d} {m}");
    // Several shapes read: the nearer one's, as in a union.
    let (program, _) = program_of_two_reads();
    let (_, m) = eval_point(&program, [-0.4, 0.0, 0.0]);
    let (_, n) = eval_point(&program, [1.4, 0.0, 0.0]);
    assert!(m != n, "{m} {n}");
}

fn program_of_two_reads() -> (Program, f64) {
    let (scene, diags, _) = crate::front::check_str(
        "t.sdf",
        "material red = phong { color: (0.9, 0.1, 0.1) };\n\
         scene { field { min(distance(sphere(0.5) @ red, p), distance(box(0.3), p - vec3(1.5, 0, 0))) }; }",
    );
    assert!(diags.iter().all(|d| !d.is_error()), "{diags:#?}");
    let scene = scene.expect("scene");
    (super::lower(&scene), 1.0)
}

/// The frame of the segment from `a` to `b` at `p`: (the distance from the axis, the
/// distance along it from `a`), and the segment's length.
fn along(a: [f64; 3], b: [f64; 3], p: [f64; 3]) -> ((f64, f64), f64) {
    let ab = [0, 1, 2].map(|i| b[i] - a[i]);
    let l = len(ab);
    let u = ab.map(|x| x / l);
    let ap = [0, 1, 2].map(|i| p[i] - a[i]);
    let t = (0..3).map(|i| ap[i] * u[i]).sum::<f64>();
    let radial = len([0, 1, 2].map(|i| ap[i] - t * u[i]));
    ((radial, t), l)
}

#[test]
fn shapes_between_two_points_are_exact_and_their_y_aligned_shapes_moved() {
    same(
        "cylinder((0, -0.7, 0), (0, 0.7, 0), 0.5)",
        "cylinder(0.5, 1.4)",
    );
    same("cone((0, -0.6, 0), (0, 0.6, 0), 0.6, 0)", "cone(0.6, 1.2)");
    same(
        "round_cone((0, -0.5, 0), (0, 0.5, 0), 0.5, 0.2)",
        "round_cone(0.5, 0.2, 1)",
    );
    // Turned: b → a along y is the same solid as a → b upside down.
    same(
        "cone((0, 0.6, 0), (0, -0.6, 0), 0.2, 0.5)",
        "capped_cone(1.2, 0.5, 0.2)",
    );
    let (a, b) = ([-0.5, -0.4, 0.3], [0.6, 0.5, -0.2]);
    exact("cylinder((-0.5, -0.4, 0.3), (0.6, 0.5, -0.2), 0.35)", |p| {
        let ((r, t), l) = along(a, b, p);
        t > 0.0 && t < l && r < 0.35
    });
    exact("cone((-0.5, -0.4, 0.3), (0.6, 0.5, -0.2), 0.5, 0.1)", |p| {
        let ((r, t), l) = along(a, b, p);
        t > 0.0 && t < l && r < 0.5 + (0.1 - 0.5) * t / l
    });
    exact(
        "round_cone((-0.5, -0.4, 0.3), (0.6, 0.5, -0.2), 0.45, 0.2)",
        |p| {
            // As round_cone_is_exact, in the segment's frame.
            let ((r, t), h) = along(a, b, p);
            let (r1, r2) = (0.45, 0.2);
            let s = (r1 - r2) / h;
            let c = (1.0f64 - s * s).sqrt();
            let k = -s * r + c * t;
            let side = r * c + t * s - r1;
            r.hypot(t) < r1 || r.hypot(t - h) < r2 || (k >= 0.0 && k <= c * h && side < 0.0)
        },
    );
}
