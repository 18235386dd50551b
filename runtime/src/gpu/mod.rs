//! GPU targets: the WGSL kernel launched through wgpu, and its PTX translation launched
//! through the CUDA driver. Results have the CPU renderer's shape (an image and the same
//! statistics) so that every backend is compared the same way.

pub mod cpu;
pub mod cuda;
pub mod launch;
pub mod points;
pub mod reduce;
pub mod wgpu;

use crate::cpu::{Counters, Render, Stats};
use crate::image::{Image, Rgba8};
use crate::memory::Memory;
use sdfc_compiler::{
    wgsl::{self, Kernel, STATS_WORDS},
    Scene, Settings,
};
use std::path::PathBuf;
use std::time::{Duration, Instant};

pub use self::launch::FAULT_AFTER_TILES;
pub use self::wgpu::{Error, Gpu};

/// The file where a compiled kernel is cached between processes, named by the hash of `key`
/// (everything the compiled code depends on: the kernel's text, the device, the driver's
/// options, sdfc's version) with the extension `ext`: in `$SDFC_CACHE_DIR`, else
/// `$XDG_CACHE_HOME/sdfc/KIND`, else `~/.cache/sdfc/KIND`, where `kind` is `cuda` (the
/// driver JIT's cubins) or `wgpu` (the Vulkan driver's pipeline cache data). `None` when
/// there is no home. The caches are an optimisation: failing to read or write them is not an
/// error.
pub(crate) fn cache_file(kind: &str, key: &impl std::hash::Hash, ext: &str) -> Option<PathBuf> {
    use std::hash::Hasher;
    let dir = match std::env::var_os("SDFC_CACHE_DIR") {
        Some(d) => PathBuf::from(d),
        None => match std::env::var_os("XDG_CACHE_HOME") {
            Some(d) => PathBuf::from(d).join("sdfc").join(kind),
            None => PathBuf::from(std::env::var_os("HOME")?)
                .join(".cache")
                .join("sdfc")
                .join(kind),
        },
    };
    let mut h = std::collections::hash_map::DefaultHasher::new();
    key.hash(&mut h);
    Some(dir.join(format!("{:016x}.{ext}", h.finish())))
}

/// Tile edge in pixels for GPU launches: a 1920×1080 frame is one launch, a 7680×4320 one
/// twelve. Every launch waits for its slowest rays, so the fewer launches a frame takes, the
/// less of the GPU idles in their tails. A 2048×2048
/// dispatch of the slowest example still lasts well under a display driver's watchdog
/// (about 2 s).
pub const TILE: u32 = 2048;

/// A GPU render and how long the GPU spent on it.
#[derive(Debug, Clone)]
pub struct GpuRender {
    /// Image and statistics (the image empty when the frame was finished on the device).
    pub render: Render,
    /// The pixels finished on the device (clamped, sRGB-encoded RGBA8), when they were read
    /// back instead of the linear colours ([`launch::Work::finished`]).
    pub finished: Option<Rgba8>,
    /// Where the frame's wall time went on the host.
    pub phases: Phases,
    /// Time of the dispatches (GPU timestamps where the adapter has them, else wall time).
    pub time: Duration,
    /// Whether `time` comes from GPU timestamps.
    pub timestamps: bool,
    /// Wall time from the first submission until the GPU finished (launch overheads
    /// included, readback excluded).
    pub wall: Duration,
    /// What each device did, when several rendered the frame ([`render_several`]).
    pub shares: Vec<launch::Share>,
}

/// Where a GPU frame's wall time went on the host (`sdfc render --stats`): buffers allocated
/// and uploaded, the launches until the GPU finished, the image and statistics read back, and
/// their conversion (to colours, statistics words and the frame's statistics).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Phases {
    pub setup: Duration,
    pub launches: Duration,
    pub readback: Duration,
    pub convert: Duration,
}

impl Phases {
    /// The whole of it.
    pub fn total(&self) -> Duration {
        self.setup + self.launches + self.readback + self.convert
    }
}

impl std::fmt::Display for Phases {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        write!(
            f,
            "{:.2} ms: setup {:.2} ms, launches {:.2} ms, readback {:.2} ms, conversion {:.2} ms",
            ms(self.total()),
            ms(self.setup),
            ms(self.launches),
            ms(self.readback),
            ms(self.convert)
        )
    }
}

/// Renders `scene` with an already generated kernel on `gpu` (with the faults of
/// [`FAULT_AFTER_TILES`] injected).
pub fn render(
    gpu: &Gpu,
    scene: &Scene,
    kernel: &Kernel,
    lipschitz: f64,
    progress: &mut dyn FnMut(f64),
) -> Result<GpuRender, Error> {
    render_faults(
        gpu,
        scene,
        kernel,
        lipschitz,
        (&launch::Faults::from_env(), true, false),
        progress,
    )
}

/// [`render`] with the faults `faults` injected, reducing the per-pixel statistics on the
/// device only when `statistics` ([`launch::Work::statistics`]), and the finished pixels instead of the
/// linear colours when `finished` ([`launch::Work::finished`]).
pub fn render_faults(
    gpu: &Gpu,
    scene: &Scene,
    kernel: &Kernel,
    lipschitz: f64,
    (faults, statistics, finished): (&launch::Faults, bool, bool),
    progress: &mut dyn FnMut(f64),
) -> Result<GpuRender, Error> {
    let uniforms =
        wgsl::uniforms(&kernel.contract.uniform, scene, lipschitz).map_err(Error::Uniform)?;
    let device = gpu.kernel(&kernel.source, wgsl::ENTRY_POINT, wgsl::WORKGROUP);
    render_one(
        &device,
        scene,
        &uniforms,
        kernel.data.as_deref(),
        (faults, statistics, finished),
        progress,
    )
}

/// Renders `scene` with a kernel already loaded on a CUDA device, whose uniform is laid out
/// as `uniform`; `data` is the kernel's scene data ([`Kernel::data`]); `faults` are injected,
/// the per-pixel statistics reduced only when `statistics`, the finished pixels instead of
/// the linear colours when `finished`.
pub fn render_cuda(
    cuda: &cuda::Cuda,
    scene: &Scene,
    (loaded, uniform, data): (&cuda::Loaded, &wgsl::Uniform, Option<&[u8]>),
    lipschitz: f64,
    (faults, statistics, finished): (&launch::Faults, bool, bool),
    progress: &mut dyn FnMut(f64),
) -> Result<GpuRender, cuda::Error> {
    let uniforms = wgsl::uniforms(uniform, scene, lipschitz)?;
    let device = cuda.kernel(loaded, wgsl::WORKGROUP);
    render_one(
        &device,
        scene,
        &uniforms,
        data,
        (faults, statistics, finished),
        progress,
    )
}

/// The work of a frame of the settings `s` in the tiles `tiles`: the kernel's uniforms and
/// scene data, whether launches are timed, whether statistics are reduced and whether pixels
/// are finished on the device.
fn work<'a>(
    s: &Settings,
    (uniforms, data): (&'a [u8], Option<&'a [u8]>),
    tiles: &'a [launch::Tile],
    timed: bool,
    (statistics, finished): (bool, bool),
) -> launch::Work<'a> {
    launch::Work {
        uniforms,
        data,
        width: s.width,
        height: s.height,
        tiles,
        timed,
        statistics,
        finished,
    }
}

/// Renders `scene` on one device, in squares of [`TILE`] pixels (finished pixels read back a
/// row of squares at a time, each while the next renders: [`launch::render_one`]).
fn render_one<D: launch::Device>(
    device: &D,
    scene: &Scene,
    uniforms: &[u8],
    data: Option<&[u8]>,
    (faults, statistics, finished): (&launch::Faults, bool, bool),
    progress: &mut dyn FnMut(f64),
) -> Result<GpuRender, D::Error> {
    let s = &scene.settings;
    let tiles = launch::tiling(s.width, s.height, TILE, 1);
    let work = work(s, (uniforms, data), &tiles, true, (statistics, finished));
    let out = launch::render_one(device, &work, faults, progress)?;
    Ok(finish(out, s))
}

/// Why a frame on several devices failed.
#[derive(Debug, thiserror::Error)]
pub enum SeveralFailed {
    /// The scene's uniforms do not fit the kernel's layout.
    #[error(transparent)]
    Layout(#[from] wgsl::Mismatch),
    /// Every device failed.
    #[error(transparent)]
    Devices(#[from] launch::SeveralError),
}

/// Renders `scene` on several devices at once ([`launch::render_several`]): the kernel's
/// uniforms are those of `scene` with the Lipschitz bound `lipschitz`, laid out as `uniform`
/// (none when every device is the CPU), and `data` its scene data, the same on every GPU
/// device. `Err` when every device failed.
pub fn render_several(
    devices: &[&dyn launch::Worker],
    scene: &Scene,
    (lipschitz, uniform, data): (f64, Option<&wgsl::Uniform>, Option<&[u8]>),
    (faults, statistics, finished): (&launch::Faults, bool, bool),
    progress: &mut dyn FnMut(f64),
) -> Result<GpuRender, SeveralFailed> {
    let s = &scene.settings;
    let uniforms = match uniform {
        Some(u) => wgsl::uniforms(u, scene, lipschitz)?,
        None => Vec::new(),
    };
    let tiles = launch::tiling(s.width, s.height, TILE, devices.len());
    let work = work(s, (&uniforms, data), &tiles, false, (statistics, finished));
    let out = launch::render_several(devices, &work, faults, progress)?;
    Ok(finish(out, s))
}

/// The image and statistics of a frame the scheduler rendered.
fn finish(out: launch::Output, s: &Settings) -> GpuRender {
    let start = Instant::now();
    let summary = out.summary;
    let mut counters = summary.counters;
    counters.camera_rays = (s.width as u64) * (s.height as u64) * (s.aa.max(1) as u64).pow(2);
    let pixels = s.width as u64 * s.height as u64;
    let stats = Stats::reduced(counters, pixels, summary.max, summary.p99);
    let mut phases = out.phases;
    phases.convert += start.elapsed();
    let finished = (!out.rgba.is_empty()).then_some(Rgba8 {
        width: s.width,
        height: s.height,
        bytes: out.rgba,
    });
    GpuRender {
        render: Render {
            image: Image {
                width: s.width,
                height: s.height,
                linear: out.linear,
            },
            stats,
            depth: None,
        },
        finished,
        phases,
        time: out.device_time.unwrap_or(out.wall),
        timestamps: out.device_time.is_some(),
        wall: out.wall,
        shares: out.shares,
    }
}

/// The most a wgpu render of `settings` allocates on each device that renders it, with a
/// scene uniform of `uniforms` bytes and scene data of `data` bytes (several devices each
/// allocate a whole frame's buffers). On the device: the uniform, the scene data, the tile
/// table, the image (16 bytes a pixel), finished pixels (4) and statistics buffers, the
/// readback copy of the image (the larger of what is read back), the statistics' reduction
/// ([`reduce_bytes`]) and the timestamp queries. On the host: wgpu's staging copy of the scene
/// data, the tile table (and its staging copy), the read-back bytes and their conversion to
/// colours (44 bytes a pixel, held at once).
pub fn memory_wgpu(settings: &Settings, uniforms: u64, data: u64) -> Memory {
    let (pixels, tiles) = pixels_and_tiles(settings);
    let stats = 4 * STATS_WORDS as u64 * pixels;
    let table = tiles * 256;
    let queries = 2 * tiles * 8;
    let reduction = reduce_bytes(pixels);
    let device = uniforms.max(16)
        + data
        + table
        + 20 * pixels
        + stats
        + 16 * pixels
        + reduction
        + 3 * queries;
    let host = data + 2 * table + 2 * queries + 44 * pixels + reduction;
    Memory { host, device }
}

/// The most a CUDA render of `settings` allocates on each device that renders it, with a
/// scene uniform of `uniforms` bytes and scene data of `data` bytes: on the device the
/// uniform, scene data, tile table, image, finished pixels (4 bytes a pixel), statistics and
/// their reduction ([`reduce_bytes`]); on the host the tile table, the read-back floats (16
/// bytes a pixel) and colours (12), and the reduction's totals.
pub fn memory_cuda(settings: &Settings, uniforms: u64, data: u64) -> Memory {
    let (pixels, tiles) = pixels_and_tiles(settings);
    let stats = 4 * STATS_WORDS as u64 * pixels;
    let reduction = reduce_bytes(pixels);
    let device = uniforms + data + 16 * tiles + 20 * pixels + stats + reduction;
    let host = 16 * tiles + 64 * tiles + 16 * pixels + 12 * pixels + reduction;
    Memory { host, device }
}

/// The bytes of the statistics' reduction for a frame of `pixels` pixels: its partial
/// records and totals ([`reduce::threads`]).
fn reduce_bytes(pixels: u64) -> u64 {
    let (first, second) = reduce::threads(pixels as usize);
    let record = 4 * sdfc_compiler::wgsl::reduce::RECORD as u64;
    (first as u64 + 2 * second as u64) * record
}

/// Copies `src` into `dst` (of the same length) on every core of the current thread pool: a
/// frame's pixels are copied into memory allocated for them, whose pages the first writes
/// fault in, which on one core holds the copy to about a gigabyte a second (measured;
/// [`crate::image::zeroed`] asks for fewer, larger pages).
pub(crate) fn copy_parallel<T: Copy + Send + Sync>(dst: &mut [T], src: &[T]) {
    use rayon::prelude::*;
    // A mebibyte a task: a 1920×1080 frame's 8 MB wakes 8 threads, not every core; on a host
    // of many cores waking them all costs more than the copy.
    let chunk = (1 << 20) / std::mem::size_of::<T>().max(1);
    dst.par_chunks_mut(chunk)
        .zip(src.par_chunks(chunk))
        .for_each(|(o, i)| o.copy_from_slice(i));
}

/// `src` copied by [`copy_parallel`] into a buffer of finished pixels from the pool of
/// [`crate::image::pixel_buffer`] (one an earlier frame handed back, its pages in memory
/// already, when there is one; else a new one, [`crate::image::zeroed`]).
pub(crate) fn to_vec_parallel(src: &[u8]) -> Vec<u8> {
    let mut out = crate::image::pixel_buffer(src.len());
    copy_parallel(&mut out, src);
    out
}

/// The bytes of a finished GPU frame: its image.
pub fn retained(settings: &Settings) -> u64 {
    12 * settings.width as u64 * settings.height as u64
}

fn pixels_and_tiles(settings: &Settings) -> (u64, u64) {
    let (w, h) = (settings.width as u64, settings.height as u64);
    let edge = TILE as u64;
    (w * h, w.div_ceil(edge) * h.div_ceil(edge))
}

/// Sums the kernel's per-pixel statistics words, read back whole, into the CPU renderer's
/// counters (all but the camera rays, which the settings give), with the marching steps of
/// each pixel: what the reduction on the device ([`reduce`]) computes, here on the host (for
/// checking it: [`wgpu::Gpu::last_statistics`]).
pub fn counters(words: &[u32]) -> (Counters, Vec<u32>) {
    use rayon::prelude::*;
    let n = STATS_WORDS as usize;
    // In parallel: a 1080p frame has two million pixels of STATS_WORDS words.
    let steps: Vec<u32> = words.par_chunks_exact(n).map(|w| w[0]).collect();
    let c = words
        .par_chunks_exact(n)
        .fold(Counters::default, |mut c, w| {
            c.steps += w[0] as u64;
            c.hits += w[1] as u64;
            c.misses += w[2] as u64;
            c.budget_misses += w[3] as u64;
            c.overshoots += w[4] as u64;
            c.nans += w[5] as u64;
            c.secondary_rays += w[6] as u64;
            c.shadow_rays += w[7] as u64;
            c.cut += w[8] as u64;
            c
        })
        .reduce(Counters::default, |mut a, b| {
            a.add(&b);
            a
        });
    (c, steps)
}
