//! Helpers shared by the runtime's integration tests: the compiler's test helpers (scenes
//! built in code, random scenes, reference formulas, the diagnostic codes, the examples;
//! one source, in `compiler/tests/compiler/common.rs`) and the wgpu adapter the GPU tests run on.
#![allow(dead_code)]

#[path = "../../../compiler/tests/compiler/common.rs"]
mod scenes;
#[allow(unused_imports)]
pub use scenes::*;

/// A wgpu adapter (lavapipe where there is no GPU), or `None`, saying that `what` skipped;
/// with `SDFC_REQUIRE_DEVICES=1` a missing adapter fails the test instead.
pub fn open_gpu(what: &str) -> Option<sdfc_runtime::gpu::Gpu> {
    match sdfc_runtime::gpu::Gpu::open(false) {
        Ok(g) => Some(g),
        Err(e) => {
            assert!(
                std::env::var("SDFC_REQUIRE_DEVICES").as_deref() != Ok("1"),
                "SDFC_REQUIRE_DEVICES=1 but wgpu found no adapter: {e}"
            );
            println!("SKIPPED: {what}: {e}");
            None
        }
    }
}

/// `scene` rendered by every backend this machine has, each with its name: the CPU always,
/// wgpu where it finds an adapter (required under `SDFC_REQUIRE_DEVICES=1`) and CUDA where it
/// finds a device (required under `SDFC_REQUIRE_CUDA=1`, as on the GPU machine); a missing
/// one is said to have skipped.
pub fn render_everywhere(
    what: &str,
    scene: &sdfc_compiler::Scene,
) -> Vec<(&'static str, sdfc_runtime::image::Image)> {
    use sdfc_runtime::backend::{Backend, Prepared};
    let mut out = Vec::new();
    for (name, backend, required) in [
        ("cpu", Backend::Cpu, true),
        ("wgpu", Backend::Wgpu, env_is("SDFC_REQUIRE_DEVICES")),
        ("cuda", Backend::Cuda, env_is("SDFC_REQUIRE_CUDA")),
    ] {
        let prepared = match Prepared::new(backend, scene, sdfc_runtime::cpu::Precision::F32) {
            Ok(p) => p,
            Err(e) => {
                assert!(!required, "{what}: {name} is required but failed: {e}");
                println!("SKIPPED: {what} on {name}: {e}");
                continue;
            }
        };
        let frame = prepared
            .render(scene, &|_| {})
            .unwrap_or_else(|e| panic!("{what}: {name} render failed: {e}"));
        out.push((name, frame.render.image));
    }
    out
}

/// A scene file loaded and made small: `width`×`height`, one sample per pixel.
#[track_caller]
pub fn load_small(path: &std::path::Path, width: u32, height: u32) -> sdfc_compiler::Scene {
    let mut scene = sdfc_runtime::frontend::load(path)
        .expect("readable")
        .scene
        .unwrap_or_else(|| panic!("{} is a valid scene", path.display()));
    scene.settings.width = width;
    scene.settings.height = height;
    scene.settings.aa = 1;
    scene
}

/// The kernels a scene renders through on a GPU: traced (where it allows it) and marched by
/// the specialised kernel, and marched by the interpreted one.
pub const KERNELS: [(sdfc_compiler::Method, sdfc_compiler::wgsl::KernelChoice); 3] = [
    (
        sdfc_compiler::Method::Auto,
        sdfc_compiler::wgsl::KernelChoice::Specialised,
    ),
    (
        sdfc_compiler::Method::March,
        sdfc_compiler::wgsl::KernelChoice::Specialised,
    ),
    (
        sdfc_compiler::Method::March,
        sdfc_compiler::wgsl::KernelChoice::Interpreted,
    ),
];

/// The kernel `kernel` of `scene` for a software adapter (`software`: lavapipe, whose loops
/// share a budget of iterations) or a GPU, as the runtime writes it (`Setup::software`).
#[track_caller]
pub fn kernel_for(
    scene: &sdfc_compiler::Scene,
    lowered: &sdfc_compiler::Lowered,
    kernel: sdfc_compiler::wgsl::KernelChoice,
    software: bool,
) -> sdfc_compiler::wgsl::Kernel {
    use sdfc_compiler::wgsl;
    let options = wgsl::Options {
        kernel,
        interp_unroll: if software {
            wgsl::interp::UNROLL_SOFTWARE
        } else {
            wgsl::interp::UNROLL
        },
        ..wgsl::Options::default()
    };
    wgsl::write_with(scene, lowered, &options).unwrap_or_else(|e| panic!("{e}"))
}

/// `scene` rendered by the CPU renderer with the default options.
pub fn cpu_render(scene: &sdfc_compiler::Scene) -> sdfc_runtime::cpu::Render {
    sdfc_runtime::cpu::render(
        scene,
        &sdfc_compiler::Lowered::new(scene),
        &sdfc_runtime::cpu::Options::default(),
        &|| {},
    )
}

/// `a` compared with `b` (a pixel differs where a channel is more than `threshold` apart),
/// printed under `label`: the test fails below `min_psnr` dB or where more than
/// `max_differing` of the pixels differ.
#[track_caller]
pub fn assert_agree(
    label: &str,
    (a, b): (&sdfc_runtime::image::Image, &sdfc_runtime::image::Image),
    threshold: f64,
    (min_psnr, max_differing): (f64, f64),
) {
    let d = sdfc_runtime::metrics::compare(a, b, threshold).expect("same size");
    println!(
        "{label}: psnr {:.1} dB, differing {:.4}",
        d.psnr, d.differing
    );
    assert!(
        d.psnr >= min_psnr && d.differing <= max_differing,
        "{label}: psnr {:.1} dB, differing {:.4}",
        d.psnr,
        d.differing
    );
}

/// A plane of the material `floor` (which `materials` declares) seen towards the horizon, on a
/// grey background: the scene with one sample a pixel, the CPU's picture of it with 12×12
/// samples a pixel, and the picture's first row of the floor (down column 80).
pub fn floor_to_the_horizon(
    materials: &str,
) -> (sdfc_compiler::Scene, sdfc_runtime::image::Image, u32) {
    let text = format!(
        "{materials}
camera {{ position: (0, 1, -4), look_at: (0, 0.6, 4), fov: 40deg }}
render {{ width: 160, height: 100, max_dist: 300, background: (0.5, 0.5, 0.5) AA }}
scene {{ plane() @ floor; }}
"
    );
    let one = checked("one sample", &text.replace("AA", ""));
    let many = checked("12×12 samples", &text.replace("AA", ", aa: 12"));
    let truth = cpu_render(&many).image;
    let horizon = (0..one.settings.height)
        .find(|&y| truth.pixel(80, y)[0] != 0.5)
        .expect("the floor");
    (one, truth, horizon)
}

/// `scene` rendered by the CPU backend in `precision`: its image.
pub fn cpu_image(
    scene: &sdfc_compiler::Scene,
    precision: sdfc_runtime::cpu::Precision,
) -> sdfc_runtime::image::Image {
    use sdfc_runtime::backend::{Backend, Prepared};
    let prepared = Prepared::new(Backend::Cpu, scene, precision).expect("the CPU backend");
    prepared
        .render(scene, &|_| {})
        .expect("a CPU render")
        .render
        .image
}

/// Fails, saying `what`, unless every channel of every pixel of `image` in its top-left
/// `size`×`size` square is within `tolerance` of 1 (a white furnace's picture).
#[track_caller]
pub fn assert_white(image: &sdfc_runtime::image::Image, size: u32, tolerance: f32, what: &str) {
    for y in 0..size {
        for x in 0..size {
            for v in image.pixel(x, y) {
                assert!(
                    (v - 1.0).abs() < tolerance,
                    "{what}: ({x}, {y}) is {v}, not 1"
                );
            }
        }
    }
}

/// The words of `line`, split at white space: a command's arguments written as one line.
pub fn words(line: &str) -> Vec<&str> {
    line.split_whitespace().collect()
}

/// The scene of the source text `text` (the file `name`), which must check without errors.
#[track_caller]
pub fn checked(name: &str, text: &str) -> sdfc_compiler::Scene {
    let (scene, diags, _) = sdfc_compiler::check_str(name, text);
    let errors: Vec<_> = diags.iter().filter(|d| d.is_error()).collect();
    assert!(errors.is_empty(), "{name}: {errors:?}");
    scene.unwrap_or_else(|| panic!("{name}: {diags:?}"))
}

/// The output of `command`, run to its end, which must have succeeded: else the test fails,
/// saying `what` and what the command printed.
#[track_caller]
pub fn run_ok(command: &mut std::process::Command, what: &str) -> std::process::Output {
    let out = command
        .output()
        .unwrap_or_else(|e| panic!("{what}: cannot run it: {e}"));
    assert!(
        out.status.success(),
        "{what}: {}\n{}{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn env_is(name: &str) -> bool {
    std::env::var(name).as_deref() == Ok("1")
}

/// The sRGB-encoded grey levels (0 to 1, the mean of the channels) of an image, as a PNG
/// viewer shows them, row by row.
pub fn grey(image: &sdfc_runtime::image::Image) -> Vec<f64> {
    image
        .to_rgba8()
        .chunks(4)
        .map(|c| (c[0] as f64 + c[1] as f64 + c[2] as f64) / (3.0 * 255.0))
        .collect()
}

/// The mean departure of each pixel of the box [x0, x1) × [y0, y1) from the mean of its 3×3
/// neighbourhood: small on smooth shading, large on speckles, streaks and ripples.
pub fn roughness(grey: &[f64], width: u32, (x0, y0, x1, y1): (u32, u32, u32, u32)) -> f64 {
    let at = |x: u32, y: u32| grey[(y * width + x) as usize];
    let mut sum = 0.0;
    for y in y0..y1 {
        for x in x0..x1 {
            let mut around = 0.0;
            for dy in 0..3 {
                for dx in 0..3 {
                    around += at(x + dx - 1, y + dy - 1);
                }
            }
            sum += (at(x, y) - around / 9.0).abs();
        }
    }
    sum / f64::from((x1 - x0) * (y1 - y0))
}
