//! The path tracer (docs/rendering.md, "Path tracing") on every backend: the white furnace,
//! noise falling as 1/√samples against a converged f64 render, the backends' agreement
//! picture for picture (one random stream: CPU f32, the f64 reference, wgpu on lavapipe, and
//! the PTX of the same kernels assembled by ptxas), and the analytic and sphere-traced paths
//! giving the same picture.

use crate::common;
use crate::evaluators;

use common::{checked, cpu_image, render_everywhere};
use sdfc_compiler::{Lowered, Method, Scene};
use sdfc_runtime::cpu::Precision;
use sdfc_runtime::image::Image;
use sdfc_runtime::metrics;
use std::path::Path;

/// The PSNR of `a` against `b`.
fn psnr(a: &Image, b: &Image) -> f64 {
    metrics::compare(a, b, 0.1).expect("same size").psnr
}

/// The kernel of `scene` translated to PTX and, where `ptxas` is on PATH, assembled for
/// sm_80 (required under SDFC_REQUIRE_DEVICES=1, as the CI's ptx test does).
fn assembles(what: &str, scene: &Scene) {
    let lowered = Lowered::new(scene);
    let kernel = sdfc_compiler::wgsl::write(scene, &lowered).expect("the kernel");
    assert!(kernel.contract.has("PATH"), "{what}: a path tracing kernel");
    let options = sdfc_compiler::ptx::Options {
        sm: 80,
        entry_point: "main".into(),
    };
    let text = sdfc_compiler::ptx::write(&kernel.module, &kernel.info, &options)
        .unwrap_or_else(|e| panic!("{what}: {e}"))
        .text;
    let Some(ptxas) = evaluators::ptxas() else {
        assert!(
            std::env::var("SDFC_REQUIRE_DEVICES").as_deref() != Ok("1"),
            "SDFC_REQUIRE_DEVICES=1 but no ptxas on PATH"
        );
        println!("SKIPPED: {what}: no ptxas on PATH");
        return;
    };
    let path = std::env::temp_dir().join(format!("sdfc_path_{what}_{}.ptx", std::process::id()));
    std::fs::write(&path, &text).unwrap();
    evaluators::assemble(&ptxas, &path, Path::new("/dev/null"), what);
    let _ = std::fs::remove_file(&path);
}

/// A sphere of the material `MAT` under a sky of radiance 1 all round, which is also the
/// background, path traced.
const FURNACE: &str = "
material m = MAT;
camera { position: (0, 2, -4), look_at: (0, 0, 0), fov: 40deg }
light sky { color: (1, 1, 1) }
render { width: 32, height: 32, method: \"path\", samples: SAMPLES, bounces: 4, tonemap: \"none\" }
scene { sphere(1) @ m; }
";

fn furnace(mat: &str, samples: u32) -> Scene {
    checked(
        "furnace",
        &FURNACE
            .replace("MAT", mat)
            .replace("SAMPLES", &samples.to_string()),
    )
}

/// Every image of `scene`: the backends of [`render_everywhere`] and the f64 reference.
fn everywhere(what: &str, scene: &Scene) -> Vec<(&'static str, Image)> {
    let mut out = render_everywhere(what, scene);
    out.push(("f64", cpu_image(scene, Precision::F64)));
    out
}

/// The pixels a grey sphere of the furnace covers (darker than the sky).
fn sphere_pixels() -> Vec<(u32, u32)> {
    let grey = furnace(
        "phong { color: (0.5, 0.5, 0.5), ambient: 0, diffuse: 1, specular: 0 }",
        4,
    );
    let image = cpu_image(&grey, Precision::F32);
    let on: Vec<(u32, u32)> = (0..32)
        .flat_map(|y| (0..32).map(move |x| (x, y)))
        .filter(|&(x, y)| image.pixel(x, y)[0] < 0.9)
        .collect();
    assert!(on.len() > 150, "the sphere covers {}", on.len());
    on
}

/// The white furnace: a diffuse sphere of albedo 1 under a uniform sky of radiance 1 is 1 at
/// every pixel (its light is the sky's, reflected whole: the sky's estimate and the BRDF's
/// path each give 1, weighed by their MIS weights, which sum to 1), on every backend; a rough
/// white metal is not above 1 (single scattering loses energy: 0.6 to 1 over the sphere).
#[test]
fn the_white_furnace_holds_when_path_traced() {
    let on = sphere_pixels();
    let white = furnace(
        "phong { color: (1, 1, 1), ambient: 0, diffuse: 1, specular: 0 }",
        4,
    );
    for (backend, image) in everywhere("white furnace", &white) {
        common::assert_white(&image, 32, 1e-4, backend);
    }
    let metal = furnace(
        "pbr { base_color: (1, 1, 1), metallic: 1, roughness: 0.6 }",
        64,
    );
    for (backend, image) in everywhere("metal furnace", &metal) {
        let values: Vec<f64> = on
            .iter()
            .map(|&(x, y)| image.pixel(x, y)[1] as f64)
            .collect();
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        let most = values.iter().copied().fold(0.0, f64::max);
        println!("{backend}: rough metal mean {mean:.4}, most {most:.4}");
        assert!(
            (0.6..1.0).contains(&mean),
            "{backend}: the rough metal's mean is {mean}"
        );
        assert!(most < 1.08, "{backend}: a pixel of the metal is {most}");
    }
}

/// A ball on a floor, lit by a sky, a point light and the ball's light on the floor and back:
/// traced analytically (no soft light), diffuse, so that its noise has no outliers.
const BALL: &str = "
material ground = phong { color: (0.7, 0.7, 0.65), ambient: 0, diffuse: 1, specular: 0 };
material ball = pbr { base_color: (0.8, 0.3, 0.2), roughness: 0.6 };
camera { position: (0, 1.5, -4), look_at: (0, 0.5, 0), fov: 45deg }
light sky { zenith: (0.3, 0.45, 0.8), horizon: (0.8, 0.85, 0.9), ground: (0.3, 0.3, 0.3) }
light point { position: (2, 3, -1), intensity: 0.6 }
render { width: 48, height: 36, method: \"path\", samples: 4, bounces: 3, tonemap: \"none\" }
scene {
  plane() @ ground;
  sphere(0.6).translate(0, 0.6, 0) @ ball;
}
";

/// Noise falls as 1/√samples: against an f64 render of 1024 samples, the PSNR of CPU renders
/// of 4 to 64 samples rises by 3.01 dB per doubling (each within 0.6 dB of it; the reference's
/// own noise, 1/16 of the 64-sample render's variance, costs that one 0.26 dB), and by
/// 12.04 dB within 1 dB over the four doublings. (Measured 2026-12-06: 27.81, 31.20, 34.05,
/// 36.88 and 40.25 dB.)
#[test]
fn noise_falls_as_one_over_the_root_of_the_samples() {
    let mut scene = checked("ball", BALL);
    assert!(
        Lowered::new(&scene)
            .traceable
            .traced(Method::Auto)
            .is_some(),
        "the ball is traced analytically"
    );
    scene.settings.samples = 1024;
    let reference = cpu_image(&scene, Precision::F64);
    let mut last = None;
    let mut first = None;
    for samples in [4, 8, 16, 32, 64] {
        scene.settings.samples = samples;
        let db = psnr(&cpu_image(&scene, Precision::F32), &reference);
        println!("{samples} samples: {db:.2} dB");
        if let Some(before) = last {
            let gain: f64 = db - before;
            assert!(
                (gain - 3.01).abs() < 0.6,
                "{samples} samples: {gain:.2} dB more than half as many"
            );
        }
        last = Some(db);
        first = first.or(Some(db));
    }
    let total = last.unwrap() - first.unwrap();
    assert!(
        (total - 4.0 * 3.01).abs() < 1.0,
        "4 to 64 samples: {total:.2} dB"
    );
}

/// The studio in small: pbr plastics and metals, glass, an emitting ball, a checker floor, a
/// sky and a sun (a disc: sphere traced), path traced.
fn studio() -> Scene {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/studio_path.sdf");
    // One sample a pixel (the file sets no `aa`), four paths each.
    let mut scene = common::load_small(&path, 64, 36);
    scene.settings.samples = 4;
    scene
}

/// The backends draw the same random numbers, so their pictures agree within rounding: the
/// studio (sphere traced) and the ball (traced) on the CPU in f32, in f64, through wgpu, each
/// against the CPU (PSNR at least 45 dB, at most 0.5 % of pixels off by 0.1), and their
/// kernels translated to PTX that ptxas assembles.
#[test]
fn the_backends_agree_picture_for_picture() {
    for (what, scene) in [("studio", studio()), ("ball", checked("ball", BALL))] {
        let images = everywhere(what, &scene);
        let (_, cpu_image) = &images[0];
        for (backend, image) in &images[1..] {
            let d = metrics::compare(image, cpu_image, 0.1).expect("same size");
            println!(
                "{what}: {backend} against the CPU: {:.1} dB, {:.4} of pixels",
                d.psnr, d.differing
            );
            assert!(
                d.psnr > 45.0 && d.differing < 0.005,
                "{what}: {backend} differs from the CPU: {d:?}"
            );
        }
        assembles(what, &scene);
    }
}

/// The analytic and the sphere-traced paths give the same picture where both apply: the
/// ball and a glass box beside it, traced and marched (PSNR at least 40 dB).
#[test]
fn traced_and_marched_paths_agree() {
    let materials = "material glass = pbr { base_color: (0.95, 1, 0.97), roughness: 0, transmission: 1, ior: 1.5 };\nmaterial gold = pbr { base_color: (1, 0.78, 0.34), metallic: 1, roughness: 0.3 };\n";
    let text = materials.to_string()
        + &BALL.replace(
        "  sphere(0.6).translate(0, 0.6, 0) @ ball;",
        "  sphere(0.6).translate(0, 0.6, 0) @ ball;\n  box((0.4, 0.5, 0.4)).translate(-1.3, 0.5, 0.3) @ glass;\n  sphere(0.3).translate(1.2, 0.3, -0.4) @ gold;",
        );
    let mut scene = checked("ball and glass", &text);
    assert!(Lowered::new(&scene)
        .traceable
        .traced(Method::Auto)
        .is_some());
    scene.settings.samples = 16;
    let traced = cpu_image(&scene, Precision::F32);
    scene.settings.method = Method::March;
    assert!(scene.settings.path, "still path traced");
    let marched = cpu_image(&scene, Precision::F32);
    let d = metrics::compare(&traced, &marched, 0.1).expect("same size");
    println!(
        "traced against marched: {:.1} dB, {:.4} of pixels",
        d.psnr, d.differing
    );
    assert!(d.psnr > 40.0, "traced and marched differ: {d:?}");
}
