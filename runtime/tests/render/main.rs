//! Rendering, one test binary: each module tests one concern of the renderers (CPU, wgpu
//! through lavapipe, CUDA where there is a device) through the library.
//!
//! - `render`, `shading`, `regressions`: properties of CPU renders (coverage, threads, debug
//!   views; shadows, mirrors, glass; renders that once went wrong);
//! - `look`, `pbr`, `penumbra`: the look (occlusion, fog, tone curves), the physically based
//!   material and soft shadows on every backend;
//! - `analytic`: which scenes are traced analytically, and their images;
//! - `stability`: scenes where sphere tracing is known to struggle;
//! - `image_conformance`, `distance_conformance`: every backend and evaluator against the
//!   others;
//! - `interpreted_kernel`: the interpreted WGSL kernel against the specialised one;
//! - `optimise`: the optimisation passes and bounding-volume culling;
//! - `devices`: several devices at once (`--devices`);
//! - `animation`, `sequence`, `animation_kernels`: the time `t`, sequences and their frames,
//!   one kernel per sequence;
//! - `colour`: colour fields of the normal, and of a painted shape moved afterwards;
//! - `checker_materials`: a checker of two materials, each cell shaded as its material;
//! - `glow`: the glow of the marching steps, by its documented sum.
//!
//! Filter by module: `cargo test --release --test render -- look::`.

#[path = "../common/mod.rs"]
mod common;
#[path = "../common/evaluators.rs"]
mod evaluators;

mod analytic;
mod animation;
mod animation_kernels;
mod checker_materials;
mod colour;
mod devices;
mod distance_conformance;
mod glow;
mod image_conformance;
mod interpreted_kernel;
mod look;
mod optimise;
mod path;
mod pbr;
mod penumbra;
mod regressions;
mod render;
mod sequence;
mod shading;
mod stability;
