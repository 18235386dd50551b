//! A launch target that stays on the device: the buffers a frame's tiles render into, kept by
//! their owner (the viewer) between frames, so that a launch ([`crate::gpu::launch::Target::Resident`])
//! leaves its pixels there for the owner's next pass instead of reading them back.

use super::buffers::padded;
use super::{Buffers, Gpu, TILE_STRIDE};
use crate::gpu::launch::Work;
use sdfc_compiler::wgsl::STATS_WORDS;

/// The buffers of frames of one size that stay on the device: the kernel's bindings (scene
/// uniform and data, tile table, linear colours, statistics, finished pixels). The pixel
/// buffers may be larger than a frame, from a larger size before, so that frames of
/// alternating sizes (a moving camera's smaller ones) do not make them again. A wgpu
/// [`super::Kernel`] renders into them when given them ([`super::Kernel::into_resident`]).
#[derive(Debug, Default)]
pub struct ResidentFrame {
    buffers: Option<Buffers>,
    /// The frame's size.
    size: (u32, u32),
    /// Pixels the pixel buffers hold.
    capacity: u64,
    /// What the scene-data buffer holds: the key its writer gave ([`ResidentFrame::fit`]).
    data_key: Option<u64>,
    /// Whether the next launch writes the scene data.
    upload_data: bool,
}

impl ResidentFrame {
    /// Makes the buffers fit `work` on `gpu`: its size, its uniform and its scene data, named
    /// by `data_key` (the data is written by the next launch only when the key, or the
    /// buffer, changes). Returns whether the frame's size changed (its pixel buffers may then
    /// be new ones).
    pub fn fit(&mut self, gpu: &Gpu, work: &Work, data_key: u64) -> bool {
        use wgpu::BufferUsages as U;
        let make = |label, size, usage| gpu.buffer(label, size, usage);
        let pixels = work.width as u64 * work.height as u64;
        let tiles = work.tiles.len() as u64 * TILE_STRIDE as u64;
        let uniform = work.uniforms.len() as u64;
        let data = work.data.map(|d| d.len() as u64);
        let resized = self.size != (work.width, work.height) || self.buffers.is_none();
        let capacity = self.capacity.max(pixels);
        let mut b = match self.buffers.take() {
            Some(b) if self.capacity >= pixels => b,
            _ => Buffers {
                uniforms: make("sdfc resident scene", uniform, U::UNIFORM | U::COPY_DST),
                data: None,
                tile: make("sdfc resident tiles", tiles, U::UNIFORM | U::COPY_DST),
                image: make("sdfc resident image", capacity * 16, U::STORAGE),
                pixels: make("sdfc resident pixels", capacity * 4, U::STORAGE),
                stats: make(
                    "sdfc resident stats",
                    capacity * 4 * STATS_WORDS as u64,
                    U::STORAGE,
                ),
                reduction: None,
                readback: [None, None],
            },
        };
        if b.uniforms.size() != padded(uniform) {
            b.uniforms = make("sdfc resident scene", uniform, U::UNIFORM | U::COPY_DST);
        }
        if b.tile.size() != padded(tiles) {
            b.tile = make("sdfc resident tiles", tiles, U::UNIFORM | U::COPY_DST);
        }
        if b.data.as_ref().map(|d| d.size()) != data.map(padded) {
            b.data = data.map(|n| make("sdfc resident scene data", n, U::STORAGE | U::COPY_DST));
            self.data_key = None;
        }
        if resized {
            self.data_key = None;
        }
        self.upload_data = self.data_key != Some(data_key);
        self.data_key = Some(data_key);
        self.buffers = Some(b);
        self.size = (work.width, work.height);
        self.capacity = capacity;
        resized
    }

    /// The linear colours of the last frame (16 bytes a pixel: red, green, blue and a word
    /// unused, a row of the frame's width after another), on the device.
    pub fn image(&self) -> Option<&wgpu::Buffer> {
        self.buffers.as_ref().map(|b| &b.image)
    }

    /// The per-pixel statistics of the last frame ([`STATS_WORDS`] words a pixel, the first
    /// the marching steps), on the device.
    pub fn stats(&self) -> Option<&wgpu::Buffer> {
        self.buffers.as_ref().map(|b| &b.stats)
    }

    /// The buffers a launch of `work` renders into, with the uniforms, the tile table and
    /// (when it changed) the scene data written (queued). `None` unless the buffers were
    /// fitted to `work` ([`ResidentFrame::fit`]).
    pub(super) fn buffers(&self, gpu: &Gpu, work: &Work) -> Option<Buffers> {
        let b = self.buffers.as_ref().filter(|b| {
            self.size == (work.width, work.height)
                && b.uniforms.size() == padded(work.uniforms.len() as u64)
                && b.tile.size() == padded(work.tiles.len() as u64 * TILE_STRIDE as u64)
                && b.data.as_ref().map(|d| d.size()) == work.data.map(|d| padded(d.len() as u64))
        })?;
        gpu.queue.write_buffer(&b.uniforms, 0, work.uniforms);
        if let (Some(buffer), Some(bytes)) = (&b.data, work.data) {
            if self.upload_data {
                gpu.queue.write_buffer(buffer, 0, bytes);
            }
        }
        gpu.queue
            .write_buffer(&b.tile, 0, &super::buffers::tile_table(work));
        Some(b.clone())
    }
}
