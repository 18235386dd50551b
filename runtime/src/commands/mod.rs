//! One module per `sdfc` subcommand: its clap arguments and its `run`; `--limit`, which
//! every command that checks or renders a scene takes, and the arguments of a render job that
//! `render` and `bench` share ([`JobArgs`]).

pub mod bench;
pub mod check;
pub mod compare;
pub mod compile;
pub mod devices;
pub mod fmt;
pub mod mesh;
pub mod mesh_region;
pub mod mesh_thin;
pub mod pareto;
pub mod pareto_mesh;
pub mod render;
pub mod sequence;
pub mod view;

use crate::backend::{Backend, Devices, Kernel};
use crate::cpu::Precision;
use crate::job::{Job, Overrides};
use crate::settings::parse_size;
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

/// Ends the process now with `code`, after flushing standard output and error, leaving
/// `objects` (a finished render's device, kernel and thread pool) and everything else to the
/// operating system: neither their destructors nor the exit handlers of the libraries loaded
/// run. Destroying a CUDA context or a Vulkan device one object at a time, and the drivers'
/// own teardown at exit, is work the operating system does anyway when the process ends (it
/// closes the driver's files and unmaps its memory, as for a process that is killed); and a
/// device still being opened on its thread ([`crate::backend::Opening`]) when a command fails
/// would otherwise run beside those exit handlers. Called at the very end of a command, once
/// its files are written, synced and renamed and its messages printed.
pub fn exit_now(code: std::process::ExitCode, objects: impl Sized) -> ! {
    use std::io::Write;
    std::mem::forget(objects);
    let _ = std::io::stdout().flush();
    let _ = std::io::stderr().flush();
    // `ExitCode` does not give its number back: it is the one it equals.
    let code = (0..=255u8)
        .find(|&n| std::process::ExitCode::from(n) == code)
        .unwrap_or(1);
    #[cfg(unix)]
    {
        // SAFETY: `_exit` ends the process at once; nothing of it runs afterwards, and the
        // standard streams were flushed above.
        #[allow(unsafe_code)]
        unsafe {
            libc::_exit(code.into())
        }
    }
    #[cfg(not(unix))]
    std::process::exit(code.into())
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

/// The arguments `sdfc render` and `sdfc bench` share: where to render, the settings
/// overridden, the GPU kernel, the float type, the worker threads and the limits; the
/// [`Job`] they describe.
#[derive(Debug, Clone, clap::Args)]
pub struct JobArgs {
    /// Backend to render with.
    #[arg(long, value_enum, default_value_t)]
    pub backend: Backend,
    /// Devices to render with: `auto` (the one `--backend` picks), `all` (every GPU of the
    /// backend), or a comma-separated list of GPU indices (CUDA devices, or wgpu adapters, as
    /// `sdfc devices` lists them; an index twice opens that GPU as two logical devices) and
    /// `cpu`. Several devices take tiles of each frame from one queue (docs/devices.md).
    #[arg(long, value_name = "auto|all|LIST", default_value = "auto", value_parser = Devices::parse)]
    pub devices: Devices,
    /// Image size, as WIDTHxHEIGHT (overrides the scene's `render` block).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Supersampling: N×N samples per pixel.
    #[arg(long, value_name = "N")]
    pub aa: Option<u32>,
    // Its help lists the settings from their table (`settings::set_help`).
    #[arg(long = "set", value_name = "KEY=VALUE", help = crate::settings::set_help())]
    pub set: Vec<String>,
    /// The GPU kernel of a marched scene: its distance program written as code
    /// (`specialised`, compiled by the driver for each scene), interpreted from a buffer
    /// (`interpreted`, one kernel for every scene), or `auto`, interpreted where the code
    /// would be large (docs/interpreted.md). [default: auto]
    #[arg(long, value_enum)]
    pub kernel: Option<Kernel>,
    /// Float type of the evaluation.
    #[arg(long, value_enum, default_value_t)]
    pub precision: Precision,
    /// Worker threads (default: one per core).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    #[command(flatten)]
    pub limits: LimitArgs,
}

impl JobArgs {
    /// The job these arguments describe.
    pub fn job(&self) -> Job {
        Job {
            backend: self.backend,
            devices: self.devices.clone(),
            precision: self.precision,
            kernel: self.kernel,
            overrides: Overrides {
                reference: false,
                size: self.size,
                aa: self.aa,
                set: self.set.clone(),
            },
            limits: self.limits.limits(),
            threads: self.threads,
            debug_nan: false,
            quiet: false,
        }
    }
}

/// Writes `bytes` to standard output and flushes it; a failure (a full disk: `> /dev/full`) is
/// reported, `error: cannot write to standard output: …`, and is exit code 2. (A closed pipe
/// ends the process quietly before this, by SIGPIPE, as `head` expects.)
pub fn write_stdout(bytes: &[u8]) -> Result<(), std::process::ExitCode> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    out.write_all(bytes)
        .and_then(|()| out.flush())
        .map_err(|e| {
            eprintln!("error: cannot write to standard output: {e}");
            std::process::ExitCode::from(2)
        })
}

/// Prints `value` as JSON on a line (indented over many with `pretty`); a value that cannot
/// be written is reported, `error: …`, and is exit code 2.
pub(crate) fn print_json(
    value: &impl serde::Serialize,
    pretty: bool,
) -> Result<(), std::process::ExitCode> {
    let text = if pretty {
        serde_json::to_string_pretty(value)
    } else {
        serde_json::to_string(value)
    };
    match text {
        Ok(s) => {
            println!("{s}");
            Ok(())
        }
        Err(e) => {
            eprintln!("error: {e}");
            Err(std::process::ExitCode::from(2))
        }
    }
}

/// A progress bar of `len` steps on stderr, drawn with `template`, when stderr is a terminal.
pub(crate) fn progress_bar(len: u64, template: &str) -> Option<indicatif::ProgressBar> {
    use std::io::IsTerminal;
    std::io::stderr().is_terminal().then(|| {
        let bar = indicatif::ProgressBar::new(len);
        if let Ok(style) = indicatif::ProgressStyle::with_template(template) {
            bar.set_style(style);
        }
        bar
    })
}

/// The stem of `file`'s name (`scene` of `scene.sdf`), else `or`: the default output's.
pub(crate) fn stem_or(file: &std::path::Path, or: &str) -> String {
    file.file_stem()
        .map_or_else(|| or.to_string(), |s| s.to_string_lossy().into_owned())
}

/// `--limit NAME=VALUE`: the resource limits of a run.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct LimitArgs {
    /// Set a resource limit (may be repeated); `sdfc --help` lists every limit with its
    /// default.
    ///
    /// An input or render that exceeds a limit stops before any work with a message naming
    /// the flag that raises it.
    #[arg(long = "limit", value_name = "NAME=VALUE", value_parser = Limits::parse)]
    pub limit: Vec<(Limit, u64)>,

    /// Give the scene's parameter NAME (`param NAME = … ;`) this value instead of its
    /// default (may be repeated); `sdfc check` lists the parameters.
    ///
    /// A value of the wrong type or outside the parameter's range is refused, at its
    /// declaration, before any work.
    #[arg(long = "param", value_name = "NAME=VALUE", value_parser = param_arg)]
    pub param: Vec<(String, String)>,
}

/// Why a `--param` argument is refused.
#[derive(Debug)]
pub enum ParamArgError {
    /// The argument has no `=`.
    NotNameValue(String),
    /// What stands before `=` is not a name.
    NotAName(String),
}

impl std::fmt::Display for ParamArgError {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            ParamArgError::NotNameValue(s) => write!(f, "`{s}` is not NAME=VALUE"),
            ParamArgError::NotAName(n) => write!(f, "`{n}` is not a parameter's name"),
        }
    }
}

impl std::error::Error for ParamArgError {}

/// `NAME=VALUE` of `--param`.
pub(crate) fn param_arg(s: &str) -> Result<(String, String), ParamArgError> {
    let (name, value) = s
        .split_once('=')
        .ok_or_else(|| ParamArgError::NotNameValue(s.to_string()))?;
    let name = name.trim();
    let ident = name
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !ident {
        return Err(ParamArgError::NotAName(name.to_string()));
    }
    Ok((name.to_string(), value.to_string()))
}

impl LimitArgs {
    /// The default limits with every `--limit` applied, in order.
    pub fn limits(&self) -> Limits {
        let mut limits = Limits::default();
        for &(limit, value) in &self.limit {
            // The parser has already checked the value's range.
            let _ = limits.set(limit, value);
        }
        for (name, value) in &self.param {
            limits.set_param(name, value);
        }
        limits
    }
}

/// The limits' table, shown once, by `sdfc --help` (each subcommand's `--limit` points
/// there).
pub fn limits_help() -> String {
    format!(
        "Limits (`--limit NAME=VALUE` on check, compile, render, mesh, bench, pareto, view, fmt and lsp; \
         docs/failures.md):\n\n{}",
        Limits::table()
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    /// A command of the job's arguments alone, as `render` and `bench` flatten them.
    #[derive(Debug, clap::Parser)]
    struct Flattened {
        #[command(flatten)]
        job: JobArgs,
    }

    #[test]
    fn the_help_of_set_lists_every_setting() {
        let help = Flattened::command().render_help().to_string();
        for key in crate::settings::SETTING_KEYS {
            assert!(help.contains(key), "`--set`'s help lacks {key}:\n{help}");
        }
        assert!(help.contains("method (auto, trace, march, path)"), "{help}");
    }
}
