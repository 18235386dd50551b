//! Values on grid points, stored sparsely in bricks of 8×8×8 points (`Bricks`): the corner
//! values and cell flags contouring holds.

use super::{pack, table, unpack, Grid, KeyMap};
use rayon::prelude::*;
use std::ops::Range;

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
        // Across bricks: each brick the corners reach looked up once.
        let b = i.map(|x| x / BRICK);
        let mut slots = [None; 8];
        std::array::from_fn(|c| {
            let d = table::corner(c);
            let (mut beyond, mut at) = (0, 0);
            for a in (0..3).rev() {
                let x = i[a] % BRICK + d[a];
                beyond |= usize::from(x == BRICK) << a;
                at = at * BRICK as usize + (x % BRICK) as usize;
            }
            let slot = *slots[beyond].get_or_insert_with(|| {
                self.slot([0, 1, 2].map(|a| b[a] + (beyond >> a & 1) as u32))
            });
            slot.map_or(self.empty, |k| self.data[k as usize][at])
        })
    }

    /// Whether `test` holds for the value at every point `i + d − 1` for the offsets `d` in
    /// `{0, 1, 2}³` whose bit `d[0] + 3·d[1] + 9·d[2]` is set in `around` (those below the
    /// grid's first point left out), each brick they reach looked up once.
    pub fn all_around(&self, i: [u32; 3], mut around: u32, test: impl Fn(T) -> bool) -> bool {
        let mut slots = [None; 27];
        while around != 0 {
            let o = around.trailing_zeros();
            around &= around - 1;
            let d = [o % 3, o / 3 % 3, o / 9];
            if (0..3).any(|a| i[a] + d[a] < 1) {
                continue;
            }
            let p = [0, 1, 2].map(|a| i[a] + d[a] - 1);
            let (b, at) = Self::split(p);
            // The brick's place among the 3×3×3 about `i`'s brick.
            let near = (0..3)
                .rev()
                .fold(0, |n, a| n * 3 + (b[a] + 1 - i[a] / BRICK) as usize);
            let slot = *slots[near].get_or_insert_with(|| self.slot(b));
            if !test(slot.map_or(self.empty, |k| self.data[k as usize][at])) {
                return false;
            }
        }
        true
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

impl<T: Copy + PartialEq + Send + Sync> Bricks<T> {
    /// The value `value(n)` at the `n`th point of `keys` (packed, sorted, each once) of
    /// `grid`, the directory chosen as [`Bricks::over`] chooses it for `held` cells. With a
    /// flat directory the bricks are made and filled in parallel, a layer of bricks along z
    /// at a time (a layer's points are contiguous in `keys`, z being their highest part, and
    /// its bricks are given contiguous slots); otherwise (or for a point beyond the flat
    /// directory) point by point, as [`Bricks::set`] does.
    pub fn from_sorted(
        empty: T,
        grid: &Grid,
        held: u64,
        keys: &[u64],
        value: impl Fn(usize) -> T + Sync,
    ) -> Self {
        let mut bricks = Self::over(empty, grid, held);
        if let Some(layers) = bricks.layers(keys) {
            bricks.fill_layers(keys, &layers, value);
        } else {
            for (n, &k) in keys.iter().enumerate() {
                bricks.set(unpack(k), value(n));
            }
        }
        bricks
    }

    /// For a flat directory holding no brick yet, the points of `keys` by layer of bricks
    /// along z, with slots given to the bricks they reach, layer after layer (`None` for a
    /// hashed directory or a point beyond the flat one).
    fn layers(&mut self, keys: &[u64]) -> Option<Vec<(Range<usize>, usize)>> {
        let Directory::Flat { dims, slots } = &mut self.index else {
            return None;
        };
        let dims = *dims;
        let layer = |k: u64| unpack(k)[2] / BRICK;
        let mut ranges = Vec::new();
        let mut start = 0;
        while start < keys.len() {
            let z = layer(keys[start]);
            let end = start + keys[start..].partition_point(|&k| layer(k) == z);
            ranges.push(start..end);
            start = end;
        }
        // The bricks each layer reaches, as flags over its plane of bricks.
        let plane = (dims[0] * dims[1]) as usize;
        let reached: Option<Vec<Vec<bool>>> = ranges
            .par_iter()
            .map(|r| {
                let mut flags = vec![false; plane];
                for &k in &keys[r.clone()] {
                    let b = unpack(k).map(|x| x / BRICK);
                    if b[0] >= dims[0] || b[1] >= dims[1] || b[2] >= dims[2] {
                        return None;
                    }
                    flags[(b[0] + dims[0] * b[1]) as usize] = true;
                }
                Some(flags)
            })
            .collect();
        let reached = reached?;
        let mut next = 0u32;
        let mut layers = Vec::with_capacity(ranges.len());
        for (r, flags) in ranges.into_iter().zip(reached) {
            let z = layer(keys[r.start]) as usize;
            let first = next;
            for (at, _) in flags.iter().enumerate().filter(|(_, &f)| f) {
                slots[z * plane + at] = next;
                next += 1;
            }
            layers.push((r, (next - first) as usize));
        }
        Some(layers)
    }

    /// The bricks of `layers` ([`Bricks::layers`]: each one's points in `keys` and its
    /// bricks' count) made, and their points set, in parallel.
    fn fill_layers(
        &mut self,
        keys: &[u64],
        layers: &[(Range<usize>, usize)],
        value: impl Fn(usize) -> T + Sync,
    ) {
        let Directory::Flat { dims, slots } = &self.index else {
            return;
        };
        let count = layers.iter().map(|l| l.1).sum::<usize>();
        let empty = self.empty;
        self.data.reserve_exact(count);
        self.data
            .par_extend((0..count).into_par_iter().map(|_| [empty; BRICK_POINTS]));
        let mut parts = Vec::with_capacity(layers.len());
        let (mut rest, mut base) = (&mut self.data[..], 0);
        for (r, n) in layers {
            let (part, tail) = std::mem::take(&mut rest).split_at_mut(*n);
            parts.push((part, base, r.clone()));
            (rest, base) = (tail, base + n);
        }
        parts.into_par_iter().for_each(|(part, base, r)| {
            for n in r {
                let (b, o) = Self::split(unpack(keys[n]));
                let at = b[0] as usize
                    + dims[0] as usize * (b[1] as usize + dims[1] as usize * b[2] as usize);
                part[slots[at] as usize - base][o] = value(n);
            }
        });
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
        // Every neighbourhood read at once is the points read one by one.
        for z in 0..15 {
            for y in 0..11 {
                for x in 0..22 {
                    for around in [
                        0,
                        1,
                        1 << 13,
                        (1 << 27) - 1,
                        0b101_0000_0110_0010_0011_0100_0101,
                    ] {
                        let one_by_one = (0..27).filter(|o| around >> o & 1 == 1).all(|o| {
                            let d = [o % 3, o / 3 % 3, o / 9];
                            (0..3).any(|a| [x, y, z][a] + d[a] < 1)
                                || flat.get([0, 1, 2].map(|a| [x, y, z][a] + d[a] - 1)) != -1
                        });
                        assert_eq!(flat.all_around([x, y, z], around, |v| v != -1), one_by_one);
                    }
                }
            }
        }
        // Filled from sorted keys in one go, flat or hashed, the same values.
        let mut keys: Vec<u64> = points.iter().map(|&i| pack(i)).collect();
        keys.sort_unstable();
        let at = |n: usize| value(unpack(keys[n]));
        let sorted = Bricks::from_sorted(-1i64, &grid, 1000, &keys, at);
        assert!(matches!(sorted.index, Directory::Flat { .. }));
        same(&sorted, &hashed);
        let mut beyond = keys.clone();
        beyond.push(pack([900, 3, 4]));
        let sorted = Bricks::from_sorted(-1i64, &grid, 1000, &beyond, |n| {
            if n < keys.len() {
                at(n)
            } else {
                7
            }
        });
        assert!(matches!(sorted.index, Directory::Hashed(_)));
        assert_eq!(sorted.get([900, 3, 4]), 7);
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
