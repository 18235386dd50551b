//! `sdfc pareto`: speed against accuracy. Renders a scene with every combination of swept
//! settings, times each (median of several frames), measures its error against the
//! reference render (PSNR, and first-hit differences where both have depth buffers), marks the
//! Pareto front and draws the chart; the sweeps, the front and the report are
//! `crate::pareto`'s.

use super::render::{self, Backend};
use crate::backend::{Devices, Prepared, Ran, Setup};
use crate::chart::{self, Chart};
use crate::cpu::reference;
use crate::cpu::{Precision, Render};
use crate::frontend;
use crate::job::{self, Error, FrameScene, Job, Open, Overrides, Ready, Use};
use crate::metrics;
use crate::output::CannotWrite;
use crate::pareto::{
    chart_of, combinations, describe, mark_fronts, parse_sweep_within, same, table, Measured,
    ReferenceInfo, Report, DEFAULT_SWEEPS,
};
use crate::settings::parse_size;
use sdfc_compiler::{
    diagnostics::scientific, Limits, LowerOptions, Lowered, Method, Scene, Settings,
};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `sdfc pareto`.
#[derive(Debug, clap::Args)]
pub struct ParetoArgs {
    /// Scene file.
    pub file: PathBuf,
    /// Backend to time (the reference is always rendered on the CPU in f64).
    #[arg(long, value_enum, default_value_t)]
    pub backend: Backend,
    /// A swept setting: `KEY=LO..HI`, `KEY=LO..HI:N` or `KEY=V1,V2,...`, with KEY one of
    /// epsilon, max_steps, samples (log-spaced ranges), relaxation (linear) or aa (every
    /// integer); with --mesh, resolution (log-spaced). May be repeated; every combination is
    /// rendered. Default: epsilon=1e-2..1e-6, max_steps=32..1024, relaxation=1..1.8; with
    /// --mesh, resolution=32..256.
    #[arg(long = "sweep", value_name = "KEY=RANGE")]
    pub sweep: Vec<String>,
    /// Frames timed per point (the median is used).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub frames: u32,
    /// Image size, as WIDTHxHEIGHT (default: the scene's own).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Override a render setting (as for `sdfc render`) before sweeping; with --mesh, a mesh
    /// setting (as for `sdfc mesh`). May be repeated.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Measure meshing instead of rendering: `sdfc mesh` at each swept resolution, its time
    /// and triangles against the largest distance of the mesh from the surface.
    #[arg(long, conflicts_with_all = ["backend", "precision", "size", "target"])]
    pub mesh: bool,
    /// With --mesh, the region to mesh, X0,Y0,Z0,X1,Y1,Z1 (as for `sdfc mesh`).
    #[arg(long, value_name = "X0,Y0,Z0,X1,Y1,Z1", value_parser = super::mesh::parse_bounds, allow_hyphen_values = true, requires = "mesh")]
    pub bounds: Option<[[f64; 3]; 2]>,
    /// Float type of the timed renders.
    #[arg(long, value_enum, default_value_t)]
    pub precision: Precision,
    /// Worker threads (default: one per core).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// The chart to draw: a .svg or .png file.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// The accuracy target drawn on the chart, in dB.
    #[arg(long, default_value_t = 40.0)]
    pub target: f64,
    /// Print the measured points as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub limits: super::LimitArgs,
}

impl ParetoArgs {
    /// The job these arguments describe: the timed renders'.
    pub fn job(&self) -> Job {
        let overrides = Overrides {
            size: self.size,
            set: self.set.clone(),
            ..Overrides::default()
        };
        Job {
            precision: self.precision,
            threads: self.threads,
            ..Job::new(self.backend, overrides, self.limits.limits())
        }
    }
}

/// Runs `sdfc pareto`.
pub fn run(args: ParetoArgs) -> ExitCode {
    if args.mesh {
        return super::pareto_mesh::run(&args);
    }
    let job = args.job();
    let limits = &job.limits;
    let mut source = match frontend::Source::read_within(&args.file, limits) {
        Ok(s) => s,
        Err(e) => return Error::from(e).exit(),
    };
    let mut loaded = source.check(limits, 0.0);
    let mut scene = match job.checked(&mut loaded, true) {
        Ok(s) => s,
        Err(e) => return e.exit(),
    };
    let specs: Vec<String> = if args.sweep.is_empty() {
        DEFAULT_SWEEPS.iter().map(|s| s.to_string()).collect()
    } else {
        args.sweep.clone()
    };
    // The swept settings are sphere tracing's: a scene that `auto` would trace analytically
    // (no ε, no step budget) is marched, unless `--set method=trace` asks otherwise.
    // A path-traced scene keeps finding its surfaces as `auto` does (its sweep is of samples).
    if scene.settings.method == Method::Auto && !scene.settings.path {
        scene.settings.method = Method::March;
    }
    let mut plan = || -> Result<_, Error> {
        check_output(args.output.as_deref()).map_err(|e| Error::Usage(e.to_string()))?;
        job.settings(&mut scene)?;
        let sweeps = specs
            .iter()
            .map(|s| parse_sweep_within(s, limits))
            .collect::<Result<Vec<_>, _>>()?;
        if sweeps
            .iter()
            .any(|s| s.key == crate::pareto::Key::Resolution)
        {
            return Err(Error::Usage(
                "resolution is a mesh's: sweep it with `sdfc pareto --mesh`".into(),
            ));
        }
        let points = combinations(&scene.settings, &sweeps, limits)?;
        Ok((points, job.pool()?))
    };
    let (points, pool) = match plan() {
        Ok(p) => p,
        Err(e) => return e.exit(),
    };
    let lowered = match job.lower(&scene, &loaded.sources, &LowerOptions::default()) {
        Ok(p) => p,
        Err(e) => return e.exit(),
    };
    match pool.install(|| measure(&args, &scene, lowered, points, limits)) {
        Ok(report) => finish(&args, &report),
        Err(e) => e.exit(),
    }
}

/// Refuses a chart name that is neither .svg nor .png, or that cannot be written (a missing
/// directory), before any work is done.
pub(super) fn check_output(out: Option<&std::path::Path>) -> Result<(), ChartRefused> {
    let Some(path) = out else { return Ok(()) };
    let ext = path.extension().map(|e| e.to_string_lossy().to_lowercase());
    match ext {
        Some(e) if e == "svg" || e == "png" => crate::output::check_writable(path).map_err(|why| {
            ChartRefused::Unwritable(CannotWrite {
                path: path.into(),
                why,
            })
        }),
        _ => Err(ChartRefused::Format(path.into())),
    }
}

/// Why the chart `--output` names cannot be written.
#[derive(Debug, thiserror::Error)]
pub(super) enum ChartRefused {
    #[error(transparent)]
    Unwritable(CannotWrite),
    #[error("`{}`: the chart must be a .svg or .png file", .0.display())]
    Format(std::path::PathBuf),
}

/// Prints the report and draws the chart.
fn finish(args: &ParetoArgs, report: &Report) -> ExitCode {
    publish(args, report, &table(report), || {
        chart_of(report, args.target)
    })
}

/// Prints a sweep's `report` (as JSON with `--json`, else its `table`) and draws its chart
/// into `--output`, if given: the end of `sdfc pareto` for pictures and for meshes.
pub(super) fn publish<R: serde::Serialize>(
    args: &ParetoArgs,
    report: &R,
    table: &str,
    chart: impl FnOnce() -> Chart,
) -> ExitCode {
    if args.json {
        if let Err(code) = super::print_json(report, true) {
            return code;
        }
    } else {
        print!("{table}");
    }
    if let Some(out) = &args.output {
        if let Err(msg) = chart::write(&chart(), out) {
            eprintln!("error: {msg}");
            return ExitCode::from(2);
        }
        eprintln!("wrote {}", out.display());
    }
    ExitCode::SUCCESS
}

/// Renders the reference, then every point, and measures them. Every render is held to the
/// memory limit before the first starts.
fn measure(
    args: &ParetoArgs,
    scene: &Scene,
    lowered: Lowered,
    mut points: Vec<Settings>,
    limits: &Limits,
) -> Result<Report, Error> {
    let default = scene.settings.clone();
    if !points.iter().any(|s| same(s, &default)) {
        points.push(default.clone());
    }
    let setup = Setup {
        precision: args.precision,
        ..Setup::default()
    };
    // Through the job's path, on the pool this runs in.
    let frame = FrameScene {
        scene: scene.clone(),
        lowered: lowered.clone(),
        phases: Vec::new(),
    };
    let on = (args.backend, &Devices::Auto);
    let mut prepared = job::prepare_here(on, frame, &setup, Open::Backend)?.prepared;
    let (reference_scene, reference_prepared) = reference_setup(scene, lowered, &points)?;
    // The reference frame is held while each point renders.
    let held = reference_prepared.retained(&reference_scene.settings);
    let reference = Use::Written {
        reference: true,
        aux: false,
    };
    job::check_memory_here(
        &reference_prepared,
        &reference_scene,
        reference,
        limits,
        false,
    )?;
    for settings in &points {
        let mut point = prepared.memory(scene, settings);
        point.host = point.host.saturating_add(held);
        point.check(limits).map_err(Error::Memory)?;
    }
    let (reference, info) = reference_render(&reference_prepared, &reference_scene)?;
    prepared.render(scene, &|_| {})?;
    let mut measured = Vec::with_capacity(points.len());
    for (i, settings) in points.iter().enumerate() {
        // A GPU kernel is specialised to some settings (ω > 1 or not, the method,
        // `max_depth`): a point that needs others gets a kernel of its own, before its
        // frames are timed.
        let mut point = scene.clone();
        point.settings = settings.clone();
        prepared.specialise(&point)?;
        let m = measure_one(
            args,
            &prepared,
            scene,
            settings,
            &reference,
            same(settings, &default),
        )?;
        eprintln!(
            "[{}/{}] {}: {:.2} ms, {:.1} steps/px, {:.2} dB",
            i + 1,
            points.len(),
            describe(settings),
            m.median_s * 1e3,
            m.steps_mean,
            m.psnr
        );
        measured.push(m);
    }
    mark_fronts(&mut measured);
    let d = measured.iter().find(|m| m.default);
    let s = &scene.settings;
    Ok(Report {
        ran: Ran::new(
            args.file.display().to_string(),
            &prepared,
            args.precision,
            s,
        ),
        frames: args.frames,
        reference: info,
        default_on_front_time: d.is_some_and(|m| m.front_time),
        default_on_front_steps: d.is_some_and(|m| m.front_steps),
        points: measured,
    })
}

/// The scene of the reference render (at the largest supersampling of the points), prepared
/// on the CPU in f64.
fn reference_setup(
    scene: &Scene,
    lowered: Lowered,
    points: &[Settings],
) -> Result<(Scene, Prepared), Error> {
    let aa = points
        .iter()
        .map(|s| s.aa)
        .max()
        .unwrap_or(scene.settings.aa);
    // A path-traced reference has `reference::PATH_FACTOR` times the most samples measured.
    let most = points
        .iter()
        .map(|s| s.samples)
        .max()
        .unwrap_or(scene.settings.samples);
    let samples = most.saturating_mul(reference::PATH_FACTOR);
    let mut reference_scene = scene.clone();
    // The most exact render the scene allows: analytic tracing where it can be traced.
    reference_scene.settings = Settings {
        aa,
        samples,
        first_sample: 0,
        method: Method::Auto,
        ..scene.settings.clone()
    };
    reference_scene.settings = reference::settings_of(&reference_scene);
    let frame = FrameScene {
        scene: reference_scene,
        lowered,
        phases: Vec::new(),
    };
    let setup = Setup {
        precision: Precision::F64,
        ..Setup::default()
    };
    let on = (Backend::Cpu, &Devices::Auto);
    let Ready {
        scene, prepared, ..
    } = job::prepare_here(on, frame, &setup, Open::Backend)?;
    Ok((scene, prepared))
}

/// The reference render and its check.
fn reference_render(
    prepared: &Prepared,
    reference_scene: &Scene,
) -> Result<(Render, ReferenceInfo), Error> {
    let aa = reference_scene.settings.aa;
    let start = std::time::Instant::now();
    let frame = prepared.render(reference_scene, &|_| {})?;
    let convergence = render::check_reference(prepared, reference_scene, &frame)?;
    let seconds = start.elapsed().as_secs_f64();
    if !convergence.converged {
        eprintln!("warning: {}", render::not_converged(&convergence));
    }
    eprintln!(
        "reference: aa {aa}, {seconds:.1} s; agrees with ε {}, aa {} to {:.2} dB",
        scientific(convergence.check_epsilon),
        convergence.check_aa,
        convergence.difference.psnr
    );
    Ok((
        frame.render,
        ReferenceInfo {
            aa,
            samples: if reference_scene.settings.path {
                reference_scene.settings.samples
            } else {
                0
            },
            convergence,
            seconds,
        },
    ))
}

/// Times one combination and measures it against the reference.
fn measure_one(
    args: &ParetoArgs,
    prepared: &Prepared,
    scene: &Scene,
    settings: &Settings,
    reference: &Render,
    default: bool,
) -> Result<Measured, Error> {
    let mut point = scene.clone();
    point.settings = settings.clone();
    let mut times = Vec::with_capacity(args.frames as usize);
    let mut last = None;
    for _ in 0..args.frames {
        let frame = prepared.render(&point, &|_| {})?;
        times.push(frame.time.as_secs_f64());
        last = Some(frame.render);
    }
    let render = last.ok_or(Error::NoFrame)?;
    times.sort_by(f64::total_cmp);
    let d = metrics::compare(&reference.image, &render.image, reference::THRESHOLD)
        .ok_or(Error::SizeDiffers)?;
    let depth = match (&reference.depth, &render.depth) {
        (Some(r), Some(t)) => metrics::compare_depth(r, t, reference::DEPTH_TOLERANCE),
        _ => None,
    };
    Ok(Measured {
        epsilon: point.epsilon(),
        max_steps: settings.max_steps,
        relaxation: settings.relaxation,
        aa: settings.aa,
        samples: if settings.path { settings.samples } else { 0 },
        median_s: times[times.len() / 2],
        min_s: times[0],
        steps_mean: render.stats.steps_mean,
        budget_misses: render.stats.counters.budget_misses,
        psnr: d.psnr,
        rmse: d.rmse,
        max: d.max,
        differing: d.differing,
        depth,
        front_time: false,
        front_steps: false,
        default,
    })
}
