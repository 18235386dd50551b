//! The scene IR and its text dump.

pub mod analysis;
pub mod analytic;
mod dump;
pub mod field;
pub mod ir;
pub mod recentre;

pub use dump::{dump, num as dump_num};
pub use ir::*;
