//! Where a patch's inner vertex goes: at the centroid of a smooth patch, at the QEF point of
//! a sharp one, or, where that point is outside the cell, at the option in the cell that is
//! on the surface nearest it (`choose`); then any inner vertex still off the surface is
//! brought onto it within its cell (`onto_surface`), and vertices of one cell that fell on
//! one point are moved apart (`separate`). `docs/mesh.md`, "Inner vertices".

use super::qef;
use super::{Field, Grid};
use glam::DVec3;

/// Edge vertices stay this fraction of a voxel inside their edge, and inner vertices inside
/// their cell, so that no two vertices coincide.
pub const MARGIN: f64 = 1e-3;

/// Step of the gradients, as a fraction of a voxel.
pub const GRADIENT_STEP: f64 = 1e-4;

/// The patch normals of a smooth patch are within this angle's cosine of their mean (20°:
/// the two faces of an edge of 140° or less, such as a hexagon's 120°, make a feature); its
/// inner vertex is projected onto the surface.
const SMOOTH_COS: f64 = 0.94;

/// An inner vertex whose field value is above this fraction of a voxel after its placement
/// (a QEF solution clamped into its cell, or off a curved patch) is projected onto the
/// surface.
pub const ON_SURFACE: f64 = 1e-3;

/// Rounds of that projection: a Newton step along the gradient, then the clamp into the cell.
const PROJECT_ROUNDS: usize = 4;

/// `g / |g|` (divided, not multiplied by the reciprocal), or zero where `g` has no finite,
/// non-zero length.
pub fn normalise(g: [f64; 3]) -> [f64; 3] {
    unit(g.into()).map_or([0.0; 3], |u| u.to_array())
}

/// `a / |a|` where `a` has a finite, non-zero length.
pub fn unit(a: DVec3) -> Option<DVec3> {
    let l = a.length();
    (l > 0.0 && l.is_finite()).then(|| a / l)
}

/// A patch's inner vertex as [`place`] puts it.
#[derive(Debug, Clone, PartialEq)]
pub struct Placed {
    /// The centroid of a smooth patch, the QEF point of a sharp one.
    pub point: [f64; 3],
    /// Whether the patch is smooth.
    pub smooth: bool,
    /// Where the QEF point is outside the cell, the options in it ([`qef::InBox`]).
    pub options: Vec<[f64; 3]>,
}

/// The inner vertex of a patch, whether the patch is smooth (its normals close to their
/// mean: the vertex is then the centroid, to be projected onto the surface), and for a sharp
/// patch whose QEF point lies outside the box `[lo, hi]` (its cell less the margin), the
/// options in the box ([`qef::InBox`]) to [`choose`] from.
pub fn place(
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    sharp: bool,
    [lo, hi]: [[f64; 3]; 2],
) -> Placed {
    let n = points.len() as f64;
    let centroid = [0, 1, 2].map(|i| points.iter().map(|p| p[i]).sum::<f64>() / n);
    let mean = normalise([0, 1, 2].map(|i| normals.iter().map(|v| v[i]).sum::<f64>()));
    let smooth = normals
        .iter()
        .all(|v| v[0] * mean[0] + v[1] * mean[1] + v[2] * mean[2] >= SMOOTH_COS);
    if smooth || !sharp {
        return Placed {
            point: centroid,
            smooth: true,
            options: Vec::new(),
        };
    }
    let r = qef::solve_in_box(points, normals, lo, hi);
    Placed {
        point: r.fit,
        smooth: false,
        options: r.options,
    }
}

/// For each sharp patch whose QEF point is outside its cell, the option on the surface (|f|
/// at most [`ON_SURFACE`] of a voxel) nearest that point, or else the option nearest the
/// surface: in one batch of evaluations.
pub fn choose(field: &Field, voxel: f64, placed: &[Placed], centres: &mut [[f64; 3]]) {
    let points: Vec<[f64; 3]> = placed
        .iter()
        .flat_map(|p| p.options.iter().copied())
        .collect();
    if points.is_empty() {
        return;
    }
    let d = field.distances(&points);
    let mut at = 0;
    for (
        p,
        Placed {
            point: fit,
            options,
            ..
        },
    ) in placed.iter().enumerate()
    {
        if options.is_empty() {
            continue;
        }
        let values = &d[at..at + options.len()];
        at += options.len();
        let far = |y: &[f64; 3]| DVec3::from(*y).distance_squared(DVec3::from(*fit));
        let on = options
            .iter()
            .zip(values)
            .filter(|(_, v)| v.abs() <= ON_SURFACE * voxel)
            .min_by(|a, b| far(a.0).total_cmp(&far(b.0)));
        let best = on.or_else(|| {
            options
                .iter()
                .zip(values)
                .min_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        });
        if let Some((y, _)) = best {
            centres[p] = *y;
        }
    }
}

/// `p` clamped into cell `c`, [`MARGIN`] of a voxel inside its faces.
pub fn inside_cell(grid: &Grid, c: [u32; 3], p: [f64; 3]) -> [f64; 3] {
    let lo = grid.point(c);
    let m = MARGIN * grid.voxel;
    [0, 1, 2].map(|i| {
        let v = if p[i].is_finite() {
            p[i]
        } else {
            lo[i] + 0.5 * grid.voxel
        };
        v.clamp(lo[i] + m, lo[i] + grid.voxel - m)
    })
}

/// The patches of a mesh: each one's cell and the edge vertices of its ring.
#[derive(Debug)]
pub struct Patches<'a> {
    /// Each patch's cell.
    pub cells: &'a [[u32; 3]],
    /// The edge vertices of the patches' rings, one after another.
    pub ring: &'a [u32],
    /// Where each patch's ring starts in `ring` (and, last, its end).
    pub starts: &'a [usize],
    /// The edge vertices' positions.
    pub crossings: &'a [[f64; 3]],
}

/// Moves every inner vertex that its placement left more than [`ON_SURFACE`] of a voxel off
/// the surface back onto it, within its cell. First Newton steps along the field's gradient,
/// each followed by the clamp into the cell (alternating projections onto the surface and the
/// cell). Where that stalls (a point clamped to its cell's face, beside a corner or an edge
/// just beyond it, whose gradient leads out of the cell), the segments from the point to its
/// patch's edge vertices, which are on the surface and on the cell's boundary, are searched
/// for the surface nearest the point (by samples, then bisection); a segment stays in the
/// cell. Returns the vertices moved.
pub fn onto_surface(
    field: &Field,
    grid: &Grid,
    patches: &Patches,
    centres: &mut [[f64; 3]],
) -> u64 {
    let tolerance = ON_SURFACE * grid.voxel;
    let d = field.distances(centres);
    let mut off: Vec<usize> = (0..centres.len())
        .filter(|&p| !(d[p].abs() <= tolerance))
        .collect();
    let moved = off.len() as u64;
    let h = GRADIENT_STEP * grid.voxel;
    for _ in 0..PROJECT_ROUNDS {
        if off.is_empty() {
            break;
        }
        let points: Vec<[f64; 3]> = off.iter().map(|&p| centres[p]).collect();
        let (values, gradients) = field.gradients(&points, h);
        let mut next = Vec::with_capacity(off.len());
        for (k, &p) in off.iter().enumerate() {
            let (v, g) = (values[k], gradients[k]);
            let g2 = DVec3::from(g).length_squared();
            if v.abs() <= tolerance {
                continue;
            }
            if g2 > 0.0 && g2.is_finite() && v.is_finite() {
                let step = [0, 1, 2].map(|i| centres[p][i] - v * g[i] / g2);
                centres[p] = inside_cell(grid, patches.cells[p], step);
            }
            next.push(p);
        }
        off = next;
    }
    if off.is_empty() {
        return moved;
    }
    // The stalled: segments from them, sampled at eighths.
    let along = |a: [f64; 3], b: [f64; 3], t: f64| [0, 1, 2].map(|i| a[i] + t * (b[i] - a[i]));
    let ring_len = |p: usize| patches.starts[p + 1] - patches.starts[p];
    let value = field.distances(&off.iter().map(|&p| centres[p]).collect::<Vec<_>>());
    // Each stalled vertex's segments end at its ring's edge vertices and at the midpoints of
    // their pairs (a chord across a convex edge lies inside the solid, across a concave one
    // outside it, so the segment to its midpoint crosses the surface in the cell).
    let ends = |p: usize| {
        let ring = &patches.ring[patches.starts[p]..patches.starts[p + 1]];
        let at = |e: u32| patches.crossings[e as usize];
        let mut ends: Vec<[f64; 3]> = ring.iter().map(|&e| at(e)).collect();
        for (k, &a) in ring.iter().enumerate() {
            for &b in &ring[k + 1..] {
                ends.push(along(at(a), at(b), 0.5));
            }
        }
        ends
    };
    const SAMPLES: usize = 8;
    let mut samples = Vec::new();
    for &p in &off {
        for b in ends(p) {
            samples.extend((1..SAMPLES).map(|j| along(centres[p], b, j as f64 / SAMPLES as f64)));
        }
    }
    let sampled = field.distances(&samples);
    // Per vertex: the bracket (segment end, t where the sign is still the point's, t where
    // it is not) nearest the point; without one, just short of the nearest edge vertex.
    struct Bracket {
        p: usize,
        a: [f64; 3],
        b: [f64; 3],
        t: [f64; 2],
        inside: bool,
    }
    let mut brackets: Vec<Bracket> = Vec::new();
    let mut at = 0;
    for (k, &p) in off.iter().enumerate() {
        let a = centres[p];
        let inside = value[k] < 0.0;
        let mut best: Option<(f64, Bracket)> = None;
        let mut nearest = (a, f64::INFINITY);
        for (n, b) in ends(p).into_iter().enumerate() {
            let length = DVec3::from(b).distance(DVec3::from(a));
            if n < ring_len(p) && length < nearest.1 {
                nearest = (b, length);
            }
            let row = &sampled[at..at + SAMPLES - 1];
            at += SAMPLES - 1;
            if let Some(j) = row.iter().position(|v| (*v < 0.0) != inside) {
                let t = [j as f64, (j + 1) as f64].map(|x| x / SAMPLES as f64);
                if best.as_ref().is_none_or(|(far, _)| t[1] * length < *far) {
                    best = Some((t[1] * length, Bracket { p, a, b, t, inside }));
                }
            }
        }
        match best {
            Some((_, bracket)) => brackets.push(bracket),
            None => {
                let moved = along(a, nearest.0, 1.0 - MARGIN);
                centres[p] = inside_cell(grid, patches.cells[p], moved);
            }
        }
    }
    for _ in 0..12 {
        let mids: Vec<[f64; 3]> = brackets
            .iter()
            .map(|r| along(r.a, r.b, 0.5 * (r.t[0] + r.t[1])))
            .collect();
        let d = field.distances(&mids);
        for (r, v) in brackets.iter_mut().zip(d) {
            let t = 0.5 * (r.t[0] + r.t[1]);
            r.t[usize::from((v < 0.0) != r.inside)] = t;
        }
    }
    for r in &brackets {
        let root = along(r.a, r.b, 0.5 * (r.t[0] + r.t[1]));
        centres[r.p] = inside_cell(grid, patches.cells[r.p], root);
    }
    moved
}

/// Moves apart the inner vertices of patches of one cell that landed on one point (two
/// sheets fitted to the same planes), each a little towards its own patch's centroid.
pub fn separate(
    grid: &Grid,
    cells: &[[u32; 3]],
    centres: &mut [[f64; 3]],
    ring: &[u32],
    starts: &[usize],
    crossings: &[[f64; 3]],
) {
    let mut p = 0;
    while p < cells.len() {
        let mut q = p + 1;
        while q < cells.len() && cells[q] == cells[p] {
            q += 1;
        }
        for a in p..q {
            for b in a + 1..q {
                if centres[a] == centres[b] {
                    let ids = &ring[starts[b]..starts[b + 1]];
                    let n = ids.len() as f64;
                    let c = [0, 1, 2]
                        .map(|i| ids.iter().map(|&v| crossings[v as usize][i]).sum::<f64>() / n);
                    let moved = [0, 1, 2].map(|i| centres[b][i] + 0.01 * (c[i] - centres[b][i]));
                    centres[b] = inside_cell(grid, cells[b], moved);
                }
            }
        }
        p = q;
    }
}
