//! `sdfc view`: the live preview follows edits of its scene file. Each test opens the viewer on a
//! scene copied to a temporary folder, rewrites the file with a numeric edit (a colour), a
//! structural edit (a new shape, saved by writing a new file and renaming it over the old one)
//! and an edit with an error, and checks from the screenshot written after each reload
//! (`--screenshot-dir`, `reload-K.png`) that the picture changes as it should and that the
//! error leaves the last good image on show. The parameter panel's tests are in
//! `view/panel.rs`.
//!
//! The window tests run under X: on `DISPLAY` when it is set, else on an Xvfb of their own
//! (which picks a free display number); wgpu presents through Vulkan (lavapipe on a machine without a
//! GPU). Where Xvfb or a Vulkan driver is missing they print that they skipped, unless
//! `SDFC_REQUIRE_DEVICES=1` (set by `.ci/run`): then they fail. The headless test needs neither.

#[path = "view/panel.rs"]
mod panel;

use sdfc_runtime::image::{read_png, Image};
use std::io::BufRead;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A plane and a red sphere in the middle of the picture, lit from the viewer's right (world
/// −x), so that the shadows of shapes added on the left (world +x) stay on the left.
const SCENE: &str = r#"
material grey = phong { color: (0.6, 0.6, 0.6) };
material ball = phong { color: (0.9, 0.1, 0.1) };
camera { position: (0, 1.5, -5), look_at: (0, 0.6, 0), fov: 50deg }
light point { position: (-3, 5, -4), intensity: 1 }
render { width: 160, height: 120, aa: 2, max_steps: 128 }
scene {
  plane((0, 1, 0), 0) @ grey;
  sphere(0.8).translate(0, 0.8, 0) @ ball;
}
"#;

/// How long one reload may take to reach its screenshot (lavapipe on a busy 2-core machine).
const PATIENCE: Duration = Duration::from_secs(180);

fn required() -> bool {
    std::env::var("SDFC_REQUIRE_DEVICES").as_deref() == Ok("1")
}

/// Skips (returns `None`) or, under `SDFC_REQUIRE_DEVICES=1`, fails.
fn skip(why: &str) -> Option<Display> {
    assert!(!required(), "SDFC_REQUIRE_DEVICES=1 but {why}");
    eprintln!("view test SKIPPED: {why}");
    None
}

/// An X display for the viewer's window: `DISPLAY`, or an Xvfb of our own.
struct Display {
    name: String,
    xvfb: Option<Child>,
}

impl Drop for Display {
    fn drop(&mut self) {
        if let Some(child) = self.xvfb.as_mut() {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

fn display() -> Option<Display> {
    let lavapipe = std::fs::read_dir("/usr/share/vulkan/icd.d")
        .map(|d| {
            d.flatten()
                .any(|e| e.file_name().to_string_lossy().starts_with("lvp_icd"))
        })
        .unwrap_or(false);
    if let Ok(name) = std::env::var("DISPLAY") {
        if !name.is_empty() {
            return Some(Display { name, xvfb: None });
        }
    }
    if !lavapipe {
        return skip("no DISPLAY and no lavapipe (`apt-get install mesa-vulkan-drivers`)");
    }
    // Xvfb picks a free display number itself (so tests running at once do not collide) and
    // writes it to the descriptor given once it accepts connections.
    let child = Command::new("Xvfb")
        .args([
            "-displayfd",
            "1",
            "-screen",
            "0",
            "1024x768x24",
            "-nolisten",
            "tcp",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn();
    let mut child = match child {
        Ok(c) => c,
        Err(e) => {
            return skip(&format!(
                "no DISPLAY and Xvfb cannot start ({e}; `apt-get install xvfb`)"
            ))
        }
    };
    let mut line = String::new();
    let read = child
        .stdout
        .take()
        .map(|out| std::io::BufReader::new(out).read_line(&mut line));
    let number = line.trim().parse::<u32>();
    let Ok(n) = number else {
        let _ = child.kill();
        panic!("Xvfb did not say which display it took ({read:?}, `{line}`)");
    };
    let display = Display {
        name: format!(":{n}"),
        xvfb: Some(child),
    };
    Some(display)
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sdfc-view-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Waits for `path` to exist, while `child` runs.
fn wait_for(path: &Path, child: &mut Child, log: &Path) -> Image {
    let start = Instant::now();
    loop {
        if path.exists() {
            return read_png(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        }
        if let Ok(Some(status)) = child.try_wait() {
            panic!(
                "the viewer stopped ({status}) before writing {}:\n{}",
                path.display(),
                std::fs::read_to_string(log).unwrap_or_default()
            );
        }
        if start.elapsed() > PATIENCE {
            let _ = child.kill();
            panic!(
                "no {} after {PATIENCE:?}:\n{}",
                path.display(),
                std::fs::read_to_string(log).unwrap_or_default()
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Waits for `child` to exit on its own, within [`PATIENCE`], checks that it succeeded and
/// returns its log.
fn exited(child: &mut Child, log: &Path) -> String {
    let deadline = Instant::now() + PATIENCE;
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        assert!(Instant::now() < deadline, "the viewer did not exit");
        std::thread::sleep(Duration::from_millis(20));
    };
    let stderr = std::fs::read_to_string(log).unwrap();
    assert!(status.success(), "the viewer failed: {status}\n{stderr}");
    stderr
}

/// The mean colour of the pixels in the box (fractions of the image's width and height).
fn mean(image: &Image, x: (f64, f64), y: (f64, f64)) -> [f32; 3] {
    let (w, h) = (image.width as f64, image.height as f64);
    let mut sum = [0.0f64; 3];
    let mut n = 0.0;
    for py in (y.0 * h) as u32..(y.1 * h) as u32 {
        for px in (x.0 * w) as u32..(x.1 * w) as u32 {
            let c = image.pixel(px, py);
            for i in 0..3 {
                sum[i] += c[i] as f64;
            }
            n += 1.0;
        }
    }
    sum.map(|s| (s / n) as f32)
}

/// The fraction of pixels in the box that differ by more than 0.02 in some channel.
fn changed(a: &Image, b: &Image, x: (f64, f64), y: (f64, f64)) -> f64 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let (w, h) = (a.width as f64, a.height as f64);
    let (mut diff, mut n) = (0.0, 0.0);
    for py in (y.0 * h) as u32..(y.1 * h) as u32 {
        for px in (x.0 * w) as u32..(x.1 * w) as u32 {
            let (p, q) = (a.pixel(px, py), b.pixel(px, py));
            if (0..3).any(|i| (p[i] - q[i]).abs() > 0.02) {
                diff += 1.0;
            }
            n += 1.0;
        }
    }
    diff / n
}

/// The centre of the picture: the sphere.
const CENTRE: ((f64, f64), (f64, f64)) = ((0.45, 0.55), (0.45, 0.55));
/// The left quarter: where the structural edit adds a box.
const LEFT: ((f64, f64), (f64, f64)) = ((0.0, 0.25), (0.2, 0.9));

/// Opens the viewer with `args` (besides the file and the screenshot folder), edits the file
/// three times, and checks each reload's screenshot.
fn follows_edits(name: &str, display: Option<&Display>, args: &[&str]) {
    let dir = temp_dir(name);
    let scene = dir.join("scene.sdf");
    std::fs::write(&scene, SCENE).unwrap();
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

/// Runs the viewer for a few frames with `env` and checks the screenshot; returns stderr.
fn screenshot_after_frames(name: &str, env: &[(&str, &str)]) -> String {
    let Some(display) = display() else {
        return String::new();
    };
    let dir = temp_dir(name);
    std::fs::write(dir.join("scene.sdf"), SCENE).unwrap();
    std::fs::create_dir_all(dir.join("xdg")).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&dir)
        .args([
            "view",
            "scene.sdf",
            "--size",
            "200x100",
            "--frames",
            "6",
            "--screenshot",
            "shot.png",
        ])
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
    let dir = temp_dir("interim");
    let scene = dir.join("scene.sdf");
    std::fs::write(&scene, SCENE).unwrap();
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

/// Runs `sdfc view … --headless --backend cpu` in `dir` and waits at most a minute for it to
/// exit by itself (killed after that, which fails the test): its status and stderr.
fn headless_run(dir: &Path, args: &[&str]) -> (std::process::ExitStatus, String) {
    let log = dir.join("stderr.log");
    let mut child = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(dir)
        .arg("view")
        .args(args)
        .args(["--headless", "--backend", "cpu"])
        .stderr(std::fs::File::create(&log).unwrap())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if started.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            let _ = child.wait();
            panic!(
                "`sdfc view {}` did not exit:\n{}",
                args.join(" "),
                std::fs::read_to_string(&log).unwrap_or_default()
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    (status, std::fs::read_to_string(&log).unwrap_or_default())
}

/// Headless through wgpu (lavapipe without a GPU), the frames stay on the device and the
/// screenshot is read back from it: the scene's picture, after its kernel compiled on another
/// thread; and `--backend auto` says what it found.
#[test]
fn headless_wgpu_screenshot_shows_the_scene() {
    let dir = temp_dir("headless-wgpu");
    std::fs::write(dir.join("scene.sdf"), SCENE).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&dir)
        .args(["view", "scene.sdf", "--headless", "--backend", "wgpu"])
        .args([
            "--size",
            "64x48",
            "--frames",
            "3",
            "--screenshot",
            "shot.png",
        ])
        .args(["--timings"])
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    if stderr.contains("the Wgpu backend is not available") {
        assert!(!required(), "{stderr}");
        eprintln!("SKIPPED: no wgpu adapter\n{stderr}");
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
    let check = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&dir)
        .args(["check", "scene.sdf"])
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&check.stderr).into_owned()
        + &String::from_utf8_lossy(&check.stdout);
    assert!(
        said.contains("tone curve: filmic (the default where it is path traced"),
        "{said}"
    );
    let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&dir)
        .args(["view", "scene.sdf", "--headless", "--backend", "wgpu"])
        .args([
            "--size",
            "64x48",
            "--frames",
            "40",
            "--screenshot",
            "shot.png",
        ])
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    if stderr.contains("the Wgpu backend is not available") {
        assert!(!required(), "{stderr}");
        eprintln!("SKIPPED: no wgpu adapter\n{stderr}");
        return;
    }
    assert!(out.status.success(), "{stderr}");
    let rendered = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&dir)
        .args([
            "render",
            "scene.sdf",
            "--backend",
            "wgpu",
            "--size",
            "64x48",
        ])
        .args(["-o", "render.png"])
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .unwrap();
    assert!(
        rendered.status.success(),
        "{}",
        String::from_utf8_lossy(&rendered.stderr)
    );
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
    let one = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&dir)
        .args(["view", "scene.sdf", "--headless", "--backend", "wgpu"])
        .args([
            "--size",
            "64x48",
            "--frames",
            "1",
            "--screenshot",
            "one.png",
        ])
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .unwrap();
    assert!(one.status.success());
    let one = read_png(&dir.join("one.png")).unwrap();
    assert_ne!(one.linear, shot.linear);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `sdfc view scene.sdf --headless` (auto) in `dir` for one frame: its status and stderr.
fn headless_auto(dir: &Path) -> (std::process::ExitStatus, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(dir)
        .args(["view", "scene.sdf", "--headless", "--size", "32x24"])
        .args(["--frames", "1", "--screenshot", "auto.png"])
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .unwrap();
    (
        out.status,
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Headless with `--frames`, the settled image counts as frames: a scene that converges in
/// fewer frames than asked for (`aa: 2`) stops and writes its screenshot.
#[test]
fn headless_frames_stop_after_the_image_settles() {
    let dir = temp_dir("headless-frames");
    std::fs::write(dir.join("scene.sdf"), SCENE).unwrap();
    let (status, stderr) = headless_run(
        &dir,
        &[
            "scene.sdf",
            "--size",
            "64x48",
            "--frames",
            "40",
            "--screenshot",
            "shot.png",
        ],
    );
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
        let (status, stderr) = headless_run(
            &dir,
            &[
                file,
                "--size",
                "32x24",
                "--frames",
                "3",
                "--screenshot",
                "shot.png",
            ],
        );
        assert!(!status.success(), "{file}: {stderr}");
        assert!(stderr.contains("no screenshot written"), "{file}: {stderr}");
        assert!(
            !dir.join("shot.png").exists(),
            "{file}: a screenshot was written"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
