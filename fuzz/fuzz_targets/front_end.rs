//! Fuzz target: any text through the whole front end (lexer, parser, checker) and the
//! lowering to a distance program. Nothing may panic, hang or overflow the stack.
#![no_main]

use libfuzzer_sys::fuzz_target;

/// Scenes larger than this (in IR nodes) are checked but not lowered. The checker's limits
/// admit scenes of 100 000 objects, whose lowering takes seconds natively and many times that
/// under the fuzzer's instrumentation: size is measured by the scaling benchmarks, and the
/// fuzzer spends its time on the shapes of inputs instead.
const LOWER_LIMIT: usize = 20_000;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let (scene, diags, sources) = sdfc_compiler::check_str("fuzz.sdf", text);
    // Rendering the diagnostics exercises every span.
    let _ = sdfc_compiler::diagnostics::render(&diags, &sources, false);
    let _ = sdfc_compiler::diagnostics::to_json(&diags, &sources);
    if let Some(scene) = scene.filter(|s| s.graph.len() <= LOWER_LIMIT) {
        let _ = sdfc_compiler::dump_ir(&scene);
        let program = sdfc_compiler::lower(&scene);
        let _ = program.dump();
    }
});
