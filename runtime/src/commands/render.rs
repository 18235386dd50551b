//! `sdfc render`: render a scene to an image (PNG, JPEG or OpenEXR; optionally the reference render with its
//! convergence check, and the depth sidecar), and the option handling `sdfc bench` and
//! `sdfc pareto` share (backend choice, `--size`, `--aa`, `--set key=value` overrides, thread
//! pools).

use crate::backend::{Frame, Prepared, Setup};
use crate::cpu::reference::{self, Convergence};
use crate::cpu::Precision;
use crate::frontend::{self, DiagnosticFormat};
use crate::output::Output;
use crate::settings::{override_settings, parse_size};
use crate::{depth, memory};
use indicatif::{ProgressBar, ProgressStyle};
use sdfc_compiler::lower::LowerOptions;
use sdfc_compiler::scene::Scene;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

pub use crate::backend::Backend;

/// Arguments of `sdfc render`.
#[derive(Debug, clap::Args)]
pub struct RenderArgs {
    /// Scene file.
    pub file: PathBuf,
    /// Backend to render with.
    #[arg(long, value_enum, default_value_t)]
    pub backend: Backend,
    /// Image size, as WIDTHxHEIGHT (overrides the scene's `render` block).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Supersampling: N×N samples per pixel.
    #[arg(long, value_name = "N")]
    pub aa: Option<u32>,
    /// Override a render setting: width, height, aa, max_steps, epsilon, max_depth, max_dist,
    /// relaxation or background (as r,g,b). May be repeated.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Output image: .png, .jpg (or .jpeg), or .exr (linear, unclamped 32-bit floats); `-`
    /// writes the PNG to standard output (default: the scene file's name with .png, in the
    /// current directory).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Print render statistics.
    #[arg(long)]
    pub stats: bool,
    /// Float type of the evaluation.
    #[arg(long, value_enum, default_value_t)]
    pub precision: Precision,
    /// Worker threads (default: one per core).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
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
    pub limits: super::LimitArgs,
}

/// Runs `sdfc render`.
pub fn run(args: RenderArgs) -> ExitCode {
    let limits = args.limits.limits();
    let mut checked = match frontend::load_scene(&args.file, DiagnosticFormat::Human, &limits) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let (backend, precision) = match reference_mode(&args) {
        Ok(b) => b,
        Err(msg) => {
            eprintln!("error: {msg}");
            return ExitCode::from(2);
        }
    };
    // The output is checked before any work, so that a render is never thrown away.
    let out = match output(&args) {
        Ok(o) => o,
        Err(msg) => {
            eprintln!("error: {msg}");
            return ExitCode::from(2);
        }
    };
    if args.reference {
        checked.scene.settings = reference::settings_of(&checked.scene);
    }
    let settings = &mut checked.scene.settings;
    if let Err(msg) = override_settings(settings, args.size, args.aa, &args.set, &limits) {
        eprintln!("error: {msg}");
        return ExitCode::from(2);
    }
    if let Err(msg) = crate::backend::method_allowed(&checked.scene) {
        eprintln!("error: {msg}");
        return ExitCode::from(1);
    }
    let pool = match thread_pool(args.threads) {
        Ok(p) => p,
        Err(msg) => {
            eprintln!("error: {msg}");
            return ExitCode::from(2);
        }
    };
    let program = match checked.lower(&LowerOptions::default(), &limits) {
        Ok(p) => p,
        Err(code) => return code,
    };
    let scene = checked.scene;
    let setup = Setup {
        precision,
        debug_nan: args.debug_nan,
    };
    let prepared = match pool.install(|| Prepared::from_program(backend, &scene, program, &setup)) {
        Ok(p) => p,
        Err(msg) => {
            eprintln!("error: the {backend:?} backend is not available: {msg}");
            return ExitCode::from(1);
        }
    };
    let needed = pool.install(|| memory::render(&prepared, &scene, args.reference, args.aux));
    eprintln!(
        "{}",
        memory::announce(&scene.settings, prepared.name(), &needed)
    );
    if let Err(msg) = needed.check(&limits) {
        eprintln!("error: {msg}");
        return ExitCode::from(1);
    }
    let started = Instant::now();
    let frame = match pool.install(|| render_with_progress(&prepared, &scene)) {
        Ok(f) => f,
        Err(msg) => {
            eprintln!("error: {msg}");
            return ExitCode::from(1);
        }
    };
    let seconds = started.elapsed().as_secs_f64();
    let check = if args.reference {
        match pool.install(|| check_reference(&prepared, &scene, &frame)) {
            Ok(c) => Some(c),
            Err(msg) => {
                eprintln!("error: {msg}");
                return ExitCode::from(1);
            }
        }
    } else {
        None
    };
    let render = frame.render;
    if let Err(msg) = out.write(&render.image) {
        eprintln!("error: {msg}");
        return ExitCode::from(2);
    }
    if let (true, Some(path)) = (args.aux, out.path()) {
        if let Err(msg) = write_sidecar(path, render.depth.as_ref(), prepared.name()) {
            eprintln!("error: {msg}");
            return ExitCode::from(2);
        }
    }
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
        let mut text = format!(
            "backend         {} ({})\n",
            prepared.name(),
            prepared.device()
        );
        if let Some(p) = prepared.preparation() {
            text.push_str(&format!("prepared        {p}\n"));
        }
        text.push_str(&format!(
            "time            {:.3} s (frame {:.3} s)\n{}\n",
            seconds,
            frame.time.as_secs_f64(),
            render.stats
        ));
        if let Some(c) = &check {
            text.push_str(&format!("{c}\n"));
        }
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
    ExitCode::SUCCESS
}

/// Where the image goes (`-o`, or the scene's name with `.png` in the current directory),
/// checked: a known format, a writable place; `--aux` needs a file to put its sidecar beside.
fn output(args: &RenderArgs) -> Result<Output, String> {
    let path = args
        .output
        .clone()
        .unwrap_or_else(|| default_output(&args.file));
    let out = Output::new(&path)?;
    if out == Output::Stdout && std::io::stdout().is_terminal() {
        return Err("`-o -` writes the PNG's bytes to standard output, which is a terminal here; redirect it (`-o - > out.png`) or name a file".into());
    }
    if args.aux && out == Output::Stdout {
        return Err(
            "--aux writes the depth sidecar beside the image file; it cannot be used with `-o -`"
                .into(),
        );
    }
    if let (true, Some(p)) = (args.aux, out.path()) {
        crate::output::check_writable(&depth::sidecar_path(p))
            .map_err(|why| format!("cannot write `{}`: {why}", depth::sidecar_path(p).display()))?;
    }
    Ok(out)
}

/// The backend and precision of a render: `--reference` means the CPU in f64.
fn reference_mode(args: &RenderArgs) -> Result<(Backend, Precision), String> {
    if !args.reference {
        return Ok((args.backend, args.precision));
    }
    match args.backend {
        Backend::Auto | Backend::Cpu => Ok((Backend::Cpu, Precision::F64)),
        b => Err(format!(
            "--reference renders on the CPU in f64; it cannot use --backend {}",
            format!("{b:?}").to_lowercase()
        )),
    }
}

/// Renders the convergence check of a reference frame (ε divided by ten, or twice the samples
/// per axis for an area-averaged reference) and compares.
pub fn check_reference(
    prepared: &Prepared,
    scene: &Scene,
    frame: &Frame,
) -> Result<Convergence, String> {
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
fn write_sidecar(image: &Path, depth: Option<&depth::Depth>, backend: &str) -> Result<(), String> {
    let path = depth::sidecar_path(image);
    match depth {
        Some(d) => d
            .write(&path)
            .map_err(|e| format!("cannot write `{}`: {e}", path.display())),
        None => {
            eprintln!("note: the {backend} backend has no depth buffers; no sidecar written");
            match std::fs::remove_file(&path) {
                Ok(()) => eprintln!("note: removed the stale sidecar `{}`", path.display()),
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(e) => {
                    return Err(format!(
                        "cannot remove the stale sidecar `{}`: {e}",
                        path.display()
                    ))
                }
            }
            Ok(())
        }
    }
}

/// Renders with a progress bar on stderr when stderr is a terminal.
fn render_with_progress(prepared: &Prepared, scene: &Scene) -> Result<Frame, String> {
    let bar = std::io::stderr().is_terminal().then(|| {
        let bar = ProgressBar::new(1000);
        if let Ok(style) =
            ProgressStyle::with_template("{bar:40} {percent:>3}% {elapsed_precise} eta {eta}")
        {
            bar.set_style(style);
        }
        bar
    });
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
    let stem = file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "render".into());
    PathBuf::from(format!("{stem}.png"))
}

/// A rayon pool of `threads` workers (default: rayon's choice, one per core).
pub fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool, String> {
    let mut b = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        if n == 0 {
            return Err("--threads must be at least 1".into());
        }
        b = b.num_threads(n);
    }
    b.build()
        .map_err(|e| format!("cannot start worker threads: {e}"))
}
