//! The window's screenshots: the scene after some frames, CPU frames without an adapter, an
//! animated scene at a time, and new kernels shown interpreted while they compile.

use crate::words;
use crate::{
    changed, display, exited, mean, scene_dir, temp_dir, wait_for, Display, CENTRE, LEFT, SCENE,
};
use sdfc_runtime::image::{read_png, Image};
use std::path::Path;
use std::process::{Command, Stdio};

/// Runs the viewer for a few frames with `env` and checks the screenshot; returns stderr.
fn screenshot_after_frames(name: &str, env: &[(&str, &str)]) -> String {
    let Some(display) = display() else {
        return String::new();
    };
    let (dir, _) = scene_dir(name, SCENE);
    std::fs::create_dir_all(dir.join("xdg")).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&dir)
        .args(words(
            "view scene.sdf --size 200x100 --frames 6 --screenshot shot.png",
        ))
        .env("DISPLAY", &display.name)
        .env("XDG_RUNTIME_DIR", dir.join("xdg"))
        .env_remove("WAYLAND_DISPLAY")
        .envs(env.iter().copied())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{stderr}");
    let shot = read_png(&dir.join("shot.png")).unwrap();
    assert_eq!((shot.width, shot.height), (200, 100), "the window's size");
    let (cx, cy) = CENTRE;
    let c = mean(&shot, cx, cy);
    assert!(c[0] > 2.0 * c[2], "a red sphere: {c:?}\n{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
    stderr
}

#[test]
fn a_screenshot_after_some_frames_shows_the_scene() {
    screenshot_after_frames("frames", &[]);
}

#[test]
fn without_an_adapter_the_window_shows_cpu_frames() {
    // No Vulkan driver to be found: the window falls back to softbuffer and the CPU renderer.
    let stderr = screenshot_after_frames(
        "soft",
        &[
            ("VK_DRIVER_FILES", "/nonexistent/icd.json"),
            ("VK_ICD_FILENAMES", "/nonexistent/icd.json"),
        ],
    );
    assert!(
        stderr.is_empty() || stderr.contains("presenting with softbuffer"),
        "{stderr}"
    );
}

#[test]
fn the_view_of_an_animated_scene_at_a_time_is_that_frame_of_the_sequence() {
    // Headless, `--time` pauses the animation at a time: the picture is the sequence's frame
    // of that time (bounce.sdf at 30 frames per second: 0.5 s is frame 15).
    let dir = temp_dir("time");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/animation/bounce.sdf");
    let scene = scene.to_str().expect("utf-8 path");
    let sdfc = env!("CARGO_BIN_EXE_sdfc");
    let run = |args: &[&str]| {
        let out = Command::new(sdfc)
            .current_dir(&dir)
            .env("XDG_RUNTIME_DIR", std::env::temp_dir())
            .args(args)
            .output()
            .expect("run sdfc");
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    for t in ["0", "0.5"] {
        run(&[
            "view",
            scene,
            "--headless",
            "--backend",
            "cpu",
            "--size",
            "96x72",
            "--time",
            t,
            "--screenshot-dir",
            t,
            "--exit-after-reloads",
            "0",
        ]);
    }
    run(&[
        "render",
        scene,
        "--backend",
        "cpu",
        "--size",
        "96x72",
        "--frames",
        "15..16",
        "-o",
        "f_##.png",
    ]);
    let at = |p: &str| read_png(&dir.join(p)).expect("a PNG");
    let (zero, half, frame) = (at("0/reload-0.png"), at("0.5/reload-0.png"), at("f_15.png"));
    assert_eq!(half, frame, "t = 0.5 s is frame 15 of the sequence");
    assert!(
        changed(&zero, &half, (0.0, 1.0), (0.0, 1.0)) > 0.0,
        "the time moves the ball"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs the viewer through wgpu on `scene.sdf` in `dir` for 8 frames with `args` and returns
/// the screenshot of the last one (the converged image of a kernel compiled before it is shown).
fn window_shot(display: &Display, dir: &Path, name: &str, args: &[&str]) -> Image {
    let shot = dir.join(format!("{name}.png"));
    let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(dir)
        .args(["view", "scene.sdf", "--backend", "wgpu", "--frames", "8"])
        .arg("--screenshot")
        .arg(&shot)
        .args(args)
        .env("DISPLAY", &display.name)
        .env("XDG_RUNTIME_DIR", dir.join("xdg"))
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{args:?}: {stderr}");
    read_png(&shot).unwrap_or_else(|e| panic!("{}: {e}\n{stderr}", shot.display()))
}

#[test]
fn the_window_shows_new_kernels_interpreted_while_they_compile() {
    // `--kernel auto` (the default): on a GPU, a marched scene whose specialised kernel is not
    // compiled yet is shown through the interpreted kernel while the specialised one compiles
    // on another thread (which one the first frame shows depends on which pipeline is ready
    // first; `view::session`'s tests hold the compile back to see both, on lavapipe too).
    // The image each load settles on is the specialised kernel's, as `--kernel specialised`
    // shows it, and the interpreted kernel's image agrees with it.
    let Some(display) = display() else { return };
    let (dir, scene) = scene_dir("interim", SCENE);
    std::fs::create_dir_all(dir.join("xdg")).unwrap();
    let shots = dir.join("shots");
    let log = dir.join("viewer.log");
    let march = ["--set", "method=march"];
    let mut child = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&dir)
        .args(["view", "scene.sdf", "--backend", "wgpu", "--timings"])
        .args(march)
        .arg("--screenshot-dir")
        .arg(&shots)
        .args(["--exit-after-reloads", "1"])
        .env("DISPLAY", &display.name)
        .env("XDG_RUNTIME_DIR", dir.join("xdg"))
        .env_remove("WAYLAND_DISPLAY")
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&log).unwrap())
        .spawn()
        .expect("sdfc view starts");
    let first = wait_for(&shots.join("reload-0.png"), &mut child, &log);
    // A structural edit: a new kernel.
    let with_box = SCENE.replace(
        "@ ball;\n",
        "@ ball;\n  box((0.5, 0.5, 0.5)).translate(2.2, 0.5, 0) @ grey;\n",
    );
    std::fs::write(&scene, &with_box).unwrap();
    let boxed = wait_for(&shots.join("reload-1.png"), &mut child, &log);
    let stderr = exited(&mut child, &log);
    // Every new kernel compiles on another thread, never on the window's. On a CPU adapter
    // (lavapipe) the interpreted kernel's frames would take longer than the compile they hide:
    // `auto` keeps the image before on show there until the kernel is ready.
    let cpu_adapter = stderr
        .lines()
        .any(|l| l.starts_with("view: rendering on wgpu") && l.contains("Cpu)"));
    for k in 0..2 {
        let line = stderr
            .lines()
            .find(|l| l.contains(&format!("load {k} timings")))
            .unwrap_or_default();
        assert!(
            line.contains("pipeline compiled")
                && line.contains("on another thread")
                && line.contains("no interpreted kernel meanwhile") == cpu_adapter,
            "load {k}'s kernel compiled on another thread (shown once ready on a CPU adapter):\n{stderr}"
        );
    }
    let (lx, ly) = LEFT;
    assert!(
        changed(&first, &boxed, lx, ly) > 0.05,
        "the box did not appear on the left"
    );

    // The settled image is the specialised kernel's; the interpreted kernel's agrees.
    let shot = |kernel: &str| {
        window_shot(
            &display,
            &dir,
            kernel,
            &["--kernel", kernel, march[0], march[1]],
        )
    };
    let (specialised, interpreted) = (shot("specialised"), shot("interpreted"));
    assert_eq!(
        boxed, specialised,
        "the window settles on the specialised kernel"
    );
    let d = sdfc_runtime::metrics::compare(&specialised, &interpreted, 0.1).unwrap();
    assert!(d.psnr >= 40.0, "the kernels' images agree: {d:?}");
    eprintln!("{stderr}\ninterpreted against specialised: {d:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
