//! The viewer session's tests: loads, edits, kernels compiling on other threads, frames on
//! the device, animation (lavapipe where a GPU is wanted).

use super::*;

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
    let dir = std::env::temp_dir().join(format!("sdfc-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("k.sdf");
    std::fs::write(&file, &marched()[0]).unwrap();
    let mut s = Session::new(file, options, Device::Wgpu(gpu.clone()));
    s.set_size(32, 24);
    assert!(s.load().ok);
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
    std::fs::write(&file, &torus).unwrap();
    s.held = Some(2);
    assert!(s.load().ok);
    let newer = kernel_text(&s);
    assert_ne!(stale, newer);
    let start = Instant::now();
    while !gpu.has_pipeline(&stale, wgsl::ENTRY_POINT, true) {
        assert!(start.elapsed() < PATIENCE, "load 1's compile never ended");
        std::thread::sleep(Duration::from_millis(10));
    }
    (s, dir, newer)
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
fn a_new_kernel_is_shown_interpreted_until_the_specialised_one_is_ready() {
    let Some(gpu) = wgpu() else { return };
    let (mut s, dir) = settled_on_marched(&gpu, "interim", interim());
    let file = dir.join("k.sdf");
    let [_, boxed, _] = marched();
    assert_eq!(s.last.unwrap().kernel, Some("specialised"));
    s.rotate(20.0, 5.0);
    let camera = s.camera();
    settle_all(&mut s);
    let before = s.image().unwrap();

    // A structural edit needs a new specialised kernel, which compiles on another thread
    // (held back here until the interpreted kernel's image has converged).
    std::fs::write(&file, &boxed).unwrap();
    s.held = Some(1);
    assert!(s.load().ok);
    assert!(s.compiling() && !s.settled());
    let info = next_frame(&mut s);
    assert_eq!(
        info.kernel,
        Some("interpreted"),
        "the interpreted kernel first"
    );
    assert!(s.title(false).contains("interpreted while compiling"));
    while s.wants_frame() {
        s.frame().expect("a frame");
    }
    assert!(!s.settled(), "the specialised kernel is still to come");
    let interpreted = s.image().unwrap();
    assert_eq!(
        s.last.unwrap().samples,
        4,
        "the interpreted image converged"
    );
    release_when_compiled(&mut s);
    settle_all(&mut s);
    assert_eq!(
        s.last.unwrap().kernel,
        Some("specialised"),
        "then the specialised"
    );
    assert!(!s.title(false).contains("compiling"));
    assert_eq!(s.camera(), camera, "the camera stayed");
    let specialised = s.image().unwrap();
    let same = crate::metrics::compare(&interpreted, &specialised, 0.1).unwrap();
    assert!(same.psnr >= 40.0, "the two kernels agree: {same:?}");
    let changed = crate::metrics::compare(&before, &specialised, 0.1).unwrap();
    assert!(changed.differing > 0.01, "the box appeared: {changed:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_kernel_ready_within_the_grace_period_is_shown_with_no_interpreted_frame() {
    // An hour's grace period stands for a driver that compiles within it: the compile,
    // held back until the interpreted kernel is ready too, ends within it however busy the
    // machine.
    let Some(gpu) = wgpu() else { return };
    let options = Options {
        grace: Duration::from_secs(3600),
        ..interim()
    };
    let (mut s, dir) = settled_on_marched(&gpu, "grace-in", options);
    let file = dir.join("k.sdf");
    let [_, boxed, _] = marched();
    let before = s.image().unwrap();

    std::fs::write(&file, &boxed).unwrap();
    s.held = Some(1);
    assert!(s.load().ok);
    assert!(s.compiling() && s.grace_deadline().is_some());
    // Nothing is rendered in the grace period, not even once the interpreted kernel's
    // pipeline is ready: the image before stays on show.
    nothing_in_the_grace_period(&mut s);
    assert!(!s.wants_frame() && !s.settled());
    assert!(s.title(false).contains("compiling the kernel"));
    assert_eq!(s.image(), Some(before.clone()));
    release_when_compiled(&mut s);
    let info = next_frame(&mut s);
    assert_eq!(
        info.kernel,
        Some("specialised"),
        "the specialised kernel first"
    );
    assert!(!s.compiling() && s.grace_deadline().is_none());
    let t = s.timings.as_ref().expect("the load's timings");
    assert_eq!(t.first_kernel, Some("specialised"));
    assert!(
        t.ready.is_some_and(|(_, within)| within),
        "ready within the grace period: {:?}",
        t.ready
    );
    // The words `--timings` prints (and scripts/bench.py's view suite reads).
    let words = t.pipeline_words(s.options.grace);
    assert!(
        words.contains("on another thread, specialised compiled within the grace period in"),
        "{words}"
    );
    settle_all(&mut s);
    assert_eq!(s.last.unwrap().kernel, Some("specialised"));
    let changed = crate::metrics::compare(&before, &s.image().unwrap(), 0.1).unwrap();
    assert!(changed.differing > 0.01, "the box appeared: {changed:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_kernel_not_ready_within_the_grace_period_is_shown_interpreted_first() {
    // The compile is held back past the grace period (the viewer's own): the interpreted
    // kernel shows the scene from the period's end until the specialised kernel is ready.
    let Some(gpu) = wgpu() else { return };
    let options = Options {
        grace: GRACE,
        ..interim()
    };
    let (mut s, dir) = settled_on_marched(&gpu, "grace-out", options);
    let file = dir.join("k.sdf");
    let [_, boxed, _] = marched();

    std::fs::write(&file, &boxed).unwrap();
    s.held = Some(1);
    assert!(s.load().ok);
    let w = waiting(&s);
    let end = w.grace_until;
    assert_eq!(end, w.compile.started + GRACE);
    let info = next_frame(&mut s);
    assert!(
        Instant::now() >= end,
        "an interpreted frame in the grace period"
    );
    assert_eq!(
        info.kernel,
        Some("interpreted"),
        "the interpreted kernel first"
    );
    assert!(s.compiling() && s.grace_deadline().is_none());
    assert!(s.title(false).contains("interpreted while compiling"));
    let t = s.timings.as_ref().expect("the load's timings");
    assert_eq!((t.first_kernel, t.ready), (Some("interpreted"), None));
    let words = t.pipeline_words(s.options.grace);
    assert!(
        words.contains("not ready within the 50 ms grace period, interpreted while compiling"),
        "{words}"
    );
    release_when_compiled(&mut s);
    settle_all(&mut s);
    assert_eq!(s.last.unwrap().kernel, Some("specialised"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_new_kernel_compiles_off_the_callers_thread_and_the_image_before_stays() {
    // With no interpreted kernel to show meanwhile (`--kernel specialised` here; `auto`
    // on lavapipe), a structural edit's load returns before its pipeline is compiled, so
    // that a window's event loop goes on answering: nothing is rendered, the image before
    // stays, the title says the kernel compiles, and the new kernel is shown once ready.
    let Some(gpu) = wgpu() else { return };
    let options = Options {
        kernel: Kernel::Specialised,
        ..Options::default()
    };
    let (mut s, dir) = settled_on_marched(&gpu, "off-thread", options);
    let file = dir.join("k.sdf");
    let [_, boxed, _] = marched();
    let before = s.image().unwrap();

    std::fs::write(&file, &boxed).unwrap();
    s.held = Some(1);
    assert!(s.load().ok);
    assert!(s.compiling() && !s.wants_frame() && !s.settled());
    assert!(
        s.grace_deadline().is_none(),
        "no grace period without an interpreted kernel"
    );
    assert!(s.title(false).contains("compiling the kernel"));
    assert!(s.frame().expect("no render error").is_none());
    assert_eq!(s.image(), Some(before.clone()), "the image before stays");
    release_when_compiled(&mut s);
    let info = next_frame(&mut s);
    assert_eq!(info.kernel, Some("specialised"));
    assert!(!s.compiling() && !s.title(false).contains("compiling"));
    let t = s.timings.as_ref().expect("the load's timings");
    assert!(t.background && !t.interim && t.pipeline.is_some());
    let words = t.pipeline_words(s.options.grace);
    assert!(
        words.contains("on another thread, shown once ready")
            && words.contains("no interpreted kernel meanwhile"),
        "{words}"
    );
    settle_all(&mut s);
    let changed = crate::metrics::compare(&before, &s.image().unwrap(), 0.1).unwrap();
    assert!(changed.differing > 0.01, "the box appeared: {changed:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn frames_on_the_device_accumulate_the_kernels_renders() {
    // On wgpu the frames stay on the device: the image, read back once settled, is the
    // mean of the kernel's renders through `sdfc render`'s path of the scene's aa × aa
    // jittered cameras, value for value; the window is given a texture, and the host holds
    // no image.
    let Some(gpu) = wgpu() else { return };
    let dir = std::env::temp_dir().join(format!("sdfc-resident-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("s.sdf");
    std::fs::write(&file, &marched()[0]).unwrap();
    let options = Options {
        kernel: Kernel::Specialised,
        ..Options::default()
    };
    let mut s = Session::new(file, options, Device::Wgpu(gpu));
    s.set_size(32, 24);
    assert!(s.load().ok);
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
fn edit_to_pixel_counts_from_the_edit() {
    // A file renamed back keeps its old modification time: the edit is when the watcher
    // saw it. A file written after the event counts from its writing.
    let old = SystemTime::UNIX_EPOCH + Duration::from_secs(1_000_000);
    let seen = old + Duration::from_secs(3600);
    assert_eq!(edit_time(Some(old), Some(seen)), Some(seen));
    let written = seen + Duration::from_millis(5);
    assert_eq!(edit_time(Some(written), Some(seen)), Some(written));
    assert_eq!(edit_time(Some(old), None), Some(old));
    assert_eq!(edit_time(None, Some(seen)), Some(seen));
}

#[test]
fn a_stale_compile_does_not_end_a_newer_loads_grace_period() {
    // Load 1's compile ends while load 2's scene waits its grace period (an hour) for its
    // own, held back: nothing is rendered until load 2's compile has ended, and then its
    // specialised kernel is shown first.
    let Some(gpu) = wgpu() else { return };
    let options = Options {
        grace: Duration::from_secs(3600),
        ..interim()
    };
    let (mut s, dir, newer) = stale_compile(&gpu, "grace-stale", options);
    nothing_in_the_grace_period(&mut s);
    assert_eq!(s.good.as_ref().unwrap().load, 2);
    assert!(s.compiling() && s.grace_deadline().is_some());
    release_when_compiled(&mut s);
    let info = next_frame(&mut s);
    assert_eq!(info.kernel, Some("specialised"));
    assert_eq!(kernel_text(&s), newer);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_stale_compile_does_not_replace_a_newer_edit() {
    let Some(gpu) = wgpu() else { return };
    let (mut s, dir, newer) = stale_compile(&gpu, "stale", interim());
    let info = next_frame(&mut s);
    assert_eq!(
        info.kernel,
        Some("interpreted"),
        "load 2's scene, interpreted"
    );
    assert_eq!(s.good.as_ref().unwrap().load, 2);
    s.held = None;
    settle_all(&mut s);
    assert_eq!(s.last.unwrap().kernel, Some("specialised"));
    assert_eq!(kernel_text(&s), newer);
    // What is shown is load 2's scene: the image of a session that compiled it at once.
    let shown = s.image().unwrap();
    let options = Options {
        kernel: Kernel::Specialised,
        ..Options::default()
    };
    let mut reference = Session::new(dir.join("k.sdf"), options, Device::Wgpu(gpu));
    reference.set_size(32, 24);
    assert!(reference.load().ok);
    assert!(
        !reference.compiling(),
        "`--kernel specialised` finds the kernel compiled for the session before"
    );
    settle_all(&mut reference);
    assert_eq!(reference.last.unwrap().kernel, Some("specialised"));
    assert_eq!(reference.image(), Some(shown));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_specialised_kernel_takes_over_at_the_animation_time_on_show() {
    // Paused at t = 0.5 s, the interpreted kernel shows the scene at that time, and so does
    // the specialised kernel that replaces it: the image of a session that compiled it at
    // once.
    let Some(gpu) = wgpu() else { return };
    let dir = std::env::temp_dir().join(format!("sdfc-interim-t-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("a.sdf");
    let animated = marched()[0]
        .replace(
            "method: \"march\" }",
            "method: \"march\", fps: 10, duration: 2 }",
        )
        .replace(
            "sphere(0.5).translate(0, 0.5, 0)",
            "sphere(0.5).translate(0, 0.5 + t, 0)",
        );
    std::fs::write(&file, animated).unwrap();
    let paused = |options: Options| Options {
        time: Some(0.5),
        ..options
    };
    let mut s = Session::new(file.clone(), paused(interim()), Device::Wgpu(gpu.clone()));
    s.set_size(32, 24);
    s.held = Some(0);
    assert!(s.load().ok);
    let info = next_frame(&mut s);
    assert_eq!(info.kernel, Some("interpreted"));
    assert_eq!(s.time(), Some(0.5));
    while s.wants_frame() {
        s.frame().expect("a frame");
    }
    let interpreted = s.image().unwrap();
    release_when_compiled(&mut s);
    settle_all(&mut s);
    assert_eq!(s.last.unwrap().kernel, Some("specialised"));
    assert_eq!(s.time(), Some(0.5), "the time on show stayed");
    let options = Options {
        kernel: Kernel::Specialised,
        ..Options::default()
    };
    let mut reference = Session::new(file.clone(), paused(options), Device::Wgpu(gpu));
    reference.set_size(32, 24);
    assert!(reference.load().ok);
    settle_all(&mut reference);
    assert_eq!(reference.time(), Some(0.5));
    assert_eq!(s.image(), reference.image());
    let same = crate::metrics::compare(&interpreted, &reference.image().unwrap(), 0.1);
    assert!(
        same.unwrap().psnr >= 40.0,
        "the interpreted kernel showed t = 0.5 s"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_animated_scene_plays_and_pauses() {
    let dir = std::env::temp_dir().join(format!("sdfc-play-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("a.sdf");
    let animated = SCENE
        .replace("aa: 2 }", "aa: 2, fps: 200, duration: 10 }")
        .replace(
            "sphere(0.5).translate(0, 0.5, 0)",
            "sphere(0.5).translate(0, 0.5 + t, 0)",
        );
    std::fs::write(&file, animated).unwrap();
    let mut s = Session::new(file, Options::default(), Device::Cpu);
    s.set_size(32, 24);
    assert!(s.load().ok);
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

#[test]
fn a_file_saved_in_place_is_read_once_written() {
    // An editor saving in place truncates the file, then writes it: a load that runs in
    // between waits for the contents instead of reporting an empty scene; a file that
    // stays empty is loaded as it is (and fails: no `scene` block).
    let dir = std::env::temp_dir().join(format!("sdfc-in-place-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("a.sdf");
    std::fs::write(&file, "").unwrap();
    let writer = {
        let file = file.clone();
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(100));
            std::fs::write(file, SCENE).unwrap();
        })
    };
    let mut s = Session::new(file.clone(), Options::default(), Device::Cpu);
    assert!(s.load().ok, "the load waited for the file's contents");
    writer.join().unwrap();
    std::fs::write(&file, "").unwrap();
    let started = Instant::now();
    let outcome = s.load();
    assert!(
        !outcome.ok && outcome.summary.contains("E0503"),
        "{}",
        outcome.summary
    );
    assert!(started.elapsed() >= EMPTY_PATIENCE);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn reloads_keep_the_moved_camera_and_errors_keep_the_image() {
    let dir = std::env::temp_dir().join(format!("sdfc-session-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("s.sdf");
    std::fs::write(&file, SCENE).unwrap();
    let mut s = Session::new(file.clone(), Options::default(), Device::Cpu);
    s.set_size(32, 24);
    assert!(s.load().ok);
    // aa 2: four jittered samples, then nothing more to render.
    assert_eq!(settle(&mut s), 4);
    assert!(s.settled());
    let first = s.image().unwrap();

    // The file's camera moves the view until the user moves it.
    std::fs::write(&file, SCENE.replace("(0, 1, -4)", "(0, 1.2, -4)")).unwrap();
    assert!(s.needs_reload(&[]));
    assert!(s.load().ok);
    assert!(!s.needs_reload(&[]), "nothing changed since");
    assert_eq!(s.camera().unwrap().position, [0.0, 1.2, -4.0]);
    s.rotate(30.0, 0.0);
    let moved = s.camera().unwrap();
    settle(&mut s);

    // A clean reload keeps the user's camera; R returns to the file's.
    std::fs::write(&file, SCENE.replace("sphere(0.5)", "sphere(0.6)")).unwrap();
    let outcome = s.load();
    assert!(outcome.ok && outcome.number == 2);
    assert_eq!(s.camera().unwrap(), moved);
    settle(&mut s);
    let good = s.image().unwrap();
    assert_ne!(good, first);

    // An edit with errors keeps the image and says why in the title.
    std::fs::write(&file, SCENE.replace("sphere(0.5)", "sphre(0.5)")).unwrap();
    let outcome = s.load();
    assert!(!outcome.ok);
    assert!(outcome.summary.contains("E0201"), "{}", outcome.summary);
    assert!(s.title(false).contains("E0201"));
    assert!(s.settled());
    assert_eq!(s.image(), Some(good.clone()));

    // So does a file that disappears; a failed load retries on any scene file's change.
    std::fs::remove_file(&file).unwrap();
    assert!(s.needs_reload(&[]));
    assert!(!s.load().ok);
    assert_eq!(s.image(), Some(good.clone()));
    assert!(s.needs_reload(&[dir.join("other.sdf")]));
    assert!(
        !s.needs_reload(std::slice::from_ref(&file)),
        "its contents are those it failed on"
    );
    s.reset_camera();
    assert!(!s.camera_moved());
    let _ = std::fs::remove_dir_all(&dir);
}

/// An ASCII STL of the tetrahedron with corners at the origin and at `size` along each axis.
fn tetrahedron_stl(size: f64) -> String {
    let [o, x, y, z] = [
        [0.0; 3],
        [size, 0.0, 0.0],
        [0.0, size, 0.0],
        [0.0, 0.0, size],
    ];
    let mut stl = String::from("solid t\n");
    for f in [[o, y, x], [o, x, z], [o, z, y], [x, y, z]] {
        stl.push_str(" facet normal 0 0 0\n  outer loop\n");
        for v in f {
            stl.push_str(&format!("   vertex {} {} {}\n", v[0], v[1], v[2]));
        }
        stl.push_str("  endloop\n endfacet\n");
    }
    stl + "endsolid t\n"
}

/// The files a scene reads besides its sources (a mesh) are watched as its imports are: a
/// change of the mesh file calls for a reload, and the reload shows the new mesh.
#[test]
fn a_changed_mesh_file_reloads() {
    let dir = std::env::temp_dir().join(format!("sdfc-session-mesh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (file, mesh) = (dir.join("s.sdf"), dir.join("part.stl"));
    std::fs::write(&mesh, tetrahedron_stl(1.0)).unwrap();
    std::fs::write(
        &file,
        SCENE.replace(
            "sphere(0.5).translate(0, 0.5, 0)",
            "mesh(\"part.stl\").translate(-0.3, 0, 0)",
        ),
    )
    .unwrap();
    let mut s = Session::new(file.clone(), Options::default(), Device::Cpu);
    s.set_size(32, 24);
    assert!(s.load().ok);
    assert!(
        s.files().iter().any(|f| f.ends_with("part.stl")),
        "{:?}",
        s.files()
    );
    assert!(!s.needs_reload(&[]));
    settle(&mut s);
    let before = s.image().unwrap();
    std::fs::write(&mesh, tetrahedron_stl(1.4)).unwrap();
    assert!(s.needs_reload(std::slice::from_ref(&mesh)));
    assert!(s.load().ok);
    assert!(!s.needs_reload(&[]), "nothing changed since");
    settle(&mut s);
    assert_ne!(s.image().unwrap(), before);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every load, the first and those after it (prepared as the scene before was), is held to the
/// `memory` limit at the view's size, whatever size the scene's settings state: a scene that
/// asks for a picture far above the limit is shown in a small view, and an edit loaded while
/// the view is larger than the limit allows is refused with the limit's message, the image
/// before staying on show.
#[test]
fn every_load_is_held_to_the_memory_limit_at_the_views_size() {
    let dir = std::env::temp_dir().join(format!("sdfc-session-memory-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("m.sdf");
    // 8000x6000 pixels: a render of the scene's size is far above 32 MiB.
    let huge = SCENE.replace("width: 32, height: 24", "width: 8000, height: 6000");
    std::fs::write(&file, &huge).unwrap();
    let mut job = Job::default();
    job.limits.apply("memory=32").unwrap();
    let options = Options {
        job,
        ..Options::default()
    };
    let mut s = Session::new(file.clone(), options, Device::Cpu);
    s.set_size(32, 24);
    let first = s.load();
    assert!(first.ok, "{}", first.summary);
    settle(&mut s);
    let shown = s.image().expect("an image");

    // A later load, in a view above the limit: refused, saying which limit.
    s.set_size(4000, 3000);
    std::fs::write(&file, huge.replace("sphere(0.5)", "sphere(0.6)")).unwrap();
    let refused = s.load();
    assert!(!refused.ok);
    assert!(
        refused
            .summary
            .contains("more than the memory limit of 32 MiB; raise it with `--limit memory="),
        "{}",
        refused.summary
    );
    assert!(
        s.title(false).contains("memory limit"),
        "{}",
        s.title(false)
    );
    assert_eq!(s.image(), Some(shown));

    // The same edit in a small view again loads.
    s.set_size(32, 24);
    let again = s.load();
    assert!(again.ok, "{}", again.summary);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A traced scene with parameters keeps its kernel when a parameter changes a size: its
/// primitives are walked in `scene_data`, so the change is new data, not a new kernel, and
/// the picture is the one a session started with the new value shows.
#[test]
fn a_parameter_of_a_traced_scene_keeps_the_kernel() {
    let Some(gpu) = wgpu() else { return };
    let dir = std::env::temp_dir().join(format!("sdfc-traced-param-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("ball.sdf");
    std::fs::write(
        &file,
        format!(
            "param r = 0.5 in 0.2..1.0;\n{}",
            SCENE.replace(
                "sphere(0.5).translate(0, 0.5, 0)",
                "sphere(r).translate(0, r, 0)"
            )
        ),
    )
    .unwrap();
    let mut s = Session::new(file.clone(), Options::default(), Device::Wgpu(gpu.clone()));
    s.set_size(32, 24);
    assert!(s.load().ok);
    settle_all(&mut s);
    let kernel = kernel_text(&s);
    assert!(
        kernel.contains("fn trace("),
        "the scene is traced analytically"
    );
    let before = s.image().unwrap();
    assert!(s.set_param("r", &sdfc_compiler::ParamValue::Float(0.8)).ok);
    assert!(!s.compiling(), "a size is new data for the kernel on show");
    assert_eq!(kernel_text(&s), kernel);
    settle_all(&mut s);
    let changed = s.image().unwrap();
    assert_ne!(changed, before);
    let mut options = Options::default();
    options.job.limits.set_param("r", "0.8");
    let mut fresh = Session::new(file, options, Device::Wgpu(gpu));
    fresh.set_size(32, 24);
    assert!(fresh.load().ok);
    settle_all(&mut fresh);
    assert_eq!(fresh.image(), Some(changed));
    let _ = std::fs::remove_dir_all(&dir);
}
