//! A render job and the one path from it to frames. [`Job`] is what `sdfc render` (a still or
//! `--frames`), `bench`, `pareto`, `view` and the Python module ask to have rendered, built
//! from their arguments: the settings overridden, the backend and its devices, the float type,
//! the GPU kernel, the worker threads and the limits. From it a scene's source is checked at a
//! time, its settings applied and it is lowered ([`Job::frame`]), prepared on its backend
//! ([`prepare`] on a device it opens or is given, [`Open`], or frame after frame by
//! [`Kernels`]), held to the memory limit for its use ([`check_memory`], [`Use`]) and
//! rendered ([`Prepared::render`]). What fails on the way is an
//! [`Error`] saying which step.

mod prepare;

pub use prepare::{
    check_memory, check_memory_here, prepare, prepare_here, Kernels, Open, Ready, Use,
};

use crate::backend::{self, Backend, Devices, Kernel, Setup};
use crate::cpu::reference;
use crate::cpu::Precision;
use crate::frontend::{self, DiagnosticFormat, Loaded, Source};
use crate::memory;
use sdfc_compiler::{
    lower_within, Diagnostic, Limit, Limits, LowerOptions, Lowered, Scene, Settings, Severity,
    SourceMap,
};
use std::process::ExitCode;
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
    /// Every device of a sequence failed before its frames were all written: how many were
    /// written of how many, and each device's position and why it failed.
    #[error(
        "every device failed ({written} of {frames} frames written): {}",
        failures_in_words(.failures)
    )]
    DevicesFailed {
        written: usize,
        frames: usize,
        failures: Vec<(usize, String)>,
    },
    /// A sequence ended with `frames - rendered` of its frames not rendered.
    #[error("{} of {frames} frames were not rendered", .frames - .rendered)]
    Unrendered { rendered: usize, frames: usize },
    /// A fault injected by `SDFC_FAULT_AFTER_TILES` into a frame of a sequence: its message.
    #[error("{0}")]
    Injected(String),
    /// A sweep of `sdfc pareto` rendered no frame.
    #[error("no frame rendered")]
    NoFrame,
    /// The reference and a render compared with it differ in size.
    #[error("the reference and the render differ in size")]
    SizeDiffers,
    /// An encoder the frames are handed to (`ffmpeg`) failed.
    #[error("{0}")]
    Encode(String),
}

/// Each device's failure, as `device P: why`, joined by `; `.
fn failures_in_words(failures: &[(usize, String)]) -> String {
    let words: Vec<String> = failures
        .iter()
        .map(|(position, why)| format!("device {position}: {why}"))
        .collect();
    words.join("; ")
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
    /// A job on `backend`, the settings overridden as `overrides`, within `limits`; the rest
    /// as by default (`--devices auto`, f32, no `--kernel`, one worker thread per core).
    pub fn new(backend: Backend, overrides: Overrides, limits: Limits) -> Job {
        Job {
            backend,
            overrides,
            limits,
            ..Job::default()
        }
    }

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

#[cfg(test)]
mod tests;
