//! A [`Kernel`] as the tile launcher's device (`launch::Device`): a frame's buffers prepared,
//! tiles dispatched and submitted, pixels and statistics read back, faults reported.

use super::buffers::{padded, tile_table, words};
use super::{Error, FrameBuffers, Kernel, TILE_STRIDE};
use crate::gpu::launch::{self, Pixels, Work};
use crate::gpu::reduce::{self, Answer, Ask};
use sdfc_compiler::wgsl::{reduce as reduction, STATS_WORDS};
use std::ops::Range;
use std::time::{Duration, Instant};

impl launch::Device for Kernel<'_> {
    type Frame = FrameBuffers;
    type Error = Error;

    fn describe(&self) -> String {
        self.gpu.describe()
    }

    fn prepare(&self, work: &Work) -> Result<FrameBuffers, Error> {
        let gpu = self.gpu;
        let limits = gpu.device.limits();
        let limit = limits.max_storage_buffer_binding_size;
        if let Some(data) = work.data.filter(|d| d.len() as u64 > limit) {
            return Err(Error::StorageBuffer {
                bytes: data.len(),
                limit,
            });
        }
        // The image (16 bytes a pixel) and the statistics are storage buffers bound whole.
        let largest = work.width as u64 * work.height as u64 * 4 * STATS_WORDS.max(4) as u64;
        let most = limit.min(limits.max_buffer_size);
        if largest > most {
            return Err(Error::FrameTooLarge {
                width: work.width,
                height: work.height,
                largest,
                most,
            });
        }
        let (pipeline, _) = gpu.cached_pipeline(self.wgsl, self.entry, work.data.is_some())?;
        let tiles = work.tiles.len() as u64;
        // Buffers kept on the device by their owner, or the spare ones (returned to the
        // spare when the frame finishes).
        let (buffers, spare) = match self.resident {
            Some(resident) => match resident.buffers(gpu, work) {
                Some(b) => (b, false),
                None => return Err(Error::NotFitted),
            },
            None => {
                let pixels = work.width as u64 * work.height as u64;
                let b = gpu.buffers(work, pixels, tiles);
                gpu.queue.write_buffer(&b.tile, 0, &tile_table(work));
                (b, true)
            }
        };
        let bind = gpu.bind_group(&pipeline.1, &buffers);
        let queries = (gpu.timestamps && work.timed).then(|| {
            gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("sdfc timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * tiles as u32,
            })
        });
        let memory = Some(gpu.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory));
        // wgpu queues its writes until the next submission: submitted now, the uploads are
        // part of the frame's setup, as CUDA's are, not of its first launch. A frame kept on
        // the device is not waited for: its writes go with its tiles.
        if work.target != launch::Target::Resident {
            gpu.queue.submit([]);
            gpu.wait()?;
        }
        Ok(FrameBuffers {
            pipeline,
            buffers,
            bind,
            queries,
            memory,
            reading: [None, None],
            spare,
        })
    }

    fn run(&self, f: &mut FrameBuffers, work: &Work, tiles: &[usize]) -> Result<(), Error> {
        self.submit(f, work, tiles)?;
        self.gpu.wait()
    }

    fn submit(&self, f: &mut FrameBuffers, work: &Work, tiles: &[usize]) -> Result<(), Error> {
        let gpu = self.gpu;
        // Each tile is its own dispatch, in one submission.
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        for &i in tiles {
            let t = work.tiles[i];
            let i = i as u32;
            let writes = f
                .queries
                .as_ref()
                .map(|q| wgpu::ComputePassTimestampWrites {
                    query_set: q,
                    beginning_of_pass_write_index: Some(2 * i),
                    end_of_pass_write_index: Some(2 * i + 1),
                });
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: None,
                timestamp_writes: writes,
            });
            pass.set_pipeline(&f.pipeline.0);
            pass.set_bind_group(0, &f.bind, &[i * TILE_STRIDE]);
            pass.dispatch_workgroups(
                t.2.div_ceil(self.workgroup),
                t.3.div_ceil(self.workgroup),
                1,
            );
        }
        gpu.queue.submit([enc.finish()]);
        Ok(())
    }

    /// The finished pixels of `range`, copied (in a submission after the launches) into
    /// readback buffer `slot` and mapped when the copy is done; the linear colours are read at
    /// [`launch::Device::collect`].
    fn start_read(
        &self,
        f: &mut FrameBuffers,
        work: &Work,
        range: Range<usize>,
        slot: usize,
    ) -> Result<(), Error> {
        if !work.finished() {
            return Ok(());
        }
        let gpu = self.gpu;
        let size = 4 * range.len() as u64;
        let kept = f.buffers.readback[slot].take();
        let buffer = kept.filter(|b| b.size() >= size).unwrap_or_else(|| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("sdfc band readback"),
                size: padded(size),
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        });
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(&f.buffers.pixels, 4 * range.start as u64, &buffer, 0, size);
        let index = gpu.queue.submit([enc.finish()]);
        let (tx, rx) = std::sync::mpsc::channel();
        buffer
            .slice(..size)
            .map_async(wgpu::MapMode::Read, move |r| {
                let _ = tx.send(r);
            });
        f.buffers.readback[slot] = Some(buffer);
        f.reading[slot] = Some((range, index, rx));
        Ok(())
    }

    /// A band's finished pixels, from the mapped buffer once its copy is done.
    fn copied(
        &self,
        f: &mut FrameBuffers,
        range: &Range<usize>,
        slot: usize,
        take: &mut dyn FnMut(&[u8]),
    ) -> Result<Option<Duration>, Error> {
        let reading = f.reading[slot].take();
        let (Some((at, index, mapped)), Some(buffer)) = (reading, &f.buffers.readback[slot]) else {
            return Ok(None);
        };
        debug_assert_eq!(&at, range, "the band read into this slot");
        let waiting = Instant::now();
        // Waits for the copy alone: the launches submitted after it may still run.
        self.gpu.wait_for(index, &mapped)?;
        let wait = waiting.elapsed();
        let size = 4 * range.len() as u64;
        take(&buffer.slice(..size).get_mapped_range()?);
        buffer.unmap();
        Ok(Some(wait))
    }

    fn read(
        &self,
        f: &mut FrameBuffers,
        work: &Work,
        ranges: &[Range<usize>],
    ) -> Result<Pixels, Error> {
        let bytes = |per: u64| -> Vec<Range<u64>> {
            ranges
                .iter()
                .map(|r| r.start as u64 * per..r.end as u64 * per)
                .collect()
        };
        // Converted in the mapped staging buffers, each conversion timed.
        use rayon::prelude::*;
        let mut convert = Duration::ZERO;
        let f32_at = |b: &[u8]| f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        let (linear, rgba) = if work.finished() {
            // The finished pixels are the bytes to write: copied out as they are.
            let rgba = self.gpu.read_with(&f.buffers.pixels, &bytes(4), |b| {
                // Copied out by every core, as the linear colours are converted.
                crate::gpu::to_vec_parallel(b)
            })?;
            (Vec::new(), rgba)
        } else {
            let linear = self.gpu.read_with(&f.buffers.image, &bytes(16), |b| {
                let start = Instant::now();
                let linear = b
                    .par_chunks_exact(16)
                    .map(|c| [f32_at(&c[0..4]), f32_at(&c[4..8]), f32_at(&c[8..12])])
                    .collect();
                convert += start.elapsed();
                linear
            })?;
            (linear, Vec::new())
        };
        Ok(Pixels {
            linear,
            rgba,
            convert,
        })
    }

    fn reduce(
        &self,
        f: &mut FrameBuffers,
        work: &Work,
        ranges: &[Range<usize>],
        ask: Ask,
    ) -> Result<Answer, Error> {
        let queries = reduce::queries(work.pixels(), ranges, ask);
        if queries.is_empty() {
            return Ok(Answer::empty(ask));
        }
        let gpu = self.gpu;
        let pipeline = gpu.reducer()?;
        let (first, second) = reduce::threads(work.pixels());
        let record = 4 * reduction::RECORD as u64;
        let (partial, total) = f.buffers.reduction.get_or_insert_with(|| {
            use wgpu::BufferUsages as U;
            let make = |label, size| {
                gpu.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size,
                    usage: U::STORAGE | U::COPY_SRC,
                    mapped_at_creation: false,
                })
            };
            (
                make("sdfc partial statistics", first as u64 * record),
                make("sdfc statistics", second as u64 * record),
            )
        });
        // One query a dispatch, each at its own offset of one buffer.
        let slots: Vec<u8> = queries
            .iter()
            .flat_map(|q| {
                let mut slot = words(&q.words());
                slot.resize(TILE_STRIDE as usize, 0);
                slot
            })
            .collect();
        let query = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sdfc reduction queries"),
            size: slots.len() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        gpu.queue.write_buffer(&query, 0, &slots);
        let entry = |binding, resource| wgpu::BindGroupEntry { binding, resource };
        let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sdfc reduction"),
            layout: &pipeline.1,
            entries: &[
                entry(
                    0,
                    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &query,
                        offset: 0,
                        size: std::num::NonZeroU64::new(4 * reduction::QUERY_WORDS as u64),
                    }),
                ),
                entry(1, f.buffers.stats.as_entire_binding()),
                entry(2, partial.as_entire_binding()),
                entry(3, total.as_entire_binding()),
            ],
        });
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        for (i, q) in queries.iter().enumerate() {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline.0);
            pass.set_bind_group(0, &bind, &[i as u32 * TILE_STRIDE]);
            pass.dispatch_workgroups(q.threads.div_ceil(reduction::WORKGROUP), 1, 1);
        }
        gpu.queue.submit([enc.finish()]);
        let totals = gpu.read_with(
            total,
            std::slice::from_ref(&(0..second as u64 * record)),
            |b| {
                b.chunks_exact(4)
                    .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                    .collect::<Vec<u32>>()
            },
        )?;
        Ok(Answer::of_totals(&totals, ask))
    }

    fn check(&self, f: &mut FrameBuffers) -> Result<(), Error> {
        if let Some(scope) = f.memory.take() {
            let error = pollster::block_on(scope.pop());
            f.memory = Some(
                self.gpu
                    .device
                    .push_error_scope(wgpu::ErrorFilter::OutOfMemory),
            );
            if let Some(e) = error {
                return Err(Error::Render(e));
            }
        }
        Ok(())
    }

    fn finish(&self, mut f: FrameBuffers, work: &Work) -> Result<Option<Duration>, Error> {
        if let Some(scope) = f.memory.take() {
            if let Some(e) = pollster::block_on(scope.pop()) {
                return Err(Error::Render(e));
            }
        }
        let time = match &f.queries {
            Some(q) => Some(self.gpu.gpu_time(q, work.tiles.len() as u32)?),
            None => None,
        };
        if f.spare {
            if let Ok(mut spare) = self.gpu.spare.lock() {
                *spare = Some(f.buffers);
            }
        }
        Ok(time)
    }

    fn fault(&self, message: String) -> Error {
        Error::Injected(message)
    }
}
