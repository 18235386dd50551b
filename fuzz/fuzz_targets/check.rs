//! Fuzz target: any text through the lexer, parser and checker alone (no lowering), so that
//! a short run reaches many inputs, and through the formatter. Nothing may panic, hang or
//! overflow the stack; formatted text formats to itself.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sdfc_compiler::{check_with, Limit, Limits, NoImports, SourceMap};

/// Limits far below the defaults: a mutated loop of 100 000 objects costs seconds under the
/// fuzzer's instrumentation and teaches it nothing that a loop of 1 000 does not, so the
/// fuzzer spends its time on the shapes of inputs instead (the limits' own paths included).
fn limits() -> Limits {
    let mut limits = Limits::default();
    for (limit, value) in [
        (Limit::Fuel, 100_000),
        (Limit::Objects, 1_000),
        (Limit::Nodes, 10_000),
    ] {
        limits.set(limit, value).expect("a valid limit");
    }
    limits
}

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let mut sources = SourceMap::new();
    let entry = sources.add("fuzz.sdf", text);
    let (_scene, diags) = check_with(&mut sources, entry, &mut NoImports, &limits());
    // Rendering the diagnostics exercises every span.
    let _ = sdfc_compiler::diagnostics::render(&diags, &sources, false);
    let _ = sdfc_compiler::diagnostics::to_json(&diags, &sources);
    // The formatter keeps the tokens or refuses (syntax errors); it never fails otherwise,
    // and what it writes it leaves as it is.
    use sdfc_compiler::format::{format, Error};
    match format(text) {
        Ok(out) => match format(&out) {
            Ok(again) => assert!(again == out, "formatting is not idempotent"),
            Err(e) => panic!("the formatted text does not format: {e}"),
        },
        Err(Error::Syntax(_)) => {}
        Err(e) => panic!("{e}"),
    }
});
