//! `sdfc render`: render a scene to an image (PNG, JPEG or OpenEXR; optionally the reference
//! render with its convergence check, and the depth sidecar) through the job's path
//! (`crate::job`); a sequence (`--frames`) is `super::sequence`'s. Also the `--stats` text and
//! the reference's check, which `sdfc pareto` shares.

use super::sequence::{self, SequenceArgs};
use super::JobArgs;
use crate::backend::{self, Devices, Frame, Opening, Prepared, Setup};
use crate::cpu::reference::{self, Convergence};
use crate::job::{self, Error, Job};
use crate::output::{CannotWrite, Output};
use crate::{depth, frontend};
use sdfc_compiler::{LowerOptions, Scene};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

pub use crate::backend::{Backend, Kernel};

/// Arguments of `sdfc render`.
#[derive(Debug, clap::Args)]
pub struct RenderArgs {
    /// Scene file.
    pub file: PathBuf,
    #[command(flatten)]
    pub job: JobArgs,
    /// Output image: .png, .jpg (or .jpeg), or .exr (linear, unclamped 32-bit floats); `-`
    /// writes the PNG to standard output (default: the scene file's name with .png, in the
    /// current directory). For a sequence: a name with a run of `#` (the zero-padded frame
    /// number, `out/frame_####.png`), an animated `.png`, or a video (`.mp4`, `.webm`,
    /// `.mkv`, `.mov`, `.gif`) through `ffmpeg` on PATH.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Print render statistics, and where the whole run went from the process's start
    /// (device, kernel, driver compile, upload, frame, readback, image).
    #[arg(long)]
    pub stats: bool,
    /// Render the reference: on the CPU in f64 with ε 1e-6, 100000 steps and no
    /// over-relaxation (`--set` still applies on top), then check it against a render with ε
    /// ten times smaller; for a field with no proven bound, the area average of at least 8×8
    /// samples at the pixel footprint's ε, checked against twice the samples per axis.
    /// `--stats` prints how well they agree, and a warning says when they do not.
    #[arg(long)]
    pub reference: bool,
    /// Also write the depth and hit buffers as a sidecar file beside the image (OUT.aux; see
    /// docs/accuracy.md). Only the CPU backend has them.
    #[arg(long)]
    pub aux: bool,
    /// Paint the pixels whose rays (camera, secondary or shadow) met a NaN distance magenta,
    /// instead of what they would show. Without it, images are unchanged.
    #[arg(long)]
    pub debug_nan: bool,
    #[command(flatten)]
    pub sequence: SequenceArgs,
    /// How hard PNG files are compressed: `fast` (fdeflate, the default, for stills and
    /// sequences), `fastest` (fdeflate without the per-row choice of filter), `none`, or
    /// zlib's `balanced` and `high`, smaller and many times slower.
    #[arg(long, value_enum, value_name = "LEVEL", default_value_t)]
    pub png_level: crate::image::PngLevel,
}

impl RenderArgs {
    /// The job these arguments describe.
    pub fn job(&self) -> Job {
        let mut job = self.job.job();
        job.overrides.reference = self.reference;
        job.debug_nan = self.debug_nan;
        job
    }
}

/// Runs `sdfc render`: one image, or a sequence of frames (`--frames`, or an output pattern
/// with `#`; docs/animation.md).
pub fn run(args: RenderArgs) -> ExitCode {
    // The CUDA driver prepares only the GPUs the render opens (before any thread starts, as
    // the environment is shared).
    let job = args.job();
    backend::see_only(job.backend, &job.devices);
    let sequence = args.sequence.frames.is_some()
        || args
            .output
            .as_deref()
            .is_some_and(|o| o.to_string_lossy().contains('#'));
    if sequence {
        if args.reference || args.aux {
            return Error::Usage(
                "--reference and --aux render one image; they cannot be used with a sequence"
                    .into(),
            )
            .exit();
        }
        let out = args.output.as_deref();
        return match sequence::run(
            &args.file,
            out,
            args.png_level,
            &args.sequence,
            &job,
            args.stats,
        ) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => e.exit(),
        };
    }
    match still(&args, &job) {
        // The image is written, renamed and synced and the messages printed: the device,
        // its kernel and the thread pool are left to the operating system (see
        // `super::exit_now`).
        Ok(finished) => super::exit_now(ExitCode::SUCCESS, finished),
        // A device may still be opening on its thread ([`Opening`]): the process ends
        // without running the libraries' exit handlers beside it.
        Err(e) => super::exit_now(e.exit(), ()),
    }
}

/// What a still render leaves when it has finished: its device, kernel and thread pool.
type Finished = (Prepared, rayon::ThreadPool);

/// Renders one image (the scene at the time 0).
fn still(args: &RenderArgs, job: &Job) -> Result<Finished, Error> {
    let mut run = Run::new();
    // The device opens on a thread of its own from here, while the scene is read, checked
    // and lowered and its kernel written; the arguments' errors are reported after the
    // scene's, as ever.
    let mode = job.mode();
    let opening = match mode {
        Ok((backend, precision))
            if job.devices == Devices::Auto && job.check_kernel(backend).is_ok() =>
        {
            Opening::start(backend, precision)
        }
        _ => None,
    };
    let mut source = frontend::Source::read_within(&args.file, &job.limits)?;
    run.lap("read", "the scene's file read");
    let frame = job.frame(&mut source, 0.0, true, &LowerOptions::default())?;
    run.split(
        "scene",
        "the rest of it (diagnostics printed, settings applied)",
        frame.phases.clone(),
    );
    let (backend, _) = mode?;
    job.check_kernel(backend)?;
    // The output is checked before any work, so that a render is never thrown away.
    let out = output(args).map_err(|e| Error::Usage(e.to_string()))?;
    let pool = job.pool()?;
    run.lap("setup", "output checked, thread pool");
    let setup = Setup {
        image_only: !args.stats,
        // 8-bit outputs take the pixels the GPU finished; OpenEXR, the reference's check
        // and the sidecar read the linear colours.
        finished: !args.reference
            && !args.aux
            && !matches!(&out, Output::File { format, .. } if format.linear()),
        ..job.setup()
    };
    let open = opening.map_or(job::Open::Backend, job::Open::Beside);
    let job::Ready {
        scene, prepared, ..
    } = job::prepare(&pool, (backend, &job.devices), frame, &setup, open)?;
    run.split("preparation", "the rest of it", prepared.preparation());
    job::check_memory(
        &pool,
        &prepared,
        &scene,
        job::Use::Written {
            reference: args.reference,
            aux: args.aux,
        },
        &job.limits,
        true,
    )?;
    run.lap("memory", "what the render allocates, announced");
    let started = Instant::now();
    let frame = pool.install(|| render_with_progress(&prepared, &scene))?;
    let seconds = started.elapsed().as_secs_f64();
    match &frame.phases {
        Some(p) => run.split(
            "render",
            "the rest of it",
            vec![
                ("upload", p.setup, "buffers allocated and written".into()),
                (
                    "frame",
                    p.launches,
                    "launches until the GPU finished".into(),
                ),
                (
                    "readback",
                    p.readback,
                    "image and statistics read back".into(),
                ),
                ("conversion", p.convert, "colours and statistics".into()),
            ],
        ),
        None => run.lap("frame", "rendered on the CPU"),
    }
    for w in frame.warnings() {
        eprintln!("warning: {w}");
    }
    let check = if args.reference {
        Some(pool.install(|| check_reference(&prepared, &scene, &frame))?)
    } else {
        None
    };
    if check.is_some() {
        run.lap("check", "the reference's convergence");
    }
    // Not synced to the disk: complete or untouched whatever happens to the process, as a
    // compiler's output (`AtomicFile::unsynced`).
    let mut frame = frame;
    let picture = frame.take_picture();
    let steps = out
        .write(&picture, false, args.png_level)
        .map_err(|e| Error::Io(e.to_string()))?;
    if let (true, Some(path)) = (args.aux, out.path()) {
        write_sidecar(path, frame.render.depth.as_ref(), prepared.name())
            .map_err(|e| Error::Io(e.to_string()))?;
    }
    run.split(
        "image",
        "the rest of it (the depth sidecar, with --aux)",
        steps,
    );
    let s = &scene.settings;
    eprintln!(
        "wrote {} ({}x{}, aa {}, {} on {}, {:.3} s)",
        out,
        s.width,
        s.height,
        s.aa,
        prepared.name(),
        prepared.device(),
        seconds
    );
    if args.stats {
        let mut text = stats(&prepared, seconds, &frame, check.as_ref());
        text.push_str(&run.to_string());
        // With the image on standard output, the statistics go to standard error.
        if out == Output::Stdout {
            eprint!("{text}");
        } else {
            print!("{text}");
        }
    }
    if let Some(c) = check.as_ref().filter(|c| !c.converged) {
        eprintln!("warning: {}", not_converged(c));
    }
    Ok((prepared, pool))
}

/// Where a whole `sdfc render` went, from the process's start (`--stats`): the time before
/// `main`, then each phase as it ended, those with parts (preparing the backend, the
/// render) split into them and the rest.
struct Run {
    /// When `main` began, and the time before it (when known).
    main: (Instant, Option<Duration>),
    /// The end of the last phase.
    last: Instant,
    /// Each phase: its name, time and what it is.
    phases: Vec<(&'static str, Duration, String)>,
}

impl Run {
    fn new() -> Run {
        let main = super::started();
        let now = Instant::now();
        Run {
            main,
            // The next phase starts where the arguments' ended (not at `main`: that counted
            // the arguments twice).
            last: now,
            phases: vec![("arguments", now - main.0, "parsed".into())],
        }
    }

    /// Ends a phase now.
    fn lap(&mut self, name: &'static str, what: &str) {
        let now = Instant::now();
        self.phases.push((name, now - self.last, what.into()));
        self.last = now;
    }

    /// Ends a phase now, listed as its `parts` and what is left of it (`rest`).
    fn split(
        &mut self,
        name: &'static str,
        rest: &str,
        parts: Vec<(&'static str, Duration, String)>,
    ) {
        let now = Instant::now();
        let whole = now - self.last;
        let known: Duration = parts.iter().map(|p| p.1).sum();
        self.phases.extend(parts);
        self.phases
            .push((name, whole.saturating_sub(known), rest.into()));
        self.last = now;
    }
}

impl std::fmt::Display for Run {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        let before = self.main.1.unwrap_or_default();
        let total = before + (self.last - self.main.0);
        writeln!(
            f,
            "run             {:.1} ms from the process's start to the image written:",
            ms(total)
        )?;
        match self.main.1 {
            Some(d) => writeln!(
                f,
                "  {:<16}{:>9.1} ms  process start until main (from /proc, ±20 ms)",
                "start",
                ms(d)
            )?,
            None => writeln!(
                f,
                "  {:<16}{:>9} ms  process start until main (unknown)",
                "start", "-"
            )?,
        }
        for (name, d, what) in &self.phases {
            writeln!(f, "  {name:<16}{:>9.1} ms  {what}", ms(*d))?;
        }
        writeln!(
            f,
            "  {:<16}{:>9} ms  the device, kernel and thread pool left to the operating system (not destroyed; the process's end is not timed from inside it)",
            "exit", "-"
        )
    }
}

/// The text of `--stats` for one frame.
pub fn stats(
    prepared: &Prepared,
    seconds: f64,
    frame: &Frame,
    check: Option<&Convergence>,
) -> String {
    let mut text = format!(
        "backend         {} ({})\n",
        prepared.name(),
        prepared.device()
    );
    if let Some(k) = prepared.kernel_kind() {
        text.push_str(&format!("kernel          {k}\n"));
    }
    text.push_str(&format!(
        "time            {:.3} s (frame {:.3} s)\n",
        seconds,
        frame.time.as_secs_f64(),
    ));
    if let Some(p) = &frame.phases {
        text.push_str(&format!("frame on host   {p}\n"));
    }
    for (i, s) in frame.shares.iter().enumerate() {
        text.push_str(&format!(
            "device {i}        {}: {} tile{}, {}{}\n",
            s.device,
            s.tiles,
            if s.tiles == 1 { "" } else { "s" },
            s.phases,
            if s.failure.is_some() { " (failed)" } else { "" }
        ));
    }
    text.push_str(&format!("{}\n", frame.render.stats));
    if let Some(c) = check {
        text.push_str(&format!("{c}\n"));
    }
    text
}

/// Where the image goes (`-o`, or the scene's name with `.png` in the current directory),
/// checked: a known format, a writable place; `--aux` needs a file to put its sidecar beside.
fn output(args: &RenderArgs) -> Result<Output, OutputRefused> {
    let path = args
        .output
        .clone()
        .unwrap_or_else(|| default_output(&args.file));
    let out = Output::new(&path)?;
    if out == Output::Stdout && std::io::stdout().is_terminal() {
        return Err(OutputRefused::Terminal);
    }
    if args.aux && out == Output::Stdout {
        return Err(OutputRefused::AuxToStdout);
    }
    if let (true, Some(p)) = (args.aux, out.path()) {
        let path = depth::sidecar_path(p);
        if let Err(why) = crate::output::check_writable(&path) {
            return Err(CannotWrite { path, why }.into());
        }
    }
    Ok(out)
}

/// Why `sdfc render` refuses its output before any work.
#[derive(Debug, thiserror::Error)]
enum OutputRefused {
    /// The image or its `--aux` sidecar cannot be written.
    #[error(transparent)]
    Path(#[from] CannotWrite),
    #[error("`-o -` writes the PNG's bytes to standard output, which is a terminal here; redirect it (`-o - > out.png`) or name a file")]
    Terminal,
    #[error("--aux writes the depth sidecar beside the image file; it cannot be used with `-o -`")]
    AuxToStdout,
}

/// Why the depth sidecar was not written, or a stale one not removed.
#[derive(Debug, thiserror::Error)]
enum SidecarError {
    #[error("cannot write `{}`: {error}", path.display())]
    Write {
        path: PathBuf,
        error: depth::DepthError,
    },
    #[error("cannot remove the stale sidecar `{}`: {error}", path.display())]
    Stale {
        path: PathBuf,
        error: std::io::Error,
    },
}

/// Renders the convergence check of a reference frame (ε divided by ten, or twice the samples
/// per axis for an area-averaged reference) and compares.
pub fn check_reference(
    prepared: &Prepared,
    scene: &Scene,
    frame: &Frame,
) -> Result<Convergence, backend::Error> {
    let mut finer = scene.clone();
    finer.settings = reference::check_settings(&scene.settings);
    let check = prepared.render(&finer, &|_| {})?;
    Ok(reference::convergence(scene, &frame.render, &check.render))
}

/// The warning printed for a reference that did not converge.
pub fn not_converged(c: &Convergence) -> String {
    format!(
        "the reference has not converged: against ε {}, aa {} it reaches {:.1} dB (needs {} dB), max difference {:.3}, and {} rays ran out of {} steps; its error is not far below the errors it would measure",
        sdfc_compiler::diagnostics::scientific(c.check_epsilon),
        c.check_aa,
        c.difference.psnr,
        reference::CONVERGED_PSNR,
        c.difference.max,
        c.budget_misses,
        c.max_steps
    )
}

/// Writes the depth sidecar beside `image`. A backend without depth buffers writes none,
/// and a sidecar left there by an earlier render is removed so that it cannot be mistaken
/// for this one's.
fn write_sidecar(
    image: &Path,
    depth: Option<&depth::Depth>,
    backend: &str,
) -> Result<(), SidecarError> {
    let path = depth::sidecar_path(image);
    match depth {
        Some(d) => d
            .write(&path)
            .map_err(|error| SidecarError::Write { path, error }),
        None => {
            eprintln!("note: the {backend} backend has no depth buffers; no sidecar written");
            match std::fs::remove_file(&path) {
                Ok(()) => eprintln!("note: removed the stale sidecar `{}`", path.display()),
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(error) => return Err(SidecarError::Stale { path, error }),
            }
            Ok(())
        }
    }
}

/// Renders with a progress bar on stderr when stderr is a terminal.
pub fn render_with_progress(prepared: &Prepared, scene: &Scene) -> Result<Frame, backend::Error> {
    let bar = super::progress_bar(1000, "{bar:40} {percent:>3}% {elapsed_precise} eta {eta}");
    let frame = prepared.render(scene, &|f| {
        if let Some(b) = &bar {
            b.set_position((f * 1000.0) as u64);
        }
    });
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    frame
}

/// `scene.sdf` → `./scene.png`.
fn default_output(file: &Path) -> PathBuf {
    PathBuf::from(format!("{}.png", super::stem_or(file, "render")))
}
