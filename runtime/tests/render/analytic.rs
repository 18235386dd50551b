//! Analytic ray tracing (issue 9): which scenes the compiler traces analytically and why,
//! traced images against sphere-traced ones of the same file, and the kernel it emits.

use crate::common;
use crate::common::assert_has;
use sdfc_compiler::{
    analytic::{choose, Choice, Reason},
    wgsl, Method, Scene,
};
use sdfc_runtime::{frontend, metrics};
use std::path::Path;

/// The conformance tolerance of image_conformance.rs: PSNR, differing fraction, threshold.
const MIN_PSNR: f64 = 30.0;
const MAX_DIFFERING: f64 = 0.02;
const THRESHOLD: f64 = 0.1;

fn load(name: &str) -> Scene {
    let path = Path::new("../examples").join(name);
    frontend::load(&path)
        .expect("readable")
        .scene
        .expect("valid example")
}

#[test]
fn the_report_scenes_1_and_2_are_traced_analytically() {
    for (name, count) in [("seed1.sdf", 3), ("seed2.sdf", 5), ("primitives.sdf", 8)] {
        match choose(&load(name)) {
            Choice::Trace(p) => assert_eq!(p.len(), count, "{name}"),
            other => panic!("{name}: {other:?}"),
        }
    }
}

#[test]
fn other_scenes_are_sphere_traced_with_a_reason() {
    assert!(matches!(
        choose(&load("seed3.sdf")),
        Choice::March(Reason::SoftLight { index: 0 })
    ));
    match choose(&load("glass.sdf")) {
        Choice::March(Reason::Node { what, .. }) => assert_eq!(what, "torus"),
        other => panic!("glass: {other:?}"),
    }
    let mut scene = load("seed1.sdf");
    scene.settings.method = Method::March;
    assert_eq!(choose(&scene), Choice::March(Reason::Asked));
}

/// Scenes 1 and 2 and the primitives example, traced and marched on the CPU, agree within
/// the conformance tolerance; the traced render takes no marching steps.
#[test]
fn traced_images_agree_with_marched_ones() {
    for name in ["seed1.sdf", "seed2.sdf", "primitives.sdf"] {
        let mut scene = load(name);
        scene.settings.width = 256;
        scene.settings.height = 160;
        let render = common::cpu_render;
        let traced = render(&scene);
        scene.settings.method = Method::March;
        let marched = render(&scene);
        assert_eq!(traced.stats.counters.steps, 0, "{name}: traced with steps");
        assert!(marched.stats.counters.steps > 0);
        assert!(traced.stats.counters.hits > 0);
        let pair = (&traced.image, &marched.image);
        common::assert_agree(name, pair, THRESHOLD, (MIN_PSNR, MAX_DIFFERING));
    }
}

/// Glass sunk into the floor, a glass box standing on it (its bottom face lies on the floor)
/// and a glass capsule lying on it (issue 24, item 2) are traced, and the picture is the
/// sphere-traced one: rays inside the glass stop at the floor within it and shade it. The
/// bounds pin down the box's bottom: when its face won the tie with the floor, the rays
/// refracted out of it started inside the floor and missed, speckling the box (35.9 dB and
/// 0.25 % of pixels differing, against 40.0 dB and 0.15 % with the tie going to the floor).
#[test]
fn glass_on_the_floor_is_traced_as_it_is_marched() {
    let text = "material glass = phong { color: (1, 1, 1), transparency: 0.9, ior: 1.5, reflect: 0.05 };\n\
                material floor = checker { a: (0.9, 0.9, 0.9), b: (0.1, 0.1, 0.1), size: 0.5, reflect: 0.2 };\n\
                material red = phong { color: (0.9, 0.2, 0.1), specular: 0.5, shininess: 30 };\n\
                camera { position: (0, 1.5, -3), look_at: (0, 0.2, 0), fov: 50deg }\n\
                light point { position: (2, 5, -3) }\n\
                render { width: 320, height: 240, max_depth: 4 }\n\
                scene {\n\
                  plane((0, 1, 0), 0) @ floor;\n\
                  sphere(0.8) @ glass;\n\
                  box((0.3, 0.3, 0.3)).rotate_y(30deg).translate(-1.4, 0.3, 0.5) @ glass;\n\
                  capsule(0.15, 1.0).rotate_z(90deg).translate(-0.2, 0.1, -1.0) @ glass;\n\
                  sphere(0.35).translate(1.3, 0.35, 0.2) @ red;\n\
                }";
    let (scene, diags, _) = sdfc_compiler::check_str("sunk.sdf", text);
    let mut scene = scene.unwrap_or_else(|| panic!("{diags:?}"));
    assert!(matches!(choose(&scene), Choice::Trace(_)));
    let render = common::cpu_render;
    let traced = render(&scene);
    scene.settings.method = Method::March;
    let marched = render(&scene);
    assert_eq!(traced.stats.counters.steps, 0);
    let d = metrics::compare(&traced.image, &marched.image, THRESHOLD).expect("same size");
    println!("psnr {:.2} dB, differing {:.4}", d.psnr, d.differing);
    assert!(
        d.psnr >= 38.0 && d.differing <= 0.002,
        "psnr {:.2} dB, differing {:.4}",
        d.psnr,
        d.differing
    );
}

/// A traced scene's kernel has no distance field and no marching loop: one `nearest` and
/// one `occlude` per primitive instead.
#[test]
fn a_traced_kernel_emits_intersections_instead_of_a_field() {
    let scene = load("primitives.sdf");
    let kernel =
        wgsl::write(&scene, &sdfc_compiler::Lowered::new(&scene)).expect("naga accepts it");
    let src = &kernel.source;
    assert!(!src.contains("fn map(") && !src.contains("fn sdf("));
    assert!(!src.contains("fn tolerance("));
    assert_eq!(src.matches("best = nearest(").count(), 8);
    assert_eq!(src.matches("through = occlude(").count(), 8);
    assert!(kernel.contract.features.contains(&("ANALYTIC", true)));
    assert!(src.contains("fn capsule_interval(") && src.contains("fn enters("));
    // Only the interval functions a scene uses: spheres and a plane in scene 1.
    let seed1 = load("seed1.sdf");
    let kernel =
        wgsl::write(&seed1, &sdfc_compiler::Lowered::new(&seed1)).expect("naga accepts it");
    let fns: Vec<&str> = kernel
        .source
        .lines()
        .filter_map(|l| l.strip_prefix("fn "))
        .filter_map(|l| l.split('(').next())
        .filter(|name| {
            name.ends_with("_interval")
                || ["slab", "clip", "enters", "into", "to_world"].contains(name)
        })
        .collect();
    assert_eq!(fns, ["sphere_interval", "plane_interval"]);
    let mut marched = scene.clone();
    marched.settings.method = Method::March;
    let kernel =
        wgsl::write(&marched, &sdfc_compiler::Lowered::new(&marched)).expect("naga accepts it");
    assert!(kernel.source.contains("fn sdf(") && !kernel.source.contains("Interval"));
}

/// Rays inside a transparent solid stop at the nearer of its far side and an opaque
/// primitive's entry, which is the surface they meet when glass overlaps only opaque
/// primitives: such glass is traced. Inside two overlapping glass primitives the far side of
/// one may lie inside the other, so glass that overlaps or touches other glass is sphere
/// traced; opaque solids may overlap freely.
#[test]
fn only_glass_touching_other_glass_is_sphere_traced() {
    let choice = |objects: &str| {
        let text = format!(
            "material glass = phong {{ transparency: 0.9, ior: 1.5 }};\n\
             material clay = phong {{ color: (0.8, 0.4, 0.2) }};\nscene {{ {objects} }}"
        );
        let (scene, diags, _) = sdfc_compiler::check_str("t.sdf", &text);
        choose(&scene.unwrap_or_else(|| panic!("{diags:?}")))
    };
    let overlap = |c: &Choice| matches!(c, Choice::March(Reason::Overlap { .. }));
    let traced = |c: &Choice| matches!(c, Choice::Trace(_));
    assert!(overlap(&choice(
        "sphere(1) @ glass; sphere(1).translate(1, 0, 0) @ glass;"
    )));
    assert!(overlap(&choice(
        "plane() @ glass; sphere(0.5).translate(3, 0, 0) @ glass; sphere(0.5) @ clay;"
    )));
    assert!(overlap(&choice(
        "plane() @ clay; box((0.5, 0.5, 0.5)).translate(0, 0.5, 0) @ glass; \
         box((0.5, 0.5, 0.5)).translate(1, 0.5, 0) @ glass;"
    )));
    assert!(traced(&choice("sphere(1) @ glass; sphere(0.3) @ clay;")));
    assert!(traced(&choice(
        "plane() @ clay; box((0.5, 0.5, 0.5)).translate(0, 0.5, 0) @ glass;"
    )));
    assert!(traced(&choice(
        "plane((0, 1, 0), -1).rotate_x(5deg) @ clay; sphere(0.5).translate(0, -0.6, 0) @ glass;"
    )));
    assert!(traced(&choice(
        "plane() @ glass; sphere(0.5) @ clay; box((1, 1, 1)).translate(4, 0, 0) @ clay;"
    )));
    assert!(traced(&choice(
        "plane() @ clay; sphere(0.5).translate(0, 0.6, 0) @ glass; sphere(0.3).translate(2, 0.3, 0) @ clay;"
    )));
    assert!(traced(&choice(
        "plane() @ clay; sphere(1) @ clay; sphere(0.6).translate(0.5, 0, 0) @ clay;"
    )));
}

/// Beyond `MAX_UNROLLED` primitives the kernel reads them from `scene_data` instead of
/// holding them: the kernels of 1 000 and 10 000 random spheres are the same text, a few
/// hundred lines whose PTX is small, while the scene data grows with the scene (32 bytes a
/// sphere and 32 a group, fewer groups than spheres). `auto` traces both.
#[test]
fn the_kernel_of_ten_thousand_spheres_stays_small() {
    let kernel = |name: &str| {
        let scene = load(name);
        let n = choose(&scene).primitives().map(<[_]>::len);
        let kernel =
            wgsl::write(&scene, &sdfc_compiler::Lowered::new(&scene)).expect("naga accepts it");
        (n, kernel)
    };
    let (n, large) = kernel("scaling/random_10000.sdf");
    assert_eq!(n, Some(10_001), "random_10000 is traced");
    let (_, small) = kernel("scaling/random_1000.sdf");
    const { assert!(wgsl::MAX_UNROLLED < 1000) };
    assert_eq!(large.source, small.source);
    assert!(large.source.len() < 24_000, "{} bytes", large.source.len());
    assert!(!large.source.contains("if enters(o - vec3"));
    let data = large.data.as_ref().expect("scene data").len();
    println!(
        "random_10000: {} bytes of WGSL, {data} bytes of scene data",
        large.source.len()
    );
    assert!((32 * 10_001..64 * 10_001).contains(&data), "{data} bytes");
    let options = sdfc_compiler::ptx::Options::default();
    let ptx = sdfc_compiler::ptx::write(&large.module, &large.info, &options)
        .expect("translates")
        .text;
    println!("random_10000: {} lines of PTX", ptx.lines().count());
    assert!(
        ptx.lines().count() < 4_000,
        "{} lines of PTX",
        ptx.lines().count()
    );
    // Up to the threshold the intersections stay unrolled, and there is no buffer.
    let (_, seed2) = kernel("seed2.sdf");
    assert!(seed2.data.is_none() && !seed2.source.contains("scene_data"));
}

/// issue 16, item 2: the check that no glass primitive overlaps another walks the
/// bounding-volume hierarchy instead of every pair: 40 000 glass spheres on a grid (1.6·10⁹
/// pairs) are chosen for tracing in a moment, and one touching pair among them is still
/// found. The `traced` limit moves where `auto` stops tracing.
#[test]
fn glass_overlap_is_found_through_the_hierarchy_and_traced_is_a_limit() {
    let grid = |extra: &str| {
        format!(
            "material glass = phong {{ color: (1, 1, 1), transparency: 0.9, ior: 1.5 }};
             scene {{
               for i in 0..200 {{ for j in 0..200 {{ sphere(0.3).translate(i, 0, j) @ glass; }} }}
               {extra}
             }}"
        )
    };
    let check = |text: &str| {
        let (scene, diags, _) = sdfc_compiler::check_str("glass.sdf", text);
        scene.unwrap_or_else(|| panic!("{diags:?}"))
    };
    let apart = check(&grid(""));
    let start = std::time::Instant::now();
    let n = choose(&apart).primitives().map(<[_]>::len);
    let took = start.elapsed();
    assert_eq!(n, Some(40_000));
    assert!(took.as_secs_f64() < 5.0, "took {took:?}");
    // One more glass sphere touching the glass sphere at (150, 0, 70); an opaque one is
    // traced.
    let touching = check(&grid("sphere(0.3).translate(150.5, 0, 70) @ glass;"));
    let opaque = check(&grid("sphere(0.3).translate(150.5, 0, 70);"));
    assert!(matches!(choose(&opaque), Choice::Trace(_)));
    assert!(
        matches!(choose(&touching), Choice::March(Reason::Overlap { .. })),
        "the touching pair is found"
    );
    // Fewer traced primitives allowed than the scene has: marched, naming the limit.
    let mut limited = apart.clone();
    limited
        .limits
        .set(sdfc_compiler::Limit::Traced, 1_000)
        .expect("valid");
    match choose(&limited) {
        Choice::March(
            r @ Reason::Many {
                count: 40_000,
                limit: 1_000,
            },
        ) => {
            let plain = r.describe();
            assert_has(&plain, &["`traced` limit of 1000"]);
            let spelled = r.describe_in(&limited.limits);
            assert_has(&spelled, &["--limit traced=40000"]);
        }
        other => panic!("{other:?}"),
    }
}
