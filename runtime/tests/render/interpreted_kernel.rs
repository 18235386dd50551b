//! The interpreted kernel (compiler/src/back/wgsl/interp.rs): its text is the same for every
//! scene of one specialisation; through wgpu (lavapipe) it renders every example and random
//! scenes as the specialised kernel does; `auto` chooses it for large programs only; and the
//! combinations that cannot work are refused with a clear error. Without a wgpu adapter the
//! image tests say they skipped, unless `SDFC_REQUIRE_DEVICES=1`.

use crate::common;
use crate::common::assert_has;
use crate::common::words;

use common::{kernel_for, random_scene};
use sdfc_compiler::{
    wgsl::{self, KernelChoice, Options},
    Lowered, Method, Rng, Scene,
};
use sdfc_runtime::{frontend, gpu, metrics};
use std::path::Path;
use std::process::Command;

/// The images of the two kernels agree to at least this PSNR (dB) and no pixel differs by
/// more than [`THRESHOLD`] in more than [`MOST_DIFFERING`] of the pixels. Each operation of
/// the interpreter is the expression the code writer writes for it, on the same f32 values,
/// so the two compute the same distances, except where the shader compiler contracts the
/// code's products and sums into fused multiply-adds or reassociates its constants, which the
/// interpreter's one operation per step cannot: a distance then differs in its last bits,
/// and a ray that grazes a surface, or runs out of steps near one, can end one step apart.
/// On lavapipe (2026-11-24, 48×32) the examples agree to 53 dB or more, five of eleven bit
/// for bit, and the random scenes to 96 dB or more; a wrong operation or register costs whole
/// objects, below 40 dB (before `interp::UNROLL`, lavapipe's loop limit cut examples/lattice.sdf
/// to 39 dB and 1.2 % of pixels).
const MIN_PSNR: f64 = 45.0;
const MOST_DIFFERING: f64 = 0.005;
const THRESHOLD: f64 = 0.1;

fn open_gpu() -> Option<gpu::Gpu> {
    common::open_gpu("interpreted kernel on wgpu")
}

/// An example, marched (an analytically traced scene has no distance program in its
/// kernel), at `width`×`height` with one sample per pixel.
fn marched(path: &Path, width: u32, height: u32) -> Scene {
    let mut scene = common::load_small(path, width, height);
    scene.settings.method = Method::March;
    // A path-traced example (examples/studio_path.sdf: 64 samples) would cost lavapipe a
    // minute through the interpreted kernel; four samples follow the same paths' code.
    scene.settings.samples = scene.settings.samples.min(PATH_SAMPLES);
    scene
}

/// The samples a pixel of a path-traced example compared here.
const PATH_SAMPLES: u32 = 4;

fn kernel(scene: &Scene, lowered: &Lowered, kernel: KernelChoice) -> wgsl::Kernel {
    kernel_for(scene, lowered, kernel, false)
}

/// The examples, and the one that imports a triangle mesh (examples/mesh/import.sdf).
fn examples() -> Vec<std::path::PathBuf> {
    let mut all = common::examples();
    all.push("../examples/mesh/import.sdf".into());
    all
}

#[test]
fn the_text_depends_on_the_specialisation_alone() {
    // Scenes of the same features (lights, materials, settings) share one kernel however
    // different their programs.
    let mut rng = Rng::new(23);
    let mut texts = std::collections::BTreeSet::new();
    let mut programs = std::collections::BTreeSet::new();
    for n in 1..8 {
        let scene = random_scene(&mut rng, n);
        let lowered = Lowered::new(&scene);
        let k = kernel(&scene, &lowered, KernelChoice::Interpreted);
        assert!(k.interpreted() && k.data.is_some());
        assert!(!k.source.contains("fn map_block") && k.source.contains("fn interpret("));
        texts.insert(k.source);
        programs.insert(lowered.program.dump());
    }
    assert_eq!(texts.len(), 1, "one kernel for every random scene");
    assert!(programs.len() > 5, "the programs differ");
    // Every example's interpreted kernel validates, and so do the media's entry points.
    let mut media = false;
    for path in examples() {
        let scene = marched(&path, 32, 24);
        let lowered = Lowered::new(&scene);
        let k = kernel(&scene, &lowered, KernelChoice::Interpreted);
        media |= k.source.contains("fn sdf_medium(");
        println!(
            "{}: {} instructions, {} live as code, {} registers",
            path.display(),
            lowered.program.len(),
            wgsl::code_size(&scene, &lowered, &Options::default()),
            wgsl::interp::registers(&lowered.program)
        );
        let specialised = kernel(&scene, &lowered, KernelChoice::Specialised);
        assert!(!specialised.interpreted());
        let set = |k: &wgsl::Kernel| {
            k.contract
                .features
                .iter()
                .filter(|f| f.1 && !["INTERPRETED", "PARAMS", "SCENE_DATA"].contains(&f.0))
                .map(|f| f.0)
                .collect::<std::collections::BTreeSet<_>>()
        };
        assert_eq!(
            set(&k),
            set(&specialised),
            "{}: the same features",
            path.display()
        );
    }
    assert!(media, "an example has glass over solids");
}

#[test]
fn auto_interprets_large_programs_only() {
    let choose_with = |path: &str, method: Option<Method>, max_instances: usize| {
        let mut scene = frontend::load(Path::new(path)).unwrap().scene.unwrap();
        if let Some(m) = method {
            scene.settings.method = m;
        }
        let lowered = Lowered::new(&scene);
        let options = Options {
            kernel: KernelChoice::Auto,
            max_instances,
            ..Options::default()
        };
        let size = wgsl::code_size(&scene, &lowered, &options);
        (wgsl::choose(&scene, &lowered, &options).unwrap(), size)
    };
    let choose = |path: &str, method| choose_with(path, method, wgsl::MAX_INSTANCES);
    let (kind, size) = choose("../examples/seed3.sdf", None);
    assert_eq!(kind, wgsl::KernelKind::Specialised, "seed3: {size}");
    // lattice's 400 spheres are walked from scene_data (the rest is small); written as code
    // they are a large program.
    let (kind, size) = choose("../examples/lattice.sdf", None);
    assert!(
        size < wgsl::interp::AUTO_INTERPRET,
        "lattice's rest: {size}"
    );
    assert_eq!(kind, wgsl::KernelKind::Specialised);
    let (kind, size) = choose_with("../examples/lattice.sdf", None, usize::MAX);
    assert!(
        size >= wgsl::interp::AUTO_INTERPRET,
        "lattice as code: {size}"
    );
    assert_eq!(kind, wgsl::KernelKind::Interpreted);
    // A traced scene has no program in its kernel; marched, its program is small.
    let (kind, _) = choose("../examples/seed2.sdf", None);
    assert_eq!(kind, wgsl::KernelKind::Specialised);
    // compound_1000's instances are read from scene_data: the rest written as code is small.
    let (kind, size) = choose("../examples/scaling/compound_1000.sdf", Some(Method::March));
    assert!(
        size < wgsl::interp::AUTO_INTERPRET,
        "compound_1000's rest: {size}"
    );
    assert_eq!(kind, wgsl::KernelKind::Specialised);
}

/// 600 hollow spheres: a shell is not an instance the walk knows, so the whole program (about
/// 9 300 instructions) is written as code.
const SHELLS: &str = "camera { position: (0, 4, -12), look_at: (0, 0, 0), fov: 50deg }
light point { position: (4, 8, -6), intensity: 1 }
render { width: 32, height: 24, method: \"march\" }
scene {
  plane((0, 1, 0), -1);
  for i in 0..600 { sphere(0.2).shell(0.04).translate(i % 30 * 0.5 - 7.5, 0, i / 30 * 0.5); }
}
";

#[test]
fn auto_keeps_the_specialised_kernel_on_a_cpu_adapter_on_cuda_and_for_sequences() {
    use sdfc_runtime::backend::{Prepared, Setup};
    let (scene, diags, _) = sdfc_compiler::check_str("shells.sdf", SHELLS);
    let scene = scene.unwrap_or_else(|| panic!("{diags:?}"));
    let lowered = Lowered::new(&scene);
    let options = Options {
        kernel: KernelChoice::Auto,
        ..Options::default()
    };
    assert!(wgsl::code_size(&scene, &lowered, &options) >= wgsl::interp::AUTO_INTERPRET);
    assert_eq!(
        wgsl::choose(&scene, &lowered, &options).unwrap(),
        wgsl::KernelKind::Interpreted,
        "the compiler's rule"
    );
    let Some(gpu) = open_gpu() else { return };
    let gpu = std::sync::Arc::new(gpu);
    let sequence = Setup {
        parameters: true,
        ..Setup::default()
    };
    let prepared = Prepared::on_gpu(gpu.clone(), &scene, &lowered, &sequence).expect("prepared");
    assert_eq!(prepared.kernel_kind(), Some("specialised"), "a sequence");
    let prepared =
        Prepared::on_gpu(gpu.clone(), &scene, &lowered, &Setup::default()).expect("prepared");
    let want = if gpu.is_cpu() {
        "specialised"
    } else {
        "interpreted"
    };
    assert_eq!(prepared.kernel_kind(), Some(want));
}

/// Renders `scene` with both kernels and asserts that the images agree; returns the PSNR.
fn assert_same(gpu: &gpu::Gpu, scene: &Scene, label: &str) -> f64 {
    let lowered = Lowered::new(scene);
    let specialised = kernel(scene, &lowered, KernelChoice::Specialised);
    let interpreted = kernel_for(scene, &lowered, KernelChoice::Interpreted, gpu.is_cpu());
    let l = lowered.program.lipschitz();
    let a = gpu::render(gpu, scene, &specialised, l, &mut |_| {}).expect("render");
    let b = gpu::render(gpu, scene, &interpreted, l, &mut |_| {}).expect("render");
    let d = metrics::compare(&a.render.image, &b.render.image, THRESHOLD).expect("same size");
    let same = a
        .render
        .image
        .linear
        .iter()
        .zip(&b.render.image.linear)
        .filter(|(x, y)| x == y)
        .count();
    println!(
        "{label:<24} psnr {:6.1} dB  differing {:.4}  bit-equal pixels {same}/{}  steps {} / {}",
        d.psnr,
        d.differing,
        a.render.image.linear.len(),
        a.render.stats.counters.steps,
        b.render.stats.counters.steps
    );
    assert_eq!(b.render.stats.counters.nans, a.render.stats.counters.nans);
    assert!(
        d.psnr >= MIN_PSNR && d.differing <= MOST_DIFFERING,
        "{label}: psnr {:.1} dB (at least {MIN_PSNR}), differing {:.4} (at most {MOST_DIFFERING})",
        d.psnr,
        d.differing
    );
    d.psnr
}

/// Every `SHARDS`th example from `shard` on: most of the time is the software adapter's
/// compiling of each example's specialised kernel, so the examples are split over tests that
/// the harness runs side by side.
fn examples_render_as_with_the_specialised_kernel(shard: usize) {
    let Some(gpu) = open_gpu() else { return };
    println!("adapter: {}", gpu.describe());
    for path in examples().into_iter().skip(shard).step_by(SHARDS) {
        let scene = marched(&path, 48, 32);
        let name = path.file_stem().unwrap_or_default().to_string_lossy();
        assert_same(&gpu, &scene, &name);
    }
}

const SHARDS: usize = 3;

#[test]
fn every_example_renders_as_with_the_specialised_kernel_0() {
    examples_render_as_with_the_specialised_kernel(0);
}

#[test]
fn every_example_renders_as_with_the_specialised_kernel_1() {
    examples_render_as_with_the_specialised_kernel(1);
}

#[test]
fn every_example_renders_as_with_the_specialised_kernel_2() {
    examples_render_as_with_the_specialised_kernel(2);
}

#[test]
fn random_scenes_render_as_with_the_specialised_kernel() {
    let Some(gpu) = open_gpu() else { return };
    let mut rng = Rng::new(2026);
    for case in 0..12 {
        let mut scene = random_scene(&mut rng, 1 + case % 6);
        scene.lights.push(sdfc_compiler::Light::Point {
            position: [3.0, 6.0, -4.0],
            color: [1.0; 3],
            intensity: 1.0,
            radius: 100.0,
            penumbra: if case % 2 == 0 { 0.1 } else { 0.0 },
            shadows: true,
        });
        scene.settings.width = 48;
        scene.settings.height = 32;
        scene.settings.aa = 1;
        assert_same(&gpu, &scene, &format!("random scene {case}"));
    }
}

fn sdfc(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .args(args)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .expect("sdfc runs");
    let text = String::from_utf8_lossy(&out.stderr).into_owned();
    (out.status.code().unwrap_or(-1), text)
}

#[test]
fn bad_combinations_are_refused() {
    let dir = std::env::temp_dir().join(format!("sdfc-interpreted-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("x.png");
    let out = out.to_str().unwrap();
    // The CPU has no GPU kernel.
    for cmd in [
        vec!["render", "../examples/seed3.sdf", "--backend", "cpu"],
        vec!["bench", "../examples/seed3.sdf", "--backend", "cpu"],
    ] {
        let mut args = cmd.clone();
        args.extend(["--kernel", "interpreted", "-o", out]);
        if cmd[0] == "bench" {
            args.truncate(args.len() - 2);
        }
        let (code, err) = sdfc(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert_has(&err, &["--kernel interpreted chooses a GPU kernel"]);
    }
    // A traced scene has no distance program to interpret.
    let (code, err) = sdfc(&words(
        "compile ../examples/seed2.sdf --emit wgsl --kernel interpreted",
    ));
    assert_eq!(code, 1, "{err}");
    assert_has(&err, &["traced analytically", "--set method=march"]);
    // Through `render` too, whatever the backend, and never by falling back to the CPU.
    for backend in ["auto", "wgpu"] {
        let (code, err) = sdfc(&[
            "render",
            "../examples/seed2.sdf",
            "--backend",
            backend,
            "--kernel",
            "interpreted",
            "-o",
            out,
        ]);
        assert_eq!(code, 1, "{err}");
        assert_has(&err, &["traced analytically"]);
        assert!(!Path::new(out).exists());
    }
    // Too few registers: the error names the limit that raises it.
    let (code, err) = sdfc(&words(
        "compile ../examples/seed3.sdf --emit wgsl --kernel interpreted --limit registers=2",
    ));
    assert_eq!(code, 1, "{err}");
    assert_has(
        &err,
        &["registers and the kernel has 2", "--limit registers="],
    );
    // `--kernel` goes with the kernel's targets only.
    let (code, err) = sdfc(&words(
        "compile ../examples/seed3.sdf --emit program --kernel interpreted",
    ));
    assert_eq!(code, 2, "{err}");
    assert_has(&err, &["`--kernel` chooses the renderer kernel"]);
    // The interpreted kernel's scene data is the program's words.
    let (code, err) = sdfc(&[
        "compile",
        "../examples/seed3.sdf",
        "--emit",
        "scene-data",
        "--kernel",
        "interpreted",
        "-o",
        dir.join("data.bin").to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let data = std::fs::read(dir.join("data.bin")).unwrap();
    assert!(data.len() > 32 && data.len() % 16 == 0);
    let _ = std::fs::remove_dir_all(&dir);
}
