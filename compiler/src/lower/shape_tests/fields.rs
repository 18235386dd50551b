//! Profile fields (`profile { … }`): made solid they equal the profiles they spell, stay
//! within their recorded bound, random formulas included; misuse as located errors; a warp
//! written as a field keeps its materials.

use super::{f, located_error, point, program, same, slope, within_l};
use crate::eval::eval_point;
use crate::lower::{lower, lower_with, LowerOptions};
use crate::program::Program;
use crate::rng::Rng;
use crate::scene::analysis::analyse;

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
        located_error(src, says, at);
    }
}

/// A random formula of the plane's point, from the operations the bound analysis rules.
fn random_plane_expr(rng: &mut Rng, depth: u32) -> String {
    let leaves = ["p.x", "p.y", "length(p)"];
    let forms = [
        "({a} + {b})",
        "({a} - {b})",
        "({a} * 1.3)",
        "sin({a})",
        "abs({a})",
        "min({a}, {b})",
        "max({a}, {b})",
        "sqrt({a} * {a} + 1)",
        "noise(vec2({a}, {b}))",
        "(sin({a}) * cos({b}))",
        "voronoi(vec2({a}, p.y))",
        "distance(star(5, 0.8, 0.4), vec2({a}, {b}))",
    ];
    rng.formula(depth, &leaves, &forms)
}

/// Random formulas of the plane, extruded and revolved: wherever the analysis proves a
/// bound, sampled slopes of the solid (the field without local bounds) stay within it.
#[test]
fn random_profile_formulas_keep_their_bound_when_made_solid() {
    let mut rng = Rng::new(36);
    let options = LowerOptions {
        local: false,
        ..LowerOptions::default()
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
        let p = lower_with(&scene, &options);
        let mut sample = Rng::new(i);
        let s = slope(&p, &mut sample, 2.0);
        assert!(s <= l * (1.0 + 1e-6), "{shape}: slope {s} above L = {l}");
    }
    assert!(proven > 15, "only {proven} of 30 have a bound");
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
    let program = lower(&scene);
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
    (lower(&scene), 1.0)
}
