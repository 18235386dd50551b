//! A frame's buffers on a [`Gpu`] and their bindings, kept for the next frame of the same
//! sizes; waiting on the device, the statistics' reduction, and reading results back.

use super::{Buffers, Error, Gpu, Pipeline, SPIN, TILE_STRIDE};
use crate::gpu::launch::Work;
use sdfc_compiler::wgsl::{reduce as reduction, STATS_WORDS};
use std::ops::Range;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The binding `binding` of a compute pass, of type `ty`.
pub(crate) fn compute_entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty,
        count: None,
    }
}

/// A storage buffer, `read_only` or not, bound at a dynamic offset when `dynamic`.
pub(crate) fn storage(read_only: bool, dynamic: bool) -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Storage { read_only },
        has_dynamic_offset: dynamic,
        min_binding_size: None,
    }
}

/// The size of a buffer for `n` bytes: at least 16, so that one for no bytes can be bound.
pub(super) fn padded(n: u64) -> u64 {
    n.max(16)
}

impl Gpu {
    /// The buffers of a frame with the work's uniforms and scene data written (queued): the
    /// spare ones when their sizes fit, else new ones.
    pub(super) fn buffers(&self, l: &Work, pixels: u64, tiles: u64) -> Buffers {
        let fits = |b: &Buffers| {
            b.uniforms.size() == padded(l.uniforms.len() as u64)
                && b.data.as_ref().map(|d| d.size()) == l.data.map(|d| padded(d.len() as u64))
                && b.tile.size() == padded(tiles * TILE_STRIDE as u64)
                && b.image.size() == padded(pixels * 16)
        };
        let b = match self.spare.lock().ok().and_then(|mut s| s.take()) {
            Some(b) if fits(&b) => b,
            _ => self.new_buffers(l, pixels, tiles),
        };
        self.queue.write_buffer(&b.uniforms, 0, l.uniforms);
        if let (Some(buffer), Some(bytes)) = (&b.data, l.data) {
            self.queue.write_buffer(buffer, 0, bytes);
        }
        b
    }

    /// A buffer of `size` bytes ([`padded`]) for `usage`, not mapped.
    pub(super) fn buffer(&self, label: &str, size: u64, usage: wgpu::BufferUsages) -> wgpu::Buffer {
        self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: padded(size),
            usage,
            mapped_at_creation: false,
        })
    }

    fn new_buffers(&self, l: &Work, pixels: u64, tiles: u64) -> Buffers {
        use wgpu::BufferUsages as U;
        let make = |label, size, usage| self.buffer(label, size, usage);
        Buffers {
            uniforms: make(
                "sdfc scene",
                l.uniforms.len() as u64,
                U::UNIFORM | U::COPY_DST,
            ),
            data: l.data.map(|bytes| {
                make(
                    "sdfc scene data",
                    bytes.len() as u64,
                    U::STORAGE | U::COPY_DST,
                )
            }),
            tile: make(
                "sdfc tiles",
                tiles * TILE_STRIDE as u64,
                U::UNIFORM | U::COPY_DST,
            ),
            image: make("sdfc image", pixels * 16, U::STORAGE | U::COPY_SRC),
            pixels: make("sdfc pixels", pixels * 4, U::STORAGE | U::COPY_SRC),
            stats: make(
                "sdfc stats",
                pixels * 4 * STATS_WORDS as u64,
                U::STORAGE | U::COPY_SRC,
            ),
            reduction: None,
            readback: [None, None],
        }
    }

    pub(super) fn bind_group(
        &self,
        layout: &wgpu::BindGroupLayout,
        b: &Buffers,
    ) -> wgpu::BindGroup {
        let tile = wgpu::BufferBinding {
            buffer: &b.tile,
            offset: 0,
            size: std::num::NonZeroU64::new(16),
        };
        let mut entries = vec![
            wgpu::BindGroupEntry {
                binding: 0,
                resource: b.uniforms.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::Buffer(tile),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: b.image.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: b.stats.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 5,
                resource: b.pixels.as_entire_binding(),
            },
        ];
        if let Some(data) = &b.data {
            entries.push(wgpu::BindGroupEntry {
                binding: 4,
                resource: data.as_entire_binding(),
            });
        }
        self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sdfc bindings"),
            layout,
            entries: &entries,
        })
    }

    /// Waits for the work submitted. On a GPU the host first polls, yielding its core
    /// between polls, for up to [`SPIN`]: the driver's blocking wait returns a tenth of a
    /// millisecond or more after the end of a frame, as long as a short frame itself
    /// (measured), and CUDA's default wait polls too. A longer
    /// wait blocks, its latency small beside the frame. A software adapter (lavapipe)
    /// renders on the host's cores, which polling would take from it: it blocks at once.
    pub fn wait(&self) -> Result<(), Error> {
        if !self.is_cpu() {
            let start = Instant::now();
            while start.elapsed() < SPIN {
                if self
                    .device
                    .poll(wgpu::PollType::Poll)
                    .map_err(Error::Poll)?
                    .is_queue_empty()
                {
                    return Ok(());
                }
                std::thread::yield_now();
            }
        }
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(Error::Poll)
    }

    /// The statistics' reduction pipeline (`sdfc_compiler::wgsl::reduce`): binding 0
    /// its query (read-only storage at a dynamic offset), 1 the kernel's statistics (read
    /// only), 2 and 3 the partial records and totals.
    pub(super) fn reducer(&self) -> Result<Pipeline, Error> {
        let mut kept = self.reducer.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(p) = kept.as_ref() {
            return Ok(p.clone());
        }
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = self
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("sdfc reduction"),
                source: wgpu::ShaderSource::Wgsl(reduction::SOURCE.into()),
            });
        let entry =
            |binding, read_only, dynamic| compute_entry(binding, storage(read_only, dynamic));
        let entries = [
            entry(0, true, true),
            entry(1, true, false),
            entry(2, false, false),
            entry(3, false, false),
        ];
        let (layout, pipeline_layout) =
            self.layouts(("sdfc reduction", "sdfc reduction"), &entries);
        // The driver's compiled code kept between processes, as a kernel's is.
        let (pipeline, _) = self.cached_compute(
            (reduction::SOURCE, reduction::ENTRY_POINT, false),
            "sdfc reduction",
            &pipeline_layout,
            &module,
        );
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::Pipeline(e));
        }
        let p = Arc::new((pipeline, layout));
        *kept = Some(p.clone());
        Ok(p)
    }

    /// The per-pixel statistics of the last frame of `pixels` pixels rendered on this device,
    /// read back whole ([`STATS_WORDS`] words a pixel), for checking their reduction on the
    /// device against the host's sums ([`crate::gpu::counters`]); `None` when no frame of that
    /// size has been rendered.
    pub fn last_statistics(&self, pixels: usize) -> Result<Option<Vec<u32>>, Error> {
        let spare = self.spare.lock().unwrap_or_else(|e| e.into_inner());
        let Some(b) = spare
            .as_ref()
            .filter(|b| b.image.size() == padded(16 * pixels as u64))
        else {
            return Ok(None);
        };
        let bytes = self.read(&b.stats, 4 * STATS_WORDS as u64 * pixels as u64)?;
        Ok(Some(
            bytes
                .chunks_exact(4)
                .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect(),
        ))
    }

    /// Waits until submission `index` is done and the mapping it was followed by has
    /// reported to `mapped` (polling first, as [`Gpu::wait`] does), not for the work
    /// submitted after it.
    pub(super) fn wait_for(
        &self,
        index: wgpu::SubmissionIndex,
        mapped: &std::sync::mpsc::Receiver<Result<(), wgpu::BufferAsyncError>>,
    ) -> Result<(), Error> {
        let done = |r: Result<(), wgpu::BufferAsyncError>| r.map_err(Error::Map);
        if !self.is_cpu() {
            let start = Instant::now();
            while start.elapsed() < SPIN {
                self.device
                    .poll(wgpu::PollType::Poll)
                    .map_err(Error::Poll)?;
                if let Ok(r) = mapped.try_recv() {
                    return done(r);
                }
                std::thread::yield_now();
            }
        }
        self.device
            .poll(wgpu::PollType::Wait {
                submission_index: Some(index),
                timeout: None,
            })
            .map_err(Error::Poll)?;
        done(mapped.recv()?)
    }

    pub(super) fn read(&self, src: &wgpu::Buffer, size: u64) -> Result<Vec<u8>, Error> {
        self.read_ranges(src, std::slice::from_ref(&(0..size)))
    }

    /// The bytes of `ranges` of `src`, one after the other, through one staging buffer.
    fn read_ranges(&self, src: &wgpu::Buffer, ranges: &[Range<u64>]) -> Result<Vec<u8>, Error> {
        self.read_with(src, ranges, |bytes| bytes.to_vec())
    }

    /// What `f` makes of the bytes of `ranges` of `src`, one after the other, read in the
    /// staging buffer while it is mapped (a frame's colours are converted there, not copied
    /// out first: 33 MB at 1920×1080).
    pub(super) fn read_with<T>(
        &self,
        src: &wgpu::Buffer,
        ranges: &[Range<u64>],
        f: impl FnOnce(&[u8]) -> T,
    ) -> Result<T, Error> {
        let size: u64 = ranges.iter().map(|r| r.end - r.start).sum();
        let kept = self.staging.lock().ok().and_then(|mut kept| {
            let at = kept.iter().position(|b| b.size() == size)?;
            Some(kept.swap_remove(at))
        });
        let staging = kept.unwrap_or_else(|| {
            self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("sdfc readback"),
                size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        });
        let mut enc = self.device.create_command_encoder(&Default::default());
        let mut at = 0;
        for r in ranges {
            enc.copy_buffer_to_buffer(src, r.start, &staging, at, r.end - r.start);
            at += r.end - r.start;
        }
        self.queue.submit([enc.finish()]);
        let slice = staging.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.wait()?;
        rx.recv()??;
        let out = f(&slice.get_mapped_range()?);
        staging.unmap();
        if let Ok(mut kept) = self.staging.lock() {
            // The few sizes a frame reads back (image or pixels, statistics, timestamps).
            if kept.len() >= 4 {
                kept.remove(0);
            }
            kept.push(staging);
        }
        Ok(out)
    }

    pub(super) fn gpu_time(&self, q: &wgpu::QuerySet, tiles: u32) -> Result<Duration, Error> {
        let n = 2 * tiles as u64;
        let resolve = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sdfc timestamps"),
            size: n * 8,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.resolve_query_set(q, 0..n as u32, &resolve, 0);
        self.queue.submit([enc.finish()]);
        let bytes = self.read(&resolve, n * 8)?;
        let ticks: Vec<u64> = bytes
            .chunks_exact(8)
            .map(|c| u64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
            .collect();
        let period = self.queue.get_timestamp_period() as f64;
        let total: u64 = ticks
            .chunks_exact(2)
            .map(|p| p[1].saturating_sub(p[0]))
            .sum();
        Ok(Duration::from_nanos((total as f64 * period) as u64))
    }
}

/// The tile table of `work`: an entry (x, y, width, height) every [`TILE_STRIDE`] bytes.
pub(super) fn tile_table(work: &Work) -> Vec<u8> {
    work.tiles
        .iter()
        .flat_map(|t| {
            let mut entry = words(&[t.0, t.1, t.2, t.3]);
            entry.resize(TILE_STRIDE as usize, 0);
            entry
        })
        .collect()
}

pub(super) fn words(w: &[u32]) -> Vec<u8> {
    w.iter().flat_map(|x| x.to_le_bytes()).collect()
}
