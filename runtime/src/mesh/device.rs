//! Where the mesher's points are evaluated (`sdfc mesh --backend`): the CPU's f64
//! interpreter, or a GPU running the compiler's points kernel in f32 (`gpu::points`: the one
//! WGSL module, through wgpu, or translated to PTX, through CUDA; the launch is all that
//! differs). [`Field`](super::Field) asks its `Gpu` for each batch (an octree level, the
//! corners, one round of root finding, the gradients' samples), which is one launch per
//! [`POINTS_PER_DISPATCH`](crate::gpu::points::POINTS_PER_DISPATCH) points, in buffers kept
//! from one batch to the next.

use crate::backend::Backend;
use crate::gpu::points::{self as on_gpu, CudaDevice, CudaPoints, WgpuPoints};
use crate::gpu::Gpu as WgpuDevice;
use sdfc_compiler::{Lowered, Scene};
use std::sync::{Arc, Mutex, OnceLock, PoisonError};

/// The rounding of an f32 evaluation, relative to the largest coordinate of the region
/// meshed (2⁻¹⁶, about 128 ulps of f32): what [`Gpu::rounding`] allows for in the octree's
/// test, so that no cell holding surface is pruned for it.
const F32_ROUNDING: f64 = 1.0 / 65_536.0;

/// The least step of a gradient's samples on the GPU, relative to the largest coordinate of
/// the region meshed (2⁻¹⁶), where the CPU's f64 takes 10⁻⁴ of a cell: the sample points
/// and their distances are rounded to f32 (a relative 2⁻²⁴ of the coordinates), so a
/// difference over a step of 2⁻¹⁶ carries an error of a few 2⁻⁸ of the gradient at worst
/// (the samples' errors mostly cancel), while a longer step mixes the normals of the faces
/// beside a sharp edge. On the bracket at resolutions 64 and 256, 2⁻¹⁶ kept every vertex
/// nearest the CPU's (within 0.3 % of a cell) of the steps 2⁻¹² to 2⁻²⁰.
const F32_GRADIENT_STEP: f64 = 1.0 / 65_536.0;

/// The devices a process opens once, shared by every mesh it makes (the parts of a 3MF, a
/// mesh made again on finer cells).
fn wgpu_device() -> Result<&'static Arc<WgpuDevice>, &'static crate::gpu::wgpu::Error> {
    static WGPU: OnceLock<Result<Arc<WgpuDevice>, crate::gpu::wgpu::Error>> = OnceLock::new();
    WGPU.get_or_init(|| WgpuDevice::open(false).map(Arc::new))
        .as_ref()
}

fn cuda_device() -> Result<&'static CudaDevice, &'static on_gpu::RunError> {
    static CUDA: OnceLock<Result<CudaDevice, on_gpu::RunError>> = OnceLock::new();
    CUDA.get_or_init(on_gpu::open_cuda).as_ref()
}

/// Why a GPU cannot evaluate a mesher's points.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum OpenError {
    /// `--backend cpu` or `auto` resolved to the CPU, which evaluates in the field itself.
    #[error("the CPU evaluates in the field itself, not as a GPU")]
    NotAGpu,
    /// The backend found no device: which backend, what it looked for and why.
    #[error(
        "--backend {backend} cannot mesh here: found no {device} ({why}); mesh with --backend cpu"
    )]
    NoDevice {
        backend: &'static str,
        device: &'static str,
        why: String,
    },
    /// The scene's points kernel cannot be written, translated or loaded.
    #[error("--backend {backend} cannot mesh this scene: its distance kernel cannot be written ({why}); mesh it with --backend cpu")]
    Kernel { backend: &'static str, why: String },
}

/// The backend `--backend` names, with `auto` resolved as `render` resolves it for one
/// device: CUDA where a driver has a device, else a wgpu GPU adapter (not a software one),
/// else the CPU.
pub fn resolve(backend: Backend) -> Backend {
    match backend {
        Backend::Auto if crate::gpu::cuda::Cuda::count() > 0 => Backend::Cuda,
        Backend::Auto if WgpuDevice::open(true).is_ok() => Backend::Wgpu,
        Backend::Auto => Backend::Cpu,
        b => b,
    }
}

/// The points kernel of one scene on one GPU.
enum Kernel {
    Wgpu(&'static Arc<WgpuDevice>, WgpuPoints),
    Cuda(CudaPoints),
}

/// A scene's points kernel on a GPU, as the mesher's [`Field`](super::Field) evaluates it:
/// the distance and material of the scene's `map` at each point, in f32.
pub struct Gpu {
    kernel: Kernel,
    /// The backend's name, as `--backend` spells it.
    pub name: &'static str,
    /// The device, in words.
    pub device: String,
    /// The largest coordinate of the region meshed, which scales the f32 rounding.
    scale: f64,
    /// Why a launch failed, when one did: the later batches are not run.
    failed: Mutex<Option<String>>,
}

impl std::fmt::Debug for Gpu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Gpu")
            .field("name", &self.name)
            .field("device", &self.device)
            .finish_non_exhaustive()
    }
}

impl Gpu {
    /// The points kernel of `scene` (as `lowered`) on `backend` (wgpu or CUDA), for the
    /// region `clip`; `Err` says why it cannot be had (no device, or a scene the kernel
    /// cannot be written for), naming the backend.
    pub fn open(
        backend: Backend,
        scene: &Scene,
        lowered: &Lowered,
        clip: &[[f64; 3]; 2],
    ) -> Result<Gpu, OpenError> {
        let (name, on) = match backend {
            Backend::Wgpu => ("wgpu", "wgpu adapter"),
            Backend::Cuda => ("cuda", "CUDA device"),
            Backend::Cpu | Backend::Auto => return Err(OpenError::NotAGpu),
        };
        let no = |why: &dyn std::fmt::Display| OpenError::NoDevice {
            backend: name,
            device: on,
            why: why.to_string(),
        };
        let cannot = |why: &dyn std::fmt::Display| OpenError::Kernel {
            backend: name,
            why: why.to_string(),
        };
        let module = on_gpu::points_module(scene, lowered, false).map_err(|e| cannot(&e))?;
        let (kernel, device) = match backend {
            Backend::Cuda => {
                let (ctx, sm) = cuda_device().map_err(|e| no(e))?;
                let ptx = on_gpu::points_ptx(&module, *sm).map_err(|e| cannot(&e))?;
                let k = CudaPoints::new(ctx, &module, &ptx).map_err(|e| cannot(&e))?;
                (Kernel::Cuda(k), format!("CUDA device 0 (sm_{sm})"))
            }
            _ => {
                let gpu = wgpu_device().map_err(|e| no(e))?;
                (
                    Kernel::Wgpu(gpu, WgpuPoints::new(gpu, &module)),
                    gpu.describe(),
                )
            }
        };
        let scale = clip.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        Ok(Gpu {
            kernel,
            name,
            device,
            scale,
            failed: Mutex::new(None),
        })
    }

    /// The distance and material id at every point (f32, as the kernel computed them), or
    /// `None` once a launch has failed (this one or an earlier: [`Gpu::failure`] says why).
    pub fn run(&self, points: &[[f64; 3]]) -> Option<Vec<(f32, u32)>> {
        let mut failed = self.failed.lock().unwrap_or_else(PoisonError::into_inner);
        if failed.is_some() {
            return None;
        }
        let ran = match &self.kernel {
            Kernel::Wgpu(gpu, k) => k.run(gpu, points),
            Kernel::Cuda(k) => k.run(points),
        };
        match ran {
            Ok((values, _)) => Some(values),
            Err(e) => {
                *failed = Some(e.to_string());
                None
            }
        }
    }

    /// Why a launch failed, if one did.
    pub fn failure(&self) -> Option<String> {
        self.failed
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clone()
    }

    /// Launches so far.
    pub fn launches(&self) -> u64 {
        match &self.kernel {
            Kernel::Wgpu(_, k) => k.launches(),
            Kernel::Cuda(k) => k.launches(),
        }
    }

    /// How far a distance computed in f32 may be from the f64 one, at most (an allowance,
    /// not a proof: [`F32_ROUNDING`] of the region's scale).
    pub fn rounding(&self) -> f64 {
        F32_ROUNDING * self.scale
    }

    /// The least step of a gradient's samples ([`F32_GRADIENT_STEP`] of the region's scale).
    pub fn least_step(&self) -> f64 {
        F32_GRADIENT_STEP * self.scale
    }
}
