//! GPU targets: the WGSL kernel launched through wgpu, and its PTX translation launched
//! through the CUDA driver. Results have the CPU renderer's shape (an image and the same
//! statistics) so that every backend is compared the same way.

pub mod cuda;
pub mod wgpu;

use crate::cpu::{Counters, Render, Stats};
use crate::image::Image;
use crate::memory::Memory;
use sdfc_compiler::back::wgsl::{self, Kernel, STATS_WORDS};
use sdfc_compiler::scene::Scene;
use std::time::Duration;

pub use self::wgpu::{Error, Gpu};

/// The testing aid `SDFC_FAULT_AFTER_TILES=N`: the GPU backends render N tiles, then report
/// a device error for the next one through the path a real device error takes (wgpu:
/// [`Error::Render`]; CUDA: a driver error), so that tests can check what a failure
/// mid-render leaves behind. Unset (or not a number), nothing is injected.
pub const FAULT_AFTER_TILES: &str = "SDFC_FAULT_AFTER_TILES";

/// The number of tiles after which to inject a device error, from [`FAULT_AFTER_TILES`].
pub(crate) fn fault_after_tiles() -> Option<usize> {
    std::env::var(FAULT_AFTER_TILES).ok()?.trim().parse().ok()
}

/// The message of the device error injected at tile `tile` (0-based), if one is.
pub(crate) fn injected_fault(after: Option<usize>, tile: usize) -> Option<String> {
    (after == Some(tile)).then(|| {
        format!(
            "device error injected at tile {} by {FAULT_AFTER_TILES}={tile} (a testing aid)",
            tile + 1
        )
    })
}

/// Tile edge in pixels for GPU launches: a 1920×1080 frame is one launch, a 7680×4320 one
/// twelve. Every launch waits for its slowest rays, so the fewer launches a frame takes, the
/// less of the GPU idles in their tails: on an H100 (BENCHMARKS.md, "Beside a hand-written
/// tracer", 2026-11-24) 2 048 against 512 pixels took seed 3 at 1920×1080 from 1.19 to
/// 0.64 ms (CUDA) and 1.28 to 0.68 ms (wgpu). A 2048×2048 dispatch of the slowest example
/// still lasts well under a display driver's watchdog (about 2 s).
pub const TILE: u32 = 2048;

/// A GPU render and how long the GPU spent on it.
#[derive(Debug, Clone)]
pub struct GpuRender {
    /// Image and statistics.
    pub render: Render,
    /// Where the frame's wall time went on the host.
    pub phases: Phases,
    /// Time of the dispatches (GPU timestamps where the adapter has them, else wall time).
    pub time: Duration,
    /// Whether `time` comes from GPU timestamps.
    pub timestamps: bool,
    /// Wall time from the first submission until the GPU finished (launch overheads
    /// included, readback excluded).
    pub wall: Duration,
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

/// Renders `scene` with an already generated kernel on `gpu`.
pub fn render(
    gpu: &Gpu,
    scene: &Scene,
    kernel: &Kernel,
    lipschitz: f64,
    progress: &mut dyn FnMut(f64),
) -> Result<GpuRender, Error> {
    let s = &scene.settings;
    let uniforms = wgsl::uniforms(&kernel.contract.uniform, scene, lipschitz)
        .map_err(|e| Error::Uniform(e.0))?;
    let launch = self::wgpu::Launch {
        wgsl: &kernel.source,
        entry: wgsl::ENTRY_POINT,
        uniforms: &uniforms,
        data: kernel.data.as_deref(),
        width: s.width,
        height: s.height,
        stats_words: STATS_WORDS,
        workgroup: wgsl::WORKGROUP,
        tile: TILE,
    };
    let frame = gpu.render(&launch, progress)?;
    let start = std::time::Instant::now();
    let stats = stats(&frame.stats, (s.width as u64) * (s.height as u64), s.aa);
    let mut phases = frame.phases;
    phases.convert += start.elapsed();
    let image = Image {
        width: s.width,
        height: s.height,
        linear: frame.linear,
    };
    Ok(GpuRender {
        render: Render {
            image,
            stats,
            depth: None,
        },
        phases,
        time: frame.gpu_time.unwrap_or(frame.wall_time),
        timestamps: frame.gpu_time.is_some(),
        wall: frame.wall_time,
    })
}

/// Renders `scene` with a kernel already loaded on a CUDA device, whose uniform is laid out
/// as `uniform`; `data` is the kernel's scene data ([`Kernel::data`]).
pub fn render_cuda(
    cuda: &cuda::Cuda,
    scene: &Scene,
    loaded: &cuda::Loaded,
    uniform: &wgsl::Uniform,
    data: Option<&[u8]>,
    lipschitz: f64,
) -> Result<GpuRender, cuda::Error> {
    let s = &scene.settings;
    let uniforms =
        wgsl::uniforms(uniform, scene, lipschitz).map_err(|e| cuda::Error::Arguments(e.0))?;
    let frame = cuda.render(
        loaded,
        &uniforms,
        data,
        s.width,
        s.height,
        STATS_WORDS,
        wgsl::WORKGROUP,
        TILE,
    )?;
    let start = std::time::Instant::now();
    let stats = stats(&frame.stats, (s.width as u64) * (s.height as u64), s.aa);
    let mut phases = frame.phases;
    phases.convert += start.elapsed();
    let image = Image {
        width: s.width,
        height: s.height,
        linear: frame.linear,
    };
    Ok(GpuRender {
        render: Render {
            image,
            stats,
            depth: None,
        },
        phases,
        time: frame.gpu_time,
        timestamps: true,
        wall: frame.wall_time,
    })
}

/// The most a wgpu render of `settings` allocates, with a scene uniform of `uniforms` bytes and
/// scene data of `data` bytes. On the device: the uniform, the scene data, the tile table, the
/// image (16 bytes a pixel) and statistics buffers, their readback copies and the timestamp
/// queries. On the host: wgpu's staging copy of the scene data, the tile table (and its
/// staging copy), the read-back bytes and their conversion to colours and statistics words,
/// then the statistics' per-pixel steps and their sorted copy.
pub fn memory_wgpu(settings: &sdfc_compiler::scene::Settings, uniforms: u64, data: u64) -> Memory {
    let (pixels, tiles) = pixels_and_tiles(settings);
    let stats = 4 * STATS_WORDS as u64 * pixels;
    let table = tiles * 256;
    let queries = 2 * tiles * 8;
    let device = uniforms.max(16) + data + table + 2 * (16 * pixels + stats) + 3 * queries;
    // Read back: the image's bytes (16 a pixel), floats (16) and colours (12), and the
    // statistics' bytes and words, all held at once (more than the colours, words, steps and
    // sorted steps held afterwards).
    let host = data + 2 * table + 2 * queries + 44 * pixels + 2 * stats;
    Memory { host, device }
}

/// The most a CUDA render of `settings` allocates, with a scene uniform of `uniforms` bytes
/// and scene data of `data` bytes: on the device the uniform, scene data, tile table, image and
/// statistics; on the host the tile table, the read-back floats (16 bytes a pixel), colours
/// (12) and statistics, then the steps.
pub fn memory_cuda(settings: &sdfc_compiler::scene::Settings, uniforms: u64, data: u64) -> Memory {
    let (pixels, tiles) = pixels_and_tiles(settings);
    let stats = 4 * STATS_WORDS as u64 * pixels;
    let device = uniforms + data + 16 * tiles + 16 * pixels + stats;
    let host = 16 * tiles + 64 * tiles + 16 * pixels + 12 * pixels + stats + 8 * pixels;
    Memory { host, device }
}

/// The bytes of a finished GPU frame: its image.
pub fn retained(settings: &sdfc_compiler::scene::Settings) -> u64 {
    12 * settings.width as u64 * settings.height as u64
}

fn pixels_and_tiles(settings: &sdfc_compiler::scene::Settings) -> (u64, u64) {
    let (w, h) = (settings.width as u64, settings.height as u64);
    let edge = TILE as u64;
    (w * h, w.div_ceil(edge) * h.div_ceil(edge))
}

/// Sums the kernel's per-pixel statistics words into the CPU renderer's statistics.
pub fn stats(words: &[u32], pixels: u64, aa: u32) -> Stats {
    use rayon::prelude::*;
    let n = STATS_WORDS as usize;
    // In parallel: a 1080p frame has two million pixels of eight words.
    let steps: Vec<u32> = words.par_chunks_exact(n).map(|w| w[0]).collect();
    let mut c = words
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
            c
        })
        .reduce(Counters::default, |mut a, b| {
            a.add(&b);
            a
        });
    c.camera_rays = pixels * (aa.max(1) as u64).pow(2);
    Stats::new(c, &steps)
}
