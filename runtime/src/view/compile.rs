//! Pipelines compiled on a thread of their own, so that the viewer's window never waits for the
//! driver: while a new scene's specialised kernel compiles, the session shows it through the
//! interpreted kernel (once a short grace period has passed without it) or keeps the image
//! before on show, and it is told (the [`Waker`]) when the compile has ended. A new pipeline
//! is dispatched once there, on no pixels, for drivers that compile at the first dispatch.

use super::resident::{self, FirstFrame};
use crate::backend::Prepared;
use crate::gpu::wgpu::PipelineTime;
use sdfc_compiler::wgsl;
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// Called on the compiling thread once its compile has ended, successfully or not: wakes whoever
/// waits for it (the window's event loop, a headless loop).
#[derive(Clone)]
pub struct Waker(Arc<dyn Fn() + Send + Sync>);

impl Waker {
    /// A waker that calls `wake`.
    pub fn new(wake: impl Fn() + Send + Sync + 'static) -> Waker {
        Waker(Arc::new(wake))
    }

    /// Wakes.
    pub fn wake(&self) {
        (self.0)()
    }
}

impl std::fmt::Debug for Waker {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Waker")
    }
}

/// The stack of a compiling thread: wgpu's shader parsing and validation may recurse deeply
/// (`wgpu::Device::create_shader_module`); the window's thread has the main thread's 8 MiB.
const STACK: usize = 32 << 20;

/// The pipeline of a prepared wgpu kernel, compiling (or found among those compiled) on a thread
/// of its own ([`crate::gpu::Gpu::pipeline_for`], which keeps it for the renders to come).
#[derive(Debug)]
pub struct Compile {
    result: Arc<Mutex<Option<Result<PipelineTime, resident::Error>>>>,
    /// When it started.
    pub started: Instant,
}

impl Compile {
    /// Starts compiling `prepared`'s pipeline, calling `done` on the compiling thread once it
    /// has ended. `None` for a scene prepared for anything but wgpu (nothing to compile).
    /// Where no thread can be started, the pipeline is compiled before this returns.
    /// `first` is what the scene's first frame will read, for the kernel's first dispatch
    /// ([`crate::gpu::Gpu::warm`]).
    pub fn start(prepared: &Prepared, first: Option<FirstFrame>, done: Waker) -> Option<Compile> {
        let wgpu = prepared.as_wgpu()?;
        let (gpu, kernel) = (&wgpu.gpu, &wgpu.kernel);
        let started = Instant::now();
        let result = Arc::new(Mutex::new(None));
        let (gpu, source, module) = (gpu.clone(), kernel.source.clone(), kernel.module.clone());
        let data = kernel.data.is_some();
        let out = result.clone();
        let job = move || {
            // A new pipeline is dispatched once on no pixels, so that a driver that compiles
            // at the first dispatch (lavapipe) does it here, and its time is the compile's.
            let r = gpu
                .pipeline_for(&source, Some(&module), wgsl::ENTRY_POINT, data)
                .map_err(resident::Error::from)
                .and_then(|p| {
                    if p.cached {
                        return Ok(p);
                    }
                    let start = Instant::now();
                    let first = first.as_ref().map(|f| (&f.uniforms[..], f.tile));
                    gpu.warm((&source, wgsl::ENTRY_POINT, data), first)?;
                    Ok(PipelineTime {
                        time: p.time + start.elapsed(),
                        ..p
                    })
                });
            *out.lock().unwrap_or_else(|e| e.into_inner()) = Some(r);
            done.wake();
        };
        let job = Arc::new(Mutex::new(Some(job)));
        let run = job.clone();
        let spawned = std::thread::Builder::new()
            .name("sdfc view compile".into())
            .stack_size(STACK)
            .spawn(move || {
                if let Some(job) = run.lock().unwrap_or_else(|e| e.into_inner()).take() {
                    job();
                }
            });
        if spawned.is_err() {
            if let Some(job) = job.lock().unwrap_or_else(|e| e.into_inner()).take() {
                job();
            }
        }
        Some(Compile { result, started })
    }

    /// Whether the compile has ended (and its result is still to be taken).
    pub fn finished(&self) -> bool {
        self.lock().is_some()
    }

    /// The compile's result once it has ended; `None` before, and after it has been taken.
    pub fn take(&self) -> Option<Result<PipelineTime, resident::Error>> {
        self.lock().take()
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Option<Result<PipelineTime, resident::Error>>> {
        self.result.lock().unwrap_or_else(|e| e.into_inner())
    }
}
