//! `sdfc view`: the live preview, a window that renders a scene continuously and reloads it
//! whenever it or a file it imports is saved (see `docs/viewer.md`).

use crate::backend::{Backend, Kernel};
use crate::job::{Job, Overrides};
use crate::view::{self, session::Options, session::GRACE, Control, Run};
use std::path::PathBuf;
use std::process::ExitCode;

/// Where the viewer renders.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum ViewBackend {
    /// The kernel on the window's GPU through wgpu when it is a hardware GPU, else the CPU.
    #[default]
    Auto,
    /// The WGSL kernel through wgpu, on the device that presents the window (lavapipe too).
    Wgpu,
    /// The CPU renderer.
    Cpu,
}

/// Arguments of `sdfc view`.
#[derive(Debug, clap::Args)]
pub struct ViewArgs {
    /// Scene file.
    pub file: PathBuf,
    /// Backend to render with.
    #[arg(long, value_enum, default_value_t)]
    pub backend: ViewBackend,
    /// Window (and image) size, as WIDTHxHEIGHT (default: the scene's `render` size).
    #[arg(long, value_name = "WxH", value_parser = crate::settings::parse_size)]
    pub size: Option<(u32, u32)>,
    /// Override a render setting (as for `sdfc render`), at every reload. May be repeated.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// The GPU kernel (wgpu): `auto` shows a marched scene whose specialised kernel is not
    /// compiled yet through the interpreted kernel until it is, compiling it on another thread
    /// (on a GPU, after waiting 50 ms for it: a kernel compiled by then is shown at once; a
    /// CPU adapter compiles before showing, as `specialised` does);
    /// `specialised` compiles each new kernel before showing it (every compile runs on another
    /// thread, the image before staying on show); `interpreted` shows every
    /// scene through the interpreted kernel (docs/interpreted.md). [default: auto]
    #[arg(long, value_enum, hide_possible_values = true)]
    pub kernel: Option<Kernel>,
    /// Print the times of each load: check, lower, tapes or kernel, pipeline, first frame,
    /// and (for reloads) from the file's modification to the first frame shown.
    #[arg(long)]
    pub timings: bool,
    /// Show the statistics in the title from the start (S or Tab toggles them).
    #[arg(long)]
    pub stats: bool,
    /// Run the session without a window (on a machine without a display): render until the
    /// image converges, then wait for changes.
    #[arg(long)]
    pub headless: bool,
    /// With --headless: once the first image has settled, orbit the camera for N frames and
    /// print the frame rate, then the time to converge after the camera stops; then exit.
    #[arg(long, value_name = "N", requires = "headless", value_parser = clap::value_parser!(u32).range(1..))]
    pub orbit_frames: Option<u32>,
    /// Stop after N frames have been presented.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub frames: Option<u64>,
    /// With --frames: write what the window shows at the last frame to this PNG file.
    #[arg(long, value_name = "OUT.png", requires = "frames")]
    pub screenshot: Option<PathBuf>,
    /// Write DIR/reload-K.png once the image after load K (0 the first) has settled: converged,
    /// or, after a load with errors, the last good image that stays on show.
    #[arg(long, value_name = "DIR")]
    pub screenshot_dir: Option<PathBuf>,
    /// An animated scene starts paused at this time, in seconds (space plays and pauses);
    /// without it the window plays the animation, and --headless shows t = 0.
    #[arg(long, value_name = "SECONDS", value_parser = time_value)]
    pub time: Option<f64>,
    /// Stop once the screenshot of load K is written (needs --screenshot-dir).
    #[arg(long, value_name = "K", requires = "screenshot_dir")]
    pub exit_after_reloads: Option<u32>,
    /// Once the image of the last load has settled (and its screenshot is written), change the
    /// parameter NAME to VALUE as its control in the panel would (kept within its range and
    /// on its step): a load, whose --timings say how long the change took to reach the
    /// screen. May be repeated: each change follows the last one's settled image.
    #[arg(long = "change", value_name = "NAME=VALUE", value_parser = super::param_arg)]
    pub change: Vec<(String, String)>,
    #[command(flatten)]
    pub limits: super::LimitArgs,
}

/// Runs `sdfc view`.
pub fn run(args: ViewArgs) -> ExitCode {
    let backend = match args.backend {
        ViewBackend::Auto => Backend::Auto,
        ViewBackend::Wgpu => Backend::Wgpu,
        ViewBackend::Cpu => Backend::Cpu,
    };
    let overrides = Overrides {
        size: args.size,
        set: args.set,
        ..Overrides::default()
    };
    let job = Job::new(backend, overrides, args.limits.limits());
    // The --set values are checked once here, so that a mistake in them stops at once rather
    // than failing every reload.
    let mut probe = sdfc_compiler::Settings::default();
    if let Err(e) = job.override_settings(&mut probe) {
        return e.exit();
    }
    if let Some(dir) = &args.screenshot_dir {
        if let Err(e) = std::fs::create_dir_all(dir) {
            eprintln!("error: cannot create `{}`: {e}", dir.display());
            return ExitCode::from(2);
        }
    }
    if let Err(e) = Kernel::check(args.kernel, backend) {
        return crate::job::Error::from(e).exit();
    }
    let run = Run {
        file: args.file,
        options: Options {
            job,
            timings: args.timings,
            kernel: args.kernel.unwrap_or_default(),
            interim_on_cpu: false,
            grace: GRACE,
            // Headless, nothing would ever settle while the clock runs.
            time: args.time.or(args.headless.then_some(0.0)),
        },
        control: Control {
            frames: args.frames,
            screenshot: args.screenshot,
            screenshot_dir: args.screenshot_dir,
            exit_after_reloads: args.exit_after_reloads,
            stats: args.stats,
            orbit_frames: args.orbit_frames,
            changes: args.change,
        },
    };
    let code = if args.headless {
        view::headless(run)
    } else {
        view::window::run(run)
    };
    // At once: a pipeline may still be compiling on another thread (Esc during a slow
    // compile), which the process's exit handlers would otherwise wait for.
    super::exit_now(code, ())
}

/// A `--time` value: a finite number of seconds, at least 0.
fn time_value(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(t) if t.is_finite() && t >= 0.0 => Ok(t),
        _ => Err(format!("expected a time in seconds, at least 0, not `{s}`")),
    }
}
