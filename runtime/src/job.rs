//! A render job and the one path from it to frames. [`Job`] is what `sdfc render` (a still or
//! `--frames`), `bench`, `pareto`, `view` and the Python module ask to have rendered, built
//! from their arguments: the settings overridden, the backend and its devices, the float type,
//! the GPU kernel, the worker threads and the limits. From it a scene's source is checked at a
//! time, its settings applied and it is lowered ([`Job::frame`]), prepared on its backend
//! ([`prepare`] on a device it opens or is given, [`Open`], or frame after frame by
//! [`Kernels`]), held to the memory limit for its use ([`check_memory`], [`Use`]) and
//! rendered ([`Prepared::render`]). What fails on the way is an
//! [`Error`] saying which step.

use crate::backend::{self, Backend, Devices, Kernel, Opening, Prepared, Setup};
use crate::cpu::reference;
use crate::cpu::Precision;
use crate::frontend::{self, DiagnosticFormat, Loaded, Source};
use crate::gpu::Gpu;
use crate::memory;
use sdfc_compiler::{
    lower_within, wgsl, Diagnostic, Limit, Limits, LowerOptions, Lowered, Program, Scene, Settings,
    Severity, SourceMap,
};
use std::process::ExitCode;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// What a command asks to have rendered, from its arguments.
#[derive(Debug, Clone, Default)]
pub struct Job {
    /// `--backend`.
    pub backend: Backend,
    /// `--devices`.
    pub devices: Devices,
    /// `--precision`: the CPU renderer's float type.
    pub precision: Precision,
    /// `--kernel`: the GPU kernel of a marched scene (`None`: not given, `auto`).
    pub kernel: Option<Kernel>,
    /// The settings overridden in every frame checked.
    pub overrides: Overrides,
    /// `--limit`.
    pub limits: Limits,
    /// `--threads` (default: one per core).
    pub threads: Option<usize>,
    /// `--debug-nan`.
    pub debug_nan: bool,
    /// The scene's diagnostics are not printed where they are found: they come back in
    /// [`Error::Scene`] alone (the Python module raises them; a command prints them).
    pub quiet: bool,
}

/// The settings a job overrides in every frame it checks, in this order.
#[derive(Debug, Clone, Default)]
pub struct Overrides {
    /// `--reference`: the reference render's settings first.
    pub reference: bool,
    /// `--size`.
    pub size: Option<(u32, u32)>,
    /// `--aa`.
    pub aa: Option<u32>,
    /// `--set`, in order.
    pub set: Vec<String>,
}

/// What failed on the way from a job to its frames. `Usage`, `Setting`, `Sequence`, `Sweep`,
/// `Arguments`, `Io`, `Read` and `--threads 0` end a command with exit code 2, the others
/// with 1.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Bad arguments: a setting out of its range, options that do not go together.
    #[error("{0}")]
    Usage(String),
    /// A setting (`--size`, `--aa`, `--set`) that cannot be read or is out of its range.
    #[error(transparent)]
    Setting(#[from] crate::settings::Error),
    /// A `--sweep` of `sdfc pareto` that cannot be read, or sweeps above their limits.
    #[error(transparent)]
    Sweep(#[from] crate::pareto::Error),
    /// A frame range, shard or sequence output that cannot be used.
    #[error(transparent)]
    Sequence(#[from] crate::sequence::Error),
    /// A `--kernel` or `--devices` the backend cannot take, wherever it is found.
    #[error(transparent)]
    Arguments(#[from] backend::Usage),
    /// A file that cannot be read or written.
    #[error("{0}")]
    Io(String),
    /// The scene file cannot be read.
    #[error(transparent)]
    Read(#[from] frontend::ReadError),
    /// The worker threads cannot be had.
    #[error(transparent)]
    Threads(#[from] Threads),
    /// The scene has errors (its diagnostics are printed where they are found, unless the
    /// job is [`Job::quiet`]).
    #[error("{}", .0.summary())]
    Scene(Box<SceneErrors>),
    /// The backend cannot be used: no device, or the scene could not be prepared on it.
    #[error("the {backend:?} backend is not available: {source}")]
    Unavailable {
        /// The backend asked for.
        backend: Backend,
        /// Why.
        source: backend::Error,
    },
    /// The backend failed: the scene asks for what it cannot do, a frame's kernel could not
    /// be written again, a render failed on its device. (Its usage errors are `Arguments`.)
    #[error(transparent)]
    Backend(backend::Error),
    /// What the render would allocate is above the `memory` limit.
    #[error(transparent)]
    Memory(#[from] memory::Exceeded),
    /// A render failed otherwise: every device of a sequence, or a result that cannot be
    /// used.
    #[error("{0}")]
    Render(String),
    /// An encoder the frames are handed to (`ffmpeg`) failed.
    #[error("{0}")]
    Encode(String),
}

impl From<backend::Error> for Error {
    fn from(e: backend::Error) -> Error {
        match e {
            backend::Error::Usage(u) => Error::Arguments(u),
            e => Error::Backend(e),
        }
    }
}

/// Why the worker threads of `--threads` cannot be had ([`thread_pool`]).
#[derive(Debug, thiserror::Error)]
pub enum Threads {
    /// `--threads 0`: a usage error.
    #[error("--threads must be at least 1")]
    Zero,
    /// More than the `threads` limit: a usage error, naming the range and how to raise it.
    #[error("--threads must be from 1 to {max} (the `threads` limit), not {asked}; {raise}")]
    TooMany {
        asked: usize,
        max: u64,
        raise: String,
    },
    /// The pool could not be started.
    #[error("cannot start worker threads: {0}")]
    Start(#[from] rayon::ThreadPoolBuildError),
}

/// A scene's errors: its diagnostics, and the files they point into.
#[derive(Debug)]
pub struct SceneErrors {
    /// The diagnostics, errors and warnings.
    pub diagnostics: Vec<Diagnostic>,
    /// The files of the compilation.
    pub sources: SourceMap,
}

impl SceneErrors {
    /// One line: the first error, where it is, and how many there are.
    pub fn summary(&self) -> String {
        first_error(&self.diagnostics, &self.sources)
    }
}

/// One line for `diagnostics` in `sources` (the viewer's title): the first error, where it
/// is, and how many there are.
pub fn first_error(diagnostics: &[Diagnostic], sources: &SourceMap) -> String {
    let errors: Vec<&Diagnostic> = diagnostics
        .iter()
        .filter(|d| d.severity == Severity::Error)
        .collect();
    let Some(d) = errors.first() else {
        return "error".into();
    };
    let at = d
        .labels
        .first()
        .map(|l| {
            let (line, col) = sources.line_col(l.span);
            format!(" at {}:{line}:{col}", sources.name(l.span.file))
        })
        .unwrap_or_default();
    let more = match errors.len() {
        1 => String::new(),
        n => format!(" (and {} more)", n - 1),
    };
    format!("error[{}]: {}{at}{more}", d.code, d.message)
}

impl Error {
    /// The scene's errors `diagnostics` in `sources`.
    fn scene(diagnostics: Vec<Diagnostic>, sources: &SourceMap) -> Error {
        Error::Scene(Box::new(SceneErrors {
            diagnostics,
            sources: sources.clone(),
        }))
    }

    /// `backend`'s failure to open its devices or prepare a scene on them: arguments it
    /// cannot take (`--devices` naming GPUs of the CPU backend) are a usage error, the rest say
    /// the backend is not available (`--devices all` finding no device, an index that does not
    /// open). Every caller that prepares or resolves devices reports them so.
    pub fn unavailable(backend: Backend, source: backend::Error) -> Error {
        match source {
            backend::Error::Usage(u) => Error::Arguments(u),
            source => Error::Unavailable { backend, source },
        }
    }

    /// The exit code of a command that stops on this error.
    pub fn code(&self) -> ExitCode {
        match self {
            Error::Usage(_)
            | Error::Setting(_)
            | Error::Sequence(_)
            | Error::Sweep(_)
            | Error::Arguments(_)
            | Error::Io(_)
            | Error::Read(_)
            | Error::Threads(Threads::Zero | Threads::TooMany { .. }) => ExitCode::from(2),
            _ => ExitCode::from(1),
        }
    }

    /// Prints the error (a scene's diagnostics are printed already) and gives the exit code.
    pub fn exit(self) -> ExitCode {
        if !matches!(self, Error::Scene(_)) {
            eprintln!("error: {self}");
        }
        self.code()
    }
}

/// A scene checked at one time, with its settings overridden by the job, and lowered.
#[derive(Debug, Clone)]
pub struct FrameScene {
    /// The scene, settings applied.
    pub scene: Scene,
    /// Its distance program and what else the backends read.
    pub lowered: Lowered,
    /// Where its time went (`--stats`): the check, then the lowering's phases.
    pub phases: Vec<(&'static str, Duration, String)>,
}

impl Job {
    /// The backend and float type the job renders with: `--reference` means the CPU in f64.
    pub fn mode(&self) -> Result<(Backend, Precision), Error> {
        self.devices.check(self.backend)?;
        if !self.overrides.reference {
            return Ok((self.backend, self.precision));
        }
        if self.devices != Devices::Auto {
            return Err(Error::Usage(
                "--reference renders on the CPU in f64; it cannot use --devices".into(),
            ));
        }
        match self.backend {
            Backend::Auto | Backend::Cpu => Ok((Backend::Cpu, Precision::F64)),
            b => Err(Error::Usage(format!(
                "--reference renders on the CPU in f64; it cannot use --backend {}",
                format!("{b:?}").to_lowercase()
            ))),
        }
    }

    /// `Err` for a `--kernel` given with `backend`, which has no GPU kernel.
    pub fn check_kernel(&self, backend: Backend) -> Result<(), Error> {
        Ok(Kernel::check(self.kernel, backend)?)
    }

    /// How the job's scenes are prepared: its float type (f64 for `--reference`), `--debug-nan`
    /// and `--kernel`; the command sets the rest.
    pub fn setup(&self) -> Setup {
        Setup {
            precision: self.mode().map_or(self.precision, |(_, p)| p),
            debug_nan: self.debug_nan,
            kernel: self.kernel.unwrap_or_default().choice(),
            ..Setup::default()
        }
    }

    /// A rayon pool of `--threads` workers (default: rayon's choice, one per core).
    pub fn pool(&self) -> Result<rayon::ThreadPool, Error> {
        Ok(thread_pool(self.threads, &self.limits)?)
    }

    /// Applies the job's settings to `scene`: the reference's (`--reference`), then `--size`,
    /// `--aa` and each `--set`, within the limits.
    pub fn settings(&self, scene: &mut Scene) -> Result<(), Error> {
        if self.overrides.reference {
            scene.settings = reference::settings_of(scene);
        }
        self.override_settings(&mut scene.settings)
    }

    /// Applies `--size`, `--aa` and each `--set` to `settings`, in order, within the limits.
    pub fn override_settings(&self, settings: &mut Settings) -> Result<(), Error> {
        let o = &self.overrides;
        Ok(crate::settings::override_settings(
            settings,
            o.size,
            o.aa,
            &o.set,
            &self.limits,
        )?)
    }

    /// The scene `loaded` checked to, taken out of it, with the job's settings; its
    /// diagnostics are printed first unless the job is quiet (warnings only when
    /// `warnings`).
    pub fn scene(&self, loaded: &mut Loaded, warnings: bool) -> Result<Scene, Error> {
        let mut scene = self.checked(loaded, warnings)?;
        self.settings(&mut scene)?;
        Ok(scene)
    }

    /// The scene `loaded` checked to, taken out of it as it is (a command that changes its
    /// settings before the job's, as `sdfc pareto` does, applies them with
    /// [`Job::settings`]); its diagnostics are printed first unless the job is quiet
    /// (warnings only when `warnings`).
    pub fn checked(&self, loaded: &mut Loaded, warnings: bool) -> Result<Scene, Error> {
        if !warnings {
            loaded.diagnostics.retain(|d| d.is_error());
        }
        if !self.quiet {
            frontend::report(loaded, DiagnosticFormat::Human);
        }
        loaded
            .scene
            .take()
            .ok_or_else(|| Error::scene(loaded.diagnostics.clone(), &loaded.sources))
    }

    /// `scene` (read from `sources`) lowered with `lowering` within the limits; a program
    /// above the `program` limit is a diagnostic (E0507), printed unless the job is quiet.
    pub fn lower(
        &self,
        scene: &Scene,
        sources: &SourceMap,
        lowering: &LowerOptions,
    ) -> Result<Lowered, Error> {
        lower_within(scene, lowering, &self.limits).map_err(|d| {
            if !self.quiet {
                let d = std::slice::from_ref(&d);
                frontend::print_diagnostics(d, sources, DiagnosticFormat::Human);
            }
            Error::scene(vec![d], sources)
        })
    }

    /// `source` checked at `time` (its diagnostics printed unless the job is quiet, warnings
    /// only when `warnings`),
    /// the job's settings applied, lowered with `lowering` (a sequence's frames with
    /// [`LowerOptions::parametric`]), and its method allowed.
    pub fn frame(
        &self,
        source: &mut Source,
        time: f64,
        warnings: bool,
        lowering: &LowerOptions,
    ) -> Result<FrameScene, Error> {
        let started = Instant::now();
        let mut loaded = source.check(&self.limits, time);
        let mut phases = vec![(
            "check",
            started.elapsed(),
            "parsed, imports read, checked and evaluated".to_string(),
        )];
        let scene = self.scene(&mut loaded, warnings)?;
        let lowered = self.lower(&scene, &loaded.sources, lowering)?;
        backend::method_allowed(&scene, &lowered.traceable)?;
        phases.extend(
            lowered
                .phases
                .list
                .iter()
                .map(|&(name, time, what)| (name, time, what.to_string())),
        );
        Ok(FrameScene {
            scene,
            lowered,
            phases,
        })
    }
}

/// A rayon pool of `threads` workers (default: rayon's choice, one per core), at most the
/// `threads` limit.
pub fn thread_pool(threads: Option<usize>, limits: &Limits) -> Result<rayon::ThreadPool, Threads> {
    let mut b = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        if n == 0 {
            return Err(Threads::Zero);
        }
        let max = limits.get(Limit::Threads);
        if n as u64 > max {
            return Err(Threads::TooMany {
                asked: n,
                max,
                raise: limits.raise_to(Limit::Threads, n as u64),
            });
        }
        b = b.num_threads(n);
    }
    Ok(b.build()?)
}

/// Where [`prepare`] finds the device it prepares a scene on.
#[derive(Debug)]
pub enum Open<'a> {
    /// The backend opens it, or several (`--devices`).
    Backend,
    /// Being opened on a thread of its own beside the front end (`sdfc render`; used for
    /// `--devices auto` when it opens for the backend asked, else the backend opens its own).
    Beside(Opening),
    /// The caller's wgpu device, open already: the viewer's window's (whose surface shows
    /// the frames it keeps on it), or the Python module's.
    Gpu(Arc<Gpu>),
    /// Where a scene before was prepared, as it was (its backend, device and setup), and left
    /// as it is: the viewer's later loads and the frames of its animation, whose last good
    /// scene stays on show until the new one is ready. The kernel is the one `setup` chooses,
    /// or with [`wgsl::KernelChoice::Auto`] the one before's; a GPU kernel whose text is
    /// unchanged (a program that differs in numbers only, with [`Setup::parameters`]) is kept
    /// and given the new `scene_data` ([`Prepared::next`]). The backend and devices asked are
    /// the ones before's.
    After(&'a Prepared),
}

/// A frame's scene prepared on its backend ([`prepare`]).
#[derive(Debug)]
pub struct Ready {
    /// The scene.
    pub scene: Scene,
    /// The backend prepared for it.
    pub prepared: Prepared,
    /// Whether a kernel (or the CPU's tapes) was built: `false` where [`Open::After`] kept
    /// the kernel before.
    pub built: bool,
}

/// Prepares a frame's scene for `backend` on `devices` (or on the device `open` says) within
/// `pool`.
pub fn prepare(
    pool: &rayon::ThreadPool,
    on: (Backend, &Devices),
    frame: FrameScene,
    setup: &Setup,
    open: Open,
) -> Result<Ready, Error> {
    pool.install(|| prepare_here(on, frame, setup, open))
}

/// [`prepare`] on the current thread's pool (the viewer's, rayon's global one).
pub fn prepare_here(
    (backend, devices): (Backend, &Devices),
    frame: FrameScene,
    setup: &Setup,
    open: Open,
) -> Result<Ready, Error> {
    let FrameScene { scene, lowered, .. } = frame;
    // Settings the scene cannot be rendered with are the scene's fault, not the backend's
    // (`Job::frame` checks them first; the viewer's loads come here directly).
    backend::method_allowed(&scene, &lowered.traceable)?;
    // A kernel asked for that cannot render the scene is an error, not a reason to fall back
    // to another backend.
    if backend != Backend::Cpu {
        let options = wgsl::Options {
            kernel: setup.kernel,
            ..Default::default()
        };
        wgsl::choose(&scene, &lowered, &options).map_err(backend::Error::Refused)?;
    }
    let unavailable = |source| Error::unavailable(backend, source);
    let (prepared, built) = match open {
        // The device is open and the scene before prepared on it: what fails is this scene's
        // preparation.
        Open::After(before) => match setup.kernel {
            wgsl::KernelChoice::Auto => before.next(&scene, lowered)?,
            kernel => before.next_with(&scene, lowered, kernel)?,
        },
        Open::Beside(o) if o.backend() == backend && *devices == Devices::Auto => (
            Prepared::opened(o, &scene, lowered, setup).map_err(unavailable)?,
            true,
        ),
        // An open device is available: what fails is the scene's preparation on it.
        Open::Gpu(gpu) if backend == Backend::Wgpu && *devices == Devices::Auto => {
            (Prepared::on_gpu(gpu, &scene, &lowered, setup)?, true)
        }
        _ => (
            Prepared::on_devices(backend, devices, &scene, lowered, setup).map_err(unavailable)?,
            true,
        ),
    };
    Ok(Ready {
        scene,
        prepared,
        built,
    })
}

/// What a prepared scene's frames are held to the `memory` limit for ([`check_memory`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Use {
    /// Rendered at the scene's settings and written (`sdfc render`, sequences, those of
    /// `bench --frames-per-second`, Python): the render, the finished frame held while its
    /// outputs are written, and with `reference` the reference's convergence check, with
    /// `aux` the depth sidecar ([`memory::render`]).
    Written {
        /// `--reference`.
        reference: bool,
        /// `--aux`.
        aux: bool,
    },
    /// Rendered at the scene's settings frame after frame, a finished frame held while the
    /// next renders (`sdfc bench`, which keeps its warm-up frame's statistics through the
    /// timed frames): the render and the frame held ([`memory::held`]).
    Held,
    /// Shown in a view of `width` × `height` pixels, whatever size the scene's settings
    /// state, one sample a frame (the viewer's window, which accumulates the samples where
    /// they are rendered): the frame's render alone.
    Shown {
        /// The view's width.
        width: u32,
        /// The view's height.
        height: u32,
    },
}

impl Use {
    /// An image written, without the reference's check or the depth sidecar.
    pub const IMAGE: Use = Use::Written {
        reference: false,
        aux: false,
    };
}

/// What frames of `scene` on `prepared` allocate, used as `used` says, announced (when
/// `announce`) and held to the `memory` limit, within `pool` (whose threads the CPU's
/// allocation counts).
pub fn check_memory(
    pool: &rayon::ThreadPool,
    prepared: &Prepared,
    scene: &Scene,
    used: Use,
    limits: &Limits,
    announce: bool,
) -> Result<(), Error> {
    pool.install(|| check_memory_here(prepared, scene, used, limits, announce))
}

/// [`check_memory`] on the current thread's pool (the viewer's, rayon's global one).
pub fn check_memory_here(
    prepared: &Prepared,
    scene: &Scene,
    used: Use,
    limits: &Limits,
    announce: bool,
) -> Result<(), Error> {
    let (settings, needed) = match used {
        Use::Written { reference, aux } => (
            scene.settings.clone(),
            memory::render(prepared, scene, reference, aux),
        ),
        Use::Held => (scene.settings.clone(), memory::held(prepared, scene)),
        Use::Shown { width, height } => {
            let mut at = scene.settings.clone();
            (at.width, at.height, at.aa) = (width, height, 1);
            let needed = prepared.memory(scene, &at);
            (at, needed)
        }
    };
    if announce {
        eprintln!("{}", memory::announce(&settings, prepared.name(), &needed));
    }
    Ok(needed.check(limits)?)
}

/// The backend prepared for the frames of a sequence: the device is opened once; a frame
/// whose distance program (and the origin it is written relative to) is the last one's
/// renders with the same kernel; another is prepared with [`Prepared::update`], which keeps a
/// GPU kernel whose text is unchanged (its constants are read from `scene_data`), so `count`
/// counts kernels built, not frames.
pub struct Kernels<'a> {
    pool: &'a rayon::ThreadPool,
    backend: Backend,
    devices: Devices,
    setup: Setup,
    /// The last frame's program and scene origin, and the backend prepared for them.
    prepared: Option<(Program, [f64; 3], Prepared)>,
    /// Kernels (or CPU tapes) prepared so far.
    pub count: usize,
    /// Time spent preparing them.
    pub time: Duration,
}

impl std::fmt::Debug for Kernels<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Kernels")
            .field("count", &self.count)
            .finish()
    }
}

impl<'a> Kernels<'a> {
    /// No kernel yet: the frames will render with `backend` on `devices`.
    pub fn new(
        pool: &'a rayon::ThreadPool,
        (backend, devices): (Backend, Devices),
        setup: Setup,
    ) -> Self {
        Kernels {
            pool,
            backend,
            devices,
            setup,
            prepared: None,
            count: 0,
            time: Duration::ZERO,
        }
    }

    /// The backend prepared for `frame` (the last one when its program is the same,
    /// specialised again if its settings need it), and the frame's scene.
    pub fn prepare(&mut self, frame: FrameScene) -> Result<(Scene, &Prepared), Error> {
        let started = Instant::now();
        let same = self
            .prepared
            .as_ref()
            .is_some_and(|(p, o, _)| *p == frame.lowered.program && *o == frame.scene.origin);
        let scene = match &mut self.prepared {
            Some((_, _, prepared)) if same => {
                let FrameScene { scene, .. } = frame;
                if prepared.specialise(&scene)? {
                    self.count += 1;
                }
                scene
            }
            // The device stays open; the kernel is kept when its text is the same (the
            // program differs in numbers only) and given the frame's constants.
            Some((held, origin, prepared)) => {
                let FrameScene { scene, lowered, .. } = frame;
                *held = lowered.program.clone();
                *origin = scene.origin;
                if prepared.update(&scene, lowered)? {
                    self.count += 1;
                }
                scene
            }
            None => {
                let program = frame.lowered.program.clone();
                let Ready {
                    scene, prepared, ..
                } = prepare(
                    self.pool,
                    (self.backend, &self.devices),
                    frame,
                    &self.setup,
                    Open::Backend,
                )?;
                self.count += 1;
                self.prepared = Some((program, scene.origin, prepared));
                scene
            }
        };
        self.time += started.elapsed();
        let (_, _, prepared) = self.prepared.as_ref().expect("prepared");
        Ok((scene, prepared))
    }

    /// The backend last prepared.
    pub fn last(&self) -> Option<&Prepared> {
        self.prepared.as_ref().map(|(_, _, p)| p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::Device;
    use sdfc_compiler::Limit;

    #[test]
    fn the_reference_renders_on_the_cpu_in_f64_and_refuses_gpus() {
        let reference = |backend, devices| Job {
            backend,
            devices,
            overrides: Overrides {
                reference: true,
                ..Overrides::default()
            },
            ..Job::default()
        };
        let mode = reference(Backend::Auto, Devices::Auto).mode().unwrap();
        assert_eq!(mode, (Backend::Cpu, Precision::F64));
        assert_eq!(
            reference(Backend::Auto, Devices::Auto).setup().precision,
            Precision::F64
        );
        let wgpu = reference(Backend::Wgpu, Devices::Auto).mode();
        assert!(
            matches!(&wgpu, Err(Error::Usage(m)) if m.ends_with("cannot use --backend wgpu")),
            "{wgpu:?}"
        );
        let listed = reference(Backend::Cpu, Devices::List(vec![Device::Cpu])).mode();
        assert!(
            matches!(&listed, Err(Error::Usage(m)) if m.contains("--devices")),
            "{listed:?}"
        );
        let plain = Job {
            precision: Precision::F64,
            ..Job::default()
        };
        assert_eq!(plain.mode().unwrap(), (Backend::Auto, Precision::F64));
    }

    #[test]
    fn usage_and_io_exit_with_2_and_the_rest_with_1() {
        let two = ExitCode::from(2);
        let one = ExitCode::from(1);
        assert_eq!(Error::Usage("bad".into()).code(), two);
        assert_eq!(Error::Io("cannot read".into()).code(), two);
        let exceeded = memory::Exceeded {
            needed: 9000,
            limit: 4096,
            raise: "raise it".into(),
        };
        assert_eq!(Error::Memory(exceeded).code(), one);
        assert_eq!(Error::Encode("ffmpeg".into()).code(), one);
        let failed = backend::Error::Device("no adapter".into());
        let unavailable = Error::Unavailable {
            backend: Backend::Wgpu,
            source: failed,
        };
        assert_eq!(
            unavailable.to_string(),
            "the Wgpu backend is not available: no adapter"
        );
        assert_eq!(unavailable.code(), one);
        let unsupported = Error::from(backend::Error::Unsupported("not traced".into()));
        assert_eq!(unsupported.to_string(), "not traced");
        assert_eq!(unsupported.code(), one);
    }

    #[test]
    fn bad_devices_are_usage_errors_and_devices_not_found_device_errors_for_every_caller() {
        let two = ExitCode::from(2);
        // A list the backend cannot take, however it is met: resolving it (as a sequence
        // does) or preparing on it (as a still does).
        let resolved = Devices::All.resolve(Backend::Cpu).unwrap_err();
        assert_eq!(resolved, backend::Resolve::Usage(backend::Usage::GpusOnCpu));
        let usage = Error::unavailable(Backend::Cpu, resolved.into());
        assert!(matches!(usage, Error::Arguments(_)), "{usage:?}");
        assert_eq!(usage.code(), two);
        assert_eq!(
            usage.to_string(),
            "--devices names GPUs, but --backend cpu renders on the CPU alone (give --backend auto, wgpu or cuda)"
        );
        let prepared = Error::from(backend::Error::Usage(backend::Usage::AllOnCpu));
        assert!(matches!(prepared, Error::Arguments(_)), "{prepared:?}");
        assert_eq!(prepared.code(), two);
        // `all` finding nothing: the backend is not available, exit 1.
        let none = Error::unavailable(Backend::Cuda, backend::Resolve::NoDevice("cuda").into());
        assert_eq!(none.code(), ExitCode::from(1));
        assert_eq!(
            none.to_string(),
            "the Cuda backend is not available: --devices all found no cuda device"
        );
        let bad = Devices::parse("0,gpu").unwrap_err();
        assert_eq!(
            Error::from(bad).to_string(),
            "bad --devices entry `gpu`: give auto, all, or a comma-separated list of device indices and `cpu` (`sdfc devices` lists the devices)"
        );
        let kernel = Job {
            backend: Backend::Cpu,
            kernel: Some(Kernel::Interpreted),
            ..Job::default()
        };
        let refused = kernel.check_kernel(Backend::Cpu).unwrap_err();
        assert_eq!(refused.code(), two);
        assert!(
            refused
                .to_string()
                .starts_with("--kernel interpreted chooses a GPU kernel"),
            "{refused}"
        );
        let zero = Job {
            threads: Some(0),
            ..Job::default()
        };
        let refused = zero.pool().unwrap_err();
        assert_eq!(refused.to_string(), "--threads must be at least 1");
        assert_eq!(refused.code(), two);
    }

    #[test]
    fn a_scene_file_that_cannot_be_read_is_a_usage_error_naming_it() {
        let missing = Source::read(std::path::Path::new("/nonexistent/scene.sdf")).unwrap_err();
        assert!(
            missing
                .to_string()
                .starts_with("cannot read `/nonexistent/scene.sdf`: "),
            "{missing}"
        );
        assert_eq!(Error::from(missing).code(), ExitCode::from(2));
        let path = std::env::temp_dir().join(format!("sdfc-job-{}.sdf", std::process::id()));
        std::fs::write(&path, b"scene { \xff }").unwrap();
        let bad = Source::read(&path).unwrap_err();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(
            bad.to_string(),
            format!(
                "`{}` is not valid UTF-8 (first bad byte at offset 8)",
                path.display()
            )
        );
    }

    /// A scene prepared after another ([`Open::After`], the viewer's later loads and animation
    /// frames) keeps the kernel before when `setup` says `auto`, takes the one it names
    /// otherwise, and builds none where the kernel's text is unchanged (numbers only).
    #[test]
    fn a_scene_prepared_after_another_keeps_or_changes_its_kernel_as_asked() {
        let gpu = match Gpu::open(false) {
            Ok(gpu) => Arc::new(gpu),
            Err(e) => {
                assert!(
                    std::env::var("SDFC_REQUIRE_DEVICES").as_deref() != Ok("1"),
                    "SDFC_REQUIRE_DEVICES=1 but no wgpu adapter: {e}"
                );
                eprintln!("job test SKIPPED: no wgpu adapter ({e})");
                return;
            }
        };
        let text = |r: &str| {
            format!(
                "render {{ width: 16, height: 12, method: \"march\" }}\n\
                 scene {{ plane((0, 1, 0), 0); sphere({r}).translate(0, 0.5, 0); }}\n"
            )
        };
        let frame = |r: &str| {
            let mut source = Source::from_text("after.sdf", text(r));
            let job = Job {
                quiet: true,
                ..Job::default()
            };
            job.frame(&mut source, 0.0, false, &LowerOptions::default())
                .expect("the scene")
        };
        let on = (Backend::Wgpu, &Devices::Auto);
        let interpreted = Setup {
            parameters: true,
            kernel: wgsl::KernelChoice::Interpreted,
            ..Setup::default()
        };
        let first = prepare_here(on, frame("0.5"), &interpreted, Open::Gpu(gpu)).unwrap();
        assert!(first.built);
        assert_eq!(first.prepared.kernel_kind(), Some("interpreted"));
        let auto = Setup::default();
        let kept = prepare_here(on, frame("0.6"), &auto, Open::After(&first.prepared)).unwrap();
        assert_eq!(kept.prepared.kernel_kind(), Some("interpreted"));
        assert!(
            !kept.built,
            "a program that differs in numbers only keeps its kernel"
        );
        let specialised = Setup {
            kernel: wgsl::KernelChoice::Specialised,
            ..auto
        };
        let after = Open::After(&kept.prepared);
        let other = prepare_here(on, frame("0.6"), &specialised, after).unwrap();
        assert_eq!(other.prepared.kernel_kind(), Some("specialised"));
        assert!(other.built);
        // On the device the scene before was prepared on, not another opened.
        let device = |r: &Ready| r.prepared.as_wgpu().expect("wgpu").gpu.clone();
        assert!(Arc::ptr_eq(&device(&first), &device(&other)));
    }

    /// `sdfc bench` holds its warm-up frame while the timed ones render: [`Use::Held`] counts
    /// that frame beside the render, so a limit the render alone fits refuses it.
    #[test]
    fn a_frame_held_while_the_next_renders_is_counted() {
        let mut source = Source::from_text(
            "held.sdf",
            "render { width: 640, height: 480, aa: 1, method: \"march\" }\n\
             scene { sphere(1); }\n"
                .to_string(),
        );
        let job = Job {
            backend: Backend::Cpu,
            quiet: true,
            ..Job::default()
        };
        let frame = job
            .frame(&mut source, 0.0, false, &LowerOptions::default())
            .expect("the scene");
        let on = (Backend::Cpu, &Devices::Auto);
        let ready = prepare_here(on, frame, &job.setup(), Open::Backend).expect("prepared");
        let (scene, prepared) = (&ready.scene, &ready.prepared);
        let s = &scene.settings;
        let (render, held) = (prepared.memory(scene, s), prepared.retained(s));
        assert_eq!(memory::held(prepared, scene).host, render.host + held);
        let alone = memory::mib(render.total());
        let both = memory::mib(render.total() + held);
        assert!(both > alone, "{alone} MiB, {both} MiB with the frame held");
        let mut limits = Limits::default();
        limits.set(Limit::Memory, alone).expect("a limit");
        let shown = Use::Shown {
            width: s.width,
            height: s.height,
        };
        assert!(check_memory_here(prepared, scene, shown, &limits, false).is_ok());
        match check_memory_here(prepared, scene, Use::Held, &limits, false) {
            Err(Error::Memory(e)) => assert_eq!((e.needed, e.limit), (both, alone)),
            other => panic!("held to {alone} MiB: {other:?}"),
        }
    }

    #[test]
    fn a_scene_with_errors_is_summarised_by_its_first_error() {
        let mut source = Source::from_text(
            "broken.sdf",
            "scene { sphere(undefined_a); sphere(undefined_b); }\n".into(),
        );
        let job = Job::default();
        let failed = job.frame(&mut source, 0.0, true, &LowerOptions::default());
        let Err(Error::Scene(errors)) = failed else {
            panic!("not the scene's errors: {failed:?}");
        };
        let summary = errors.summary();
        assert!(summary.starts_with("error[E"), "{summary}");
        assert!(summary.contains(" at broken.sdf:1:"), "{summary}");
        assert!(summary.ends_with(" (and 1 more)"), "{summary}");
        assert_eq!(Error::Scene(errors).code(), ExitCode::from(1));
    }

    #[test]
    fn the_jobs_settings_are_applied_in_order_within_the_limits() {
        let job = Job {
            overrides: Overrides {
                size: Some((64, 48)),
                aa: Some(2),
                set: vec!["width=32".into(), "max_steps=100".into()],
                ..Overrides::default()
            },
            ..Job::default()
        };
        let mut settings = Settings::default();
        job.override_settings(&mut settings).unwrap();
        assert_eq!(
            (
                settings.width,
                settings.height,
                settings.aa,
                settings.max_steps
            ),
            (32, 48, 2, 100)
        );
        let bad = Job {
            overrides: Overrides {
                set: vec!["max_steps".into()],
                ..Overrides::default()
            },
            ..Job::default()
        };
        let refused = bad.override_settings(&mut settings);
        assert!(
            matches!(&refused, Err(Error::Setting(e)) if e.to_string().contains("KEY=VALUE")),
            "{refused:?}"
        );
    }
}
