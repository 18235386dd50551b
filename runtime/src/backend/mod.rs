//! Backends behind one interface: a scene is prepared once for a backend (program lowered,
//! tapes or kernel generated, device opened, module loaded) and then rendered any number of
//! times; what a render allocates is known before it starts ([`Prepared::memory`]). Each
//! backend implements [`Renderer`] in a module of its own (`cpu.rs`, `wgpu.rs`, `cuda.rs`,
//! and `several.rs` for several devices at once); [`Prepared`] holds one, and the
//! preparations that choose it are here (`opening.rs` the one that joins a device opened
//! beside the front end). What fails is an [`Error`].

mod cpu;
mod cuda;
mod opening;
mod several;
mod wgpu;

pub use self::cpu::CpuPrepared;
pub use self::cuda::CudaPrepared;
pub use self::opening::{see_only, Opening};
pub use self::several::SeveralPrepared;
pub use self::wgpu::WgpuPrepared;

use crate::cpu::{Precision, Render};
use crate::gpu::{self, cuda::Cuda, Gpu};
use crate::memory::{self, Memory};
use sdfc_compiler::{
    analytic::{Choice, Traceable},
    lower_scene, wgsl, LowerOptions, Lowered, Method, Scene, Settings,
};
use std::sync::Arc;
use std::time::Duration;

/// What fails preparing a scene on a backend or rendering it there.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The scene asks for what the backend or its kernel cannot do: analytic tracing of a
    /// scene that does not allow it, a GPU kernel that cannot render it, settings its kernel
    /// was not specialised for, GPUs of the CPU backend.
    #[error("{0}")]
    Unsupported(String),
    /// The kernel asked for cannot render the scene (`wgsl::choose`).
    #[error(transparent)]
    Refused(#[from] wgsl::Refused),
    /// A device could not be opened: no driver, no adapter, no such index.
    #[error("{0}")]
    Device(String),
    /// The kernel could not be written, translated to PTX, loaded, or compiled into a
    /// pipeline.
    #[error("{0}")]
    Kernel(String),
    /// A render failed on its device (or on every device of several).
    #[error("{0}")]
    Render(String),
    /// Asked of a preparation that does not do it (a CUDA preparation's `next`).
    #[error("{0}")]
    Misuse(String),
    /// Arguments the backend cannot take: a usage error wherever it is found.
    #[error(transparent)]
    Usage(#[from] Usage),
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
            Resolve::NoDevice(_) => Error::Device(e.to_string()),
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

/// Which devices a render uses (`--devices`).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum Devices {
    /// The one device `--backend` picks.
    #[default]
    Auto,
    /// Every GPU of the backend: every CUDA device, or every wgpu adapter (the CPU is not
    /// one of them).
    All,
    /// These, in order: GPUs by index (CUDA devices, or wgpu adapters, as `sdfc devices`
    /// lists them), and `cpu`. An index given twice opens the device twice: two logical
    /// devices that share it.
    List(Vec<Device>),
}

/// One entry of `--devices`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Device {
    /// The CPU renderer.
    Cpu,
    /// A GPU by index.
    Gpu(usize),
}

impl Devices {
    /// Reads `--devices`: `auto`, `all`, or a comma-separated list of indices and `cpu`.
    pub fn parse(text: &str) -> Result<Devices, Usage> {
        match text.trim() {
            "auto" => return Ok(Devices::Auto),
            "all" => return Ok(Devices::All),
            _ => {}
        }
        text.split(',')
            .map(|entry| match entry.trim() {
                "cpu" => Ok(Device::Cpu),
                e => e
                    .parse()
                    .map(Device::Gpu)
                    .map_err(|_| Usage::DevicesEntry(e.into())),
            })
            .collect::<Result<Vec<_>, _>>()
            .map(Devices::List)
    }

    /// The devices of `backend` these name; `None` for `auto` (the one device the backend
    /// picks). Every caller reports a failure as `job::Error::unavailable` does: GPUs asked of
    /// the CPU backend are a usage error, `all` finding none a device error.
    pub fn resolve(&self, backend: Backend) -> Result<Option<Vec<Device>>, Resolve> {
        let list: Vec<Device> = match self {
            Devices::Auto => return Ok(None),
            Devices::All => match gpu_kind(backend)? {
                Backend::Cuda => (0..Cuda::count()).map(Device::Gpu).collect(),
                _ => (0..gpu::wgpu::adapters().len()).map(Device::Gpu).collect(),
            },
            Devices::List(list) => list.clone(),
        };
        if list.is_empty() {
            return Err(Resolve::NoDevice(match gpu_kind(backend)? {
                Backend::Cuda => "cuda",
                _ => "wgpu",
            }));
        }
        Ok(Some(list))
    }

    /// `Err` naming the first entry `backend` cannot render on (a GPU with `--backend cpu`).
    pub fn check(&self, backend: Backend) -> Result<(), Usage> {
        match self {
            Devices::List(list) if backend == Backend::Cpu => {
                match list.iter().find_map(|d| match d {
                    Device::Gpu(i) => Some(*i),
                    Device::Cpu => None,
                }) {
                    Some(i) => Err(Usage::GpuOnCpu(i)),
                    None => Ok(()),
                }
            }
            Devices::All if backend == Backend::Cpu => Err(Usage::AllOnCpu),
            _ => Ok(()),
        }
    }
}

/// Where the first preparation of a scene for a GPU went (`sdfc render --stats`): the
/// device opened and the kernel written; the driver's compile is the wgpu pipeline's
/// (`pipeline`) or the CUDA module's load (`cuda.rs`).
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

/// `Err` when the scene's settings ask for analytic tracing (`method=trace`) of a scene that
/// does not allow it, saying why, from the primitives the lowering found (`traceable`):
/// `sdfc render` refuses such settings before preparing a backend.
pub fn method_allowed(scene: &Scene, traceable: &Traceable) -> Result<(), Error> {
    if scene.settings.method == Method::Trace {
        if let Choice::March(reason) = traceable.choose(scene.settings.method) {
            return Err(Error::Unsupported(format!(
                "this scene cannot be ray traced analytically: {}; use method=auto or method=march",
                reason.describe()
            )));
        }
    }
    Ok(())
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
    fn retained(&self, settings: &Settings) -> u64;

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
    fn render(
        &self,
        scene: &Scene,
        progress: &(dyn Fn(f64) + Sync),
        faults: &gpu::launch::Faults,
    ) -> Result<Frame, Error>;

    /// Whether GPU frames reduce the per-pixel statistics on the device (the opposite of
    /// [`Setup::image_only`]): `sdfc bench` reduces them for its warm-up frame alone. Nothing
    /// to do on the CPU, which counts them as it renders.
    fn reduce_statistics(&mut self, _on: bool) {}

    /// This device as one of several rendering `scene` together.
    fn part<'a>(&'a self, scene: &'a Scene) -> Result<Part<'a>, Error>;

    /// `scene`, lowered as `lowered`, prepared as this is (see [`Prepared::next`]), with the
    /// wgpu kernel `kernel` instead of this one's choice when given.
    fn next(
        &self,
        scene: &Scene,
        lowered: Lowered,
        kernel: Option<wgsl::KernelChoice>,
    ) -> Result<(Prepared, bool), Error>;

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

/// A scene prepared for one backend, or for several devices ([`Renderer`]).
#[derive(Debug)]
pub struct Prepared(Box<dyn Renderer>);

/// Whose GPUs `--devices` indexes: CUDA's or wgpu's (for `auto`, CUDA's where a driver has
/// devices).
fn gpu_kind(backend: Backend) -> Result<Backend, Usage> {
    match backend {
        Backend::Cuda | Backend::Wgpu => Ok(backend),
        Backend::Auto if Cuda::count() > 0 => Ok(Backend::Cuda),
        Backend::Auto => Ok(Backend::Wgpu),
        Backend::Cpu => Err(Usage::GpusOnCpu),
    }
}

/// The kernel for `scene`, chosen (`wgsl::choose`), written and validated.
fn kernel(scene: &Scene, lowered: &Lowered, setup: &Setup) -> Result<wgsl::Kernel, Error> {
    let options = kernel_options(setup);
    wgsl::choose(scene, lowered, &options)?;
    wgsl::write_with(scene, lowered, &options).map_err(|e| Error::Kernel(e.to_string()))
}

fn kernel_options(setup: &Setup) -> wgsl::Options {
    wgsl::Options {
        debug_nan: setup.debug_nan,
        parameters: setup.parameters,
        kernel: setup.kernel,
        interp_unroll: if setup.software {
            wgsl::interp::UNROLL_SOFTWARE
        } else {
            wgsl::interp::UNROLL
        },
        ..wgsl::Options::default()
    }
}

/// The text and data of the kernel for `scene`, not validated (to compare with a kernel
/// held).
fn kernel_text(scene: &Scene, lowered: &Lowered, setup: &Setup) -> Result<wgsl::Text, Error> {
    let options = kernel_options(setup);
    wgsl::choose(scene, lowered, &options)?;
    wgsl::write_text(scene, lowered, &options).map_err(|e| Error::Kernel(e.to_string()))
}

impl Prepared {
    /// `backend` prepared.
    fn of(backend: impl Renderer + 'static) -> Prepared {
        Prepared(Box::new(backend))
    }

    /// Prepares `scene` for `backend`. `Err` says why the backend cannot be used.
    pub fn new(backend: Backend, scene: &Scene, precision: Precision) -> Result<Prepared, Error> {
        let setup = Setup {
            precision,
            ..Setup::default()
        };
        let lowered = lower_scene(scene, &LowerOptions::default());
        Self::from_program(backend, scene, lowered, &setup)
    }

    /// Prepares `scene`, lowered as `lowered` (its program and what else the backends
    /// read), for `backend`.
    pub fn from_program(
        backend: Backend,
        scene: &Scene,
        lowered: Lowered,
        setup: &Setup,
    ) -> Result<Prepared, Error> {
        method_allowed(scene, &lowered.traceable)?;
        let cpu = |lowered| Prepared::of(CpuPrepared::new(scene, lowered, setup));
        let wgpu =
            |hardware| WgpuPrepared::open(scene, &lowered, setup, hardware).map(Prepared::of);
        let cuda = || CudaPrepared::open(scene, &lowered, setup, Cuda::open).map(Prepared::of);
        match backend {
            Backend::Cpu => Ok(cpu(lowered)),
            Backend::Wgpu => wgpu(false),
            Backend::Cuda => cuda(),
            Backend::Auto if setup.precision == Precision::F64 => Ok(cpu(lowered)),
            Backend::Auto => match cuda().or_else(|_| wgpu(true)) {
                Ok(p) => Ok(p),
                Err(_) => Ok(cpu(lowered)),
            },
        }
    }

    /// Prepares `scene`, lowered as `lowered`, for `backend` on `devices`: the device the
    /// backend picks ([`Devices::Auto`]), or several that render each frame together.
    pub fn on_devices(
        backend: Backend,
        devices: &Devices,
        scene: &Scene,
        lowered: Lowered,
        setup: &Setup,
    ) -> Result<Prepared, Error> {
        let Some(list) = devices.resolve(backend)? else {
            return Self::from_program(backend, scene, lowered, setup);
        };
        method_allowed(scene, &lowered.traceable)?;
        let mut parts = Vec::with_capacity(list.len());
        for d in &list {
            let part = match *d {
                Device::Cpu => Prepared::of(CpuPrepared::new(scene, lowered.clone(), setup)),
                Device::Gpu(i) => match gpu_kind(backend)? {
                    // On a stream of its own: the same index twice is two logical devices on
                    // one GPU, running side by side.
                    Backend::Cuda => {
                        Prepared::of(CudaPrepared::open(scene, &lowered, setup, || {
                            Cuda::open_device(i, true)
                        })?)
                    }
                    _ => {
                        let gpu = Gpu::open_index(i).map_err(|e| Error::Device(e.to_string()))?;
                        Self::on_gpu(Arc::new(gpu), scene, &lowered, setup)?
                    }
                },
            };
            parts.push(part);
        }
        Ok(match parts.len() {
            1 => parts.remove(0),
            _ => Prepared::of(SeveralPrepared { parts }),
        })
    }

    /// Prepares `scene`, lowered as `lowered`, for wgpu on an already opened device:
    /// generates and validates the kernel (its pipeline is compiled, or found in the
    /// device's cache, at the first render or by [`Gpu::pipeline_for`]).
    pub fn on_gpu(
        gpu: Arc<Gpu>,
        scene: &Scene,
        lowered: &Lowered,
        setup: &Setup,
    ) -> Result<Prepared, Error> {
        WgpuPrepared::on_gpu_after(gpu, scene, lowered, setup, None).map(|(p, _)| Prepared::of(p))
    }

    /// Prepares `scene`, lowered as `lowered`, for the CPU renderer.
    pub fn on_cpu(scene: &Scene, lowered: Lowered, setup: &Setup) -> Result<Prepared, Error> {
        method_allowed(scene, &lowered.traceable)?;
        Ok(Prepared::of(CpuPrepared::new(scene, lowered, setup)))
    }

    /// `scene`, lowered as `lowered`, prepared as this is (the same backend, device and
    /// setup), leaving this as it is: a wgpu kernel whose text is unchanged is reused (with
    /// [`Setup::parameters`], a program that differs only in numbers: only its `scene_data`
    /// is new); the CPU's tapes are made again. Also says whether a kernel (or the tapes) was
    /// built. The viewer keeps its last good scene until the new one is ready; a sequence
    /// replaces its scene with [`Prepared::update`]. CUDA and several devices are prepared
    /// again with `update` alone.
    pub fn next(&self, scene: &Scene, lowered: Lowered) -> Result<(Prepared, bool), Error> {
        self.0.next(scene, lowered, None)
    }

    /// [`Prepared::next`] with the wgpu kernel `kernel` instead of this one's choice (the
    /// viewer shows a scene through the interpreted kernel while its specialised kernel
    /// compiles); the same as `next` for the CPU.
    pub fn next_with(
        &self,
        scene: &Scene,
        lowered: Lowered,
        kernel: wgsl::KernelChoice,
    ) -> Result<(Prepared, bool), Error> {
        self.0.next(scene, lowered, Some(kernel))
    }

    /// Prepares `scene`, lowered as `lowered`, in place of the scene this was prepared for,
    /// keeping the device: a GPU kernel whose text is unchanged (with [`Setup::parameters`], a
    /// program that differs only in numbers) is kept and given the new `scene_data`; another
    /// is compiled. Returns whether a kernel (or the CPU's tapes) was built.
    pub fn update(&mut self, scene: &Scene, lowered: Lowered) -> Result<bool, Error> {
        method_allowed(scene, &lowered.traceable)?;
        self.0.update(scene, lowered)
    }

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

    /// Specialises the GPU kernel again when `scene` needs other features than it has
    /// (another method, over-relaxation on or off, another `max_depth`, soft shadows where
    /// the kernel has hard ones, ...: [`wgsl::Contract::check`]): a sweep of ω from 1 up must
    /// turn `RELAX` on. Keeps the device; nothing to do on the CPU. Says whether a kernel was
    /// written.
    pub fn specialise(&mut self, scene: &Scene) -> Result<bool, Error> {
        if self.check_contract(scene).is_ok() {
            return Ok(false);
        }
        self.0.specialise(scene)
    }

    /// `Err` when `scene` needs a kernel specialised otherwise than this one
    /// ([`wgsl::Contract::check`]; [`Prepared::specialise`] writes it again): a render never
    /// silently ignores a setting or a feature of the scene.
    pub fn check_contract(&self, scene: &Scene) -> Result<(), Error> {
        let Some(contract) = self.contract() else {
            return Ok(());
        };
        let traced = self.traceable().traced(scene.settings.method).is_some();
        contract.check(scene, traced).map_err(|m| {
            Error::Unsupported(format!(
                "the {} kernel cannot render this scene: {m}; specialise it again",
                self.name()
            ))
        })
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
    pub fn render(&self, scene: &Scene, progress: &(dyn Fn(f64) + Sync)) -> Result<Frame, Error> {
        self.render_faults(scene, progress, &gpu::launch::Faults::from_env())
    }

    /// [`Prepared::render`] with the faults `faults` injected.
    pub fn render_faults(
        &self,
        scene: &Scene,
        progress: &(dyn Fn(f64) + Sync),
        faults: &gpu::launch::Faults,
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
