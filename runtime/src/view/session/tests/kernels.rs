//! The session's kernels compiling on other threads: shown interpreted until the specialised
//! one is ready (or not, within the grace period), stale compiles, the kernel at the animation's
//! time, and a parameter's change that keeps it.

use super::*;

#[test]
fn a_new_kernel_is_shown_interpreted_until_the_specialised_one_is_ready() {
    let Some(gpu) = wgpu() else { return };
    let (mut s, dir) = settled_on_marched(&gpu, "interim", interim());
    assert_eq!(s.last.unwrap().kernel, Some("specialised"));
    s.rotate(20.0, 5.0);
    let camera = s.camera();
    settle_all(&mut s);
    let before = s.image().unwrap();

    // A structural edit needs a new specialised kernel, which compiles on another thread
    // (held back here until the interpreted kernel's image has converged).
    add_the_box(&mut s, &dir);
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
    assert_appeared(&before, &specialised);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_kernel_ready_within_the_grace_period_is_shown_with_no_interpreted_frame() {
    // An hour's grace period stands for a driver that compiles within it: the compile,
    // held back until the interpreted kernel is ready too, ends within it however busy the
    // machine.
    let Some(gpu) = wgpu() else { return };
    let (mut s, dir) = settled_on_marched(&gpu, "grace-in", an_hours_grace());
    let before = s.image().unwrap();

    add_the_box(&mut s, &dir);
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
    assert_appeared(&before, &s.image().unwrap());
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

    add_the_box(&mut s, &dir);
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
    let options = specialised();
    let (mut s, dir) = settled_on_marched(&gpu, "off-thread", options);
    let before = s.image().unwrap();

    add_the_box(&mut s, &dir);
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
    assert_appeared(&before, &s.image().unwrap());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_stale_compile_does_not_end_a_newer_loads_grace_period() {
    // Load 1's compile ends while load 2's scene waits its grace period (an hour) for its
    // own, held back: nothing is rendered until load 2's compile has ended, and then its
    // specialised kernel is shown first.
    let Some(gpu) = wgpu() else { return };
    let (mut s, dir, newer) = stale_compile(&gpu, "grace-stale", an_hours_grace());
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
    let options = specialised();
    let mut reference = loaded(dir.join("k.sdf"), options, Device::Wgpu(gpu));
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
    let (dir, file) = temp_file("interim-t", "a.sdf");
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
    let options = specialised();
    let mut reference = loaded(file.clone(), paused(options), Device::Wgpu(gpu));
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

/// A traced scene with parameters keeps its kernel when a parameter changes a size: its
/// primitives are walked in `scene_data`, so the change is new data, not a new kernel, and
/// the picture is the one a session started with the new value shows.
#[test]
fn a_parameter_of_a_traced_scene_keeps_the_kernel() {
    let Some(gpu) = wgpu() else { return };
    let (dir, file) = temp_file("traced-param", "ball.sdf");
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
    let mut s = loaded(file.clone(), Options::default(), Device::Wgpu(gpu.clone()));
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
    let mut fresh = loaded(file, options, Device::Wgpu(gpu));
    settle_all(&mut fresh);
    assert_eq!(fresh.image(), Some(changed));
    let _ = std::fs::remove_dir_all(&dir);
}
