//! The rays of a wave and what they are traced with: a ray waiting to be traced, the
//! samples the rays of a tile add up to, and the per-thread workspace (evaluators, lanes,
//! buffers) that tiles (`tile.rs`) and the shading of each wave (`shade.rs`) share.

use super::context::Context;
use super::lanes::{Lanes, Launch};
use super::march::{Shadowed, Traced};
use super::vec::V3;
use super::Tapes;
use sdfc_compiler::{Evaluator, Float};

/// A ray waiting to be traced, with what it contributes to.
#[derive(Debug, Clone, Copy)]
pub(super) struct Ray<T> {
    pub origin: V3<T>,
    pub dir: V3<T>,
    /// Path length of the pixel's ray before this segment.
    pub t0: T,
    /// The colour weight this ray's result is added with.
    pub weight: V3<T>,
    /// The sample (index within the tile) it belongs to.
    pub sample: u32,
    /// 0 for camera rays, +1 per bounce.
    pub depth: u32,
    /// Whether it travels inside a solid (marching -f).
    pub inside: bool,
    /// The path tracer's density of the direction as its last bounce drew it, for the
    /// weight of the sky it may reach (0: a camera ray, a mirror's or a refraction's, whose
    /// sky is not weighed; always 0 in the Whitted renderer).
    pub pdf: T,
    /// The density the sky's next-event estimate at its origin gave the direction (`N·D/π`).
    pub sky_pdf: T,
}

impl<T: Float> Ray<T> {
    /// The ray this one's hit at path length `t0` sends on from `origin` along `dir` (one
    /// bounce deeper, of the same sample), with no densities.
    pub fn child(&self, t0: T, origin: V3<T>, dir: V3<T>, weight: V3<T>, inside: bool) -> Ray<T> {
        Ray {
            origin,
            dir,
            t0,
            weight,
            sample: self.sample,
            depth: self.depth + 1,
            inside,
            pdf: T::zero(),
            sky_pdf: T::zero(),
        }
    }
}

/// What the rays of a tile add up to, per sample (index within the tile).
#[derive(Debug)]
pub(super) struct Samples<T> {
    /// Colour gathered so far.
    pub acc: Vec<V3<T>>,
    /// Marching steps taken.
    pub steps: Vec<u32>,
    /// With `--debug-nan`: whether a ray of the sample met a NaN (else empty).
    pub nan: Vec<bool>,
}

impl<T: Float> Samples<T> {
    pub fn new(n: usize, debug_nan: bool) -> Self {
        Samples {
            acc: vec![V3::zero(); n],
            steps: vec![0; n],
            nan: if debug_nan {
                vec![false; n]
            } else {
                Vec::new()
            },
        }
    }

    /// Records that a ray of `sample` met a NaN (kept only with `--debug-nan`).
    pub fn met_nan(&mut self, sample: u32) {
        if let Some(flag) = self.nan.get_mut(sample as usize) {
            *flag = true;
        }
    }
}

/// Evaluators of the scene's media (`super::Tapes::new`).
#[derive(Debug)]
pub(super) struct Media<'t, T: Float> {
    pub medium: Evaluator<'t, T>,
    pub solid: Evaluator<'t, T>,
    pub solid_full: Evaluator<'t, T>,
}

/// The evaluators of a marched scene: its distance, its distance and material, and the
/// media's where glass may overlap an opaque solid.
#[derive(Debug)]
pub(super) struct Evaluators<'t, T: Float> {
    pub dist: Evaluator<'t, T>,
    pub full: Evaluator<'t, T>,
    pub media: Option<Media<'t, T>>,
}

/// Scratch space of one thread: evaluators, lanes and buffers, reused from tile to tile.
#[derive(Debug)]
pub(super) struct Workspace<'t, T: Float> {
    /// The evaluators, where the scene is marched (a traced scene evaluates no program, so
    /// its tapes are never prepared).
    pub marching: Option<Evaluators<'t, T>>,
    pub lanes: Lanes<T>,
    pub launches: Vec<Launch<T>>,
    pub traced: Vec<Traced<T>>,
    /// Normal and material of each traced ray's hit, under analytic tracing.
    pub surfaces: Vec<(V3<T>, u32)>,
    pub shadowed: Vec<Shadowed<T>>,
    pub x: Vec<T>,
    pub y: Vec<T>,
    pub z: Vec<T>,
    pub d: Vec<T>,
    pub m: Vec<u32>,
}

impl<'t, T: Float> Workspace<'t, T> {
    /// The workspace of a render in `ctx`: with evaluators of `tapes` where it marches.
    pub fn new(ctx: &Context<T>, tapes: &'t Tapes, lanes: usize, chunk: usize) -> Self {
        let marching = ctx.analytic.is_none().then(|| {
            let built = tapes.built();
            Evaluators {
                dist: Evaluator::new(&built.distance, chunk),
                full: Evaluator::new(&built.full, chunk),
                media: built.media.as_ref().map(|m| Media {
                    medium: Evaluator::new(&m.medium, chunk),
                    solid: Evaluator::new(&m.solid, chunk),
                    solid_full: Evaluator::new(&m.solid_full, chunk),
                }),
            }
        });
        Workspace {
            marching,
            lanes: Lanes::new(lanes.max(1)),
            launches: Vec::new(),
            traced: Vec::new(),
            surfaces: Vec::new(),
            shadowed: Vec::new(),
            x: Vec::new(),
            y: Vec::new(),
            z: Vec::new(),
            d: Vec::new(),
            m: Vec::new(),
        }
    }
}
