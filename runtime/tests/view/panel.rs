//! The viewer's parameter panel: a parametric scene opens with the panel beside its image;
//! `--change` sets a control as a slider or checkbox would, and the screenshot after each
//! change shows the panel with the new value and the picture re-rendered (through the numeric
//! path for a number, a new kernel for a bool that switches a part on or off); the values set
//! survive an edit of the file while it still accepts them. Headless, `--change` takes the same
//! path, keeps a value within its range and on its step, and refuses what no control shows.

use super::*;

/// A ball on a floor, with a radius, a floor that can be switched off, and a colour.
const PARAMETRIC: &str = concat!(
    r#"
param radius = 0.5 in 0.2..1.0 step 0.1 "Ball radius";
param floor = true "A floor under the ball";
"#,
    studio!(),
    r#"render { width: 200, height: 200, aa: 2, max_steps: 128 }
scene {
  union([for i in 0..1 if floor { plane((0, 1, 0), 0) @ grey }]
    + [sphere(radius).translate(0, radius, 0) @ ball]);
}
"#
);

/// The scene's image in the screenshot: its `render` size, on the left.
const IMAGE: (u32, u32) = (200, 200);

/// The part of `shot` in pixels `x0..x1` (all rows) as fractions, for [`mean`] and [`changed`].
fn columns(shot: &Image, x0: u32, x1: u32) -> ((f64, f64), (f64, f64)) {
    let w = shot.width as f64;
    ((x0 as f64 / w, x1 as f64 / w), (0.0, 1.0))
}

/// The fraction of the pixels in columns `x0..x1` brighter than 0.5 in every channel (text).
fn bright(shot: &Image, x0: u32, x1: u32) -> f64 {
    let mut n = 0;
    for y in 0..shot.height {
        for x in x0..x1 {
            if shot.pixel(x, y).iter().all(|c| *c > 0.5) {
                n += 1;
            }
        }
    }
    n as f64 / ((x1 - x0) * shot.height) as f64
}

#[test]
fn the_panel_shows_parameters_and_a_change_rerenders_the_scene() {
    let Some(display) = display() else { return };
    let (dir, scene) = scene_dir("panel", PARAMETRIC);
    let shots = dir.join("shots");
    let log = dir.join("viewer.log");
    let runtime = dir.join("xdg");
    std::fs::create_dir_all(&runtime).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&dir)
        .args(["view", "scene.sdf", "--backend", "wgpu", "--timings"])
        // Marched: an analytically traced scene writes its shapes' numbers into its kernel
        // (docs/viewer.md), a marched one reads them from `scene_data`.
        .args(["--set", "method=march"])
        .arg("--screenshot-dir")
        .arg(&shots)
        .args(["--change", "radius=0.9", "--change", "floor=false"])
        .args(["--exit-after-reloads", "4"])
        .env("XDG_RUNTIME_DIR", &runtime)
        .env("DISPLAY", &display.name)
        .env_remove("WAYLAND_DISPLAY")
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&log).unwrap())
        .spawn()
        .expect("sdfc view starts");
    let shot =
        |k: u32, child: &mut Child| wait_for(&shots.join(format!("reload-{k}.png")), child, &log);

    // Load 0: the scene at its defaults, the panel on its right (the window widened by it).
    let first = shot(0, &mut child);
    let (w, h) = IMAGE;
    assert_eq!(first.height, h);
    assert!(
        first.width >= w + 200,
        "the window is the image and the panel beside it: {}x{}",
        first.width,
        first.height
    );
    let (image, panel) = (columns(&first, 0, w), columns(&first, w + 4, first.width));
    // The panel: egui's dark grey, with its text; the image: the scene (a red ball).
    let p = mean(&first, panel.0, panel.1);
    assert!(
        p.iter().all(|c| *c < 0.1) && (p[0] - p[2]).abs() < 0.01,
        "the panel's background is a dark grey: {p:?}"
    );
    let text = bright(&first, w + 4, first.width);
    assert!(
        (0.002..0.3).contains(&text),
        "the panel has text on it: {text} of its pixels are bright"
    );
    let across = |a: f64, b: f64| {
        let f = w as f64 / first.width as f64;
        (a * f, b * f)
    };
    let ball = mean(&first, across(0.45, 0.55), (0.45, 0.55));
    assert!(ball[0] > 2.0 * ball[2], "a red ball in the image: {ball:?}");

    // Load 1: `--change radius=0.9`, as the slider would set it: a larger ball, the panel
    // showing the new value, and the kernel kept (only numbers changed).
    let larger = shot(1, &mut child);
    assert_eq!((larger.width, larger.height), (first.width, first.height));
    let grew = changed(&first, &larger, image.0, image.1);
    assert!(
        grew > 0.05,
        "the ball did not grow: {grew} of the image changed"
    );
    let moved = changed(&first, &larger, panel.0, panel.1);
    assert!(
        moved > 0.001,
        "the panel does not show the new value: {moved} of it changed"
    );

    // Load 2: `--change floor=false`, as the checkbox would: the floor goes (a new kernel).
    let floorless = shot(2, &mut child);
    let gone = changed(&larger, &floorless, image.0, (0.85, 1.0));
    assert!(
        gone > 0.5,
        "the floor did not go: {gone} of the bottom changed"
    );

    // Load 3: an edit of the file that keeps both parameters (a new description): the values
    // set stay, so the picture stays.
    std::fs::write(
        &scene,
        PARAMETRIC.replace("\"Ball radius\"", "\"Radius of the ball\""),
    )
    .unwrap();
    let kept = shot(3, &mut child);
    assert_eq!(
        changed(&floorless, &kept, image.0, image.1),
        0.0,
        "the values set did not survive the edit"
    );

    // Load 4: an edit that narrows the radius's range below the value set: the default
    // stands again (the floor stays off).
    let narrowed = PARAMETRIC
        .replace("\"Ball radius\"", "\"Radius of the ball\"")
        .replace("0.2..1.0", "0.2..0.8");
    std::fs::write(&scene, narrowed).unwrap();
    let back = shot(4, &mut child);
    let stderr = exited(&mut child, &log);
    assert!(
        changed(&kept, &back, image.0, image.1) > 0.05,
        "the radius outside the new range stayed"
    );
    assert!(
        changed(&floorless, &back, image.0, (0.85, 1.0)) < 0.01,
        "the floor came back"
    );
    let line = |k: u32| {
        stderr
            .lines()
            .find(|l| l.starts_with(&format!("view: load {k} ")) && l.contains("timings"))
            .unwrap_or_default()
            .to_string()
    };
    assert!(
        line(1).contains("load 1 (radius = 0.9) timings")
            && line(1).contains("kernel kept (numbers only)")
            && line(1).contains("change to pixel"),
        "a number's change keeps the kernel and is timed from the change:\n{stderr}"
    );
    assert!(
        line(2).contains("(floor = false)") && !line(2).contains("kept"),
        "switching a part off builds a new kernel:\n{stderr}"
    );
    eprintln!("{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn headless_changes_take_the_controls_values_and_refuse_others() {
    let (dir, _) = scene_dir("panel-headless", PARAMETRIC);
    let base = [
        "scene.sdf",
        "--size",
        "40x30",
        "--timings",
        "--screenshot-dir",
        "shots",
    ];
    // 0.94 is kept on the step (0.9); 7 within the range (1.0, its top).
    let args: Vec<&str> = base
        .iter()
        .copied()
        .chain(["--change", "radius=0.94", "--change", "radius=7"])
        .chain(["--exit-after-reloads", "2"])
        .collect();
    let (status, stderr) = headless_run(&dir, &args);
    assert!(status.success(), "{stderr}");
    assert!(stderr.contains("load 1 (radius = 0.9) timings"), "{stderr}");
    assert!(stderr.contains("load 2 (radius = 1) timings"), "{stderr}");
    assert!(dir.join("shots/reload-2.png").exists());
    // What no control shows is refused, naming what is there.
    for (change, says) in [
        (
            "radius=wide",
            "`wide` is not a value of `radius` (0.2..1 step 0.1)",
        ),
        ("floor=1", "`1` is not a value of `floor`"),
        (
            "radious=1",
            "no parameter `radious`; its parameters: `radius`, `floor`",
        ),
    ] {
        let args: Vec<&str> = base
            .iter()
            .copied()
            .chain(["--change", change, "--exit-after-reloads", "1"])
            .collect();
        let (status, stderr) = headless_run(&dir, &args);
        assert_eq!(status.code(), Some(2), "{change}: {stderr}");
        assert!(
            stderr.contains(&format!("error: --change {change}: ")) && stderr.contains(says),
            "{change}:\n{stderr}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
