//! Fuzz target: any text through the whole front end (lexer, parser, checker) and the
//! lowering to a distance program. Nothing may panic, hang or overflow the stack.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sdfc_compiler::{check_with, Limit, Limits, NoImports, SourceMap};

/// Scenes larger than this (in IR nodes) are checked but not lowered. The checker's limits
/// admit scenes of 100 000 objects, whose lowering takes seconds natively and many times that
/// under the fuzzer's instrumentation: size is measured by the scaling benchmarks, and the
/// fuzzer spends its time on the shapes of inputs instead.
const LOWER_LIMIT: usize = 20_000;

/// Evaluation steps far below the default 50 million: a mutated recursion or loop that runs
/// to the default costs many seconds under the fuzzer's instrumentation (more than its
/// timeout) and reaches no code a million steps do not.
fn limits() -> Limits {
    let mut limits = Limits::default();
    limits.set(Limit::Fuel, 1_000_000).expect("a valid limit");
    limits
}

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let mut sources = SourceMap::new();
    let entry = sources.add("fuzz.sdf", text);
    let (scene, diags) = check_with(&mut sources, entry, &mut NoImports, &limits());
    // Rendering the diagnostics exercises every span.
    let _ = sdfc_compiler::diagnostics::render(&diags, &sources, false);
    let _ = sdfc_compiler::diagnostics::to_json(&diags, &sources);
    if let Some(scene) = scene.filter(|s| s.graph.len() <= LOWER_LIMIT) {
        let _ = sdfc_compiler::dump_ir(&scene);
        let program = sdfc_compiler::lower(&scene);
        let _ = program.dump();
    }
});
