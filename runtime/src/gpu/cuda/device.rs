//! A [`Kernel`] as the tile launcher's device (`launch::Device`): a frame's buffers checked and
//! allocated, tiles launched, pixels and statistics read back through page-locked memory.

#![allow(unsafe_code)] // The driver API is C: its calls are wrapped here, each with its reason.

use super::super::launch::{self, Pixels, Work};
use super::super::reduce::{self, Answer, Ask};
use super::{driver, Error, FrameBuffers, Kernel, Loaded};
use cudarc::driver::{sys, LaunchConfig, PushKernelArg};
use sdfc_compiler::{
    ptx::{self, Argument, Space},
    wgsl::{reduce as reduction, STATS_WORDS},
};
use std::ops::Range;
use std::time::{Duration, Instant};

impl Kernel<'_> {
    /// The bytes of `src` read back through the device's kept page-locked buffer (allocated,
    /// or reallocated for another size, here).
    fn read_pinned(&self, src: &cudarc::driver::CudaView<'_, u8>) -> Result<Vec<u8>, Error> {
        let s = &self.cuda.stream;
        let kept = self.cuda.pinned.lock().ok().and_then(|mut p| p.take());
        let mut pinned = match kept.filter(|p| p.len() == src.len()) {
            Some(p) => p,
            // SAFETY: page-locked host memory, cached (no write-combining flag: the host reads
            // it); its bytes are not read before the copy below has written every one of them.
            None => unsafe { self.cuda.ctx.alloc_pinned_with_flags::<u8>(src.len(), 0) }
                .map_err(driver("allocating page-locked memory"))?,
        };
        s.memcpy_dtoh(src, &mut pinned)
            .map_err(driver("reading the pixels"))?;
        let bytes =
            super::super::to_vec_parallel(pinned.as_slice().map_err(driver("reading the pixels"))?);
        if let Ok(mut p) = self.cuda.pinned.lock() {
            *p = Some(pinned);
        }
        Ok(bytes)
    }
}

impl launch::Device for Kernel<'_> {
    type Frame = FrameBuffers;
    type Error = Error;

    fn describe(&self) -> String {
        self.cuda.describe()
    }

    fn prepare(&self, work: &Work) -> Result<FrameBuffers, Error> {
        let s = &self.cuda.stream;
        let pixels = work.width as usize * work.height as usize;
        check_launch(self.loaded, work.uniforms, pixels, STATS_WORDS, work.data)?;
        let table: Vec<u32> = work
            .tiles
            .iter()
            .flat_map(|t| [t.0, t.1, t.2, t.3])
            .collect();
        // Kept buffers of another size are freed below through the context current on this
        // thread, which a pool thread may not have yet: the driver would refuse the free, and
        // the next call report it (a render at another size once failed so).
        self.cuda
            .ctx
            .bind_to_thread()
            .map_err(driver("making the context current"))?;
        let kept = self.cuda.spare.lock().ok().and_then(|mut k| k.take());
        let fits = |f: &FrameBuffers| {
            f.image.len() == pixels * 4
                && f.uniforms.len() == work.uniforms.len()
                && f.tiles.len() == table.len()
                && f.data.as_ref().map(|d| d.len()) == work.data.map(|d| d.len())
        };
        if let Some(mut f) = kept.filter(fits) {
            // Every pixel of the tiles is written by the kernel: the buffers need no clearing.
            s.memcpy_htod(work.uniforms, &mut f.uniforms)
                .map_err(driver("uploading the scene"))?;
            s.memcpy_htod(&table, &mut f.tiles)
                .map_err(driver("uploading the tiles"))?;
            if let (Some(d), Some(bytes)) = (&mut f.data, work.data) {
                s.memcpy_htod(bytes, d)
                    .map_err(driver("uploading the scene data"))?;
            }
            f.events.clear();
            s.synchronize().map_err(driver("uploading the scene"))?;
            return Ok(f);
        }
        let uniforms = s
            .clone_htod(work.uniforms)
            .map_err(driver("uploading the scene"))?;
        let tiles = s
            .clone_htod(&table)
            .map_err(driver("uploading the tiles"))?;
        let image = s
            .alloc_zeros::<f32>(pixels * 4)
            .map_err(driver("allocating the image"))?;
        let stats = s
            .alloc_zeros::<u32>(pixels * STATS_WORDS as usize)
            .map_err(driver("allocating the statistics"))?;
        let finished = s
            .alloc_zeros::<u8>(pixels * 4)
            .map_err(driver("allocating the pixels"))?;
        let data = match work.data {
            Some(bytes) => Some(
                s.clone_htod(bytes)
                    .map_err(driver("uploading the scene data"))?,
            ),
            None => None,
        };
        s.synchronize().map_err(driver("uploading the scene"))?;
        Ok(FrameBuffers {
            uniforms,
            tiles,
            image,
            stats,
            data,
            pixels: finished,
            events: Vec::with_capacity(work.tiles.len()),
            reduction: None,
            readback: [(None, None), (None, None)],
        })
    }

    fn run(&self, f: &mut FrameBuffers, work: &Work, tiles: &[usize]) -> Result<(), Error> {
        self.submit(f, work, tiles)?;
        self.cuda
            .stream
            .synchronize()
            .map_err(driver("running the kernel"))
    }

    fn submit(&self, f: &mut FrameBuffers, work: &Work, tiles: &[usize]) -> Result<(), Error> {
        let s = &self.cuda.stream;
        let workgroup = self.workgroup;
        // Each launch is timed by its own pair of events, and the times are summed: the
        // same measure as the wgpu path's per-pass timestamps (gaps between launches excluded).
        let flags = Some(sys::CUevent_flags::CU_EVENT_DEFAULT);
        for &i in tiles {
            let t = work.tiles[i];
            let timed = if work.timed {
                let start = self
                    .cuda
                    .ctx
                    .new_event(flags)
                    .map_err(driver("creating an event"))?;
                let end = self
                    .cuda
                    .ctx
                    .new_event(flags)
                    .map_err(driver("creating an event"))?;
                Some((start, end))
            } else {
                None
            };
            let tile_view = f.tiles.slice(4 * i..4 * i + 4);
            let cfg = LaunchConfig {
                grid_dim: (t.2.div_ceil(workgroup), t.3.div_ceil(workgroup), 1),
                block_dim: (workgroup, workgroup, 1),
                shared_mem_bytes: 0,
            };
            let mut launch = s.launch_builder(&self.loaded.function);
            launch
                .arg(&f.uniforms)
                .arg(&tile_view)
                .arg(&mut f.image)
                .arg(&mut f.stats);
            if let Some(d) = &f.data {
                launch.arg(d);
            }
            launch.arg(&mut f.pixels);
            if let Some((start, _)) = &timed {
                start.record(s).map_err(driver("recording an event"))?;
            }
            // SAFETY: the kernel's parameters are its buffers in binding order, as the PTX back
            // end declares them: four, the scene data when the kernel has it, and the finished
            // pixels, each at least as large as its type (`check_launch` compared them with the
            // kernel's parameters in `prepare`); the image, statistics and pixels hold every
            // pixel the tiles cover.
            unsafe { launch.launch(cfg) }.map_err(driver("launching the kernel"))?;
            if let Some((start, end)) = timed {
                end.record(s).map_err(driver("recording an event"))?;
                f.events.push((start, end));
            }
        }
        Ok(())
    }

    /// The finished pixels of `range`, copied (on the stream, behind the launches) into
    /// page-locked buffer `slot`; the linear colours are read at [`launch::Device::collect`].
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
        let bytes = 4 * range.len();
        let (kept, at) = &mut f.readback[slot];
        let mut pinned = match kept.take().filter(|p| p.len() >= bytes) {
            Some(p) => p,
            // SAFETY: page-locked host memory, cached (the host reads it); its bytes are read
            // only after the copy below has written them (`collect` reads the copied prefix).
            None => unsafe { self.cuda.ctx.alloc_pinned_with_flags::<u8>(bytes, 0) }
                .map_err(driver("allocating page-locked memory"))?,
        };
        let s = &self.cuda.stream;
        // The band's bytes alone, into the buffer's start: a buffer kept from a longer band
        // (the last band is shorter) is longer, and the driver copies as many bytes as the
        // destination holds, past the end of the pixels. The copy into a plain slice records
        // no event of the buffer's: its own is recorded behind it.
        let host = pinned
            .as_mut_slice()
            .map_err(driver("reading the pixels"))?;
        s.memcpy_dtoh(
            &f.pixels.slice(4 * range.start..4 * range.end),
            &mut host[..bytes],
        )
        .map_err(driver("reading the pixels"))?;
        let copied = s
            .record_event(Some(sys::CUevent_flags::CU_EVENT_DISABLE_TIMING))
            .map_err(driver("reading the pixels"))?;
        *kept = Some(pinned);
        *at = Some((range, copied));
        Ok(())
    }

    /// A band's finished pixels, from the page-locked buffer once its copy is done.
    fn copied(
        &self,
        f: &mut FrameBuffers,
        range: &Range<usize>,
        slot: usize,
        take: &mut dyn FnMut(&[u8]),
    ) -> Result<Option<Duration>, Error> {
        let (kept, at) = &mut f.readback[slot];
        let copied = at.take().filter(|(r, _)| r == range);
        let (Some(pinned), Some((_, copied))) = (kept.as_ref(), copied) else {
            return Ok(None);
        };
        let waiting = Instant::now();
        // Waits for the copy alone: the launches queued after it may still run.
        copied.synchronize().map_err(driver("reading the pixels"))?;
        let wait = waiting.elapsed();
        let bytes = pinned.as_slice().map_err(driver("reading the pixels"))?;
        take(&bytes[..4 * range.len()]);
        Ok(Some(wait))
    }

    fn read(
        &self,
        f: &mut FrameBuffers,
        work: &Work,
        ranges: &[Range<usize>],
    ) -> Result<Pixels, Error> {
        let s = &self.cuda.stream;
        let n: usize = ranges.iter().map(|r| r.end - r.start).sum();
        // The finished pixels (4 bytes each) or the linear colours (4 floats).
        let paged = work.finished() && ranges.len() != 1;
        let mut rgba = vec![0u8; if paged { 4 * n } else { 0 }];
        let mut image = vec![0f32; if work.finished() { 0 } else { 4 * n }];
        if work.finished() && ranges.len() == 1 {
            // Through the kept page-locked buffer, then copied out.
            let r = &ranges[0];
            rgba = self.read_pinned(&f.pixels.slice(4 * r.start..4 * r.end))?;
        }
        let mut at = 0;
        for r in ranges {
            let len = r.end - r.start;
            if work.finished() && ranges.len() == 1 {
                // Read above.
            } else if work.finished() {
                s.memcpy_dtoh(
                    &f.pixels.slice(4 * r.start..4 * r.end),
                    &mut rgba[4 * at..4 * (at + len)],
                )
                .map_err(driver("reading the pixels"))?;
            } else {
                s.memcpy_dtoh(
                    &f.image.slice(4 * r.start..4 * r.end),
                    &mut image[4 * at..4 * (at + len)],
                )
                .map_err(driver("reading the image"))?;
            }
            at += len;
        }
        s.synchronize().map_err(driver("reading the image"))?;
        let convert = Instant::now();
        let linear = {
            use rayon::prelude::*;
            image
                .par_chunks_exact(4)
                .map(|c| [c[0], c[1], c[2]])
                .collect()
        };
        drop(image);
        Ok(Pixels {
            linear,
            rgba,
            convert: convert.elapsed(),
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
        let reducer = self.cuda.reducer()?;
        let s = &self.cuda.stream;
        let (first, second) = reduce::threads(work.pixels());
        let record = reduction::RECORD as usize;
        if f.reduction.is_none() {
            let partial = s
                .alloc_zeros::<u32>(first as usize * record)
                .map_err(driver("allocating the statistics' reduction"))?;
            let total = s
                .alloc_zeros::<u32>(second as usize * record)
                .map_err(driver("allocating the statistics' reduction"))?;
            f.reduction = Some((partial, total));
        }
        let Some((partial, total)) = f.reduction.as_mut() else {
            unreachable!("made above")
        };
        let words: Vec<u32> = queries.iter().flat_map(|q| q.words()).collect();
        let slots = s
            .clone_htod(&words)
            .map_err(driver("uploading the reduction's queries"))?;
        let n = reduction::QUERY_WORDS as usize;
        for (i, q) in queries.iter().enumerate() {
            let query = slots.slice(n * i..n * (i + 1));
            let cfg = LaunchConfig {
                grid_dim: (q.threads.div_ceil(reduction::WORKGROUP), 1, 1),
                block_dim: (reduction::WORKGROUP, 1, 1),
                shared_mem_bytes: 0,
            };
            let mut launch = s.launch_builder(&reducer.function);
            launch
                .arg(&query)
                .arg(&f.stats)
                .arg(&mut *partial)
                .arg(&mut *total);
            // SAFETY: the reduction's parameters are its four buffers in binding order (the
            // PTX back end's interface): a query of `QUERY_WORDS` words, the frame's
            // statistics (`STATS_WORDS` a pixel, every pixel a query names within the frame),
            // and the partial records and totals, a record of `RECORD` words for each thread
            // of the first and second stage (`reduce::threads`, which sized them).
            unsafe { launch.launch(cfg) }.map_err(driver("reducing the statistics"))?;
        }
        let totals = s
            .clone_dtoh(&*total)
            .map_err(driver("reading the statistics"))?;
        s.synchronize().map_err(driver("reducing the statistics"))?;
        Ok(Answer::of_totals(&totals, ask))
    }

    fn finish(&self, f: FrameBuffers, work: &Work) -> Result<Option<Duration>, Error> {
        let mut time = None;
        if work.timed {
            let mut ms = 0.0f64;
            for (start, end) in &f.events {
                ms += start.elapsed_ms(end).map_err(driver("reading the timer"))? as f64;
            }
            time = Some(Duration::from_secs_f64(ms / 1e3));
        }
        if let Ok(mut spare) = self.cuda.spare.lock() {
            *spare = Some(f);
        }
        Ok(time)
    }

    fn fault(&self, message: String) -> Error {
        Error::Injected(message)
    }
}

/// `Err` unless the buffers a launch passes are those `k`'s parameters declare: the uniform
/// (binding 0), a tile (1), the image (2) and statistics (3) of `pixels` pixels, `data` (4)
/// exactly when the kernel reads `scene_data`, and the finished pixels (5); each a device
/// address, each as large as its type.
fn check_launch(
    k: &Loaded,
    uniforms: &[u8],
    pixels: usize,
    stats_words: u32,
    data: Option<&[u8]>,
) -> Result<(), Error> {
    let address = std::mem::size_of::<sys::CUdeviceptr>() as u32;
    let arg = |binding, space, bytes: usize| Argument {
        group: 0,
        binding,
        space,
        bytes: bytes as u64,
        size: address,
    };
    let writable = Space::Storage { writable: true };
    let mut args = vec![
        arg(0, Space::Uniform, uniforms.len()),
        arg(1, Space::Uniform, 4 * std::mem::size_of::<u32>()),
        arg(2, writable, pixels * 4 * std::mem::size_of::<f32>()),
        arg(3, writable, pixels * stats_words as usize * 4),
    ];
    if let Some(d) = data {
        args.push(arg(4, Space::Storage { writable: false }, d.len()));
    }
    args.push(arg(5, writable, pixels * 4));
    ptx::check_arguments(&k.params, &args).map_err(Error::Arguments)
}
