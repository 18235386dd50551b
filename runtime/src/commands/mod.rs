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
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// When `main` began, and how long the process had run by then ([`process_age`]).
static MAIN: OnceLock<(Instant, Option<Duration>)> = OnceLock::new();

/// Marks the start of `main` (the binary calls it first), for `sdfc render --stats`'s
/// breakdown of the whole run.
pub fn main_started() {
    MAIN.get_or_init(|| (Instant::now(), process_age()));
}

/// When `main` began and how long the process had run by then: marked by [`main_started`],
/// else (the commands called as a library) now.
pub fn started() -> (Instant, Option<Duration>) {
    *MAIN.get_or_init(|| (Instant::now(), None))
}

/// How long ago this process started, from Linux's /proc: its start in clock ticks since
/// boot (`/proc/self/stat`, field 22, at USER_HZ = 100, the value Linux's common
/// architectures export) against the time since boot (`/proc/uptime`, in hundredths of a
/// second), so to about ±20 ms; `None` elsewhere.
fn process_age() -> Option<Duration> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // The fields after the command's name, which is in parentheses and may hold spaces:
    // the state is field 3, the start time field 22.
    let rest = stat.get(stat.rfind(')')? + 2..)?;
    let ticks: f64 = rest.split(' ').nth(19)?.parse().ok()?;
    let uptime = std::fs::read_to_string("/proc/uptime").ok()?;
    let uptime: f64 = uptime.split(' ').next()?.parse().ok()?;
    Some(Duration::from_secs_f64((uptime - ticks / 100.0).max(0.0)))
}

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
