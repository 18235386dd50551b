//! `sdfc view`: the live preview follows edits of its scene file. Each test opens the viewer on a
//! scene copied to a temporary folder, rewrites the file with a numeric edit (a colour), a
//! structural edit (a new shape, saved by writing a new file and renaming it over the old one)
//! and an edit with an error, and checks from the screenshot written after each reload
//! (`--screenshot-dir`, `reload-K.png`) that the picture changes as it should and that the
//! error leaves the last good image on show (`edits`); the window's screenshots (`window`),
//! the viewer without a window (`headless`) and the parameter panel (`panel`) are modules of
//! their own, this file their helpers.
//!
//! The window tests run under X: on `DISPLAY` when it is set, else on an Xvfb of their own
//! (which picks a free display number); wgpu presents through Vulkan (lavapipe on a machine without a
//! GPU). Where Xvfb or a Vulkan driver is missing they print that they skipped, unless
//! `SDFC_REQUIRE_DEVICES=1` (set by `.ci/run`): then they fail. The headless test needs neither.

mod edits;
mod headless;
mod panel;
mod window;

use sdfc_runtime::image::{read_png, Image};
use std::io::BufRead;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// The materials, camera and light of the tests' scenes: a grey floor and a red ball, seen
/// from the front, lit from the viewer's right (world −x).
macro_rules! studio {
    () => {
        r#"material grey = phong { color: (0.6, 0.6, 0.6) };
material ball = phong { color: (0.9, 0.1, 0.1) };
camera { position: (0, 1.5, -5), look_at: (0, 0.6, 0), fov: 50deg }
light point { position: (-3, 5, -4), intensity: 1 }
"#
    };
}
use studio;

/// A plane and a red sphere in the middle of the picture, lit from the viewer's right (world
/// −x), so that the shadows of shapes added on the left (world +x) stay on the left.
const SCENE: &str = concat!(
    "\n",
    studio!(),
    r#"render { width: 160, height: 120, aa: 2, max_steps: 128 }
scene {
  plane((0, 1, 0), 0) @ grey;
  sphere(0.8).translate(0, 0.8, 0) @ ball;
}
"#
);

/// How long one reload may take to reach its screenshot (lavapipe on a busy 2-core machine).
const PATIENCE: Duration = Duration::from_secs(180);

/// The words of `line`, split at white space: a command's arguments written as one line.
fn words(line: &str) -> Vec<&str> {
    line.split_whitespace().collect()
}

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
        .args(words("-displayfd 1 -screen 0 1024x768x24 -nolisten tcp"))
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

/// A fresh directory for the test `name` holding `text` as `scene.sdf`: the directory and the
/// scene's path.
fn scene_dir(name: &str, text: &str) -> (PathBuf, PathBuf) {
    let dir = temp_dir(name);
    let scene = dir.join("scene.sdf");
    std::fs::write(&scene, text).unwrap();
    (dir, scene)
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
