//! Meshing a scene's surface (`sdfc mesh`): the cells of a grid that may hold surface, found
//! by an octree pruned with the distance program's proven Lipschitz bound (`octree`); the
//! surface patch of each such cell, with edge vertices found on the surface and a vertex
//! inside the cell placed from the field's gradients, which keeps sharp edges and corners
//! (`contour`), with the walls and gaps thinner than a cell that the grid misses found
//! (`thin`); and the file formats (`write`; 3MF in `threemf`, its archive in `zip`). `docs/mesh.md` describes the method and its
//! guarantees.

mod bricks;
mod closure;
pub mod contour;
pub mod device;
pub mod octree;
pub mod parts;
pub mod place;
pub mod qef;
pub mod table;
pub mod thin;
pub mod threemf;
pub mod write;
pub mod zip;

pub use bricks::{At, Bricks};
use rayon::prelude::*;
use sdfc_compiler::{Evaluator, Outputs, Program, Tape, DEFAULT_CHUNK};
use std::collections::{HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};
use std::sync::atomic::{AtomicU64, Ordering};

/// Bits of one grid index in a packed key: grids of up to 2²⁰ − 2 cells along an axis.
pub const KEY_BITS: u32 = 20;

/// The most cells along one axis that a packed key can index (an implementation bound, not a
/// resource limit).
pub const AXIS_CELLS: u32 = (1 << KEY_BITS) - 2;

/// The grid's points are offset from the bounds by this fraction of a cell (2 − φ), so that
/// faces at the bounds, or at round fractions of them (a box's faces are its bounding box's),
/// do not fall on grid planes, where the corners' signs would be decided by rounding.
pub const GRID_OFFSET: f64 = 0.381_966_011_250_105;

/// A regular grid of cubic cells: point `(i, j, k)` is at `origin + (i, j, k)·voxel`, for
/// `0 ≤ i ≤ cells[0]` and so on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// The position of point (0, 0, 0).
    pub origin: [f64; 3],
    /// The edge of a cell.
    pub voxel: f64,
    /// Cells along each axis.
    pub cells: [u32; 3],
}

impl Grid {
    /// The grid `sdfc mesh` lays over the clip box `clip` (its low and high corners) with
    /// cells of `voxel`: it starts 1 + [`GRID_OFFSET`] cells below the box and ends a cell or
    /// more above it, so that its outermost points lie outside the clip and the surface is
    /// closed.
    pub fn over(clip: &[[f64; 3]; 2], voxel: f64) -> Grid {
        Grid {
            origin: clip[0].map(|x| x - (1.0 + GRID_OFFSET) * voxel),
            voxel,
            cells: Self::cells_over(clip, voxel).map(|n| n as u32),
        }
    }

    /// The cells along each axis of [`Grid::over`], as numbers (to be checked against
    /// [`AXIS_CELLS`] before they are made indices).
    pub fn cells_over(clip: &[[f64; 3]; 2], voxel: f64) -> [f64; 3] {
        [0, 1, 2].map(|i| {
            ((clip[1][i] - clip[0][i]) / voxel + 1.0 + GRID_OFFSET)
                .ceil()
                .max(1.0)
                + 1.0
        })
    }

    /// The position of grid point `i`.
    pub fn point(&self, i: [u32; 3]) -> [f64; 3] {
        [0, 1, 2].map(|a| self.origin[a] + i[a] as f64 * self.voxel)
    }

    /// Cells of the dense grid.
    pub fn dense_cells(&self) -> u64 {
        self.cells.iter().map(|&n| n as u64).product()
    }

    /// Points of the dense grid.
    pub fn dense_points(&self) -> u64 {
        self.cells.iter().map(|&n| n as u64 + 1).product()
    }
}

/// A grid index packed into one key (x in the low bits).
pub fn pack(i: [u32; 3]) -> u64 {
    i[0] as u64 | (i[1] as u64) << KEY_BITS | (i[2] as u64) << (2 * KEY_BITS)
}

/// The grid index of a key.
pub fn unpack(k: u64) -> [u32; 3] {
    let m = (1u64 << KEY_BITS) - 1;
    [
        (k & m) as u32,
        (k >> KEY_BITS & m) as u32,
        (k >> (2 * KEY_BITS) & m) as u32,
    ]
}

/// A vector of `lengths`' sum, its consecutive parts of those lengths filled in parallel by
/// `fill(part's index, part)`.
pub(crate) fn filled_in_parts<T: Copy + Default + Send>(
    lengths: &[usize],
    fill: impl Fn(usize, &mut [T]) + Sync,
) -> Vec<T> {
    let mut out = vec![T::default(); lengths.iter().sum()];
    let mut parts = Vec::with_capacity(lengths.len());
    let mut rest = &mut out[..];
    for &n in lengths {
        let (part, tail) = std::mem::take(&mut rest).split_at_mut(n);
        parts.push(part);
        rest = tail;
    }
    parts
        .into_par_iter()
        .enumerate()
        .for_each(|(r, part)| fill(r, part));
    out
}

/// A hasher for packed keys: one multiplication, its high bits folded down.
#[derive(Debug, Default, Clone, Copy)]
pub struct KeyHasher(u64);

impl Hasher for KeyHasher {
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }

    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(23) ^ x).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }

    fn finish(&self) -> u64 {
        self.0 ^ self.0 >> 29
    }
}

/// A map from packed keys.
pub type KeyMap<V> = HashMap<u64, V, BuildHasherDefault<KeyHasher>>;
/// A set of packed keys.
pub type KeySet = HashSet<u64, BuildHasherDefault<KeyHasher>>;

/// The scene's distance field as the mesher reads it: the distance program, intersected
/// with a clip box (so that what reaches out of the meshed region is cut and closed), with
/// the L that bounds it. Its points are evaluated by the CPU's interpreter (f64), or, given
/// a [`device::Gpu`], by the scene's points kernel there (f32), a batch at a time either way;
/// the clip box is applied on the host.
#[derive(Debug)]
pub struct Field {
    distance: Tape,
    materials: Tape,
    gpu: Option<device::Gpu>,
    clip: [[f64; 3]; 2],
    /// `|f(p)| / lipschitz` is at most the distance from `p` to the surface (when `proven`).
    pub lipschitz: f64,
    /// Whether that bound is proven; without it the mesher evaluates the dense grid.
    pub proven: bool,
    evaluated: AtomicU64,
    /// Nanoseconds spent in [`Field::distances`] and [`Field::materials`].
    nanos: AtomicU64,
}

/// Points per task of a parallel evaluation.
const TASK: usize = 4096;

impl Field {
    /// The field of `program` (L its [`Program::lipschitz`]; `proven` from the analysis)
    /// clipped to the box `clip` (min, max): `max(f, box)`, whose L is at least 1.
    pub fn new(program: &Program, proven: bool, clip: [[f64; 3]; 2]) -> Field {
        Field {
            distance: Tape::new(program, Outputs::Distance),
            materials: Tape::new(program, Outputs::DistanceAndMaterial),
            clip,
            gpu: None,
            lipschitz: program.lipschitz().max(1.0),
            proven,
            evaluated: AtomicU64::new(0),
            nanos: AtomicU64::new(0),
        }
    }

    /// This field evaluated by `gpu` instead of the CPU.
    pub fn on(mut self, gpu: device::Gpu) -> Field {
        self.gpu = Some(gpu);
        self
    }

    /// The GPU that evaluates the field, if one does.
    pub fn gpu(&self) -> Option<&device::Gpu> {
        self.gpu.as_ref()
    }

    /// How far a distance may be from the f64 one by the rounding of its evaluation, at most:
    /// 0 on the CPU (whose rounding the callers' relative slack covers), the f32 allowance
    /// on a GPU ([`device::Gpu::rounding`]).
    pub fn rounding(&self) -> f64 {
        self.gpu.as_ref().map_or(0.0, |g| g.rounding())
    }

    /// Points evaluated so far.
    pub fn evaluated(&self) -> u64 {
        self.evaluated.load(Ordering::Relaxed)
    }

    /// Seconds spent evaluating so far (on the GPU: the launches, the transfers and the
    /// conversions to and from f32; the clip box included either way).
    pub fn evaluating(&self) -> f64 {
        self.nanos.load(Ordering::Relaxed) as f64 * 1e-9
    }

    fn timed<T>(&self, f: impl FnOnce() -> T) -> T {
        let t = std::time::Instant::now();
        let out = f();
        self.nanos
            .fetch_add(t.elapsed().as_nanos() as u64, Ordering::Relaxed);
        out
    }

    /// The signed distance to the clip box (exact).
    fn clip_distance(&self, p: [f64; 3]) -> f64 {
        let [lo, hi] = self.clip;
        let q: [f64; 3] = [0, 1, 2].map(|i| (lo[i] - p[i]).max(p[i] - hi[i]));
        let outside = q.iter().map(|v| v.max(0.0).powi(2)).sum::<f64>().sqrt();
        outside + q[0].max(q[1]).max(q[2]).min(0.0)
    }

    /// The clipped field at every point, in parallel (on the CPU's threads, or in one batch
    /// on the GPU, then clipped on the CPU's). A NaN distance counts as outside; after a
    /// GPU's launch has failed, every distance is NaN ([`device::Gpu::failure`]).
    pub fn distances(&self, points: &[[f64; 3]]) -> Vec<f64> {
        self.timed(|| self.clipped(points))
    }

    /// The clipped field at `count` points, the `n`th at `point(n)`, as [`Field::distances`]
    /// gives it, to the bit: on the CPU each task writes its points straight into the
    /// evaluator's columns, so that no array of the points is made (on a GPU, one is).
    pub fn distances_of(
        &self,
        count: usize,
        point: impl Fn(usize) -> [f64; 3] + Sync + Send,
    ) -> Vec<f64> {
        if self.gpu.is_some() {
            let points: Vec<[f64; 3]> = (0..count).into_par_iter().map(point).collect();
            return self.distances(&points);
        }
        self.timed(|| {
            let mut out = vec![0.0; count];
            self.evaluated.fetch_add(count as u64, Ordering::Relaxed);
            out.par_chunks_mut(TASK).enumerate().for_each_init(
                || Scratch::new(&self.distance),
                |s, (k, o)| {
                    s.fill((k * TASK..k * TASK + o.len()).map(&point));
                    s.eval_filled(o, None);
                    let [x, y, z] = &s.xyz;
                    for (i, d) in o.iter_mut().enumerate() {
                        let b = self.clip_distance([x[i], y[i], z[i]]);
                        *d = if *d > b { *d } else { b };
                    }
                },
            );
            out
        })
    }

    /// `d` at the points `p` intersected with the clip box.
    fn clip(&self, d: &mut [f64], p: &[[f64; 3]]) {
        for (d, q) in d.iter_mut().zip(p) {
            let b = self.clip_distance(*q);
            *d = if *d > b { *d } else { b };
        }
    }

    fn clipped(&self, points: &[[f64; 3]]) -> Vec<f64> {
        let mut out = vec![0.0; points.len()];
        self.evaluated
            .fetch_add(points.len() as u64, Ordering::Relaxed);
        let clip = |o: &mut [f64], p: &[[f64; 3]]| self.clip(o, p);
        if let Some(gpu) = &self.gpu {
            let values = gpu.run(points);
            out.par_chunks_mut(TASK)
                .zip(points.par_chunks(TASK))
                .enumerate()
                .for_each(|(k, (o, p))| {
                    match &values {
                        Some(v) => {
                            for (d, v) in o.iter_mut().zip(&v[k * TASK..]) {
                                *d = v.0 as f64;
                            }
                        }
                        None => o.fill(f64::NAN),
                    }
                    clip(o, p);
                });
            return out;
        }
        points
            .par_chunks(TASK)
            .zip(out.par_chunks_mut(TASK))
            .for_each_init(
                || Scratch::new(&self.distance),
                |s, (p, o)| {
                    s.run(p, o, None);
                    clip(o, p);
                },
            );
        out
    }

    /// The material id at every point (0 where a GPU's launch has failed).
    pub fn materials(&self, points: &[[f64; 3]]) -> Vec<u32> {
        self.timed(|| self.materials_at(points))
    }

    fn materials_at(&self, points: &[[f64; 3]]) -> Vec<u32> {
        if let Some(gpu) = &self.gpu {
            return match gpu.run(points) {
                Some(v) => v.into_iter().map(|(_, m)| m).collect(),
                None => vec![0; points.len()],
            };
        }
        let mut out = vec![0u32; points.len()];
        let mut scratch = vec![0.0; points.len()];
        points
            .par_chunks(TASK)
            .zip(out.par_chunks_mut(TASK).zip(scratch.par_chunks_mut(TASK)))
            .for_each_init(
                || Scratch::new(&self.materials),
                |s, (p, (m, d))| s.run(p, d, Some(m)),
            );
        out
    }

    /// The clipped field and its gradient at every point, from four samples at the corners
    /// of a tetrahedron of edge `2√2·h` around it (their mean is the value, to O(h²)), in
    /// one batch. On a GPU, `h` is at least [`device::Gpu::least_step`], beyond f32's
    /// rounding.
    pub fn gradients(&self, points: &[[f64; 3]], h: f64) -> (Vec<f64>, Vec<[f64; 3]>) {
        let h = self.gpu.as_ref().map_or(h, |g| h.max(g.least_step()));
        let samples = |p: &[[f64; 3]]| -> Vec<[f64; 3]> {
            p.iter()
                .flat_map(|p| TETRAHEDRON.map(|k| [0, 1, 2].map(|i| p[i] + h * k[i])))
                .collect()
        };
        if self.gpu.is_some() {
            let d = self.distances(&samples(points));
            return d.chunks_exact(4).map(|s| gradient(s, h)).unzip();
        }
        // On the CPU, each task makes its points' samples and reduces their values: the
        // samples of every point are never held at once.
        let mut values = vec![0.0; points.len()];
        let mut gradients = vec![[0.0; 3]; points.len()];
        self.evaluated
            .fetch_add(4 * points.len() as u64, Ordering::Relaxed);
        self.timed(|| {
            points
                .par_chunks(TASK / 4)
                .zip(values.par_chunks_mut(TASK / 4))
                .zip(gradients.par_chunks_mut(TASK / 4))
                .for_each_init(
                    || (Scratch::new(&self.distance), Vec::new()),
                    |(s, d), ((p, v), g)| {
                        let q = samples(p);
                        d.resize(q.len(), 0.0);
                        s.run(&q, d, None);
                        self.clip(d, &q);
                        for ((s, v), g) in d.chunks_exact(4).zip(v).zip(g) {
                            (*v, *g) = gradient(s, h);
                        }
                    },
                )
        });
        (values, gradients)
    }
}

/// The offsets of [`Field::gradients`]' samples about a point (in units of `h`).
const TETRAHEDRON: [[f64; 3]; 4] = [
    [1.0, -1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [-1.0, 1.0, -1.0],
    [1.0, 1.0, 1.0],
];

/// The value and gradient at a point from its four samples' values `s` ([`TETRAHEDRON`]).
fn gradient(s: &[f64], h: f64) -> (f64, [f64; 3]) {
    let mut g = [0.0; 3];
    for (k, v) in TETRAHEDRON.iter().zip(s) {
        for i in 0..3 {
            g[i] += k[i] * v / (4.0 * h);
        }
    }
    (s.iter().sum::<f64>() / 4.0, g)
}

/// The largest |f| of `field` at the vertices of `mesh` and at its triangles' centres.
pub fn error(field: &Field, mesh: &Mesh) -> [f64; 2] {
    let largest = |d: Vec<f64>| d.into_iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let centres: Vec<[f64; 3]> = mesh
        .triangles
        .iter()
        .map(|t| {
            [0, 1, 2].map(|i| {
                t.iter()
                    .map(|&v| mesh.positions[v as usize][i])
                    .sum::<f64>()
                    / 3.0
            })
        })
        .collect();
    [
        largest(field.distances(&mesh.positions)),
        largest(field.distances(&centres)),
    ]
}

/// One thread's evaluator and input columns.
struct Scratch<'t> {
    eval: Evaluator<'t, f64>,
    xyz: [Vec<f64>; 3],
}

impl<'t> Scratch<'t> {
    fn new(tape: &'t Tape) -> Self {
        Scratch {
            eval: Evaluator::new(tape, DEFAULT_CHUNK),
            xyz: [Vec::new(), Vec::new(), Vec::new()],
        }
    }

    fn run(&mut self, points: &[[f64; 3]], d: &mut [f64], m: Option<&mut [u32]>) {
        for (i, col) in self.xyz.iter_mut().enumerate() {
            col.clear();
            col.extend(points.iter().map(|p| p[i]));
        }
        self.eval_filled(d, m);
    }

    /// The columns set to `points`.
    fn fill(&mut self, points: impl Iterator<Item = [f64; 3]>) {
        for col in &mut self.xyz {
            col.clear();
        }
        for p in points {
            for (col, x) in self.xyz.iter_mut().zip(p) {
                col.push(x);
            }
        }
    }

    /// The field at the points of the columns.
    fn eval_filled(&mut self, d: &mut [f64], m: Option<&mut [u32]>) {
        let [x, y, z] = &self.xyz;
        self.eval.eval(x, y, z, d, m);
    }
}

/// A triangle mesh: vertex positions (in the coordinates the scene was written in) and
/// triangles counter-clockwise seen from outside, with the material of each.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<[f64; 3]>,
    /// Triangles as vertex indices.
    pub triangles: Vec<[u32; 3]>,
    /// The material id of each triangle (at its patch's inner vertex).
    pub materials: Vec<u32>,
    /// The material id at each vertex (for vertex colours).
    pub vertex_materials: Vec<u32>,
}

/// What meshing did, for `--stats`-like reports and the benchmarks.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Stats {
    /// Octree cells whose centre was evaluated, at every level (the dense grid's cells when
    /// the field has no proven bound).
    pub octree_cells: u64,
    /// Grid cells the octree left (that may hold surface).
    pub candidates: u64,
    /// Cells added because a neighbour's crossed edge reached them (0 when the bound holds).
    pub added: u64,
    /// Cells that hold surface.
    pub surface_cells: u64,
    /// Points evaluated in all (centres, corners, root finding, gradients, flips).
    pub evaluated: u64,
    /// Patches whose inner vertex was placed at a sharp feature.
    pub features: u64,
    /// Edges flipped to follow a sharp edge.
    pub flips: u64,
    /// Inner vertices that their placement left off the surface (a QEF solution outside its
    /// cell), projected onto it within their cell.
    pub projected: u64,
    /// Whether the dense grid was evaluated (no proven bound).
    pub dense: bool,
    /// Walls and gaps thinner than a cell that the grid missed (grid edges that cross one
    /// twice, `thin`).
    pub thin: Option<thin::Thin>,
    /// The cell of the grid first asked for, where features thinner than it made `sdfc mesh`
    /// mesh again on a finer grid.
    pub refined_from: Option<f64>,
    /// The largest |f| at the mesh's vertices and at its triangles' centres (the distance to
    /// the surface where the field is exact), when measured ([`Settings::measure`]).
    pub error: Option<[f64; 2]>,
    /// What evaluated the points, as `--backend` names it (`cpu`, `wgpu`, `cuda`).
    pub backend: &'static str,
    /// The GPU's launches (0 on the CPU).
    pub launches: u64,
    /// Seconds of the meshing spent evaluating points ([`Field::evaluating`]).
    pub evaluating: f64,
    /// Seconds from the command's start to the octree's (reading, checking, lowering; the
    /// device opened and its kernel compiled), where a command measured it.
    pub before: Option<f64>,
}

/// Settings of a mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Place inner vertices at sharp features (QEF of the gradients) and flip edges along
    /// them; off, every inner vertex is projected onto the surface from its patch's centroid.
    pub sharp: bool,
    /// Root-finding iterations for each edge vertex.
    pub refine: u32,
    /// Find the material of each triangle and vertex (for formats that carry them).
    pub materials: bool,
    /// Measure the mesh's distance to the surface ([`Stats::error`]).
    pub measure: bool,
    /// Mesh again on a finer grid where walls or gaps thinner than a cell were missed
    /// (`commands::mesh_thin`); off, they are only warned about.
    pub thin: bool,
    /// What evaluates the field's points (`--backend`): the CPU (f64), or a GPU (f32, the
    /// scene's points kernel; [`device`]); `auto` is resolved by [`device::resolve`].
    pub backend: crate::backend::Backend,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            sharp: true,
            refine: 6,
            materials: true,
            measure: false,
            thin: true,
            backend: crate::backend::Backend::Cpu,
        }
    }
}
