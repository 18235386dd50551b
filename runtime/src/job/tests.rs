//! The job's unit tests: the reference's backend and precision, settings overridden, threads,
//! the path from a source to frames, and errors naming their step.

use super::*;
use crate::backend::Device;
use crate::gpu::Gpu;
use sdfc_compiler::{analytic::Reason, wgsl, Limit};
use std::sync::Arc;

#[test]
fn the_reference_renders_on_the_cpu_in_f64_and_refuses_gpus() {
    let reference = |backend, devices| Job {
        backend,
        devices,
        overrides: Overrides {
            reference: true,
            ..Overrides::default()
        },
        ..Job::default()
    };
    let mode = reference(Backend::Auto, Devices::Auto).mode().unwrap();
    assert_eq!(mode, (Backend::Cpu, Precision::F64));
    assert_eq!(
        reference(Backend::Auto, Devices::Auto).setup().precision,
        Precision::F64
    );
    let wgpu = reference(Backend::Wgpu, Devices::Auto).mode();
    assert!(
        matches!(&wgpu, Err(Error::Usage(m)) if m.ends_with("cannot use --backend wgpu")),
        "{wgpu:?}"
    );
    let listed = reference(Backend::Cpu, Devices::List(vec![Device::Cpu])).mode();
    assert!(
        matches!(&listed, Err(Error::Usage(m)) if m.contains("--devices")),
        "{listed:?}"
    );
    let plain = Job {
        precision: Precision::F64,
        ..Job::default()
    };
    assert_eq!(plain.mode().unwrap(), (Backend::Auto, Precision::F64));
}

#[test]
fn usage_and_io_exit_with_2_and_the_rest_with_1() {
    let two = ExitCode::from(2);
    let one = ExitCode::from(1);
    assert_eq!(Error::Usage("bad".into()).code(), two);
    assert_eq!(Error::Io("cannot read".into()).code(), two);
    let exceeded = memory::Exceeded {
        needed: 9000,
        limit: 4096,
        raise: "raise it".into(),
    };
    assert_eq!(Error::Memory(exceeded).code(), one);
    assert_eq!(Error::Encode("ffmpeg".into()).code(), one);
    let failed = backend::Error::NoDevice("wgpu");
    let unavailable = Error::Unavailable {
        backend: Backend::Wgpu,
        source: failed,
    };
    assert_eq!(
        unavailable.to_string(),
        "the Wgpu backend is not available: --devices all found no wgpu device"
    );
    assert_eq!(unavailable.code(), one);
    let unsupported = Error::from(backend::Error::NotTraceable(Reason::Occlusion));
    assert_eq!(
        unsupported.to_string(),
        "this scene cannot be ray traced analytically: the render asks for ambient `occlusion`, which samples a distance field; use method=auto or method=march"
    );
    assert_eq!(unsupported.code(), one);
}

#[test]
fn bad_devices_are_usage_errors_and_devices_not_found_device_errors_for_every_caller() {
    let two = ExitCode::from(2);
    // A list the backend cannot take, however it is met: resolving it (as a sequence
    // does) or preparing on it (as a still does).
    let resolved = Devices::All.resolve(Backend::Cpu).unwrap_err();
    assert_eq!(resolved, backend::Resolve::Usage(backend::Usage::GpusOnCpu));
    let usage = Error::unavailable(Backend::Cpu, resolved.into());
    assert!(matches!(usage, Error::Arguments(_)), "{usage:?}");
    assert_eq!(usage.code(), two);
    assert_eq!(
        usage.to_string(),
        "--devices names GPUs, but --backend cpu renders on the CPU alone (give --backend auto, wgpu or cuda)"
    );
    let prepared = Error::from(backend::Error::Usage(backend::Usage::AllOnCpu));
    assert!(matches!(prepared, Error::Arguments(_)), "{prepared:?}");
    assert_eq!(prepared.code(), two);
    // `all` finding nothing: the backend is not available, exit 1.
    let none = Error::unavailable(Backend::Cuda, backend::Resolve::NoDevice("cuda").into());
    assert_eq!(none.code(), ExitCode::from(1));
    assert_eq!(
        none.to_string(),
        "the Cuda backend is not available: --devices all found no cuda device"
    );
    let bad = Devices::parse("0,gpu").unwrap_err();
    assert_eq!(
        Error::from(bad).to_string(),
        "bad --devices entry `gpu`: give auto, all, or a comma-separated list of device indices and `cpu` (`sdfc devices` lists the devices)"
    );
    let kernel = Job {
        backend: Backend::Cpu,
        kernel: Some(Kernel::Interpreted),
        ..Job::default()
    };
    let refused = kernel.check_kernel(Backend::Cpu).unwrap_err();
    assert_eq!(refused.code(), two);
    assert!(
        refused
            .to_string()
            .starts_with("--kernel interpreted chooses a GPU kernel"),
        "{refused}"
    );
    let zero = Job {
        threads: Some(0),
        ..Job::default()
    };
    let refused = zero.pool().unwrap_err();
    assert_eq!(refused.to_string(), "--threads must be at least 1");
    assert_eq!(refused.code(), two);
}

#[test]
fn a_scene_file_that_cannot_be_read_is_a_usage_error_naming_it() {
    let missing = Source::read(std::path::Path::new("/nonexistent/scene.sdf")).unwrap_err();
    assert!(
        missing
            .to_string()
            .starts_with("cannot read `/nonexistent/scene.sdf`: "),
        "{missing}"
    );
    assert_eq!(Error::from(missing).code(), ExitCode::from(2));
    let path = std::env::temp_dir().join(format!("sdfc-job-{}.sdf", std::process::id()));
    std::fs::write(&path, b"scene { \xff }").unwrap();
    let bad = Source::read(&path).unwrap_err();
    std::fs::remove_file(&path).unwrap();
    assert_eq!(
        bad.to_string(),
        format!(
            "`{}` is not valid UTF-8 (first bad byte at offset 8)",
            path.display()
        )
    );
}

/// A scene prepared after another ([`Open::After`], the viewer's later loads and animation
/// frames) keeps the kernel before when `setup` says `auto`, takes the one it names
/// otherwise, and builds none where the kernel's text is unchanged (numbers only).
#[test]
fn a_scene_prepared_after_another_keeps_or_changes_its_kernel_as_asked() {
    let gpu = match Gpu::open(false) {
        Ok(gpu) => Arc::new(gpu),
        Err(e) => {
            assert!(
                std::env::var("SDFC_REQUIRE_DEVICES").as_deref() != Ok("1"),
                "SDFC_REQUIRE_DEVICES=1 but no wgpu adapter: {e}"
            );
            eprintln!("job test SKIPPED: no wgpu adapter ({e})");
            return;
        }
    };
    let text = |r: &str| {
        format!(
            "render {{ width: 16, height: 12, method: \"march\" }}\n\
             scene {{ plane((0, 1, 0), 0); sphere({r}).translate(0, 0.5, 0); }}\n"
        )
    };
    let frame = |r: &str| {
        let mut source = Source::from_text("after.sdf", text(r));
        let job = Job {
            quiet: true,
            ..Job::default()
        };
        job.frame(&mut source, 0.0, false, &LowerOptions::default())
            .expect("the scene")
    };
    let on = (Backend::Wgpu, &Devices::Auto);
    let interpreted = Setup {
        parameters: true,
        kernel: wgsl::KernelChoice::Interpreted,
        ..Setup::default()
    };
    let first = prepare_here(on, frame("0.5"), &interpreted, Open::Gpu(gpu)).unwrap();
    assert!(first.built);
    assert_eq!(first.prepared.kernel_kind(), Some("interpreted"));
    let auto = Setup::default();
    let kept = prepare_here(on, frame("0.6"), &auto, Open::After(&first.prepared)).unwrap();
    assert_eq!(kept.prepared.kernel_kind(), Some("interpreted"));
    assert!(
        !kept.built,
        "a program that differs in numbers only keeps its kernel"
    );
    let specialised = Setup {
        kernel: wgsl::KernelChoice::Specialised,
        ..auto
    };
    let after = Open::After(&kept.prepared);
    let other = prepare_here(on, frame("0.6"), &specialised, after).unwrap();
    assert_eq!(other.prepared.kernel_kind(), Some("specialised"));
    assert!(other.built);
    // On the device the scene before was prepared on, not another opened.
    let device = |r: &Ready| r.prepared.as_wgpu().expect("wgpu").gpu.clone();
    assert!(Arc::ptr_eq(&device(&first), &device(&other)));
}

/// `sdfc bench` holds its warm-up frame while the timed ones render: [`Use::Held`] counts
/// that frame beside the render, so a limit the render alone fits refuses it.
#[test]
fn a_frame_held_while_the_next_renders_is_counted() {
    let mut source = Source::from_text(
        "held.sdf",
        "render { width: 640, height: 480, aa: 1, method: \"march\" }\n\
         scene { sphere(1); }\n"
            .to_string(),
    );
    let job = Job {
        backend: Backend::Cpu,
        quiet: true,
        ..Job::default()
    };
    let frame = job
        .frame(&mut source, 0.0, false, &LowerOptions::default())
        .expect("the scene");
    let on = (Backend::Cpu, &Devices::Auto);
    let ready = prepare_here(on, frame, &job.setup(), Open::Backend).expect("prepared");
    let (scene, prepared) = (&ready.scene, &ready.prepared);
    let s = &scene.settings;
    let (render, held) = (prepared.memory(scene, s), prepared.retained(s));
    assert_eq!(memory::held(prepared, scene).host, render.host + held);
    let alone = memory::mib(render.total());
    let both = memory::mib(render.total() + held);
    assert!(both > alone, "{alone} MiB, {both} MiB with the frame held");
    let mut limits = Limits::default();
    limits.set(Limit::Memory, alone).expect("a limit");
    let shown = Use::Shown {
        width: s.width,
        height: s.height,
    };
    assert!(check_memory_here(prepared, scene, shown, &limits, false).is_ok());
    match check_memory_here(prepared, scene, Use::Held, &limits, false) {
        Err(Error::Memory(e)) => assert_eq!((e.needed, e.limit), (both, alone)),
        other => panic!("held to {alone} MiB: {other:?}"),
    }
}

#[test]
fn a_scene_with_errors_is_summarised_by_its_first_error() {
    let mut source = Source::from_text(
        "broken.sdf",
        "scene { sphere(undefined_a); sphere(undefined_b); }\n".into(),
    );
    let job = Job::default();
    let failed = job.frame(&mut source, 0.0, true, &LowerOptions::default());
    let Err(Error::Scene(errors)) = failed else {
        panic!("not the scene's errors: {failed:?}");
    };
    let summary = errors.summary();
    assert!(summary.starts_with("error[E"), "{summary}");
    assert!(summary.contains(" at broken.sdf:1:"), "{summary}");
    assert!(summary.ends_with(" (and 1 more)"), "{summary}");
    assert_eq!(Error::Scene(errors).code(), ExitCode::from(1));
}

#[test]
fn the_jobs_settings_are_applied_in_order_within_the_limits() {
    let job = Job {
        overrides: Overrides {
            size: Some((64, 48)),
            aa: Some(2),
            set: vec!["width=32".into(), "max_steps=100".into()],
            ..Overrides::default()
        },
        ..Job::default()
    };
    let mut settings = Settings::default();
    job.override_settings(&mut settings).unwrap();
    assert_eq!(
        (
            settings.width,
            settings.height,
            settings.aa,
            settings.max_steps
        ),
        (32, 48, 2, 100)
    );
    let bad = Job {
        overrides: Overrides {
            set: vec!["max_steps".into()],
            ..Overrides::default()
        },
        ..Job::default()
    };
    let refused = bad.override_settings(&mut settings);
    assert!(
        matches!(&refused, Err(Error::Setting(e)) if e.to_string().contains("KEY=VALUE")),
        "{refused:?}"
    );
}

#[test]
fn typed_failures_keep_their_messages_word_for_word() {
    use crate::gpu::{cuda, wgpu};
    let said = |e: backend::Error| Error::from(e).to_string();
    assert_eq!(
        said(
            wgpu::Error::StorageBuffer {
                bytes: 300,
                limit: 256
            }
            .into()
        ),
        "GPU error while rendering: the scene's primitives take 300 bytes, more than the 256 \
         bytes a storage buffer of this adapter may bind"
    );
    let large = wgpu::Error::FrameTooLarge {
        width: 100,
        height: 50,
        largest: 320_000,
        most: 1000,
    };
    assert_eq!(
        said(large.into()),
        "GPU error while rendering: a 100x50 frame needs buffers of 320000 bytes, more than the \
         1000 bytes this adapter allows; render it smaller or with --backend cuda"
    );
    let cut = backend::Error::Cut {
        adapter: "llvmpipe".into(),
        cut: 7,
    };
    assert!(said(cut).starts_with(
        "the adapter llvmpipe ended 7 marching loops before they returned: a software adapter \
         (Mesa's llvmpipe, as lavapipe) stops every loop of a shader once they have run 65 535 \
         iterations together"
    ));
    let missing = |restricted| cuda::Error::NoSuchDevice {
        index: 3,
        count: 2,
        restricted,
    };
    assert_eq!(
        said(missing(true).into()),
        "CUDA driver error during opening the device: there is no CUDA device 3 (the driver \
         found 2 of those named; `sdfc devices` lists them)"
    );
    assert_eq!(
        said(missing(false).into()),
        "CUDA driver error during opening the device: there is no CUDA device 3 (the driver \
         found 2; `sdfc devices` lists them)"
    );
    let failed = Error::DevicesFailed {
        written: 3,
        frames: 10,
        failures: vec![(0, "lost".into()), (1, "out of memory".into())],
    };
    assert_eq!(
        failed.to_string(),
        "every device failed (3 of 10 frames written): device 0: lost; device 1: out of memory"
    );
    let unrendered = Error::Unrendered {
        rendered: 3,
        frames: 10,
    };
    assert_eq!(unrendered.to_string(), "7 of 10 frames were not rendered");
    // A caller tells the failures apart by their variants.
    assert!(matches!(
        Error::from(backend::Error::NotTraceable(Reason::Glow)),
        Error::Backend(backend::Error::NotTraceable(Reason::Glow))
    ));
}
