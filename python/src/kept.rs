//! What a scene keeps between calls of the native module: the render prepared last and the
//! distance kernel compiled last, so that `Scene.render` and `Scene.distance` asked again with
//! the same settings neither prepare the backend nor compile a kernel again.

use sdfc_compiler::Lowered;
use sdfc_runtime::backend::{Backend, Prepared};
use sdfc_runtime::gpu::points::{self as on_gpu, CudaPoints, RunError, WgpuPoints};
use std::sync::{Mutex, PoisonError};

/// A scene's kept preparations. Each is taken out while a call uses it and put back after,
/// so that calls from several threads never wait on each other (the later ones prepare
/// their own).
#[derive(Debug, Default)]
pub struct Kept {
    render: Mutex<Option<Render>>,
    points: Mutex<Option<Points>>,
}

/// The render prepared last: for the backend asked (`auto` included) and whether it keeps
/// the image alone.
#[derive(Debug)]
struct Render {
    backend: Backend,
    image_only: bool,
    prepared: Prepared,
}

/// The distance kernel compiled last: its backend and WGSL text.
#[derive(Debug)]
struct Points {
    backend: String,
    source: String,
    kernel: Kernel,
}

#[derive(Debug)]
enum Kernel {
    Wgpu(WgpuPoints),
    Cuda(CudaPoints),
}

/// Why distances at points could not be computed on a GPU (a `RuntimeError` in Python).
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// The module of distances at points cannot be written.
    #[error("{0}")]
    Module(#[from] sdfc_compiler::points::Error),
    /// The device cannot run it.
    #[error("{0}")]
    Run(#[from] RunError),
    /// There is no wgpu device: why, as it was first told.
    #[error("{0}")]
    NoWgpu(&'static sdfc_runtime::gpu::Error),
}

impl Kept {
    /// The render kept for `backend` and `image_only`, taken out (a kept one of other
    /// settings is dropped).
    pub fn take_render(&self, backend: Backend, image_only: bool) -> Option<Prepared> {
        let kept = self
            .render
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take()?;
        (kept.backend == backend && kept.image_only == image_only).then_some(kept.prepared)
    }

    /// Keeps `prepared`, the render of `backend` and `image_only`, for the next call.
    pub fn keep_render(&self, backend: Backend, image_only: bool, prepared: Prepared) {
        *self.render.lock().unwrap_or_else(PoisonError::into_inner) = Some(Render {
            backend,
            image_only,
            prepared,
        });
    }

    /// Distances (f32 bytes) and material ids (u32 bytes) at `points` (program coordinates)
    /// from the scene's WGSL part on a GPU: through wgpu, or as PTX through CUDA. The kernel
    /// is compiled again only where its text or backend differs from the one kept.
    pub fn distances(
        &self,
        backend: &str,
        scene: &sdfc_compiler::Scene,
        lowered: &Lowered,
        points: &[[f64; 3]],
    ) -> Result<(Vec<u8>, Vec<u8>), GpuError> {
        let module = on_gpu::points_module(scene, lowered, false)?;
        let kept = self
            .points
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take()
            .filter(|k| k.backend == backend && k.source == module.source);
        let kernel = match kept {
            Some(k) => k.kernel,
            None if backend == "cuda" => {
                let (ctx, sm) = super::cuda_device().as_ref().map_err(Clone::clone)?;
                let ptx = on_gpu::points_ptx(&module, *sm)?;
                Kernel::Cuda(CudaPoints::new(ctx, &module, &ptx)?)
            }
            None => {
                let gpu = super::wgpu_device().map_err(GpuError::NoWgpu)?;
                Kernel::Wgpu(WgpuPoints::new(gpu, &module))
            }
        };
        let (values, _) = match &kernel {
            Kernel::Cuda(k) => k.run(points)?,
            Kernel::Wgpu(k) => k.run(super::wgpu_device().map_err(GpuError::NoWgpu)?, points)?,
        };
        *self.points.lock().unwrap_or_else(PoisonError::into_inner) = Some(Points {
            backend: backend.to_string(),
            source: module.source,
            kernel,
        });
        let d = super::bytes(values.iter().map(|&(d, _)| d));
        let m = super::bytes(values.iter().map(|&(_, m)| m));
        Ok((d, m))
    }
}
