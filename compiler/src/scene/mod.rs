//! The scene IR and its text dump.

pub mod analysis;
mod dump;
pub mod ir;

pub use dump::{dump, num as dump_num};
pub use ir::*;
