//! What a CPU render allocates, at most: the bound `sdfc render` announces and holds to the
//! `memory` limit. `runtime/tests/memory/memory.rs` measures renders with a counting allocator against it.
//!
//! Every vector the renderer allocates is counted at its largest: a vector filled by `push`
//! or `resize` may hold up to twice its largest length (and at least 8 elements). A tile's
//! waves of rays are bounded by the depth-first tracing of `tile.rs`.

use super::context::{branching, Lamp, Mat};
use super::lanes::{Lanes, Launch};
use super::march::{Shadowed, Traced};
use super::shade::Hit;
use super::tile::{Rect, TileOut, WAVE};
use super::vec::V3;
use super::wave::Ray;
use super::{Options, Precision, Tapes};
use sdfc_compiler::{Evaluator, Float, Scene, Settings};
use std::mem::size_of;

/// Allocations of the thread pool and the collection of tiles, whatever the image.
const BOOKKEEPING: u64 = 1 << 20;

/// `count` values of `X`, in bytes.
fn bytes<X>(count: u64) -> u64 {
    count.saturating_mul(size_of::<X>() as u64)
}

/// The capacity of a vector of `X` grown by `push` or `resize` to at most `count`, in bytes.
fn grown<X>(count: u64) -> u64 {
    bytes::<X>(count.saturating_mul(2).max(8))
}

/// The most bytes [`super::render_tapes`] allocates rendering `scene` with `tapes` on
/// `threads` threads, its result included.
pub fn memory(scene: &Scene, tapes: &Tapes, options: &Options, threads: usize) -> u64 {
    match options.precision {
        Precision::F32 => in_type::<f32>(scene, tapes, options, threads),
        Precision::F64 => in_type::<f64>(scene, tapes, options, threads),
    }
}

/// The bytes of a finished render (the image and its depth buffers).
pub fn retained(settings: &Settings) -> u64 {
    let pixels = settings.width as u64 * settings.height as u64;
    bytes::<[f32; 3]>(pixels).saturating_add(bytes::<f32>(2 * pixels))
}

/// The sizes a render's allocations depend on.
struct Shape {
    /// Pixels of the image.
    pixels: u64,
    /// Tiles of the image.
    tiles: u64,
    /// Samples (camera rays) of the largest tile.
    samples: u64,
    /// The most rays traced at once: the camera rays of a tile, or a piece of a later wave.
    wave: u64,
    /// Rays one hit spawns at most.
    branching: u64,
    /// Shadow rays per hit at most.
    lamps: u64,
}

impl Shape {
    fn new(scene: &Scene, options: &Options) -> Self {
        let s = &scene.settings;
        let edge = options.tile.max(1) as u64;
        let (w, h) = (s.width as u64, s.height as u64);
        let spp = (s.aa.max(1) as u64).pow(2);
        let samples = edge.min(w) * edge.min(h) * spp;
        let branching = branching(scene) as u64;
        let wave = if branching > 0 {
            samples.max(WAVE as u64)
        } else {
            samples
        };
        Shape {
            pixels: w * h,
            tiles: w.div_ceil(edge) * h.div_ceil(edge),
            samples,
            wave,
            branching,
            lamps: scene.lights.len() as u64,
        }
    }
}

fn in_type<T: Float>(scene: &Scene, tapes: &Tapes, options: &Options, threads: usize) -> u64 {
    let shape = Shape::new(scene, options);
    let per_thread = workspace::<T>(&shape, scene, tapes, options)
        .saturating_add(tile::<T>(&shape, scene.settings.max_depth as u64));
    shared::<T>(&shape, scene, tapes)
        .saturating_add(per_thread.saturating_mul(threads.max(1) as u64))
        .saturating_add(BOOKKEEPING)
}

/// What the whole render holds: the tiles' outputs, the assembled image, steps and depth
/// buffers with the sorted copy of the steps, the list of tiles, materials and lights.
fn shared<T: Float>(shape: &Shape, scene: &Scene, tapes: &Tapes) -> u64 {
    // Per pixel: the tile outputs (colour, steps, distance, coverage: 24 bytes) and the
    // assembled image (12), steps (4), sorted steps (4) and depth buffers (8).
    let per_pixel = 24 + 12 + 4 + 4 + 8;
    [
        shape.pixels.saturating_mul(per_pixel),
        grown::<Rect>(shape.tiles),
        bytes::<TileOut>(shape.tiles),
        bytes::<Mat<T>>(scene.materials.len() as u64 + 1),
        bytes::<Lamp<T>>(shape.lamps),
        super::analytic::heap_bytes::<T>(scene, &tapes.traceable),
    ]
    .into_iter()
    .fold(0, u64::saturating_add)
}

/// A thread's workspace, kept from tile to tile: evaluators (where `scene` marches: a
/// traced render has none), lanes and the buffers of a wave.
fn workspace<T: Float>(shape: &Shape, scene: &Scene, tapes: &Tapes, options: &Options) -> u64 {
    let w = shape.wave;
    let marched = tapes.traceable.traced(scene.settings.method).is_none();
    let evaluators: usize = if marched {
        tapes
            .all()
            .into_iter()
            .map(|t| Evaluator::<T>::heap_bytes(t, options.chunk))
            .sum()
    } else {
        0
    };
    let lanes = Lanes::<T>::heap_bytes(options.lanes.max(1));
    [
        evaluators as u64,
        lanes as u64,
        grown::<Launch<T>>(w.saturating_mul(shape.lamps.max(1))),
        grown::<Traced<T>>(w),
        // Under analytic tracing, the normal and material of each traced ray.
        grown::<(V3<T>, u32)>(w),
        grown::<Shadowed<T>>(w.saturating_mul(shape.lamps)),
        // x, y, z and d hold four normal taps per hit; m one material per hit.
        4 * grown::<T>(w.saturating_mul(4)),
        grown::<u32>(w),
    ]
    .into_iter()
    .fold(0, u64::saturating_add)
}

/// What one tile holds while it renders: its samples, its camera rays, the waves waiting to
/// be traced (one per level of the depth-first descent) and the buffers of one bounce.
fn tile<T: Float>(shape: &Shape, max_depth: u64) -> u64 {
    let (s, b, w) = (shape.samples, shape.branching, shape.wave);
    // Level 1 holds what the camera rays spawned; each deeper level what a piece spawned.
    let waiting = b
        .saturating_mul(s)
        .saturating_add(max_depth.saturating_sub(1).saturating_mul(b * WAVE as u64));
    [
        bytes::<V3<T>>(s),
        bytes::<u32>(s),
        bytes::<bool>(s),
        bytes::<Ray<T>>(s.saturating_add(waiting)),
        grown::<Hit<T>>(w),
        bytes::<V3<T>>(w),
        grown::<(usize, V3<T>)>(w.saturating_mul(shape.lamps)),
    ]
    .into_iter()
    .fold(0, u64::saturating_add)
}
