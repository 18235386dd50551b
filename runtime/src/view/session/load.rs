//! The viewer session's loads: the scene file read (again when it changed under the read),
//! checked, lowered, prepared and held to the memory limit through the job's path (the first
//! on the window's device, a later one as the last one was), its specialised pipeline compiled
//! on another thread while the interpreted kernel (prepared the same way) shows it, and the
//! load installed.

use super::*;
use crate::backend::{Backend, Devices};
use crate::job::{self, FrameScene};
use sdfc_compiler::{Limits, Settings};

impl Session {
    /// Loads the scene file again (or for the first time): on success the new scene replaces
    /// the old one, and the camera stays where the user moved it; on failure the diagnostics
    /// are printed as `sdfc check` prints them and the last good scene stays.
    pub fn load(&mut self) -> Outcome {
        self.load_edited(None)
    }

    /// [`Session::load`] after an edit seen at `edited` (the first file event of the batch
    /// that called for the reload): `--timings`' edit to pixel counts from the later of that
    /// and the newest modification time of the scene's files. A file renamed back, or copied
    /// with its time kept, has an old modification time; the event is when it changed.
    pub fn load_edited(&mut self, edited: Option<SystemTime>) -> Outcome {
        self.load_because(edited, None)
    }

    /// [`Session::load_edited`], for `cause` when it is not an edit of the files (the panel's
    /// change of a parameter, made at `edited`).
    pub(super) fn load_because(
        &mut self,
        edited: Option<SystemTime>,
        cause: Option<String>,
    ) -> Outcome {
        let number = self.loads;
        self.loads += 1;
        let started = Instant::now();
        let began = SystemTime::now();
        let modified = Fingerprint::modified(&self.files);
        match self.compile() {
            Ok((good, mut timings)) => {
                timings.number = number;
                timings.modified = match cause {
                    Some(_) => edited,
                    None => edit_time(Fingerprint::modified(&self.files).or(modified), edited),
                };
                timings.cause = cause;
                timings.began = began;
                self.install(good);
                self.keep_taken_values();
                self.timings = Some(timings);
                self.failed = false;
                self.status = None;
                Outcome {
                    number,
                    ok: true,
                    summary: "ok".into(),
                }
            }
            Err(summary) => {
                self.failed = true;
                self.status = Some(summary.clone());
                let kept = if self.good.is_some() {
                    "the last good scene stays on show"
                } else {
                    "nothing to show yet"
                };
                eprintln!(
                    "view: load {number} of `{}` failed after {:.1} ms; {kept}",
                    self.file.display(),
                    ms(started.elapsed())
                );
                Outcome {
                    number,
                    ok: false,
                    summary,
                }
            }
        }
    }

    /// Reads, checks, lowers and prepares the scene, printing what `sdfc check` prints;
    /// `Err` is the one-line summary of the first problem.
    fn compile(&mut self) -> Result<(Good, Timings), String> {
        let job = self.job();
        let start = Instant::now();
        let mut loaded = self.read(&job.limits).map_err(|e| {
            let msg = e.to_string();
            eprintln!("error: {msg}");
            msg
        })?;
        let scene = job.scene(&mut loaded, true).map_err(summary)?;
        let check_time = start.elapsed();
        let start = Instant::now();
        let lowered = job
            .lower(&scene, &loaded.sources, &lower_options(&scene))
            .map_err(summary)?;
        let lower_time = start.elapsed();
        eprintln!(
            "{}: ok; {}; {}",
            self.file.display(),
            frontend::summary(&loaded, &scene),
            frontend::method(&loaded, &scene, &lowered.traceable)
        );
        let start = Instant::now();
        let (ready, grade, interim_lowered) =
            self.prepare(&job, scene, lowered).map_err(summary)?;
        let prepare_time = start.elapsed();
        let job::Ready {
            scene,
            prepared,
            built,
        } = ready;
        // Its frames are the view's size, whatever the scene's settings say.
        job::check_memory_here(&prepared, &scene, self.shown(), &job.limits, false)
            .map_err(summary)?;
        let pipeline = self
            .pipeline(&prepared, &scene, interim_lowered)
            .map_err(|e| e.to_string())
            .inspect_err(|msg| eprintln!("error: {msg}"))?;
        let background = pipeline.waiting.is_some();
        let good = Good {
            file_camera: scene.camera.clone(),
            method: method(&prepared, &scene),
            aa: samples_wanted(&scene.settings),
            scene,
            grade,
            prepared,
            load: self.loads - 1,
            waiting: pipeline.waiting,
        };
        let timings = Timings {
            number: 0,
            cause: None,
            check: check_time,
            lower: lower_time,
            prepare: prepare_time,
            built,
            pipeline: pipeline.ready,
            background,
            interim: pipeline.interim_possible,
            first_kernel: None,
            interim_prepare: pipeline.interim_prepare,
            interim_pipeline: None,
            ready: None,
            modified: None,
            began: SystemTime::now(),
            first_frame: None,
            printed: false,
        };
        Ok((good, timings))
    }

    /// Reads and checks the scene file (once it is not empty, or has stayed empty for
    /// [`EMPTY_PATIENCE`]), again while its files change under the read, and notes the files
    /// read and their fingerprint; `Err` when the file cannot be read.
    fn read(&mut self, limits: &Limits) -> Result<frontend::Loaded, frontend::ReadError> {
        let start = Instant::now();
        let empty = || std::fs::metadata(&self.file).is_ok_and(|m| m.len() == 0);
        while empty() && start.elapsed() < EMPTY_PATIENCE {
            std::thread::sleep(Duration::from_millis(5));
        }
        let mut loaded = match frontend::load_with(&self.file, limits) {
            Ok(l) => l,
            Err(e) => {
                self.files = vec![self.file.clone()];
                self.fingerprint = Fingerprint::of(&self.files);
                return Err(e);
            }
        };
        // Files that changed while they were read (an editor saving in place truncates, then
        // writes) are read again: a load stands on contents still there after it was read.
        for _ in 0..STABLE_READS {
            self.note_read(&loaded);
            if !self.fingerprint.changed() {
                break;
            }
            match frontend::load_with(&self.file, limits) {
                Ok(again) => loaded = again,
                Err(_) => break,
            }
        }
        Ok(loaded)
    }

    /// Notes the files `loaded` read and the fingerprint of their contents as it read them.
    fn note_read(&mut self, loaded: &frontend::Loaded) {
        // The scene's files and the others it read (meshes, fonts), as the load read them.
        let sources = files_of(&loaded.sources)
            .into_iter()
            .zip(0..)
            .map(|(f, i)| (f, loaded.sources.text(FileId(i)).as_bytes()));
        let data = loaded
            .data
            .iter()
            .map(|(name, bytes)| (PathBuf::from(name), bytes.as_slice()));
        let read: Vec<(PathBuf, &[u8])> = sources.chain(data).collect();
        self.files = read.iter().map(|(f, _)| f.clone()).collect();
        self.fingerprint = Fingerprint::from_sources(read.into_iter());
    }

    /// Prepares the checked and lowered scene through the job's path, its grade taken out;
    /// with the lowering kept for the interpreted kernel where it may show the scene while
    /// the specialised one compiles.
    fn prepare(
        &self,
        job: &Job,
        mut scene: Scene,
        lowered: Lowered,
    ) -> Result<(job::Ready, Grade, Option<Lowered>), Error> {
        // The GPU kernel reads the distance program's constants from `scene_data`, so an edit
        // of numbers only keeps the kernel (and its pipeline) and uploads the new numbers.
        // The kernel kept is the specialised one unless `--kernel interpreted`; with `auto`
        // the interpreted kernel shows the scene while the specialised one compiles, once the
        // grace period has passed without it.
        let kernel = match self.options.kernel {
            Kernel::Interpreted => wgsl::KernelChoice::Interpreted,
            Kernel::Auto | Kernel::Specialised => wgsl::KernelChoice::Specialised,
        };
        let setup = Setup {
            parameters: true,
            kernel,
            ..job.setup()
        };
        let interim_lowered = match (&self.device, self.options.kernel) {
            (Device::Wgpu(gpu), Kernel::Auto) if !gpu.is_cpu() || self.options.interim_on_cpu => {
                Some(lowered.clone())
            }
            _ => None,
        };
        // Through the job's path: the first scene on the window's device (or the CPU), a
        // later one as the last one was, on its device, the last one staying on show until
        // this one is ready.
        let open = match (&self.good, &self.device) {
            (Some(good), _) => job::Open::After(&good.prepared),
            (None, Device::Cpu) => job::Open::Backend,
            (None, Device::Wgpu(gpu)) => job::Open::Gpu(gpu.clone()),
        };
        // The frames render linear light, which adds up as samples do; the exposure and tone
        // curve are applied to their mean, as `sdfc render` grades the mean of its samples.
        let grade = Grade::take(&mut scene.settings);
        let frame = FrameScene {
            scene,
            lowered,
            phases: Vec::new(),
        };
        let ready = job::prepare_here((self.backend(), &Devices::Auto), frame, &setup, open)?;
        Ok((ready, grade, interim_lowered))
    }

    /// The pipeline of `prepared`'s kernel: had at once where it was compiled before;
    /// otherwise compiling on another thread (the driver may take seconds; lavapipe tens of
    /// them), never on the caller's: a window's event loop goes on answering meanwhile. With
    /// `--kernel auto` the interpreted kernel (of `interim_lowered`) shows the scene from the
    /// end of the grace period where it can; otherwise the image before stays on show until
    /// the pipeline is ready. Nothing on the CPU.
    fn pipeline(
        &self,
        prepared: &Prepared,
        scene: &Scene,
        interim_lowered: Option<Lowered>,
    ) -> Result<PipelineState, crate::gpu::wgpu::Error> {
        let mut pipeline = PipelineState {
            ready: None,
            waiting: None,
            interim_prepare: Duration::ZERO,
            interim_possible: false,
        };
        let Some(crate::backend::WgpuPrepared { gpu, kernel, .. }) = prepared.as_wgpu() else {
            return Ok(pipeline);
        };
        let data = kernel.data.is_some();
        if gpu.has_pipeline(&kernel.source, wgsl::ENTRY_POINT, data) {
            pipeline.ready =
                Some(gpu.pipeline_for(&kernel.source, None, wgsl::ENTRY_POINT, data)?);
            return Ok(pipeline);
        }
        let start = Instant::now();
        let interim = match interim_lowered {
            Some(lowered) => self.interim(gpu, scene, lowered),
            None => None,
        };
        pipeline.interim_prepare = start.elapsed();
        pipeline.interim_possible = interim.is_some();
        let grace = match interim {
            Some(_) => self.options.grace,
            None => Duration::ZERO,
        };
        let first = self.first_frame(prepared, scene);
        pipeline.waiting =
            Compile::start(prepared, first, self.compile_waker()).map(|compile| Waiting {
                load: self.loads - 1,
                grace_until: compile.started + grace,
                compile,
                interim,
                shown: false,
            });
        Ok(pipeline)
    }

    /// The interpreted kernel of `scene`, lowered as `lowered`, to show it while its specialised
    /// kernel compiles, prepared through the job's path: `None` where it cannot render the
    /// scene (an analytically traced one, a program above the `registers` limit) or its frames
    /// would be above the `memory` limit at the view's size. Its pipeline is compiled once per
    /// specialisation; until then it compiles on another thread too.
    fn interim(&self, gpu: &Arc<Gpu>, scene: &Scene, lowered: Lowered) -> Option<Interim> {
        let job = &self.job();
        let setup = Setup {
            parameters: true,
            kernel: wgsl::KernelChoice::Interpreted,
            ..job.setup()
        };
        // The last interpreted kernel, whose validated kernel serves again where its text is
        // the same (and its pipeline, compiled, with it).
        let held = self
            .good
            .as_ref()
            .and_then(|g| g.waiting.as_ref())
            .and_then(|w| w.interim.as_ref())
            .map(|i| &i.prepared)
            .or(self.interpreter.as_ref());
        let open = match held {
            Some(p) => job::Open::After(p),
            None => job::Open::Gpu(gpu.clone()),
        };
        let frame = FrameScene {
            scene: scene.clone(),
            lowered,
            phases: Vec::new(),
        };
        let on = (Backend::Wgpu, &Devices::Auto);
        let prepared = job::prepare_here(on, frame, &setup, open).ok()?.prepared;
        job::check_memory_here(&prepared, scene, self.shown(), &job.limits, false).ok()?;
        let kernel = &prepared.as_wgpu()?.kernel;
        let data = kernel.data.is_some();
        let (compile, pipeline) = if gpu.has_pipeline(&kernel.source, wgsl::ENTRY_POINT, data) {
            let time = gpu.pipeline_for(&kernel.source, None, wgsl::ENTRY_POINT, data);
            (None, Some(time.ok()?))
        } else {
            let first = self.first_frame(&prepared, scene);
            (
                Some(Compile::start(&prepared, first, self.compile_waker())?),
                None,
            )
        };
        Some(Interim {
            prepared,
            compile,
            pipeline,
        })
    }

    /// What the first frame of a newly loaded `scene` will give `prepared`'s kernel to read,
    /// as [`Session::frame`] sets it up: the camera on show (the user's, else the scene's),
    /// the size of a new scene's first frame, and the first sample's offset.
    fn first_frame(&self, prepared: &Prepared, scene: &Scene) -> Option<FirstFrame> {
        let crate::backend::WgpuPrepared {
            kernel, lipschitz, ..
        } = prepared.as_wgpu()?;
        let moving = self.moving() || self.playing();
        let scale = if moving {
            self.scale
        } else {
            self.preview_scale()
        };
        let low = scale > 1 || moving;
        let (w, h) = (self.size.0.div_ceil(scale), self.size.1.div_ceil(scale));
        let base = match &self.user_camera {
            Some(orbit) => orbit.camera(),
            None => scene.camera.clone(),
        };
        let n = scene.settings.aa.max(1);
        // A path-traced frame jitters within the pixel itself.
        let (dx, dy) = if low || scene.settings.path {
            (0.0, 0.0)
        } else {
            camera::sample_offset(0, n)
        };
        let mut first = scene.clone();
        first.camera = camera::jittered(&base, dx, dy, w, h);
        let s = &mut first.settings;
        (s.width, s.height, s.aa) = (w, h, 1);
        (s.samples, s.first_sample) = (1, 0);
        FirstFrame::of((kernel, *lipschitz), &first)
    }

    /// Takes the results of the compiles on other threads that have ended: a ready interpreted
    /// pipeline shows the scene from the next frame; a ready specialised one replaces the
    /// interpreted kernel from the next frame (the camera and the animation's time stay).
    pub(super) fn poll(&mut self) {
        let timings = self.options.timings;
        let held = self
            .good
            .as_ref()
            .and_then(|g| g.waiting.as_ref())
            .is_some_and(|w| self.held(w.load));
        let Some(good) = self.good.as_mut() else {
            return;
        };
        let Some(w) = good.waiting.as_mut() else {
            return;
        };
        if let Some(i) = w.interim.as_mut() {
            match i.compile.as_ref().and_then(Compile::take) {
                Some(Ok(time)) => {
                    i.compile = None;
                    i.pipeline = Some(time);
                }
                Some(Err(msg)) => {
                    eprintln!("error: the interpreted kernel: {msg}");
                    w.interim = None;
                }
                None => {}
            }
        }
        if held {
            return;
        }
        let Some(result) = w.compile.take() else {
            return;
        };
        let load = good.load;
        let Some(w) = good.waiting.take() else {
            return;
        };
        match result {
            Ok(time) => {
                if let Some(t) = self.timings.as_mut().filter(|t| t.first_frame.is_none()) {
                    // Ready before the interpreted kernel showed anything (within the grace
                    // period, or after it but before the interpreted kernel was ready): the
                    // load's line says so.
                    t.pipeline = Some(time);
                    t.ready = Some((w.compile.started.elapsed(), w.in_grace()));
                } else if timings {
                    eprintln!(
                        "view: load {load}: specialised kernel ready {:.1} ms after the load (pipeline {} {:.1} ms on another thread); interpreted while compiling until then",
                        ms(w.compile.started.elapsed()),
                        if time.cached { "found" } else { "compiled" },
                        ms(time.time),
                    );
                }
                // A render error of the interpreted kernel does not stop the specialised one.
                self.broken = None;
                if let Some(i) = w.interim {
                    self.interpreter = Some(i.prepared);
                }
                if w.shown {
                    // The image starts again from the specialised kernel's samples; the one on
                    // show stays until its first frame replaces it.
                    self.accumulation = Accumulation::default();
                }
            }
            Err(msg) => {
                eprintln!("error: {msg}");
                match w.interim {
                    Some(i) => {
                        eprintln!("view: load {load}: the interpreted kernel stays on show");
                        good.prepared = i.prepared;
                        // No grace period: there is no other kernel to wait for.
                        good.waiting = i.compile.map(|compile| Waiting {
                            load,
                            grace_until: compile.started,
                            compile,
                            interim: None,
                            shown: false,
                        });
                    }
                    None => self.broken = Some(msg.to_string()),
                }
            }
        }
    }

    /// The backend the session prepares its scenes for: its device's.
    pub(super) fn backend(&self) -> Backend {
        match self.device {
            Device::Cpu => Backend::Cpu,
            Device::Wgpu(_) => Backend::Wgpu,
        }
    }

    /// How the session's frames use memory: shown at the view's size, a sample each.
    pub(super) fn shown(&self) -> job::Use {
        job::Use::Shown {
            width: self.size.0,
            height: self.size.1,
        }
    }

    fn install(&mut self, good: Good) {
        self.version += 1;
        self.playback = self.playback_of(&good.scene);
        self.good = Some(good);
        self.broken = None;
        self.preview = true;
        self.accumulation = Accumulation::default();
    }
}

/// A loaded kernel's pipeline: had at once, or compiling on another thread (and whether the
/// interpreted kernel could show the scene meanwhile, and the time to prepare it).
struct PipelineState {
    ready: Option<PipelineTime>,
    waiting: Option<Waiting>,
    interim_prepare: Duration,
    interim_possible: bool,
}

/// How `scene` is rendered through `prepared`, for the title: `trace`, `march`, or
/// `path (traced)` or `path (marched)`.
fn method(prepared: &Prepared, scene: &Scene) -> &'static str {
    let traced = prepared.traceable().traced(scene.settings.method).is_some();
    match (scene.settings.path, traced) {
        (false, true) => "trace",
        (false, false) => "march",
        (true, true) => "path (traced)",
        (true, false) => "path (marched)",
    }
}

/// Samples per pixel of a converged image: the scene's `aa`, squared; a path-traced picture
/// converges at its `samples`, one a frame.
fn samples_wanted(settings: &Settings) -> u32 {
    if settings.path {
        settings.samples.max(1)
    } else {
        let n = settings.aa.max(1);
        n * n
    }
}
