//! The command line, one test binary: the `sdfc` commands and their outputs (`cli`), the
//! code a user takes away (`embed`, `emit_rust`), and speed against accuracy (`accuracy`).
//!
//! Filter by module: `cargo test --release --test cli -- embed::`.

#[path = "../common/mod.rs"]
mod common;

mod accuracy;
mod cli;
mod embed;
mod emit_rust;
