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
