//! `sdfc render`: its outputs and their formats, the warnings and memory it announces, an
//! interrupt, the devices it renders on (no adapter or driver, a device error mid-render, the
//! pipeline cache, a device opening beside the front end) and the breakdown of `--stats`.

use crate::cli::{
    dir, entries, exits, ok, png_size, put, scene_dir, scene_file, sdfc, wgpu_available,
};
use crate::common::assert_has;
use crate::common::words;
use std::path::Path;
use std::process::{Command, Output};

#[test]
fn render_writes_the_default_output_in_the_current_directory() {
    let d = scene_dir("default");
    let out = ok(&d, &["render", "ball.sdf", "--stats"]);
    assert_eq!(png_size(&d.join("ball.png")), (40, 30));
    assert_eq!(
        entries(&d),
        ["ball.png", "ball.sdf"],
        "no temporary file left"
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_has(&stdout, &["steps/pixel", "overshoots"]);
}

#[test]
fn size_aa_set_and_output_options() {
    let d = scene_dir("options");
    ok(
        &d,
        &words("render ball.sdf --size 24x16 --aa 2 --set max_steps=64 --set epsilon=1e-3 -o x.png --precision f64 --threads 1"),
    );
    assert_eq!(png_size(&d.join("x.png")), (24, 16));
    let out = sdfc(
        &d,
        &[
            "render", "ball.sdf", "--set", "width=8", "--set", "height=6", "-o", "y.png",
        ],
    );
    assert!(out.status.success());
    assert_eq!(png_size(&d.join("y.png")), (8, 6));
}

#[test]
fn render_prints_the_warnings_of_check() {
    let d = dir("warnings");
    put(
        &d,
        "dark.sdf",
        "render { width: 8, height: 6 }\nscene { sphere(1); }\n",
    );
    let out = sdfc(&d, &["render", "dark.sdf"]);
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_has(&err, &["[W0008]", "no lights"]);
}

#[test]
fn outputs_are_written_in_the_format_their_extension_names() {
    let d = scene_dir("formats");
    for name in ["out.jpg", "out.JPEG"] {
        ok(&d, &["render", "ball.sdf", "-o", name]);
        let bytes = std::fs::read(d.join(name)).expect("jpeg");
        assert_eq!(&bytes[..3], &[0xFF, 0xD8, 0xFF], "{name} is not a JPEG");
        assert_eq!(&bytes[bytes.len() - 2..], &[0xFF, 0xD9]);
    }
    // OpenEXR: magic number, version 2 (single-part scanline), a header of 305 bytes, the
    // offset table and 30 rows of 40 float RGB pixels (runtime/src/output.rs).
    ok(&d, &["render", "ball.sdf", "-o", "out.exr"]);
    let exr = std::fs::read(d.join("out.exr")).expect("exr");
    assert_eq!(&exr[..8], &[0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0]);
    assert!(String::from_utf8_lossy(&exr[..100]).contains("channels\0chlist"));
    assert_eq!(exr.len(), 8 + 305 + 30 * 8 + 30 * (8 + 40 * 12));
    // Unknown formats are refused before the render, leaving nothing.
    for name in ["out.tiff", "out"] {
        let out = sdfc(&d, &["render", "ball.sdf", "-o", name]);
        assert_eq!(out.status.code(), Some(2), "{name}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_has(&err, &[".png`, `.jpg`"]);
        assert!(!err.contains("allocating"), "{err}");
    }
    // `-o -`: the PNG on standard output (statistics on standard error), no file named `-`.
    let out = ok(&d, &["render", "ball.sdf", "-o", "-", "--stats"]);
    assert_eq!(&out.stdout[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(
        &out.stdout[out.stdout.len() - 8..out.stdout.len() - 4],
        b"IEND"
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("steps/pixel"));
    let out = sdfc(&d, &["render", "ball.sdf", "-o", "-", "--aux"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        entries(&d),
        ["ball.sdf", "out.JPEG", "out.exr", "out.jpg"],
        "no other file, no temporary file left"
    );
}

/// `sdfc render FILE --backend wgpu` run in `d` where Vulkan finds no driver.
fn on_wgpu_without_adapters(d: &Path, file: &str) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(d)
        .args(["render", file, "--backend", "wgpu"])
        .env("WGPU_BACKEND", "vulkan")
        .env("VK_ICD_FILENAMES", "/nonexistent.json")
        .env("VK_DRIVER_FILES", "/nonexistent.json")
        .output()
        .expect("run sdfc")
}

#[test]
fn no_gpu_adapter_is_a_clear_error() {
    let d = scene_dir("adapter");
    let out = on_wgpu_without_adapters(&d, "ball.sdf");
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_has(&err, &["no wgpu adapter found", "mesa-vulkan-drivers"]);
    assert_eq!(entries(&d), ["ball.sdf"]);
}

#[test]
fn no_cuda_driver_is_a_clear_error() {
    let d = scene_dir("cuda");
    let out = sdfc(&d, &["render", "ball.sdf", "--backend", "cuda"]);
    if out.status.success() {
        println!("SKIPPED: a CUDA driver and device are present here");
        return;
    }
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_has(&err, &["CUDA"]);
    assert_eq!(entries(&d), ["ball.sdf"]);
}

#[test]
fn an_interrupt_stops_a_render_and_leaves_no_file() {
    let d = scene_dir("interrupt");
    let mut child = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&d)
        .args(words(
            "render ball.sdf --backend cpu --size 4000x3000 --aa 4 -o big.png",
        ))
        .spawn()
        .expect("spawn");
    std::thread::sleep(std::time::Duration::from_millis(500));
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill");
    assert!(killed.success());
    let status = child.wait().expect("wait");
    assert!(!status.success());
    assert_eq!(entries(&d), ["ball.sdf"], "no output and no temporary file");
}

#[test]
fn a_render_announces_its_memory_and_stops_above_the_memory_limit() {
    let d = scene_dir("memory");
    let out = sdfc(
        &d,
        &["render", "ball.sdf", "--backend", "cpu", "-o", "a.png"],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert_has(
        &err,
        &["render: 40x30, aa 1, cpu: allocating at most ", " MiB"],
    );
    let err = exits(
        &d,
        &words("render ball.sdf --backend cpu --limit memory=1 --size 2000x2000 -o b.png"),
        1,
    );
    assert_has(
        &err,
        &["more than the memory limit of 1 MiB", "--limit memory="],
    );
    assert_eq!(entries(&d), ["a.png", "ball.sdf"], "no file written");
}

#[test]
fn debug_nan_paints_nan_pixels_magenta_in_the_written_image() {
    let d = dir("debug-nan");
    let scene =
        std::fs::canonicalize("../compiler/tests/in/ok/nan_at_run_time.sdf").expect("scene");
    let scene = scene.to_string_lossy();
    let magenta = |png: &str| {
        let image = sdfc_runtime::image::read_png(&d.join(png)).expect("png");
        image
            .linear
            .iter()
            .filter(|c| c[0] > 0.99 && c[1] < 0.01 && c[2] > 0.99)
            .count()
    };
    for (flag, png) in [(None, "plain.png"), (Some("--debug-nan"), "debug.png")] {
        let mut args = vec!["render", &scene, "--backend", "cpu", "-o", png];
        args.extend(flag);
        ok(&d, &args);
    }
    assert_eq!(magenta("plain.png"), 0);
    assert!(magenta("debug.png") > 100);
}

#[test]
fn a_gpu_error_mid_render_is_one_message_and_leaves_no_file() {
    let d = scene_dir("gpu-fault");
    if !wgpu_available(&d) {
        return;
    }
    // 4100x16 is three tiles of 2048 pixels: the second fails after the first rendered.
    let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&d)
        .args(words("render ball.sdf --backend wgpu --size 4100x16"))
        .args(["-o", "fault.png"])
        .env("SDFC_FAULT_AFTER_TILES", "1")
        // Mesa's window-system code complains on stderr without it.
        .env("XDG_RUNTIME_DIR", &d)
        .output()
        .expect("run sdfc");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    let errors: Vec<&str> = err.lines().filter(|l| l.starts_with("error")).collect();
    assert_eq!(
        errors,
        ["error: GPU error while rendering: device error injected at tile 2 by SDFC_FAULT_AFTER_TILES=1 (a testing aid)"],
        "{err}"
    );
    assert_eq!(entries(&d), ["ball.sdf"], "no output and no temporary file");
}

/// A wgpu render on a Vulkan adapter stores the driver's pipeline cache data for its kernel
/// in the cache directory (`SDFC_CACHE_DIR`, as the CUDA JIT cache), in a file named by the
/// kernel and the device; a second process rendering the same kernel finds it and gives it to
/// the driver, and a render of another kernel gets a file of its own. (Lavapipe stores no
/// compiled code in it, 96 bytes of headers, so this shows the files are found, not that
/// the driver's compile gets faster: that is a GPU's measurement,
/// scripts/device-first-second.sh.) `--stats` also reduces the frame's statistics on the
/// device, whose pipeline keeps a file of its own, the same for every scene.
#[test]
fn a_second_process_finds_the_wgpu_pipeline_cache() {
    let d = scene_dir("pipeline-cache");
    if !wgpu_available(&d) {
        return;
    }
    let cache = d.join("cache");
    let render = |size: &str| {
        let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
            .current_dir(&d)
            .args(["render", "ball.sdf", "--backend", "wgpu", "--stats"])
            .args(["--size", size, "-o", "out.png"])
            .env("SDFC_CACHE_DIR", &cache)
            .env("XDG_RUNTIME_DIR", &d)
            .output()
            .expect("run sdfc");
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let line = text
            .lines()
            .find(|l| l.trim_start().starts_with("driver compile"))
            .unwrap_or_else(|| panic!("no driver compile line: {text}"))
            .to_string();
        (line, entries(&cache))
    };
    let (first, files) = render("16x16");
    assert_has(&first, &["bytes of driver cache data stored"]);
    assert_eq!(
        files.len(),
        2,
        "the kernel's and the reduction's: {files:?}"
    );
    assert!(files.iter().all(|f| f.ends_with(".pipeline")), "{files:?}");
    let (second, again) = render("24x16");
    assert_has(
        &second,
        &["pipeline created from", "bytes of stored driver cache data"],
    );
    assert_eq!(again, files, "the same kernel, the same file");
    // Another kernel (a box in place of the sphere) gets a file of its own.
    let scene = std::fs::read_to_string(d.join("ball.sdf")).expect("scene");
    let boxed = scene.replace("sphere(1)", "box((0.5, 0.5, 0.5))");
    put(&d, "ball.sdf", boxed);
    let (third, more) = render("16x16");
    assert_has(&third, &["stored"]);
    assert_eq!(more.len(), 3, "{more:?}");
}

/// The device opens on a thread of its own while the scene is read and checked (`Opening`):
/// a scene with errors still prints its diagnostics and exits 1 whatever the device does (no
/// adapter, no CUDA driver, or a device still opening when the process ends), and the
/// arguments' own errors still come after the scene's.
#[test]
fn a_scene_with_errors_exits_1_whatever_the_device_does() {
    let d = dir("errors-device");
    put(&d, "broken.sdf", "scene { sphere(; }");
    let diagnostics = |out: &Output| {
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert_has(&err, &["broken.sdf", "E0101"]);
        assert!(!err.contains("adapter") && !err.contains("CUDA"), "{err}");
        err
    };
    // No wgpu adapter at all.
    let no_adapter = on_wgpu_without_adapters(&d, "broken.sdf");
    diagnostics(&no_adapter);
    // Whatever this machine has: a device opening (lavapipe, a GPU) or none.
    for backend in ["wgpu", "cuda", "auto"] {
        let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
            .current_dir(&d)
            .args(["render", "broken.sdf", "--backend", backend, "--stats"])
            .env("XDG_RUNTIME_DIR", &d)
            .output()
            .expect("run sdfc");
        diagnostics(&out);
        assert!(
            out.stdout.is_empty(),
            "no statistics for a scene with errors"
        );
    }
    // Scene errors come before the arguments' (`--reference` renders on the CPU alone).
    let both = sdfc(
        &d,
        &["render", "broken.sdf", "--reference", "--backend", "wgpu"],
    );
    diagnostics(&both);
    scene_file(&d);
    let err = exits(
        &d,
        &["render", "ball.sdf", "--reference", "--backend", "wgpu"],
        2,
    );
    assert_has(&err, &["--reference renders on the CPU in f64"]);
    let kernel = sdfc(
        &d,
        &words("render broken.sdf --backend cpu --kernel interpreted"),
    );
    diagnostics(&kernel);
    assert_eq!(
        entries(&d),
        ["ball.sdf", "broken.sdf"],
        "no image, no temporary file"
    );
}

/// `--stats`'s breakdown of the whole run: its phases add up to its total, a device opened
/// beside the front end says so with its own time, and the image's steps (sRGB, PNG, write,
/// rename; a still is not synced to the disk) are listed; the device is left to the operating system at the end.
#[test]
fn the_run_breakdown_adds_up_and_names_the_overlapped_device() {
    let d = scene_dir("breakdown");
    let backends: &[&str] = if wgpu_available(&d) {
        &["cpu", "wgpu"]
    } else {
        &["cpu"]
    };
    for backend in backends {
        let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
            .current_dir(&d)
            .args(["render", "ball.sdf", "--backend", backend, "--stats"])
            .args(["-o", "out.png"])
            .env("XDG_RUNTIME_DIR", &d)
            .output()
            .expect("run sdfc");
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{text}{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let block: Vec<&str> = text
            .lines()
            .skip_while(|l| !l.starts_with("run "))
            .collect();
        let total: f64 = block[0]
            .split_whitespace()
            .nth(1)
            .expect("total")
            .parse()
            .expect("ms");
        let mut sum = 0.0;
        let mut names = Vec::new();
        for line in &block[1..] {
            let name = line[2..18].trim();
            names.push(name);
            if let Ok(ms) = line[18..]
                .split(" ms")
                .next()
                .expect("ms")
                .trim()
                .parse::<f64>()
            {
                sum += ms;
            }
        }
        // Each phase is rounded to 0.1 ms.
        assert!(
            (sum - total).abs() <= 0.05 * names.len() as f64 + 0.1,
            "{text}"
        );
        for step in ["scene", "sRGB", "PNG", "write", "rename", "image", "exit"] {
            assert!(names.contains(&step), "{step} in {text}");
        }
        // A still image is not synced to the disk (`AtomicFile::unsynced`).
        assert!(!names.contains(&"fsync"), "{text}");
        let device = block.iter().find(|l| l.trim_start().starts_with("device "));
        match *backend {
            "cpu" => assert!(device.is_none(), "{text}"),
            _ => {
                let line = device.expect("a device phase");
                assert!(line.contains("overlapped with the front end"), "{text}");
            }
        }
        assert_eq!(png_size(&d.join("out.png")), (40, 30));
    }
}
