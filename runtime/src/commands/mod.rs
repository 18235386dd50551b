//! One module per `sdfc` subcommand: its clap arguments and its `run`; and `--limit`, which
//! every command that checks or renders a scene takes.

pub mod bench;
pub mod check;
pub mod compare;
pub mod compile;
pub mod devices;
pub mod mesh;
pub mod pareto;
pub mod render;
pub mod sequence;
pub mod view;

use sdfc_compiler::{Limit, Limits};

/// `--limit NAME=VALUE`: the resource limits of a run.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct LimitArgs {
    /// Set a resource limit (may be repeated); see `--help` for the names and defaults.
    #[arg(
        long = "limit",
        value_name = "NAME=VALUE",
        value_parser = Limits::parse,
        long_help = limits_help()
    )]
    pub limit: Vec<(Limit, u64)>,
}

impl LimitArgs {
    /// The default limits with every `--limit` applied, in order.
    pub fn limits(&self) -> Limits {
        let mut limits = Limits::default();
        for &(limit, value) in &self.limit {
            // The parser has already checked the value's range.
            let _ = limits.set(limit, value);
        }
        limits
    }
}

fn limits_help() -> String {
    format!(
        "Set a resource limit (may be repeated). An input or render that exceeds a limit \
         stops before any work with a message naming the flag that raises it.\n\n{}",
        Limits::table()
    )
}
