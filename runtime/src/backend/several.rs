//! Several devices behind [`Renderer`] (`--devices`): each prepared as one device is, rendering
//! each frame together through the one tile scheduler ([`gpu::render_several`]).

use super::{Error, Frame, Part, Prepared, Progress, Renderer, Setup};
use crate::gpu::{self, launch::Faults};
use crate::memory::Memory;
use sdfc_compiler::{analytic::Traceable, wgsl, Lowered, Scene, Settings};
use std::time::Duration;

/// A scene prepared on several devices, in the order `--devices` names them.
#[derive(Debug)]
pub struct SeveralPrepared {
    pub(super) parts: Vec<Prepared>,
}

impl Renderer for SeveralPrepared {
    fn name(&self) -> &'static str {
        let first = self.parts.first().map_or("cpu", |p| p.name());
        if self.parts.iter().all(|p| p.name() == first) {
            first
        } else {
            "mixed"
        }
    }

    fn device(&self) -> String {
        let each: Vec<String> = self.parts.iter().map(|p| p.device()).collect();
        format!("{} devices: {}", self.parts.len(), each.join(" + "))
    }

    fn kernel_kind(&self) -> Option<&'static str> {
        self.parts.iter().find_map(|p| p.kernel_kind())
    }

    /// The first device's (they are prepared one after another).
    fn preparation(&self) -> Vec<(&'static str, Duration, String)> {
        self.parts
            .first()
            .map(|p| p.preparation())
            .unwrap_or_default()
    }

    /// Each GPU holds a whole frame's buffers in its own memory: the limit counts the most one
    /// of them allocates, not their sum. The bands read back and the image they are assembled
    /// into are no more than one GPU's whole readback on the host; the CPU's share is host
    /// memory beside it.
    fn memory(&self, scene: &Scene, settings: &Settings) -> Memory {
        let each: Vec<Memory> = self
            .parts
            .iter()
            .map(|p| p.memory(scene, settings))
            .collect();
        let (cpu, gpus): (Vec<&Memory>, Vec<&Memory>) = each.iter().partition(|m| m.device == 0);
        Memory {
            host: cpu.iter().map(|m| m.host).sum::<u64>()
                + gpus.iter().map(|m| m.host).max().unwrap_or(0),
            device: gpus.iter().map(|m| m.device).max().unwrap_or(0),
        }
    }

    fn retained(&self, settings: &Settings) -> u64 {
        match self.parts.as_slice() {
            [one] => one.retained(settings),
            _ => gpu::retained(settings),
        }
    }

    fn program_len(&self) -> usize {
        self.parts.first().map_or(0, |p| p.program_len())
    }

    fn traceable(&self) -> &Traceable {
        self.parts[0].traceable()
    }

    fn contract(&self) -> Option<&wgsl::Contract> {
        self.parts.iter().find_map(|p| p.contract())
    }

    fn reduce_statistics(&mut self, on: bool) {
        for p in &mut self.parts {
            p.reduce_statistics(on);
        }
    }

    /// The setup of the first GPU device's kernel.
    fn setup(&self) -> Option<&Setup> {
        self.parts.iter().find_map(|p| p.0.setup())
    }

    fn render(&self, scene: &Scene, progress: Progress, faults: &Faults) -> Result<Frame, Error> {
        let statistics = !self.setup().is_some_and(|s| s.image_only);
        let finished = self.setup().is_some_and(|s| s.finished);
        let mut workers = Vec::with_capacity(self.parts.len());
        let (mut lipschitz, mut uniform, mut data) = (1.0, None, None);
        for p in &self.parts {
            let Part { worker, kernel } = p.0.part(scene)?;
            if let Some((l, u, d)) = kernel {
                (lipschitz, uniform, data) = (l, Some(u), d);
            }
            workers.push(worker);
        }
        let workers: Vec<&dyn gpu::launch::Worker> = workers.iter().map(|w| w.as_ref()).collect();
        let r = gpu::render_several(
            &workers,
            scene,
            (lipschitz, uniform, data),
            (faults, statistics, finished),
            &mut |f| progress(f),
        )?;
        Ok(Frame::of(r))
    }

    fn part<'a>(&'a self, _: &'a Scene) -> Result<Part<'a>, Error> {
        Err(Error::Nested)
    }

    fn update(&mut self, scene: &Scene, lowered: Lowered) -> Result<bool, Error> {
        let mut built = false;
        for p in &mut self.parts {
            built |= p.update(scene, lowered.clone())?;
        }
        Ok(built)
    }

    fn specialise(&mut self, scene: &Scene) -> Result<bool, Error> {
        let mut again = false;
        for p in &mut self.parts {
            again |= p.specialise(scene)?;
        }
        Ok(again)
    }
}
