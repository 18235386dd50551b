//! Helpers shared by the runtime's integration tests: the compiler's test helpers (scenes
//! built in code, random scenes, reference formulas, the diagnostic codes, the examples;
//! one source, in `compiler/tests/compiler/common.rs`) and the wgpu adapter the GPU tests run on.
#![allow(dead_code)]

#[path = "../../../compiler/tests/compiler/common.rs"]
mod scenes;
#[allow(unused_imports)]
pub use scenes::*;

/// A wgpu adapter (lavapipe where there is no GPU), or `None`, saying that `what` skipped;
/// with `SDFC_REQUIRE_DEVICES=1` a missing adapter fails the test instead.
pub fn open_gpu(what: &str) -> Option<sdfc_runtime::gpu::Gpu> {
    match sdfc_runtime::gpu::Gpu::open(false) {
        Ok(g) => Some(g),
        Err(e) => {
            assert!(
                std::env::var("SDFC_REQUIRE_DEVICES").as_deref() != Ok("1"),
                "SDFC_REQUIRE_DEVICES=1 but wgpu found no adapter: {e}"
            );
            println!("SKIPPED: {what}: {e}");
            None
        }
    }
}

/// `scene` rendered by every backend this machine has, each with its name: the CPU always,
/// wgpu where it finds an adapter (required under `SDFC_REQUIRE_DEVICES=1`) and CUDA where it
/// finds a device (required under `SDFC_REQUIRE_CUDA=1`, as on the GPU machine); a missing
/// one is said to have skipped.
pub fn render_everywhere(
    what: &str,
    scene: &sdfc_compiler::Scene,
) -> Vec<(&'static str, sdfc_runtime::image::Image)> {
    use sdfc_runtime::backend::{Backend, Prepared};
    let mut out = Vec::new();
    for (name, backend, required) in [
        ("cpu", Backend::Cpu, true),
        ("wgpu", Backend::Wgpu, env_is("SDFC_REQUIRE_DEVICES")),
        ("cuda", Backend::Cuda, env_is("SDFC_REQUIRE_CUDA")),
    ] {
        let prepared = match Prepared::new(backend, scene, sdfc_runtime::cpu::Precision::F32) {
            Ok(p) => p,
            Err(e) => {
                assert!(!required, "{what}: {name} is required but failed: {e}");
                println!("SKIPPED: {what} on {name}: {e}");
                continue;
            }
        };
        let frame = prepared
            .render(scene, &|_| {})
            .unwrap_or_else(|e| panic!("{what}: {name} render failed: {e}"));
        out.push((name, frame.render.image));
    }
    out
}

fn env_is(name: &str) -> bool {
    std::env::var(name).as_deref() == Ok("1")
}
