//! The compiler's integration tests, one binary (as naga keeps its own): each module tests
//! one area through the crate's public interface, with no renderer, GPU or window linked, so
//! that a change of the compiler rebuilds and relinks this binary alone among the tests of
//! the front end and the back ends.
//!
//! - `distance_formulas`: every primitive and operator, lowered and run by the interpreter,
//!   against an independent formula;
//! - `batch_interpreter`: the batch interpreter against the one-point reference path;
//! - `robustness`: the front end on deep nesting, huge expressions, endless evaluation and
//!   mutated inputs;
//! - `format`: the formatter over every `.sdf` file and fuzz seed, idempotent and keeping
//!   the meaning;
//! - `grammar`: `grammar/sdf.ebnf` as a recogniser over the lexer's tokens;
//! - `snapshots`: the AST, scene IR, distance programs, WGSL parts and kernels, PTX and
//!   diagnostics of the small inputs of `tests/in`, as insta snapshots (`snapshots/`);
//! - `emit_rust`: the Rust back end's text;
//! - `ptx`: the PTX back end, assembled by `ptxas`;
//! - `tint`: the WGSL kernels compiled by Chromium's WebGPU compiler;
//! - `tidy`: the repository's rules (module cycles, file headers, the docs and the editor
//!   grammar against the compiler's tables); `counts`: the counts that may only fall
//!   (`Result<_, String>`).
//!
//! The scenes built in code that these and the runtime's suites share are in `common`.

mod batch_interpreter;
mod common;
mod counts;
mod distance_formulas;
mod emit_rust;
mod format;
mod grammar;
mod ptx;
mod reference;
mod robustness;
mod scan;
mod snapshots;
mod tidy;
mod tint;
