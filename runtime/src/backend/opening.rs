//! The device of a render opened on a thread of its own while the front end reads, checks
//! and lowers the scene ([`Opening`]), the preparation that joins it ([`Prepared::opened`]),
//! and the CUDA driver restricted to the devices a render opens ([`see_only`]).

use super::{kernel, CpuPrepared, CudaPrepared, Error, Preparation, Prepared, Setup, WgpuPrepared};
use super::{method_allowed, Backend, Device, Devices};
use crate::cpu::Precision;
use crate::gpu::{self, cuda::Cuda, Gpu};
use sdfc_compiler::{wgsl, Lowered, Scene};
use std::time::{Duration, Instant};

/// Restricts the CUDA driver of this process to the GPUs a render with `backend` on
/// `devices` opens ([`gpu::cuda::only_devices`]): device 0 for `--devices auto`, the GPUs of
/// a list; `all` opens every one. A CUDA context then costs its own GPU's initialisation, not
/// every GPU's of the host. Nothing for wgpu and the
/// CPU. Call it before any thread starts.
pub fn see_only(backend: Backend, devices: &Devices) {
    if !matches!(backend, Backend::Cuda | Backend::Auto) {
        return;
    }
    match devices {
        Devices::Auto => gpu::cuda::only_devices(&[0]),
        Devices::All => {}
        Devices::List(list) => {
            let gpus: Vec<usize> = list
                .iter()
                .filter_map(|d| match d {
                    Device::Gpu(i) => Some(*i),
                    Device::Cpu => None,
                })
                .collect();
            gpu::cuda::only_devices(&gpus);
        }
    }
}

/// The device of a render being opened on a thread of its own ([`Opening::start`], as soon as
/// the arguments name the backend) while the scene is read, checked and lowered and its kernel
/// written: opening a device is most of the first second of `sdfc render` that is not the
/// driver's floor. [`Prepared::opened`] joins it where
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
    fn join(self) -> Result<(Opened, Duration), Error> {
        let start = Instant::now();
        let opened = self.thread.join().map_err(|_| Error::OpeningPanicked)?;
        Ok((opened, start.elapsed()))
    }
}

impl Prepared {
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
    ) -> Result<Prepared, Error> {
        method_allowed(scene, &lowered.traceable)?;
        let timed = |setup: &Setup| {
            let start = Instant::now();
            (kernel(scene, &lowered, setup), start.elapsed())
        };
        let on_cuda =
            |cuda, (kernel, time): (Result<wgsl::Kernel, Error>, Duration), waited, took| {
                let timing = Preparation {
                    device: waited,
                    kernel: time,
                    pipeline: None,
                    overlapped: Some(took),
                };
                CudaPrepared::new(cuda, kernel?, &lowered, setup, timing).map(Prepared::of)
            };
        // The kernel for a hardware adapter, written before the adapter is known.
        let hardware = WgpuPrepared::setup_for(false, setup);
        let on_wgpu = |gpu, kernel, waited, took| {
            let timing = (waited, took);
            WgpuPrepared::opened(gpu, scene, &lowered, setup, (hardware, kernel), timing)
                .map(Prepared::of)
        };
        match opening.backend {
            Backend::Cuda => {
                let kernel = timed(&setup.on_cuda());
                let (opened, waited) = opening.join()?;
                let cuda = opened.cuda.ok_or(Error::NotOpened("CUDA"))?;
                let cuda = cuda?;
                on_cuda(cuda, kernel, waited, opened.took)
            }
            Backend::Wgpu => {
                let kernel = timed(&hardware);
                let (opened, waited) = opening.join()?;
                let gpu = opened.wgpu.ok_or(Error::NotOpened("wgpu"))?;
                let gpu = gpu?;
                on_wgpu(gpu, kernel, waited, opened.took)
            }
            _ => {
                let kernel = Cuda::driver_present().then(|| timed(&setup.on_cuda()));
                let (opened, waited) = opening.join()?;
                let cuda = match (opened.cuda, kernel) {
                    (Some(Ok(cuda)), Some(kernel)) => on_cuda(cuda, kernel, waited, opened.took),
                    (Some(Ok(cuda)), None) => {
                        CudaPrepared::open(scene, &lowered, setup, || Ok(cuda)).map(Prepared::of)
                    }
                    _ => Err(Error::NotOpened("CUDA")),
                };
                cuda.or_else(|_| match opened.wgpu {
                    Some(Ok(gpu)) => on_wgpu(gpu, timed(&hardware), waited, opened.took),
                    Some(Err(e)) => Err(Error::Wgpu(e)),
                    // CUDA opened, and its kernel failed: a GPU adapter, as `from_program`.
                    None => WgpuPrepared::open(scene, &lowered, setup, true).map(Prepared::of),
                })
                .or_else(|_| Ok(Prepared::of(CpuPrepared::new(scene, lowered, setup))))
            }
        }
    }
}
