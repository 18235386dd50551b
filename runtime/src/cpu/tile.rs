//! One tile of the image: its camera rays, the waves of secondary rays they spawn, and the
//! per-thread workspace the waves run in.
//!
//! Secondary rays are traced in waves of at most [`WAVE`] rays, depth first: the rays a
//! piece of a wave spawns are traced (and theirs, and so on) before the next piece. A hit
//! can spawn two rays (glass reflects and refracts), so tracing whole waves breadth first
//! would hold up to 2^depth rays per sample; depth first, a tile holds at most
//! `max_depth` pieces at once, which is what `super::memory` counts on.

use super::context::Context;
use super::march::{Status, Traced};
use super::shade;
use super::stats::Counters;
use super::vec::V3;
use super::wave::{Ray, Samples, Workspace};
use sdfc_compiler::Float;

/// A pixel rectangle.
#[derive(Debug, Clone, Copy)]
pub(super) struct Rect {
    pub x: u32,
    pub y: u32,
    pub w: u32,
    pub h: u32,
}

/// Secondary rays are traced in pieces of at most this many rays.
pub(super) const WAVE: usize = 1024;

/// What a tile produces.
#[derive(Debug)]
pub(super) struct TileOut {
    /// Linear colours, row-major within the tile.
    pub pixels: Vec<[f32; 3]>,
    /// Marching steps per pixel.
    pub steps: Vec<u32>,
    /// Mean first-hit distance of the pixel's camera rays that hit (NaN where none hit).
    pub distance: Vec<f32>,
    /// Fraction of the pixel's camera rays that hit.
    pub coverage: Vec<f32>,
    pub counters: Counters,
}

/// Renders one tile.
pub(super) fn render<T: Float>(ctx: &Context<T>, ws: &mut Workspace<'_, T>, rect: Rect) -> TileOut {
    if ctx.path {
        return super::path::render(ctx, ws, rect);
    }
    let spp = ctx.camera.samples_per_pixel();
    let mut samples = Samples::new((rect.w * rect.h * spp) as usize, ctx.debug_nan);
    let mut counters = Counters::default();
    let camera = camera_rays(ctx, rect);
    counters.camera_rays = camera.len() as u64;
    let next = shade::bounce(ctx, ws, &camera, &mut samples, &mut counters);
    let (distance, coverage) = first_hits(&ws.traced, spp as usize);
    drop(camera);
    descend(ctx, ws, &next, &mut samples, &mut counters);
    let scale = T::one() / T::from_f64(spp as f64);
    let chunk = spp as usize;
    let mut pixels: Vec<[f32; 3]> = samples
        .acc
        .chunks(chunk)
        .map(|s| {
            let sum = super::look::grade(ctx, s.iter().fold(V3::zero(), |a, &c| a + c) * scale);
            [
                sum.x.to_f64() as f32,
                sum.y.to_f64() as f32,
                sum.z.to_f64() as f32,
            ]
        })
        .collect();
    for (pixel, nan) in pixels.iter_mut().zip(samples.nan.chunks(chunk)) {
        if nan.contains(&true) {
            *pixel = super::NAN_COLOUR;
        }
    }
    let steps = samples
        .steps
        .chunks(chunk)
        .map(|s| s.iter().sum())
        .collect();
    TileOut {
        pixels,
        steps,
        distance,
        coverage,
        counters,
    }
}

/// Traces `wave` and, depth first, every ray it spawns, in pieces of at most [`WAVE`] rays.
/// The recursion is as deep as `max_depth`: rays at that depth spawn none.
fn descend<T: Float>(
    ctx: &Context<T>,
    ws: &mut Workspace<'_, T>,
    wave: &[Ray<T>],
    samples: &mut Samples<T>,
    counters: &mut Counters,
) {
    for piece in wave.chunks(WAVE) {
        let next = shade::bounce(ctx, ws, piece, samples, counters);
        descend(ctx, ws, &next, samples, counters);
    }
}

/// Per pixel, from the camera rays' results (`spp` consecutive samples per pixel): the mean
/// distance to the first hit over the rays that hit (NaN where none did) and the fraction of
/// rays that hit.
pub(super) fn first_hits<T: Float>(traced: &[Traced<T>], spp: usize) -> (Vec<f32>, Vec<f32>) {
    let pixels = traced.len() / spp.max(1);
    let mut distance = Vec::with_capacity(pixels);
    let mut coverage = Vec::with_capacity(pixels);
    for samples in traced.chunks(spp.max(1)) {
        let (mut sum, mut hits) = (T::zero(), 0u32);
        for s in samples.iter().filter(|s| s.status == Status::Hit) {
            sum = sum + s.t;
            hits += 1;
        }
        distance.push(if hits == 0 {
            f32::NAN
        } else {
            (sum / T::from_f64(hits as f64)).to_f64() as f32
        });
        coverage.push(hits as f32 / samples.len() as f32);
    }
    (distance, coverage)
}

/// One ray per sample, pixels row-major, samples row-major within the pixel.
fn camera_rays<T: Float>(ctx: &Context<T>, rect: Rect) -> Vec<Ray<T>> {
    let spp = ctx.camera.samples_per_pixel();
    let mut rays = Vec::with_capacity((rect.w * rect.h * spp) as usize);
    for y in rect.y..rect.y + rect.h {
        for x in rect.x..rect.x + rect.w {
            for s in 0..spp {
                rays.push(Ray {
                    origin: ctx.camera.origin(),
                    dir: ctx.camera.direction(x, y, s),
                    t0: T::zero(),
                    weight: V3::splat(T::one()),
                    sample: rays.len() as u32,
                    depth: 0,
                    inside: false,
                    pdf: T::zero(),
                    sky_pdf: T::zero(),
                });
            }
        }
    }
    rays
}
