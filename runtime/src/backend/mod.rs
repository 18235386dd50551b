//! Backends behind one interface: a scene is prepared once for a backend (program lowered,
//! tapes or kernel generated, device opened, module loaded) and then rendered any number of
//! times; what a render allocates is known before it starts ([`Prepared::memory`]). Each
//! backend implements [`Renderer`] in a module of its own (`cpu.rs`, `wgpu.rs`, `cuda.rs`,
//! and `several.rs` for several devices at once); [`Prepared`] holds one, and the
//! preparations that choose it are `prepare.rs`'s (`opening.rs` the one that joins a device
//! opened beside the front end), the devices `--devices` asks for `devices.rs`'s. What fails is
//! an [`Error`].

mod cpu;
mod cuda;
mod devices;
mod opening;
mod prepare;
mod several;
mod wgpu;

pub use self::cpu::CpuPrepared;
pub use self::cuda::CudaPrepared;
pub use self::opening::{see_only, Opening};
pub use self::several::SeveralPrepared;
pub use self::wgpu::WgpuPrepared;
pub use devices::{Device, Devices};
pub use prepare::method_allowed;

use crate::cpu::{Precision, Render};
use crate::gpu::{self, launch::Faults};
use crate::memory::{self, Memory};
use prepare::{kernel, written};
use sdfc_compiler::{
    analytic::{self, Traceable},
    ptx, wgsl, Lowered, Scene, Settings,
};
use std::time::Duration;

/// What fails preparing a scene on a backend or rendering it there.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// `method=trace` asked of a scene that cannot be traced analytically, for this reason.
    #[error(
        "this scene cannot be ray traced analytically: {}; use method=auto or method=march",
        .0.describe()
    )]
    NotTraceable(analytic::Reason),
    /// The kernel asked for cannot render the scene (`wgsl::choose`).
    #[error(transparent)]
    Refused(#[from] wgsl::Refused),
    /// A kernel specialised for other settings than the scene's (a frame of an animation
    /// whose settings changed): the kernel's name and what differs.
    #[error("the {kernel} kernel cannot render this scene: {mismatch}; specialise it again")]
    Stale {
        kernel: &'static str,
        mismatch: wgsl::Mismatch,
    },
    /// Arguments the backend cannot take: a usage error wherever it is found.
    #[error(transparent)]
    Usage(#[from] Usage),
    /// `--devices all` found no GPU of the backend (`cuda` or `wgpu`).
    #[error("--devices all found no {0} device")]
    NoDevice(&'static str),
    /// The wgpu path failed: no adapter or device, a pipeline refused, a render's error.
    #[error(transparent)]
    Wgpu(#[from] gpu::wgpu::Error),
    /// A software adapter ended `cut` marching loops of a frame early: its picture would be
    /// wrong.
    #[error(
        "the adapter {adapter} ended {cut} marching loops before they returned: a software \
         adapter (Mesa's llvmpipe, as lavapipe) stops every loop of a shader once they have \
         run 65 535 iterations together, and this scene's distance walks need more, so the \
         picture would be wrong; render it with `--backend cpu`, or on a GPU"
    )]
    Cut { adapter: String, cut: u64 },
    /// The CUDA path failed: no driver or device, the JIT, a driver call.
    #[error(transparent)]
    Cuda(#[from] gpu::cuda::Error),
    /// The device opened beside the front end was not of the backend (`CUDA` or `wgpu`)
    /// that the scene asks for.
    #[error("no {0} device was opened")]
    NotOpened(&'static str),
    /// The kernel could not be written (naga rejected the WGSL: a compiler bug).
    #[error(transparent)]
    Write(#[from] wgsl::Error),
    /// The thread opening the device beside the front end panicked.
    #[error("the thread opening the device panicked")]
    OpeningPanicked,
    /// The kernel could not be translated to PTX.
    #[error(transparent)]
    Ptx(#[from] ptx::Error),
    /// Several devices asked to hold several devices (a bug of sdfc's).
    #[error("several devices cannot hold several devices")]
    Nested,
    /// Every device of several failed a frame.
    #[error(transparent)]
    Several(#[from] gpu::SeveralFailed),
    /// A CUDA preparation's or several devices' `next` (a bug of sdfc's): they are prepared
    /// again with `Prepared::update`.
    #[error("CUDA kernels and several devices are prepared again with Prepared::update")]
    NotNext,
}

/// A `--kernel` or `--devices` that cannot be read or that the backend cannot take: a usage
/// error (a command stops with exit code 2).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Usage {
    /// `--kernel` given with the CPU backend, which has no GPU kernel.
    #[error(
        "--kernel {} chooses a GPU kernel, and the CPU backend has none (it interprets every \
         program); drop --kernel or choose a GPU with --backend",
        .0.name()
    )]
    KernelOnCpu(Kernel),
    /// A `--devices` entry that is neither an index nor `cpu`.
    #[error("bad --devices entry `{0}`: give auto, all, or a comma-separated list of device indices and `cpu` (`sdfc devices` lists the devices)")]
    DevicesEntry(String),
    /// A GPU's index in `--devices` with the CPU backend.
    #[error("--devices entry `{0}` names a GPU, but --backend cpu renders on the CPU alone (give --backend auto, wgpu or cuda)")]
    GpuOnCpu(usize),
    /// `--devices all` with the CPU backend.
    #[error("--devices all names every GPU, but --backend cpu renders on the CPU alone (give --backend auto, wgpu or cuda)")]
    AllOnCpu,
    /// GPUs asked of the CPU backend, whose GPUs `--devices` would index.
    #[error("--devices names GPUs, but --backend cpu renders on the CPU alone (give --backend auto, wgpu or cuda)")]
    GpusOnCpu,
}

/// Why `--devices` names no device to render on ([`Devices::resolve`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Resolve {
    /// The list cannot be used with the backend: a usage error.
    #[error(transparent)]
    Usage(#[from] Usage),
    /// `--devices all` found no GPU of the backend (`cuda` or `wgpu`): a device error.
    #[error("--devices all found no {0} device")]
    NoDevice(&'static str),
}

impl From<Resolve> for Error {
    fn from(e: Resolve) -> Error {
        match e {
            Resolve::Usage(u) => Error::Usage(u),
            Resolve::NoDevice(backend) => Error::NoDevice(backend),
        }
    }
}

/// Where a scene is rendered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Backend {
    /// CUDA if a driver and device are present, else a wgpu GPU adapter, else the CPU.
    #[default]
    Auto,
    /// The CPU renderer with the batch interpreter.
    Cpu,
    /// The WGSL kernel through wgpu (a GPU, or lavapipe on a CPU).
    Wgpu,
    /// The PTX kernel through the CUDA driver.
    Cuda,
}

/// How a scene is prepared, besides the backend.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Setup {
    /// Float type of the CPU renderer (the GPU backends are f32).
    pub precision: Precision,
    /// Paint pixels whose rays met a NaN magenta (`--debug-nan`).
    pub debug_nan: bool,
    /// GPU kernels read their distance program's constants from `scene_data`
    /// (`wgsl::Options::parameters`), so that [`Prepared::update`] reuses a kernel for a
    /// program that differs only in numbers (the frames of an animation).
    pub parameters: bool,
    /// Which GPU kernel a marched scene gets (`--kernel`): its distance program written as
    /// code, interpreted from a buffer, or the one `wgsl::choose` expects sooner.
    pub kernel: wgsl::KernelChoice,
    /// GPU frames read back the image alone, without reducing the per-pixel statistics on
    /// the device (`sdfc render` without `--stats`, sequences): their [`Frame`]'s statistics
    /// then count nothing but the camera rays.
    pub image_only: bool,
    /// GPU frames are finished on the device: clamped and sRGB-encoded to RGBA8 by the kernel
    /// (bit for bit the host's encoding), and only those 4 bytes a pixel read back instead of
    /// the linear colours (16): their [`Frame`] has [`Frame::finished`] and an empty linear
    /// image. For outputs of 8-bit pixels (PNG, JPEG, video); not for OpenEXR, `--reference`
    /// or `--aux`, which read the linear colours. The CPU backend renders as ever.
    pub finished: bool,
    /// The kernel runs on a software adapter (lavapipe, llvmpipe), where every loop of a
    /// shader shares one budget of iterations: the interpreted kernel then runs more
    /// instructions an iteration (`wgsl::Options::interp_unroll`). Set by the preparation
    /// for the adapter it finds.
    pub software: bool,
}

/// The GPU kernel asked for on the command line (`--kernel`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Kernel {
    /// The interpreted kernel where the distance program written as code would be large
    /// (compiling it takes the drivers seconds), else the specialised one.
    #[default]
    Auto,
    /// The distance program written as code: the fastest frames, compiled for each scene.
    Specialised,
    /// One kernel that interprets the distance program from a buffer: no compile per scene.
    Interpreted,
}

impl Kernel {
    /// The choice for the WGSL back end.
    pub fn choice(self) -> wgsl::KernelChoice {
        match self {
            Kernel::Auto => wgsl::KernelChoice::Auto,
            Kernel::Specialised => wgsl::KernelChoice::Specialised,
            Kernel::Interpreted => wgsl::KernelChoice::Interpreted,
        }
    }

    /// The kernel's name, as in `--kernel`.
    pub fn name(self) -> &'static str {
        match self {
            Kernel::Auto => "auto",
            Kernel::Specialised => "specialised",
            Kernel::Interpreted => "interpreted",
        }
    }

    /// `Err` for a `--kernel` given with a backend that has no GPU kernel.
    pub fn check(kernel: Option<Kernel>, backend: Backend) -> Result<(), Usage> {
        match kernel {
            Some(k) if backend == Backend::Cpu => Err(Usage::KernelOnCpu(k)),
            _ => Ok(()),
        }
    }
}

impl Setup {
    /// This setup with `--kernel auto` meaning the specialised kernel.
    fn specialised_for_auto(&self) -> Setup {
        Setup {
            kernel: match self.kernel {
                wgsl::KernelChoice::Auto => wgsl::KernelChoice::Specialised,
                other => other,
            },
            ..*self
        }
    }

    /// This setup on a CUDA device, where `--kernel auto` is the specialised kernel: the
    /// driver's JIT compiles even the largest marched programs as code within seconds, while
    /// the interpreted kernel's frames are many times slower.
    fn on_cuda(&self) -> Setup {
        self.specialised_for_auto()
    }
}

/// Where the first preparation of a scene for a GPU went (`sdfc render --stats`): the
/// device opened and the kernel written; the driver's compile is the wgpu pipeline's
/// (`pipeline`) or the CUDA module's load (`gpu/cuda/jit.rs`).
#[derive(Debug, Clone, Copy, Default)]
pub struct Preparation {
    /// Opening the device: wgpu's adapters enumerated and a device opened, or the CUDA
    /// context created (zero for a device opened by the caller, as the viewer's).
    pub device: Duration,
    /// Writing the WGSL kernel and validating it with naga.
    pub kernel: Duration,
    /// The wgpu pipeline, when the preparation created it (a device opened by the caller
    /// creates it at its first render, or by [`Gpu::pipeline_for`]).
    pub pipeline: Option<gpu::wgpu::PipelineTime>,
    /// For a device opened on a thread of its own ([`Opening`]): the time its opening took
    /// there, beside the front end; `device` is then the time the preparation waited for it.
    pub overlapped: Option<Duration>,
}

impl Preparation {
    /// What the phase `device` of `--stats` was: the device's opening (`what`), or, for a
    /// device opened beside the front end, the wait for it and how long it took there.
    fn opening(&self, what: &str) -> String {
        match self.overlapped {
            None => what.into(),
            Some(took) => format!(
                "waited for the device: {what} on a thread of its own in {:.1} ms, overlapped with the front end",
                took.as_secs_f64() * 1e3
            ),
        }
    }
}

impl Preparation {
    /// The phases of `--stats` for a device opened first (`parts`, the device's phase
    /// first) in the order they ended: a device opened beside the front end was waited for
    /// after the kernel was written.
    fn ordered(
        &self,
        mut parts: Vec<(&'static str, Duration, String)>,
    ) -> Vec<(&'static str, Duration, String)> {
        if self.overlapped.is_some() && parts.len() >= 2 {
            parts.swap(0, 1);
        }
        parts
    }
}

/// A finished frame: the render and the time it took (GPU time for GPU backends).
#[derive(Debug)]
pub struct Frame {
    /// Image and statistics.
    pub render: Render,
    /// Time of the frame (GPU time for GPU backends).
    pub time: Duration,
    /// Wall time of the frame (the same as `time` on the CPU).
    pub wall: Duration,
    /// Where a GPU frame's wall time went on the host (`None` on the CPU).
    pub phases: Option<crate::gpu::Phases>,
    /// What each device did, when several rendered the frame.
    pub shares: Vec<gpu::launch::Share>,
    /// The pixels the GPU finished ([`Setup::finished`]); `render.image` is then empty.
    pub finished: Option<crate::image::Rgba8>,
}

impl Frame {
    /// The frame's pixels to write, taken out of it (its image is left empty): those the GPU
    /// finished, else its linear image.
    pub fn take_picture(&mut self) -> crate::image::Picture {
        if let Some(f) = self.finished.take() {
            return crate::image::Picture::Finished(f);
        }
        let image = &mut self.render.image;
        let empty = crate::image::Image {
            width: image.width,
            height: image.height,
            linear: Vec::new(),
        };
        crate::image::Picture::Linear(std::mem::replace(image, empty))
    }

    /// The warnings of devices that failed while others finished the frame.
    pub fn warnings(&self) -> Vec<String> {
        self.shares
            .iter()
            .enumerate()
            .filter_map(|(i, s)| {
                s.failure.as_ref().map(|f| {
                    format!(
                        "device {i} ({}) failed after {} tile{}: {f}; the other devices rendered its tiles",
                        s.device,
                        s.tiles,
                        if s.tiles == 1 { "" } else { "s" }
                    )
                })
            })
            .collect()
    }
}

impl Frame {
    /// The frame a GPU render gave.
    fn of(r: gpu::GpuRender) -> Frame {
        Frame {
            render: r.render,
            time: r.time,
            wall: r.wall,
            phases: Some(r.phases),
            shares: r.shares,
            finished: r.finished,
        }
    }
}

/// Bytes of a kernel's scene data.
fn bytes(data: &Option<Vec<u8>>) -> u64 {
    data.as_ref().map_or(0, |d| d.len() as u64)
}

/// The GPU kernel's kind, for `--stats` and `sdfc bench`.
fn kind(interpreted: bool) -> &'static str {
    if interpreted {
        "interpreted"
    } else {
        "specialised"
    }
}

/// A scene prepared after another ([`Prepared::next`]), and whether a kernel (or the CPU's
/// tapes) was built for it.
pub(crate) type Next = Result<(Prepared, bool), Error>;

/// What a render tells of how far it has come: the fraction done.
pub type Progress<'a> = &'a (dyn Fn(f64) + Sync);

/// A scene prepared for one backend, or for several devices: what every backend answers.
/// [`Prepared`] holds one and does what is the same for all (the kernel's contract checked
/// before a render, the method checked before a preparation).
pub trait Renderer: std::fmt::Debug + Send + Sync {
    /// The backend's name, as in `--backend`.
    fn name(&self) -> &'static str;

    /// The device, for messages.
    fn device(&self) -> String;

    /// The GPU kernel's kind, for `--stats` and `sdfc bench`: "specialised" or
    /// "interpreted" (`None` on the CPU).
    fn kernel_kind(&self) -> Option<&'static str> {
        None
    }

    /// Where the first preparation went, for `--stats`: (phase, time, how) for the device,
    /// the kernel, its PTX and the driver's compile; on the CPU, the tapes.
    fn preparation(&self) -> Vec<(&'static str, Duration, String)>;

    /// The most memory rendering `settings` allocates (with the current pool's threads on
    /// the CPU), the finished frame included.
    fn memory(&self, scene: &Scene, settings: &Settings) -> Memory;

    /// The bytes a finished frame holds (its image and, on the CPU, its depth buffers).
    fn retained(&self, settings: &Settings) -> u64 {
        gpu::retained(settings)
    }

    /// Instructions of the distance program (CPU) or of the kernel's `map` (GPU).
    fn program_len(&self) -> usize;

    /// The scene's primitives, or why it cannot be traced analytically, as lowered.
    fn traceable(&self) -> &Traceable;

    /// The contract of the GPU kernel: what it was specialised for and what it reads
    /// (`None` on the CPU, which reads every setting at every render).
    fn contract(&self) -> Option<&wgsl::Contract> {
        None
    }

    /// The setup of a GPU kernel (of the first GPU device of several).
    fn setup(&self) -> Option<&Setup> {
        None
    }

    /// Renders one frame, its contract checked; `progress` gets the fraction done.
    fn render(&self, scene: &Scene, progress: Progress, faults: &Faults) -> Result<Frame, Error>;

    /// Whether GPU frames reduce the per-pixel statistics on the device (the opposite of
    /// [`Setup::image_only`]): `sdfc bench` reduces them for its warm-up frame alone. Nothing
    /// to do on the CPU, which counts them as it renders.
    fn reduce_statistics(&mut self, _on: bool) {}

    /// This device as one of several rendering `scene` together.
    fn part<'a>(&'a self, scene: &'a Scene) -> Result<Part<'a>, Error>;

    /// `scene`, lowered as `lowered`, prepared as this is (see [`Prepared::next`]), with the
    /// wgpu kernel `kernel` instead of this one's choice when given. A CUDA preparation and
    /// several devices keep the default, [`Error::NotNext`]: they are prepared again with
    /// [`Prepared::update`].
    fn next(&self, _scene: &Scene, _lowered: Lowered, _kernel: Option<wgsl::KernelChoice>) -> Next {
        Err(Error::NotNext)
    }

    /// Prepares `scene`, lowered as `lowered`, in place of this one's scene (see
    /// [`Prepared::update`]).
    fn update(&mut self, scene: &Scene, lowered: Lowered) -> Result<bool, Error>;

    /// Writes the GPU kernel again for `scene`, whose settings its contract refuses (see
    /// [`Prepared::specialise`]).
    fn specialise(&mut self, _scene: &Scene) -> Result<bool, Error> {
        Ok(false)
    }

    /// The wgpu preparation, for the viewer, which keeps its frames on the device.
    fn as_wgpu(&self) -> Option<&WgpuPrepared> {
        None
    }
}

/// One device of several rendering a frame together: its launcher, and (for a GPU) its
/// kernel's Lipschitz bound, uniform layout and scene data.
pub struct Part<'a> {
    /// The device's worker for the tile scheduler.
    pub worker: Box<dyn gpu::launch::Worker + 'a>,
    /// The GPU kernel's inputs; `None` on the CPU.
    pub kernel: Option<(f64, &'a wgsl::Uniform, Option<&'a [u8]>)>,
}

impl std::fmt::Debug for Part<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Part")
            .field("worker", &self.worker.name())
            .finish_non_exhaustive()
    }
}

/// What a timed render ran, the head of `sdfc bench`'s and `sdfc pareto`'s reports: the scene
/// file, the backend and its device, the float type and the image size.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Ran {
    /// The scene file.
    pub scene: String,
    /// Backend used.
    pub backend: &'static str,
    /// The device it ran on.
    pub device: String,
    /// Float type.
    pub precision: &'static str,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
}

impl Ran {
    /// `scene` rendered on `prepared` in `precision` at the size of `settings`.
    pub fn new(
        scene: String,
        prepared: &Prepared,
        precision: Precision,
        settings: &Settings,
    ) -> Ran {
        Ran {
            scene,
            backend: prepared.name(),
            device: prepared.device(),
            precision: match precision {
                Precision::F32 => "f32",
                Precision::F64 => "f64",
            },
            width: settings.width,
            height: settings.height,
        }
    }
}

/// A scene prepared for one backend, or for several devices ([`Renderer`]).
#[derive(Debug)]
pub struct Prepared(Box<dyn Renderer>);

impl Prepared {
    /// The contract of the GPU kernel: what it was specialised for and what it reads
    /// (`None` on the CPU, which reads every setting at every render).
    pub fn contract(&self) -> Option<&wgsl::Contract> {
        self.0.contract()
    }

    /// Whether the next GPU frames reduce their per-pixel statistics on the device (they
    /// do unless prepared with [`Setup::image_only`]); without them a frame's statistics
    /// count nothing but the camera rays.
    pub fn reduce_statistics(&mut self, on: bool) {
        self.0.reduce_statistics(on)
    }

    /// The backend's name, as in `--backend`.
    pub fn name(&self) -> &'static str {
        self.0.name()
    }

    /// The device, for messages.
    pub fn device(&self) -> String {
        self.0.device()
    }

    /// The GPU kernel's kind, for `--stats` and `sdfc bench`: "specialised" or
    /// "interpreted" (`None` on the CPU).
    pub fn kernel_kind(&self) -> Option<&'static str> {
        self.0.kernel_kind()
    }

    /// Where the first preparation for a GPU went, for `--stats`: (phase, time, how) for
    /// the device, the kernel, its PTX and the driver's compile; on the CPU, the tapes.
    pub fn preparation(&self) -> Vec<(&'static str, Duration, String)> {
        self.0.preparation()
    }

    /// The most memory rendering `settings` allocates (with the current pool's threads on
    /// the CPU), the finished frame included.
    pub fn memory(&self, scene: &Scene, settings: &Settings) -> Memory {
        self.0.memory(scene, settings)
    }

    /// The bytes a finished frame holds (its image and, on the CPU, its depth buffers).
    pub fn retained(&self, settings: &Settings) -> u64 {
        self.0.retained(settings)
    }

    /// Instructions of the distance program (CPU) or of the kernel's `map` (GPU).
    pub fn program_len(&self) -> usize {
        self.0.program_len()
    }

    /// The scene's primitives, or why it cannot be traced analytically, as lowered.
    pub fn traceable(&self) -> &Traceable {
        self.0.traceable()
    }

    /// The wgpu preparation (`None` for another backend or several devices): the viewer
    /// renders its frames on the device through it.
    pub fn as_wgpu(&self) -> Option<&WgpuPrepared> {
        self.0.as_wgpu()
    }

    /// Renders one frame; `progress` gets the fraction done. The faults of the testing aid
    /// `SDFC_FAULT_AFTER_TILES` are injected.
    pub fn render(&self, scene: &Scene, progress: Progress) -> Result<Frame, Error> {
        self.render_faults(scene, progress, &Faults::from_env())
    }

    /// [`Prepared::render`] with the faults `faults` injected.
    pub fn render_faults(
        &self,
        scene: &Scene,
        progress: Progress,
        faults: &Faults,
    ) -> Result<Frame, Error> {
        self.check_contract(scene)?;
        self.0.render(scene, progress, faults)
    }
}

impl memory::Footprint for Prepared {
    fn memory(&self, scene: &Scene, settings: &Settings) -> Memory {
        Prepared::memory(self, scene, settings)
    }

    fn retained(&self, settings: &Settings) -> u64 {
        Prepared::retained(self, settings)
    }
}
