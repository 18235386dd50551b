//! Renders that once went wrong, each kept by its test: tapes prepared for a traced render, a
//! constant colour field, a profile written as a formula, a surface near `max_dist`, a warp's
//! materials, a scene beyond the default `max_dist`.

use crate::common;
use crate::render::{small, METHODS};
use common::*;
use sdfc_compiler::{Lowered, Method, Node, Scene};
use sdfc_runtime::cpu::{self, Options, Precision};

/// A traced render evaluates no distance program, so its tapes are never prepared (issue 37:
/// a large traced scene spent most of its preparation on them); a marched render of the
/// same scene prepares them, and both give the image they gave when tapes were prepared up
/// front.
#[test]
fn a_traced_render_prepares_no_tapes() {
    let mut scene = single(Node::Sphere { radius: 1.0 });
    small(&mut scene, 32, 24);
    let lowered = Lowered::new(&scene);
    for (method, marches) in [(Method::Trace, false), (Method::March, true)] {
        scene.settings.method = method;
        let tapes = cpu::Tapes::new(&lowered);
        let r = cpu::render_tapes(&scene, &tapes, &Options::default(), &|| {});
        assert!(
            r.stats.counters.hits > 20,
            "{method:?}: {} hits",
            r.stats.counters.hits
        );
        assert_eq!(tapes.prepared(), marches, "{method:?}");
        let prepared = cpu::Tapes::new(&lowered);
        prepared.prepare();
        let again = cpu::render_tapes(&scene, &prepared, &Options::default(), &|| {});
        assert_eq!(r.image.linear, again.image.linear, "{method:?}");
    }
}

/// A material whose colour (and a checker whose colours) are colour fields of constants
/// renders the image of the plain colours, bit for bit, sphere traced and traced
/// analytically, in f32 and in the f64 reference; a field that varies changes it.
#[test]
fn a_constant_colour_field_renders_as_the_plain_colour() {
    let text = |red: &str, a: &str| {
        format!(
            "material red = phong {{ color: {red}, specular: 0.4 }};\n\
             material floor = checker {{ a: {a}, b: (0.1, 0.12, 0.15), size: 0.5 }};\n\
             camera {{ position: (0, 1.5, -4), look_at: (0, 0.3, 0) }}\n\
             light point {{ position: (3, 5, -4) }}\n\
             render {{ width: 48, height: 32 }}\n\
             scene {{ plane((0, 1, 0), -0.8) @ floor; sphere(1) @ red; }}"
        )
    };
    let scene = |t: &str| {
        let (scene, diags, _) = sdfc_compiler::check_str("colours.sdf", t);
        scene.unwrap_or_else(|| panic!("{diags:?}"))
    };
    let plain = scene(&text("(0.9, 0.2, 0.2)", "(0.9, 0.9, 0.85)"));
    let fields = scene(&text(
        "field { vec3(0.9, 0.2, 0.2) }",
        "field { (0.9, 0.9, 0.85) }",
    ));
    let varying = scene(&text(
        "field { vec3(0.9, 0.2 + 0.2 * sin(8 * p.y), 0.2) }",
        "(0.9, 0.9, 0.85)",
    ));
    for precision in [Precision::F32, Precision::F64] {
        let options = Options {
            precision,
            ..Options::default()
        };
        for method in METHODS {
            let run = |s: &Scene| {
                let mut s = s.clone();
                s.settings.method = method;
                cpu::render(&s, &Lowered::new(&s), &options, &|| {})
                    .image
                    .linear
            };
            let want = run(&plain);
            assert!(
                run(&fields) == want,
                "{precision:?} {method:?}: the constant fields change the image"
            );
            assert!(
                run(&varying) != want,
                "{precision:?} {method:?}: a field that varies"
            );
        }
    }
}

/// A profile written as a formula of the plane's point renders as the built-in profile it
/// spells: `profile { length(p) - r }` extruded and revolved against `circle(r)`, both
/// sphere traced, in f32 and in the f64 reference (the formula is only known to be a bound,
/// the built-in exact: the steps differ, the surfaces do not).
#[test]
fn a_profile_formula_renders_as_the_profile_it_spells() {
    let text = |disc: &str| {
        format!(
            "material red = phong {{ color: (0.9, 0.2, 0.2), specular: 0.4 }};\n\
             camera {{ position: (0, 1.5, -4), look_at: (0, 0, 0) }}\n\
             light point {{ position: (3, 5, -4) }}\n\
             render {{ width: 64, height: 48, method: \"march\" }}\n\
             scene {{ plane((0, 1, 0), -0.8) @ red;\n\
             extrude({disc}, 0.6).rotate_y(30deg).translate(-0.9, 0, 0);\n\
             revolve({disc}.translate(0.6, 0)).translate(1, 0, 0); }}"
        )
    };
    let scene = |t: &str| {
        let (scene, diags, _) = sdfc_compiler::check_str("profile.sdf", t);
        scene.unwrap_or_else(|| panic!("{diags:?}"))
    };
    let built_in = scene(&text("circle(0.5)"));
    let formula = scene(&text("profile { length(p) - 0.5 }"));
    let other = scene(&text("profile { length(p) - 0.45 }"));
    for precision in [Precision::F32, Precision::F64] {
        let options = Options {
            precision,
            ..Options::default()
        };
        let run = |s: &Scene| cpu::render(s, &Lowered::new(s), &options, &|| {}).image;
        let want = run(&built_in);
        let d = sdfc_runtime::metrics::compare(&run(&formula), &want, 0.1).expect("same size");
        println!(
            "{precision:?}: {:.1} dB, {:.4} differing",
            d.psnr, d.differing
        );
        assert!(d.psnr > 60.0 && d.differing == 0.0, "{precision:?}: {d:?}");
        // A different radius is seen.
        let d = sdfc_runtime::metrics::compare(&run(&other), &want, 0.1).expect("same size");
        assert!(d.psnr < 40.0, "{precision:?}: {d:?}");
    }
}

/// The fraction of `image`'s pixels that are not the background.
fn coverage(image: &sdfc_runtime::image::Image, background: [f64; 3]) -> f64 {
    let off = |c: &[f32; 3]| (0..3).any(|i| (f64::from(c[i]) - background[i]).abs() > 0.02);
    image.linear.iter().filter(|c| off(c)).count() as f64 / image.linear.len() as f64
}

/// A marched surface 73 units away, within the default `max_dist` of 100, is seen on every
/// backend: the first over-relaxed step (ω·73 > 100) crosses `max_dist`, and only a step the
/// march has verified may end the ray as a miss (docs/rendering.md, "Marching").
#[test]
fn a_surface_near_max_dist_is_not_lost_to_a_relaxed_step() {
    let text = "camera { position: (0, 0, -74), look_at: (0, 0, 0), fov: 3deg }\n\
                render { width: 32, height: 24, method: \"march\" }\n\
                scene { sphere(1).round(0.01); }";
    let (scene, diags, _) = sdfc_compiler::check_str("far.sdf", text);
    let scene = scene.unwrap_or_else(|| panic!("{diags:?}"));
    assert!(scene.settings.relaxation > 1.0 && scene.settings.max_dist == 100.0);
    for (backend, image) in render_everywhere("far sphere", &scene) {
        let c = coverage(&image, scene.settings.background);
        println!("{backend}: {:.1} % of pixels on the sphere", 100.0 * c);
        assert!(
            c > 0.15,
            "{backend}: the sphere covers {:.3} of the picture",
            c
        );
    }
}

/// A warp written as a field, `distance(s, q)`, shows `s`'s materials on every backend: the
/// red sphere stays red (it rendered all grey, the default material).
#[test]
fn a_warp_written_as_a_field_shows_the_warped_shapes_materials() {
    let text = "material red = phong { color: (0.9, 0.1, 0.1) };\n\
                material grey = phong { color: (0.5, 0.5, 0.5) };\n\
                camera { position: (0, 1, -4), look_at: (0.7, 0, 0), fov: 50deg }\n\
                light point { position: (2, 4, -4) }\n\
                render { width: 48, height: 32 }\n\
                let s = union(sphere(0.5) @ red, box(0.3).translate(1.5, 0, 0) @ grey);\n\
                scene { field { distance(s, vec3(p.x, p.y + 0.2 * sin(3 * p.x), p.z)) }; }";
    let (scene, diags, _) = sdfc_compiler::check_str("warp.sdf", text);
    let scene = scene.unwrap_or_else(|| panic!("{diags:?}"));
    for (backend, image) in render_everywhere("warp", &scene) {
        let red = image
            .linear
            .iter()
            .filter(|c| c[0] > 0.2 && c[0] > 3.0 * c[1])
            .count();
        let grey = image
            .linear
            .iter()
            .filter(|c| c[0] > 0.1 && (c[0] - c[1]).abs() < 0.02)
            .count();
        println!("{backend}: {red} red and {grey} grey pixels");
        assert!(red > 20 && grey > 10, "{backend}: {red} red, {grey} grey");
    }
}

/// A scene whose bounded parts lie beyond the default `max_dist` of 100 is seen (the default
/// covers them from the camera) on every backend: it was an empty picture without a word.
#[test]
fn a_scene_beyond_a_hundred_units_is_seen_with_the_default_max_dist() {
    let text = "camera { position: (0, 0, -150), look_at: (0, 0, 0), fov: 3deg }\n\
                light point { position: (0, 10, -100) }\n\
                render { width: 32, height: 24 }\n\
                scene { sphere(3); }";
    let (scene, diags, _) = sdfc_compiler::check_str("far.sdf", text);
    let scene = scene.unwrap_or_else(|| panic!("{diags:?}"));
    for (backend, image) in render_everywhere("far scene", &scene) {
        let c = coverage(&image, scene.settings.background);
        println!("{backend}: {:.1} % of pixels on the sphere", 100.0 * c);
        assert!(
            c > 0.08,
            "{backend}: the sphere covers {c:.3} of the picture"
        );
    }
}
