//! Fuzz target: every scene the checker accepts must give a WGSL kernel that naga validates
//! and PTX that the PTX writer produces without error.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sdfc_compiler::{check_with, ptx, wgsl, Limit, Limits, NoImports, SourceMap};

/// Scenes larger than this (in IR nodes) are skipped: writing and validating the kernel of a
/// scene of thousands of objects takes seconds under the fuzzer's instrumentation.
const KERNEL_LIMIT: usize = 2_000;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    // A million evaluation steps, not the default 50 million: see the front_end target.
    let mut limits = Limits::default();
    limits.set(Limit::Fuel, 1_000_000).expect("a valid limit");
    let mut sources = SourceMap::new();
    let entry = sources.add("fuzz.sdf", text);
    let (Some(scene), _) = check_with(&mut sources, entry, &mut NoImports, &limits) else { return };
    if scene.graph.len() > KERNEL_LIMIT {
        return;
    }
    let lowered = sdfc_compiler::Lowered::new(&scene);
    let kernel = match wgsl::write(&scene, &lowered) {
        Ok(k) => k,
        Err(e) => panic!("invalid kernel for an accepted scene: {e}"),
    };
    let options = ptx::Options { sm: 70, entry_point: wgsl::ENTRY_POINT.to_string() };
    if let Err(e) = ptx::write(&kernel.module, &kernel.info, &options) {
        panic!("PTX writer failed on a validated kernel: {e}");
    }
});
