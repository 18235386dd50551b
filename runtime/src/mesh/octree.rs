//! The grid cells that may hold surface. Where the field's bound is proven, `|f(c)| / L` is
//! at most the distance from a cell's centre `c` to the surface, so a cell whose centre has
//! `|f(c)| > L·r` (r its half-diagonal) holds none, nor do its sub-cells: an octree over
//! the grid evaluates one point per cell, level by level, and subdivides only the cells the
//! test keeps. The cells of the last level are not tested by their centres: every child of a
//! kept two-cell cube is a candidate, and its corners, which contouring evaluates anyway,
//! decide (a cell whose corners all have one sign holds no patch). A field without a proven
//! bound gets the dense grid.

use super::{pack, Field, Grid};

/// Relative slack of the test, for the rounding of the distance program.
const SLACK: f64 = 1e-6;

/// Bytes per octree cell at most, counting every cell the octree may evaluate and the
/// candidates: while a level is evaluated it holds its cells' indices, centres and values (44
/// bytes each), and the indices of the next level's cells in a vector that may double (24
/// bytes each) and, at the last level, their keys (8 bytes each).
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
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Candidates {
    /// Packed keys of the cells (their lowest corner).
    pub cells: Vec<u64>,
    /// Octree cells whose centre was evaluated (0 for the dense grid).
    pub evaluated: u64,
}

/// The cells of `grid` that may hold surface of `field`, with at most `max_cells` octree
/// cells evaluated and candidates returned together (`Err` with the count reached when that
/// would be exceeded; for a dense grid, its cell count). `progress` receives the fraction of levels done.
pub fn candidates(
    field: &Field,
    grid: &Grid,
    max_cells: u64,
    progress: &dyn Fn(f64),
) -> Result<Candidates, u64> {
    if !field.proven {
        let n = grid.dense_cells();
        if n > max_cells {
            return Err(n);
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
            return Err(evaluated);
        }
        let half = 0.5 * size as f64 * grid.voxel;
        let centres: Vec<[f64; 3]> = frontier
            .iter()
            .map(|c| [0, 1, 2].map(|a| grid.origin[a] + c[a] as f64 * 2.0 * half + half))
            .collect();
        let d = field.distances(&centres);
        let reach = field.lipschitz * half * 3f64.sqrt() * (1.0 + SLACK) + SLACK * grid.voxel;
        let kept = || {
            frontier
                .iter()
                .zip(&d)
                .filter(|(_, d)| !(d.abs() > reach))
                .map(|(c, _)| *c)
        };
        progress((level + 1) as f64 / levels.max(1) as f64);
        let child = size / 2;
        let children = |c: [u32; 3]| {
            (0..8u32)
                .map(move |o| [0, 1, 2].map(|a| 2 * c[a] + (o >> a & 1)))
                .filter(move |ch| (0..3).all(|a| ch[a] * child < grid.cells[a]))
        };
        // The next level's cells are counted before they are stored, so that a grid too fine
        // for the cells limit is refused without allocating them.
        let count: u64 = kept().map(|c| children(c).count() as u64).sum();
        if evaluated + count > max_cells {
            return Err(evaluated + count);
        }
        let mut next = Vec::with_capacity(count as usize);
        next.extend(kept().flat_map(children));
        if level + 1 == levels {
            let mut cells: Vec<u64> = next.into_iter().map(pack).collect();
            cells.sort_unstable();
            return Ok(Candidates { cells, evaluated });
        }
        frontier = next;
    }
    Ok(Candidates {
        cells: Vec::new(),
        evaluated,
    })
}
