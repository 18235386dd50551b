//! The CPU renderer of docs/rendering.md: sphere tracing of a distance program, evaluated by the
//! batch interpreter, with Phong shading, hard and soft shadows, reflection and refraction.
//!
//! The image is cut into tiles rendered in parallel (rayon). Within a tile, rays travel in
//! waves: all camera rays, then all the rays their hits spawned, and so on (no recursion).
//! Each wave is marched in lanes of up to `Options::lanes` rays that are evaluated as one
//! batch per step. A tile's result depends only on the tile, so the image is bit-identical
//! whatever the number of threads.

mod analytic;
mod camera;
mod context;
mod lanes;
mod look;
mod march;
mod memory;
mod mesh_hit;
mod path;
mod pbr;
pub mod reference;
mod shade;
mod stats;
mod tile;
mod vec;
mod wave;

pub use memory::{memory, retained};
pub use stats::{Counters, Stats};

use crate::depth::Depth;
use crate::image::Image;
use context::Context;
use rayon::prelude::*;
use sdfc_compiler::{
    analytic::Traceable, Float, Lowered, Media, Outputs, Program, Scene, Settings, Tape,
};
use std::sync::OnceLock;
use tile::Rect;
use wave::Workspace;

/// The float type a render runs in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Precision {
    /// Single precision (the default of every backend).
    #[default]
    F32,
    /// Double precision (the reference for accuracy measurements).
    F64,
}

/// How the renderer works (not what it renders: that is the scene's settings).
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// The Lipschitz bound L ≥ 1 of the field: steps are d / L.
    pub lipschitz: f64,
    /// Edge of a square tile, in pixels.
    pub tile: u32,
    /// Rays marched together.
    pub lanes: usize,
    /// Points per pass of the interpreter over the program.
    pub chunk: usize,
    /// Float type.
    pub precision: Precision,
    /// Paint the pixels whose rays met a NaN (camera, secondary or shadow rays) in
    /// [`NAN_COLOUR`] instead of what they would show (`--debug-nan`).
    pub debug_nan: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            lipschitz: 1.0,
            tile: 32,
            // A whole tile's camera rays marched together, the interpreter passing over them
            // at once: each step of the program is decoded once for more points, and a guarded
            // block runs on more of them (a large union's hierarchy spreads a batch's points
            // over many small blocks). Against 256, the scaling scenes took 20–35% less CPU
            // time and no example more, the images unchanged.
            lanes: TILE_RAYS,
            chunk: TILE_RAYS,
            precision: Precision::F32,
            debug_nan: false,
        }
    }
}

/// The rays of a tile of the default size (32 × 32), one sample each: the default number of
/// lanes, and of points per pass of the interpreter.
const TILE_RAYS: usize = 1024;

/// The linear colour of a pixel whose rays met a NaN, with `--debug-nan` (magenta, on every
/// backend).
pub const NAN_COLOUR: [f32; 3] = [1.0, 0.0, 1.0];

/// A distance program prepared for the CPU renderer, once per scene: its tape for the
/// distance alone (marching, normals, shadows) and its tape for distance and material, and
/// where glass may overlap an opaque solid, the tapes of the scene's media; with them, the
/// scene's primitives for analytic tracing (the lowering's [`Traceable`]), which a render
/// traces when its `method` setting picks tracing.
///
/// The tapes are prepared when a render first marches (a traced scene evaluates no program,
/// so it never prepares them), or at once by [`Tapes::prepare`].
#[derive(Debug, Clone)]
pub struct Tapes {
    program: Program,
    media: Option<Media>,
    built: OnceLock<Built>,
    traceable: Traceable,
    /// The materials' colour fields, run at hit points.
    colours: Vec<sdfc_compiler::ColourProgram>,
}

/// The tapes of [`Tapes`], once prepared.
#[derive(Debug, Clone)]
struct Built {
    distance: Tape,
    full: Tape,
    media: Option<MediaTapes>,
}

/// The tapes of [`sdfc_compiler::Media`]: the medium's distance (marched by rays
/// inside glass) and the solids' distance (their normals) and distance and material.
#[derive(Debug, Clone)]
struct MediaTapes {
    medium: Tape,
    solid: Tape,
    solid_full: Tape,
}

impl Tapes {
    /// Prepares the tapes of a lowered scene: its program's two, and its media's when its
    /// glass may overlap an opaque solid (docs/rendering.md, "Inside glass").
    /// (Not prepared yet: see [`Tapes::prepare`].)
    pub fn new(lowered: &Lowered) -> Self {
        Tapes {
            program: lowered.program.clone(),
            media: lowered.media.clone(),
            built: OnceLock::new(),
            traceable: lowered.traceable.clone(),
            colours: lowered.colours.programs.clone(),
        }
    }

    /// [`Tapes::new`], keeping the lowered scene's program rather than a copy of it.
    pub fn of(lowered: Lowered) -> Self {
        let Lowered {
            program,
            traceable,
            media,
            colours,
            ..
        } = lowered;
        Tapes {
            program,
            media,
            built: OnceLock::new(),
            traceable,
            colours: colours.programs,
        }
    }

    /// Prepares the tapes now, if they are not yet.
    pub fn prepare(&self) {
        self.built();
    }

    /// Whether the tapes are prepared.
    pub fn prepared(&self) -> bool {
        self.built.get().is_some()
    }

    /// The tapes, prepared on first use.
    fn built(&self) -> &Built {
        self.built.get_or_init(|| {
            let program = &self.program;
            Built {
                distance: Tape::new(program, Outputs::Distance),
                full: Tape::new(program, Outputs::DistanceAndMaterial),
                media: self.media.as_ref().map(|m| MediaTapes {
                    medium: Tape::new(&m.medium, Outputs::Distance),
                    solid: Tape::new(&m.solid, Outputs::Distance),
                    solid_full: Tape::new(&m.solid, Outputs::DistanceAndMaterial),
                }),
            }
        })
    }

    /// The distance program the tapes are prepared from.
    pub fn program(&self) -> &Program {
        &self.program
    }

    /// The scene's primitives, or why it cannot be traced analytically.
    pub fn traceable(&self) -> &Traceable {
        &self.traceable
    }

    /// Every tape, for the memory bound of a marched render (each thread has an evaluator
    /// of each); prepares them.
    fn all(&self) -> Vec<&Tape> {
        let built = self.built();
        let mut out = vec![&built.distance, &built.full];
        if let Some(m) = &built.media {
            out.extend([&m.medium, &m.solid, &m.solid_full]);
        }
        out
    }
}

/// A rendered image and its statistics.
#[derive(Debug, Clone)]
pub struct Render {
    /// The linear image.
    pub image: Image,
    /// What happened while rendering it.
    pub stats: Stats,
    /// Where each pixel's camera rays first hit a surface (the CPU renderer always fills it
    /// in; the GPU backends do not).
    pub depth: Option<Depth>,
}

/// The tiles of an image, row-major.
fn tiles(settings: &Settings, edge: u32) -> Vec<Rect> {
    let edge = edge.max(1);
    let mut out = Vec::new();
    for y in (0..settings.height).step_by(edge as usize) {
        for x in (0..settings.width).step_by(edge as usize) {
            out.push(Rect {
                x,
                y,
                w: edge.min(settings.width - x),
                h: edge.min(settings.height - y),
            });
        }
    }
    out
}

/// Number of tiles a render of `settings` is cut into (for progress reporting).
pub fn tile_count(settings: &Settings, options: &Options) -> u64 {
    tiles(settings, options.tile).len() as u64
}

/// Renders `scene` (lowered as `lowered`) on the current rayon pool, calling `progress` once
/// per finished tile, in `options.precision`.
pub fn render(
    scene: &Scene,
    lowered: &Lowered,
    options: &Options,
    progress: &(dyn Fn() + Sync),
) -> Render {
    render_tapes(scene, &Tapes::new(lowered), options, progress)
}

/// [`render`] with the program's tapes already prepared. It allocates at most [`memory`]
/// bytes (with the current pool's number of threads).
pub fn render_tapes(
    scene: &Scene,
    tapes: &Tapes,
    options: &Options,
    progress: &(dyn Fn() + Sync),
) -> Render {
    match options.precision {
        Precision::F32 => render_in::<f32>(scene, tapes, options, progress),
        Precision::F64 => render_in::<f64>(scene, tapes, options, progress),
    }
}

/// What every ray of `scene` rendered with `tapes` and `options` reads, in the float type `T`.
fn context<T: Float>(scene: &Scene, tapes: &Tapes, options: &Options) -> Context<T> {
    Context::new(
        scene,
        &tapes.traceable,
        &tapes.colours,
        options.lipschitz,
        options.debug_nan,
    )
}

/// [`render_tapes`] in the float type `T`.
pub fn render_in<T: Float>(
    scene: &Scene,
    tapes: &Tapes,
    options: &Options,
    progress: &(dyn Fn() + Sync),
) -> Render {
    let ctx = context::<T>(scene, tapes, options);
    let rects = tiles(&scene.settings, options.tile);
    let outs: Vec<tile::TileOut> = rects
        .par_iter()
        .map_init(
            || Workspace::new(&ctx, tapes, options.lanes, options.chunk),
            |ws, &rect| {
                let out = tile::render(&ctx, ws, rect);
                progress();
                out
            },
        )
        .collect();
    assemble(&scene.settings, &rects, &outs)
}

/// Renders the rows `rows` of `scene`'s image (every column) on the current rayon pool:
/// their linear colours and marching steps, row-major, and the counters they add up to (the
/// pixels are those of a whole render; their depth buffers are not kept). The scheduler of
/// several devices renders bands of an image so when the CPU is one of them.
pub fn render_rows(
    scene: &Scene,
    tapes: &Tapes,
    options: &Options,
    rows: std::ops::Range<u32>,
) -> (Vec<[f32; 3]>, Vec<u32>, Counters) {
    match options.precision {
        Precision::F32 => rows_in::<f32>(scene, tapes, options, rows),
        Precision::F64 => rows_in::<f64>(scene, tapes, options, rows),
    }
}

fn rows_in<T: Float>(
    scene: &Scene,
    tapes: &Tapes,
    options: &Options,
    rows: std::ops::Range<u32>,
) -> (Vec<[f32; 3]>, Vec<u32>, Counters) {
    let ctx = context::<T>(scene, tapes, options);
    let s = &scene.settings;
    let edge = options.tile.max(1);
    let rects: Vec<Rect> = tiles(s, edge)
        .into_iter()
        .filter(|r| r.y < rows.end && r.y + r.h > rows.start)
        .map(|r| {
            let y = r.y.max(rows.start);
            Rect {
                y,
                h: (r.y + r.h).min(rows.end) - y,
                ..r
            }
        })
        .collect();
    let outs: Vec<tile::TileOut> = rects
        .par_iter()
        .map_init(
            || Workspace::new(&ctx, tapes, options.lanes, options.chunk),
            |ws, &rect| tile::render(&ctx, ws, rect),
        )
        .collect();
    let width = s.width as usize;
    let n = width * (rows.end - rows.start) as usize;
    let mut linear = vec![[0.0f32; 3]; n];
    let mut steps = vec![0u32; n];
    let mut counters = Counters::default();
    for (rect, out) in rects.iter().zip(&outs) {
        counters.add(&out.counters);
        for row in 0..rect.h {
            let dst = (rect.y - rows.start + row) as usize * width + rect.x as usize;
            let src = (row * rect.w) as usize;
            let w = rect.w as usize;
            linear[dst..dst + w].copy_from_slice(&out.pixels[src..src + w]);
            steps[dst..dst + w].copy_from_slice(&out.steps[src..src + w]);
        }
    }
    (linear, steps, counters)
}

/// Puts the tiles together into the image and the statistics.
fn assemble(settings: &Settings, rects: &[Rect], outs: &[tile::TileOut]) -> Render {
    let mut image = Image::new(settings.width, settings.height);
    let mut steps = vec![0u32; image.linear.len()];
    let spp = settings.aa.max(1) * settings.aa.max(1);
    let mut depth = Depth::empty(settings.width, settings.height, spp);
    let mut counters = Counters::default();
    for (rect, out) in rects.iter().zip(outs) {
        counters.add(&out.counters);
        for row in 0..rect.h {
            let dst = ((rect.y + row) * settings.width + rect.x) as usize;
            let src = (row * rect.w) as usize;
            let (d, s) = (dst..dst + rect.w as usize, src..src + rect.w as usize);
            image.linear[d.clone()].copy_from_slice(&out.pixels[s.clone()]);
            steps[d.clone()].copy_from_slice(&out.steps[s.clone()]);
            depth.distance[d.clone()].copy_from_slice(&out.distance[s.clone()]);
            depth.coverage[d].copy_from_slice(&out.coverage[s]);
        }
    }
    Render {
        image,
        stats: Stats::new(counters, &steps),
        depth: Some(depth),
    }
}
