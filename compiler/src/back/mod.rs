//! Back ends that write a distance program as source text.

pub mod rust;
pub mod shader;
pub mod wgsl;
pub mod ptx;
