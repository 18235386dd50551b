//! Tests of the analysis rules: the facts and warnings derived for small scenes, and, for the
//! claims that matter to the renderer, an empirical check on the lowered program: sphere
//! tracing with steps of `f / L` never steps across the surface, and the exact primitives
//! have unit gradients.

use super::*;
use crate::eval::eval_point;
use crate::front::check_str;
use crate::lower::{lower, lower_with, LowerOptions};
use crate::program::Program;
use crate::rng::Rng;
use crate::scene::V3;

fn scene(objects: &str) -> (Scene, Vec<Diagnostic>) {
    let text = format!("scene {{ {objects}; }}");
    let (scene, diags, _) = check_str("test.sdf", &text);
    let scene = scene.unwrap_or_else(|| panic!("{objects}: {diags:?}"));
    (scene, diags)
}

fn root(objects: &str) -> Derived {
    let (s, _) = scene(objects);
    *analyse(&s).root().expect("objects")
}

/// The analysis's warnings (not those about lights and the camera, `front/placement.rs`).
fn codes(objects: &str) -> Vec<&'static str> {
    scene(objects)
        .1
        .iter()
        .map(|d| d.code)
        .filter(|c| !["W0008", "W0009", "W0010"].contains(c))
        .collect()
}

#[test]
fn the_stretch_warning_says_which_rays_step_shorter() {
    let (_, diags) = scene("box((0.5, 1, 0.5)).twist(4)");
    let d = diags.iter().find(|d| d.code == "W0003").expect("W0003");
    assert!(
        d.notes.iter().any(|n| n.contains("local bounds")),
        "{:?}",
        d.notes
    );
    assert!(!d.notes.iter().any(|n| n.contains("every ray")));
}

#[test]
fn the_exact_primitives_are_exact() {
    for p in [
        "sphere(1)",
        "box((1, 2, 3))",
        "round_box((1, 1, 1), 0.2)",
        "plane((0, 1, 0), 0)",
        "torus(1, 0.25)",
        "cylinder(0.5, 1)",
        "capsule(0.5, 1)",
        "cone(0.5, 1)",
        // The hulls of balls and of parallel cylinders (`sdfc check` says exact for them).
        "hull(sphere(1), sphere(0.5).translate(3, 0, 0), sphere(0.2).translate(1, 2, 0))",
        "hull(cylinder(0.5, 1), cylinder(0.3, 1).translate(2, 0, 1)).rotate_x(20deg)",
    ] {
        let d = root(p);
        assert_eq!(d.facts.exactness, Exactness::Exact, "{p}");
        assert_eq!(d.facts.lipschitz, 1.0, "{p}");
        assert!(d.proven, "{p}");
    }
}

#[test]
fn rigid_motions_and_uniform_scale_keep_exactness() {
    let d = root("sphere(1).translate(1, 2, 3).rotate_y(30deg).scale(2)");
    assert_eq!(d.facts.exactness, Exactness::Exact);
    assert_eq!(d.facts.lipschitz, 1.0);
}

#[test]
fn bounds_and_approximations() {
    // What each is, and whether that is proven.
    const BOUND: (Exactness, bool) = (Exactness::Bound, true);
    const APPROXIMATE: (Exactness, bool) = (Exactness::Approximate, true);
    const UNPROVEN: (Exactness, bool) = (Exactness::Approximate, false);
    let cases = [
        ("ellipsoid((1, 2, 3))", BOUND),
        ("sphere(1).scale((1, 2, 1))", BOUND),
        ("union(sphere(1), box(1).translate(3, 0, 0))", BOUND),
        ("subtract(box(1), sphere(1.2))", BOUND),
        (
            "smooth_union(0.5, sphere(1), box(1).translate(1, 0, 0))",
            BOUND,
        ),
        (
            "smooth_union(2, sphere(1), box(1), variant: \"exp\")",
            BOUND,
        ),
        ("sphere(1).round(0.2)", BOUND),
        ("sphere(1).shell(0.1)", BOUND),
        ("capsule().elongate((1, 0, 0))", BOUND),
        ("sphere(0.5).translate(0.2, 0, 0).mirror()", BOUND),
        ("mandelbulb()", UNPROVEN),
        ("ellipsoid((1, 2, 3)).round(0.1)", UNPROVEN),
        ("box((1, 2, 1)).twist(1)", APPROXIMATE),
        ("box((2, 0.2, 0.5)).bend(0.5)", APPROXIMATE),
    ];
    for (p, (e, proven)) in cases {
        let d = root(p);
        assert_eq!((d.facts.exactness, d.proven), (e, proven), "{p}: {d:?}");
    }
}

#[test]
fn a_mirror_of_a_shape_on_its_side_or_symmetric_stays_exact() {
    assert_eq!(
        root("box(1).mirror(x: true, y: true)").facts.exactness,
        Exactness::Exact
    );
    assert_eq!(
        root("sphere(0.5).translate(1, 0, 0).mirror()")
            .facts
            .exactness,
        Exactness::Exact
    );
    assert_eq!(
        root("sphere(0.5).translate(0.2, 0, 0).mirror()")
            .facts
            .exactness,
        Exactness::Bound
    );
}

#[test]
fn twist_and_bend_lipschitz_bounds() {
    // A box of half-extents (0.5, 1, 0.5): ρ = √0.5.
    let rho = 0.5f64.hypot(0.5);
    let d = root("box((0.5, 1, 0.5)).twist(2)");
    assert!(
        (d.facts.lipschitz - twist_stretch(2.0 * rho)).abs() < 1e-12,
        "{d:?}"
    );
    let d = root("box((2, 0.25, 0.5)).bend(0.5)");
    assert!((d.facts.lipschitz - bend_stretch(0.5 * 2f64.hypot(0.25))).abs() < 1e-12);
    // A rounded twist reads the twisted field at level 0.2: ρ grows by 0.2.
    let d = root("box((0.5, 1, 0.5)).twist(2).round(0.2)");
    let rho = 0.7f64.hypot(0.7);
    assert!(
        (d.facts.lipschitz - twist_stretch(2.0 * rho)).abs() < 1e-12,
        "{d:?}"
    );
    // The largest L wins in a union; the cause is the twist.
    let (s, _) = scene("union(sphere(1), box((0.5, 1, 0.5)).twist(2).translate(3, 0, 0))");
    let a = analyse(&s);
    let cause = a.root().and_then(|r| r.cause).expect("a cause");
    assert_eq!(kind(s.graph.node(cause)), "twist");
    assert!(a.step_lipschitz() > 1.5);
}

#[test]
fn warnings_name_the_unreliable_constructs() {
    const NONE: &[&str] = &[];
    // Windows nested in windows multiply (9 × 9 cells): the outer one keeps its own cell.
    let inner = "sphere(0.6).repeat((1, 0, 1), (3, 1, 3))";
    let nested = format!("{inner}.repeat((5, 0, 5))");
    let nested_off = format!("{inner}.translate(0.2, 0, 0.2).repeat((4, 0, 4))");
    let cases: [(&str, &[&str]); 17] = [
        ("sphere(1)", NONE),
        (
            "smooth_union(2, sphere(0.5), box(0.4).translate(1, 0, 0), variant: \"exp\")",
            &["W0002"],
        ),
        (
            "smooth_union(0.1, sphere(0.5), box(0.4).translate(1, 0, 0), variant: \"exp\")",
            NONE,
        ),
        ("box((0.5, 1, 0.5)).twist(4)", &["W0003"]),
        ("box((0.5, 1, 0.5)).twist(0.5)", NONE),
        ("plane((0, 1, 0), 0).twist(0.1)", &["W0004"]),
        // Copies reaching one cell out are evaluated with their neighbours; three cells out
        // on every axis would need 343 cells.
        ("sphere(0.6).repeat((1, 0, 1))", NONE),
        ("sphere(2.5).repeat((1, 1, 1))", &["W0005"]),
        // The repeated field is the exact distance to every copy, so offsetting it is safe.
        ("sphere(0.4).repeat((1, 0, 1)).round(0.2)", NONE),
        ("sphere(0.4).repeat((1, 0, 1))", NONE),
        ("sphere(0.2).translate(0.2, 0, 0).repeat((1, 0, 1))", NONE),
        (&nested, NONE),
        (&nested_off, &["W0006"]),
        // Rounded by 2, the copies must be bounded 2 units out: 125 cells.
        (
            "sphere(0.2).translate(0.2, 0.2, 0.2).repeat((1, 1, 1)).round(2)",
            &["W0006"],
        ),
        ("sphere(0.2).translate(0, 0.2, 0).repeat((1, 0, 1))", NONE),
        ("sphere(1).scale((1, 1, 12))", &["W0007"]),
        ("sphere(1).scale((1, 1, 2))", NONE),
    ];
    for (src, want) in cases {
        assert_eq!(codes(src), want, "{src}");
    }
}

#[test]
fn one_warning_per_construct_in_a_loop() {
    let (scene, diags, _) = check_str(
        "loop.sdf",
        "scene { for i in 0..10 { box((0.5, 1, 0.5)).twist(3 + i).translate(i * 3, 0, 0); } }",
    );
    assert!(scene.is_some());
    assert_eq!(
        diags.iter().filter(|d| d.code == "W0003").count(),
        1,
        "{diags:?}"
    );
}

#[test]
fn the_renderers_l_is_clamped() {
    let (s, _) = scene("plane((0, 1, 0), 0).twist(1)");
    let a = analyse(&s);
    assert!(a.root().expect("root").facts.lipschitz > MAX_STEP_LIPSCHITZ);
    assert_eq!(a.step_lipschitz(), MAX_STEP_LIPSCHITZ);
    let (s, _) = scene("sphere(1)");
    assert_eq!(analyse(&s).step_lipschitz(), 1.0);
}

// ---- Empirical checks on the lowered program ----

/// A point uniform in a box.
fn in_box(rng: &mut Rng, b: &Aabb) -> V3 {
    [0, 1, 2].map(|i| b.min[i] + (b.max[i] - b.min[i]) * rng.uniform())
}

fn f(program: &Program, p: V3) -> f64 {
    eval_point::<f64>(program, p).0
}

/// Marches rays from the sphere around `box` towards random points in it with steps of
/// f / l, and counts the steps that cross the surface (some point sampled along the step
/// is inside).
fn crossings(program: &Program, b: &Aabb, l: f64, rays: usize) -> usize {
    let mut rng = Rng::new(0x9e37_79b9_7f4a_7c15);
    let centre = [0, 1, 2].map(|i| (b.min[i] + b.max[i]) * 0.5);
    let radius = (0..3).map(|i| b.max[i] - b.min[i]).fold(0.0, f64::max) * 1.5;
    let mut bad = 0;
    for _ in 0..rays {
        let target = in_box(&mut rng, b);
        let u = [
            rng.uniform() * 2.0 - 1.0,
            rng.uniform() * 2.0 - 1.0,
            rng.uniform() * 2.0 - 1.0,
        ];
        let n = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt().max(1e-9);
        let o = [0, 1, 2].map(|i| centre[i] + u[i] / n * radius);
        let dir = [0, 1, 2].map(|i| target[i] - o[i]);
        let len = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
        let dir = dir.map(|x| x / len);
        let at = |t: f64| [0, 1, 2].map(|i| o[i] + dir[i] * t);
        let mut t = 0.0;
        for _ in 0..400 {
            let d = f(program, at(t));
            if d < 1e-6 || t > 4.0 * radius {
                break;
            }
            let step = d / l;
            if (1..=24).any(|k| f(program, at(t + step * k as f64 / 24.0)) < -1e-9) {
                bad += 1;
                break;
            }
            t += step;
        }
    }
    bad
}

/// The scene's program as written (no local bounds), its analysis and a box around it.
fn traced(objects: &str) -> (Program, f64, bool, Aabb) {
    let (s, _) = scene(objects);
    let a = analyse(&s);
    let r = *a.root().expect("root");
    let written = LowerOptions {
        local: false,
        ..LowerOptions::default()
    };
    let program = lower_with(&s, &written);
    assert_eq!(program.lipschitz(), a.step_lipschitz());
    (program, r.facts.lipschitz, r.proven, r.bounds.grow(0.1))
}

/// Proven fields of every kind of rule.
const PROVEN: &[&str] = &[
    "box((0.5, 1.5, 0.2)).twist(2)",
    "box((0.5, 1.5, 0.2)).twist(2).round(0.1)",
    "box((1.5, 0.1, 0.4)).bend(1)",
    "smooth_union(1.5, sphere(0.5), box(0.3).translate(1.2, 0, 0), variant: \"exp\")",
    "smooth_subtract(0.8, box(0.8), sphere(0.5).translate(0.5, 0.5, 0), variant: \"exp\")",
    "smooth_union(0.6, box((0.2, 1, 0.2)).twist(3), sphere(0.4))",
    "sphere(1).scale((1, 0.1, 3))",
    "box(0.3).translate(0.5, 0.4, 0).mirror(x: true, y: true)",
    "cone(0.5, 1).elongate((0.3, 0.2, 0))",
    "intersect(sphere(0.3).repeat((1, 1, 1)), box(2))",
    "intersect(sphere(0.4).repeat((1, 0, 1)).round(0.2), box(2))",
    "smooth_subtract(0.3, sphere(1), sphere(0.12).repeat((0.3, 0.3, 0.3)))",
    "sphere(0.45).translate(0.3, 0, 0).repeat((1, 0, 0), (3, 1, 1))",
    "intersect(sphere(0.7).repeat((1, 0, 1)), box(2))",
    "intersect(sphere(0.4).translate(0.2, 0, 0).repeat((1, 0, 1)).round(0.3), box(2))",
];

#[test]
fn steps_of_f_over_l_never_cross_a_proven_surface() {
    for objects in PROVEN {
        let (program, l, proven, b) = traced(objects);
        assert!(proven, "{objects}");
        assert_eq!(crossings(&program, &b, l, 400), 0, "{objects}: L = {l}");
    }
}

#[test]
fn with_local_bounds_steps_of_f_never_cross_a_proven_surface() {
    // Each field alone, and beside a sphere and under a subtraction, so that the operands of
    // combinations are divided by their own L.
    for objects in PROVEN {
        for scene_text in [
            objects.to_string(),
            format!("union({objects}, sphere(0.3).translate(2.5, 0, 0))"),
            format!("subtract({objects}, sphere(0.3).translate(0, 0.4, 0))"),
        ] {
            let (s, _) = scene(&scene_text);
            let program = lower(&s);
            assert_eq!(program.lipschitz(), 1.0, "{scene_text}");
            let b = analyse(&s).root().expect("root").bounds.grow(0.1);
            assert_eq!(crossings(&program, &b, 1.0, 300), 0, "{scene_text}");
        }
    }
}

#[test]
fn the_bounds_are_needed() {
    // Stepping a strongly twisted box with L = 1 crosses its surface.
    let (program, l, _, b) = traced("box((0.5, 1.5, 0.1)).twist(4)");
    assert!(l > 2.0);
    assert!(crossings(&program, &b, 1.0, 150) > 0);
    // So does a repetition whose copies reach too far out of their cells for the neighbours
    // to be evaluated (45 cells), which no L repairs.
    let (program, _, proven, _) =
        traced("sphere(1.2).translate(0.3, 0, 0).repeat((1, 1, 1), (3, 3, 3))");
    assert!(!proven);
    let b = Aabb::centred([2.8, 2.5, 2.5]);
    assert!(crossings(&program, &b, 1.0, 300) > 0);
}

#[test]
fn exact_primitives_have_unit_gradients() {
    for p in [
        "sphere(1)",
        "box((1, 0.5, 0.25))",
        "round_box((1, 0.5, 0.5), 0.2)",
        "torus(1, 0.3)",
        "cylinder(0.5, 1)",
        "capsule(0.4, 1)",
        "cone(0.6, 1.2)",
    ] {
        let (program, _, _, b) = traced(p);
        let b = b.grow(1.0);
        let mut rng = Rng::new(7);
        let h = 1e-6;
        let mut unit = 0;
        for _ in 0..400 {
            let x = in_box(&mut rng, &b);
            let g: Vec<f64> = (0..3)
                .map(|i| {
                    let (mut a, mut c) = (x, x);
                    a[i] += h;
                    c[i] -= h;
                    (f(&program, a) - f(&program, c)) / (2.0 * h)
                })
                .collect();
            let n = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
            assert!(n < 1.0 + 1e-4, "{p}: |∇f| = {n} at {x:?}");
            unit += ((n - 1.0).abs() < 1e-4) as usize;
        }
        // Away from the creases of the distance (a set of measure zero), |∇f| = 1.
        assert!(
            unit >= 390,
            "{p}: {unit} of 400 points have a unit gradient"
        );
    }
}
