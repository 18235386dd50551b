//! Meshing a scene's surface (`sdfc mesh`): the cells of a grid that may hold surface, found
//! by an octree pruned with the distance program's proven Lipschitz bound (`octree`); the
//! surface patch of each such cell, with edge vertices found on the surface and a vertex
//! inside the cell placed from the field's gradients, which keeps sharp edges and corners
//! (`contour`), with the walls and gaps thinner than a cell that the grid misses found
//! (`thin`); and the file formats (`write`; 3MF in `threemf`, its archive in `zip`). `docs/mesh.md` describes the method and its
//! guarantees.

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

    fn clipped(&self, points: &[[f64; 3]]) -> Vec<f64> {
        let mut out = vec![0.0; points.len()];
        self.evaluated
            .fetch_add(points.len() as u64, Ordering::Relaxed);
        let clip = |o: &mut [f64], p: &[[f64; 3]]| {
            for (d, q) in o.iter_mut().zip(p) {
                let b = self.clip_distance(*q);
                *d = if *d > b { *d } else { b };
            }
        };
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
        const K: [[f64; 3]; 4] = [
            [1.0, -1.0, -1.0],
            [-1.0, -1.0, 1.0],
            [-1.0, 1.0, -1.0],
            [1.0, 1.0, 1.0],
        ];
        let samples: Vec<[f64; 3]> = points
            .iter()
            .flat_map(|p| K.map(|k| [0, 1, 2].map(|i| p[i] + h * k[i])))
            .collect();
        let d = self.distances(&samples);
        d.chunks_exact(4)
            .map(|s| {
                let mut g = [0.0; 3];
                for (k, v) in K.iter().zip(s) {
                    for i in 0..3 {
                        g[i] += k[i] * v / (4.0 * h);
                    }
                }
                (s.iter().sum::<f64>() / 4.0, g)
            })
            .unzip()
    }
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

/// Values on grid points, stored sparsely in bricks of 8×8×8 points found through a
/// directory: the points a cell reads lie in one or a few bricks, so a walk over cells in key
/// order touches memory mostly in sequence. The directory is a flat array over the grid's
/// bricks where it takes no more than the bricks the cells held may fill ([`Bricks::over`]),
/// a hash map otherwise (a grid far larger than the surface in it).
#[derive(Debug, Clone)]
pub struct Bricks<T: Copy> {
    index: Directory,
    data: Vec<[T; BRICK_POINTS]>,
    empty: T,
}

/// Where each brick's values are in [`Bricks::data`].
#[derive(Debug, Clone)]
enum Directory {
    /// Slots for the bricks of the points `0..dims·BRICK` along each axis, x fastest
    /// (`u32::MAX` for a brick not held).
    Flat { dims: [u32; 3], slots: Vec<u32> },
    /// By packed brick index.
    Hashed(KeyMap<u32>),
}

/// Where a point's value is in a [`Bricks`] (its brick's slot and its place in the brick).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct At(u32, u32);

/// Points along a brick's edge (a power of two).
const BRICK: u32 = 8;
const BRICK_POINTS: usize = (BRICK * BRICK * BRICK) as usize;

/// Bytes of one slot of a flat directory.
const SLOT: u64 = 4;

impl<T: Copy + PartialEq> Bricks<T> {
    /// No values; `empty` is what an unset point reads.
    pub fn new(empty: T) -> Self {
        Bricks {
            index: Directory::Hashed(KeyMap::default()),
            data: Vec::new(),
            empty,
        }
    }

    /// No values on the points of `grid` (and those a cell beyond its last cells reaches),
    /// for `held` cells: a flat directory where the grid has at most [`Bricks::flat_bricks`]
    /// of them, a hash map otherwise.
    pub fn over(empty: T, grid: &Grid, held: u64) -> Self {
        let dims = Self::dims(grid);
        let count = dims.iter().map(|&n| n as u64).product::<u64>();
        let index = if count <= Self::flat_bricks(held) {
            Directory::Flat {
                dims,
                slots: vec![u32::MAX; count as usize],
            }
        } else {
            Directory::Hashed(KeyMap::default())
        };
        Bricks {
            index,
            data: Vec::new(),
            empty,
        }
    }

    /// Bricks along each axis of a flat directory over `grid`: its points, and the points
    /// one cell beyond them, which the corners of a cell at the grid's far side reach.
    fn dims(grid: &Grid) -> [u32; 3] {
        grid.cells.map(|n| (n + 2) / BRICK + 1)
    }

    /// The most bricks a flat directory may have for `held` cells (those bricks' values could
    /// fill, each cell touching at most eight).
    pub fn flat_bricks(held: u64) -> u64 {
        held.saturating_mul(8)
    }

    fn split(i: [u32; 3]) -> ([u32; 3], usize) {
        let b = i.map(|x| x / BRICK);
        let o = i.map(|x| (x % BRICK) as usize);
        (b, o[0] + BRICK as usize * (o[1] + BRICK as usize * o[2]))
    }

    /// The slot of brick `b`, where it is held.
    fn slot(&self, b: [u32; 3]) -> Option<u32> {
        match &self.index {
            Directory::Flat { dims, slots } => {
                if b[0] >= dims[0] || b[1] >= dims[1] || b[2] >= dims[2] {
                    return None;
                }
                let at = b[0] as usize
                    + dims[0] as usize * (b[1] as usize + dims[1] as usize * b[2] as usize);
                let k = slots[at];
                (k != u32::MAX).then_some(k)
            }
            Directory::Hashed(map) => map.get(&pack(b)).copied(),
        }
    }

    /// The value at point `i` (`empty` where none was set).
    pub fn get(&self, i: [u32; 3]) -> T {
        let (b, o) = Self::split(i);
        match self.slot(b) {
            Some(k) => self.data[k as usize][o],
            None => self.empty,
        }
    }

    /// The values at the eight corners of the cell whose lowest corner is `i`, in the order
    /// of [`table::corner`] (one brick lookup when the cell lies in one brick).
    pub fn cube(&self, i: [u32; 3]) -> [T; 8] {
        if i.iter().all(|&x| x % BRICK < BRICK - 1) {
            let (b, o) = Self::split(i);
            let Some(k) = self.slot(b) else {
                return [self.empty; 8];
            };
            let brick = &self.data[k as usize];
            let (sy, sz) = (BRICK as usize, (BRICK * BRICK) as usize);
            return std::array::from_fn(|c| {
                brick[o + (c & 1) + (c >> 1 & 1) * sy + (c >> 2 & 1) * sz]
            });
        }
        std::array::from_fn(|c| {
            let d = table::corner(c);
            self.get([i[0] + d[0], i[1] + d[1], i[2] + d[2]])
        })
    }

    /// Sets the value at point `i`.
    pub fn set(&mut self, i: [u32; 3], v: T) {
        let (b, o) = Self::split(i);
        let k = self.slot_or_new(b);
        self.data[k as usize][o] = v;
    }

    /// Sets the value at point `i` to `v` where `replace` holds for the value there, saying
    /// where it is, for [`Bricks::put`] (one lookup for a test and a set).
    pub fn replace_if(&mut self, i: [u32; 3], replace: impl Fn(T) -> bool, v: T) -> Option<At> {
        let (b, o) = Self::split(i);
        let k = self.slot_or_new(b);
        let at = &mut self.data[k as usize][o];
        replace(*at).then(|| {
            *at = v;
            At(k, o as u32)
        })
    }

    /// Sets the value at a place [`Bricks::replace_if`] gave.
    pub fn put(&mut self, At(k, o): At, v: T) {
        self.data[k as usize][o as usize] = v;
    }

    /// The slot of brick `b`, a brick of `empty` values made for it where there was none.
    fn slot_or_new(&mut self, b: [u32; 3]) -> u32 {
        let next = self.data.len() as u32;
        let k = match &mut self.index {
            Directory::Flat { dims, slots } => {
                // A point beyond the flat directory's bricks (none that contouring sets: see
                // [`Bricks::dims`]) moves every brick to a hash map.
                if b[0] >= dims[0] || b[1] >= dims[1] || b[2] >= dims[2] {
                    self.rehash();
                    return self.slot_or_new(b);
                }
                let at = b[0] as usize
                    + dims[0] as usize * (b[1] as usize + dims[1] as usize * b[2] as usize);
                if slots[at] == u32::MAX {
                    slots[at] = next;
                }
                slots[at]
            }
            Directory::Hashed(map) => *map.entry(pack(b)).or_insert(next),
        };
        if k == next {
            self.data.push([self.empty; BRICK_POINTS]);
        }
        k
    }

    /// The flat directory replaced by a hash map of the same bricks.
    fn rehash(&mut self) {
        if let Directory::Flat { dims, slots } = &self.index {
            let mut map = KeyMap::default();
            for (at, &k) in slots.iter().enumerate() {
                if k != u32::MAX {
                    let (at, nx, ny) = (at as u64, dims[0] as u64, dims[1] as u64);
                    let b = [at % nx, at / nx % ny, at / (nx * ny)].map(|x| x as u32);
                    map.insert(pack(b), k);
                }
            }
            self.index = Directory::Hashed(map);
        }
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        let index = match &self.index {
            Directory::Flat { slots, .. } => slots.len() * SLOT as usize,
            Directory::Hashed(map) => map.len() * 24,
        };
        self.data.len() * std::mem::size_of::<[T; BRICK_POINTS]>() + index
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat directory reads as the hash map does: values set at the grid's points, the
    /// corners of a cell across bricks, points never set; and a point beyond its bricks moves
    /// them to a hash map with every value kept.
    #[test]
    fn a_flat_directory_reads_as_a_hashed_one() {
        let grid = Grid {
            origin: [0.0; 3],
            voxel: 1.0,
            cells: [20, 9, 13],
        };
        let mut flat = Bricks::over(-1i64, &grid, 1000);
        assert!(matches!(flat.index, Directory::Flat { .. }));
        let mut hashed = Bricks::new(-1i64);
        let value = |i: [u32; 3]| (i[0] * 10_000 + i[1] * 100 + i[2]) as i64;
        let mut points = Vec::new();
        for z in (0..=14).step_by(3) {
            for y in 0..=10 {
                for x in (0..=21).step_by(2) {
                    points.push([x, y, z]);
                }
            }
        }
        for &i in &points {
            flat.set(i, value(i));
            hashed.set(i, value(i));
        }
        let same = |flat: &Bricks<i64>, hashed: &Bricks<i64>| {
            for z in 0..16 {
                for y in 0..12 {
                    for x in 0..23 {
                        assert_eq!(flat.get([x, y, z]), hashed.get([x, y, z]), "{x} {y} {z}");
                        assert_eq!(flat.cube([x, y, z]), hashed.cube([x, y, z]), "{x} {y} {z}");
                    }
                }
            }
        };
        same(&flat, &hashed);
        assert_eq!(flat.get([900, 3, 4]), -1);
        flat.set([900, 3, 4], 7);
        hashed.set([900, 3, 4], 7);
        assert!(matches!(flat.index, Directory::Hashed(_)));
        assert_eq!(flat.get([900, 3, 4]), 7);
        same(&flat, &hashed);
        // A grid far larger than the cells held gets a hash map from the start.
        let wide = Grid {
            cells: [4000, 4000, 4000],
            ..grid
        };
        assert!(matches!(
            Bricks::over(0u8, &wide, 1000).index,
            Directory::Hashed(_)
        ));
    }
}
