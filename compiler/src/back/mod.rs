//! Back ends that write a distance program as source text.

pub mod points;
pub mod ptx;
pub mod rust;
pub mod shader;
pub mod shadertoy;
pub mod wgsl;
