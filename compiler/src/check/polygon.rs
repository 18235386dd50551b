//! Whether a polygon is simple: the first two of its edges that meet other than at a shared
//! end, found over a grid of cells, so that the work grows with the points (and the cells
//! the edges cross) rather than with their square. Each cell an edge is put in and each pair
//! of edges tested is one evaluation step, within the steps the `fuel` limit leaves.

/// The steps allowed ran out before the test ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OutOfSteps;

/// The first two edges of the closed polygon through `v` that meet other than at a shared
/// end, by the index of their first points, in the order of a test of every pair (`(i, j)`,
/// `i < j`; an edge of no length is `(i, i + 1)`, before its pairs), or none. `steps` counts
/// the steps taken; past `budget`, `Err`.
///
/// Every edge is put in each cell of a grid that it may touch (column by column, widened by
/// a billionth of the polygon's extent against rounding), and only edges sharing a cell are
/// tested: edges that meet share the cell of the point where they meet. Edges far longer
/// than the average, or many through one cell (a star of thousands of thin points), cost
/// more steps: the fuel bounds them.
pub fn crossing(
    v: &[[f64; 2]],
    budget: u64,
    steps: &mut u64,
) -> Result<Option<(usize, usize)>, OutOfSteps> {
    let n = v.len();
    let mut spend = |k: u64| {
        *steps = steps.saturating_add(k);
        if *steps > budget {
            Err(OutOfSteps)
        } else {
            Ok(())
        }
    };
    // The order of a test of every pair: (i, j), with an edge of no length at i first.
    let mut best: Option<((usize, usize), (usize, usize))> = None;
    let found = |best: &mut Option<_>, key: (usize, usize), pair: (usize, usize)| {
        if best.is_none_or(|(k, _)| key < k) {
            *best = Some((key, pair));
        }
    };
    let edge = |i: usize| (v[i], v[(i + 1) % n]);
    for i in 0..n {
        let (a, b) = edge(i);
        if a == b {
            found(&mut best, (i, 0), (i, (i + 1) % n));
        }
    }
    // Neighbours share an end: they may only fold back onto each other.
    for i in 0..n {
        let j = (i + 1) % n;
        let (key, (o, p, q)) = if j == 0 {
            ((0, n - 1), (v[0], v[1], v[n - 1]))
        } else {
            ((i, j), (v[j], v[i], v[(j + 1) % n]))
        };
        if cross(o, p, q) == 0.0
            && (p[0] - o[0]) * (q[0] - o[0]) + (p[1] - o[1]) * (q[1] - o[1]) > 0.0
        {
            found(&mut best, key, key);
        }
    }
    spend(n as u64)?;

    let grid = Grid::new(v);
    let mut cells: Vec<(u64, u32)> = Vec::with_capacity(2 * n);
    for k in 0..n {
        let (a, b) = edge(k);
        let before = cells.len();
        grid.cells(a, b, |c| cells.push((c, k as u32)));
        spend((cells.len() - before) as u64)?;
    }
    cells.sort_unstable();
    let mut start = 0;
    while start < cells.len() {
        let cell = cells[start].0;
        let end = start + cells[start..].partition_point(|&(c, _)| c == cell);
        let here = &cells[start..end];
        spend((here.len() * here.len().saturating_sub(1) / 2) as u64)?;
        for (x, &(_, i)) in here.iter().enumerate() {
            for &(_, j) in &here[x + 1..] {
                let (i, j) = (i as usize, j as usize);
                let adjacent = j == i + 1 || (i == 0 && j == n - 1);
                if adjacent || best.is_some_and(|(k, _)| (i, j) >= k) {
                    continue;
                }
                let ((a, b), (c, d)) = (edge(i), edge(j));
                if meet(a, b, c, d) {
                    found(&mut best, (i, j), (i, j));
                }
            }
        }
        start = end;
    }
    Ok(best.map(|(_, pair)| pair))
}

/// Twice the signed area of the triangle `o`, `a`, `b`.
fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// Whether the segments `a`–`b` and `c`–`d` have a point in common.
fn meet(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    // Whether q, on the line through a and b, lies within their box.
    let within = |a: [f64; 2], b: [f64; 2], q: [f64; 2]| {
        q[0] >= a[0].min(b[0])
            && q[0] <= a[0].max(b[0])
            && q[1] >= a[1].min(b[1])
            && q[1] <= a[1].max(b[1])
    };
    let (d1, d2) = (cross(c, d, a), cross(c, d, b));
    let (d3, d4) = (cross(a, b, c), cross(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    (d1 == 0.0 && within(c, d, a))
        || (d2 == 0.0 && within(c, d, b))
        || (d3 == 0.0 && within(a, b, c))
        || (d4 == 0.0 && within(a, b, d))
}

/// A grid of square cells over the points' box, as wide as the polygon's edges are long on
/// average (so that an edge is in a few cells, and a cell holds a few edges), at most about
/// `2n` cells along an axis.
struct Grid {
    lo: [f64; 2],
    /// A cell's side.
    cell: f64,
    /// How far an edge's cells reach beyond it, against rounding.
    pad: [f64; 2],
    /// Columns and rows.
    count: [u64; 2],
}

impl Grid {
    fn new(v: &[[f64; 2]]) -> Grid {
        let n = v.len();
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        let mut length = 0.0;
        for (i, p) in v.iter().enumerate() {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
            let q = v[(i + 1) % n];
            length += (q[0] - p[0]).hypot(q[1] - p[1]);
        }
        let extent = [hi[0] - lo[0], hi[1] - lo[1]];
        let widest = extent[0].max(extent[1]);
        let most = 2.0 * n as f64 + 1.0;
        let cell = (length / n as f64).max(widest / most);
        let count = extent.map(|e| (e / cell).floor().clamp(0.0, most) as u64 + 1);
        // A box beyond f64 (a point at ±1e308) or of no extent is one cell.
        let (cell, count) = if cell.is_finite() && cell > 0.0 {
            (cell, count)
        } else {
            (1.0, [1; 2])
        };
        let pad = extent.map(|e| if e.is_finite() { e * 1e-9 } else { 0.0 });
        Grid {
            lo,
            cell,
            pad,
            count,
        }
    }

    /// The column (axis 0) or row (axis 1) of the coordinate `x`.
    fn index(&self, axis: usize, x: f64) -> u64 {
        let i = ((x - self.lo[axis]) / self.cell).floor();
        // NaN (never for finite points) goes to 0 as `as` casts it.
        i.clamp(0.0, (self.count[axis] - 1) as f64) as u64
    }

    /// Calls `put` with each cell the segment `a`–`b` may touch.
    fn cells(&self, a: [f64; 2], b: [f64; 2], mut put: impl FnMut(u64)) {
        let (x0, x1) = (a[0].min(b[0]), a[0].max(b[0]));
        let (y0, y1) = (a[1].min(b[1]) - self.pad[1], a[1].max(b[1]) + self.pad[1]);
        let (c0, c1) = (
            self.index(0, x0 - self.pad[0]),
            self.index(0, x1 + self.pad[0]),
        );
        for col in c0..=c1 {
            // The segment's heights over the column's stretch of x (the whole of its
            // height where it is upright or in one column).
            let (ya, yb) = if c0 == c1 || x1 - x0 <= 0.0 {
                (y0, y1)
            } else {
                let left = self.lo[0] + col as f64 * self.cell - self.pad[0];
                let right = left + self.cell + 2.0 * self.pad[0];
                let at = |x: f64| {
                    let t = ((x.clamp(x0, x1) - a[0]) / (b[0] - a[0])).clamp(0.0, 1.0);
                    a[1] + t * (b[1] - a[1])
                };
                let (p, q) = (at(left), at(right));
                (
                    (p.min(q) - self.pad[1]).max(y0),
                    (p.max(q) + self.pad[1]).min(y1),
                )
            };
            for row in self.index(1, ya)..=self.index(1, yb) {
                put(row * self.count[0] + col);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The test of every pair, which the grid replaces.
    fn every_pair(v: &[[f64; 2]]) -> Option<(usize, usize)> {
        let n = v.len();
        for i in 0..n {
            let (a, b) = (v[i], v[(i + 1) % n]);
            if a == b {
                return Some((i, (i + 1) % n));
            }
            for j in i + 1..n {
                let (c, d) = (v[j], v[(j + 1) % n]);
                let next = j == i + 1;
                let wrap = i == 0 && j == n - 1;
                if next || wrap {
                    let (o, p, q) = if next { (b, a, d) } else { (a, b, c) };
                    if cross(o, p, q) == 0.0
                        && (p[0] - o[0]) * (q[0] - o[0]) + (p[1] - o[1]) * (q[1] - o[1]) > 0.0
                    {
                        return Some((i, j));
                    }
                    continue;
                }
                if meet(a, b, c, d) {
                    return Some((i, j));
                }
            }
        }
        None
    }

    #[test]
    fn the_grid_finds_what_every_pair_finds() {
        let mut rng = crate::rng::Rng::new(46);
        for case in 0..3000 {
            let n = 3 + case % 12;
            // Points on a small lattice, so that edges touch, overlap and fold back often.
            let v: Vec<[f64; 2]> = (0..n)
                .map(|_| [(rng.below(6) as f64) * 0.5, (rng.below(6) as f64) * 0.5])
                .collect();
            let mut steps = 0;
            assert_eq!(
                crossing(&v, u64::MAX, &mut steps),
                Ok(every_pair(&v)),
                "{v:?}"
            );
        }
    }

    #[test]
    fn a_hundred_thousand_points_take_steps_in_proportion() {
        let n = 100_000;
        let circle: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                [a.cos(), a.sin()]
            })
            .collect();
        let mut steps = 0;
        assert_eq!(crossing(&circle, u64::MAX, &mut steps), Ok(None));
        assert!(steps < 10 * n as u64, "{steps} steps");
        // A crossing at the far end is found too.
        let mut crossed = circle.clone();
        crossed.swap(n - 10, n - 20);
        let mut steps = 0;
        assert!(matches!(
            crossing(&crossed, u64::MAX, &mut steps),
            Ok(Some(_))
        ));
        // A budget too small is out of steps, not a long wait.
        let mut steps = 0;
        assert_eq!(crossing(&circle, 1000, &mut steps), Err(OutOfSteps));
    }
}
