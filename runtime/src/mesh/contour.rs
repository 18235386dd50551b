//! The surface in the candidate cells: the corners' signs, the crossed edges (with every
//! cell around a crossed edge taken in, so that no patch lacks its neighbour), a vertex on
//! the surface on each crossed edge (found by root finding), each cell's patches
//! (`table`), an inner vertex for each patch (`place`), and the patch fanned around it;
//! then the edges between two sharp patches are flipped to run along the sharp edge.
//!
//! Why the result is closed, 2-manifold and oriented, by vertex positions as well as by
//! indices: every patch edge lies on a cell face and is shared by the two patches of the
//! cells on either side of it, in opposite directions (`table`); a fan's inner edges belong
//! to it alone; an edge vertex lies strictly inside its grid edge and an inner vertex
//! strictly inside its cell, so no two vertices share a position; a fan triangle has its
//! inner vertex off the face its other two vertices lie on, so none has zero area; and a
//! flip replaces two triangles by two that share a new edge, which is made only once.

use super::closure::{closure, Closure};
use super::octree::Candidates;
use super::place::{
    choose, inside_cell, normalise, onto_surface, place, separate, Patches, Placed, GRADIENT_STEP,
    MARGIN, ON_SURFACE,
};
use super::table::{corner, patches, EDGES};
use super::{pack, unpack, Bricks, Field, Grid, KeyMap, KeySet, Mesh, Settings, Stats};
use glam::DVec3;
use rayon::prelude::*;

/// Bisections after the root finding's rounds for an edge vertex still off the surface.
const BISECTIONS: u32 = 24;

/// Bytes held at most for `candidates` cells of `grid` before contouring: their keys; the
/// points asked for, each at most once (a position, its index, its place and its value); and
/// the bricks of corner values (f64) and cell flags, at most eight per candidate and at most
/// the grid's, with a slot of each one's flat directory ([`Bricks::over`]: one where the
/// grid's bricks are at most eight per candidate), with 12 bytes a point to spare.
pub fn candidate_bytes(grid: &Grid, candidates: u64) -> u64 {
    let points = candidates.saturating_mul(8).min(grid.dense_points());
    let bricks = grid
        .cells
        .iter()
        .map(|&n| (n as u64 + 1).div_ceil(8) + 1)
        .product::<u64>();
    let brick = 512 * (8 + 1 + 12) + 64 + 3 * 4;
    candidates
        .saturating_mul(8)
        .saturating_add(points.saturating_mul(24 + 12 + 8 + 8))
        .saturating_add(
            candidates
                .saturating_mul(8)
                .min(bricks)
                .saturating_mul(brick),
        )
}

/// Bytes held per surface cell at most: three owned edges with their key, position, normal
/// and index, four patches, twelve fan triangles with their owners and materials, the
/// evaluations' scratch, and the output mesh with the file's bytes.
pub const BYTES_PER_SURFACE_CELL: u64 =
    8 + 3 * (8 + 24 + 24 + 12 + 8) + 4 * 64 + 12 * 48 + 7 * 40 + 12 * 50;

/// Why contouring stopped.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Stop {
    /// The cells held (candidates and the cells crossed edges reach) would exceed the limit.
    Cells(u64),
    /// The caller refused the surface cells' memory (its message).
    Refused(String),
}

/// Contours the surface in `candidates` (sorted cell keys, and the corners whose values the
/// octree knows), holding at most `max_cells` cells; `surface` is told the number of surface
/// cells before they are contoured, and may refuse.
pub fn contour(
    field: &Field,
    grid: &Grid,
    candidates: impl Into<Candidates>,
    settings: &Settings,
    max_cells: u64,
    surface_cells: &dyn Fn(u64) -> Result<(), String>,
    progress: &dyn Fn(f64),
) -> Result<(Mesh, Stats), Stop> {
    let Candidates {
        cells: candidates,
        centres: known,
        ..
    } = candidates.into();
    let mut stats = Stats {
        candidates: candidates.len() as u64,
        ..Stats::default()
    };
    let Closure {
        values,
        mut surface,
        ..
    } = closure(field, grid, candidates, known, max_cells, &mut stats).map_err(Stop::Cells)?;
    progress(0.2);
    // Found in the candidates' order, sorted unless cells were added.
    if !surface.is_sorted() {
        surface.par_sort_unstable();
    }
    stats.surface_cells = surface.len() as u64;
    surface_cells(stats.surface_cells).map_err(Stop::Refused)?;

    // Edge vertices: each crossed edge is owned by the cell at its lower end.
    let owned = Owned::new(&surface);
    let edges = owned.keys(&surface);
    let crossings = roots(field, grid, &values, &edges, settings.refine);
    progress(0.5);
    let h = GRADIENT_STEP * grid.voxel;
    let (_, gradients) = field.gradients(&crossings, h);
    let normals: Vec<[f64; 3]> = gradients.iter().map(|g| normalise(*g)).collect();
    progress(0.6);

    let rings = Rings::new(&surface, &owned);
    let edge = Edges {
        crossings: &crossings,
        normals: &normals,
    };
    let (centres, smooth) = inner_vertices(field, grid, settings, &rings, edge, &mut stats);
    progress(0.75);

    let base = crossings.len() as u32;
    let (mut triangles, owner) = rings.fans(base);
    let mut positions = crossings;
    positions.extend_from_slice(&centres);
    if settings.sharp {
        stats.flips = flip(
            field,
            &positions,
            &mut triangles,
            &owner,
            &smooth,
            grid.voxel,
        );
    }
    progress(0.9);
    let (materials, vertex_materials) = if settings.materials {
        let at_centres = field.materials(&centres);
        let by_triangle = owner.iter().map(|&p| at_centres[p as usize]).collect();
        let mut at_vertices = field.materials(&positions[..base as usize]);
        at_vertices.extend_from_slice(&at_centres);
        (by_triangle, at_vertices)
    } else {
        (vec![0; triangles.len()], vec![0; positions.len()])
    };
    stats.evaluated = field.evaluated();
    progress(1.0);
    Ok((
        Mesh {
            positions,
            triangles,
            materials,
            vertex_materials,
        },
        stats,
    ))
}

/// The crossed edges each surface cell owns (those from its lower corner), numbered cell
/// after cell in the surface cells' order: which axes each cell's are along, as bits, and
/// the number of the first.
struct Owned {
    bits: Vec<u8>,
    first: Vec<u32>,
}

impl Owned {
    /// The edges of `surface` (sorted cells and their configurations).
    fn new(surface: &[(u64, u8)]) -> Owned {
        let bits: Vec<u8> = surface
            .par_iter()
            .map(|&(_, config)| {
                (0..3).fold(0u8, |bits, axis| {
                    let (a, b) = EDGES[axis * 4];
                    bits | u8::from((config >> a & 1) != (config >> b & 1)) << axis
                })
            })
            .collect();
        let mut first = Vec::with_capacity(surface.len() + 1);
        let mut count = 0u32;
        for &b in &bits {
            first.push(count);
            count += b.count_ones();
        }
        first.push(count);
        Owned { bits, first }
    }

    /// The number of the edge along `axis` that surface cell `n` owns, if it owns one.
    fn id(&self, n: usize, axis: usize) -> Option<u32> {
        let bits = self.bits[n];
        (bits >> axis & 1 == 1).then(|| self.first[n] + (bits & ((1 << axis) - 1)).count_ones())
    }

    /// Each edge's key (its cell's key and its axis), made in parallel.
    fn keys(&self, surface: &[(u64, u8)]) -> Vec<u64> {
        let mut edges = vec![0u64; self.first[surface.len()] as usize];
        let mut parts = Vec::with_capacity(surface.len().div_ceil(RING_TASK));
        let mut rest = &mut edges[..];
        for (k, cells) in surface.chunks(RING_TASK).enumerate() {
            let start = k * RING_TASK;
            let n = self.first[start + cells.len()] - self.first[start];
            let (part, tail) = std::mem::take(&mut rest).split_at_mut(n as usize);
            parts.push((start, cells, part));
            rest = tail;
        }
        parts.into_par_iter().for_each(|(start, cells, part)| {
            let mut at = 0;
            for (n, &(c, _)) in cells.iter().enumerate() {
                for axis in 0..3 {
                    if self.bits[start + n] >> axis & 1 == 1 {
                        part[at] = c << 2 | axis as u64;
                        at += 1;
                    }
                }
            }
        });
        edges
    }
}

/// The edge vertices: their positions and unit normals.
#[derive(Clone, Copy)]
struct Edges<'a> {
    crossings: &'a [[f64; 3]],
    normals: &'a [[f64; 3]],
}

/// Surface cells per task of [`Rings::new`].
const RING_TASK: usize = 1 << 14;

/// The patches: each one's cell and its ring of edge vertices.
struct Rings {
    /// Each patch's cell.
    cells: Vec<[u32; 3]>,
    /// The edge vertices of the patches' rings, one after another.
    ring: Vec<u32>,
    /// Where each patch's ring starts in `ring` (and, last, its end).
    starts: Vec<usize>,
}

impl Rings {
    /// The patches of the `surface` cells (`table`), with the numbers of their edge
    /// vertices (`owned`): those of a run of cells per task, joined in order. An edge is
    /// owned by the cell at its lower end, one of the eight at the corners of the cell from
    /// its lowest; the cells are sorted, so the cell at each corner is found by a cursor
    /// that only moves forward.
    fn new(surface: &[(u64, u8)], owned: &Owned) -> Rings {
        let parts: Vec<Rings> = (0..surface.len())
            .step_by(RING_TASK)
            .collect::<Vec<_>>()
            .into_par_iter()
            .map(|start| {
                let part = &surface[start..(start + RING_TASK).min(surface.len())];
                let mut rings = Rings {
                    cells: Vec::with_capacity(part.len()),
                    ring: Vec::with_capacity(4 * part.len()),
                    starts: Vec::with_capacity(part.len()),
                };
                let offset = |a: usize| pack(corner(a));
                let mut cursors: [usize; 8] = std::array::from_fn(|a| {
                    let target = part.first().map_or(0, |&(c, _)| c + offset(a));
                    surface.partition_point(|&(k, _)| k < target)
                });
                for &(c, config) in part {
                    let i = unpack(c);
                    for cycle in patches(config) {
                        for &e in cycle {
                            let (a, _) = EDGES[e as usize];
                            let target = c + offset(a);
                            let m = &mut cursors[a];
                            while *m < surface.len() && surface[*m].0 < target {
                                *m += 1;
                            }
                            let id = (*m < surface.len() && surface[*m].0 == target)
                                .then(|| owned.id(*m, e as usize / 4))
                                .flatten();
                            rings.ring.push(id.unwrap_or(0));
                        }
                        rings.cells.push(i);
                        rings.starts.push(rings.ring.len());
                    }
                }
                rings
            })
            .collect();
        let patches = parts.iter().map(|p| p.cells.len()).sum::<usize>();
        let mut rings = Rings {
            cells: Vec::with_capacity(patches),
            ring: Vec::with_capacity(parts.iter().map(|p| p.ring.len()).sum()),
            starts: Vec::with_capacity(patches + 1),
        };
        rings.starts.push(0);
        for part in parts {
            let base = rings.ring.len();
            rings.cells.extend_from_slice(&part.cells);
            rings.ring.extend_from_slice(&part.ring);
            rings.starts.extend(part.starts.iter().map(|s| base + s));
        }
        rings
    }

    /// Patch `p`'s ring.
    fn of(&self, p: usize) -> &[u32] {
        &self.ring[self.starts[p]..self.starts[p + 1]]
    }

    /// Each patch fanned around its inner vertex (vertex `base + p` for patch `p`): the
    /// triangles and each one's patch, a run of patches per task.
    fn fans(&self, base: u32) -> (Vec<[u32; 3]>, Vec<u32>) {
        // The triangles of patch `p` are `starts[p]..starts[p + 1]`.
        let count = self.ring.len();
        let (mut triangles, mut owner) = (vec![[0u32; 3]; count], vec![0u32; count]);
        let mut parts = Vec::with_capacity(self.cells.len().div_ceil(RING_TASK));
        let (mut rest_t, mut rest_o) = (&mut triangles[..], &mut owner[..]);
        for first in (0..self.cells.len()).step_by(RING_TASK) {
            let last = (first + RING_TASK).min(self.cells.len());
            let n = self.starts[last] - self.starts[first];
            let (t, tail_t) = std::mem::take(&mut rest_t).split_at_mut(n);
            let (o, tail_o) = std::mem::take(&mut rest_o).split_at_mut(n);
            parts.push((first..last, t, o));
            (rest_t, rest_o) = (tail_t, tail_o);
        }
        parts.into_par_iter().for_each(|(patches, t, o)| {
            let offset = self.starts[patches.start];
            for p in patches {
                let (start, end) = (self.starts[p], self.starts[p + 1]);
                for k in start..end {
                    let next = if k + 1 == end { start } else { k + 1 };
                    t[k - offset] = [base + p as u32, self.ring[k], self.ring[next]];
                    o[k - offset] = p as u32;
                }
            }
        });
        (triangles, owner)
    }
}

/// Each patch's inner vertex (`place`, `choose`; smooth ones moved onto the surface; all kept
/// inside their cell, projected and separated), and whether its patch is smooth.
fn inner_vertices(
    field: &Field,
    grid: &Grid,
    settings: &Settings,
    rings: &Rings,
    edge: Edges,
    stats: &mut Stats,
) -> (Vec<[f64; 3]>, Vec<bool>) {
    let patch_count = rings.cells.len();
    let inner: Vec<Placed> = (0..patch_count)
        .into_par_iter()
        .map(|p| {
            let ids = rings.of(p);
            let mut pts = [[0.0; 3]; 12];
            let mut nrm = [[0.0; 3]; 12];
            let n = ids.len().min(12);
            for (k, &v) in ids.iter().take(n).enumerate() {
                pts[k] = edge.crossings[v as usize];
                nrm[k] = edge.normals[v as usize];
            }
            let lo = grid.point(rings.cells[p]).map(|x| x + MARGIN * grid.voxel);
            let hi = lo.map(|x| x + (1.0 - 2.0 * MARGIN) * grid.voxel);
            place(&pts[..n], &nrm[..n], settings.sharp, [lo, hi])
        })
        .collect();
    let mut centres: Vec<[f64; 3]> = inner.par_iter().map(|c| c.point).collect();
    let smooth: Vec<bool> = inner.par_iter().map(|c| c.smooth).collect();
    choose(field, grid.voxel, &inner, &mut centres);
    stats.features = smooth.iter().filter(|s| !**s).count() as u64;
    onto_zero(field, grid, rings, edge.normals, &smooth, &mut centres);
    centres
        .par_iter_mut()
        .zip(&rings.cells)
        .for_each(|(centre, &cell)| *centre = inside_cell(grid, cell, *centre));
    let patches = Patches {
        cells: &rings.cells,
        ring: &rings.ring,
        starts: &rings.starts,
        crossings: edge.crossings,
    };
    stats.projected = onto_surface(field, grid, &patches, &mut centres);
    separate(
        grid,
        &rings.cells,
        &mut centres,
        &rings.ring,
        &rings.starts,
        edge.crossings,
    );
    (centres, smooth)
}

/// Smooth patches: the centroid moved along the patch's mean normal to where the field is
/// zero (Newton's steps for a field of unit gradient along the normal).
fn onto_zero(
    field: &Field,
    grid: &Grid,
    rings: &Rings,
    normals: &[[f64; 3]],
    smooth: &[bool],
    centres: &mut [[f64; 3]],
) {
    let round: Vec<usize> = (0..rings.cells.len()).filter(|&p| smooth[p]).collect();
    let mean: Vec<[f64; 3]> = round
        .par_iter()
        .map(|&p| {
            let ids = rings.of(p);
            normalise([0, 1, 2].map(|i| ids.iter().map(|&v| normals[v as usize][i]).sum::<f64>()))
        })
        .collect();
    for _ in 0..2 {
        let d = field.distances_of(round.len(), |k| centres[round[k]]);
        for (k, &p) in round.iter().enumerate() {
            if d[k].is_finite() && d[k].abs() < grid.voxel {
                centres[p] = [0, 1, 2].map(|i| centres[p][i] - d[k] * mean[k][i]);
            }
        }
    }
}

/// Edges updated by one task of [`roots`].
const ROOT_TASK: usize = 1 << 12;

/// An edge's root being found: its lower end, axis, bracket (t, f) on each side, which side
/// moved last, and the next point to evaluate.
struct Root {
    p: [f64; 3],
    axis: usize,
    lo: (f64, f64),
    hi: (f64, f64),
    side: i8,
    t: f64,
}

/// One round of [`roots`] for an edge whose field at its point `r.t` is `f`: nothing where
/// `f` is within `tolerance` (or not finite); else the bracket narrowed (Illinois) and the
/// next point, regula falsi's or, when `bisect` (or where that falls outside the bracket),
/// the bracket's middle. Whether the edge goes on.
fn step(r: &mut Root, f: f64, tolerance: f64, bisect: bool) -> bool {
    if !f.is_finite() || f.abs() <= tolerance {
        return false;
    }
    if (f < 0.0) == (r.lo.1 < 0.0) {
        r.lo = (r.t, f);
        if r.side == -1 {
            r.hi.1 /= 2.0;
        }
        r.side = -1;
    } else {
        r.hi = (r.t, f);
        if r.side == 1 {
            r.lo.1 /= 2.0;
        }
        r.side = 1;
    }
    let (a, b) = (r.lo, r.hi);
    let t = a.0 - a.1 * (b.0 - a.0) / (b.1 - a.1);
    r.t = if !bisect && t.is_finite() && t > a.0.min(b.0) && t < a.0.max(b.0) {
        t
    } else {
        0.5 * (a.0 + b.0)
    };
    (b.0 - a.0).abs() > 1e-12
}

/// The surface point on each edge: regula falsi (Illinois) from the corner values,
/// `iterations` rounds, kept [`MARGIN`] inside the edge.
fn roots(
    field: &Field,
    grid: &Grid,
    values: &Bricks<f64>,
    edges: &[u64],
    iterations: u32,
) -> Vec<[f64; 3]> {
    let mut state: Vec<Root> = edges
        .par_iter()
        .map(|&e| {
            let axis = (e & 3) as usize;
            let i = unpack(e >> 2);
            let mut j = i;
            j[axis] += 1;
            let (d0, d1) = (values.get(i), values.get(j));
            let t = d0 / (d0 - d1);
            Root {
                p: grid.point(i),
                axis,
                lo: (0.0, d0),
                hi: (1.0, d1),
                side: 0,
                t: if t.is_finite() {
                    t.clamp(0.0, 1.0)
                } else {
                    0.5
                },
            }
        })
        .collect();
    let at = |r: &Root, t: f64| {
        let mut q = r.p;
        q[r.axis] += t * grid.voxel;
        q
    };
    let mut active: Vec<usize> = (0..state.len()).collect();
    // Past `iterations`, the edges whose field is still above a quarter of [`ON_SURFACE`]
    // (regula falsi stalls at a kink of the field, beside an edge or corner of the surface) go
    // on by bisection.
    let rounds = if iterations > 0 {
        iterations + BISECTIONS
    } else {
        0
    };
    for round in 0..rounds {
        if active.is_empty() {
            break;
        }
        let d = field.distances_of(active.len(), |n| {
            let r = &state[active[n]];
            at(r, r.t)
        });
        let tolerance = if round + 1 < iterations {
            1e-12 * grid.voxel.max(1e-300)
        } else {
            0.25 * ON_SURFACE * grid.voxel
        };
        let bisect = round + 1 >= iterations;
        // The active edges in runs of [`ROOT_TASK`], each with the part of `state` its
        // edges lie in (`active` is increasing), updated in parallel.
        let mut parts = Vec::with_capacity(active.len().div_ceil(ROOT_TASK));
        let (mut rest, mut base) = (&mut state[..], 0);
        for (ks, ds) in active.chunks(ROOT_TASK).zip(d.chunks(ROOT_TASK)) {
            let end = ks[ks.len() - 1] + 1;
            let (part, tail) = std::mem::take(&mut rest).split_at_mut(end - base);
            parts.push((part, base, ks, ds));
            (rest, base) = (tail, end);
        }
        let next: Vec<Vec<usize>> = parts
            .into_par_iter()
            .map(|(part, base, ks, ds)| {
                let mut next = Vec::with_capacity(ks.len());
                for (&k, &f) in ks.iter().zip(ds) {
                    if step(&mut part[k - base], f, tolerance, bisect) {
                        next.push(k);
                    }
                }
                next
            })
            .collect();
        active = next.concat();
    }
    state
        .par_iter()
        .map(|r| at(r, r.t.clamp(MARGIN, 1.0 - MARGIN)))
        .collect()
}

fn normal(p: &[[f64; 3]], t: [u32; 3]) -> DVec3 {
    let [a, b, c] = t.map(|i| DVec3::from(p[i as usize]));
    (b - a).cross(c - a)
}

/// Flips the patch edge between two sharp patches' fans to join their inner vertices, where
/// the field is nearer zero at the new edge's midpoint than at the old one's (the edge then
/// follows a sharp edge of the surface instead of cutting across it), the new triangles
/// face the way the old ones did, and the new edge is not there yet. Returns the flips made.
fn flip(
    field: &Field,
    positions: &[[f64; 3]],
    triangles: &mut [[u32; 3]],
    owner: &[u32],
    smooth: &[bool],
    voxel: f64,
) -> u64 {
    // The sharp patches' triangles, in order (found in parallel).
    let sharp: Vec<usize> = (0..triangles.len())
        .into_par_iter()
        .filter(|&t| !smooth[owner[t] as usize])
        .collect();
    // Each fan triangle [centre, a, b] has one patch edge, a → b.
    let mut by_edge: KeyMap<u32> = KeyMap::default();
    by_edge.reserve(sharp.len());
    for &t in &sharp {
        let tri = triangles[t];
        by_edge.insert((tri[1] as u64) << 32 | tri[2] as u64, t as u32);
    }
    let mut pairs = Vec::new();
    for &t in &sharp {
        let (a, b) = (triangles[t][1], triangles[t][2]);
        if a > b {
            continue;
        }
        if let Some(&u) = by_edge.get(&((b as u64) << 32 | a as u64)) {
            pairs.push((t, u as usize));
        }
    }
    let mids: Vec<[f64; 3]> = pairs
        .iter()
        .flat_map(|&(t, u)| {
            let (c1, c2) = (triangles[t][0], triangles[u][0]);
            let (a, b) = (triangles[t][1], triangles[t][2]);
            let mid = |x: u32, y: u32| {
                let (p, q) = (positions[x as usize], positions[y as usize]);
                [0, 1, 2].map(|i| 0.5 * (p[i] + q[i]))
            };
            [mid(c1, c2), mid(a, b)]
        })
        .collect();
    let d = field.distances(&mids);
    let mut made = KeySet::default();
    let mut flips = 0;
    for (k, &(t, u)) in pairs.iter().enumerate() {
        let (new, old) = (d[2 * k].abs(), d[2 * k + 1].abs());
        if !(new < old && old > MARGIN * voxel) {
            continue;
        }
        let (c1, a, b) = (triangles[t][0], triangles[t][1], triangles[t][2]);
        let c2 = triangles[u][0];
        let key = (c1.min(c2) as u64) << 32 | c1.max(c2) as u64;
        if made.contains(&key) {
            continue;
        }
        let before = {
            let (n1, n2) = (
                normal(positions, triangles[t]),
                normal(positions, triangles[u]),
            );
            n1 + n2
        };
        let (s, r) = ([c1, a, c2], [c2, b, c1]);
        let (ns, nr) = (normal(positions, s), normal(positions, r));
        // Well above what the files' f32 coordinates can round to zero.
        let tiny = 1e-6 * voxel * voxel;
        if ns.length() <= tiny
            || nr.length() <= tiny
            || ns.dot(before) <= 0.0
            || nr.dot(before) <= 0.0
        {
            continue;
        }
        made.insert(key);
        triangles[t] = s;
        triangles[u] = r;
        flips += 1;
    }
    flips
}
