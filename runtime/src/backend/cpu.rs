//! The CPU renderer behind [`Renderer`]: the distance program's tapes, prepared once, and the
//! render options.

use super::{Error, Frame, Next, Part, Prepared, Progress, Renderer, Setup};
use crate::cpu::{self, Options, Tapes};
use crate::gpu::{self, launch::Faults};
use crate::memory::Memory;
use sdfc_compiler::{analytic::Traceable, wgsl, Lowered, Scene, Settings};
use std::time::{Duration, Instant};

/// A scene prepared for the CPU: the distance program and its tapes, and the render options.
#[derive(Debug)]
pub struct CpuPrepared {
    pub(super) tapes: Box<Tapes>,
    pub(super) options: Options,
    /// How long the tapes took to prepare (`--stats`).
    taped: Duration,
}

impl CpuPrepared {
    /// The CPU's preparation: the tapes, prepared now where `scene` is marched (a traced
    /// scene never evaluates its program).
    pub(super) fn new(scene: &Scene, lowered: Lowered, setup: &Setup) -> CpuPrepared {
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
        CpuPrepared {
            tapes,
            options,
            taped: started.elapsed(),
        }
    }

    /// The setup this was prepared with.
    fn setup(&self) -> Setup {
        Setup {
            precision: self.options.precision,
            debug_nan: self.options.debug_nan,
            ..Setup::default()
        }
    }
}

impl Renderer for CpuPrepared {
    fn name(&self) -> &'static str {
        "cpu"
    }

    fn device(&self) -> String {
        format!("CPU, {} threads", rayon::current_num_threads())
    }

    fn preparation(&self) -> Vec<(&'static str, Duration, String)> {
        vec![(
            "tapes",
            self.taped,
            if self.tapes.prepared() {
                "the distance program prepared for the interpreter (distance, material, media)"
                    .into()
            } else {
                "none: the scene is traced, the interpreter does not run".into()
            },
        )]
    }

    fn memory(&self, scene: &Scene, settings: &Settings) -> Memory {
        let mut at = scene.clone();
        at.settings = settings.clone();
        Memory {
            host: cpu::memory(
                &at,
                &self.tapes,
                &self.options,
                rayon::current_num_threads(),
            ),
            device: 0,
        }
    }

    fn retained(&self, settings: &Settings) -> u64 {
        cpu::retained(settings)
    }

    fn program_len(&self) -> usize {
        self.tapes.program().len()
    }

    fn traceable(&self) -> &Traceable {
        self.tapes.traceable()
    }

    fn render(&self, scene: &Scene, progress: Progress, _: &Faults) -> Result<Frame, Error> {
        let tiles = cpu::tile_count(&scene.settings, &self.options).max(1) as f64;
        let done = std::sync::atomic::AtomicU64::new(0);
        let start = Instant::now();
        let render = cpu::render_tapes(scene, &self.tapes, &self.options, &|| {
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

    fn part<'a>(&'a self, scene: &'a Scene) -> Result<Part<'a>, Error> {
        Ok(Part {
            worker: Box::new(gpu::cpu::Device::new(scene, &self.tapes, &self.options)),
            kernel: None,
        })
    }

    fn next(&self, scene: &Scene, lowered: Lowered, _: Option<wgsl::KernelChoice>) -> Next {
        Ok((Prepared::on_cpu(scene, lowered, &self.setup())?, true))
    }

    fn update(&mut self, scene: &Scene, lowered: Lowered) -> Result<bool, Error> {
        *self = CpuPrepared::new(scene, lowered, &self.setup());
        Ok(true)
    }
}
