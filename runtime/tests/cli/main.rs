//! The command line, one test binary: the `sdfc` commands and their outputs (`cli` what they
//! share, `render`, `check`, `files` what they read and write, `commands` the smaller ones), the
//! code a user takes away (`embed`, `emit_rust`), and speed against accuracy (`accuracy`).
//!
//! Filter by module: `cargo test --release --test cli -- embed::`.

#[path = "../common/mod.rs"]
mod common;

mod accuracy;
mod check;
mod cli;
mod commands;
mod embed;
mod emit_rust;
mod files;
mod render;
