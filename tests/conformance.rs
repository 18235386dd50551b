//! Cross-backend conformance: every example rendered small on wgpu and on the CPU agrees
//! within a stated tolerance. On a machine without a wgpu adapter the test says it skipped,
//! unless `SDFC_REQUIRE_DEVICES=1` (set by CI, which installs lavapipe): then it fails.

use sdfc_compiler::{back::wgsl, lower};
use sdfc_runtime::{cpu, frontend, gpu, metrics};
use std::path::PathBuf;

/// Minimum PSNR (dB) between the wgpu and CPU renders of an example.
const MIN_PSNR: f64 = 30.0;
/// Most pixels allowed to differ by more than [`THRESHOLD`] in some channel.
const MAX_DIFFERING: f64 = 0.02;
/// Per-channel difference that counts a pixel as differing.
const THRESHOLD: f64 = 0.1;

fn examples() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir("../examples")
        .expect("examples/")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "sdf"))
        .collect();
    files.sort();
    files
}

fn open_gpu() -> Option<gpu::Gpu> {
    match gpu::Gpu::open(false) {
        Ok(g) => Some(g),
        Err(e) => {
            assert!(
                std::env::var("SDFC_REQUIRE_DEVICES").as_deref() != Ok("1"),
                "SDFC_REQUIRE_DEVICES=1 but wgpu found no adapter: {e}"
            );
            println!("SKIPPED: wgpu conformance: {e}");
            None
        }
    }
}

#[test]
fn wgpu_matches_cpu_on_every_example() {
    let Some(gpu) = open_gpu() else { return };
    println!("adapter: {}", gpu.describe());
    let mut failures = Vec::new();
    for path in examples() {
        let mut scene = frontend::load(&path)
            .expect("readable")
            .scene
            .expect("valid example");
        scene.settings.width = 96;
        scene.settings.height = 64;
        scene.settings.aa = 1;
        let program = lower::lower(&scene);
        let kernel = wgsl::write(&scene, &program).expect("valid kernel");
        let on_gpu = gpu::render(&gpu, &scene, &kernel, 1.0, &mut |_| {}).expect("gpu render");
        let on_cpu = cpu::render(&scene, &program, &cpu::Options::default(), &|| {});
        let d =
            metrics::compare(&on_gpu.render.image, &on_cpu.image, THRESHOLD).expect("same size");
        println!(
            "{:<14} psnr {:6.1} dB  differing {:.4}  steps/px gpu {:.1} cpu {:.1}",
            path.file_stem().unwrap_or_default().to_string_lossy(),
            d.psnr,
            d.differing,
            on_gpu.render.stats.steps_mean,
            on_cpu.stats.steps_mean
        );
        assert_eq!(
            on_gpu.render.stats.counters.nans,
            0,
            "{}: NaN on the GPU",
            path.display()
        );
        if d.psnr < MIN_PSNR || d.differing > MAX_DIFFERING {
            failures.push(format!(
                "{}: psnr {:.1} dB, differing {:.4}",
                path.display(),
                d.psnr,
                d.differing
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "backends disagree:\n{}",
        failures.join("\n")
    );
}

/// Renders `scene` on wgpu and on the CPU and asserts that they agree within the tolerance.
fn assert_agree(
    gpu: &gpu::Gpu,
    scene: &sdfc_compiler::scene::Scene,
    program: &lower::Program,
    kernel: &wgsl::Kernel,
    label: &str,
) {
    let on_gpu = gpu::render(gpu, scene, kernel, 1.0, &mut |_| {}).expect("gpu render");
    let on_cpu = cpu::render(scene, program, &cpu::Options::default(), &|| {});
    let d = metrics::compare(&on_gpu.render.image, &on_cpu.image, THRESHOLD).expect("same size");
    println!(
        "{label}: psnr {:.1} dB, differing {:.4}",
        d.psnr, d.differing
    );
    assert!(
        d.psnr >= MIN_PSNR && d.differing <= MAX_DIFFERING,
        "{label}: psnr {:.1} dB, differing {:.4}",
        d.psnr,
        d.differing
    );
}

/// A distance program large enough that `map` and `sdf` are cut into functions
/// (examples/scaling/compound_100.sdf, about 15 000 instructions) renders on wgpu as on the
/// CPU.
#[test]
fn a_kernel_with_outlined_blocks_matches_the_cpu() {
    let Some(gpu) = open_gpu() else { return };
    let path = PathBuf::from("../examples/scaling/compound_100.sdf");
    let mut scene = frontend::load(&path)
        .expect("readable")
        .scene
        .expect("valid scene");
    scene.settings.width = 64;
    scene.settings.height = 48;
    scene.settings.aa = 1;
    let program = lower::lower(&scene);
    let kernel = wgsl::write(&scene, &program).expect("valid kernel");
    assert!(kernel.source.contains("fn map_block") && kernel.source.contains("fn sdf_block"));
    assert_agree(&gpu, &scene, &program, &kernel, "compound_100");
}

/// Shadow rays pass through glass on the GPU as on the CPU even when no refracted ray is
/// traced (`max_depth: 0`, so the kernel has no refraction code).
#[test]
fn shadows_through_glass_match_without_secondary_rays() {
    let Some(gpu) = open_gpu() else { return };
    let text = "material glass = phong { transparency: 0.9, ior: 1.5 };\n\
                camera { position: (0, 3, -4), look_at: (0, 0, 0), fov: 50deg }\n\
                light point { position: (0, 6, 0), intensity: 1, radius: 50 }\n\
                render { width: 64, height: 48, max_depth: 0, method: \"march\" }\n\
                scene { plane(); sphere(0.8).translate(0, 1.2, 0) @ glass; }";
    let (scene, diags, _) = sdfc_compiler::check::check_str("glass.sdf", text);
    let scene = scene.unwrap_or_else(|| panic!("{diags:?}"));
    let program = lower::lower(&scene);
    let kernel = wgsl::write(&scene, &program).expect("valid kernel");
    assert!(kernel.features.contains(&("TRANSPARENT", true)));
    assert!(kernel.features.contains(&("REFRACTION", false)));
    assert_agree(&gpu, &scene, &program, &kernel, "glass shadow");
}

/// `--debug-nan` on wgpu: the kernel's `DEBUG_NAN` feature paints the same pixels magenta
/// as the CPU renderer; without it the kernel is the default one and paints none.
#[test]
fn debug_nan_marks_the_same_pixels_on_wgpu() {
    let Some(gpu) = open_gpu() else { return };
    let path = PathBuf::from("../tests/in/ok/nan_at_run_time.sdf");
    let scene = frontend::load(&path)
        .expect("readable")
        .scene
        .expect("valid scene");
    let program = lower::lower(&scene);
    let magenta = |image: &sdfc_runtime::image::Image| -> Vec<bool> {
        image.linear.iter().map(|&c| c == cpu::NAN_COLOUR).collect()
    };
    let plain_kernel = wgsl::write(&scene, &program).expect("valid kernel");
    assert!(!plain_kernel.source.contains("DEBUG_NAN"));
    let plain = gpu::render(&gpu, &scene, &plain_kernel, 1.0, &mut |_| {}).expect("render");
    assert!(plain.render.stats.counters.nans > 0, "no NaN on the GPU");
    assert!(!magenta(&plain.render.image).contains(&true));
    let options = wgsl::Options { debug_nan: true };
    let kernel = wgsl::write_with(&scene, &program, &options).expect("valid kernel");
    assert!(kernel.source.contains("+DEBUG_NAN"));
    let on_gpu = gpu::render(&gpu, &scene, &kernel, 1.0, &mut |_| {}).expect("render");
    let cpu_options = cpu::Options {
        debug_nan: true,
        ..cpu::Options::default()
    };
    let on_cpu = cpu::render(&scene, &program, &cpu_options, &|| {});
    let (g, c) = (magenta(&on_gpu.render.image), magenta(&on_cpu.image));
    let differ = g.iter().zip(&c).filter(|(a, b)| a != b).count();
    let marked = g.iter().filter(|&&m| m).count();
    println!("debug-nan: {marked} magenta pixels on wgpu, {differ} differ from the CPU");
    assert!(marked > 0);
    assert!(
        differ * 50 <= g.len(),
        "{differ} of {} pixels differ",
        g.len()
    );
}
