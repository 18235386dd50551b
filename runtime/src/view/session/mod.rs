//! The viewer's session, apart from any window: it loads and checks the scene file, prepares it
//! for the CPU renderer or wgpu, keeps the last good scene when an edit has errors, holds the
//! camera the user moved, and renders frames progressively (one sample per pixel, and fewer
//! pixels when a frame exceeds its budget, while the camera moves; jittered samples
//! accumulated up to the scene's `aa` when it is still), and plays an animated scene's time `t`
//! (each frame's scene checked at its time, its kernel kept while only numbers change). On wgpu,
//! a scene whose specialised kernel is not compiled yet waits a short grace period ([`GRACE`])
//! for it to compile on another thread ([`super::compile`]), and is shown through the
//! interpreted kernel from then until it is ready. A load is `load.rs`'s, a frame `frame.rs`'s,
//! the camera's moves `navigate.rs`'s, an animation's time `playback.rs`'s; the tests are
//! `tests.rs`.

use super::camera::{self, Orbit};
use super::compile::{Compile, Waker};
use super::grade::Grade;
use super::resident::{FirstFrame, Resident};
use super::watch::Fingerprint;
use crate::backend::{Kernel, Prepared, Setup};
use crate::frontend::{self};
use crate::gpu::wgpu::PipelineTime;
use crate::gpu::Gpu;
use crate::image::Image;
use crate::job::{Error, Job};
use sdfc_compiler::{wgsl, Animation, Camera, LowerOptions, Lowered, Scene};
use sdfc_compiler::{FileId, SourceMap};
use std::path::{Path, PathBuf};
use std::sync::{mpsc, Arc};
use std::time::{Duration, Instant, SystemTime};
use timings::Timings;

mod frame;
mod load;
mod navigate;
mod params;
mod playback;
mod timings;

pub use frame::FrameError;

/// The time a frame may take while the camera moves; a slower one lowers the resolution.
pub const FRAME_BUDGET: Duration = Duration::from_millis(33);

/// How long after the last camera motion the camera counts as still (and samples accumulate).
pub const SETTLE: Duration = Duration::from_millis(120);

/// How many times a load reads files that keep changing under it before it goes on with
/// what it read.
const STABLE_READS: usize = 4;

/// How long a load waits for an empty scene file to be written: an editor saving in place
/// truncates the file, then writes it, and a busy machine can run the load in between. No
/// one saves a scene empty on purpose; one that stays empty this long is loaded (and reported
/// as it is).
const EMPTY_PATIENCE: Duration = Duration::from_millis(500);

/// The largest divisor of the resolution while moving.
pub const MAX_SCALE: u32 = 8;

/// How long a load whose specialised pipeline compiles on another thread (`--kernel auto` on a
/// GPU) waits for it before showing the scene through the interpreted kernel. A driver that
/// compiles a kernel in a few milliseconds then shows the specialised kernel's frame at once,
/// with no slower interpreted frame before it; a compile that takes longer is hidden as
/// before, its interpreted frame shown this much later (measured): 50 ms
/// is a few frames at 60 Hz, short beside a slow compile's seconds and well above a fast
/// one's few milliseconds. The window's event loop is never held: it is woken at the end of the period
/// ([`Session::grace_deadline`]).
pub const GRACE: Duration = Duration::from_millis(50);

/// How the session treats the scene, from the command line.
#[derive(Debug, Clone)]
pub struct Options {
    /// The job: its backend, `--size` (overriding the scene's; the window's size replaces it
    /// when the window is resized), the `--set key=value` overrides of render settings,
    /// applied at every load, and the resource limits.
    pub job: Job,
    /// `--timings`: print the times of each load and of its first frame.
    pub timings: bool,
    /// `--time`: an animated scene starts paused at this time (seconds) instead of playing.
    pub time: Option<f64>,
    /// `--kernel`: on wgpu, the specialised kernel, shown through the interpreted one while it
    /// compiles on a GPU when it is not ready within the grace period (`auto`); the
    /// specialised kernel alone, each new one compiled before it is shown (`specialised`); or
    /// the interpreted kernel alone (`interpreted`).
    pub kernel: Kernel,
    /// With `auto`, show the interpreted kernel while the specialised one compiles on a CPU
    /// adapter (lavapipe) too. `sdfc view` leaves it off: there the interpreted kernel's
    /// frames took 25 to 150 times the specialised kernel's (docs/interpreted.md), longer
    /// than the compile they would hide; the tests, which have no other adapter, set it.
    pub interim_on_cpu: bool,
    /// With `auto`, how long a load waits for its specialised pipeline before showing the
    /// interpreted kernel ([`GRACE`]; the tests set their own).
    pub grace: Duration,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            job: Job::default(),
            timings: false,
            time: None,
            kernel: Kernel::default(),
            interim_on_cpu: false,
            grace: GRACE,
        }
    }
}

/// The playing of an animated scene's time `t`: the frame on show is the scene checked at the
/// start of the animation frame (`k / fps`) the clock is in, looping over `duration` when the
/// scene states one.
#[derive(Debug)]
struct Playback {
    /// The scene's files as the load that started (or last renewed) the playback read them.
    source: frontend::Source,
    animation: Animation,
    /// When the clock read 0, while playing.
    origin: Instant,
    /// The clock while paused.
    paused: Option<f64>,
    /// The animation frame on show.
    shown: Option<u64>,
}

/// Where frames are rendered.
#[derive(Debug, Clone)]
pub enum Device {
    /// The CPU renderer.
    Cpu,
    /// The WGSL kernel through wgpu, on this device.
    Wgpu(Arc<Gpu>),
}

impl Device {
    /// The backend's name, as in `--backend`.
    pub fn name(&self) -> &'static str {
        match self {
            Device::Cpu => "cpu",
            Device::Wgpu(_) => "wgpu",
        }
    }

    /// The device, for messages.
    pub fn describe(&self) -> String {
        match self {
            Device::Cpu => format!("CPU, {} threads", rayon::current_num_threads()),
            Device::Wgpu(gpu) => gpu.describe(),
        }
    }
}

/// The scene being shown: the last load that compiled.
#[derive(Debug)]
struct Good {
    /// The scene; its camera and size are set for each frame. It is ungraded: its frames are
    /// linear light, accumulated as such, and `grade` is applied to their mean.
    scene: Scene,
    /// The scene's exposure and tone curve, taken out of `scene` ([`Grade::take`]).
    grade: Grade,
    prepared: Prepared,
    /// The camera the file gives.
    file_camera: Camera,
    /// Samples per pixel of a converged image (the scene's `aa`, squared, or its path
    /// tracer's `samples`).
    aa: u32,
    /// `trace`, `march`, or `path (traced)` or `path (marched)`.
    method: &'static str,
    /// The load it came from.
    load: u32,
    /// While the pipeline of `prepared` compiles on another thread: that compile, and the
    /// interpreted kernel shown meanwhile (after the grace period).
    waiting: Option<Waiting>,
}

/// The compile of a scene's specialised pipeline, and the interpreted kernel that shows the
/// scene until it is ready (when that kernel can render the scene). It belongs to its scene
/// ([`Good`]): a newer load replaces both, and a stale compile's result is never seen.
#[derive(Debug)]
struct Waiting {
    /// The load whose kernel compiles.
    load: u32,
    compile: Compile,
    interim: Option<Interim>,
    /// Whether a frame of the interpreted kernel was rendered.
    shown: bool,
    /// The end of the grace period: until then nothing is rendered, the specialised kernel
    /// being awaited (the image of the scene before stays on show).
    grace_until: Instant,
}

/// The interpreted kernel of a scene whose specialised pipeline compiles.
#[derive(Debug)]
struct Interim {
    prepared: Prepared,
    /// Its own pipeline's compile, while it runs (once per specialisation of the kernel).
    compile: Option<Compile>,
    /// How its pipeline was had, once it was.
    pipeline: Option<PipelineTime>,
}

impl Good {
    /// The kernel frames are rendered with now: the specialised one, or while it compiles
    /// the interpreted one once its pipeline is ready and the grace period is over; `None`
    /// while neither is.
    fn kernel(&self) -> Option<&Prepared> {
        match &self.waiting {
            None => Some(&self.prepared),
            Some(w) if w.in_grace() => None,
            Some(w) => w
                .interim
                .as_ref()
                .filter(|i| i.compile.is_none())
                .map(|i| &i.prepared),
        }
    }
}

impl Waiting {
    /// Whether the grace period runs: the specialised kernel is awaited before the interpreted
    /// one is shown.
    fn in_grace(&self) -> bool {
        Instant::now() < self.grace_until
    }

    /// Whether a compile has ended whose result is still to be taken (the specialised one's
    /// unless `held`).
    fn finished(&self, held: bool) -> bool {
        (!held && self.compile.finished())
            || self
                .interim
                .as_ref()
                .and_then(|i| i.compile.as_ref())
                .is_some_and(Compile::finished)
    }
}

/// The result of one load of the scene file.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// 0 for the first load, then 1, 2, … for each reload.
    pub number: u32,
    /// Whether the scene compiled and replaced the one shown.
    pub ok: bool,
    /// One line: `ok` or the first error.
    pub summary: String,
}

/// One rendered frame.
#[derive(Debug, Clone, Copy)]
pub struct FrameInfo {
    /// Its size (smaller than the view while moving, when frames are over budget).
    pub width: u32,
    pub height: u32,
    /// Samples per pixel accumulated so far, and the target (the scene's `aa`, squared).
    pub samples: u32,
    pub target: u32,
    /// Render time of this frame (wall time, read-back included).
    pub time: Duration,
    /// Mean marching steps per pixel of this frame (NaN on wgpu unless they were asked for:
    /// [`Session::want_steps`]).
    pub steps: f64,
    /// Whether the camera was moving.
    pub moving: bool,
    /// The GPU kernel that rendered it, `specialised` or `interpreted` (`None` on the CPU).
    pub kernel: Option<&'static str>,
}

/// Samples accumulated at one size.
#[derive(Debug, Default)]
struct Accumulation {
    width: u32,
    height: u32,
    /// Their sums, on the CPU (on wgpu they stay on the device: [`Resident`]).
    sum: Vec<[f32; 3]>,
    count: u32,
    /// Whether the samples are of a still camera at full size.
    still: bool,
}

/// The viewer's state between frames.
#[derive(Debug)]
pub struct Session {
    file: PathBuf,
    options: Options,
    device: Device,
    good: Option<Good>,
    /// The files the last load read (the entry file and its imports).
    files: Vec<PathBuf>,
    /// Their contents as that load saw them.
    fingerprint: Fingerprint,
    /// Loads so far.
    loads: u32,
    /// Whether the last load failed.
    failed: bool,
    /// The summary of the last failure, while it stands.
    status: Option<String>,
    /// The camera the user moved to; `None` follows the file's camera.
    user_camera: Option<Orbit>,
    /// The view's size.
    size: (u32, u32),
    /// Moving until then.
    moving_until: Option<Instant>,
    /// The divisor of the resolution while moving.
    scale: u32,
    /// Whether the next frame is the first of a newly loaded scene, rendered at a lower
    /// resolution when full frames take longer than the budget.
    preview: bool,
    /// The time of the last full-resolution frame.
    last_full: Option<Duration>,
    accumulation: Accumulation,
    /// The image on show: the mean of the accumulated samples (on the CPU; on wgpu it stays
    /// on the device, in `resident`).
    shown: Option<Image>,
    /// On wgpu, the frames on the device: the accumulated samples and the texture on show.
    resident: Option<Resident>,
    /// Counts the scenes installed (loads and animation frames), so that a kernel's scene
    /// data is uploaded to the device once per scene.
    version: u64,
    /// Whether each frame's mean steps per pixel are wanted (the statistics in the title): on
    /// wgpu they are then read back from the device.
    steps_wanted: bool,
    /// The last frame.
    last: Option<FrameInfo>,
    /// A render error that stops rendering until the next load or camera move.
    broken: Option<String>,
    timings: Option<Timings>,
    /// The animated scene's time, played or paused; `None` for a still.
    playback: Option<Playback>,
    /// Told by each compile on another thread when it ends ([`Session::wait_for_compile`]).
    compiled: (mpsc::Sender<()>, mpsc::Receiver<()>),
    /// Also called when such a compile ends (the window's event loop).
    waker: Option<Waker>,
    /// The last interpreted kernel shown, kept after the specialised kernel replaced it: a
    /// later scene of the same specialisation reuses its validated kernel
    /// ([`Prepared::next_with`]).
    interpreter: Option<Prepared>,
    /// The values the panel gave parameters (name, value as text), offered to every load
    /// ([`sdfc_compiler::Limits::offer_param`]): kept while the scene accepts them.
    panel: Vec<(String, String)>,
    /// Tests hold back the compile of this load's specialised kernel, to see what is shown
    /// meanwhile.
    #[cfg(test)]
    held: Option<u32>,
}

impl Session {
    /// A session on `file`, rendering on `device`; nothing is loaded until [`Session::load`].
    pub fn new(file: PathBuf, options: Options, device: Device) -> Session {
        let size = options.job.overrides.size.unwrap_or((640, 480));
        Session {
            files: vec![file.clone()],
            file,
            options,
            device,
            good: None,
            fingerprint: Fingerprint::default(),
            loads: 0,
            failed: false,
            status: None,
            user_camera: None,
            size,
            moving_until: None,
            scale: 1,
            preview: false,
            last_full: None,
            accumulation: Accumulation::default(),
            shown: None,
            resident: None,
            version: 0,
            steps_wanted: false,
            last: None,
            broken: None,
            timings: None,
            playback: None,
            compiled: mpsc::channel(),
            waker: None,
            interpreter: None,
            panel: Vec::new(),
            #[cfg(test)]
            held: None,
        }
    }

    /// Whether the compile of load `load`'s specialised kernel is held back (by a test).
    #[cfg(test)]
    fn held(&self, load: u32) -> bool {
        self.held == Some(load)
    }

    #[cfg(not(test))]
    fn held(&self, _: u32) -> bool {
        false
    }

    /// Calls `waker` (on another thread) whenever a pipeline compiling on another thread is
    /// ready or has failed, as well as making [`Session::wants_frame`] true.
    pub fn set_waker(&mut self, waker: Waker) {
        self.waker = Some(waker);
    }

    /// What a compile on another thread calls when it ends.
    fn compile_waker(&self) -> Waker {
        let tx = self.compiled.0.clone();
        let also = self.waker.clone();
        Waker::new(move || {
            let _ = tx.send(());
            if let Some(w) = &also {
                w.wake();
            }
        })
    }

    /// Waits, at most `timeout` and not past the end of the grace period, for a pipeline
    /// compiling on another thread, when there is no frame to render until it ends or the
    /// grace period does; returns at once otherwise.
    pub fn wait_for_compile(&self, timeout: Duration) {
        if self.compiling() && !self.wants_frame() {
            let timeout = match self.grace_deadline() {
                Some(end) => timeout.min(end.saturating_duration_since(Instant::now())),
                None => timeout,
            };
            let _ = self.compiled.1.recv_timeout(timeout);
        }
    }

    /// While the scene on show waits its grace period for its specialised kernel: when the
    /// period ends, and a frame of the interpreted kernel may be due (a window's event loop
    /// wakes then). `None` when there is no such period, or it is over.
    pub fn grace_deadline(&self) -> Option<Instant> {
        let w = self.good.as_ref()?.waiting.as_ref()?;
        w.in_grace().then_some(w.grace_until)
    }

    /// Whether the scene on show waits for its specialised kernel's pipeline, compiling on
    /// another thread (its frames are the interpreted kernel's, or none yet: in the grace
    /// period, or while the interpreted kernel's pipeline compiles too).
    pub fn compiling(&self) -> bool {
        self.good.as_ref().is_some_and(|g| g.waiting.is_some())
    }

    /// The device frames are rendered on.
    pub fn device(&self) -> &Device {
        &self.device
    }

    /// The files the last load read: the scene file and every file it imports.
    pub fn files(&self) -> &[PathBuf] {
        &self.files
    }

    /// Whether a batch of file events (`paths`, the files they name) calls for a reload: the
    /// contents of a file the last load read changed (or it appeared or disappeared), or the
    /// last load failed and a scene file (`.sdf`) it did not read changed, perhaps a missing
    /// import.
    pub fn needs_reload(&self, paths: &[PathBuf]) -> bool {
        let read: Vec<PathBuf> = self.files.iter().map(|f| absolute(f)).collect();
        self.fingerprint.changed()
            || (self.failed
                && paths.iter().any(|p| {
                    p.extension().is_some_and(|e| e == "sdf") && !read.contains(&absolute(p))
                }))
    }

    /// The window title: the file, the problem with the last load if it failed, a render
    /// error, and with `stats` the backend, method, frame time, steps per pixel and samples.
    pub fn title(&self, stats: bool) -> String {
        let mut title = format!("sdfc view: {}", self.file.display());
        if let Some(t) = self.time() {
            let state = if self.playing() { "playing" } else { "paused" };
            title.push_str(&format!(" | t = {t:.2} s, {state}"));
        }
        if let Some(status) = &self.status {
            title.push_str(&format!(" | {status}"));
        }
        if let Some(msg) = &self.broken {
            title.push_str(&format!(" | render error: {msg}"));
        }
        // A path-traced picture says how far it has converged: it accumulates while the
        // camera rests and starts again at any change.
        if let (Some(good), Some(f)) = (&self.good, &self.last) {
            if good.scene.settings.path && !stats {
                title.push_str(&format!(" | {}/{} samples", f.samples, f.target));
            }
        }
        match self.good.as_ref().and_then(|g| g.waiting.as_ref()) {
            Some(w) if !w.in_grace() && w.interim.as_ref().is_some_and(|i| i.compile.is_none()) => {
                title.push_str(" | interpreted while compiling")
            }
            // In the grace period, and after it until a kernel is ready.
            Some(_) => title.push_str(" | compiling the kernel"),
            None => {}
        }
        if let (true, Some(good), Some(f)) = (stats, &self.good, &self.last) {
            let kernel = f
                .kernel
                .map(|k| format!(" {k} kernel,"))
                .unwrap_or_default();
            title.push_str(&format!(
                " | {} ({}),{kernel} {}, {}x{}, {}/{} samples, {:.1} ms, {:.1} steps/px",
                self.device.name(),
                self.device.describe(),
                good.method,
                f.width,
                f.height,
                f.samples,
                f.target,
                ms(f.time),
                f.steps
            ));
        }
        title
    }
}

/// When the edit a load follows was made: the later of the newest modification time of the
/// scene's files and the first file event of the batch that called for the load (`None`
/// when neither is known).
fn edit_time(modified: Option<SystemTime>, event: Option<SystemTime>) -> Option<SystemTime> {
    match (modified, event) {
        (Some(m), Some(e)) => Some(m.max(e)),
        (m, e) => m.or(e),
    }
}

/// The lowering of a scene: an animated one, or one with parameters, keeps the structure of
/// its program whatever its numbers (`LowerOptions::parametric`), so that its frames share one
/// kernel, as do the values a parameter's slider passes through (a translation by a length
/// that passes 0 stays in the program).
fn lower_options(scene: &Scene) -> LowerOptions {
    if scene.animation.animated() || !scene.params.is_empty() {
        LowerOptions::parametric()
    } else {
        LowerOptions::default()
    }
}

/// `path` made absolute (as the watcher reports paths), or as it is.
fn absolute(path: &Path) -> PathBuf {
    std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf())
}

/// The paths of the files of a compilation, in file order (the entry file first).
fn files_of(sources: &SourceMap) -> Vec<PathBuf> {
    (0..sources.len() as u32)
        .map(|i| PathBuf::from(sources.name(FileId(i))))
        .collect()
}

/// The one line of `e` for the window, printed first unless it is a scene's errors (whose
/// diagnostics are printed where they are found).
fn summary(e: Error) -> String {
    if !matches!(e, Error::Scene(_)) {
        eprintln!("error: {e}");
    }
    e.to_string()
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

#[cfg(test)]
mod tests;
