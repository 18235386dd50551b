//! The cells contouring holds (`contour`'s first step): the candidates' corner values, found
//! as one sorted list of grid points and evaluated in one batch, and the closure over the
//! crossed edges (each crossed edge's four cells held, their corners evaluated in turn),
//! with the surface cells and their configurations; the walls and gaps thinner than a cell
//! that the candidates' corners miss are looked for on the way (`thin`).

use super::table::{corner, EDGES};
use super::thin;
use super::{filled_in_parts, pack, unpack, Bricks, Field, Grid, Stats, KEY_BITS};
use rayon::prelude::*;
use std::sync::OnceLock;

/// The cells contouring holds while it closes over the crossed edges: their corner values,
/// which of them are held, how many, and those the surface crosses.
pub(super) struct Closure {
    /// Corner values. A point whose value was asked for holds -∞ until it comes (the field
    /// never gives -∞: see `Field`).
    pub(super) values: Bricks<f64>,
    /// Whether a cell is held.
    set: Bricks<bool>,
    /// The cells held.
    held: u64,
    /// The surface cells and their configurations, in the order found.
    pub(super) surface: Vec<(u64, u8)>,
}

/// The corner values of `candidates` (those of `known`, corners with their values, read
/// instead of evaluated) and the closure (each crossed edge's four cells), and the surface
/// cells among them; `Err` with the cells held once more than `max_cells` are.
pub(super) fn closure(
    field: &Field,
    grid: &Grid,
    candidates: Vec<u64>,
    known: Vec<(u64, f64)>,
    max_cells: u64,
    stats: &mut Stats,
) -> Result<Closure, u64> {
    let held = candidates.len() as u64;
    let mut closure = Closure {
        values: Bricks::over(f64::NAN, grid, held),
        set: Bricks::from_sorted(false, grid, held, &candidates, |_| true),
        held,
        surface: Vec::new(),
    };
    let mut pending = candidates;
    let mut first = true;
    let mut known = Some(known);
    while !pending.is_empty() {
        if closure.held > max_cells {
            return Err(closure.held);
        }
        if let Some(known) = known.take() {
            closure.evaluate_first(field, grid, &pending, known);
        } else {
            closure.evaluate(field, grid, &pending);
        }
        if first {
            // Walls and gaps between the candidates' corners that no corner sees.
            stats.thin = thin::missed(field, grid, &closure.values, &pending);
        }
        let missing = closure.cross(&pending);
        if !first {
            stats.added += pending.len() as u64;
        }
        first = false;
        pending = missing;
    }
    Ok(closure)
}

impl Closure {
    /// The values at the corners of `candidates` (sorted keys), when none has been asked
    /// for yet: the corners found as one sorted list ([`corners`]), not cell by cell, those
    /// of `known` (corners of them) read, the others evaluated.
    fn evaluate_first(
        &mut self,
        field: &Field,
        grid: &Grid,
        candidates: &[u64],
        mut known: Vec<(u64, f64)>,
    ) {
        if !known.is_sorted_by_key(|&(k, _)| k) {
            known.par_sort_unstable_by_key(|&(k, _)| k);
        }
        let keys = corners_unknown(candidates, &known);
        let d = field.distances_of(keys.len(), |n| grid.point(unpack(keys[n])));
        self.values = Bricks::from_sorted(f64::NAN, grid, self.held, &keys, |n| d[n]);
        for (k, v) in known {
            self.values.set(unpack(k), v);
        }
    }

    /// The values at the corners of `pending` not asked for yet.
    fn evaluate(&mut self, field: &Field, grid: &Grid, pending: &[u64]) {
        let mut need: Vec<[u32; 3]> = Vec::new();
        let mut places = Vec::new();
        for &c in pending {
            let i = unpack(c);
            for k in 0..8 {
                let p = add(i, corner(k));
                if let Some(at) = self.values.replace_if(p, f64::is_nan, f64::NEG_INFINITY) {
                    need.push(p);
                    places.push(at);
                }
            }
        }
        let d = field.distances_of(need.len(), |n| grid.point(need[n]));
        drop(need);
        for (at, v) in places.into_iter().zip(d) {
            self.values.put(at, v);
        }
    }

    /// The surface cells of `pending` kept; returns the cells around their crossed edges
    /// not held yet, now held.
    fn cross(&mut self, pending: &[u64]) -> Vec<u64> {
        // The surface cells, and whether any cell around a crossed edge of each was not held
        // before (read in parallel; only those cells are visited again below, in order).
        let set = &self.set;
        let found: Vec<(u64, u8, bool)> = pending
            .par_iter()
            .filter_map(|&c| {
                let config = configuration(&self.values, c);
                if config == 0 || config == 255 {
                    return None;
                }
                // Offsets of -1 below the grid's first cell name no cell.
                let lacks = !set.all_around(unpack(c), around_crossed(config), |held| held);
                Some((c, config, lacks))
            })
            .collect();
        let mut missing = Vec::new();
        self.surface.reserve(found.len());
        for &(c, config, lacks) in &found {
            self.surface.push((c, config));
            if !lacks {
                continue;
            }
            let i = unpack(c);
            for e in crossed(config) {
                let lower = add(i, corner(EDGES[e].0));
                for n in edge_cells(lower, e / 4) {
                    if self.set.replace_if(n, |held| !held, true).is_some() {
                        self.held += 1;
                        missing.push(pack(n));
                    }
                }
            }
        }
        missing
    }
}

/// The corners of `cells` (sorted keys), sorted, each once, less those of `known` (sorted by
/// key): a layer along z at a time, in parallel. The corners of one layer of cells along x
/// and y ([`corners`]) are their corners in two layers of points, so each layer of points is
/// a merge of those of the two layers of cells beside it.
fn corners_unknown(cells: &[u64], known: &[(u64, f64)]) -> Vec<u64> {
    let z_of = |k: u64| k >> (2 * KEY_BITS);
    if cells.is_empty() {
        return Vec::new();
    }
    let mut starts: Vec<usize> = vec![0];
    starts.extend((1..cells.len()).filter(|&n| z_of(cells[n]) != z_of(cells[n - 1])));
    starts.push(cells.len());
    // Each layer of cells' corners in its own layer of points.
    let flat: Vec<(u64, Vec<u64>)> = starts
        .par_windows(2)
        .map(|w| (z_of(cells[w[0]]), corners(&cells[w[0]..w[1]], 2)))
        .collect();
    let mut layers: Vec<u64> = flat.iter().flat_map(|&(z, _)| [z, z + 1]).collect();
    layers.dedup();
    let step = 1 << (2 * KEY_BITS);
    let parts: Vec<Vec<u64>> = layers
        .par_iter()
        .map(|&z| {
            let find = |z: u64| {
                flat.binary_search_by_key(&z, |l| l.0)
                    .ok()
                    .map(|k| &flat[k].1[..])
            };
            let below = z.checked_sub(1).and_then(find).unwrap_or(&[]);
            let here = find(z).unwrap_or(&[]);
            let keys = union(here, below, step);
            let from = known.partition_point(|&(k, _)| z_of(k) < z);
            let to = known.partition_point(|&(k, _)| z_of(k) <= z);
            unknown(keys, &known[from..to])
        })
        .collect();
    let lengths: Vec<usize> = parts.iter().map(Vec::len).collect();
    filled_in_parts(&lengths, |r, out| out.copy_from_slice(&parts[r]))
}

/// The corners of `cells` (sorted keys), sorted, each once, along the first `axes` axes:
/// the cells grown by one point along x, then y, then z, each a merge of two sorted lists (a
/// key plus one along an axis keeps its order: no index reaches the next axis's bits, see
/// [`super::AXIS_CELLS`]).
fn corners(cells: &[u64], axes: u32) -> Vec<u64> {
    // Along x in one pass: each key, and the next point where it is not the next key.
    let mut keys = Vec::with_capacity(2 * cells.len());
    for (k, &c) in cells.iter().enumerate() {
        keys.push(c);
        if cells.get(k + 1) != Some(&(c + 1)) {
            keys.push(c + 1);
        }
    }
    for axis in 1..axes {
        keys = grown(&keys, 1 << (axis * KEY_BITS));
    }
    keys
}

/// The sorted keys `keys` less those of `known` (sorted by key), in place.
fn unknown(mut keys: Vec<u64>, known: &[(u64, f64)]) -> Vec<u64> {
    let mut known = known.iter().map(|&(k, _)| k).peekable();
    keys.retain(|&k| {
        while known.next_if(|&j| j < k).is_some() {}
        known.next_if_eq(&k).is_none()
    });
    keys
}

/// The union of the sorted keys `a` and `a + step`, sorted, each once.
fn grown(a: &[u64], step: u64) -> Vec<u64> {
    union(a, a, step)
}

/// The union of the sorted keys `a` and `b + step`, sorted, each once.
fn union(a: &[u64], b: &[u64], step: u64) -> Vec<u64> {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while j < b.len() {
        let shifted = b[j] + step;
        if i < a.len() && a[i] <= shifted {
            if a[i] == shifted {
                j += 1;
            }
            out.push(a[i]);
            i += 1;
        } else {
            out.push(shifted);
            j += 1;
        }
    }
    out.extend_from_slice(&a[i..]);
    out
}

/// `a + b`, by components.
pub(super) fn add(a: [u32; 3], b: [u32; 3]) -> [u32; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// Which corners of cell `c` are inside (bit set: negative distance).
fn configuration(values: &Bricks<f64>, c: u64) -> u8 {
    let mut config = 0u8;
    for (k, d) in values.cube(unpack(c)).into_iter().enumerate() {
        if d < 0.0 {
            config |= 1 << k;
        }
    }
    config
}

/// The edges of a cell of configuration `config` that the surface crosses (their ends'
/// signs differ).
fn crossed(config: u8) -> impl Iterator<Item = usize> {
    (0..12).filter(move |&e| {
        let (a, b) = EDGES[e];
        (config >> a & 1) != (config >> b & 1)
    })
}

/// The cells around the crossed edges of a cell of configuration `config`, other than the
/// cell itself, as bits of its 3×3×3 neighbourhood (bit `dx + 3·dy + 9·dz` for the offset
/// `(dx, dy, dz) − 1`): the cells [`edge_cells`] gives for each crossed edge, each once.
fn around_crossed(config: u8) -> u32 {
    static TABLE: OnceLock<[u32; 256]> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|c| around(c as u8)))[config as usize]
}

/// [`around_crossed`], computed.
fn around(config: u8) -> u32 {
    let mut bits = 0u32;
    for e in crossed(config) {
        let lower = corner(EDGES[e].0);
        let axis = e / 4;
        for k in 0..4u32 {
            let mut d = lower.map(|x| x + 1);
            let (u, v) = match axis {
                0 => (1, 2),
                1 => (0, 2),
                _ => (0, 1),
            };
            d[u] -= k & 1;
            d[v] -= k >> 1 & 1;
            bits |= 1 << (d[0] + 3 * d[1] + 9 * d[2]);
        }
    }
    bits & !(1 << 13)
}

/// The four cells around the grid edge from `lower` along `axis` (those inside the grid's
/// index range).
fn edge_cells(lower: [u32; 3], axis: usize) -> impl Iterator<Item = [u32; 3]> {
    let (u, v) = match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    (0..4u32).filter_map(move |k| {
        let mut c = lower;
        for (bit, a) in [(k & 1, u), (k >> 1 & 1, v)] {
            if bit == 1 {
                c[a] = c[a].checked_sub(1)?;
            }
        }
        Some(c)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The corners found as one sorted list are those found cell by cell.
    #[test]
    fn corners_are_each_cells_eight_corners_once() {
        let mut cells: Vec<u64> = Vec::new();
        for z in 0..7u32 {
            for y in 0..6u32 {
                for x in 0..9u32 {
                    if (x * 7 + y * 3 + z * 5) % 4 != 1 || (x + y + z) % 3 == 0 {
                        cells.push(pack([x, y, z]));
                    }
                }
            }
        }
        cells.push(pack([super::super::AXIS_CELLS - 1, 3, 2]));
        cells.sort_unstable();
        let mut expected: Vec<u64> = cells
            .iter()
            .flat_map(|&c| (0..8).map(move |k| pack(add(unpack(c), corner(k)))))
            .collect();
        expected.sort_unstable();
        expected.dedup();
        assert_eq!(corners(&cells, 3), expected);
        assert_eq!(corners_unknown(&cells, &[]), expected);
        let known: Vec<(u64, f64)> = expected.iter().step_by(3).map(|&k| (k, 0.0)).collect();
        let rest: Vec<u64> = expected
            .iter()
            .enumerate()
            .filter(|(n, _)| n % 3 != 0)
            .map(|(_, &k)| k)
            .collect();
        assert_eq!(corners_unknown(&cells, &known), rest);
        // The neighbourhood of each configuration holds the cells around its crossed edges.
        let i = [5u32, 5, 5];
        for config in 0..=255u8 {
            let mut cells: Vec<[u32; 3]> = crossed(config)
                .flat_map(|e| edge_cells(add(i, corner(EDGES[e].0)), e / 4))
                .filter(|&n| n != i)
                .collect();
            cells.sort_unstable();
            cells.dedup();
            let mut bits = around_crossed(config);
            let mut from_bits = Vec::new();
            while bits != 0 {
                let o = bits.trailing_zeros();
                bits &= bits - 1;
                from_bits.push([o % 3 + 4, o / 3 % 3 + 4, o / 9 + 4]);
            }
            from_bits.sort_unstable();
            assert_eq!(from_bits, cells, "{config}");
        }
        assert!(corners(&[], 3).is_empty());
        assert!(corners_unknown(&[], &[]).is_empty());
        // Known corners are left out, each once; keys not among them are ignored.
        let known = [(2, 0.5), (5, -1.0), (6, 1.0), (11, 2.0)];
        assert_eq!(
            unknown(vec![1, 2, 3, 5, 7, 9, 10], &known),
            [1, 3, 7, 9, 10]
        );
        assert_eq!(unknown(vec![], &known), Vec::<u64>::new());
    }
}
