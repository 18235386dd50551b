//! The viewer follows edits of its scene file (a colour, a new shape saved by renaming, an
//! error that leaves the last good image on show): in a window on wgpu, on the CPU, and headless.

use crate::{changed, display, exited, mean, scene_dir, wait_for, Display, CENTRE, LEFT, SCENE};
use std::process::{Command, Stdio};

/// Opens the viewer with `args` (besides the file and the screenshot folder), edits the file
/// three times, and checks each reload's screenshot.
fn follows_edits(name: &str, display: Option<&Display>, args: &[&str]) {
    let (dir, scene) = scene_dir(name, SCENE);
    let shots = dir.join("shots");
    let log = dir.join("viewer.log");
    let runtime = dir.join("xdg");
    std::fs::create_dir_all(&runtime).unwrap();
    let mut command = Command::new(env!("CARGO_BIN_EXE_sdfc"));
    command
        .current_dir(&dir)
        .args(["view", "scene.sdf", "--screenshot-dir"])
        .arg(&shots)
        .args(["--exit-after-reloads", "3", "--timings"])
        .args(args)
        .env("XDG_RUNTIME_DIR", &runtime)
        .env_remove("WAYLAND_DISPLAY")
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&log).unwrap());
    match display {
        Some(d) => command.env("DISPLAY", &d.name),
        None => command.env_remove("DISPLAY"),
    };
    let mut child = command.spawn().expect("sdfc view starts");

    let first = wait_for(&shots.join("reload-0.png"), &mut child, &log);
    let (cx, cy) = CENTRE;
    let c = mean(&first, cx, cy);
    assert!(
        c[0] > 2.0 * c[2] && c[0] > 2.0 * c[1],
        "a red sphere: {c:?}"
    );

    // A numeric edit: the sphere turns blue, and nothing else changes.
    std::fs::write(&scene, SCENE.replace("(0.9, 0.1, 0.1)", "(0.1, 0.1, 0.9)")).unwrap();
    let blue = wait_for(&shots.join("reload-1.png"), &mut child, &log);
    let c = mean(&blue, cx, cy);
    assert!(
        c[2] > 2.0 * c[0] && c[2] > 2.0 * c[1],
        "a blue sphere: {c:?}"
    );
    let (lx, ly) = LEFT;
    assert!(
        changed(&first, &blue, lx, ly) < 0.01,
        "the colour edit changed the left of the picture"
    );

    // A structural edit, saved as editors do: a new file renamed over the old one.
    let with_box = SCENE.replace("(0.9, 0.1, 0.1)", "(0.1, 0.1, 0.9)").replace(
        "@ ball;\n",
        "@ ball;\n  box((0.5, 0.5, 0.5)).translate(2.2, 0.5, 0) @ grey;\n",
    );
    let new = dir.join(".scene.sdf.new");
    std::fs::write(&new, &with_box).unwrap();
    std::fs::rename(&new, &scene).unwrap();
    let boxed = wait_for(&shots.join("reload-2.png"), &mut child, &log);
    assert!(
        changed(&blue, &boxed, lx, ly) > 0.05,
        "the box did not appear on the left: {} of its pixels changed",
        changed(&blue, &boxed, lx, ly)
    );
    assert!(
        changed(&blue, &boxed, cx, cy) < 0.01,
        "the box changed the sphere"
    );

    // An edit with an error: the last good image stays.
    std::fs::write(&scene, with_box.replace("sphere(0.8)", "sphre(0.8)")).unwrap();
    let kept = wait_for(&shots.join("reload-3.png"), &mut child, &log);
    let stderr = exited(&mut child, &log);
    assert_eq!(
        changed(&boxed, &kept, (0.0, 1.0), (0.0, 1.0)),
        0.0,
        "the error changed the picture"
    );
    assert!(
        stderr.contains("sphre") && stderr.contains("E0201"),
        "the diagnostics are printed as `sdfc check` prints them:\n{stderr}"
    );
    assert!(
        stderr.contains("edit to pixel"),
        "--timings prints the reloads' timings:\n{stderr}"
    );
    if name == "wgpu" {
        // The numeric edit keeps the kernel (its constants are read from `scene_data`); the
        // structural edit builds a new one.
        let load = |k: u32| {
            stderr
                .lines()
                .find(|l| l.contains(&format!("load {k} timings")))
                .unwrap_or_default()
        };
        assert!(
            load(1).contains("kernel kept (numbers only)"),
            "a numeric edit keeps the wgpu kernel:\n{stderr}"
        );
        assert!(
            load(2).contains(", kernel ") && !load(2).contains("kept"),
            "a structural edit builds a new kernel:\n{stderr}"
        );
    }
    eprintln!("{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_window_follows_edits_through_wgpu() {
    let Some(display) = display() else { return };
    follows_edits("wgpu", Some(&display), &["--backend", "wgpu"]);
}

#[test]
fn the_window_follows_edits_on_the_cpu() {
    let Some(display) = display() else { return };
    follows_edits("cpu", Some(&display), &["--backend", "cpu"]);
}

#[test]
fn the_headless_session_follows_edits() {
    follows_edits("headless", None, &["--headless", "--backend", "cpu"]);
}
