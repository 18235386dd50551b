//! Backends behind one interface: a scene is prepared once for a backend (program lowered,
//! tapes or kernel generated, device opened, module loaded) and then rendered any number of
//! times; what a render allocates is known before it starts ([`Prepared::memory`]).

use crate::cpu::{self, Options, Precision, Render, Tapes};
use crate::gpu::{self, cuda::Cuda, Gpu};
use crate::memory::{self, Memory};
use sdfc_compiler::back::{ptx, wgsl};
use sdfc_compiler::lower::{self, LowerOptions, Lowered};
use sdfc_compiler::program::Program;
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
}

/// A scene prepared for one backend.
#[derive(Debug)]
pub enum Prepared {
    /// CPU: the distance program, its tapes and the render options.
    Cpu {
        program: Program,
        tapes: Box<Tapes>,
        options: Options,
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
    },
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
            Backend::Cpu => Ok(Self::cpu(lowered, setup)),
            Backend::Wgpu => Self::wgpu(scene, &lowered, setup, false),
            Backend::Cuda => Self::cuda(scene, &lowered, setup),
            Backend::Auto if setup.precision == Precision::F64 => Ok(Self::cpu(lowered, setup)),
            Backend::Auto => Self::cuda(scene, &lowered, setup)
                .or_else(|_| Self::wgpu(scene, &lowered, setup, true))
                .or_else(|_| Ok(Self::cpu(lowered, setup))),
        }
    }

    fn cpu(lowered: Lowered, setup: &Setup) -> Prepared {
        let options = Options {
            precision: setup.precision,
            debug_nan: setup.debug_nan,
            lipschitz: lowered.program.lipschitz(),
            ..Options::default()
        };
        Prepared::Cpu {
            tapes: Box::new(Tapes::new(&lowered)),
            program: lowered.program,
            options,
        }
    }

    fn kernel(scene: &Scene, lowered: &Lowered, setup: &Setup) -> Result<wgsl::Kernel, String> {
        wgsl::write_with(scene, lowered, &Self::kernel_options(setup)).map_err(|e| e.to_string())
    }

    fn kernel_options(setup: &Setup) -> wgsl::Options {
        wgsl::Options {
            debug_nan: setup.debug_nan,
            parameters: setup.parameters,
            ..wgsl::Options::default()
        }
    }

    /// The text and data of the kernel for `scene`, not validated (to compare with a kernel
    /// held).
    fn kernel_text(scene: &Scene, lowered: &Lowered, setup: &Setup) -> Result<wgsl::Text, String> {
        wgsl::write_text(scene, lowered, &Self::kernel_options(setup)).map_err(|e| e.to_string())
    }

    fn wgpu(
        scene: &Scene,
        lowered: &Lowered,
        setup: &Setup,
        require_hardware: bool,
    ) -> Result<Prepared, String> {
        let gpu = Gpu::open(require_hardware).map_err(|e| e.to_string())?;
        Self::on_gpu(Arc::new(gpu), scene, lowered, setup)
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
        let prepared = Prepared::Wgpu {
            gpu,
            kernel: Box::new(kernel),
            lipschitz: lowered.program.lipschitz(),
            lowered: Box::new(lowered.clone()),
            setup: *setup,
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
                };
                Ok((Self::on_cpu(scene, lowered, &setup)?, true))
            }
            Prepared::Wgpu {
                gpu, kernel, setup, ..
            } => Self::on_gpu_after(gpu.clone(), scene, &lowered, setup, Some(kernel)),
            Prepared::Cuda { .. } => {
                Err("a CUDA kernel is prepared again with Prepared::update".into())
            }
        }
    }

    /// Prepares `scene`, lowered as `lowered`, for the CPU renderer.
    pub fn on_cpu(scene: &Scene, lowered: Lowered, setup: &Setup) -> Result<Prepared, String> {
        method_allowed(scene, &lowered.traceable)?;
        Ok(Self::cpu(lowered, setup))
    }

    fn cuda(scene: &Scene, lowered: &Lowered, setup: &Setup) -> Result<Prepared, String> {
        let cuda = Cuda::open().map_err(|e| e.to_string())?;
        let module = Self::cuda_module(&cuda, scene, lowered, setup)?;
        Ok(Prepared::Cuda {
            cuda: Box::new(cuda),
            module: Box::new(module),
            lipschitz: lowered.program.lipschitz(),
            lowered: Box::new(lowered.clone()),
            setup: *setup,
        })
    }

    /// Writes the kernel for `scene`, translates it to PTX and loads it on `cuda`.
    fn cuda_module(
        cuda: &Cuda,
        scene: &Scene,
        lowered: &Lowered,
        setup: &Setup,
    ) -> Result<CudaModule, String> {
        Self::cuda_module_of(cuda, Self::kernel(scene, lowered, setup)?)
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
        let loaded = cuda
            .load(&ptx, wgsl::ENTRY_POINT)
            .map_err(|e| e.to_string())?;
        Ok(CudaModule {
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
            } => {
                method_allowed(scene, &lowered.traceable)?;
                let text = Self::kernel_text(scene, &lowered, setup)?;
                let built = text.source != module.source;
                if built {
                    **module = Self::cuda_module_of(cuda, Self::kernel(scene, &lowered, setup)?)?;
                } else {
                    module.data = text.data;
                }
                *lipschitz = lowered.program.lipschitz();
                **held = lowered;
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

    /// The lowered scene a GPU kernel was written from.
    fn lowered(&self) -> Option<&Lowered> {
        match self {
            Prepared::Cpu { .. } => None,
            Prepared::Wgpu { lowered, .. } | Prepared::Cuda { lowered, .. } => Some(lowered),
        }
    }

    /// The backend's name, as in `--backend`.
    pub fn name(&self) -> &'static str {
        match self {
            Prepared::Cpu { .. } => "cpu",
            Prepared::Wgpu { .. } => "wgpu",
            Prepared::Cuda { .. } => "cuda",
        }
    }

    /// The device, for messages.
    pub fn device(&self) -> String {
        match self {
            Prepared::Cpu { .. } => format!("CPU, {} threads", rayon::current_num_threads()),
            Prepared::Wgpu { gpu, .. } => gpu.describe(),
            Prepared::Cuda { cuda, .. } => cuda.describe(),
        }
    }

    /// How the backend was prepared, for `--stats`: PTX generation and JIT times for CUDA.
    pub fn preparation(&self) -> Option<String> {
        match self {
            Prepared::Cuda { module, .. } => Some(format!(
                "PTX generated in {:.2} ms; module {} in {:.1} ms",
                module.ptx_time.as_secs_f64() * 1e3,
                if module.loaded.cached {
                    "read from the JIT cache and loaded"
                } else {
                    "compiled by the driver JIT and loaded"
                },
                module.loaded.load_time.as_secs_f64() * 1e3
            )),
            _ => None,
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
        }
    }

    /// The bytes a finished frame holds (its image and, on the CPU, its depth buffers).
    pub fn retained(&self, settings: &Settings) -> u64 {
        match self {
            Prepared::Cpu { .. } => cpu::retained(settings),
            _ => gpu::retained(settings),
        }
    }

    /// Instructions of the distance program (CPU) or of the kernel's `map` (GPU).
    pub fn program_len(&self) -> usize {
        match self {
            Prepared::Cpu { program, .. } => program.len(),
            Prepared::Wgpu { lowered, .. } | Prepared::Cuda { lowered, .. } => {
                lowered.program.len()
            }
        }
    }

    /// The scene's primitives, or why it cannot be traced analytically, as lowered.
    pub fn traceable(&self) -> &Traceable {
        match self {
            Prepared::Cpu { tapes, .. } => tapes.traceable(),
            Prepared::Wgpu { lowered, .. } | Prepared::Cuda { lowered, .. } => &lowered.traceable,
        }
    }

    /// Renders one frame; `progress` gets the fraction done.
    pub fn render(&self, scene: &Scene, progress: &(dyn Fn(f64) + Sync)) -> Result<Frame, String> {
        self.check_contract(scene)?;
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
                })
            }
            Prepared::Wgpu {
                gpu,
                kernel,
                lipschitz,
                ..
            } => {
                let r = gpu::render(gpu, scene, kernel, *lipschitz, &mut |f| progress(f))
                    .map_err(|e| e.to_string())?;
                Ok(Frame {
                    render: r.render,
                    time: r.time,
                    wall: r.wall,
                    phases: Some(r.phases),
                })
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
                    &module.loaded,
                    &module.contract.uniform,
                    module.data.as_deref(),
                    *lipschitz,
                )
                .map_err(|e| e.to_string())?;
                progress(1.0);
                Ok(Frame {
                    render: r.render,
                    time: r.time,
                    wall: r.wall,
                    phases: Some(r.phases),
                })
            }
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
