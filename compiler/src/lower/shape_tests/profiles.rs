//! The profiles (2-D shapes): made solid they equal the primitives they describe; extrusions
//! and revolutions, polygons, arcs and Bézier strokes against brute force; bad profiles as
//! located errors; insets.

use super::{exact, f, located_error, point, program, same};
use crate::rng::Rng;
use crate::scene::analysis::analyse;

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
        located_error(src, says, at);
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
