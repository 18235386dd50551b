//! The sdfc runtime: loading scenes from disk, the CPU renderer, image IO, and the commands of
//! the `sdfc` binary.

pub mod backend;
pub mod chart;
pub mod commands;
pub mod cpu;
pub mod depth;
pub mod fp32;
pub mod frontend;
pub mod gpu;
pub mod image;
pub mod job;
/// `sdfc lsp`, its own crate (it needs neither the GPU nor the renderer).
pub use sdfc_lsp as lsp;
pub mod memory;
pub mod mesh;
pub mod metrics;
pub mod output;
pub mod pareto;
pub mod sequence;
pub mod settings;
pub mod tally;
pub mod view;
