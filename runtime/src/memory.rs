//! What a render allocates: the bound announced before a render starts, held to the
//! `memory` limit (`--limit memory=MIB`), and the allocations of writing its outputs.

use sdfc_compiler::{Limit, Limits, Scene, Settings};
use std::fmt;

/// Bytes in a MiB.
pub const MIB: u64 = 1 << 20;

/// Bytes allocated at most, on the host and on the GPU.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Memory {
    /// Host memory.
    pub host: u64,
    /// Device memory (buffers on the GPU, including readback buffers).
    pub device: u64,
}

impl Memory {
    /// Host and device together: what the `memory` limit bounds.
    pub fn total(&self) -> u64 {
        self.host.saturating_add(self.device)
    }

    /// `Err` when `self` exceeds the `memory` limit of `limits`, saying how to raise it.
    pub fn check(&self, limits: &Limits) -> Result<(), Exceeded> {
        let limit = limits.get(Limit::Memory);
        let needed = mib(self.total());
        if needed <= limit {
            return Ok(());
        }
        Err(Exceeded {
            needed,
            limit,
            raise: limits.raise_to(Limit::Memory, needed),
        })
    }
}

/// A render above the `memory` limit.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("the render would allocate up to {needed} MiB, more than the memory limit of {limit} MiB; {raise}")]
pub struct Exceeded {
    /// What the render would allocate, in MiB (rounded up).
    pub needed: u64,
    /// The limit, in MiB.
    pub limit: u64,
    /// How to raise the limit that far, as the limits spell it (`Limits::raise_to`).
    pub raise: String,
}

/// Bytes in whole MiB, rounded up.
pub fn mib(bytes: u64) -> u64 {
    bytes.div_ceil(MIB)
}

impl fmt::Display for Memory {
    /// `allocating at most 96 MiB` (with the device's share on GPU backends).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "allocating at most {} MiB", mib(self.total()))?;
        if self.device > 0 {
            write!(f, " ({} MiB of it on the GPU)", mib(self.device))?;
        }
        Ok(())
    }
}

/// The most bytes writing the outputs of a render of `settings` allocates, in whichever
/// format (`crate::output`): for PNG the RGBA8 image, the PNG bytes (at most the raw image
/// with its filter bytes, in a vector that may double) and the encoder's state; for JPEG,
/// streamed into the file, the RGB8 image, the encoder's rows of blocks (3 planes of 16 rows)
/// and its tables; OpenEXR is streamed from the image itself (a header and a buffer); and with
/// `aux` the depth sidecar's bytes.
pub fn output(settings: &Settings, aux: bool) -> u64 {
    let (w, h) = (settings.width as u64, settings.height as u64);
    let rgba = 4 * w * h;
    let png = rgba + 2 * (rgba + h + 4096) + 4 * MIB + 16 * (4 * w + 1);
    let jpeg = 3 * w * h + 48 * (w + 16) + MIB;
    let exr = 64 * 1024;
    let sidecar = if aux { 20 + 8 * w * h } else { 0 };
    png.max(jpeg).max(exr) + sidecar
}

/// What rendering on a prepared scene allocates (`backend::Prepared` answers it; the trait
/// keeps this module below the backends, whose launchers count in [`Memory`]).
pub trait Footprint {
    /// The most memory rendering `settings` allocates, the finished frame included.
    fn memory(&self, scene: &Scene, settings: &Settings) -> Memory;
    /// The bytes a finished frame holds.
    fn retained(&self, settings: &Settings) -> u64;
}

/// The most a `sdfc render` of `scene` allocates on `prepared`: the render; with
/// `reference`, the finished frame held while its convergence check (which may sample more)
/// renders; then the frame
/// held while its outputs are written.
pub fn render(prepared: &impl Footprint, scene: &Scene, reference: bool, aux: bool) -> Memory {
    let s = &scene.settings;
    let frame = prepared.memory(scene, s);
    let held = prepared.retained(s);
    let check = if reference {
        let finer = crate::cpu::reference::check_settings(s);
        prepared.memory(scene, &finer).host.saturating_add(held)
    } else {
        0
    };
    let writing = held.saturating_add(output(s, aux));
    Memory {
        host: frame.host.max(check).max(writing),
        device: frame.device,
    }
}

/// The most frames of `scene` rendered one after another on `prepared` allocate when a
/// finished frame is held while the next renders (`sdfc bench`, which keeps its warm-up
/// frame's statistics): the render and the frame held.
pub fn held(prepared: &impl Footprint, scene: &Scene) -> Memory {
    let s = &scene.settings;
    let frame = prepared.memory(scene, s);
    Memory {
        host: frame.host.saturating_add(prepared.retained(s)),
        device: frame.device,
    }
}

/// The announcement before a render: `render: 1920x1080, aa 4, cpu: allocating at most 96 MiB`.
pub fn announce(settings: &Settings, backend: &str, memory: &Memory) -> String {
    format!(
        "render: {}x{}, aa {}, {backend}: {memory}",
        settings.width, settings.height, settings.aa
    )
}
