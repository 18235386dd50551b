//! Walls and gaps thinner than a cell: a feature that a grid edge crosses twice, so that both
//! its ends have one sign and the grid misses it (false holes in a thin wall, a sheet in
//! pieces, two parts fused across a narrow gap). `docs/mesh.md`, "Thin walls and gaps".
//!
//! Along an edge whose ends have the values `a` and `b` of one sign, the surface can lie
//! between them only if `|a| / L + |b| / L` is less than the edge (the bound keeps a ball of
//! radius `|f| / L` about each end free of surface); where the values beyond both ends grow
//! away from the edge (a valley of |f| along it), the edge is probed where the two balls
//! meet. A probe of the other sign proves two roots on the edge, one on each side of it,
//! which bisection finds. Two roots are not yet a wall: an edge that clips a corner, a
//! crease or the tip of a ridge crosses the surface twice too. A wall or gap has two faces
//! that face away from each other, so the normals at the two roots must be nearly opposite
//! (more than [`OPPOSITE`] apart): a ridge of 60° (a thread's crest) has normals 120° apart
//! and a box's corner 90°, and neither is reported. The feature's thickness is its extent
//! along the edge projected onto the mean of the two normals, the thickness across it.

use super::place::unit;
use super::{unpack, Bricks, Field, Grid};
use glam::DVec3;
use rayon::prelude::*;

/// The normals at a feature's two roots are at least this far apart (`cos` below its
/// negative): 155°, walls whose faces are within 25° of parallel.
pub const OPPOSITE: f64 = 0.9;

/// A feature a cell away is like it when neither thickness is more than this many times
/// the other.
const ALIKE: f64 = 1.5;

/// How far (in cells) a feature that closes ([`closes`]) may close.
const CLOSES_WITHIN: f64 = 64.0;

/// A feature is followed ([`Finder::tapers_to_nothing`]) where its thickness changes by more
/// than this share of it per cell, and for at most [`WALK`] cells.
const TAPER: f64 = 0.05;
const WALK: usize = 8;

/// Bisection rounds towards each root (the thickness to 2⁻¹⁶ of a cell).
const BISECTIONS: u32 = 16;

/// Edges probed together, enough that their evaluations are shared among the threads (the
/// memory this holds is a few MiB, whatever the grid).
const BATCH: usize = 1 << 15;

/// Which share of the features found, thinnest first, the reported thickness leaves below
/// it: a tenth, so that the refined grid resolves nine features in ten, and a few edges that
/// clip a wall's rim obliquely do not set the cell.
const QUANTILE: f64 = 0.1;

/// Thickness bins per halving, over [`OCTAVES`] halvings below a cell.
const BINS_PER_OCTAVE: usize = 8;
const OCTAVES: usize = 24;
const BINS: usize = BINS_PER_OCTAVE * OCTAVES;

/// The features a grid missed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Thin {
    /// A point inside a feature of about [`Thin::thickness`] (the mid-point between its
    /// roots), in the field's coordinates.
    pub at: [f64; 3],
    /// The thickness across them that [`QUANTILE`] of the features found are thinner than
    /// (to 9 % of it).
    pub thickness: f64,
    /// The thinnest found.
    pub thinnest: f64,
    /// Grid edges that cross such features twice.
    pub edges: u64,
}

/// Probes pending evaluation, and what has been found.
struct Finder<'a> {
    field: &'a Field,
    grid: &'a Grid,
    /// The probes pending.
    probes: Vec<Probe>,
    /// Per thickness bin: features found, and a point in one of them.
    bins: Vec<(u64, [f64; 3])>,
    thinnest: f64,
}

/// The walls and gaps thinner than a cell that the grid of `values` missed along the edges
/// of `cells` (each cell's three edges from its lowest corner), or `None`.
pub fn missed(field: &Field, grid: &Grid, values: &Bricks<f64>, cells: &[u64]) -> Option<Thin> {
    let l = field.lipschitz;
    let h = grid.voxel;
    let mut finder = Finder {
        field,
        grid,
        probes: Vec::new(),
        bins: vec![(0, [0.0; 3]); BINS],
        thinnest: f64::INFINITY,
    };
    // The cells are scanned in parallel, a window at a time; their probes are then run in
    // the cells' order, in batches of [`BATCH`].
    for window in cells.chunks(SCAN) {
        let found: Vec<Vec<Probe>> = window
            .par_chunks(SCAN_TASK)
            .map(|part| {
                let mut probes = Vec::new();
                for &c in part {
                    probe(grid, values, l, c, &mut probes);
                }
                probes
            })
            .collect();
        for p in found.into_iter().flatten() {
            finder.probes.push(p);
            if finder.probes.len() == BATCH {
                finder.run();
            }
        }
    }
    finder.run();
    finder.result(h)
}

/// A probe: its edge's lower end (a point), axis, the probe's offset along it and whether the
/// ends are inside.
type Probe = ([f64; 3], usize, f64, bool);

/// Cells scanned together for probes, and by one task.
const SCAN: usize = 1 << 16;
const SCAN_TASK: usize = 1 << 11;

/// The probes of cell `c`'s three edges from its lowest corner (bound `l`): where both ends
/// have one sign, their balls leave room for the surface, and the values beyond both ends
/// grow away from the edge, the point where the two balls meet.
fn probe(grid: &Grid, values: &Bricks<f64>, l: f64, c: u64, probes: &mut Vec<Probe>) {
    let h = grid.voxel;
    let far = 2.0 * l * h;
    let i = unpack(c);
    let cube = values.cube(i);
    for axis in 0..3 {
        let (a, b) = (cube[0], cube[1 << axis]);
        if !(a.is_finite() && b.is_finite()) || (a < 0.0) != (b < 0.0) {
            continue;
        }
        // Balls far wider than the edge, without dividing (the test below decides the rest).
        if a.abs() + b.abs() > far {
            continue;
        }
        let (ra, rb) = (a.abs() / l, b.abs() / l);
        if ra + rb >= h {
            continue;
        }
        // Beyond the ends: a point not evaluated counts as growing.
        let grows = |k: [u32; 3], v: f64| {
            let w = values.get(k);
            !w.is_finite() || w.abs() > v.abs()
        };
        let mut before = i;
        let mut after = i;
        after[axis] += 2;
        let before_grows = match i[axis].checked_sub(1) {
            Some(x) => {
                before[axis] = x;
                grows(before, a)
            }
            None => true,
        };
        if !(before_grows && grows(after, b)) {
            continue;
        }
        let t = 0.5 * (h + ra - rb);
        probes.push((grid.point(i), axis, t.clamp(0.0, h), a < 0.0));
    }
}

impl Finder<'_> {
    /// Evaluates the pending probes and measures the features they prove.
    fn run(&mut self) {
        if self.probes.is_empty() {
            return;
        }
        let h = self.grid.voxel;
        let lines: Vec<Line> = self
            .probes
            .drain(..)
            .map(|(p, axis, t, inside)| {
                let mut centre = p;
                centre[axis] += t;
                let mut dir = [0.0; 3];
                dir[axis] = 1.0;
                Line {
                    centre,
                    dir,
                    ends: [-t, h - t],
                    inside,
                }
            })
            .collect();
        // The probes of the other sign: two roots on each edge.
        let (lines, offsets): (Vec<Line>, Vec<[f64; 2]>) = crossings(self.field, &lines)
            .into_iter()
            .zip(&lines)
            .filter_map(|(o, l)| Some((*l, o?)))
            .unzip();
        if lines.is_empty() {
            return;
        }
        let roots: Vec<[f64; 3]> = lines
            .iter()
            .zip(&offsets)
            .flat_map(|(l, o)| o.map(|s| l.at(s)))
            .collect();
        let (_, gradients) = self.field.gradients(&roots, 1e-3 * h);
        // Opposite faces: the feature's thickness across it, its mid-point and normal.
        let mut found: Vec<(Line, f64)> = Vec::new();
        for (k, (l, o)) in lines.iter().zip(&offsets).enumerate() {
            let (Some(g0), Some(g1)) = (
                unit(gradients[2 * k].into()),
                unit(gradients[2 * k + 1].into()),
            ) else {
                continue;
            };
            if g0.dot(g1) > -OPPOSITE {
                continue;
            }
            let normal = unit(g0 - g1).unwrap_or(g0);
            let thickness = (o[1] - o[0]).abs() * normal.dot(l.dir.into()).abs();
            let centre = l.at(0.5 * (o[0] + o[1]));
            found.push((
                Line {
                    centre,
                    dir: normal.to_array(),
                    ends: [-h, h],
                    inside: l.inside,
                },
                thickness,
            ));
        }
        // Extended: across the feature a cell away from the mid-point, along four
        // directions in it, a feature of the same sign within [`ALIKE`] as thick, in three
        // of the four. A wall's body and rim pass; the wedge of air where a curved part
        // touches another (a sphere on a floor) thickens or closes within a cell, and a
        // ridge thickens away from its tip.
        let mut around: Vec<Line> = Vec::with_capacity(4 * found.len());
        for (l, _) in &found {
            let (u, v) = tangents(l.dir);
            for d in [u, u.map(|x| -x), v, v.map(|x| -x)] {
                around.push(Line {
                    centre: [0, 1, 2].map(|i| l.centre[i] + h * d[i]),
                    ..*l
                });
            }
        }
        let spans = spans(self.field, &around);
        let tapers = self.tapers_to_nothing(&found, &spans);
        for (k, (l, thickness)) in found.iter().enumerate() {
            if tapers[k] {
                continue;
            }
            let alike = spans[4 * k..4 * k + 4]
                .iter()
                .filter(|t| t.is_some_and(|t| t <= ALIKE * thickness && ALIKE * t >= *thickness))
                .count();
            if alike < 3 || closes(&spans[4 * k..4 * k + 4], *thickness, h) {
                continue;
            }
            self.thinnest = self.thinnest.min(*thickness);
            let entry = &mut self.bins[bin(thickness / h)];
            if entry.0 == 0 {
                entry.1 = l.centre;
            }
            entry.0 += 1;
        }
    }

    /// Whether each feature of `found` (with its `spans` a cell away along ±u and ±v) thins
    /// to nothing within [`WALK`] cells: where it tapers by more than [`TAPER`] of its
    /// thickness per cell, it is followed from cell to cell the way it thins, and it is a
    /// wedge that closes where it comes to a quarter of its thickness or ends with the two
    /// faces meeting (the point there has the sign of the feature's sides). That is the gap
    /// under a coil or a part that lifts off a floor at a small angle: like a contact, no
    /// finer grid resolves it, and the grid that misses it joins nothing the contact does
    /// not. A wall of even thickness is not followed.
    fn tapers_to_nothing(&self, found: &[(Line, f64)], spans: &[Option<f64>]) -> Vec<bool> {
        let h = self.grid.voxel;
        // Per feature followed: its index, the line at its place now, and the way it thins.
        let mut walkers: Vec<(usize, Line, [f64; 3])> = Vec::new();
        let mut verdict = vec![false; found.len()];
        for (k, (l, t)) in found.iter().enumerate() {
            let s = &spans[4 * k..4 * k + 4];
            let (u, v) = tangents(l.dir);
            let slope = |p: Option<f64>, m: Option<f64>| match (p, m) {
                (Some(p), Some(m)) => (p - m) / (2.0 * h),
                _ => 0.0,
            };
            let (gu, gv) = (slope(s[0], s[1]), slope(s[2], s[3]));
            if (gu * gu + gv * gv).sqrt() * h <= TAPER * t {
                continue;
            }
            // Down the slope of the thickness.
            let Some(d) = unit(-(DVec3::from(u) * gu + DVec3::from(v) * gv)) else {
                continue;
            };
            walkers.push((k, *l, d.to_array()));
        }
        for _ in 0..WALK {
            if walkers.is_empty() {
                break;
            }
            for (_, l, d) in &mut walkers {
                l.centre = [0, 1, 2].map(|i| l.centre[i] + h * d[i]);
            }
            let lines: Vec<Line> = walkers.iter().map(|w| w.1).collect();
            let at = spans_or_sign(self.field, &lines);
            let mut next = Vec::new();
            for (w, a) in walkers.into_iter().zip(at) {
                let t = found[w.0].1;
                match a {
                    Span::Thick(s) if s < 0.25 * t => verdict[w.0] = true,
                    Span::Thick(s) if s < t => next.push(w),
                    Span::Closed => verdict[w.0] = true,
                    _ => {}
                }
            }
            walkers = next;
        }
        verdict
    }

    /// The thickness [`QUANTILE`] of the features are thinner than, and a point in one.
    fn result(&self, h: f64) -> Option<Thin> {
        let edges: u64 = self.bins.iter().map(|b| b.0).sum();
        if edges == 0 {
            return None;
        }
        let target = ((edges as f64 * QUANTILE).ceil() as u64).max(1);
        let mut seen = 0;
        for (k, &(n, at)) in self.bins.iter().enumerate().rev() {
            seen += n;
            if seen >= target {
                // The bin's lower edge: no feature in it is thinner than that by more than
                // one bin.
                let thickness = (h * bin_low(k)).max(self.thinnest);
                return Some(Thin {
                    at,
                    thickness,
                    thinnest: self.thinnest,
                    edges,
                });
            }
        }
        None
    }
}

/// A segment through a feature: from `centre + ends[0]·dir` to `centre + ends[1]·dir`, whose
/// ends are inside the solid when `inside` (and the feature, at the centre, outside), or the
/// other way round.
#[derive(Debug, Clone, Copy)]
struct Line {
    centre: [f64; 3],
    dir: [f64; 3],
    ends: [f64; 2],
    inside: bool,
}

impl Line {
    fn at(&self, s: f64) -> [f64; 3] {
        [0, 1, 2].map(|i| self.centre[i] + s * self.dir[i])
    }

    /// Whether the value `v` has the ends' sign (no value counts as theirs).
    fn like_ends(&self, v: f64) -> bool {
        !v.is_finite() || (v < 0.0) == self.inside
    }
}

/// The offsets of the two roots on each line whose centre has the feature's sign (one
/// between each end and the centre, by bisection); `None` for the others.
fn crossings(field: &Field, lines: &[Line]) -> Vec<Option<[f64; 2]>> {
    let centres: Vec<[f64; 3]> = lines.iter().map(|l| l.centre).collect();
    let d = field.distances(&centres);
    let ids: Vec<usize> = (0..lines.len())
        .filter(|&k| d[k] != 0.0 && !lines[k].like_ends(d[k]))
        .collect();
    // Brackets [end side, centre side] of each root.
    let mut brackets: Vec<[[f64; 2]; 2]> = ids
        .iter()
        .map(|&k| lines[k].ends.map(|e| [e, 0.0]))
        .collect();
    for _ in 0..BISECTIONS {
        let mids: Vec<[f64; 3]> = ids
            .iter()
            .zip(&brackets)
            .flat_map(|(&k, b)| b.map(|s| lines[k].at(0.5 * (s[0] + s[1]))))
            .collect();
        let d = field.distances(&mids);
        for (j, b) in brackets.iter_mut().enumerate() {
            for (side, s) in b.iter_mut().enumerate() {
                let m = 0.5 * (s[0] + s[1]);
                if lines[ids[j]].like_ends(d[2 * j + side]) {
                    s[0] = m;
                } else {
                    s[1] = m;
                }
            }
        }
    }
    let mut out = vec![None; lines.len()];
    for (&k, b) in ids.iter().zip(&brackets) {
        out[k] = Some(b.map(|s| 0.5 * (s[0] + s[1])));
    }
    out
}

/// The feature's extent along each line, where its centre has the feature's sign and both
/// its ends the other (`None` elsewhere: no feature there, or one thicker than the line).
fn spans(field: &Field, lines: &[Line]) -> Vec<Option<f64>> {
    let ends: Vec<[f64; 3]> = lines.iter().flat_map(|l| l.ends.map(|s| l.at(s))).collect();
    let d = field.distances(&ends);
    let ids: Vec<usize> = (0..lines.len())
        .filter(|&k| lines[k].like_ends(d[2 * k]) && lines[k].like_ends(d[2 * k + 1]))
        .collect();
    let kept: Vec<Line> = ids.iter().map(|&k| lines[k]).collect();
    let mut out = vec![None; lines.len()];
    for (&k, o) in ids.iter().zip(crossings(field, &kept)) {
        out[k] = o.map(|o| o[1] - o[0]);
    }
    out
}

/// What a line finds: the feature and its extent, the sides' sign at its centre (the
/// feature has closed there), or neither (the feature's sign, but wider than the line).
enum Span {
    Thick(f64),
    Closed,
    Open,
}

/// [`Span`] along each line.
fn spans_or_sign(field: &Field, lines: &[Line]) -> Vec<Span> {
    let centres: Vec<[f64; 3]> = lines.iter().map(|l| l.centre).collect();
    let d = field.distances(&centres);
    spans(field, lines)
        .into_iter()
        .zip(lines.iter().zip(d))
        .map(|(s, (l, v))| match s {
            Some(t) => Span::Thick(t),
            None if l.like_ends(v) => Span::Closed,
            None => Span::Open,
        })
        .collect()
}

/// The bin of a thickness `t` in cells, the thinnest last: bin `k` holds
/// `2^(-(k+1)/8) < t ≤ 2^(-k/8)`, the last everything thinner.
fn bin(t: f64) -> usize {
    if !(t > 0.0) {
        return BINS - 1;
    }
    ((-t.log2() * BINS_PER_OCTAVE as f64).floor().max(0.0) as usize).min(BINS - 1)
}

/// The lower edge of bin `k`, in cells.
fn bin_low(k: usize) -> f64 {
    if k + 1 == BINS {
        return 0.0;
    }
    (-((k + 1) as f64) / BINS_PER_OCTAVE as f64).exp2()
}

/// Whether the feature of thickness `t`, `spans` thick a cell `h` away along ±u and ±v,
/// closes nearby: the quadric through the five thicknesses, along each line that bends up
/// (by more than the bisections' error) with its lowest point within [`CLOSES_WITHIN`]
/// cells, falls below half of `t`. That is the gap where a curved part touches another,
/// `ρ²/2R` at `ρ` from the contact (a sphere on a floor, whose quadric has no cross term in
/// any frame, and a cylinder, whose quadric without it falls below zero), which no finer
/// grid resolves and which joins nothing the contact does not; a wall of even or tapering
/// thickness bends by no more than the error.
fn closes(spans: &[Option<f64>], t: f64, h: f64) -> bool {
    let mut lowest = t;
    for pair in spans.chunks(2) {
        let (Some(plus), Some(minus)) = (pair[0], pair[1]) else {
            continue;
        };
        let bend = plus + minus - 2.0 * t;
        if !(bend > 1e-4 * h) {
            continue;
        }
        let (a, b) = (bend / (2.0 * h * h), (plus - minus) / (2.0 * h));
        if (b / (2.0 * a)).abs() <= CLOSES_WITHIN * h {
            lowest -= b * b / (4.0 * a);
        }
    }
    lowest < 0.5 * t
}

/// Two unit vectors perpendicular to the unit vector `n` and to each other.
fn tangents(n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    // The axis least along n, crossed with it.
    let k = (0..3)
        .min_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
        .unwrap_or(0);
    let n = DVec3::from(n);
    let u = unit(n.cross(DVec3::AXES[k])).unwrap_or(DVec3::X);
    (u.to_array(), n.cross(u).to_array())
}

#[cfg(test)]
mod tests {
    use super::super::table::corner;
    use super::*;

    #[test]
    fn the_corners_along_each_axis_are_the_lowest_corners_neighbours() {
        for axis in 0..3 {
            let mut e = [0; 3];
            e[axis] = 1;
            assert_eq!(corner(1 << axis), e);
        }
    }

    #[test]
    fn bins_hold_their_thicknesses() {
        for t in [1.0, 0.9, 0.5, 0.3, 0.01, 1e-6] {
            let k = bin(t);
            assert!(bin_low(k) <= t && t <= bin_low(k.saturating_sub(1)).max(1.0) * 1.0001);
        }
    }
}
