//! CUDA behind [`Renderer`]: the device, the kernel translated to PTX and loaded as a module,
//! and what it takes to write the kernel again.

use super::{kernel, written, Error, Frame, Part, Preparation, Progress, Renderer, Setup};
use crate::gpu::{self, cuda::Cuda, launch::Faults};
use crate::memory::Memory;
use sdfc_compiler::{analytic::Traceable, ptx, wgsl, Lowered, Scene, Settings};
use std::time::{Duration, Instant};

/// A scene prepared for CUDA: the device, the loaded module (with the kernel's scene data and
/// the settings it was specialised for) and the scene's Lipschitz bound L (and the lowered
/// scene and setup, to specialise the kernel again for other settings).
#[derive(Debug)]
pub struct CudaPrepared {
    cuda: Box<Cuda>,
    module: Box<CudaModule>,
    lipschitz: f64,
    lowered: Box<Lowered>,
    setup: Setup,
    timing: Preparation,
}

/// A kernel loaded on a CUDA device, with what its launches need and the WGSL text it was
/// translated from.
#[derive(Debug)]
struct CudaModule {
    loaded: gpu::cuda::Loaded,
    data: Option<Vec<u8>>,
    contract: wgsl::Contract,
    ptx_time: Duration,
    source: String,
    interpreted: bool,
}

impl CudaPrepared {
    /// Prepares `scene` on the CUDA device `open` opens (timing its opening).
    pub(super) fn open(
        scene: &Scene,
        lowered: &Lowered,
        setup: &Setup,
        open: impl FnOnce() -> Result<Cuda, gpu::cuda::Error>,
    ) -> Result<CudaPrepared, Error> {
        let start = Instant::now();
        let cuda = open()?;
        let device = start.elapsed();
        let start = Instant::now();
        let kernel = kernel(scene, lowered, &setup.on_cuda())?;
        let timing = Preparation {
            device,
            kernel: start.elapsed(),
            ..Preparation::default()
        };
        Self::new(cuda, kernel, lowered, setup, timing)
    }

    /// The CUDA preparation of `kernel` (written for `lowered`) on `cuda`: translated to PTX
    /// and loaded.
    pub(super) fn new(
        cuda: Cuda,
        kernel: wgsl::Kernel,
        lowered: &Lowered,
        setup: &Setup,
        timing: Preparation,
    ) -> Result<CudaPrepared, Error> {
        let module = CudaModule::load(&cuda, kernel)?;
        Ok(CudaPrepared {
            cuda: Box::new(cuda),
            module: Box::new(module),
            lipschitz: lowered.program.lipschitz(),
            lowered: Box::new(lowered.clone()),
            setup: *setup,
            timing,
        })
    }
}

impl CudaModule {
    /// Translates `kernel` to PTX and loads it on `cuda`.
    fn load(cuda: &Cuda, kernel: wgsl::Kernel) -> Result<CudaModule, Error> {
        let start = Instant::now();
        let options = ptx::Options {
            sm: cuda.sm,
            entry_point: wgsl::ENTRY_POINT.to_string(),
        };
        let ptx = ptx::write(&kernel.module, &kernel.info, &options)?;
        let ptx_time = start.elapsed();
        let tracing = match (kernel.contract.has("ANALYTIC"), kernel.contract.has("PATH")) {
            (true, _) => gpu::cuda::Tracing::Analytic,
            (false, true) => gpu::cuda::Tracing::MarchedPaths,
            (false, false) => gpu::cuda::Tracing::Marched,
        };
        let loaded = cuda.load(&ptx, wgsl::ENTRY_POINT, gpu::cuda::register_cap(tracing))?;
        Ok(CudaModule {
            interpreted: kernel.interpreted(),
            loaded,
            data: kernel.data,
            contract: kernel.contract,
            ptx_time,
            source: kernel.source,
        })
    }
}

impl Renderer for CudaPrepared {
    fn name(&self) -> &'static str {
        "cuda"
    }

    fn device(&self) -> String {
        self.cuda.describe()
    }

    fn kernel_kind(&self) -> Option<&'static str> {
        Some(super::kind(self.module.interpreted))
    }

    fn preparation(&self) -> Vec<(&'static str, Duration, String)> {
        let (timing, module) = (&self.timing, &self.module);
        timing.ordered(vec![
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
        ])
    }

    fn memory(&self, _: &Scene, settings: &Settings) -> Memory {
        gpu::memory_cuda(
            settings,
            self.module.contract.uniform.size.into(),
            super::bytes(&self.module.data),
        )
    }

    fn program_len(&self) -> usize {
        self.lowered.program.len()
    }

    fn traceable(&self) -> &Traceable {
        &self.lowered.traceable
    }

    fn contract(&self) -> Option<&wgsl::Contract> {
        Some(&self.module.contract)
    }

    fn setup(&self) -> Option<&Setup> {
        Some(&self.setup)
    }

    fn reduce_statistics(&mut self, on: bool) {
        self.setup.image_only = !on;
    }

    fn render(&self, scene: &Scene, progress: Progress, faults: &Faults) -> Result<Frame, Error> {
        let module = &self.module;
        let r = gpu::render_cuda(
            &self.cuda,
            scene,
            (
                &module.loaded,
                &module.contract.uniform,
                module.data.as_deref(),
            ),
            self.lipschitz,
            (faults, !self.setup.image_only, self.setup.finished),
            &mut |f| progress(f),
        )?;
        Ok(Frame::of(r))
    }

    fn part<'a>(&'a self, _: &'a Scene) -> Result<Part<'a>, Error> {
        let module = &self.module;
        Ok(Part {
            worker: Box::new(self.cuda.kernel(&module.loaded, wgsl::WORKGROUP)),
            kernel: Some((
                self.lipschitz,
                &module.contract.uniform,
                module.data.as_deref(),
            )),
        })
    }

    fn update(&mut self, scene: &Scene, lowered: Lowered) -> Result<bool, Error> {
        let text = written(scene, &lowered, &self.setup, wgsl::write_text)?;
        let built = text.source != self.module.source;
        if built {
            let kernel = kernel(scene, &lowered, &self.setup.on_cuda())?;
            *self.module = CudaModule::load(&self.cuda, kernel)?;
        } else {
            self.module.data = text.data;
        }
        self.lipschitz = lowered.program.lipschitz();
        *self.lowered = lowered;
        Ok(built)
    }

    fn specialise(&mut self, scene: &Scene) -> Result<bool, Error> {
        super::method_allowed(scene, &self.lowered.traceable)?;
        // The same device and context; the new module replaces the old one.
        let kernel = kernel(scene, &self.lowered, &self.setup.on_cuda())?;
        *self.module = CudaModule::load(&self.cuda, kernel)?;
        Ok(true)
    }
}
