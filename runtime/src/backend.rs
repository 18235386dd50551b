//! Backends behind one interface: a scene is prepared once for a backend (program lowered,
//! tapes or kernel generated, device opened, module loaded) and then rendered any number of
//! times; what a render allocates is known before it starts ([`Prepared::memory`]).

use crate::cpu::{self, Options, Precision, Render, Tapes};
use crate::gpu::{self, cuda::Cuda, Gpu};
use crate::memory::{self, Memory};
use sdfc_compiler::back::{ptx, wgsl};
use sdfc_compiler::lower::{self, LowerOptions, Lowered};
use sdfc_compiler::scene::analytic::{Choice, Traceable};
use sdfc_compiler::scene::{Method, Scene, Settings};
use std::sync::Arc;
use std::time::{Duration, Instant};

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
    /// GPU frames read back the image alone, not the per-pixel statistics (`sdfc render`
    /// without `--stats`, sequences): their [`Frame`]'s statistics then count nothing but
    /// the camera rays. At 1920×1080 the statistics are 66 MB to read back and convert.
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

    /// `Err` for a `--kernel` given with a backend that has no GPU kernel.
    pub fn check(kernel: Option<Kernel>, backend: Backend) -> Result<(), String> {
        match kernel {
            Some(k) if backend == Backend::Cpu => Err(format!(
                "--kernel {} chooses a GPU kernel, and the CPU backend has none (it interprets \
                 every program); drop --kernel or choose a GPU with --backend",
                match k {
                    Kernel::Auto => "auto",
                    Kernel::Specialised => "specialised",
                    Kernel::Interpreted => "interpreted",
                }
            )),
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

    /// This setup on a CUDA device, where `--kernel auto` is the specialised kernel: on an
    /// H100 (BENCHMARKS.md, "Interpreted against specialised", 2026-11-24) the driver's JIT of
    /// the largest marched programs as code took at most 2.9 s cold and 0.8 s warm, a whole
    /// render with the interpreted kernel 1.4–1.8 s cold, and its frames were 17 to 100 times
    /// slower.
    fn on_cuda(&self) -> Setup {
        self.specialised_for_auto()
    }
}

/// A scene prepared for one backend.
#[derive(Debug)]
pub enum Prepared {
    /// CPU: the distance program and its tapes, and the render options.
    Cpu {
        tapes: Box<Tapes>,
        options: Options,
        /// How long the tapes took to prepare (`--stats`).
        taped: Duration,
    },
    /// wgpu: the device (which may be shared, as the viewer shares its window's), the
    /// validated kernel and the scene's Lipschitz bound L (and the lowered scene and setup,
    /// to specialise the kernel again for other settings).
    Wgpu {
        gpu: Arc<Gpu>,
        kernel: Box<wgsl::Kernel>,
        lipschitz: f64,
        lowered: Box<Lowered>,
        setup: Setup,
        timing: Preparation,
    },
    /// CUDA: the device, the loaded module (with the kernel's scene data and the settings it
    /// was specialised for) and the scene's Lipschitz bound L (and the lowered scene and
    /// setup, to specialise the kernel again for other settings).
    Cuda {
        cuda: Box<Cuda>,
        module: Box<CudaModule>,
        lipschitz: f64,
        lowered: Box<Lowered>,
        setup: Setup,
        timing: Preparation,
    },
    /// Several devices (`--devices`), each prepared as above, rendering each frame together
    /// ([`gpu::render_several`]).
    Several(Vec<Prepared>),
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
    pub fn parse(text: &str) -> Result<Devices, String> {
        match text.trim() {
            "auto" => return Ok(Devices::Auto),
            "all" => return Ok(Devices::All),
            _ => {}
        }
        text.split(',')
            .map(|entry| match entry.trim() {
                "cpu" => Ok(Device::Cpu),
                e => e.parse().map(Device::Gpu).map_err(|_| {
                    format!(
                        "bad --devices entry `{e}`: give auto, all, or a comma-separated list of device indices and `cpu` (`sdfc devices` lists the devices)"
                    )
                }),
            })
            .collect::<Result<Vec<_>, _>>()
            .map(Devices::List)
    }

    /// The devices of `backend` these name; `None` for `auto` (the one device the backend
    /// picks).
    pub fn resolve(&self, backend: Backend) -> Result<Option<Vec<Device>>, String> {
        let list: Vec<Device> = match self {
            Devices::Auto => return Ok(None),
            Devices::All => match Prepared::gpu_kind(backend)? {
                Backend::Cuda => (0..Cuda::count()).map(Device::Gpu).collect(),
                _ => (0..gpu::wgpu::adapters().len()).map(Device::Gpu).collect(),
            },
            Devices::List(list) => list.clone(),
        };
        if list.is_empty() {
            return Err(format!(
                "--devices all found no {} device",
                format!("{:?}", Prepared::gpu_kind(backend)?).to_lowercase()
            ));
        }
        Ok(Some(list))
    }

    /// `Err` naming the first entry `backend` cannot render on (a GPU with `--backend cpu`).
    pub fn check(&self, backend: Backend) -> Result<(), String> {
        match self {
            Devices::List(list) if backend == Backend::Cpu => match list.iter().find_map(|d| match d {
                Device::Gpu(i) => Some(i),
                Device::Cpu => None,
            }) {
                Some(i) => Err(format!(
                    "--devices entry `{i}` names a GPU, but --backend cpu renders on the CPU alone (give --backend auto, wgpu or cuda)"
                )),
                None => Ok(()),
            },
            Devices::All if backend == Backend::Cpu => Err(
                "--devices all names every GPU, but --backend cpu renders on the CPU alone (give --backend auto, wgpu or cuda)".into(),
            ),
            _ => Ok(()),
        }
    }
}

/// Where the first preparation of a scene for a GPU went (`sdfc render --stats`): the
/// device opened and the kernel written; the driver's compile is the wgpu pipeline's
/// (`pipeline`) or the CUDA module's load ([`CudaModule`]).
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

/// The device of a render being opened on a thread of its own ([`Opening::start`], as soon as
/// the arguments name the backend) while the scene is read, checked and lowered and its kernel
/// written: opening a device is most of the first second of `sdfc render` that is not the
/// driver's floor (BENCHMARKS.md, "The first second"). [`Prepared::opened`] joins it where
/// the device is needed. Dropped unjoined (a scene with errors), the thread is left to finish
/// or to end with the process.
#[derive(Debug)]
pub struct Opening {
    backend: Backend,
    thread: std::thread::JoinHandle<Opened>,
}

/// What an [`Opening`]'s thread opened, and how long that took there.
#[derive(Debug)]
struct Opened {
    /// The CUDA device (`--backend cuda`, or `auto` first).
    cuda: Option<Result<Cuda, gpu::cuda::Error>>,
    /// The wgpu device (`--backend wgpu`; for `auto`, a hardware adapter's, opened only when
    /// CUDA could not be).
    wgpu: Option<Result<Gpu, gpu::Error>>,
    took: Duration,
}

impl Opening {
    /// Starts opening the device [`Prepared::from_program`] would open for `backend` at
    /// `precision`; `None` where it opens none (the CPU, or `auto` in f64).
    pub fn start(backend: Backend, precision: Precision) -> Option<Opening> {
        let open: fn() -> Opened = match backend {
            Backend::Cpu => return None,
            Backend::Auto if precision == Precision::F64 => return None,
            Backend::Cuda => || Opened {
                cuda: Some(Cuda::open()),
                wgpu: None,
                took: Duration::ZERO,
            },
            Backend::Wgpu => || Opened {
                cuda: None,
                wgpu: Some(Gpu::open(false)),
                took: Duration::ZERO,
            },
            Backend::Auto => || {
                let cuda = Cuda::open();
                let wgpu = cuda.is_err().then(|| Gpu::open(true));
                Opened {
                    cuda: Some(cuda),
                    wgpu,
                    took: Duration::ZERO,
                }
            },
        };
        let thread = std::thread::Builder::new()
            .name("sdfc device".into())
            .spawn(move || {
                let start = Instant::now();
                let opened = open();
                Opened {
                    took: start.elapsed(),
                    ..opened
                }
            })
            .ok()?;
        Some(Opening { backend, thread })
    }

    /// The backend it opens for.
    pub fn backend(&self) -> Backend {
        self.backend
    }

    /// Waits for the thread: what it opened, and how long this waited.
    fn join(self) -> Result<(Opened, Duration), String> {
        let start = Instant::now();
        let opened = self
            .thread
            .join()
            .map_err(|_| "the thread opening the device panicked".to_string())?;
        Ok((opened, start.elapsed()))
    }
}

/// A kernel loaded on a CUDA device, with what its launches need and the WGSL text it was
/// translated from.
#[derive(Debug)]
pub struct CudaModule {
    loaded: gpu::cuda::Loaded,
    data: Option<Vec<u8>>,
    contract: wgsl::Contract,
    ptx_time: Duration,
    source: String,
    interpreted: bool,
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
pub fn method_allowed(scene: &Scene, traceable: &Traceable) -> Result<(), String> {
    if scene.settings.method == Method::Trace {
        if let Choice::March(reason) = traceable.choose(scene.settings.method) {
            return Err(format!(
                "this scene cannot be ray traced analytically: {}; use method=auto or method=march",
                reason.describe()
            ));
        }
    }
    Ok(())
}

impl Prepared {
    /// Prepares `scene` for `backend`. `Err` says why the backend cannot be used.
    pub fn new(backend: Backend, scene: &Scene, precision: Precision) -> Result<Prepared, String> {
        let setup = Setup {
            precision,
            ..Setup::default()
        };
        let lowered = lower::lower_scene(scene, &LowerOptions::default());
        Self::from_program(backend, scene, lowered, &setup)
    }

    /// Prepares `scene`, lowered as `lowered` (its program and what else the backends
    /// read), for `backend`.
    pub fn from_program(
        backend: Backend,
        scene: &Scene,
        lowered: Lowered,
        setup: &Setup,
    ) -> Result<Prepared, String> {
        method_allowed(scene, &lowered.traceable)?;
        match backend {
            Backend::Cpu => Ok(Self::cpu(scene, lowered, setup)),
            Backend::Wgpu => Self::wgpu(scene, &lowered, setup, false),
            Backend::Cuda => Self::cuda(scene, &lowered, setup, Cuda::open),
            Backend::Auto if setup.precision == Precision::F64 => {
                Ok(Self::cpu(scene, lowered, setup))
            }
            Backend::Auto => Self::cuda(scene, &lowered, setup, Cuda::open)
                .or_else(|_| Self::wgpu(scene, &lowered, setup, true))
                .or_else(|_| Ok(Self::cpu(scene, lowered, setup))),
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
    ) -> Result<Prepared, String> {
        let Some(list) = devices.resolve(backend)? else {
            return Self::from_program(backend, scene, lowered, setup);
        };
        method_allowed(scene, &lowered.traceable)?;
        let mut parts = Vec::with_capacity(list.len());
        for d in &list {
            let part = match *d {
                Device::Cpu => Self::cpu(scene, lowered.clone(), setup),
                Device::Gpu(i) => {
                    match Self::gpu_kind(backend)? {
                        Backend::Cuda => {
                            // On a stream of its own: the same index twice is two logical
                            // devices on one GPU, running side by side.
                            Self::cuda(scene, &lowered, setup, || Cuda::open_device(i, true))?
                        }
                        _ => {
                            let gpu = Gpu::open_index(i).map_err(|e| e.to_string())?;
                            Self::on_gpu(Arc::new(gpu), scene, &lowered, setup)?
                        }
                    }
                }
            };
            parts.push(part);
        }
        Ok(match parts.len() {
            1 => parts.remove(0),
            _ => Prepared::Several(parts),
        })
    }

    /// Whose GPUs `--devices` indexes: CUDA's or wgpu's (for `auto`, CUDA's where a driver
    /// has devices).
    fn gpu_kind(backend: Backend) -> Result<Backend, String> {
        match backend {
            Backend::Cuda | Backend::Wgpu => Ok(backend),
            Backend::Auto if Cuda::count() > 0 => Ok(Backend::Cuda),
            Backend::Auto => Ok(Backend::Wgpu),
            Backend::Cpu => Err(
                "--devices names GPUs, but --backend cpu renders on the CPU alone (give --backend auto, wgpu or cuda)".into(),
            ),
        }
    }

    /// The CPU's preparation: the tapes, prepared now where `scene` is marched (a traced
    /// scene never evaluates its program).
    fn cpu(scene: &Scene, lowered: Lowered, setup: &Setup) -> Prepared {
        let options = Options {
            precision: setup.precision,
            debug_nan: setup.debug_nan,
            lipschitz: lowered.program.lipschitz(),
            ..Options::default()
        };
        let started = Instant::now();
        let tapes = Box::new(Tapes::of(lowered));
        if tapes.traceable().traced(scene.settings.method).is_none() {
            tapes.prepare();
        }
        Prepared::Cpu {
            tapes,
            options,
            taped: started.elapsed(),
        }
    }

    fn kernel(scene: &Scene, lowered: &Lowered, setup: &Setup) -> Result<wgsl::Kernel, String> {
        let options = Self::kernel_options(setup);
        wgsl::choose(scene, lowered, &options)?;
        wgsl::write_with(scene, lowered, &options).map_err(|e| e.to_string())
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
    fn kernel_text(scene: &Scene, lowered: &Lowered, setup: &Setup) -> Result<wgsl::Text, String> {
        let options = Self::kernel_options(setup);
        wgsl::choose(scene, lowered, &options)?;
        wgsl::write_text(scene, lowered, &options).map_err(|e| e.to_string())
    }

    fn wgpu(
        scene: &Scene,
        lowered: &Lowered,
        setup: &Setup,
        require_hardware: bool,
    ) -> Result<Prepared, String> {
        let start = Instant::now();
        let gpu = Gpu::open(require_hardware).map_err(|e| e.to_string())?;
        let device = start.elapsed();
        let prepared = Self::on_gpu(Arc::new(gpu), scene, lowered, setup)?;
        Self::with_pipeline(prepared, device, None)
    }

    /// A wgpu preparation with its pipeline created now, so that the first render does not
    /// include the driver's compile; `device` and `overlapped` are its device's opening
    /// ([`Preparation`]).
    fn with_pipeline(
        mut prepared: Prepared,
        device: Duration,
        overlapped: Option<Duration>,
    ) -> Result<Prepared, String> {
        if let Prepared::Wgpu {
            gpu,
            kernel,
            timing,
            ..
        } = &mut prepared
        {
            let data = kernel.data.is_some();
            let module = Some(&kernel.module);
            let pipeline = gpu.pipeline_for(&kernel.source, module, wgsl::ENTRY_POINT, data);
            timing.pipeline = Some(pipeline.map_err(|e| e.to_string())?);
            timing.device = device;
            timing.overlapped = overlapped;
        }
        Ok(prepared)
    }

    /// The setup of a kernel on a wgpu adapter: on a CPU adapter (lavapipe) the interpreted
    /// kernel's frames are 25 to 150 times the specialised kernel's (BENCHMARKS.md,
    /// "Interpreted against specialised"), which its compile never repays, so `auto` keeps
    /// the specialised kernel there, and for the frames of a sequence (`parameters`), which
    /// share one specialised kernel. A CPU adapter's setup is marked [`Setup::software`].
    fn wgpu_setup(cpu_adapter: bool, setup: &Setup) -> Setup {
        let setup = if cpu_adapter || setup.parameters {
            setup.specialised_for_auto()
        } else {
            *setup
        };
        Setup {
            software: cpu_adapter,
            ..setup
        }
    }

    /// [`Prepared::from_program`] on the device `opening` opens: its kernel is written while
    /// the device opens (for `auto`, the CUDA kernel where a CUDA driver is installed), and
    /// the thread is joined where the device is needed. The errors are those of
    /// [`Prepared::from_program`], the device's before the kernel's, and `auto` falls back as
    /// it does.
    pub fn opened(
        opening: Opening,
        scene: &Scene,
        lowered: Lowered,
        setup: &Setup,
    ) -> Result<Prepared, String> {
        method_allowed(scene, &lowered.traceable)?;
        let timed = |setup: &Setup| {
            let start = Instant::now();
            (Self::kernel(scene, &lowered, setup), start.elapsed())
        };
        match opening.backend {
            Backend::Cuda => {
                let kernel = timed(&setup.on_cuda());
                let (opened, waited) = opening.join()?;
                let cuda = opened.cuda.ok_or("no CUDA device was opened")?;
                let cuda = cuda.map_err(|e| e.to_string())?;
                let timing = Preparation {
                    device: waited,
                    kernel: kernel.1,
                    pipeline: None,
                    overlapped: Some(opened.took),
                };
                Self::cuda_prepared(cuda, kernel.0?, &lowered, setup, timing)
            }
            Backend::Wgpu => {
                let hardware = Self::wgpu_setup(false, setup);
                let kernel = timed(&hardware);
                let (opened, waited) = opening.join()?;
                let gpu = opened.wgpu.ok_or("no wgpu device was opened")?;
                let gpu = gpu.map_err(|e| e.to_string())?;
                let timing = (waited, opened.took);
                Self::wgpu_opened(gpu, scene, &lowered, setup, (hardware, kernel), timing)
            }
            _ => {
                let kernel = Cuda::driver_present().then(|| timed(&setup.on_cuda()));
                let (opened, waited) = opening.join()?;
                let cuda = match (opened.cuda, kernel) {
                    (Some(Ok(cuda)), Some((kernel, time))) => {
                        let timing = Preparation {
                            device: waited,
                            kernel: time,
                            pipeline: None,
                            overlapped: Some(opened.took),
                        };
                        kernel.and_then(|k| Self::cuda_prepared(cuda, k, &lowered, setup, timing))
                    }
                    (Some(Ok(cuda)), None) => Self::cuda(scene, &lowered, setup, || Ok(cuda)),
                    _ => Err("no CUDA device".into()),
                };
                cuda.or_else(|_| match opened.wgpu {
                    Some(Ok(gpu)) => {
                        let hardware = Self::wgpu_setup(false, setup);
                        let kernel = timed(&hardware);
                        let timing = (waited, opened.took);
                        Self::wgpu_opened(gpu, scene, &lowered, setup, (hardware, kernel), timing)
                    }
                    Some(Err(e)) => Err(e.to_string()),
                    // CUDA opened, and its kernel failed: a GPU adapter, as `from_program`.
                    None => Self::wgpu(scene, &lowered, setup, true),
                })
                .or_else(|_| Ok(Self::cpu(scene, lowered, setup)))
            }
        }
    }

    /// A wgpu preparation on `gpu`, opened on an [`Opening`]'s thread in `took` while this
    /// waited `waited` for it, with the kernel `written` (and the time it took) for the
    /// setup `hardware` before the adapter was known: it serves when it is the kernel this
    /// adapter's setup writes (only `wgsl::choose` reads the kernel choice, so a specialised
    /// kernel is the same under either), and the kernel is written again otherwise.
    fn wgpu_opened(
        gpu: Gpu,
        scene: &Scene,
        lowered: &Lowered,
        setup: &Setup,
        (hardware, written): (Setup, (Result<wgsl::Kernel, String>, Duration)),
        (waited, took): (Duration, Duration),
    ) -> Result<Prepared, String> {
        let setup = Self::wgpu_setup(gpu.is_cpu(), setup);
        let (kernel, time) = match written {
            (k, time) if setup == hardware || k.as_ref().is_ok_and(|k| !k.interpreted()) => {
                (k?, time)
            }
            _ => {
                let start = Instant::now();
                (Self::kernel(scene, lowered, &setup)?, start.elapsed())
            }
        };
        let prepared = Prepared::Wgpu {
            gpu: Arc::new(gpu),
            kernel: Box::new(kernel),
            lipschitz: lowered.program.lipschitz(),
            lowered: Box::new(lowered.clone()),
            setup,
            timing: Preparation {
                kernel: time,
                ..Preparation::default()
            },
        };
        Self::with_pipeline(prepared, waited, Some(took))
    }

    /// Prepares `scene`, lowered as `lowered`, for wgpu on an already opened device:
    /// generates and validates the kernel (its pipeline is compiled, or found in the
    /// device's cache, at the first render or by [`Gpu::pipeline_for`]).
    pub fn on_gpu(
        gpu: Arc<Gpu>,
        scene: &Scene,
        lowered: &Lowered,
        setup: &Setup,
    ) -> Result<Prepared, String> {
        Self::on_gpu_after(gpu, scene, lowered, setup, None).map(|(p, _)| p)
    }

    /// [`Prepared::on_gpu`], reusing `held`'s validated kernel when the new kernel's text is
    /// the same (with [`Setup::parameters`], a program that differs from `held`'s only in
    /// numbers): only its `scene_data` is new. Also says whether a kernel was built.
    fn on_gpu_after(
        gpu: Arc<Gpu>,
        scene: &Scene,
        lowered: &Lowered,
        setup: &Setup,
        held: Option<&wgsl::Kernel>,
    ) -> Result<(Prepared, bool), String> {
        method_allowed(scene, &lowered.traceable)?;
        let setup = &Self::wgpu_setup(gpu.is_cpu(), setup);
        let start = Instant::now();
        let (kernel, built) = match held {
            Some(held) => {
                let text = Self::kernel_text(scene, lowered, setup)?;
                if text.source == held.source {
                    let mut kernel = held.clone();
                    kernel.data = text.data;
                    (kernel, false)
                } else {
                    (Self::kernel(scene, lowered, setup)?, true)
                }
            }
            None => (Self::kernel(scene, lowered, setup)?, true),
        };
        let timing = Preparation {
            kernel: start.elapsed(),
            ..Preparation::default()
        };
        let prepared = Prepared::Wgpu {
            gpu,
            kernel: Box::new(kernel),
            lipschitz: lowered.program.lipschitz(),
            lowered: Box::new(lowered.clone()),
            setup: *setup,
            timing,
        };
        Ok((prepared, built))
    }

    /// `scene`, lowered as `lowered`, prepared as this is (the same backend, device and
    /// setup), leaving this as it is: a wgpu kernel whose text is unchanged is reused
    /// ([`Prepared::on_gpu_after`]); the CPU's tapes are made again. Also says whether a
    /// kernel (or the tapes) was built. The viewer keeps its last good scene until the new one
    /// is ready; a sequence replaces its scene with [`Prepared::update`].
    pub fn next(&self, scene: &Scene, lowered: Lowered) -> Result<(Prepared, bool), String> {
        match self {
            Prepared::Cpu { options, .. } => {
                let setup = Setup {
                    precision: options.precision,
                    debug_nan: options.debug_nan,
                    parameters: false,
                    kernel: wgsl::KernelChoice::default(),
                    image_only: false,
                    finished: false,
                    software: false,
                };
                Ok((Self::on_cpu(scene, lowered, &setup)?, true))
            }
            Prepared::Wgpu {
                gpu, kernel, setup, ..
            } => Self::on_gpu_after(gpu.clone(), scene, &lowered, setup, Some(kernel)),
            Prepared::Cuda { .. } | Prepared::Several(_) => Err(
                "CUDA kernels and several devices are prepared again with Prepared::update".into(),
            ),
        }
    }

    /// [`Prepared::next`] with the wgpu kernel `kernel` instead of this one's choice (the
    /// viewer shows a scene through the interpreted kernel while its specialised kernel
    /// compiles); the same as `next` for the CPU.
    pub fn next_with(
        &self,
        scene: &Scene,
        lowered: Lowered,
        kernel: wgsl::KernelChoice,
    ) -> Result<(Prepared, bool), String> {
        match self {
            Prepared::Wgpu {
                gpu,
                kernel: held,
                setup,
                ..
            } => {
                let setup = Setup { kernel, ..*setup };
                Self::on_gpu_after(gpu.clone(), scene, &lowered, &setup, Some(held))
            }
            _ => self.next(scene, lowered),
        }
    }

    /// Prepares `scene`, lowered as `lowered`, for the CPU renderer.
    pub fn on_cpu(scene: &Scene, lowered: Lowered, setup: &Setup) -> Result<Prepared, String> {
        method_allowed(scene, &lowered.traceable)?;
        Ok(Self::cpu(scene, lowered, setup))
    }

    /// Prepares `scene` on the CUDA device `open` opens (timing its opening).
    fn cuda(
        scene: &Scene,
        lowered: &Lowered,
        setup: &Setup,
        open: impl FnOnce() -> Result<Cuda, gpu::cuda::Error>,
    ) -> Result<Prepared, String> {
        let start = Instant::now();
        let cuda = open().map_err(|e| e.to_string())?;
        let device = start.elapsed();
        let start = Instant::now();
        let kernel = Self::kernel(scene, lowered, &setup.on_cuda())?;
        let timing = Preparation {
            device,
            kernel: start.elapsed(),
            ..Preparation::default()
        };
        Self::cuda_prepared(cuda, kernel, lowered, setup, timing)
    }

    /// The CUDA preparation of `kernel` (written for `lowered`) on `cuda`: translated to PTX
    /// and loaded.
    fn cuda_prepared(
        cuda: Cuda,
        kernel: wgsl::Kernel,
        lowered: &Lowered,
        setup: &Setup,
        timing: Preparation,
    ) -> Result<Prepared, String> {
        let module = Self::cuda_module_of(&cuda, kernel)?;
        Ok(Prepared::Cuda {
            cuda: Box::new(cuda),
            module: Box::new(module),
            lipschitz: lowered.program.lipschitz(),
            lowered: Box::new(lowered.clone()),
            setup: *setup,
            timing,
        })
    }

    /// Writes the kernel for `scene`, translates it to PTX and loads it on `cuda`.
    fn cuda_module(
        cuda: &Cuda,
        scene: &Scene,
        lowered: &Lowered,
        setup: &Setup,
    ) -> Result<CudaModule, String> {
        Self::cuda_module_of(cuda, Self::kernel(scene, lowered, &setup.on_cuda())?)
    }

    /// Translates `kernel` to PTX and loads it on `cuda`.
    fn cuda_module_of(cuda: &Cuda, kernel: wgsl::Kernel) -> Result<CudaModule, String> {
        let start = Instant::now();
        let options = ptx::Options {
            sm: cuda.sm,
            entry_point: wgsl::ENTRY_POINT.to_string(),
        };
        let ptx = ptx::write(&kernel.module, &kernel.info, &options).map_err(|e| e.to_string())?;
        let ptx_time = start.elapsed();
        let marched = !kernel.contract.has("ANALYTIC");
        let loaded = cuda
            .load(&ptx, wgsl::ENTRY_POINT, gpu::cuda::register_cap(marched))
            .map_err(|e| e.to_string())?;
        Ok(CudaModule {
            interpreted: kernel.interpreted(),
            loaded,
            data: kernel.data,
            contract: kernel.contract,
            ptx_time,
            source: kernel.source,
        })
    }

    /// Prepares `scene`, lowered as `lowered`, in place of the scene this was prepared for,
    /// keeping the device: a GPU kernel whose text is unchanged (with [`Setup::parameters`], a
    /// program that differs only in numbers) is kept and given the new `scene_data`; another
    /// is compiled. Returns whether a kernel (or the CPU's tapes) was built.
    pub fn update(&mut self, scene: &Scene, lowered: Lowered) -> Result<bool, String> {
        method_allowed(scene, &lowered.traceable)?;
        match self {
            Prepared::Cpu { .. } | Prepared::Wgpu { .. } => {
                let (next, built) = self.next(scene, lowered)?;
                *self = next;
                Ok(built)
            }
            Prepared::Cuda {
                cuda,
                module,
                lipschitz,
                lowered: held,
                setup,
                ..
            } => {
                method_allowed(scene, &lowered.traceable)?;
                let text = Self::kernel_text(scene, &lowered, setup)?;
                let built = text.source != module.source;
                if built {
                    **module = Self::cuda_module_of(
                        cuda,
                        Self::kernel(scene, &lowered, &setup.on_cuda())?,
                    )?;
                } else {
                    module.data = text.data;
                }
                *lipschitz = lowered.program.lipschitz();
                **held = lowered;
                Ok(built)
            }
            Prepared::Several(parts) => {
                let mut built = false;
                for p in parts {
                    built |= p.update(scene, lowered.clone())?;
                }
                Ok(built)
            }
        }
    }

    /// The contract of the GPU kernel: what it was specialised for and what it reads
    /// (`None` on the CPU, which reads every setting at every render).
    pub fn contract(&self) -> Option<&wgsl::Contract> {
        match self {
            Prepared::Cpu { .. } => None,
            Prepared::Wgpu { kernel, .. } => Some(&kernel.contract),
            Prepared::Cuda { module, .. } => Some(&module.contract),
            Prepared::Several(parts) => parts.iter().find_map(|p| p.contract()),
        }
    }

    /// Specialises the GPU kernel again when `scene` needs other features than it has
    /// (another method, over-relaxation on or off, another `max_depth`, soft shadows where
    /// the kernel has hard ones, ...: [`wgsl::Contract::check`]): a sweep of ω from 1 up must
    /// turn `RELAX` on. Keeps the device; nothing to do on the CPU. Says whether a kernel was
    /// written.
    pub fn specialise(&mut self, scene: &Scene) -> Result<bool, String> {
        if self.check_contract(scene).is_ok() {
            return Ok(false);
        }
        match self {
            Prepared::Cpu { .. } => Ok(false),
            Prepared::Wgpu {
                kernel,
                lowered,
                setup,
                ..
            } => {
                method_allowed(scene, &lowered.traceable)?;
                **kernel = Self::kernel(scene, lowered, setup)?;
                Ok(true)
            }
            Prepared::Cuda {
                cuda,
                module,
                lowered,
                setup,
                ..
            } => {
                method_allowed(scene, &lowered.traceable)?;
                // The same device and context; the new module replaces the old one.
                **module = Self::cuda_module(cuda, scene, lowered, setup)?;
                Ok(true)
            }
            Prepared::Several(parts) => {
                let mut again = false;
                for p in parts {
                    again |= p.specialise(scene)?;
                }
                Ok(again)
            }
        }
    }

    /// `Err` when `scene` needs a kernel specialised otherwise than this one
    /// ([`wgsl::Contract::check`]; [`Prepared::specialise`] writes it again): a render never
    /// silently ignores a setting or a feature of the scene.
    fn check_contract(&self, scene: &Scene) -> Result<(), String> {
        let (Some(contract), Some(lowered)) = (self.contract(), self.lowered()) else {
            return Ok(());
        };
        let traced = lowered.traceable.traced(scene.settings.method).is_some();
        contract.check(scene, traced).map_err(|m| {
            format!(
                "the {} kernel cannot render this scene: {m}; specialise it again",
                self.name()
            )
        })
    }

    /// The setup of a GPU kernel (of the first GPU device of several).
    fn setup(&self) -> Option<&Setup> {
        match self {
            Prepared::Cpu { .. } => None,
            Prepared::Wgpu { setup, .. } | Prepared::Cuda { setup, .. } => Some(setup),
            Prepared::Several(parts) => parts.iter().find_map(|p| p.setup()),
        }
    }

    /// The lowered scene a GPU kernel was written from.
    fn lowered(&self) -> Option<&Lowered> {
        match self {
            Prepared::Cpu { .. } => None,
            Prepared::Wgpu { lowered, .. } | Prepared::Cuda { lowered, .. } => Some(lowered),
            Prepared::Several(parts) => parts.iter().find_map(|p| p.lowered()),
        }
    }

    /// The backend's name, as in `--backend`.
    pub fn name(&self) -> &'static str {
        match self {
            Prepared::Cpu { .. } => "cpu",
            Prepared::Wgpu { .. } => "wgpu",
            Prepared::Cuda { .. } => "cuda",
            Prepared::Several(parts) => {
                let first = parts.first().map_or("cpu", |p| p.name());
                if parts.iter().all(|p| p.name() == first) {
                    first
                } else {
                    "mixed"
                }
            }
        }
    }

    /// The device, for messages.
    pub fn device(&self) -> String {
        match self {
            Prepared::Cpu { .. } => format!("CPU, {} threads", rayon::current_num_threads()),
            Prepared::Wgpu { gpu, .. } => gpu.describe(),
            Prepared::Cuda { cuda, .. } => cuda.describe(),
            Prepared::Several(parts) => {
                let each: Vec<String> = parts.iter().map(|p| p.device()).collect();
                format!("{} devices: {}", parts.len(), each.join(" + "))
            }
        }
    }

    /// The GPU kernel's kind, for `--stats` and `sdfc bench`: "specialised" or
    /// "interpreted" (`None` on the CPU).
    pub fn kernel_kind(&self) -> Option<&'static str> {
        let interpreted = match self {
            Prepared::Cpu { .. } => return None,
            Prepared::Wgpu { kernel, .. } => kernel.interpreted(),
            Prepared::Cuda { module, .. } => module.interpreted,
            Prepared::Several(parts) => return parts.iter().find_map(|p| p.kernel_kind()),
        };
        Some(if interpreted {
            "interpreted"
        } else {
            "specialised"
        })
    }

    /// Where the first preparation for a GPU went, for `--stats`: (phase, time, how) for
    /// the device, the kernel, its PTX and the driver's compile; on the CPU, the tapes.
    pub fn preparation(&self) -> Vec<(&'static str, Duration, String)> {
        let mut parts = self.preparation_parts();
        // A device opened beside the front end was waited for after the kernel was written:
        // the phases in the order they ended.
        if let Prepared::Wgpu { timing, .. } | Prepared::Cuda { timing, .. } = self {
            if timing.overlapped.is_some() && parts.len() >= 2 {
                parts.swap(0, 1);
            }
        }
        parts
    }

    /// [`Prepared::preparation`], the device first.
    fn preparation_parts(&self) -> Vec<(&'static str, Duration, String)> {
        use gpu::wgpu::DriverCache;
        match self {
            Prepared::Cpu { taped, tapes, .. } => vec![(
                "tapes",
                *taped,
                if tapes.prepared() {
                    "the distance program prepared for the interpreter (distance, material, media)"
                        .into()
                } else {
                    "none: the scene is traced, the interpreter does not run".into()
                },
            )],
            // Several devices: the first device's (they are prepared one after another).
            Prepared::Several(parts) => parts.first().map(|p| p.preparation()).unwrap_or_default(),
            Prepared::Wgpu { timing, .. } => {
                let mut out = vec![(
                    "device",
                    timing.device,
                    timing.opening("wgpu adapters enumerated, device opened"),
                )];
                out.extend([(
                    "kernel",
                    timing.kernel,
                    "WGSL written and validated by naga".into(),
                )]);
                if let Some(p) = timing.pipeline {
                    let how = match p.driver {
                        DriverCache::NotAsked => "found among this device's pipelines".into(),
                        DriverCache::Unsupported => {
                            "pipeline created (the adapter keeps no pipeline cache)".into()
                        }
                        DriverCache::Written(n) => {
                            format!("pipeline compiled, {n} bytes of driver cache data stored")
                        }
                        DriverCache::Read(n) => {
                            format!("pipeline created from {n} bytes of stored driver cache data")
                        }
                    };
                    out.push(("driver compile", p.time, how));
                }
                out
            }
            Prepared::Cuda { timing, module, .. } => vec![
                (
                    "device",
                    timing.device,
                    timing.opening("CUDA context created"),
                ),
                (
                    "kernel",
                    timing.kernel,
                    "WGSL written and validated by naga".into(),
                ),
                (
                    "PTX",
                    module.ptx_time,
                    "translated from the naga module".into(),
                ),
                (
                    "driver compile",
                    module.loaded.load_time,
                    if module.loaded.cached {
                        "module read from the JIT cache and loaded".into()
                    } else {
                        "module compiled by the driver JIT and loaded".into()
                    },
                ),
            ],
        }
    }

    /// The most memory rendering `settings` allocates (with the current pool's threads on
    /// the CPU), the finished frame included.
    pub fn memory(&self, scene: &Scene, settings: &Settings) -> Memory {
        let mut at = scene.clone();
        at.settings = settings.clone();
        match self {
            Prepared::Cpu { tapes, options, .. } => Memory {
                host: cpu::memory(&at, tapes, options, rayon::current_num_threads()),
                device: 0,
            },
            Prepared::Wgpu { kernel, .. } => gpu::memory_wgpu(
                settings,
                kernel.contract.uniform.size.into(),
                bytes(&kernel.data),
            ),
            Prepared::Cuda { module, .. } => gpu::memory_cuda(
                settings,
                module.contract.uniform.size.into(),
                bytes(&module.data),
            ),
            // Each device holds a whole frame's buffers; the bands read back and the image
            // they are assembled into are no more than one device's whole readback.
            Prepared::Several(parts) => parts.iter().fold(Memory::default(), |m, p| {
                let d = p.memory(scene, settings);
                Memory {
                    host: m.host + d.host,
                    device: m.device + d.device,
                }
            }),
        }
    }

    /// The bytes a finished frame holds (its image and, on the CPU, its depth buffers).
    pub fn retained(&self, settings: &Settings) -> u64 {
        match self {
            Prepared::Cpu { .. } => cpu::retained(settings),
            Prepared::Several(parts) if parts.len() == 1 => parts[0].retained(settings),
            _ => gpu::retained(settings),
        }
    }

    /// Instructions of the distance program (CPU) or of the kernel's `map` (GPU).
    pub fn program_len(&self) -> usize {
        match self {
            Prepared::Cpu { tapes, .. } => tapes.program().len(),
            Prepared::Wgpu { lowered, .. } | Prepared::Cuda { lowered, .. } => {
                lowered.program.len()
            }
            Prepared::Several(parts) => parts.first().map_or(0, |p| p.program_len()),
        }
    }

    /// The scene's primitives, or why it cannot be traced analytically, as lowered.
    pub fn traceable(&self) -> &Traceable {
        match self {
            Prepared::Cpu { tapes, .. } => tapes.traceable(),
            Prepared::Wgpu { lowered, .. } | Prepared::Cuda { lowered, .. } => &lowered.traceable,
            Prepared::Several(parts) => parts[0].traceable(),
        }
    }

    /// Renders one frame; `progress` gets the fraction done. The faults of the testing aid
    /// `SDFC_FAULT_AFTER_TILES` are injected.
    pub fn render(&self, scene: &Scene, progress: &(dyn Fn(f64) + Sync)) -> Result<Frame, String> {
        self.render_faults(scene, progress, &gpu::launch::Faults::from_env())
    }

    /// [`Prepared::render`] with the faults `faults` injected.
    pub fn render_faults(
        &self,
        scene: &Scene,
        progress: &(dyn Fn(f64) + Sync),
        faults: &gpu::launch::Faults,
    ) -> Result<Frame, String> {
        self.check_contract(scene)?;
        let statistics = !self.setup().is_some_and(|s| s.image_only);
        let finished = self.setup().is_some_and(|s| s.finished);
        match self {
            Prepared::Cpu { tapes, options, .. } => {
                let tiles = cpu::tile_count(&scene.settings, options).max(1) as f64;
                let done = std::sync::atomic::AtomicU64::new(0);
                let start = Instant::now();
                let render = cpu::render_tapes(scene, tapes, options, &|| {
                    let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                    progress(n as f64 / tiles);
                });
                let time = start.elapsed();
                Ok(Frame {
                    render,
                    time,
                    wall: time,
                    phases: None,
                    shares: Vec::new(),
                    finished: None,
                })
            }
            Prepared::Wgpu {
                gpu,
                kernel,
                lipschitz,
                ..
            } => {
                let r = gpu::render_faults(
                    gpu,
                    scene,
                    kernel,
                    *lipschitz,
                    (faults, statistics, finished),
                    &mut |f| progress(f),
                )
                .map_err(|e| e.to_string())?;
                Ok(Frame::of(r))
            }
            Prepared::Cuda {
                cuda,
                module,
                lipschitz,
                ..
            } => {
                let r = gpu::render_cuda(
                    cuda,
                    scene,
                    (
                        &module.loaded,
                        &module.contract.uniform,
                        module.data.as_deref(),
                    ),
                    *lipschitz,
                    (faults, statistics, finished),
                    &mut |f| progress(f),
                )
                .map_err(|e| e.to_string())?;
                Ok(Frame::of(r))
            }
            Prepared::Several(parts) => {
                let mut workers: Vec<Box<dyn gpu::launch::Worker + '_>> = Vec::new();
                let mut data = None;
                let mut uniform = None;
                let mut lipschitz = 1.0;
                for p in parts {
                    match p {
                        Prepared::Cpu { tapes, options, .. } => {
                            workers.push(Box::new(gpu::cpu::Device::new(scene, tapes, options)))
                        }
                        Prepared::Wgpu {
                            gpu,
                            kernel,
                            lipschitz: l,
                            ..
                        } => {
                            data = kernel.data.as_deref();
                            uniform = Some(&kernel.contract.uniform);
                            lipschitz = *l;
                            workers.push(Box::new(gpu.kernel(
                                &kernel.source,
                                wgsl::ENTRY_POINT,
                                wgsl::WORKGROUP,
                            )));
                        }
                        Prepared::Cuda {
                            cuda,
                            module,
                            lipschitz: l,
                            ..
                        } => {
                            data = module.data.as_deref();
                            uniform = Some(&module.contract.uniform);
                            lipschitz = *l;
                            workers.push(Box::new(cuda.kernel(&module.loaded, wgsl::WORKGROUP)));
                        }
                        Prepared::Several(_) => {
                            return Err("several devices cannot hold several devices".into())
                        }
                    }
                }
                let workers: Vec<&dyn gpu::launch::Worker> =
                    workers.iter().map(|w| w.as_ref()).collect();
                let r = gpu::render_several(
                    &workers,
                    scene,
                    (lipschitz, uniform, data),
                    (faults, statistics, finished),
                    &mut |f| progress(f),
                )?;
                Ok(Frame::of(r))
            }
        }
    }
}

impl Frame {
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

impl memory::Footprint for Prepared {
    fn memory(&self, scene: &Scene, settings: &Settings) -> Memory {
        Prepared::memory(self, scene, settings)
    }

    fn retained(&self, settings: &Settings) -> u64 {
        Prepared::retained(self, settings)
    }
}
