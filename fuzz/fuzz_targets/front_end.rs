//! Fuzz target: any text through the whole front end (lexer, parser, checker) and the
//! lowering to a distance program. Nothing may panic, hang or overflow the stack.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let (scene, diags, sources) = sdfc_compiler::check::check_str("fuzz.sdf", text);
    // Rendering the diagnostics exercises every span.
    let _ = sdfc_compiler::diagnostics::render(&diags, &sources, false);
    let _ = sdfc_compiler::diagnostics::to_json(&diags, &sources);
    if let Some(scene) = scene {
        let _ = sdfc_compiler::scene::dump(&scene);
        let program = sdfc_compiler::lower::lower(&scene);
        let _ = program.dump();
    }
});
