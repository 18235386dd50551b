//! One module per `sdfc` subcommand: its clap arguments and its `run`.

pub mod bench;
pub mod check;
pub mod compare;
pub mod compile;
pub mod pareto;
pub mod render;
