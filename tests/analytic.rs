//! Analytic ray tracing (issue 9): which scenes the compiler traces analytically and why,
//! traced images against sphere-traced ones of the same file, and the kernel it emits.

use sdfc_compiler::back::wgsl;
use sdfc_compiler::lower::lower;
use sdfc_compiler::scene::analytic::{choose, Choice, Reason};
use sdfc_compiler::scene::{Method, Scene};
use sdfc_runtime::{cpu, frontend, metrics};
use std::path::Path;

/// The conformance tolerance of tests/conformance.rs: PSNR, differing fraction, threshold.
const MIN_PSNR: f64 = 30.0;
const MAX_DIFFERING: f64 = 0.02;
const THRESHOLD: f64 = 0.1;

fn load(name: &str) -> Scene {
    let path = Path::new("../examples").join(name);
    frontend::load(&path)
        .expect("readable")
        .scene
        .expect("valid example")
}

#[test]
fn the_report_scenes_1_and_2_are_traced_analytically() {
    for (name, count) in [("seed1.sdf", 3), ("seed2.sdf", 5), ("primitives.sdf", 7)] {
        match choose(&load(name)) {
            Choice::Trace(p) => assert_eq!(p.len(), count, "{name}"),
            other => panic!("{name}: {other:?}"),
        }
    }
}

#[test]
fn other_scenes_are_sphere_traced_with_a_reason() {
    assert!(matches!(
        choose(&load("seed3.sdf")),
        Choice::March(Reason::SoftLight { index: 0 })
    ));
    match choose(&load("glass.sdf")) {
        Choice::March(Reason::Node { what, .. }) => assert_eq!(what, "torus"),
        other => panic!("glass: {other:?}"),
    }
    let mut scene = load("seed1.sdf");
    scene.settings.method = Method::March;
    assert_eq!(choose(&scene), Choice::March(Reason::Asked));
}

/// Scenes 1 and 2 and the primitives example, traced and marched on the CPU, agree within
/// the conformance tolerance; the traced render takes no marching steps.
#[test]
fn traced_images_agree_with_marched_ones() {
    for name in ["seed1.sdf", "seed2.sdf", "primitives.sdf"] {
        let mut scene = load(name);
        scene.settings.width = 256;
        scene.settings.height = 160;
        let render = |scene: &Scene| {
            cpu::render(scene, &lower(scene), &cpu::Options::default(), &|| {})
        };
        let traced = render(&scene);
        scene.settings.method = Method::March;
        let marched = render(&scene);
        assert_eq!(traced.stats.counters.steps, 0, "{name}: traced with steps");
        assert!(marched.stats.counters.steps > 0);
        assert!(traced.stats.counters.hits > 0);
        let d = metrics::compare(&traced.image, &marched.image, THRESHOLD).expect("same size");
        println!("{name}: psnr {:.1} dB, differing {:.4}", d.psnr, d.differing);
        assert!(
            d.psnr >= MIN_PSNR && d.differing <= MAX_DIFFERING,
            "{name}: psnr {:.1} dB, differing {:.4}",
            d.psnr,
            d.differing
        );
    }
}

/// A traced scene's kernel has no distance field and no marching loop: one `nearest` and
/// one `occlude` per primitive instead.
#[test]
fn a_traced_kernel_emits_intersections_instead_of_a_field() {
    let scene = load("primitives.sdf");
    let kernel = wgsl::write(&scene, &lower(&scene)).expect("naga accepts it");
    let src = &kernel.source;
    assert!(!src.contains("fn map(") && !src.contains("fn sdf("));
    assert!(!src.contains("fn tolerance("));
    assert_eq!(src.matches("best = nearest(").count(), 7);
    assert_eq!(src.matches("through = occlude(").count(), 7);
    assert!(kernel.features.contains(&("ANALYTIC", true)));
    let mut marched = scene.clone();
    marched.settings.method = Method::March;
    let kernel = wgsl::write(&marched, &lower(&marched)).expect("naga accepts it");
    assert!(kernel.source.contains("fn sdf(") && !kernel.source.contains("Interval"));
}
