//! sdfc: a compiler for scenes of signed distance fields.
//!
//! The stages are typed functions with one entry each:
//!
//! ```text
//! syntax::parse   .sdf text            → ast::File + diagnostics   (logos, chumsky)
//! check::check    files (via a Loader) → scene::Scene + diagnostics
//! scene::analysis::analyse  scene::Scene → exactness and Lipschitz bound per node
//! lower::lower    scene::Scene         → program::Program           (flat scalar SSA)
//! eval            program::Program     → distances at batches of points (CPU, f32/f64)
//! back::rust      program::Program     → Rust source over glam
//! back::wgsl      Scene + Program      → WGSL kernel, validated by naga
//! back::shader    wgsl::Kernel         → SPIR-V, MSL, GLSL, HLSL (naga)
//! back::ptx       naga::Module         → PTX
//! ```
//!
//! The crate does no IO and never panics on user input: imports are read through the
//! [`check::Loader`] the caller passes in, and every problem is a [`Diagnostic`].

pub mod animation;
pub mod back;
pub mod check;
pub mod diagnostics;
pub mod eval;
pub mod limits;
pub mod lower;
pub mod program;
pub mod scene;
pub mod span;
pub mod syntax;

pub use diagnostics::{Diagnostic, Severity};
pub use limits::{Limit, Limits};
pub use span::{FileId, SourceMap, Span};
