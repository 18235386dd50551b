//! Meshes traced analytically (issue 52, item 1): a mesh used as it is read, placed by
//! translations, rotations and scales in a plain union, is met ray by triangle through its
//! hierarchy (docs/mesh.md, "Traced"); the picture is the sphere-traced one, the same on the
//! CPU (f32 and the f64 reference) and through wgpu, and PTX assembles where `ptxas` is on the
//! PATH. A mesh that is rounded, or a light with a penumbra, keeps the scene marched.

use super::common::{assert_agree, cpu_render, open_gpu, run_ok};
use super::meshes::{dir, root, s, write_scene};
use crate::common::assert_has;
use sdfc_compiler::{
    analytic::{choose, Choice, Reason},
    wgsl, Lowered, Method, Scene,
};
use sdfc_runtime::{cpu, frontend, gpu, metrics};
use std::path::Path;

/// The scene: the bracket meshed at resolution 40, turned, scaled and moved, twice (the
/// same mesh placed as two primitives), beside a sphere, on a floor, lit without penumbra.
fn scene_text(shape: &str, penumbra: &str) -> String {
    format!(
        "material steel = phong {{ color: (0.62, 0.64, 0.7), specular: 0.6, shininess: 64 }};
material brass = phong {{ color: (0.8, 0.6, 0.25), specular: 0.8, shininess: 48 }};
material floor = phong {{ color: (0.8, 0.8, 0.8) }};
camera {{ position: (1.8, 1.5, -2.4), look_at: (0, 0.1, 0), fov: 45deg }}
light point {{ position: (-2, 4, -3), intensity: 1.1{penumbra} }}
light directional {{ direction: (1, -1, 0.5), color: (0.3, 0.3, 0.3) }}
render {{ width: 160, height: 120, max_depth: 0 }}
scene {{
  {shape} @ steel;
  mesh(\"part.stl\").rotate_y(30deg).scale(0.5).translate(-0.9, -0.2, 0.6) @ brass;
  sphere(0.2).translate(0.8, -0.22, -0.5) @ brass;
  plane((0, 1, 0), -0.42) @ floor;
}}
"
    )
}

fn load(path: &Path) -> Scene {
    frontend::load(path)
        .expect("readable")
        .scene
        .expect("a valid scene")
}

/// The bracket's mesh and a scene around it, in a directory of its own.
fn setup(name: &str, shape: &str, penumbra: &str) -> Scene {
    let d = dir(name);
    let part = d.join("part.stl");
    if !part.exists() {
        let bracket = root().join("examples/mesh/bracket.sdf");
        super::meshes::mesh(&[s(&bracket), "--resolution", "40", "-o", s(&part)]);
    }
    load(&write_scene(&d, "scene.sdf", &scene_text(shape, penumbra)))
}

#[test]
fn a_mesh_as_read_is_traced_as_it_is_marched() {
    let mut scene = setup("traced-mesh", "mesh(\"part.stl\")", "");
    match choose(&scene) {
        Choice::Trace(p) => assert_eq!(p.len(), 4),
        other => panic!("not traced: {other:?}"),
    }
    let traced = cpu_render(&scene);
    assert_eq!(traced.stats.counters.steps, 0, "traced with steps");
    let f64_options = cpu::Options {
        precision: cpu::Precision::F64,
        ..cpu::Options::default()
    };
    let reference = cpu::render(&scene, &Lowered::new(&scene), &f64_options, &|| {}).image;
    scene.settings.method = Method::March;
    let marched = cpu_render(&scene);
    assert!(marched.stats.counters.steps > 0);
    for (what, image, psnr) in [
        ("marched", &marched.image, 55.0),
        ("f64", &reference, 100.0),
    ] {
        let d = metrics::compare(&traced.image, image, 0.1).expect("same size");
        println!(
            "traced against {what}: {:.1} dB, {:.4} differing",
            d.psnr, d.differing
        );
        assert!(
            d.psnr >= psnr && d.differing <= 0.005,
            "traced against {what}: {:.1} dB, {:.4} differing",
            d.psnr,
            d.differing
        );
    }
}

#[test]
fn wgpu_traces_a_mesh_as_the_cpu_does() {
    let scene = setup("traced-mesh-gpu", "mesh(\"part.stl\")", "");
    let lowered = Lowered::new(&scene);
    let kernel = wgsl::write(&scene, &lowered).expect("a valid kernel");
    assert!(kernel.source.contains("fn mesh_interval("));
    assert!(!kernel.source.contains("fn map("));
    if let Some(ptxas) = which_ptxas() {
        let options = sdfc_compiler::ptx::Options::default();
        let ptx = sdfc_compiler::ptx::write(&kernel.module, &kernel.info, &options).expect("PTX");
        let d = dir("traced-mesh-ptx");
        let file = d.join("k.ptx");
        std::fs::write(&file, ptx.text).expect("write");
        run_ok(
            std::process::Command::new(ptxas).args([
                "-arch=sm_90",
                s(&file),
                "-o",
                s(&d.join("k.cubin")),
            ]),
            "ptxas runs",
        );
    }
    wgpu_agrees_with_cpu(
        "traced mesh",
        (&scene, &kernel),
        "wgpu against cpu",
        (95.0, 0.0005),
    );
}

/// `ptxas` on the PATH (required under `SDFC_REQUIRE_DEVICES=1`).
fn which_ptxas() -> Option<std::path::PathBuf> {
    let found = std::env::var_os("PATH").and_then(|p| {
        std::env::split_paths(&p)
            .map(|d| d.join("ptxas"))
            .find(|f| f.is_file())
    });
    assert!(
        found.is_some() || std::env::var("SDFC_REQUIRE_DEVICES").as_deref() != Ok("1"),
        "SDFC_REQUIRE_DEVICES=1 but no ptxas on PATH"
    );
    found
}

/// A traced scene's meshes are held to the `scene_data` limit as a marched scene's are: the
/// kernel is refused before it is written, naming the limit (the traced kernel skipped the
/// check when first written, then was refused as an invalid kernel, "internal compiler
/// error", by `sdfc compile` and `sdfc render`).
#[test]
fn a_traced_mesh_is_held_to_the_scene_data_limit() {
    let mut scene = setup("traced-mesh-limit", "mesh(\"part.stl\")", "");
    scene
        .limits
        .set(sdfc_compiler::Limit::SceneData, 1)
        .expect("a limit");
    let lowered = Lowered::new(&scene);
    assert!(matches!(choose(&scene), Choice::Trace(_)));
    let refused = wgsl::choose(&scene, &lowered, &wgsl::Options::default())
        .expect_err("refused before the kernel is written");
    assert!(
        matches!(refused, wgsl::Refused::MeshData { limit: 1, .. }),
        "{refused}"
    );
    // The file `setup` wrote (`dir` would empty its directory).
    let scene_file = std::env::temp_dir()
        .join(format!(
            "sdfc-mesh-traced-mesh-limit-{}",
            std::process::id()
        ))
        .join("scene.sdf");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .args([
            "compile",
            "--emit",
            "wgsl",
            "--limit",
            "scene_data=1",
            s(&scene_file),
        ])
        .output()
        .expect("sdfc runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert_has(&stderr, &["above the scene_data limit of 1 MiB"]);
    assert!(!stderr.contains("internal compiler error"), "{stderr}");
    let e = wgsl::write(&scene, &lowered).expect_err("above the limit");
    assert!(
        e.message.contains("scene_data limit of 1 MiB"),
        "{}",
        e.message
    );
}

#[test]
fn a_changed_mesh_or_a_penumbra_is_marched() {
    let rounded = setup("traced-mesh-round", "mesh(\"part.stl\").round(0.02)", "");
    match choose(&rounded) {
        Choice::March(Reason::Node { what, .. }) => assert_eq!(what, "round"),
        other => panic!("rounded: {other:?}"),
    }
    let soft = setup("traced-mesh-soft", "mesh(\"part.stl\")", ", penumbra: 3deg");
    assert_eq!(choose(&soft), Choice::March(Reason::SoftLight { index: 0 }));
}

/// Path tracing a traced scene whose mesh and sphere are scaled: the kernel's path tracer and
/// the intervals of framed primitives each had a `fn to_world`, so such a kernel did not
/// validate (found with this test's scene); the path-traced picture through wgpu is the CPU's.
#[test]
fn a_path_traced_scaled_mesh_has_a_kernel() {
    let d = dir("traced-mesh-path");
    let part = d.join("part.stl");
    let bracket = root().join("examples/mesh/bracket.sdf");
    super::meshes::mesh(&[s(&bracket), "--resolution", "24", "-o", s(&part)]);
    let text = "material glass = pbr { base_color: (0.95, 1, 0.97), roughness: 0, transmission: 1, ior: 1.5 };
material gold = pbr { base_color: (1, 0.78, 0.34), metallic: 1, roughness: 0.25 };
material floor = pbr { base_color: (0.6, 0.6, 0.6), roughness: 0.8 };
camera { position: (1.8, 1.5, -2.4), look_at: (0, 0.1, 0), fov: 45deg }
light sky { zenith: (0.12, 0.28, 0.7), horizon: (0.6, 0.7, 0.85), ground: (0.45, 0.44, 0.42) }
light directional { direction: (-0.5, -1, 0.8), color: (1, 0.92, 0.8) }
render { width: 96, height: 64, method: \"path\", samples: 4, bounces: 3 }
scene {
  mesh(\"part.stl\") @ gold;
  mesh(\"part.stl\").scale(0.5).translate(-0.8, -0.2, -0.5) @ glass;
  sphere(0.3).scale(0.5).translate(0.8, -0.27, -0.5) @ gold;
  plane((0, 1, 0), -0.42) @ floor;
}
";
    let scene = load(&write_scene(&d, "scene.sdf", text));
    assert!(matches!(choose(&scene), Choice::Trace(_)));
    let lowered = Lowered::new(&scene);
    let kernel = wgsl::write(&scene, &lowered).expect("a valid kernel");
    wgpu_agrees_with_cpu(
        "path-traced mesh",
        (&scene, &kernel),
        "path traced, wgpu against cpu",
        (80.0, 0.0005),
    );
}

/// `scene` rendered through `kernel` by wgpu (where there is an adapter, else the test `what`
/// skips) against the CPU's render: `label`, and at least `bounds` (PSNR, most pixels
/// differing by 0.1) alike.
fn wgpu_agrees_with_cpu(
    what: &str,
    (scene, kernel): (&Scene, &wgsl::Kernel),
    label: &str,
    bounds: (f64, f64),
) {
    let Some(gpu) = open_gpu(what) else {
        return;
    };
    let on_gpu = gpu::render(&gpu, scene, kernel, 1.0, &mut |_| {}).expect("gpu render");
    let on_cpu = cpu_render(scene);
    assert_agree(label, (&on_gpu.render.image, &on_cpu.image), 0.1, bounds);
}
