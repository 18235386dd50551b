//! Several devices (`--devices`, docs/devices.md) with what this machine has: lavapipe opened
//! twice as two logical devices renders every example bit for bit as one device does, and so
//! does a sequence; the CPU beside lavapipe agrees with lavapipe within the conformance
//! tolerance (the CPU renderer is another implementation); a device that fails hands its tile
//! back and the render completes on the other, with a warning, and when every device fails
//! the render fails with each device's error; `sdfc devices` lists the adapter and the CPU;
//! a bad `--devices` entry is named in the error. Without a wgpu adapter the tests say they
//! skipped, unless `SDFC_REQUIRE_DEVICES=1` (set by CI, which installs lavapipe).

use crate::common;
use crate::common::assert_has;
use common::load_small;

use sdfc_compiler::{wgsl, Lowered};
use sdfc_runtime::gpu::launch::Worker;
use sdfc_runtime::{cpu, gpu, metrics};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn open_gpu() -> Option<gpu::Gpu> {
    common::open_gpu("several devices")
}

fn bits(image: &sdfc_runtime::image::Image) -> Vec<u32> {
    image
        .linear
        .iter()
        .flat_map(|p| p.iter().map(|c| c.to_bits()))
        .collect()
}

#[test]
fn two_logical_devices_render_every_example_bit_for_bit_as_one() {
    let (Some(a), Some(b)) = (open_gpu(), open_gpu()) else {
        return;
    };
    // An odd size: bands of unequal height, the last one short.
    for path in common::examples() {
        let scene = load_small(&path, 131, 97);
        let lowered = Lowered::new(&scene);
        let l = lowered.program.lipschitz();
        let kernel = wgsl::write(&scene, &lowered).expect("valid kernel");
        let one = gpu::render(&a, &scene, &kernel, l, &mut |_| {}).expect("one device");
        let ka = a.kernel(&kernel.source, wgsl::ENTRY_POINT, wgsl::WORKGROUP);
        let kb = b.kernel(&kernel.source, wgsl::ENTRY_POINT, wgsl::WORKGROUP);
        let workers: [&dyn Worker; 2] = [&ka, &kb];
        let mut calls = 0;
        let none = gpu::launch::Faults::default();
        let data = kernel.data.as_deref();
        let two = gpu::render_several(
            &workers,
            &scene,
            (l, Some(&kernel.contract.uniform), data),
            (&none, true, false),
            &mut |_| calls += 1,
        )
        .expect("two devices");
        let name = path.display();
        assert!(
            bits(&one.render.image) == bits(&two.render.image),
            "{name}: the images differ"
        );
        assert_eq!(one.render.stats, two.render.stats, "{name}: statistics");
        assert_eq!(two.shares.len(), 2);
        let tiles: usize = two.shares.iter().map(|s| s.tiles).sum();
        assert!(tiles >= 8, "{name}: {tiles} bands for two devices");
        assert_eq!(calls, tiles, "{name}: progress once per band");
        assert!(two.shares.iter().all(|s| s.failure.is_none()));
        // The pixels the kernel finishes (clamped, sRGB-encoded) are the host's encoding of
        // its linear colours, bit for bit: on one device, and assembled from two devices'
        // bands.
        let srgb = one.render.image.to_rgba8();
        let finished = |r: gpu::GpuRender| r.finished.expect("finished pixels").bytes;
        let alone = gpu::render_faults(&a, &scene, &kernel, l, (&none, false, true), &mut |_| {})
            .expect("finished on one device");
        assert!(
            alone.render.image.linear.is_empty(),
            "{name}: no linear image"
        );
        assert!(finished(alone) == srgb, "{name}: finished pixels differ");
        let banded = gpu::render_several(
            &workers,
            &scene,
            (l, Some(&kernel.contract.uniform), data),
            (&none, false, true),
            &mut |_| {},
        )
        .expect("finished on two devices");
        assert!(finished(banded) == srgb, "{name}: finished bands differ");
    }
}

/// The statistics a frame reports are reduced on the device (`gpu::reduce`): they are the
/// host's sums of the per-pixel statistics read back whole, percentile included.
#[test]
fn statistics_reduced_on_the_device_are_the_hosts_sums() {
    let Some(a) = open_gpu() else { return };
    for (name, aa) in [("seed3", 2), ("seed6", 1), ("glass", 1)] {
        let path = PathBuf::from(format!("../examples/{name}.sdf"));
        let mut scene = load_small(&path, 131, 97);
        scene.settings.aa = aa;
        let lowered = Lowered::new(&scene);
        let l = lowered.program.lipschitz();
        let kernel = wgsl::write(&scene, &lowered).expect("valid kernel");
        let frame = gpu::render(&a, &scene, &kernel, l, &mut |_| {}).expect("lavapipe");
        let words = a
            .last_statistics(131 * 97)
            .expect("read back")
            .expect("the frame's buffers are kept");
        let (mut counters, steps) = gpu::counters(&words);
        counters.camera_rays = frame.render.stats.counters.camera_rays;
        let host = cpu::Stats::new(counters, &steps);
        assert!(
            host.counters.steps > 0 && host.steps_p99 > 0,
            "{name}: {host:?}"
        );
        assert_eq!(frame.render.stats, host, "{name}");
    }
}

#[test]
fn the_cpu_beside_lavapipe_agrees_with_lavapipe_alone() {
    let Some(a) = open_gpu() else { return };
    // Measured on lavapipe (LLVM 15, 2026-11-24): 54.1, 126.1 and 52.9 dB; the CPU's share of
    // the bands varies from run to run, so the bounds are those of the CPU alone against
    // lavapipe (image_conformance.rs) less a margin.
    for (name, min_psnr) in [("seed3", 45.0), ("seed6", 90.0), ("glass", 38.0)] {
        let path = PathBuf::from(format!("../examples/{name}.sdf"));
        let scene = load_small(&path, 96, 64);
        let lowered = Lowered::new(&scene);
        let l = lowered.program.lipschitz();
        let kernel = wgsl::write(&scene, &lowered).expect("valid kernel");
        let one = gpu::render(&a, &scene, &kernel, l, &mut |_| {}).expect("lavapipe");
        let tapes = cpu::Tapes::new(&lowered);
        let options = cpu::Options {
            lipschitz: l,
            ..cpu::Options::default()
        };
        let on_cpu = gpu::cpu::Device::new(&scene, &tapes, &options);
        let ka = a.kernel(&kernel.source, wgsl::ENTRY_POINT, wgsl::WORKGROUP);
        let workers: [&dyn Worker; 2] = [&on_cpu, &ka];
        let none = gpu::launch::Faults::default();
        let data = kernel.data.as_deref();
        // Which device takes which band depends on the threads' timing: a device may take
        // every band before the other starts. The render is repeated, up to five times, until
        // both devices rendered bands; that render must agree with lavapipe's.
        let render = || {
            gpu::render_several(
                &workers,
                &scene,
                (l, Some(&kernel.contract.uniform), data),
                (&none, true, false),
                &mut |_| {},
            )
            .expect("cpu and lavapipe")
        };
        let mut mixed = render();
        for _ in 1..5 {
            if mixed.shares.iter().all(|s| s.tiles > 0) {
                break;
            }
            mixed = render();
        }
        assert!(
            mixed.shares.iter().all(|s| s.tiles > 0),
            "{name}: both rendered in one of five renders"
        );
        let d = metrics::compare(&one.render.image, &mixed.render.image, 0.1).expect("same size");
        println!(
            "{name}: cpu + lavapipe against lavapipe: {:.1} dB, {:.4} differing",
            d.psnr, d.differing
        );
        assert!(d.psnr >= min_psnr, "{name}: {:.1} dB", d.psnr);
        assert!(d.differing <= 0.002, "{name}: {:.4} differing", d.differing);
        // The CPU's bands are the CPU renderer's pixels: the whole CPU render has them.
        let alone = cpu::render(&scene, &lowered, &options, &|| {});
        let rows = mixed.shares[0].tiles;
        assert!(rows > 0);
        let c = mixed.render.stats.counters;
        assert_eq!(c.camera_rays, alone.stats.counters.camera_rays);
    }
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sdfc-devices-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

fn sdfc(cwd: &Path, args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_sdfc"));
    c.current_dir(cwd)
        .args(args)
        .env_remove("SDFC_FAULT_AFTER_TILES");
    // Mesa's window-system code complains on stderr without it.
    c.env("XDG_RUNTIME_DIR", cwd);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("run sdfc")
}

/// `sdfc COMMAND FILE` followed by the words of `rest`, run in `d` with `env`.
fn sdfc_on(d: &Path, command: &str, file: &str, rest: &str, env: &[(&str, &str)]) -> Output {
    let mut args = vec![command, file];
    args.extend(common::words(rest));
    sdfc(d, &args, env)
}

/// The absolute path of the example `name`.
fn example(name: &str) -> String {
    std::fs::canonicalize(Path::new("../examples").join(name))
        .unwrap_or_else(|e| panic!("examples/{name}: {e}"))
        .display()
        .to_string()
}

fn seed3() -> String {
    example("seed3.sdf")
}

/// The standard error of `out`, which must have exited with `code`.
#[track_caller]
fn exited(out: &Output, code: i32) -> String {
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(code), "{err}");
    err
}

/// The one line of `err` that starts with `kind`.
#[track_caller]
fn only_line<'a>(err: &'a str, kind: &str) -> &'a str {
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with(kind)).collect();
    assert_eq!(lines.len(), 1, "{err}");
    lines[0]
}

/// Where there is a wgpu adapter, a fresh directory for the test `name`.
fn wgpu_dir(name: &str) -> Option<PathBuf> {
    open_gpu().map(|_| dir(name))
}

fn render(d: &Path, devices: &str, out: &str, env: &[(&str, &str)]) -> Output {
    let rest = format!("--backend wgpu --devices {devices} --size 160x120 -o {out}");
    sdfc_on(d, "render", &seed3(), &rest, env)
}

/// Where there is a wgpu adapter, a fresh directory for the test `name` holding `one.png`,
/// the image [`render`] makes on device 0 alone.
fn one_device_image(name: &str) -> Option<PathBuf> {
    let d = wgpu_dir(name)?;
    let one = render(&d, "0", "one.png", &[]);
    assert!(one.status.success(), "{one:?}");
    Some(d)
}

#[test]
fn a_failing_device_hands_its_tile_back_and_the_others_finish() {
    let Some(d) = one_device_image("fault") else {
        return;
    };
    // The second device fails at its second band; the first renders the rest.
    let out = render(&d, "0,0", "two.png", &[("SDFC_FAULT_AFTER_TILES", "1:1")]);
    let err = exited(&out, 0);
    let warning = only_line(&err, "warning");
    assert!(
        warning.starts_with("warning: device 1 (")
            && warning.contains("failed after 1 tile: GPU error while rendering: device error injected at tile 2 by SDFC_FAULT_AFTER_TILES=1:1 (a testing aid); the other devices rendered its tiles"),
        "{err}"
    );
    let a = std::fs::read(d.join("one.png")).expect("one.png");
    let b = std::fs::read(d.join("two.png")).expect("two.png");
    assert!(a == b, "the image differs from one device's");

    // Both fail: one error naming each device's, and no image.
    let out = render(&d, "0,0", "none.png", &[("SDFC_FAULT_AFTER_TILES", "2")]);
    let err = exited(&out, 1);
    let error = only_line(&err, "error");
    assert!(
        error.starts_with("error: every device failed (4 of ")
            && error.contains("device 0 (")
            && error.contains("device 1 (")
            && error.matches("device error injected at tile 3").count() == 2,
        "{err}"
    );
    assert!(!d.join("none.png").exists());

    // One device alone: the fault is the render's error, as before.
    let out = render(&d, "0", "alone.png", &[("SDFC_FAULT_AFTER_TILES", "0:0")]);
    let err = exited(&out, 1);
    assert_has(&err, &["error: GPU error while rendering: device error injected at tile 1 by SDFC_FAULT_AFTER_TILES=0:0 (a testing aid)"]);
}

#[test]
fn the_cpu_and_lavapipe_render_together_from_the_command_line() {
    let Some(d) = one_device_image("mixed") else {
        return;
    };
    let rest = "--backend wgpu --devices cpu,0 --size 160x120 --stats -o mixed.png";
    let out = sdfc_on(&d, "render", &seed3(), rest, &[]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{out:?}");
    assert_has(&text, &["backend         mixed (2 devices: CPU, "]);
    assert_has(&text, &["device 0        CPU, "]);
    assert_has(&text, &["device 1        "]);
    let compare = sdfc(&d, &["compare", "one.png", "mixed.png", "--json"], &[]);
    let json = String::from_utf8_lossy(&compare.stdout);
    let v: serde_json::Value = serde_json::from_str(&json).expect("json");
    let psnr = v["psnr"].as_f64().expect("psnr");
    assert!(psnr > 40.0, "{json}");
}

fn sequence(d: &Path, devices: &str, pattern: &str, env: &[(&str, &str)]) -> Output {
    let rest =
        format!("--backend wgpu --devices {devices} --size 96x64 --frames 0..6 -o {pattern}");
    sdfc_on(d, "render", &example("animation/orbit.sdf"), &rest, env)
}

#[test]
fn the_frames_of_a_sequence_go_to_the_devices_and_survive_one_failing() {
    let Some(d) = wgpu_dir("frames") else {
        return;
    };
    let one = sequence(&d, "0", "one/f_##.png", &[]);
    assert!(one.status.success(), "{one:?}");
    let same = |dir: &str| {
        for k in 0..6 {
            let a = std::fs::read(d.join(format!("one/f_{k:02}.png"))).expect("frame");
            let b = std::fs::read(d.join(format!("{dir}/f_{k:02}.png"))).expect("frame");
            assert!(a == b, "{dir}: frame {k} differs");
        }
    };
    let two = sequence(&d, "0,0", "two/f_##.png", &[]);
    let err = exited(&two, 0);
    assert_has(&err, &["(2 devices: wgpu on "]);
    same("two");
    // The second device fails on its first frame (it opens its device after taking one,
    // while the first is still opening its own); the first renders every frame.
    let fault = [("SDFC_FAULT_AFTER_TILES", "1:0")];
    let out = sequence(&d, "0,0", "back/f_##.png", &fault);
    let err = exited(&out, 0);
    assert_has(&err, &["warning: device 1 failed: device error injected at tile 1 by SDFC_FAULT_AFTER_TILES=1:0 (a testing aid); the other devices render its frame"]);
    same("back");
    // Every device fails at its second frame: two frames are written, then the error.
    let fault = [("SDFC_FAULT_AFTER_TILES", "1")];
    let out = sequence(&d, "0,0", "none/f_##.png", &fault);
    let err = exited(&out, 1);
    assert_has(
        &err,
        &["error: every device failed (2 of 6 frames written): device "],
    );
}

#[test]
fn a_sequence_on_two_logical_devices_is_the_sequence_on_one() {
    let Some(d) = wgpu_dir("sequence") else {
        return;
    };
    let orbit = example("animation/orbit.sdf");
    for (devices, pattern) in [("0", "one/f_##.png"), ("0,0", "two/f_##.png")] {
        let rest = format!(
            "--backend wgpu --devices {devices} --size 96x64 --frames 0..3 --stats -o {pattern}"
        );
        let out = sdfc_on(&d, "render", &orbit, &rest, &[]);
        assert!(out.status.success(), "{out:?}");
        // `--stats` says where the time went: each device's steps and the writers'.
        let err = String::from_utf8_lossy(&out.stderr);
        assert_has(&err, &["where the sequence's time went"]);
        let place = if devices == "0" { "device" } else { "device 1" };
        assert!(
            err.contains(&format!("\n  {place}: "))
                && err.contains("opening and first preparation"),
            "{err}"
        );
        assert_has(&err, &["\n  writers: ", " fsync "]);
    }
    for k in 0..3 {
        let a = std::fs::read(d.join(format!("one/f_{k:02}.png"))).expect("frame");
        let b = std::fs::read(d.join(format!("two/f_{k:02}.png"))).expect("frame");
        assert!(a == b, "frame {k} differs");
    }
    let rest = "--backend wgpu --devices 0,0 --size 64x48 --frames 1 --json";
    let bench = sdfc_on(&d, "bench", &orbit, rest, &[]);
    let json = String::from_utf8_lossy(&bench.stdout);
    assert!(bench.status.success(), "{bench:?}");
    assert_has(&json, &["2 devices: "]);
}

#[test]
fn devices_lists_the_adapters_and_the_cpu() {
    let Some(d) = wgpu_dir("list") else {
        return;
    };
    let out = sdfc(&d, &["devices"], &[]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{out:?}");
    let adapter = gpu::Gpu::open(false).expect("adapter").describe();
    let name = adapter.split(" (").next().unwrap_or_default().to_string();
    assert!(
        text.lines().any(|l| l.starts_with("wgpu 0: ")
            && l.contains(&name)
            && l.contains("largest buffer")),
        "{text}"
    );
    assert!(text.lines().any(|l| l.starts_with("cuda")), "{text}");
    assert!(
        text.lines()
            .any(|l| l.starts_with("cpu: the CPU renderer, ")),
        "{text}"
    );
}

#[test]
fn bad_devices_are_named_in_the_error() {
    let d = dir("bad");
    let scene = seed3();
    for (devices, backend, code, expected) in [
        ("0,x", "wgpu", 2, "bad --devices entry `x`"),
        ("0,,1", "wgpu", 2, "bad --devices entry ``"),
        ("gpu", "auto", 2, "bad --devices entry `gpu`"),
        (
            "cpu,0",
            "cpu",
            2,
            "--devices entry `0` names a GPU, but --backend cpu",
        ),
        ("0,99", "wgpu", 1, "there is no wgpu adapter 99"),
    ] {
        let rest = format!("--backend {backend} --devices {devices} --size 8x8 -o x.png");
        let out = sdfc_on(&d, "render", &scene, &rest, &[]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(code), "{devices}: {err}");
        assert!(err.contains(expected), "{devices}: {err}");
        assert!(!d.join("x.png").exists());
    }
    let out = sdfc_on(
        &d,
        "render",
        &scene,
        "--reference --devices 0,0 -o x.png",
        &[],
    );
    let err = exited(&out, 2);
    assert_has(&err, &["it cannot use --devices"]);
}

/// A still and a sequence report `--devices` alike: a list the backend cannot take is a usage
/// error (exit 2), `--devices all` finding no device a device error (exit 1), with one
/// message. (The sequence resolves the list itself, to hand whole frames to several devices.)
#[test]
fn a_still_and_a_sequence_report_bad_devices_alike() {
    let d = dir("alike");
    let listed = sdfc(&d, &["devices"], &[]);
    let no_cuda = String::from_utf8_lossy(&listed.stdout)
        .lines()
        .any(|l| l.starts_with("cuda: none"));
    let orbit = example("animation/orbit.sdf");
    let mut cases = vec![
        (
            "cpu,0",
            "cpu",
            2,
            "error: --devices entry `0` names a GPU, but --backend cpu",
        ),
        (
            "all",
            "cpu",
            2,
            "error: --devices all names every GPU, but --backend cpu",
        ),
    ];
    if no_cuda {
        cases.push((
            "all",
            "cuda",
            1,
            "error: the Cuda backend is not available: --devices all found no cuda device",
        ));
    }
    for (devices, backend, code, expected) in cases {
        let still = [seed3().as_str(), "-o", "x.png"].map(String::from);
        let frames = [orbit.as_str(), "--frames", "0..2", "-o", "f_#.png"].map(String::from);
        for what in [&still[..], &frames[..]] {
            let mut args = vec!["render", "--backend", backend, "--devices", devices];
            args.extend(["--size", "8x8"]);
            args.extend(what.iter().map(String::as_str));
            let out = sdfc(&d, &args, &[]);
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(code), "{args:?}: {err}");
            assert!(err.contains(expected), "{args:?}: {err}");
        }
    }
}

/// Without the per-pixel statistics (`Setup::image_only`: `sdfc render` without `--stats`, and
/// sequences) a GPU frame is the same image, and only its statistics are left empty; a
/// software adapter's keep them (their count of cut loops decides whether the frame stands).
#[test]
fn a_frame_without_statistics_is_the_same_image() {
    use sdfc_runtime::backend::{Prepared, Setup};
    let Some(gpu) = open_gpu() else { return };
    let gpu = std::sync::Arc::new(gpu);
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/seed3.sdf");
    let scene = load_small(&path, 96, 64);
    let lowered = Lowered::new(&scene);
    let frame = |setup: &Setup| {
        Prepared::on_gpu(gpu.clone(), &scene, &lowered, setup)
            .expect("prepared")
            .render(&scene, &|_| {})
            .expect("rendered")
    };
    let with = frame(&Setup::default());
    let without = frame(&Setup {
        image_only: true,
        ..Setup::default()
    });
    assert_eq!(with.render.image.linear, without.render.image.linear);
    assert!(with.render.stats.counters.steps > 0 && with.render.stats.counters.hits > 0);
    if gpu.is_cpu() {
        assert_eq!(with.render.stats.counters, without.render.stats.counters);
    } else {
        assert_eq!(without.render.stats.counters.steps, 0);
        assert_eq!(without.render.stats.counters.hits, 0);
    }
}
