//! The viewer without a window (`--headless`): screenshots on wgpu, path tracing's samples
//! accumulated, frames that stop once the image settles, a scene that never loads, and an
//! orbit measured.

use crate::words;
use crate::{headless_run, mean, required, scene_dir, temp_dir, CENTRE, SCENE};
use sdfc_runtime::image::read_png;
use std::path::Path;
use std::process::{Command, Output};

/// Headless through wgpu (lavapipe without a GPU), the frames stay on the device and the
/// screenshot is read back from it: the scene's picture, after its kernel compiled on another
/// thread; and `--backend auto` says what it found.
#[test]
fn headless_wgpu_screenshot_shows_the_scene() {
    let (dir, _) = scene_dir("headless-wgpu", SCENE);
    let args = "view scene.sdf --headless --backend wgpu --size 64x48 --frames 3 --screenshot shot.png --timings";
    let (out, stderr) = sdfc_in(&dir, &words(args));
    if no_wgpu(&stderr) {
        return;
    }
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("on another thread"), "{stderr}");
    let shot = read_png(&dir.join("shot.png")).unwrap();
    assert_eq!((shot.width, shot.height), (64, 48));
    let (cx, cy) = CENTRE;
    let c = mean(&shot, cx, cy);
    assert!(
        c[0] > 2.0 * c[2] && c[0] > 2.0 * c[1],
        "a red sphere: {c:?}"
    );

    // `auto` takes a hardware GPU; with only a software adapter it renders on the CPU and
    // says so, without asking for a driver to be installed.
    let (status, auto) = headless_auto(&dir);
    assert!(status.success(), "{auto}");
    let software = auto.contains("only the software adapter");
    assert!(
        auto.contains("rendering on wgpu") || software,
        "a software adapter is there: {auto}"
    );
    assert!(!software || !auto.contains("mesa-vulkan-drivers"), "{auto}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Headless through wgpu, a path-traced scene accumulates one sample a frame on the device
/// while the camera rests and stops at its `samples`: the screenshot is `sdfc render`'s
/// picture of those samples (through wgpu), to within the rounding of summing frames, under
/// the scene's default tone curve, filmic (the frames add up in linear light and their mean
/// is graded: a mean of graded frames was 0.18 apart).
#[test]
fn headless_wgpu_path_tracing_accumulates_the_scenes_samples() {
    let dir = temp_dir("headless-path");
    let scene = SCENE
        .replace(
            "aa: 2, max_steps: 128",
            "method: \"path\", samples: 6, bounces: 2",
        )
        .replace(
            "light point",
            "light sky { zenith: (0.3, 0.4, 0.7), horizon: (0.8, 0.8, 0.8) }\nlight point",
        );
    std::fs::write(dir.join("scene.sdf"), &scene).unwrap();
    let (check, said) = sdfc_in(&dir, &["check", "scene.sdf"]);
    let said = said + &String::from_utf8_lossy(&check.stdout);
    assert!(
        said.contains("tone curve: filmic (the default where it is path traced"),
        "{said}"
    );
    let args =
        "view scene.sdf --headless --backend wgpu --size 64x48 --frames 40 --screenshot shot.png";
    let (out, stderr) = sdfc_in(&dir, &words(args));
    if no_wgpu(&stderr) {
        return;
    }
    assert!(out.status.success(), "{stderr}");
    let args = "render scene.sdf --backend wgpu --size 64x48 -o render.png";
    let (rendered, stderr) = sdfc_in(&dir, &words(args));
    assert!(rendered.status.success(), "{stderr}");
    let shot = read_png(&dir.join("shot.png")).unwrap();
    let render = read_png(&dir.join("render.png")).unwrap();
    let most = shot
        .linear
        .iter()
        .zip(&render.linear)
        .flat_map(|(a, b)| (0..3).map(move |i| (a[i] - b[i]).abs()))
        .fold(0.0f32, f32::max);
    // One sRGB level of 255 apart at most, where the sums round across a level.
    assert!(
        most < 0.02,
        "the view's six frames against the render: {most}"
    );
    // One frame alone is another picture: the frames were six samples, not one six times.
    let args =
        "view scene.sdf --headless --backend wgpu --size 64x48 --frames 1 --screenshot one.png";
    let (one, _) = sdfc_in(&dir, &words(args));
    assert!(one.status.success());
    let one = read_png(&dir.join("one.png")).unwrap();
    assert_ne!(one.linear, shot.linear);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `sdfc view scene.sdf --headless` (auto) in `dir` for one frame: its status and stderr.
fn headless_auto(dir: &Path) -> (std::process::ExitStatus, String) {
    let args = "view scene.sdf --headless --size 32x24 --frames 1 --screenshot auto.png";
    let (out, stderr) = sdfc_in(dir, &words(args));
    (out.status, stderr)
}

/// `sdfc` run in `dir` with `args`, wgpu's runtime folder set: its output and its standard
/// error.
fn sdfc_in(dir: &Path, args: &[&str]) -> (Output, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(dir)
        .args(args)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    (out, stderr)
}

/// Whether wgpu found no adapter, as `stderr` says: then the test skips (or, under
/// `SDFC_REQUIRE_DEVICES=1`, fails).
fn no_wgpu(stderr: &str) -> bool {
    let missing = stderr.contains("the Wgpu backend is not available");
    if missing {
        assert!(!required(), "{stderr}");
        eprintln!("SKIPPED: no wgpu adapter\n{stderr}");
    }
    missing
}

/// Headless with `--frames`, the settled image counts as frames: a scene that converges in
/// fewer frames than asked for (`aa: 2`) stops and writes its screenshot.
#[test]
fn headless_frames_stop_after_the_image_settles() {
    let (dir, _) = scene_dir("headless-frames", SCENE);
    let args = "scene.sdf --size 64x48 --frames 40 --screenshot shot.png";
    let (status, stderr) = headless_run(&dir, &words(args));
    assert!(status.success(), "{stderr}");
    let shot = read_png(&dir.join("shot.png")).unwrap();
    assert_eq!((shot.width, shot.height), (64, 48));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A scene that never loads (errors, or no file) has no image: `--screenshot` fails and
/// writes nothing, instead of an empty picture and success.
#[test]
fn headless_screenshot_of_a_scene_that_never_loads_fails() {
    let dir = temp_dir("headless-broken");
    std::fs::write(dir.join("broken.sdf"), "scene { sphre(1); }").unwrap();
    for file in ["broken.sdf", "missing.sdf"] {
        let args = format!("{file} --size 32x24 --frames 3 --screenshot shot.png");
        let (status, stderr) = headless_run(&dir, &words(&args));
        assert!(!status.success(), "{file}: {stderr}");
        assert!(stderr.contains("no screenshot written"), "{file}: {stderr}");
        assert!(
            !dir.join("shot.png").exists(),
            "{file}: a screenshot was written"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--orbit-frames` is a measurement: it prints the orbit's frame rate and the time to
/// converge once the camera stops, then the run ends (it waited for file changes before).
#[test]
fn headless_orbit_prints_its_figures_and_exits() {
    let (dir, _) = scene_dir("headless-orbit", SCENE);
    let (status, stderr) = headless_run(
        &dir,
        &["scene.sdf", "--size", "32x24", "--orbit-frames", "3"],
    );
    assert!(status.success(), "{stderr}");
    assert!(stderr.contains("view: orbit: 3 frames in"), "{stderr}");
    assert!(stderr.contains("after the camera stopped"), "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}
