//! A scene prepared for its backend ([`Prepared`]'s constructors): the method checked, the GPU
//! kernel chosen, written and validated, the devices opened or given, and a later frame's scene
//! given to the kernel prepared before.

use super::cpu::CpuPrepared;
use super::cuda::CudaPrepared;
use super::devices::{gpu_kind, Device, Devices};
use super::several::SeveralPrepared;
use super::wgpu::WgpuPrepared;
use super::{Backend, Error, Next, Prepared, Renderer, Setup};
use crate::cpu::Precision;
use crate::gpu::{cuda::Cuda, Gpu};
use sdfc_compiler::{
    analytic::{Choice, Traceable},
    lower_scene, wgsl, LowerOptions, Lowered, Method, Scene,
};
use std::sync::Arc;

/// `Err` when the scene's settings ask for analytic tracing (`method=trace`) of a scene that
/// does not allow it, saying why, from the primitives the lowering found (`traceable`):
/// `sdfc render` refuses such settings before preparing a backend.
pub fn method_allowed(scene: &Scene, traceable: &Traceable) -> Result<(), Error> {
    if scene.settings.method == Method::Trace {
        if let Choice::March(reason) = traceable.choose(scene.settings.method) {
            return Err(Error::NotTraceable(reason));
        }
    }
    Ok(())
}

/// The kernel for `scene`, chosen (`wgsl::choose`), written and validated.
pub(super) fn kernel(
    scene: &Scene,
    lowered: &Lowered,
    setup: &Setup,
) -> Result<wgsl::Kernel, Error> {
    written(scene, lowered, setup, wgsl::write_with)
}

/// What `write` makes of the kernel for `scene` once it is chosen (`wgsl::choose`):
/// `wgsl::write_with`, the kernel validated, or `wgsl::write_text`, its text and data alone
/// (to compare with a kernel held).
pub(super) fn written<T>(
    scene: &Scene,
    lowered: &Lowered,
    setup: &Setup,
    write: fn(&Scene, &Lowered, &wgsl::Options) -> Result<T, wgsl::Error>,
) -> Result<T, Error> {
    let options = kernel_options(setup);
    wgsl::choose(scene, lowered, &options)?;
    Ok(write(scene, lowered, &options)?)
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

impl Prepared {
    /// `backend` prepared.
    pub(super) fn of(backend: impl Renderer + 'static) -> Prepared {
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
                        let gpu = Gpu::open_index(i)?;
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
    pub fn next(&self, scene: &Scene, lowered: Lowered) -> Next {
        self.0.next(scene, lowered, None)
    }

    /// [`Prepared::next`] with the wgpu kernel `kernel` instead of this one's choice (the
    /// viewer shows a scene through the interpreted kernel while its specialised kernel
    /// compiles); the same as `next` for the CPU.
    pub fn next_with(&self, scene: &Scene, lowered: Lowered, kernel: wgsl::KernelChoice) -> Next {
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
        contract
            .check(scene, traced)
            .map_err(|mismatch| Error::Stale {
                kernel: self.name(),
                mismatch,
            })
    }
}
