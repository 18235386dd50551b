//! The scene IR and its text dump.

mod dump;
pub mod ir;

pub use dump::dump;
pub use ir::*;
