//! sdfc: a compiler for scenes of signed distance fields.
//!
//! The stages are typed functions with one entry each, re-exported here; the modules that
//! implement them are private to the crate:
//!
//! ```text
//! parse             .sdf text            → ast::File + diagnostics   (logos, chumsky)
//! check             files (via a Loader) → Scene + diagnostics (the placement warnings too)
//! analysis::analyse Scene                → exactness and Lipschitz bound per node
//! Lowered::new      Scene                → Program (flat scalar SSA) and the scene's facts
//! Evaluator         Program              → distances at batches of points (CPU, f32/f64)
//! rust::write       Program              → Rust source over glam
//! wgsl::write       Scene + Lowered      → WGSL kernel, validated by naga
//! shader::write     wgsl::Kernel         → SPIR-V, MSL, GLSL, HLSL (naga)
//! ptx::write        naga::Module         → PTX
//! ```
//!
//! The crate does no IO and never panics on user input: imports are read through the
//! [`Loader`] the caller passes in, and every problem is a [`Diagnostic`].

// The stages, private to the crate: what other crates use is re-exported below.
mod back;
mod check;
mod eval;
mod front;
mod limits;
mod lower;
mod program;
mod rng;
mod scene;
mod span;
mod syntax;

/// A frame's structure, compared over frames to tell a still from an animation.
pub mod animation;
/// Diagnostics as data, rendered only at the edge (`render` as text, `to_json` as JSON lines).
pub mod diagnostics;
pub mod files;
/// The primitives' table: one entry per built-in shape or profile marched by its formula.
pub mod prim;

/// Sources, spans, resource limits and diagnostics.
pub use crate::{
    diagnostics::{has_errors, Diagnostic, Severity},
    limits::{Limit, LimitError, Limits, Spelling},
    span::{FileId, SourceMap, Span},
};

/// The front end: parse, format and check `.sdf` text (imports read through a [`Loader`]),
/// the AST and its dump, the built-ins table the checker, docs, editors and the Python package
/// read (with the types and values of its signatures), and the
/// readers of the mesh files `mesh(path)` reads.
pub use crate::{
    check::types::{Type, Value},
    check::{builtins, colour::srgb_to_linear, meshfile, Constant, LoadError, Loader, NoImports},
    front::{check, check_at, check_str, check_with, check_with_constants},
    syntax::{ast, dump as dump_ast, format, lexer, parse},
};

/// The scene IR the checker builds, its text dump, its analysis (exactness, Lipschitz
/// bounds) and whether it is traced analytically.
pub use crate::scene::{
    analysis, analytic, dump as dump_ir,
    ir::{
        Animation, Camera, Colour, Combine, Exactness, Graph, Light, Material, MaterialId, Method,
        Node, Pattern, Scene, Settings, Smooth, V3,
    },
    look,
    params::{Accepts, ParamValue, Parameter},
    pbr, sampling, NodeId, Pbr, Tonemap,
};

/// The lowering, once per scene: the distance program and what every back end reads of the
/// scene (`Lowered`: program, traceable primitives, media, instances, colour fields).
pub use crate::{
    lower::{lower, lower_scene, lower_with, lower_within, LowerOptions, Lowered},
    lower::{ColourProgram, Colours, Media},
    program::{mesh::TriMesh, Binary, Op, Program, Step, Unary},
};

/// The batch interpreter of distance programs (f32 or f64), and the bounds it verifies.
pub use crate::eval::{
    eval_point, verify, verify::verify_fields, wide, Evaluator, Float, Outputs, Tape, DEFAULT_CHUNK,
};

/// The writers: the WGSL kernel (validated by naga), PTX from it, SPIR-V/MSL/GLSL/HLSL,
/// Shadertoy, Rust source over glam, and the distance at a buffer of points (WGSL and PTX).
pub use crate::back::{points, ptx, rust, shader, shadertoy, wgsl};

/// The deterministic generator tests draw points from.
pub use crate::rng::Rng;
