//! A frame's scene prepared on its backend, on the device [`Open`] names or frame after frame by
//! [`Kernels`], and held to the memory limit for its [`Use`] ([`check_memory`]).

use super::{Error, FrameScene};
use crate::backend::{self, Backend, Devices, Opening, Prepared, Setup};
use crate::gpu::Gpu;
use crate::memory;
use sdfc_compiler::{wgsl, Limits, Program, Scene};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Where [`prepare`] finds the device it prepares a scene on.
#[derive(Debug)]
pub enum Open<'a> {
    /// The backend opens it, or several (`--devices`).
    Backend,
    /// Being opened on a thread of its own beside the front end (`sdfc render`; used for
    /// `--devices auto` when it opens for the backend asked, else the backend opens its own).
    Beside(Opening),
    /// The caller's wgpu device, open already: the viewer's window's (whose surface shows
    /// the frames it keeps on it), or the Python module's.
    Gpu(Arc<Gpu>),
    /// Where a scene before was prepared, as it was (its backend, device and setup), and left
    /// as it is: the viewer's later loads and the frames of its animation, whose last good
    /// scene stays on show until the new one is ready. The kernel is the one `setup` chooses,
    /// or with [`wgsl::KernelChoice::Auto`] the one before's; a GPU kernel whose text is
    /// unchanged (a program that differs in numbers only, with [`Setup::parameters`]) is kept
    /// and given the new `scene_data` ([`Prepared::next`]). The backend and devices asked are
    /// the ones before's.
    After(&'a Prepared),
    /// Where a scene before was prepared, taken over: its backend, device and setup, its GPU
    /// kernel kept where the new kernel's text is the same and given the new `scene_data`
    /// ([`Prepared::update`]): for a caller that has no more use for the scene before (the
    /// Python module's renders). Unlike [`Open::After`], every backend and set of devices
    /// can be taken over.
    Replacing(Prepared),
}

/// A frame's scene prepared on its backend ([`prepare`]).
#[derive(Debug)]
pub struct Ready {
    /// The scene.
    pub scene: Scene,
    /// The backend prepared for it.
    pub prepared: Prepared,
    /// Whether a kernel (or the CPU's tapes) was built: `false` where [`Open::After`] or
    /// [`Open::Replacing`] kept the kernel before.
    pub built: bool,
}

/// Prepares a frame's scene for `backend` on `devices` (or on the device `open` says) within
/// `pool`.
pub fn prepare(
    pool: &rayon::ThreadPool,
    on: (Backend, &Devices),
    frame: FrameScene,
    setup: &Setup,
    open: Open,
) -> Result<Ready, Error> {
    pool.install(|| prepare_here(on, frame, setup, open))
}

/// [`prepare`] on the current thread's pool (the viewer's, rayon's global one).
pub fn prepare_here(
    (backend, devices): (Backend, &Devices),
    frame: FrameScene,
    setup: &Setup,
    open: Open,
) -> Result<Ready, Error> {
    let FrameScene { scene, lowered, .. } = frame;
    // Settings the scene cannot be rendered with are the scene's fault, not the backend's
    // (`Job::frame` checks them first; the viewer's loads come here directly).
    backend::method_allowed(&scene, &lowered.traceable)?;
    // A kernel asked for that cannot render the scene is an error, not a reason to fall back
    // to another backend.
    if backend != Backend::Cpu {
        let options = wgsl::Options {
            kernel: setup.kernel,
            ..Default::default()
        };
        wgsl::choose(&scene, &lowered, &options).map_err(backend::Error::Refused)?;
    }
    let unavailable = |source| Error::unavailable(backend, source);
    let (prepared, built) = match open {
        // The device is open and the scene before prepared on it: what fails is this scene's
        // preparation.
        Open::After(before) => match setup.kernel {
            wgsl::KernelChoice::Auto => before.next(&scene, lowered)?,
            kernel => before.next_with(&scene, lowered, kernel)?,
        },
        Open::Replacing(mut before) => {
            let built = before.update(&scene, lowered)?;
            (before, built)
        }
        Open::Beside(o) if o.backend() == backend && *devices == Devices::Auto => (
            Prepared::opened(o, &scene, lowered, setup).map_err(unavailable)?,
            true,
        ),
        // An open device is available: what fails is the scene's preparation on it.
        Open::Gpu(gpu) if backend == Backend::Wgpu && *devices == Devices::Auto => {
            (Prepared::on_gpu(gpu, &scene, &lowered, setup)?, true)
        }
        _ => (
            Prepared::on_devices(backend, devices, &scene, lowered, setup).map_err(unavailable)?,
            true,
        ),
    };
    Ok(Ready {
        scene,
        prepared,
        built,
    })
}

/// What a prepared scene's frames are held to the `memory` limit for ([`check_memory`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Use {
    /// Rendered at the scene's settings and written (`sdfc render`, sequences, those of
    /// `bench --frames-per-second`, Python): the render, the finished frame held while its
    /// outputs are written, and with `reference` the reference's convergence check, with
    /// `aux` the depth sidecar ([`memory::render`]).
    Written {
        /// `--reference`.
        reference: bool,
        /// `--aux`.
        aux: bool,
    },
    /// Rendered at the scene's settings frame after frame, a finished frame held while the
    /// next renders (`sdfc bench`, which keeps its warm-up frame's statistics through the
    /// timed frames): the render and the frame held ([`memory::held`]).
    Held,
    /// Shown in a view of `width` × `height` pixels, whatever size the scene's settings
    /// state, one sample a frame (the viewer's window, which accumulates the samples where
    /// they are rendered): the frame's render alone.
    Shown {
        /// The view's width.
        width: u32,
        /// The view's height.
        height: u32,
    },
}

impl Use {
    /// An image written, without the reference's check or the depth sidecar.
    pub const IMAGE: Use = Use::Written {
        reference: false,
        aux: false,
    };
}

/// What frames of `scene` on `prepared` allocate, used as `used` says, announced (when
/// `announce`) and held to the `memory` limit, within `pool` (whose threads the CPU's
/// allocation counts).
pub fn check_memory(
    pool: &rayon::ThreadPool,
    prepared: &Prepared,
    scene: &Scene,
    used: Use,
    limits: &Limits,
    announce: bool,
) -> Result<(), Error> {
    pool.install(|| check_memory_here(prepared, scene, used, limits, announce))
}

/// [`check_memory`] on the current thread's pool (the viewer's, rayon's global one).
pub fn check_memory_here(
    prepared: &Prepared,
    scene: &Scene,
    used: Use,
    limits: &Limits,
    announce: bool,
) -> Result<(), Error> {
    let (settings, needed) = match used {
        Use::Written { reference, aux } => (
            scene.settings.clone(),
            memory::render(prepared, scene, reference, aux),
        ),
        Use::Held => (scene.settings.clone(), memory::held(prepared, scene)),
        Use::Shown { width, height } => {
            let mut at = scene.settings.clone();
            (at.width, at.height, at.aa) = (width, height, 1);
            let needed = prepared.memory(scene, &at);
            (at, needed)
        }
    };
    if announce {
        eprintln!("{}", memory::announce(&settings, prepared.name(), &needed));
    }
    Ok(needed.check(limits)?)
}

/// The backend prepared for the frames of a sequence: the device is opened once; a frame
/// whose distance program (and the origin it is written relative to) is the last one's
/// renders with the same kernel; another is prepared with [`Prepared::update`], which keeps a
/// GPU kernel whose text is unchanged (its constants are read from `scene_data`), so `count`
/// counts kernels built, not frames.
pub struct Kernels<'a> {
    pool: &'a rayon::ThreadPool,
    backend: Backend,
    devices: Devices,
    setup: Setup,
    /// The last frame's program and scene origin, and the backend prepared for them.
    prepared: Option<(Program, [f64; 3], Prepared)>,
    /// Kernels (or CPU tapes) prepared so far.
    pub count: usize,
    /// Time spent preparing them.
    pub time: Duration,
}

impl std::fmt::Debug for Kernels<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Kernels")
            .field("count", &self.count)
            .finish()
    }
}

impl<'a> Kernels<'a> {
    /// No kernel yet: the frames will render with `backend` on `devices`.
    pub fn new(
        pool: &'a rayon::ThreadPool,
        (backend, devices): (Backend, Devices),
        setup: Setup,
    ) -> Self {
        Kernels {
            pool,
            backend,
            devices,
            setup,
            prepared: None,
            count: 0,
            time: Duration::ZERO,
        }
    }

    /// The backend prepared for `frame` (the last one when its program is the same,
    /// specialised again if its settings need it), and the frame's scene.
    pub fn prepare(&mut self, frame: FrameScene) -> Result<(Scene, &Prepared), Error> {
        let started = Instant::now();
        let same = self
            .prepared
            .as_ref()
            .is_some_and(|(p, o, _)| *p == frame.lowered.program && *o == frame.scene.origin);
        let scene = match &mut self.prepared {
            Some((_, _, prepared)) if same => {
                let FrameScene { scene, .. } = frame;
                if prepared.specialise(&scene)? {
                    self.count += 1;
                }
                scene
            }
            // The device stays open; the kernel is kept when its text is the same (the
            // program differs in numbers only) and given the frame's constants.
            Some((held, origin, prepared)) => {
                let FrameScene { scene, lowered, .. } = frame;
                *held = lowered.program.clone();
                *origin = scene.origin;
                if prepared.update(&scene, lowered)? {
                    self.count += 1;
                }
                scene
            }
            None => {
                let program = frame.lowered.program.clone();
                let Ready {
                    scene, prepared, ..
                } = prepare(
                    self.pool,
                    (self.backend, &self.devices),
                    frame,
                    &self.setup,
                    Open::Backend,
                )?;
                self.count += 1;
                self.prepared = Some((program, scene.origin, prepared));
                scene
            }
        };
        self.time += started.elapsed();
        let (_, _, prepared) = self.prepared.as_ref().expect("prepared");
        Ok((scene, prepared))
    }

    /// The backend last prepared.
    pub fn last(&self) -> Option<&Prepared> {
        self.prepared.as_ref().map(|(_, _, p)| p)
    }
}
