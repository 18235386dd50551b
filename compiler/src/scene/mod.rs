//! The scene IR (`ir.rs`, with the programs of user fields in `field.rs`), its text dump, its
//! analysis and whether it is traced analytically. [`NodeId`], the handle of a shape node,
//! is defined here: the IR's nodes and the fields' programs both name nodes by it.

pub mod analysis;
pub mod analytic;
pub mod bounds;
mod clip;
mod cost;
mod dump;
pub mod field;
pub mod frame;
pub mod ir;
pub mod look;
pub mod paint;
pub mod params;
pub mod path;
pub mod pbr;
pub mod reach;
pub mod recentre;
pub mod sampling;

pub use dump::{dump, num as dump_num};
pub use ir::*;
pub use look::Tonemap;
pub use path::Path;
pub use pbr::Pbr;

/// Names a node of a [`Graph`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeId(pub u32);
