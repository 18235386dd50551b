//! The viewer session's tests: the helpers, frames on the device, animation (lavapipe where a
//! GPU is wanted); kernels compiling on other threads are `kernels`', loads and edits `loads`',
//! path-traced scenes `path`'s.

use super::*;

mod kernels;
mod loads;
mod path;

const SCENE: &str = "camera { position: (0, 1, -4), look_at: (0, 0.5, 0), fov: 50deg }\n\
    light point { position: (2, 4, -3), intensity: 1 }\n\
    render { width: 32, height: 24, aa: 2 }\n\
    scene { plane((0, 1, 0), 0); sphere(0.5).translate(0, 0.5, 0); }\n";

fn settle(s: &mut Session) -> u32 {
    let mut frames = 0;
    while s.wants_frame() {
        s.frame().expect("a CPU frame");
        frames += 1;
    }
    frames
}

/// A fresh directory `sdfc-{name}-{process}` of the temporary directory.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sdfc-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// [`temp_dir`] and the path of its file `file`.
fn temp_file(name: &str, file: &str) -> (PathBuf, PathBuf) {
    let dir = temp_dir(name);
    let file = dir.join(file);
    (dir, file)
}

/// A session of `file` with `options` on `device`, 32×24, loaded without errors.
#[track_caller]
fn loaded(file: PathBuf, options: Options, device: Device) -> Session {
    let mut s = Session::new(file, options, device);
    s.set_size(32, 24);
    assert!(s.load().ok);
    s
}

/// The options of a session that shows the specialised kernel alone.
fn specialised() -> Options {
    Options {
        kernel: Kernel::Specialised,
        ..Options::default()
    }
}

/// Writes `text` to `file` and loads it, the compile of load `held` held back.
#[track_caller]
fn load_held(s: &mut Session, file: &Path, text: &str, held: u32) {
    std::fs::write(file, text).unwrap();
    s.held = Some(held);
    assert!(s.load().ok);
}

/// Fails unless the session's title ends with `tail`.
#[track_caller]
fn assert_title_ends(s: &Session, tail: &str) {
    let title = s.title(false);
    assert!(title.ends_with(tail), "{title}");
}

/// Fails unless `after` differs from `before` (the box that an edit added appeared).
#[track_caller]
fn assert_appeared(before: &Image, after: &Image) {
    let changed = crate::metrics::compare(before, after, 0.1).unwrap();
    assert!(changed.differing > 0.01, "the box appeared: {changed:?}");
}

/// The longest a test waits for lavapipe to compile a kernel on a busy 2-core machine.
const PATIENCE: Duration = Duration::from_secs(300);

/// A wgpu device (lavapipe on a machine without a GPU), or `None` after saying the test
/// skipped (a failure under `SDFC_REQUIRE_DEVICES=1`).
fn wgpu() -> Option<Arc<Gpu>> {
    match Gpu::open(false) {
        Ok(gpu) => Some(Arc::new(gpu)),
        Err(e) => {
            assert!(
                std::env::var("SDFC_REQUIRE_DEVICES").as_deref() != Ok("1"),
                "SDFC_REQUIRE_DEVICES=1 but no wgpu adapter: {e}"
            );
            eprintln!("session test SKIPPED: no wgpu adapter ({e})");
            None
        }
    }
}

/// The options of a session that shows the interpreted kernel while the specialised one
/// compiles, on lavapipe too, as soon as its pipeline is ready (no grace period).
fn interim() -> Options {
    Options {
        interim_on_cpu: true,
        grace: Duration::ZERO,
        ..Options::default()
    }
}

/// [`interim`]'s options with a grace period of an hour: one within which any compile ends.
fn an_hours_grace() -> Options {
    Options {
        grace: Duration::from_secs(3600),
        ..interim()
    }
}

/// The compile the scene on show waits for.
fn waiting(s: &Session) -> &Waiting {
    s.good
        .as_ref()
        .and_then(|g| g.waiting.as_ref())
        .expect("a compile")
}

/// Renders until the image is final, waiting for the kernels compiling on other threads.
fn settle_all(s: &mut Session) {
    let start = Instant::now();
    while !s.settled() {
        assert!(start.elapsed() < PATIENCE, "the session never settled");
        s.wait_for_compile(Duration::from_secs(1));
        s.frame().expect("a frame");
    }
}

/// Waits until the held specialised compile of the scene on show has ended, then lets the
/// session take it.
fn release_when_compiled(s: &mut Session) {
    let start = Instant::now();
    while !waiting(s).compile.finished() {
        assert!(start.elapsed() < PATIENCE, "the compile never ended");
        s.wait_for_compile(Duration::from_secs(1));
    }
    s.held = None;
}

/// Renders (none is rendered, in the grace period of a held compile) until the interpreted
/// kernel's pipeline is ready, and once more.
fn nothing_in_the_grace_period(s: &mut Session) {
    let start = Instant::now();
    loop {
        let interim = waiting(s).interim.as_ref().expect("an interpreted kernel");
        let ready = interim.compile.is_none();
        assert!(
            start.elapsed() < PATIENCE,
            "the interpreted kernel never compiled"
        );
        s.wait_for_compile(Duration::from_secs(1));
        let frame = s.frame().expect("no render error");
        assert!(frame.is_none(), "a frame in the grace period");
        if ready {
            return;
        }
    }
}

/// The next frame rendered (waiting for a kernel when there is none to render with).
fn next_frame(s: &mut Session) -> FrameInfo {
    let start = Instant::now();
    loop {
        assert!(start.elapsed() < PATIENCE, "no frame was rendered");
        s.wait_for_compile(Duration::from_secs(1));
        if let Some(info) = s.frame().expect("a frame") {
            return info;
        }
    }
}

/// The text of the kernel the session keeps for its scene (the specialised one).
fn kernel_text(s: &Session) -> String {
    let p = &s.good.as_ref().expect("a scene").prepared;
    match p.as_wgpu() {
        Some(w) => w.kernel.source.clone(),
        None => panic!("not a wgpu scene: {}", p.name()),
    }
}

/// A session with `options` on the first of [`marched`]'s scenes, in `k.sdf` of a fresh
/// directory named after `name`, loaded and settled: the session and the directory.
fn settled_on_marched(gpu: &Arc<Gpu>, name: &str, options: Options) -> (Session, PathBuf) {
    let (dir, file) = temp_file(name, "k.sdf");
    std::fs::write(&file, &marched()[0]).unwrap();
    let mut s = loaded(file, options, Device::Wgpu(gpu.clone()));
    settle_all(&mut s);
    (s, dir)
}

/// A session with `options` on the marched scene, settled, then two edits: load 1 (a box
/// more), whose kernel compiles, and load 2 (a torus instead), whose compile is held back;
/// returned once load 1's compile has ended, with the scene's directory (named after
/// `name`) and load 2's kernel.
fn stale_compile(gpu: &Arc<Gpu>, name: &str, options: Options) -> (Session, PathBuf, String) {
    let (mut s, dir) = settled_on_marched(gpu, name, options);
    let file = dir.join("k.sdf");
    let [_, boxed, torus] = marched();
    std::fs::write(&file, &boxed).unwrap();
    assert!(s.load().ok);
    let stale = kernel_text(&s);
    load_held(&mut s, &file, &torus, 2);
    let newer = kernel_text(&s);
    assert_ne!(stale, newer);
    let start = Instant::now();
    while !gpu.has_pipeline(&stale, wgsl::ENTRY_POINT, true) {
        assert!(start.elapsed() < PATIENCE, "load 1's compile never ended");
        std::thread::sleep(Duration::from_millis(10));
    }
    (s, dir, newer)
}

/// Loads the edit of [`settled_on_marched`]'s scene in `dir` that adds a box, its compile held
/// back.
fn add_the_box(s: &mut Session, dir: &Path) {
    let [_, boxed, _] = marched();
    load_held(s, &dir.join("k.sdf"), &boxed, 1);
}

/// A marched scene (the interpreted kernel renders marched scenes alone), and two
/// structural edits of it (new kernels).
fn marched() -> [String; 3] {
    let base = SCENE.replace("aa: 2 }", "aa: 2, method: \"march\" }");
    let edit = |shape: &str| {
        base.replace(
            "sphere(0.5).translate(0, 0.5, 0);",
            &format!("sphere(0.5).translate(0, 0.5, 0); {shape};"),
        )
    };
    [
        base.clone(),
        edit("box((0.3, 0.3, 0.3)).translate(-1.2, 0.3, 0)"),
        edit("torus(0.4, 0.1).translate(1.2, 0.1, 0)"),
    ]
}

#[test]
fn frames_on_the_device_accumulate_the_kernels_renders() {
    // On wgpu the frames stay on the device: the image, read back once settled, is the
    // mean of the kernel's renders through `sdfc render`'s path of the scene's aa × aa
    // jittered cameras, value for value; the window is given a texture, and the host holds
    // no image.
    let Some(gpu) = wgpu() else { return };
    let (dir, file) = temp_file("resident", "s.sdf");
    std::fs::write(&file, &marched()[0]).unwrap();
    let mut s = loaded(file, specialised(), Device::Wgpu(gpu));
    settle_all(&mut s);
    assert_eq!(s.last.unwrap().samples, 4);
    assert!(s.texture().is_some(), "a texture on show");
    assert!(s.host_image().is_none(), "no frame crossed to the host");
    let shown = s.image().expect("the image, read back");
    let base = s.camera().unwrap();
    let good = s.good.as_ref().unwrap();
    let mut scene = good.scene.clone();
    let mut sum = vec![[0.0f32; 3]; 32 * 24];
    for k in 0..4 {
        let (dx, dy) = camera::sample_offset(k, 2);
        scene.camera = camera::jittered(&base, dx, dy, 32, 24);
        let frame = good.prepared.render(&scene, &|_| {}).expect("a render");
        for (s, c) in sum.iter_mut().zip(&frame.render.image.linear) {
            for i in 0..3 {
                s[i] += c[i];
            }
        }
    }
    let inv = 1.0 / 4.0f32;
    let mean = Image {
        width: 32,
        height: 24,
        linear: sum
            .iter()
            .map(|c| [c[0] * inv, c[1] * inv, c[2] * inv])
            .collect(),
    };
    assert_eq!(shown, mean);
    // The statistics' steps per pixel are read back when asked for, and only then: those
    // of the frame on show at once (the last jittered sample's).
    let last = good.prepared.render(&scene, &|_| {}).expect("a render");
    assert!(s.last.unwrap().steps.is_nan());
    s.want_steps(true);
    assert_eq!(s.last.unwrap().steps, last.render.stats.steps_mean);
    s.rotate(1.0, 0.0);
    let info = s.frame().expect("a frame").expect("a frame while moving");
    let good = s.good.as_ref().unwrap();
    let frame = good
        .prepared
        .render(&good.scene, &|_| {})
        .expect("a render");
    assert!(info.steps > 1.0, "{info:?}");
    assert_eq!(info.steps, frame.render.stats.steps_mean);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_animated_scene_plays_and_pauses() {
    let (dir, file) = temp_file("play", "a.sdf");
    let animated = SCENE
        .replace("aa: 2 }", "aa: 2, fps: 200, duration: 10 }")
        .replace(
            "sphere(0.5).translate(0, 0.5, 0)",
            "sphere(0.5).translate(0, 0.5 + t, 0)",
        );
    std::fs::write(&file, animated).unwrap();
    let mut s = loaded(file, Options::default(), Device::Cpu);
    assert!(s.playing(), "a window plays the animation");
    assert!(
        s.wants_frame(),
        "a playing animation always has a frame to render"
    );
    s.frame().expect("a frame");
    let first = s.image().unwrap();
    std::thread::sleep(Duration::from_millis(300));
    s.frame().expect("a frame");
    assert!(s.time().unwrap() > 0.0, "the clock moved on");
    assert_ne!(s.image().unwrap(), first, "the sphere rose");
    assert!(s.title(false).contains("playing"));
    // Paused, the time stays and the samples accumulate to the scene's aa.
    s.toggle_pause();
    assert!(!s.playing() && s.title(false).contains("paused"));
    let at = s.time();
    settle(&mut s);
    assert!(s.settled());
    std::thread::sleep(Duration::from_millis(50));
    assert_eq!(s.time(), at);
    s.toggle_pause();
    assert!(s.playing());
    let _ = std::fs::remove_dir_all(&dir);
}
