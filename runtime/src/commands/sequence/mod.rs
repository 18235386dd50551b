//! `sdfc render --frames`: an animated scene rendered as a sequence of frames
//! (docs/animation.md): numbered images written atomically and skipped when they exist (so
//! a killed job resumes), one shard of a job array, an animated PNG, or a video through
//! `ffmpeg`. The kernel is prepared again only when a frame's distance program differs from
//! the previous frame's; camera, lights, materials and settings are read at every render.
//! Where the frames go is `sink.rs`'s.

use crate::backend::{Backend, Device, Devices, Setup};
use crate::frontend::Source;
use crate::gpu::launch::{Faults, Queue};
use crate::image::{Picture, PngLevel};
use crate::job::{self, Error, FrameScene, Job, Kernels};
use crate::output::{Submit, Task, Writers, Written};
use crate::sequence::{Frames, Shard, Target};
use crate::tally::Tally;
use indicatif::ProgressBar;
use sdfc_compiler::{Animation, LowerOptions};
use sdfc_compiler::{Limit, Limits};
use std::path::{Path, PathBuf};
use std::time::Instant;

mod sink;
use sink::Sink;

/// The arguments of `sdfc render` that a sequence alone reads.
#[derive(Debug, clap::Args)]
pub struct SequenceArgs {
    /// Render the frames A up to B − 1 of the animation (docs/animation.md), at the times
    /// k / fps; without it, an output pattern with `#` renders the frames the scene's
    /// `render { fps, duration }` states.
    #[arg(long, value_name = "A..B", value_parser = crate::sequence::Frames::parse)]
    pub frames: Option<Frames>,
    /// Frames per second of the sequence (overrides `render { fps }`).
    #[arg(long, value_name = "F")]
    pub fps: Option<f64>,
    /// Render only the frames whose number is ≡ I (mod N): shard I of N of a job array
    /// (`--shard $SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT`).
    #[arg(long, value_name = "I/N", value_parser = crate::sequence::Shard::parse)]
    pub shard: Option<crate::sequence::Shard>,
    /// Render frames whose files exist already (by default they are skipped, so that a
    /// killed job resumes where it stopped).
    #[arg(long)]
    pub force: bool,
}

/// Renders the sequence of the scene `file` that `args` ask for, `job` being its job, to
/// `output` (default: numbered PNG files named after the scene), PNG files compressed at
/// `png_level`; with `stats` (`--stats`), where the time went ([`Tally`]).
pub fn run(
    file: &Path,
    output: Option<&Path>,
    png_level: PngLevel,
    args: &SequenceArgs,
    job: &Job,
    stats: bool,
) -> Result<(), Error> {
    let limits = &job.limits;
    let mut source = Source::read_within(file, limits)?;
    // The animation's settings are the same at every time (E0406): read them at t = 0.
    let lowering = LowerOptions::parametric();
    let first = job.frame(&mut source, 0.0, true, &lowering)?;
    let animation = first.scene.animation;
    let animated = animation.animated();
    let fps = fps(args, &animation)?;
    let frames = frame_range(args, &animation, limits)?;
    let shard = args.shard.unwrap_or_default();
    let path = output.map_or_else(|| default_pattern(file), Path::to_path_buf);
    let target = target(&path, shard, frames)?;
    let mut sink = Sink::open(&target, frames, fps)?;
    let (backend, _) = job.mode()?;
    job.check_kernel(backend)?;
    let pool = job.pool()?;
    let setup = Setup {
        parameters: true,
        image_only: true,
        // 8-bit frames take the pixels the GPU finished; OpenEXR the linear colours.
        finished: !matches!(&target, Target::Numbered(_, format) if format.linear()),
        ..job.setup()
    };
    let (mine, todo) = todo(args, shard.frames(frames), &sink);
    let skipped = mine - todo.len();
    announce(animated, (frames, fps, shard), todo.len(), skipped);
    let bar = progress(mine as u64, skipped as u64);
    let mut first = Some(first);
    let tally = Tally::default();
    let mut checker = Checker {
        job,
        source: std::sync::Mutex::new(&mut source),
        lowering: &lowering,
        fps,
        bar: bar.as_ref(),
        tally: &tally,
        place: "main thread",
    };
    let started = Instant::now();
    let writers = writers(&sink, &first, png_level);
    let workers = workers(job, backend, animated)?;
    let out = (&mut checker, &mut sink, writers.as_ref());
    let (count, device) = match workers {
        Some(list) => {
            let frames = FramesOn {
                pool: &pool,
                devices: list.len(),
                backend,
                setup,
                limits,
                tally: &tally,
            };
            frames.render(&list, &todo, &mut first, out)?
        }
        None => {
            let frames = FramesHere {
                pool: &pool,
                kernels: (backend, job.devices.clone()),
                setup,
                limits,
                tally: &tally,
                animated,
            };
            frames.render(&todo, &mut first, out)?
        }
    };
    checker.finish(writers, sink)?;
    let seconds = started.elapsed().as_secs_f64();
    if stats {
        eprintln!(
            "where the sequence's time went (each step's sum over the frames, how many, the mean in ms; the writers' steps summed over their {} threads):\n{}",
            Writers::cores(),
            tally.report()
        );
    }
    summary(todo.len(), &path, seconds, (count, device));
    Ok(())
}

/// The frames per second: `--fps` (from 0.01 to 1000), or the scene's.
fn fps(args: &SequenceArgs, animation: &Animation) -> Result<f64, Error> {
    match args.fps {
        Some(f) if f.is_finite() && (0.01..=1000.0).contains(&f) => Ok(f),
        Some(f) => Err(Error::Usage(format!(
            "--fps must be a number from 0.01 to 1000, not {f}"
        ))),
        None => Ok(animation.fps),
    }
}

/// Where the frames go (numbered files for a shard), the directory of numbered files made.
fn target(path: &Path, shard: Shard, frames: Frames) -> Result<Target, Error> {
    let target = Target::new(path)?;
    if shard.count > 1 && !matches!(target, Target::Numbered(..)) {
        return Err(Error::Usage(
            "--shard renders part of a sequence: its frames must go to numbered files (`-o out/frame_####.png`), not one animated PNG or video".into(),
        ));
    }
    if let Target::Numbered(pattern, _) = &target {
        create_directory(&pattern.path(frames.start))?;
    }
    Ok(target)
}

/// How many frames the shard has (`mine`), and those to render (all with `--force`).
fn todo(args: &SequenceArgs, mine: impl Iterator<Item = u64>, sink: &Sink) -> (usize, Vec<u64>) {
    let mine: Vec<u64> = mine.collect();
    let todo = mine.iter().filter(|&&k| args.force || !sink.exists(k));
    (mine.len(), todo.copied().collect())
}

/// Says which frames the sequence renders: `n` of them, `skipped` already written.
fn announce(animated: bool, (frames, fps, shard): (Frames, f64, Shard), n: usize, skipped: usize) {
    if !animated {
        eprintln!("note: the scene does not read `t`: every frame is the same");
    }
    eprintln!(
        "render: frames {}..{} at {fps} fps{}: {} to render, {skipped} already written",
        frames.start,
        frames.end,
        if shard.count > 1 {
            format!(", shard {}/{}", shard.index, shard.count)
        } else {
            String::new()
        },
        n
    );
}

/// The threads that write numbered files while the next frames render (at most a gigabyte
/// of frames waits for them).
fn writers(sink: &Sink, first: &Option<FrameScene>, png_level: PngLevel) -> Option<Writers> {
    match sink {
        Sink::Numbered(..) => {
            let threads = Writers::cores();
            let s = &first.as_ref().expect("the first frame").scene.settings;
            let frame = (12 * s.width as u64 * s.height as u64).max(1);
            let depth = (2 * threads as u64).min((1 << 30) / frame).max(1);
            Some(Writers::new(threads, depth as usize, png_level))
        }
        _ => None,
    }
}

/// The devices that take whole frames from one queue: several, for a scene that reads `t`.
fn workers(job: &Job, backend: Backend, animated: bool) -> Result<Option<Vec<Device>>, Error> {
    let resolved = job.devices.resolve(backend);
    let list = resolved.map_err(|e| Error::unavailable(backend, e.into()))?;
    Ok(list.filter(|list| list.len() > 1 && animated))
}

/// The last line: `written` frames to `path` in `seconds`, `count` kernels on `device`.
fn summary(written: usize, path: &Path, seconds: f64, (count, device): (usize, Option<String>)) {
    eprintln!(
        "wrote {} frame{} to {} in {seconds:.3} s ({:.2} frames/s); {} kernel{} prepared{}",
        written,
        if written == 1 { "" } else { "s" },
        path.display(),
        written as f64 / seconds.max(1e-9),
        count,
        if count == 1 { "" } else { "s" },
        match device {
            Some(d) => format!(" ({d})"),
            None => String::new(),
        }
    );
}

/// The tally's name of the device that renders the frames of [`FramesHere`].
const HERE: &str = "device";

/// The frames of a sequence on one device (or on devices splitting each frame), checked on
/// a thread of their own a frame or two ahead; a scene that does not read `t` rendered once.
struct FramesHere<'a> {
    pool: &'a rayon::ThreadPool,
    kernels: (Backend, Devices),
    setup: Setup,
    limits: &'a Limits,
    tally: &'a Tally,
    animated: bool,
}

impl FramesHere<'_> {
    /// Renders `todo`; returns the kernels prepared and the device, for the log.
    fn render(
        &self,
        todo: &[u64],
        first: &mut Option<FrameScene>,
        (checker, sink, writers): (&mut Checker, &mut Sink, Option<&Writers>),
    ) -> Result<(usize, Option<String>), Error> {
        let mut kernels = Kernels::new(self.pool, self.kernels.clone(), self.setup);
        // The picture of a scene that does not read `t`, rendered once.
        let mut still: Option<Picture> = None;
        checker.place = "checking thread";
        let checker = &*checker;
        std::thread::scope(|scope| -> Result<(), Error> {
            let (tx, checked) = std::sync::mpsc::sync_channel(2);
            scope.spawn(move || {
                for &k in todo {
                    let frame = checker.frame(k, first);
                    let failed = frame.is_err();
                    // The receiver is gone after an error of its own.
                    if tx.send((k, frame)).is_err() || failed {
                        return;
                    }
                }
            });
            for (n, (k, frame)) in checked.iter().enumerate() {
                let frame = frame?;
                let started = Instant::now();
                let picture = match &still {
                    Some(picture) => picture.clone(),
                    None => {
                        let picture = self.picture(&mut kernels, (n, k), (frame, started))?;
                        if !self.animated {
                            still = Some(picture.clone());
                        }
                        picture
                    }
                };
                self.deliver((k, picture, started), (checker, &mut *sink, writers))?;
            }
            Ok(())
        })?;
        let device = kernels
            .last()
            .map(|p| format!("{} on {}", p.name(), p.device()));
        Ok((kernels.count, device))
    }

    /// Frame `k`, the `n`th here, prepared (its memory checked), rendered and its warnings said.
    fn picture(
        &self,
        kernels: &mut Kernels,
        (n, k): (usize, u64),
        (frame, started): (FrameScene, Instant),
    ) -> Result<Picture, Error> {
        let (scene, prepared) = kernels.prepare(frame)?;
        let memory = job::Use::IMAGE;
        job::check_memory(self.pool, prepared, &scene, memory, self.limits, n == 0)?;
        self.tally.since(HERE, preparing(n == 0), started);
        let rendered = Instant::now();
        let mut frame = self.pool.install(|| prepared.render(&scene, &|_| {}))?;
        match &frame.phases {
            Some(p) => self.tally.phases(HERE, p),
            None => self.tally.since(HERE, "render", rendered),
        }
        for w in frame.warnings() {
            eprintln!("warning: frame {k}: {w}");
        }
        Ok(frame.take_picture())
    }

    /// Frame `k`'s picture handed to the writers (numbered files) or written to the sink.
    fn deliver(
        &self,
        (k, picture, started): (u64, Picture, Instant),
        (checker, sink, writers): (&Checker, &mut Sink, Option<&Writers>),
    ) -> Result<(), Error> {
        match (writers, &*sink) {
            (Some(w), Sink::Numbered(pattern, format)) => {
                let task = Task::file(k, pattern.path(k), *format, picture, started);
                let handing = Instant::now();
                w.submit(task).map_err(|e| Error::Encode(e.to_string()))?;
                self.tally.since(HERE, "handing to the writers", handing);
                for done in w.written() {
                    report(done, checker, sink)?;
                }
            }
            _ => {
                let writing = Instant::now();
                sink.write(k, &picture)?;
                // Its buffer takes the next frame's pixels.
                if let Picture::Finished(f) = picture {
                    f.recycle();
                }
                self.tally.since(HERE, "writing", writing);
                checker.written(k, sink, started.elapsed().as_secs_f64());
            }
        }
        Ok(())
    }
}

/// Checks the frames of a sequence one after the other (the source is read once and checked
/// at each time), and logs those written; shared by the thread that checks and the one that
/// logs.
struct Checker<'a> {
    job: &'a Job,
    source: std::sync::Mutex<&'a mut Source>,
    lowering: &'a LowerOptions,
    fps: f64,
    bar: Option<&'a ProgressBar>,
    /// Where the time went.
    tally: &'a Tally,
    /// The tally's name of the thread that checks.
    place: &'static str,
}

impl Checker<'_> {
    /// Frame `k` checked at its time (`first`, the frame checked at t = 0, when it is that).
    fn frame(&self, k: u64, first: &mut Option<FrameScene>) -> Result<FrameScene, Error> {
        let time = Animation::time_of(self.fps, k);
        if let Some(f) = first.take().filter(|_| time == 0.0) {
            return Ok(f);
        }
        let started = Instant::now();
        let mut source = self.source.lock().unwrap_or_else(|e| e.into_inner());
        let frame = self.job.frame(&mut source, time, false, self.lowering);
        drop(source);
        self.tally.since(self.place, "check", started);
        frame.map_err(|e| {
            if let Some(b) = self.bar {
                b.abandon();
            }
            if let Error::Scene(_) = e {
                eprintln!("error: frame {k} (t = {time} s) has errors");
            }
            e
        })
    }

    /// The frames the writers still hold written and logged, the bar cleared, the sink finished.
    fn finish(&self, writers: Option<Writers>, sink: Sink) -> Result<(), Error> {
        if let Some(w) = writers {
            for done in w.finish() {
                report(done, self, &sink)?;
            }
        }
        if let Some(b) = self.bar {
            b.finish_and_clear();
        }
        sink.finish()
    }

    /// Frame `k` was written in `seconds`.
    fn written(&self, k: u64, sink: &Sink, seconds: f64) {
        let time = Animation::time_of(self.fps, k);
        match self.bar {
            Some(b) => b.inc(1),
            None => eprintln!(
                "frame {k} (t = {time:.4} s): {} ({seconds:.3} s)",
                sink.describe(k)
            ),
        }
    }
}

/// The tally's name of a frame's preparation: the first opens the device and prepares the
/// kernel (a CUDA context takes about a second on a host of four GPUs), the others only give
/// it the frame's numbers.
fn preparing(first: bool) -> &'static str {
    match first {
        true => "opening and first preparation",
        false => "prepare",
    }
}

/// Logs a frame the writers' pool wrote, or gives its error.
fn report(done: Written, checker: &Checker, sink: &Sink) -> Result<(), Error> {
    done.result.map_err(|e| Error::Io(e.to_string()))?;
    for (step, time, _) in &done.steps {
        checker.tally.add("writers", step, *time);
    }
    checker.written(done.k, sink, done.seconds);
    Ok(())
}

/// A frame checked and waiting for a device.
struct Pending {
    k: u64,
    frame: FrameScene,
}

/// What a device's worker reports.
enum Report {
    /// Frame `k` rendered in `seconds`; its picture, unless the worker handed it to the
    /// writers' pool (numbered files, written side by side and logged as the pool writes
    /// them; an animated PNG or a video takes the frames in order).
    Frame {
        k: u64,
        picture: Option<Picture>,
        seconds: f64,
    },
    /// The frame could not be handed to the writers.
    Unwritten(String),
    /// The device failed on a frame, which it handed back.
    Failed { position: usize, message: String },
    /// The worker ended after preparing `kernels` kernels on `device`.
    Ended { kernels: usize, device: String },
}

/// The frames of a sequence on several devices: each device's worker takes the next checked
/// frame from one queue (prepared on its device as [`Kernels`] prepares frames); frames are
/// written in order as they come.
struct FramesOn<'a> {
    pool: &'a rayon::ThreadPool,
    /// How many devices render frames side by side.
    devices: usize,
    backend: crate::backend::Backend,
    setup: Setup,
    limits: &'a Limits,
    /// Where the time went.
    tally: &'a Tally,
}

impl FramesOn<'_> {
    /// Renders `todo` on `devices`; returns the kernels prepared and the devices, for the
    /// log.
    fn render(
        &self,
        devices: &[crate::backend::Device],
        todo: &[u64],
        first: &mut Option<FrameScene>,
        (checker, sink, writers): (&mut Checker, &mut Sink, Option<&Writers>),
    ) -> Result<(usize, Option<String>), Error> {
        let queue = Queue::new(std::iter::empty(), true);
        let numbered = match (&*sink, writers) {
            (Sink::Numbered(pattern, format), Some(w)) => {
                Some((w.submitter(), pattern.clone(), *format))
            }
            _ => None,
        };
        let (tx, rx) = std::sync::mpsc::channel();
        // Frames checked ahead of the devices: enough to keep each busy.
        let ahead = 2 * devices.len();
        std::thread::scope(|scope| {
            for (position, &device) in devices.iter().enumerate() {
                let (queue, tx, numbered) = (&queue, tx.clone(), numbered.clone());
                scope.spawn(move || {
                    let run = std::panic::AssertUnwindSafe(|| {
                        self.work((position, device), queue, numbered, tx)
                    });
                    // A worker that panicked holds a frame no one will render.
                    if std::panic::catch_unwind(run).is_err() {
                        queue.abandon();
                    }
                });
            }
            drop(tx);
            let mut ready = std::collections::BTreeMap::new();
            let mut next = 0;
            let mut alive = devices.len();
            let (mut kernels, mut names) = (0, Vec::new());
            let mut failures = Vec::new();
            // Handles one report: frames are written in order, as soon as they can be.
            let mut handle = |event: Report,
                              sink: &mut Sink,
                              checker: &Checker|
             -> Result<(), Error> {
                match event {
                    Report::Frame {
                        k,
                        picture,
                        seconds,
                    } => {
                        ready.insert(k, (picture, seconds));
                    }
                    Report::Unwritten(message) => return Err(Error::Io(message)),
                    Report::Failed { position, message } => {
                        alive -= 1;
                        eprintln!(
                            "warning: device {position} failed: {message}; {}",
                            if alive > 0 {
                                "the other devices render its frame"
                            } else {
                                "no device is left"
                            }
                        );
                        failures.push((position, message));
                    }
                    Report::Ended { kernels: n, device } => {
                        kernels += n;
                        names.push(device);
                    }
                }
                while let Some((picture, seconds)) = todo.get(next).and_then(|k| ready.remove(k)) {
                    if let Some(picture) = picture {
                        sink.write(todo[next], &picture)?;
                        checker.written(todo[next], sink, seconds);
                    }
                    next += 1;
                }
                for done in writers.map(|w| w.written()).unwrap_or_default() {
                    report(done, checker, sink)?;
                }
                if alive == 0 && next < todo.len() {
                    return Err(Error::DevicesFailed {
                        written: next,
                        frames: todo.len(),
                        failures: std::mem::take(&mut failures),
                    });
                }
                Ok(())
            };
            let result = (|| -> Result<(), Error> {
                for &k in todo {
                    let frame = checker.frame(k, first)?;
                    let waiting = Instant::now();
                    while queue.waiting() >= ahead {
                        match rx.recv_timeout(std::time::Duration::from_millis(20)) {
                            Ok(r) => handle(r, sink, checker)?,
                            Err(_) => continue,
                        }
                    }
                    checker
                        .tally
                        .since("main thread", "waiting for a device", waiting);
                    queue.push(Pending { k, frame });
                    while let Ok(r) = rx.try_recv() {
                        handle(r, sink, checker)?;
                    }
                }
                queue.close();
                // Every worker ends once the queue is empty (or it failed).
                while let Ok(r) = rx.recv() {
                    handle(r, sink, checker)?;
                }
                Ok(())
            })();
            // On an error, the workers finish no more frames.
            queue.abandon();
            result?;
            if next < todo.len() {
                return Err(Error::Unrendered {
                    rendered: next,
                    frames: todo.len(),
                });
            }
            names.sort();
            names.dedup();
            Ok((
                kernels,
                Some(format!("{} devices: {}", devices.len(), names.join(", "))),
            ))
        })
    }

    /// One device's worker: takes frames until none is left, or until the device fails (its
    /// frame then goes back to the queue). `SDFC_FAULT_AFTER_TILES` counts the device's tiles
    /// over every frame it rendered.
    fn work(
        &self,
        (position, device): (usize, crate::backend::Device),
        queue: &Queue<Pending>,
        numbered: Option<(Submit, crate::sequence::Pattern, crate::output::Format)>,
        tx: std::sync::mpsc::Sender<Report>,
    ) {
        let list = crate::backend::Devices::List(vec![device]);
        let mut kernels = Kernels::new(self.pool, (self.backend, list), self.setup);
        let faults = Faults::from_env();
        let mut tiles = 0;
        let here = format!("device {position}");
        let tally = self.tally;
        let mut idle = Instant::now();
        // The device is opened (and its kernel prepared) on a copy of the next frame before
        // it takes one: frames go only to devices that are open, so a device slow to open
        // holds back none of them (the others render them all if it opens last).
        let next = queue.first(|p| p.frame.clone());
        tally.since(&here, "waiting for a frame", idle);
        if let Some(frame) = next {
            let opening = Instant::now();
            if let Err(e) = kernels.prepare(frame) {
                let message = match e {
                    Error::Scene(_) => "the frame has errors".into(),
                    e => e.to_string(),
                };
                let _ = tx.send(Report::Failed { position, message });
                return;
            }
            tally.since(&here, preparing(true), opening);
            idle = Instant::now();
        }
        // Whether the memory a frame takes was checked (at the first frame taken).
        let mut checked = false;
        while let Some(Pending { k, frame }) = queue.take() {
            tally.since(&here, "waiting for a frame", idle);
            let kept = frame.clone();
            let started = Instant::now();
            let first = !checked;
            let rendered = (|| {
                let (scene, prepared) = kernels.prepare(frame)?;
                if first {
                    // Every device holds a frame at once: what one allocates, times the
                    // devices (announced once).
                    let one = self
                        .pool
                        .install(|| crate::memory::render(prepared, &scene, false, false));
                    let n = self.devices as u64;
                    let all = crate::memory::Memory {
                        host: one.host.saturating_mul(n),
                        device: one.device.saturating_mul(n),
                    };
                    if position == 0 {
                        let on = format!("{n} devices");
                        eprintln!("{}", crate::memory::announce(&scene.settings, &on, &all));
                    }
                    all.check(self.limits).map_err(Error::Memory)?;
                }
                let s = &scene.settings;
                let n = crate::gpu::launch::tiling(s.width, s.height, crate::gpu::TILE, 1).len();
                if let Some(message) = faults.injected_within(position, tiles..tiles + n) {
                    return Err(Error::Injected(message));
                }
                tiles += n;
                tally.since(&here, preparing(false), started);
                let rendered = Instant::now();
                self.pool
                    .install(|| prepared.render_faults(&scene, &|_| {}, &Faults::default()))
                    .map(|mut f| {
                        match &f.phases {
                            Some(p) => tally.phases(&here, p),
                            None => tally.since(&here, "render", rendered),
                        }
                        f.take_picture()
                    })
                    .map_err(Error::from)
            })();
            match rendered {
                Ok(picture) => {
                    checked = true;
                    let picture = match &numbered {
                        Some((writers, pattern, format)) => {
                            let task = Task::file(k, pattern.path(k), *format, picture, started);
                            let handing = Instant::now();
                            if let Err(e) = writers.submit(task) {
                                let _ = tx.send(Report::Unwritten(e.to_string()));
                            }
                            tally.since(&here, "handing to the writers", handing);
                            None
                        }
                        None => Some(picture),
                    };
                    let seconds = started.elapsed().as_secs_f64();
                    let _ = tx.send(Report::Frame {
                        k,
                        picture,
                        seconds,
                    });
                    queue.done();
                    idle = Instant::now();
                }
                Err(e) => {
                    queue.hand_back(Pending { k, frame: kept });
                    let message = match e {
                        Error::Scene(_) => "the frame has errors".into(),
                        e => e.to_string(),
                    };
                    let _ = tx.send(Report::Failed { position, message });
                    return;
                }
            }
        }
        let device = kernels
            .last()
            .map_or_else(String::new, |p| format!("{} on {}", p.name(), p.device()));
        let _ = tx.send(Report::Ended {
            kernels: kernels.count,
            device,
        });
    }
}

/// The frames to render: `--frames`, or the scene's `fps × duration`, within the `frames`
/// limit.
fn frame_range(
    args: &SequenceArgs,
    animation: &Animation,
    limits: &Limits,
) -> Result<Frames, Error> {
    let frames = match args.frames {
        Some(f) => f,
        None => {
            let n = animation.frames();
            if n == 0 {
                return Err(Error::Usage(
                    "the scene states no animation (its `render` block has no `duration`): give the frames with --frames A..B, or add `duration: SECONDS` to `render`".into(),
                ));
            }
            Frames { start: 0, end: n }
        }
    };
    let max = limits.get(Limit::Frames);
    if frames.len() > max {
        return Err(Error::Usage(format!(
            "the sequence has {} frames, more than {max}; {}",
            frames.len(),
            limits.raise_to(Limit::Frames, frames.len())
        )));
    }
    Ok(frames)
}

/// `scene.sdf` → `./scene_####.png`.
fn default_pattern(file: &Path) -> PathBuf {
    PathBuf::from(format!("{}_####.png", super::stem_or(file, "frame")))
}

/// Creates the directory of `file` when it is missing.
fn create_directory(file: &Path) -> Result<(), Error> {
    match file.parent() {
        Some(dir) if !dir.as_os_str().is_empty() && !dir.is_dir() => std::fs::create_dir_all(dir)
            .map_err(|e| Error::Io(format!("cannot create `{}`: {e}", dir.display()))),
        _ => Ok(()),
    }
}

/// A progress bar over the shard's frames on a terminal (frames already written count as
/// done); `None` elsewhere, where each frame prints a line.
fn progress(len: u64, done: u64) -> Option<ProgressBar> {
    let template = "{bar:40} {pos}/{len} frames {elapsed_precise} eta {eta} ({per_sec})";
    let bar = super::progress_bar(len, template);
    if let Some(bar) = &bar {
        bar.set_position(done);
    }
    bar
}
