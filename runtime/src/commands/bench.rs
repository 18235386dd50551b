//! `sdfc bench`: time the rendering of scenes (median per frame, rays per second, steps, and
//! for GPU targets the achieved fraction of the FP32 floor).

use super::JobArgs;
use crate::backend::{Ran, Setup};
use crate::cpu::Stats;
use crate::fp32;
use crate::frontend;
use crate::job::{self, Error, FrameScene, Job, Kernels, Open, Ready, Use};
use sdfc_compiler::LowerOptions;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `sdfc bench`.
#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// Scene files.
    #[arg(required = true)]
    pub file: Vec<PathBuf>,
    #[command(flatten)]
    pub job: JobArgs,
    /// Frames timed per scene (after one untimed warm-up frame).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub frames: u32,
    /// Print one JSON array instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Time an animated scene's sequence instead (docs/animation.md): every frame checked
    /// at its time, lowered, prepared again only when its program changed, and rendered, at
    /// 1920x1080 unless --size says otherwise; reports the sustained frames per second and
    /// the kernels prepared.
    #[arg(long)]
    pub frames_per_second: bool,
    /// With --frames-per-second: the frames A up to B − 1 (default: the scene's
    /// `fps × duration`).
    #[arg(long, value_name = "A..B", value_parser = crate::sequence::Frames::parse)]
    pub sequence: Option<crate::sequence::Frames>,
    /// How GPU kernels hold the distance program's constants: read from a buffer, so that
    /// programs differing only in numbers share one kernel (as `sdfc render` of a sequence and
    /// `sdfc view` do), or written as literals, a kernel per program (as `sdfc render` of a
    /// still does). Default: parameters with --frames-per-second, literal otherwise.
    #[arg(long, value_enum)]
    pub constants: Option<Constants>,
}

/// The timing of one scene.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Timing {
    /// The scene, backend, device, float type and size.
    #[serde(flatten)]
    pub ran: Ran,
    /// Samples per pixel edge.
    pub aa: u32,
    /// Worker threads.
    pub threads: usize,
    /// Frames timed.
    pub frames: u32,
    /// Median seconds per frame.
    pub median_s: f64,
    /// Median wall time per frame, seconds: for GPU backends from the first submission until
    /// the GPU finished (launch overheads included, readback excluded).
    pub median_wall_s: f64,
    /// Median host time of the whole frame, seconds: from the render's call until its
    /// pixels are in host memory (setup, launches, readback and conversion; on several
    /// devices, the measure their speed-up is taken in). The timed frames reduce no
    /// statistics: those printed are the warm-up frame's.
    pub median_frame_s: f64,
    /// Fastest frame, seconds.
    pub min_s: f64,
    /// Camera rays per second, in millions (at the median).
    pub mrays_per_s: f64,
    /// All rays (camera, secondary, shadow) per second, in millions (at the median).
    pub total_mrays_per_s: f64,
    /// The GPU kernel: "specialised" (the distance program as code) or "interpreted";
    /// null on the CPU.
    pub kernel: Option<&'static str>,
    /// How the scene was rendered: its surfaces found by "trace" (analytic) or "march"
    /// (sphere tracing), shaded by Whitted's model; or "path+trace" and "path+march", path
    /// traced (`method: "path"`) with its surfaces found either way.
    pub method: &'static str,
    /// Instructions of the distance program.
    pub program_len: usize,
    /// FP32 operations of one evaluation of the distance, every guarded block counted
    /// (`fp32::distance_ops`): for a program with guarded blocks, an upper bound of the work
    /// per evaluation.
    pub ops_per_eval: f64,
    /// Evaluations of the distance in the warm-up frame (marching steps and normal taps; 0 under
    /// analytic tracing, which evaluates no distance, and then the FP32 fields are null).
    pub evaluations: u64,
    /// GPU targets: the device's peak FP32 rate in TFLOP/s (null for the CPU and for a
    /// device not in the table of `fp32::PEAKS`).
    pub fp32_peak_tflops: Option<f64>,
    /// GPU targets: ops_per_eval · evaluations / (median_s · peak), the fraction of the
    /// FP32 peak achieved (`fp32::fraction_of_peak`): null where the peak is, for a program
    /// with guarded blocks (what ran is not counted) and where the quotient would exceed 1.
    /// Never above 1.
    pub fp32_fraction: Option<f64>,
    /// Statistics of the warm-up frame (the timed frames render the same).
    pub stats: Stats,
    /// On several devices, what each did in the last frame (as `render --stats` prints it:
    /// bands, and its setup with the uploads, launches with the waits for them, readback and
    /// conversion); absent on one.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub devices: Vec<String>,
}

/// How the kernels of a timed sequence hold the program's constants.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Constants {
    /// Read from the kernel's buffer: one kernel for programs that differ in numbers only.
    #[default]
    Parameters,
    /// Written as literals: a kernel for every program.
    Literal,
}

/// The timing of one scene's sequence (`--frames-per-second`).
#[derive(Debug, Clone, serde::Serialize)]
pub struct SequenceTiming {
    /// The scene file.
    pub scene: String,
    /// Backend used.
    pub backend: &'static str,
    /// The device it ran on.
    pub device: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The first frame and one past the last (the first, rendered before timing, included).
    pub frames: [u64; 2],
    /// Frames timed (all but the first).
    pub timed: u64,
    /// Wall seconds of the timed frames, from checking each to its image in host memory.
    pub seconds: f64,
    /// Timed frames per second.
    pub frames_per_s: f64,
    /// Seconds of the timed frames spent checking and lowering.
    pub check_s: f64,
    /// Seconds spent preparing kernels (or CPU tapes) for the timed frames.
    pub prepare_s: f64,
    /// Seconds spent rendering the timed frames (wall, readback included).
    pub render_s: f64,
    /// Kernels prepared for the whole sequence (the first frame's included).
    pub kernels: usize,
}

/// Times the sequence of each scene (`--frames-per-second`).
fn run_sequences(args: &BenchArgs) -> Result<Vec<SequenceTiming>, Error> {
    use sdfc_compiler::Animation;
    use std::time::{Duration, Instant};
    let mut job = args.job.job();
    job.overrides.size = job.overrides.size.or(Some((1920, 1080)));
    let pool = job.pool()?;
    let mut out = Vec::new();
    for file in &args.file {
        let mut source = frontend::Source::read(file)?;
        // The frames are lowered as `sdfc render --frames` lowers them.
        let lowering = LowerOptions::parametric();
        let first = job.frame(&mut source, 0.0, true, &lowering)?;
        let animation = first.scene.animation;
        let frames = match args.sequence {
            Some(f) => f,
            None => crate::sequence::Frames {
                start: 0,
                end: animation.frames(),
            },
        };
        if frames.len() < 2 {
            return Err(Error::Usage(format!(
                "{}: --frames-per-second needs at least two frames: the scene's `render` block states {} (fps × duration); give --sequence A..B",
                file.display(),
                frames.len()
            )));
        }
        let setup = Setup {
            parameters: args.constants.unwrap_or(Constants::Parameters) == Constants::Parameters,
            // As `sdfc render --frames` renders a sequence: the image alone, finished on the GPU.
            image_only: true,
            finished: true,
            ..job.setup()
        };
        let mut kernels = Kernels::new(&pool, (job.backend, job.devices.clone()), setup);
        let (mut check, mut render) = (Duration::ZERO, Duration::ZERO);
        let mut prepare_before = Duration::ZERO;
        let mut started = Instant::now();
        let mut size = (0, 0);
        for k in frames.start..frames.end {
            let t0 = Instant::now();
            let time = Animation::time_of(animation.fps, k);
            let frame = job.frame(&mut source, time, false, &lowering)?;
            let t1 = Instant::now();
            let (scene, prepared) = kernels.prepare(frame)?;
            let t2 = Instant::now();
            if k == frames.start {
                job::check_memory(&pool, prepared, &scene, Use::IMAGE, &job.limits, false)?;
            }
            let image = pool.install(|| prepared.render(&scene, &|_| {}))?;
            size = (image.render.image.width, image.render.image.height);
            if k == frames.start {
                // The first frame is not timed: the device opens and the kernel compiles.
                prepare_before = kernels.time;
                started = Instant::now();
                continue;
            }
            check += t1 - t0;
            render += t2.elapsed();
        }
        let seconds = started.elapsed().as_secs_f64();
        let timed = frames.len() - 1;
        let prepared = kernels.last().expect("a frame was prepared");
        out.push(SequenceTiming {
            scene: file.display().to_string(),
            backend: prepared.name(),
            device: prepared.device(),
            width: size.0,
            height: size.1,
            frames: [frames.start, frames.end],
            timed,
            seconds,
            frames_per_s: timed as f64 / seconds,
            check_s: check.as_secs_f64(),
            prepare_s: (kernels.time - prepare_before).as_secs_f64(),
            render_s: render.as_secs_f64(),
            kernels: kernels.count,
        });
    }
    Ok(out)
}

/// Runs `sdfc bench`.
pub fn run(args: BenchArgs) -> ExitCode {
    let job = args.job.job();
    // The CUDA driver prepares only the GPUs measured (before any thread starts).
    crate::backend::see_only(job.backend, &job.devices);
    if let Err(e) = job.check_kernel(job.backend) {
        return e.exit();
    }
    if args.frames_per_second {
        let timings = match run_sequences(&args) {
            Ok(t) => t,
            Err(e) => return e.exit(),
        };
        if args.json {
            if let Err(code) = super::print_json(&timings, true) {
                return code;
            }
        } else {
            println!(
                "{:<28} {:>7} {:>9} {:>8} {:>9} {:>8} {:>9} {:>9} {:>9}",
                "scene",
                "backend",
                "size",
                "frames",
                "frames/s",
                "kernels",
                "check ms",
                "prep ms",
                "render ms"
            );
            for t in &timings {
                let name = std::path::Path::new(&t.scene)
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_else(|| t.scene.clone());
                let per = |s: f64| s / t.timed as f64 * 1e3;
                println!(
                    "{:<28} {:>7} {:>9} {:>8} {:>9.2} {:>8} {:>9.2} {:>9.2} {:>9.2}",
                    name,
                    t.backend,
                    format!("{}x{}", t.width, t.height),
                    format!("{}..{}", t.frames[0], t.frames[1]),
                    t.frames_per_s,
                    t.kernels,
                    per(t.check_s),
                    per(t.prepare_s),
                    per(t.render_s)
                );
            }
        }
        return ExitCode::SUCCESS;
    }
    let pool = match job.pool() {
        Ok(p) => p,
        Err(e) => return e.exit(),
    };
    let mut timings = Vec::new();
    for file in &args.file {
        let t = match time_file(&args, &job, &pool, file) {
            Ok(t) => t,
            Err(e @ (Error::Usage(_) | Error::Io(_) | Error::Scene(_))) => return e.exit(),
            Err(e) => {
                eprintln!("error: {}: {e}", file.display());
                return e.code();
            }
        };
        if !args.json {
            if timings.is_empty() {
                println!("{}", header());
            }
            println!("{}", row(&t));
        }
        timings.push(t);
    }
    if args.json {
        if let Err(code) = super::print_json(&timings, true) {
            return code;
        }
    }
    ExitCode::SUCCESS
}

/// Times one scene file: read, checked, its settings applied and lowered as a still
/// ([`Job::frame`]), then [`time_scene`].
fn time_file(
    args: &BenchArgs,
    job: &Job,
    pool: &rayon::ThreadPool,
    file: &std::path::Path,
) -> Result<Timing, Error> {
    let mut source = frontend::Source::read(file)?;
    let frame = job.frame(&mut source, 0.0, true, &LowerOptions::default())?;
    let name = file.display().to_string();
    pool.install(|| time_scene(args, job, name, frame))
}

/// Prepares `frame` through the job's path ([`job::prepare_here`]), holds it to the memory
/// limit with a frame held while the next renders ([`Use::Held`]), then renders one warm-up
/// frame and `frames` timed frames. GPU backends are timed on the device (timestamps or
/// events); the CPU by the wall clock.
fn time_scene(
    args: &BenchArgs,
    job: &Job,
    name: String,
    frame: FrameScene,
) -> Result<Timing, Error> {
    let ops_per_eval = fp32::distance_ops(&frame.lowered.program);
    let guarded = !frame.lowered.program.blocks().is_empty();
    let setup = Setup {
        parameters: args.constants == Some(Constants::Parameters),
        // The image is not kept: the GPU finishes it, and only its 8-bit pixels cross.
        finished: true,
        ..job.setup()
    };
    let on = (job.backend, &job.devices);
    let Ready {
        scene,
        mut prepared,
        ..
    } = job::prepare_here(on, frame, &setup, Open::Backend)?;
    // The warm-up frame is held while the timed ones render.
    job::check_memory_here(&prepared, &scene, Use::Held, &job.limits, false)?;
    let scene = &scene;
    // The warm-up frame's statistics are those printed (every frame has the same); the
    // timed frames read back their pixels alone, as `sdfc render` and sequences do.
    let warm = prepared.render(scene, &|_| {})?;
    let (last, mut shares) = (warm.render, warm.shares);
    if let Some(f) = warm.finished {
        f.recycle();
    }
    prepared.reduce_statistics(false);
    let mut times = Vec::new();
    let mut walls = Vec::new();
    let mut whole = Vec::new();
    for _ in 0..args.frames {
        let started = std::time::Instant::now();
        let frame = prepared.render(scene, &|_| {})?;
        whole.push(started.elapsed().as_secs_f64());
        times.push(frame.time.as_secs_f64());
        walls.push(frame.wall.as_secs_f64());
        shares = frame.shares;
        // Its buffer takes the next frame's pixels.
        if let Some(f) = frame.finished {
            f.recycle();
        }
    }
    times.sort_by(f64::total_cmp);
    let median = times[times.len() / 2];
    let c = &last.stats.counters;
    let s = &scene.settings;
    let traced = prepared.traceable().traced(s.method).is_some();
    let evaluations = if traced { 0 } else { fp32::evaluations(c) };
    // No peak for the CPU, nor for a traced scene.
    let peak = match prepared.kernel_kind() {
        Some(_) if !traced => fp32::peak_flops(&prepared.device()),
        _ => None,
    };
    Ok(Timing {
        ran: Ran::new(name, &prepared, job.precision, s),
        aa: s.aa,
        threads: rayon::current_num_threads(),
        frames: args.frames,
        median_s: median,
        median_wall_s: {
            walls.sort_by(f64::total_cmp);
            walls[walls.len() / 2]
        },
        median_frame_s: {
            whole.sort_by(f64::total_cmp);
            whole[whole.len() / 2]
        },
        min_s: times[0],
        mrays_per_s: c.camera_rays as f64 / median / 1e6,
        total_mrays_per_s: (c.camera_rays + c.secondary_rays + c.shadow_rays) as f64 / median / 1e6,
        kernel: prepared.kernel_kind(),
        method: match (s.path, traced) {
            (false, true) => "trace",
            (false, false) => "march",
            (true, true) => "path+trace",
            (true, false) => "path+march",
        },
        program_len: prepared.program_len(),
        ops_per_eval,
        evaluations,
        fp32_peak_tflops: peak.map(|p| p / 1e12),
        fp32_fraction: peak
            .filter(|_| !guarded)
            .and_then(|p| fp32::fraction(ops_per_eval, evaluations, median, p)),
        stats: last.stats,
        devices: shares
            .iter()
            .map(|s| format!("{}: {} bands, {}", s.device, s.tiles, s.phases))
            .collect(),
    })
}

fn header() -> String {
    format!(
        "{:<28} {:>7} {:>10} {:>9} {:>4} {:>7} {:>10} {:>10} {:>8} {:>8} {:>9} {:>6} {:>6}",
        "scene",
        "backend",
        "method",
        "size",
        "aa",
        "threads",
        "median ms",
        "min ms",
        "host ms",
        "Mrays/s",
        "steps/px",
        "p99",
        "max"
    )
}

fn row(t: &Timing) -> String {
    let name = std::path::Path::new(&t.ran.scene)
        .file_name()
        .map(|n| n.to_string_lossy().into_owned());
    format!(
        "{:<28} {:>7} {:>10} {:>9} {:>4} {:>7} {:>10.2} {:>10.2} {:>8.2} {:>8.2} {:>9.1} {:>6} {:>6}",
        name.unwrap_or_else(|| t.ran.scene.clone()),
        t.ran.backend,
        t.method,
        format!("{}x{}", t.ran.width, t.ran.height),
        t.aa,
        t.threads,
        t.median_s * 1e3,
        t.min_s * 1e3,
        t.median_frame_s * 1e3,
        t.mrays_per_s,
        t.stats.steps_mean,
        t.stats.steps_p99,
        t.stats.steps_max
    )
}
