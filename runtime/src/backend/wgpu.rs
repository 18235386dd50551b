//! wgpu behind [`Renderer`]: the device (which may be shared, as the viewer shares its
//! window's), the validated kernel, and what it takes to write the kernel again.

use super::{
    kernel, written, Error, Frame, Next, Part, Preparation, Prepared, Progress, Renderer, Setup,
};
use crate::gpu::{self, launch::Faults, Gpu};
use crate::memory::Memory;
use sdfc_compiler::{analytic::Traceable, wgsl, Lowered, Scene, Settings};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// A scene prepared for wgpu: the device, the validated kernel and the scene's Lipschitz bound
/// L (and the lowered scene and setup, to specialise the kernel again for other settings).
#[derive(Debug)]
pub struct WgpuPrepared {
    /// The device.
    pub gpu: Arc<Gpu>,
    /// The kernel.
    pub kernel: Box<wgsl::Kernel>,
    /// The scene's Lipschitz bound L.
    pub lipschitz: f64,
    lowered: Box<Lowered>,
    setup: Setup,
    timing: Preparation,
}

impl WgpuPrepared {
    /// Opens a wgpu device (a hardware adapter's when `require_hardware`) and prepares
    /// `scene` on it, its pipeline created now.
    pub(super) fn open(
        scene: &Scene,
        lowered: &Lowered,
        setup: &Setup,
        require_hardware: bool,
    ) -> Result<WgpuPrepared, Error> {
        let start = Instant::now();
        let gpu = Gpu::open(require_hardware)?;
        let device = start.elapsed();
        let (prepared, _) = Self::on_gpu_after(Arc::new(gpu), scene, lowered, setup, None)?;
        prepared.with_pipeline(device, None)
    }

    /// This preparation with its pipeline created now, so that the first render does not
    /// include the driver's compile; `device` and `overlapped` are its device's opening
    /// ([`Preparation`]).
    fn with_pipeline(
        mut self,
        device: Duration,
        overlapped: Option<Duration>,
    ) -> Result<WgpuPrepared, Error> {
        let data = self.kernel.data.is_some();
        let module = Some(&self.kernel.module);
        let pipeline = self
            .gpu
            .pipeline_for(&self.kernel.source, module, wgsl::ENTRY_POINT, data);
        self.timing.pipeline = Some(pipeline?);
        self.timing.device = device;
        self.timing.overlapped = overlapped;
        Ok(self)
    }

    /// The setup of a kernel on a wgpu adapter: on a CPU adapter (lavapipe) the interpreted
    /// kernel's frames are 25 to 150 times the specialised kernel's, which its compile never
    /// repays, so `auto` keeps the specialised kernel there, and for the frames of a sequence
    /// (`parameters`), which share one specialised kernel. A CPU adapter's setup is marked
    /// [`Setup::software`], and counts its cut loops whatever [`Setup::image_only`] asks.
    pub(super) fn setup_for(cpu_adapter: bool, setup: &Setup) -> Setup {
        let setup = if cpu_adapter || setup.parameters {
            setup.specialised_for_auto()
        } else {
            *setup
        };
        // Its frames always count their cut loops (`render` refuses a frame with any), even
        // where the caller wants the image alone (`sdfc render` without `--stats`).
        Setup {
            software: cpu_adapter,
            image_only: setup.image_only && !cpu_adapter,
            ..setup
        }
    }

    /// A wgpu preparation on `gpu`, opened on an [`super::Opening`]'s thread in `took` while
    /// this waited `waited` for it, with the kernel `written` (and the time it took) for the
    /// setup `hardware` before the adapter was known: it serves when it is the kernel this
    /// adapter's setup writes (only `wgsl::choose` reads the kernel choice, so a specialised
    /// kernel is the same under either), and the kernel is written again otherwise.
    pub(super) fn opened(
        gpu: Gpu,
        scene: &Scene,
        lowered: &Lowered,
        setup: &Setup,
        (hardware, written): (Setup, (Result<wgsl::Kernel, Error>, Duration)),
        (waited, took): (Duration, Duration),
    ) -> Result<WgpuPrepared, Error> {
        let setup = Self::setup_for(gpu.is_cpu(), setup);
        let (kernel, time) = match written {
            (k, time) if setup == hardware || k.as_ref().is_ok_and(|k| !k.interpreted()) => {
                (k?, time)
            }
            _ => {
                let start = Instant::now();
                (kernel(scene, lowered, &setup)?, start.elapsed())
            }
        };
        let prepared = WgpuPrepared {
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
        prepared.with_pipeline(waited, Some(took))
    }

    /// Prepares `scene`, lowered as `lowered`, on `gpu`, reusing `held`'s validated kernel
    /// when the new kernel's text is the same (with [`Setup::parameters`], a program that
    /// differs from `held`'s only in numbers): only its `scene_data` is new. Also says whether
    /// a kernel was built. The pipeline is compiled, or found in the device's cache, at the
    /// first render or by [`Gpu::pipeline_for`].
    pub(super) fn on_gpu_after(
        gpu: Arc<Gpu>,
        scene: &Scene,
        lowered: &Lowered,
        setup: &Setup,
        held: Option<&wgsl::Kernel>,
    ) -> Result<(WgpuPrepared, bool), Error> {
        super::method_allowed(scene, &lowered.traceable)?;
        let setup = &Self::setup_for(gpu.is_cpu(), setup);
        let start = Instant::now();
        let (kernel, built) = match held {
            Some(held) => {
                let text = written(scene, lowered, setup, wgsl::write_text)?;
                if text.source == held.source {
                    let mut kernel = held.clone();
                    kernel.data = text.data;
                    (kernel, false)
                } else {
                    (super::kernel(scene, lowered, setup)?, true)
                }
            }
            None => (super::kernel(scene, lowered, setup)?, true),
        };
        let timing = Preparation {
            kernel: start.elapsed(),
            ..Preparation::default()
        };
        let prepared = WgpuPrepared {
            gpu,
            kernel: Box::new(kernel),
            lipschitz: lowered.program.lipschitz(),
            lowered: Box::new(lowered.clone()),
            setup: *setup,
            timing,
        };
        Ok((prepared, built))
    }
}

impl Renderer for WgpuPrepared {
    fn name(&self) -> &'static str {
        "wgpu"
    }

    fn device(&self) -> String {
        self.gpu.describe()
    }

    fn kernel_kind(&self) -> Option<&'static str> {
        Some(super::kind(self.kernel.interpreted()))
    }

    fn preparation(&self) -> Vec<(&'static str, Duration, String)> {
        use gpu::wgpu::DriverCache;
        let timing = &self.timing;
        let mut out = vec![
            (
                "device",
                timing.device,
                timing.opening("wgpu adapters enumerated, device opened"),
            ),
            (
                "kernel",
                timing.kernel,
                "WGSL written and validated by naga".into(),
            ),
        ];
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
        timing.ordered(out)
    }

    fn memory(&self, _: &Scene, settings: &Settings) -> Memory {
        gpu::memory_wgpu(
            settings,
            self.kernel.contract.uniform.size.into(),
            super::bytes(&self.kernel.data),
        )
    }

    fn program_len(&self) -> usize {
        self.lowered.program.len()
    }

    fn traceable(&self) -> &Traceable {
        &self.lowered.traceable
    }

    fn contract(&self) -> Option<&wgsl::Contract> {
        Some(&self.kernel.contract)
    }

    fn setup(&self) -> Option<&Setup> {
        Some(&self.setup)
    }

    fn reduce_statistics(&mut self, on: bool) {
        // A software adapter's frames always count their cut loops (`render` checks them).
        self.setup.image_only = !on && !self.setup.software;
    }

    fn render(&self, scene: &Scene, progress: Progress, faults: &Faults) -> Result<Frame, Error> {
        let r = gpu::render_faults(
            &self.gpu,
            scene,
            &self.kernel,
            self.lipschitz,
            (faults, !self.setup.image_only, self.setup.finished),
            &mut |f| progress(f),
        )?;
        let cut = r.render.stats.counters.cut;
        if cut > 0 {
            return Err(Error::Cut {
                adapter: self.gpu.describe(),
                cut,
            });
        }
        Ok(Frame::of(r))
    }

    fn part<'a>(&'a self, _: &'a Scene) -> Result<Part<'a>, Error> {
        Ok(Part {
            worker: Box::new(self.gpu.kernel(
                &self.kernel.source,
                wgsl::ENTRY_POINT,
                wgsl::WORKGROUP,
            )),
            kernel: Some((
                self.lipschitz,
                &self.kernel.contract.uniform,
                self.kernel.data.as_deref(),
            )),
        })
    }

    fn next(&self, scene: &Scene, lowered: Lowered, kernel: Option<wgsl::KernelChoice>) -> Next {
        let setup = Setup {
            kernel: kernel.unwrap_or(self.setup.kernel),
            ..self.setup
        };
        let held = Some(&*self.kernel);
        let (next, built) = Self::on_gpu_after(self.gpu.clone(), scene, &lowered, &setup, held)?;
        Ok((Prepared::of(next), built))
    }

    fn update(&mut self, scene: &Scene, lowered: Lowered) -> Result<bool, Error> {
        let held = Some(&*self.kernel);
        let (next, built) =
            Self::on_gpu_after(self.gpu.clone(), scene, &lowered, &self.setup, held)?;
        *self = next;
        Ok(built)
    }

    fn specialise(&mut self, scene: &Scene) -> Result<bool, Error> {
        super::method_allowed(scene, &self.lowered.traceable)?;
        *self.kernel = kernel(scene, &self.lowered, &self.setup)?;
        Ok(true)
    }

    fn as_wgpu(&self) -> Option<&WgpuPrepared> {
        Some(self)
    }
}
