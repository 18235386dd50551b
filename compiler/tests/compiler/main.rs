//! The compiler's integration tests, one binary (as naga keeps its own): each module tests
//! one area through the crate's public interface, with no renderer, GPU or window linked.
//!
//! - `distance_formulas`: every primitive and operator, lowered and run by the interpreter,
//!   against an independent formula;
//! - `batch_interpreter`: the batch interpreter against the one-point reference path;
//! - `robustness`: the front end on deep nesting, huge expressions, endless evaluation and
//!   mutated inputs;
//! - `format`: the formatter over every `.sdf` file and fuzz seed, idempotent and keeping
//!   the meaning.
//!
//! The scenes built in code that these and the runtime's suites share are in `common`.

mod batch_interpreter;
mod common;
mod distance_formulas;
mod format;
mod robustness;
