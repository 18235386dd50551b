//! The grid cells that may hold surface. Where the field's bound is proven, `|f(c)| / L` is
//! at most the distance from a cell's centre `c` to the surface, so a cell whose centre has
//! `|f(c)| > L·r` (r its half-diagonal) holds none, nor do its sub-cells: an octree over
//! the grid evaluates one point per cell, level by level, and subdivides only the cells the
//! test keeps. The cells of the last level are not tested by their centres: every child of a
//! kept two-cell cube is a candidate, and its corners, which contouring evaluates anyway,
//! decide (a cell whose corners all have one sign holds no patch). A field without a proven
//! bound gets the dense grid. A GPU's f32 distances widen the test by their rounding
//! ([`Field::rounding`]): a cell more may be kept, never one less.
//!
//! A grid too fine for the cells limit, or with more candidates than the memory limit lets
//! contouring hold, is refused at the first level that proves it ([`candidates_at_least`]),
//! usually one of the first few, before the large levels are evaluated or stored: a point
//! inside the solid whose value is `d` is the centre of a ball of radius `|d| / L` inside it,
//! and every line through the ball meets the surface on both sides of it (the clipped solid
//! is bounded), in cells that the octree keeps.

use super::{filled_in_parts, pack, Field, Grid};
use rayon::prelude::*;

/// Relative slack of the test, for the rounding of the distance program.
const SLACK: f64 = 1e-6;

/// Bytes per octree cell at most, counting every cell the octree may evaluate and the
/// candidates: while a level is evaluated it holds its cells' indices, centres and values (44
/// bytes each), and the indices of the next level's cells in a vector that may double (24
/// bytes each) and, at the last level, their keys (8 bytes each) and the kept cells' centres
/// as keys and values (16 bytes each, once the 24 of the centres are freed).
const BYTES_PER_OCTREE_CELL: u64 = 44 + 24;

/// The most [`candidates`] allocates for `grid`: every octree cell it may evaluate and every
/// candidate (at most 8/7 of the dense grid's cells, and at most `max_cells`), or the dense
/// grid's keys when the bound is not proven.
pub fn bytes(grid: &Grid, proven: bool, max_cells: u64) -> u64 {
    if proven {
        (grid.dense_cells().saturating_mul(8) / 7 + 1)
            .min(max_cells)
            .saturating_mul(BYTES_PER_OCTREE_CELL)
    } else {
        grid.dense_cells().saturating_mul(8)
    }
}

/// The cells that may hold surface, sorted by key, and the cells evaluated to find them.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidates {
    /// Packed keys of the cells (their lowest corner).
    pub cells: Vec<u64>,
    /// Octree cells whose centre was evaluated (0 for the dense grid).
    pub evaluated: u64,
    /// The centres of the last level's cells kept, which are corners of the candidates
    /// (the corner every child of one shares), with their values: packed keys, sorted.
    /// Contouring reads them instead of evaluating those corners again.
    pub centres: Vec<(u64, f64)>,
}

impl From<Vec<u64>> for Candidates {
    /// Candidates found otherwise: sorted cell keys, none of whose corners is known.
    fn from(cells: Vec<u64>) -> Self {
        Candidates {
            cells,
            evaluated: 0,
            centres: Vec::new(),
        }
    }
}

/// Why [`candidates`] stopped early.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refused {
    /// The octree cells evaluated and the candidates would exceed the cells limit: this many
    /// or more.
    Cells(u64),
    /// There would be more candidates than asked for at most: this many or more.
    Candidates(u64),
}

/// The cells of `grid` that may hold surface of `field`, with at most `max_cells` octree
/// cells evaluated and candidates returned together (`Err` with the count reached, or a
/// lower bound of it, when that would be exceeded; for a dense grid, its cell count). A
/// level that proves more than `max_candidates` candidates stops it too (more may be
/// returned: the caller checks their number). `progress` receives the fraction of levels
/// done.
pub fn candidates(
    field: &Field,
    grid: &Grid,
    max_cells: u64,
    max_candidates: u64,
    progress: &dyn Fn(f64),
) -> Result<Candidates, Refused> {
    if !field.proven {
        let n = grid.dense_cells();
        if n > max_cells {
            return Err(Refused::Cells(n));
        }
        let [nx, ny, nz] = grid.cells;
        let mut cells = Vec::with_capacity(n as usize);
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    cells.push(pack([i, j, k]));
                }
            }
        }
        cells.sort_unstable();
        return Ok(Candidates {
            cells,
            evaluated: 0,
            centres: Vec::new(),
        });
    }
    let largest = grid.cells.iter().copied().max().unwrap_or(1).max(1);
    // At least one level above the cells, so that the last level is cells of edge two.
    let levels = (u32::BITS - (largest - 1).leading_zeros()).max(1);
    let mut frontier: Vec<[u32; 3]> = vec![[0; 3]];
    let mut evaluated = 0u64;
    for level in 0..levels {
        let size = 1u32 << (levels - level);
        evaluated += frontier.len() as u64;
        if evaluated > max_cells {
            return Err(Refused::Cells(evaluated));
        }
        let half = 0.5 * size as f64 * grid.voxel;
        // The centres are grid points, placed as the grid places them, so that the last
        // level's are the corners contouring would evaluate, to the bit ([`Candidates::centres`]).
        let d = field.distances_of(frontier.len(), |n| {
            grid.point(frontier[n].map(|x| x * size + size / 2))
        });
        // The surface these values prove, before the next level is counted or stored.
        let within = max_cells.saturating_sub(evaluated).min(max_candidates);
        // The balls inside, shrunk by the rounding of a GPU's f32 distances.
        let rounding = field.rounding();
        let shrunk: Vec<f64>;
        let inside = if rounding > 0.0 {
            shrunk = d
                .iter()
                .map(|&v| if v < 0.0 { (v + rounding).min(0.0) } else { v })
                .collect();
            &shrunk
        } else {
            &d
        };
        let surface =
            candidates_at_least(&frontier, inside, size, grid.voxel, field.lipschitz, within);
        if evaluated.saturating_add(surface) > max_cells {
            return Err(Refused::Cells(evaluated.saturating_add(surface)));
        }
        if surface > max_candidates {
            return Err(Refused::Candidates(surface));
        }
        let reach =
            field.lipschitz * half * 3f64.sqrt() * (1.0 + SLACK) + SLACK * grid.voxel + rounding;
        let keep: Vec<bool> = d.par_iter().map(|d| !(d.abs() > reach)).collect();
        progress((level + 1) as f64 / levels.max(1) as f64);
        let runs = Runs::new(&frontier, &keep, size / 2, grid.cells);
        // The next level's cells are counted before they are stored, so that a grid too fine
        // for the cells limit is refused without allocating them.
        let count = runs.count();
        if evaluated + count > max_cells {
            return Err(Refused::Cells(evaluated + count));
        }
        if level + 1 == levels {
            let cells = runs.children(pack);
            let centres = frontier
                .par_iter()
                .zip(&d)
                .zip(&keep)
                .filter(|(_, &k)| k)
                .map(|((c, &d), _)| (pack(c.map(|x| 2 * x + 1)), d))
                .collect();
            return Ok(Candidates {
                cells,
                evaluated,
                centres,
            });
        }
        let next = runs.children(|c| c);
        frontier = next;
    }
    Ok(Candidates {
        cells: Vec::new(),
        evaluated,
        centres: Vec::new(),
    })
}

/// A level's cells (sorted by key: z, then y, then x) in runs of one layer along z, with
/// which of them are kept, from which the next level's cells (`child` grid cells along an
/// edge, those that begin inside a grid of `cells`) are made sorted by key, a layer at a
/// time in parallel: the children of one layer along z of the parents lie in two layers of
/// their own, each row of parents giving two rows in turn, where a parent's children along
/// x follow its neighbour's. No sort is needed, and the next level is sorted in turn.
struct Runs<'a> {
    cells: &'a [[u32; 3]],
    keep: &'a [bool],
    child: u32,
    grid: [u32; 3],
    /// The start of each layer's run in `cells` (and, last, their end).
    starts: Vec<usize>,
    /// Children of each layer's kept cells.
    counts: Vec<u64>,
}

impl<'a> Runs<'a> {
    fn new(cells: &'a [[u32; 3]], keep: &'a [bool], child: u32, grid: [u32; 3]) -> Self {
        let mut starts = vec![0];
        if !cells.is_empty() {
            starts.extend((1..cells.len()).filter(|&n| cells[n][2] != cells[n - 1][2]));
            starts.push(cells.len());
        }
        let mut runs = Runs {
            cells,
            keep,
            child,
            grid,
            starts,
            counts: Vec::new(),
        };
        runs.counts = (0..runs.starts.len() - 1)
            .into_par_iter()
            .map(|r| runs.layer(r, &mut |_| ()))
            .collect();
        runs
    }

    /// The next level's cells.
    fn count(&self) -> u64 {
        self.counts.iter().sum()
    }

    /// Whether a child's index `x` along `axis` begins inside the grid.
    fn inside(&self, x: u32, axis: usize) -> bool {
        x * self.child < self.grid[axis]
    }

    /// The children of layer `r`'s kept cells, in key order, each given to `emit`; their
    /// number.
    fn layer(&self, r: usize, emit: &mut impl FnMut([u32; 3])) -> u64 {
        let run = &self.cells[self.starts[r]..self.starts[r + 1]];
        let keep = &self.keep[self.starts[r]..self.starts[r + 1]];
        let mut n = 0;
        for dz in 0..2 {
            let z = 2 * run[0][2] + dz;
            if !self.inside(z, 2) {
                continue;
            }
            let mut row = 0;
            while row < run.len() {
                let end = row + run[row..].partition_point(|c| c[1] == run[row][1]);
                for dy in 0..2 {
                    let y = 2 * run[row][1] + dy;
                    if !self.inside(y, 1) {
                        continue;
                    }
                    for (c, _) in run[row..end].iter().zip(&keep[row..end]).filter(|p| *p.1) {
                        for dx in 0..2 {
                            let x = 2 * c[0] + dx;
                            if self.inside(x, 0) {
                                emit([x, y, z]);
                                n += 1;
                            }
                        }
                    }
                }
                row = end;
            }
        }
        n
    }

    /// The children of the kept cells, sorted by key, each made by `make`.
    fn children<T: Send + Copy + Default>(&self, make: impl Fn([u32; 3]) -> T + Sync) -> Vec<T> {
        let lengths: Vec<usize> = self.counts.iter().map(|&n| n as usize).collect();
        filled_in_parts(&lengths, |r, part| {
            let mut k = 0;
            self.layer(r, &mut |c| {
                part[k] = make(c);
                k += 1;
            });
        })
    }
}

/// Relative slack of the radii in [`candidates_at_least`], for the rounding of the distances.
const BALL_SLACK: f64 = 1e-6;

/// The most balls [`candidates_at_least`] sorts into rows (16 bytes each); beyond (a fine
/// level, whose sorting would cost about as much as its evaluation) it counts them by slices
/// alone.
const ROWS_SORTED: usize = 1 << 16;

/// Grid columns of a disc of radius `r` cells about a cell corner of the grid, at least: the
/// column centres (at half-integers of it) strictly inside the square inscribed in the disc,
/// of half side `r / √2`, `2k` along each side where `k` counts the `m + ½ < r / √2`.
fn columns_within(r: f64) -> u64 {
    let k = (r / std::f64::consts::SQRT_2 - 0.5 - 1e-9).ceil().max(0.0) as u64;
    (2 * k).saturating_mul(2 * k)
}

/// A lower bound on the candidates [`candidates`] returns, from one level's cells (`cells`,
/// indices at the level, `size` grid cells of edge `voxel` along an edge) and their centres'
/// values `d` under the bound `lipschitz`: `0` unless it may exceed `within` (the rows are
/// not sorted otherwise).
///
/// A centre with `d < 0` is inside the solid, with the ball of radius `ρ = |d| / L` about it
/// (the field is proven). The solid is bounded, so every line through that ball parallel to
/// an axis passes from inside to outside on each side of it: two points of the surface
/// (zeros of the field), in two grid cells of the line's column, which the octree keeps at
/// every level (a cell holding a zero has `|f(c)| ≤ L·r`) and returns. The balls about the
/// centres of one row of this level along the axis have one disc as their shadow, that of
/// the largest, which within half the level's edge lies in the row's square: the rows'
/// columns are distinct. So each axis gives twice the sum over rows of the columns of the
/// largest disc (within half an edge), or, counted in one pass, over the cells of one slice
/// across the axis (one per row); the bound is the largest of these.
pub fn candidates_at_least(
    cells: &[[u32; 3]],
    d: &[f64],
    size: u32,
    voxel: f64,
    lipschitz: f64,
    within: u64,
) -> u64 {
    // Radii in grid cells, within half the level's edge.
    let cap = 0.5 * size as f64;
    let radius = |d: f64| (-d * (1.0 - BALL_SLACK) / (lipschitz * voxel) - BALL_SLACK).min(cap);
    let lines = |d: f64| 2 * columns_within(radius(d));
    // One pass: the lines of every ball, and by slices across each axis (the cells of one
    // slice lie in distinct rows along it), where there are no more slices than cells: their
    // sums then take at most the 24 bytes a cell that the octree's memory bound leaves free
    // while a level is evaluated ([`BYTES_PER_OCTREE_CELL`]).
    let slices = cells.iter().flatten().max().map_or(0, |&m| m as usize + 1);
    let slices = if slices <= cells.len() { slices } else { 0 };
    let mut sums = [(); 3].map(|_| vec![0u64; slices]);
    let (mut unshared, mut balls) = (0u64, 0usize);
    for (c, &d) in cells.iter().zip(d) {
        if !(d < 0.0) {
            continue;
        }
        let n = lines(d);
        if n == 0 {
            continue;
        }
        unshared += n;
        balls += 1;
        if slices > 0 {
            for (axis, sum) in sums.iter_mut().enumerate() {
                sum[c[axis] as usize] += n;
            }
        }
    }
    // Without sharing rows: when even that stays within, so does the bound.
    if unshared <= within {
        return 0;
    }
    let mut best = sums
        .iter()
        .map(|s| s.iter().copied().max().unwrap_or(0))
        .max()
        .unwrap_or(0);
    drop(sums);
    // The largest ball of each row, where the balls are few enough to sort.
    if best > within || balls > ROWS_SORTED {
        return best;
    }
    let mut rows: Vec<(u64, f64)> = Vec::with_capacity(balls);
    for axis in 0..3 {
        rows.clear();
        rows.extend(
            cells
                .iter()
                .zip(d)
                .filter(|&(_, &d)| d < 0.0 && lines(d) > 0)
                .map(|(c, &d)| {
                    let (u, v) = (c[(axis + 1) % 3] as u64, c[(axis + 2) % 3] as u64);
                    (u | v << 32, radius(d))
                }),
        );
        rows.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(b.1.total_cmp(&a.1)));
        rows.dedup_by_key(|row| row.0);
        let sum: u64 = rows.iter().map(|&(_, r)| 2 * columns_within(r)).sum();
        best = best.max(sum);
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::unpack;

    /// The children made layer by layer are sorted, each once, and are those of the kept
    /// cells that begin inside the grid, over grids whose sides are odd or even.
    #[test]
    fn children_are_made_sorted() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for (grid, child) in [([1, 1, 1], 1), ([259, 147, 259], 4), ([37, 3, 20], 1)] {
            let parents = grid.map(|n: u32| n.div_ceil(2 * child));
            let mut cells = Vec::new();
            for z in 0..parents[2] {
                for y in 0..parents[1] {
                    for x in 0..parents[0] {
                        cells.push([x, y, z]);
                    }
                }
            }
            let keep: Vec<bool> = cells
                .iter()
                .map(|_| {
                    state = state
                        .wrapping_mul(6_364_136_223_846_793_005)
                        .wrapping_add(1);
                    state >> 62 != 0
                })
                .collect();
            let runs = Runs::new(&cells, &keep, child, grid);
            let made = runs.children(pack);
            let mut expected: Vec<u64> = cells
                .iter()
                .zip(&keep)
                .filter(|(_, &k)| k)
                .flat_map(|(c, _)| {
                    (0..8u32).map(move |o| [0, 1, 2].map(|a| 2 * c[a] + (o >> a & 1)))
                })
                .filter(|ch| (0..3).all(|a| ch[a] * child < grid[a]))
                .map(pack)
                .collect();
            expected.sort_unstable();
            assert_eq!(made, expected, "{grid:?}");
            assert_eq!(runs.count(), made.len() as u64);
            assert!(made
                .iter()
                .all(|&k| (0..3).all(|a| unpack(k)[a] * child < grid[a])));
            let unpacked = runs.children(|c| c);
            assert_eq!(unpacked.iter().map(|&c| pack(c)).collect::<Vec<_>>(), made);
        }
        let none = Runs::new(&[], &[], 1, [4, 4, 4]);
        assert_eq!(none.count(), 0);
        assert!(none.children(pack).is_empty());
    }
}
