//! The surface patches of a grid cell, for each of the 256 ways its corners can lie inside
//! or outside: directed cycles of the cell's edges that the surface crosses, computed once
//! from the cube's faces (no hand-written table).
//!
//! On each face the crossed edges are paired into segments: a face with two crossed edges
//! has one segment; a face with four (inside corners on a diagonal) has two, each cutting off
//! one inside corner. The rule depends on the face's four corners alone, so the two cells
//! that share a face pair its edges alike and the patches of neighbouring cells meet along
//! the same segments: the surface is closed. Each segment is directed so that the patch runs
//! counter-clockwise seen from outside the solid (outward normals), which gives the two cells
//! of a face opposite directions on the segment they share. Every crossed edge then has one
//! segment leaving it and one entering it in its cell, and the segments form cycles.

use std::sync::OnceLock;

/// Corner `c` of the unit cell is at `(c & 1, c >> 1 & 1, c >> 2 & 1)`.
pub fn corner(c: usize) -> [u32; 3] {
    [(c & 1) as u32, (c >> 1 & 1) as u32, (c >> 2 & 1) as u32]
}

/// Edge `e` runs along axis `e / 4` from corner `EDGES[e].0` to corner `EDGES[e].1`.
pub const EDGES: [(usize, usize); 12] = {
    let mut edges = [(0, 0); 12];
    let mut e = 0;
    while e < 12 {
        let axis = e / 4;
        let k = e % 4;
        // The other two axes, in increasing order, take the bits of k.
        let (u, v) = match axis {
            0 => (1, 2),
            1 => (0, 2),
            _ => (0, 1),
        };
        let from = ((k & 1) << u) | ((k >> 1 & 1) << v);
        edges[e] = (from, from | 1 << axis);
        e += 1;
    }
    edges
};

/// The patches of one configuration: each a cycle of edge numbers, counter-clockwise seen
/// from outside.
pub type Patches = Vec<Vec<u8>>;

/// The patches of configuration `config` (bit `c` set: corner `c` is inside).
pub fn patches(config: u8) -> &'static Patches {
    static TABLE: OnceLock<Vec<Patches>> = OnceLock::new();
    &TABLE.get_or_init(|| (0..=255u8).map(build).collect())[config as usize]
}

fn edge_between(a: usize, b: usize) -> usize {
    EDGES
        .iter()
        .position(|&(x, y)| (x, y) == (a, b) || (x, y) == (b, a))
        .unwrap_or(usize::MAX)
}

fn build(config: u8) -> Patches {
    let inside = |c: usize| config >> c & 1 == 1;
    // Twice the coordinates, so that edge midpoints are whole numbers.
    let at = |c: usize| corner(c).map(|x| 2 * x as i64);
    let mid = |e: usize| {
        let (a, b) = EDGES[e];
        let (p, q) = (at(a), at(b));
        [0, 1, 2].map(|i| (p[i] + q[i]) / 2)
    };
    let mut next = [usize::MAX; 12];
    for axis in 0..3 {
        for side in 0..2u32 {
            let (u, v) = match axis {
                0 => (1, 2),
                1 => (0, 2),
                _ => (0, 1),
            };
            // The face's corners in cyclic order, and its outward normal.
            let ring: Vec<usize> = [(0, 0), (1, 0), (1, 1), (0, 1)]
                .iter()
                .map(|&(a, b)| (side as usize) << axis | a << u | b << v)
                .collect();
            let mut normal = [0i64; 3];
            normal[axis] = if side == 1 { 1 } else { -1 };
            let crossed: Vec<usize> = (0..4)
                .filter(|&i| inside(ring[i]) != inside(ring[(i + 1) % 4]))
                .collect();
            // Segments as (edge, edge, an inside corner on the segment's inner side).
            let mut segments = Vec::new();
            match crossed.len() {
                2 => {
                    let (i, j) = (crossed[0], crossed[1]);
                    let c = ring.iter().copied().find(|&c| inside(c)).unwrap_or(0);
                    segments.push((
                        edge_between(ring[i], ring[(i + 1) % 4]),
                        edge_between(ring[j], ring[(j + 1) % 4]),
                        c,
                    ));
                }
                4 => {
                    for k in 0..4 {
                        let c = ring[k];
                        if inside(c) {
                            let prev = ring[(k + 3) % 4];
                            let next = ring[(k + 1) % 4];
                            segments.push((edge_between(prev, c), edge_between(c, next), c));
                        }
                    }
                }
                _ => {}
            }
            for (a, b, c) in segments {
                // Direct a→b when (b − a) · (n × (c − a)) > 0: the inside lies to the left
                // of the direction of travel seen from outside the solid.
                let (ma, mb, pc) = (mid(a), mid(b), at(c));
                let w = [0, 1, 2].map(|i| pc[i] - ma[i]);
                let nxw = [
                    normal[1] * w[2] - normal[2] * w[1],
                    normal[2] * w[0] - normal[0] * w[2],
                    normal[0] * w[1] - normal[1] * w[0],
                ];
                let dot: i64 = (0..3).map(|i| (mb[i] - ma[i]) * nxw[i]).sum();
                let (from, to) = if dot > 0 { (a, b) } else { (b, a) };
                next[from] = to;
            }
        }
    }
    let mut seen = [false; 12];
    let mut cycles = Vec::new();
    for start in 0..12 {
        if next[start] == usize::MAX || seen[start] {
            continue;
        }
        let mut cycle = Vec::new();
        let mut e = start;
        while !seen[e] {
            seen[e] = true;
            cycle.push(e as u8);
            e = next[e];
        }
        cycles.push(cycle);
    }
    cycles
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every crossed edge lies on exactly one patch, once; no other edge does; a lone inside
    /// corner gives one triangle counter-clockwise seen from outside.
    #[test]
    fn patches_cover_the_crossed_edges_once() {
        for config in 0..=255u8 {
            let inside = |c: usize| config >> c & 1 == 1;
            let mut count = [0; 12];
            for cycle in patches(config) {
                assert!(cycle.len() >= 3, "{config}: {cycle:?}");
                for &e in cycle {
                    count[e as usize] += 1;
                }
            }
            for (e, &(a, b)) in EDGES.iter().enumerate() {
                let crossed = inside(a) != inside(b);
                assert_eq!(count[e], usize::from(crossed), "config {config}, edge {e}");
            }
        }
        // Corner 0 inside: edges 0 (x), 4 (y), 8 (z) in the order x → y → z.
        let p = patches(1);
        assert_eq!(p.len(), 1);
        let c = &p[0];
        let i = c.iter().position(|&e| e == 0).expect("edge 0");
        assert_eq!(c[(i + 1) % 3], 4);
        assert_eq!(c[(i + 2) % 3], 8);
    }

    /// Complementary configurations give the same cycles reversed where no face is
    /// ambiguous (the surface is the same, seen from the other side).
    #[test]
    fn a_config_and_its_complement_are_opposite_when_unambiguous() {
        let single = patches(0b0000_0011);
        let other = patches(!0b0000_0011);
        assert_eq!(single.len(), 1);
        let mut a = single[0].clone();
        let mut b = other[0].clone();
        b.reverse();
        let r = b.iter().position(|&e| e == a[0]).expect("same edges");
        b.rotate_left(r);
        a.rotate_left(0);
        assert_eq!(a, b);
    }
}
