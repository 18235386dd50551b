//! Triangle meshes as shapes (`mesh("part.stl")`): the triangles, their angle-weighted
//! pseudo-normals and a bounding volume hierarchy over them, and the signed distance at a
//! point, in f32 or f64, that every evaluator of `Op::Mesh` computes the same way (the WGSL
//! kernel's `mesh_distance` walks the same hierarchy in the same order: back/wgsl/mesh.rs).
//!
//! The distance is the distance to the nearest triangle, found through the hierarchy (a node
//! is skipped where its box is no nearer than the best triangle so far; the nearer child is
//! visited first). The nearest point on a triangle and the feature it lies on (a corner, an
//! edge or the face) follow Ericson's `ClosestPtPointTriangle` (Real-Time Collision
//! Detection, 2005, §5.1.5). The sign is that of `(p − q) · n` with `q` the nearest point and
//! `n` the angle-weighted pseudo-normal of the feature `q` lies on (Bærentzen and Aanæs,
//! "Signed distance computation using the angle weighted pseudonormal", IEEE TVCG 2005): the
//! face's normal, the sum of an edge's two faces' normals, or the sum of a corner's faces'
//! normals weighted by their angles there. On a closed, consistently oriented mesh this is
//! the exact signed distance. Where the mesh is open, an edge with one face takes that face's
//! normal: points nearest to the rim get the side of the face at the rim, so the sign is
//! right away from the holes and may be wrong seen through one.
//!
//! Every coordinate is stored as a value an f32 holds exactly (the GPU reads f32), and every
//! box rounded outwards to one, so the f32 and f64 evaluations and the GPU's read the same
//! triangles and boxes.

use super::Float;
use glam::DVec3;
use std::collections::HashMap;
use triangle::{bound, nearest, point_of, sub3, FACE};

mod triangle;

/// Triangles per leaf of the hierarchy, at most.
pub const LEAF: usize = 4;

/// The deepest stack a walk needs: the hierarchy halves its triangles at each level, so it is
/// at most log₂(2³²) + 2 deep, and a walk holds at most one entry per level and one more.
pub const STACK: usize = 40;

/// One triangle: its corners `a`, `b`, `c` (counter-clockwise seen from outside), then the
/// pseudo-normals of `a`, `b`, `c` and of the edges `ab`, `bc`, `ca` (the face's normal is
/// `(b − a) × (c − a)`).
pub type Triangle = [[f64; 3]; 9];

/// A node of the hierarchy: a box, and either `count` triangles from `first` (a leaf) or,
/// when `count` is 0, two children at `first` and `first + 1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    pub first: u32,
    pub count: u32,
}

/// A triangle mesh ready to be queried.
#[derive(Debug, Clone, PartialEq)]
pub struct TriMesh {
    /// The file's name, for the program's text.
    pub name: String,
    /// Its index among the meshes of its scene (`Op::Mesh` names it so).
    pub id: u32,
    /// Where its data starts in the GPU's `scene_data`, in vectors of 16 bytes
    /// (back/wgsl/mesh.rs): after every mesh of the scene with a smaller id.
    pub base: u32,
    triangles: Vec<Triangle>,
    nodes: Vec<Node>,
    /// The largest magnitude of a coordinate of its box ([`bound_pad`]).
    reach: f64,
    /// What building found: open and non-manifold edges, dropped triangles.
    pub report: Report,
}

/// What [`TriMesh::new`] found in a mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Report {
    /// Edges with one triangle (the rims of holes).
    pub open_edges: usize,
    /// Edges with more than two triangles.
    pub non_manifold_edges: usize,
    /// Triangles of no area (two corners the same, or three in a line), dropped.
    pub degenerate: usize,
    /// Whether the triangles were wound inside out (negative volume) and turned round.
    pub flipped: bool,
}

/// Why a mesh cannot be built.
#[derive(Debug, Clone, PartialEq)]
pub enum Invalid {
    /// A vertex's coordinate is NaN or infinite (after scaling): its index.
    NotFinite(usize),
    /// A triangle names a vertex that does not exist: the triangle and the index.
    Index(usize, u32),
    /// No triangle of any area is left.
    Empty,
}

/// `a / |a|`, or `a` itself where it has no length (divided, not multiplied by the
/// reciprocal, so that the normals are those the mesh has always had).
fn unit(a: DVec3) -> DVec3 {
    let l = a.length();
    if l > 0.0 {
        a / l
    } else {
        a
    }
}

/// The f32 nearest to `x`, as an f64.
fn f32_near(x: f64) -> f64 {
    f64::from(x as f32)
}

/// The f32 next to the finite `f`, towards +∞ (`up`) or −∞.
fn f32_next(f: f32, up: bool) -> f32 {
    if f == 0.0 {
        let tiny = f32::from_bits(1);
        return if up { tiny } else { -tiny };
    }
    let bits = f.to_bits();
    // Away from zero the magnitude's bits grow by one, towards zero they shrink.
    f32::from_bits(if (f > 0.0) == up { bits + 1 } else { bits - 1 })
}

/// The largest f32 at or below `x`.
fn f32_down(x: f64) -> f64 {
    let f = x as f32;
    if f64::from(f) > x {
        f64::from(f32_next(f, false))
    } else {
        f64::from(f)
    }
}

/// The smallest f32 at or above `x`.
fn f32_up(x: f64) -> f64 {
    let f = x as f32;
    if f64::from(f) < x {
        f64::from(f32_next(f, true))
    } else {
        f64::from(f)
    }
}

impl TriMesh {
    /// How far beyond a triangle's edges (in its barycentric coordinates) a traced ray still
    /// meets it: enough to cover the f32 rounding of the coordinates (a ray through an edge
    /// meets one of its two triangles, not the crack between), too little to show.
    pub const EDGE: f64 = 1e-5;

    /// Builds a mesh from `positions` (scaled by `scale`, rounded to f32) and `faces`
    /// (indices into them, counter-clockwise seen from outside). Corners at the same place
    /// are one vertex; triangles of no area are dropped; a mesh wound inside out is turned.
    pub fn new(
        name: &str,
        positions: &[[f64; 3]],
        faces: &[[u32; 3]],
        scale: f64,
    ) -> Result<TriMesh, Invalid> {
        // Weld: one vertex per position.
        let mut index: HashMap<[u64; 3], u32> = HashMap::new();
        let mut verts: Vec<[f64; 3]> = Vec::new();
        let mut remap = Vec::with_capacity(positions.len());
        for (i, p) in positions.iter().enumerate() {
            let q = p.map(|x| f32_near(x * scale));
            if q.iter().any(|x| !x.is_finite()) {
                return Err(Invalid::NotFinite(i));
            }
            // +0 and −0 are one place.
            let key = q.map(|x| (x + 0.0).to_bits());
            let v = *index.entry(key).or_insert_with(|| {
                verts.push(q);
                verts.len() as u32 - 1
            });
            remap.push(v);
        }
        let mut report = Report::default();
        let mut tris: Vec<[u32; 3]> = Vec::with_capacity(faces.len());
        for (t, f) in faces.iter().enumerate() {
            let mut g = [0u32; 3];
            for k in 0..3 {
                g[k] = *remap.get(f[k] as usize).ok_or(Invalid::Index(t, f[k]))?;
            }
            let [a, b, c] = g.map(|i| DVec3::from(verts[i as usize]));
            let n = (b - a).cross(c - a);
            if g[0] == g[1] || g[1] == g[2] || g[2] == g[0] || n.length_squared() == 0.0 {
                report.degenerate += 1;
                continue;
            }
            tris.push(g);
        }
        if tris.is_empty() {
            return Err(Invalid::Empty);
        }
        // Six times the signed volume: negative for a mesh wound inside out.
        let volume: f64 = tris
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| DVec3::from(verts[i as usize]));
                a.dot(b.cross(c))
            })
            .sum();
        if volume < 0.0 {
            report.flipped = true;
            for t in &mut tris {
                t.swap(1, 2);
            }
        }
        // Pseudo-normals: per vertex the angle-weighted sum of its faces' unit normals, per
        // edge the sum of its faces' (Bærentzen and Aanæs 2005).
        let mut vn = vec![DVec3::ZERO; verts.len()];
        let mut edges: HashMap<(u32, u32), (DVec3, u32)> = HashMap::new();
        for t in &tris {
            let p = t.map(|i| DVec3::from(verts[i as usize]));
            let n = unit((p[1] - p[0]).cross(p[2] - p[0]));
            for k in 0..3 {
                let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
                let (u, v) = (unit(b - a), unit(c - a));
                let angle = u.dot(v).clamp(-1.0, 1.0).acos();
                vn[t[k] as usize] += n * angle;
                let (i, j) = (t[k], t[(k + 1) % 3]);
                let e = edges
                    .entry((i.min(j), i.max(j)))
                    .or_insert((DVec3::ZERO, 0));
                e.0 += n;
                e.1 += 1;
            }
        }
        for (_, count) in edges.values() {
            match count {
                1 => report.open_edges += 1,
                2 => {}
                _ => report.non_manifold_edges += 1,
            }
        }
        let triangles: Vec<Triangle> = tris
            .iter()
            .map(|t| {
                let en = |k: usize| {
                    let (i, j) = (t[k], t[(k + 1) % 3]);
                    unit(edges[&(i.min(j), i.max(j))].0).to_array()
                };
                [
                    verts[t[0] as usize],
                    verts[t[1] as usize],
                    verts[t[2] as usize],
                    unit(vn[t[0] as usize]).to_array(),
                    unit(vn[t[1] as usize]).to_array(),
                    unit(vn[t[2] as usize]).to_array(),
                    en(0),
                    en(1),
                    en(2),
                ]
            })
            .collect();
        let (triangles, nodes) = hierarchy(triangles);
        let reach = nodes[0]
            .lo
            .iter()
            .chain(&nodes[0].hi)
            .fold(0.0f64, |m, x| m.max(x.abs()));
        Ok(TriMesh {
            name: name.to_string(),
            id: 0,
            base: 0,
            triangles,
            nodes,
            reach,
            report,
        })
    }

    /// The vectors of 16 bytes its data takes in `scene_data` (back/wgsl/mesh.rs): a header,
    /// two per node, nine per triangle.
    pub fn vectors(&self) -> u64 {
        1 + 2 * self.nodes.len() as u64 + 9 * self.triangles.len() as u64
    }

    /// The triangles, in the hierarchy's order.
    pub fn triangles(&self) -> &[Triangle] {
        &self.triangles
    }

    /// The hierarchy's nodes; the root is the first.
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// The box around every triangle (low and high corners).
    pub fn aabb(&self) -> ([f64; 3], [f64; 3]) {
        (self.nodes[0].lo, self.nodes[0].hi)
    }

    /// The signed distance at `p`: negative inside.
    pub fn distance<T: Float>(&self, p: [T; 3]) -> T {
        self.walk(p, T::from_f64(f64::INFINITY)).0
    }

    /// [`TriMesh::distance`], the walk bounded from its start by a triangle near `p`: the
    /// triangle `hint` names (one of an earlier query, a point near this one, as along a
    /// ray), which is then set to the nearest triangle at `p`. The distance to any triangle
    /// bounds the distance to the nearest, so nodes no nearer than that bound (padded by
    /// [`bound_pad`] for rounding) are skipped from the root down, where the walk from the root
    /// alone would visit them until it first reaches a leaf. Every node and triangle the
    /// walk from the root alone would take as nearest is still visited in the same order, so
    /// the result is the same, bit for bit, whatever the hint (a test holds it to that).
    pub fn distance_from<T: Float>(&self, p: [T; 3], hint: &mut u32) -> T {
        let start = (*hint as usize).min(self.triangles.len() - 1);
        let (d2, _) = nearest(&self.triangles[start], p);
        let (d, t) = self.walk(p, bound(d2, p, T::from_f64(self.reach)));
        *hint = t;
        d
    }

    /// The largest magnitude of a coordinate of its box ([`bound_pad`]).
    pub fn reach(&self) -> f64 {
        self.reach
    }

    /// The walk over the hierarchy from the root, skipping what is no nearer than `best`
    /// (squared): the signed distance and the nearest triangle.
    fn walk<T: Float>(&self, p: [T; 3], mut best: T) -> (T, u32) {
        let f = |x: f64| T::from_f64(x);
        let zero = T::zero();
        let box_d2 = |n: &Node| {
            let mut s = zero;
            for ((&lo, &hi), &x) in n.lo.iter().zip(&n.hi).zip(&p) {
                let d = (f(lo) - x).max(zero).max(x - f(hi));
                s = s + d * d;
            }
            s
        };
        let mut sign_of = (zero, 0u32, 0usize);
        let mut stack = [0u32; STACK];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let n = &self.nodes[stack[top] as usize];
            if box_d2(n) >= best {
                continue;
            }
            if n.count > 0 {
                for t in n.first..n.first + n.count {
                    let (d2, feature) = nearest(&self.triangles[t as usize], p);
                    if d2 < best {
                        best = d2;
                        sign_of = (d2, t, feature);
                    }
                }
                continue;
            }
            // The nearer child on top, so that it is visited first.
            let (l, r) = (n.first, n.first + 1);
            let dl = box_d2(&self.nodes[l as usize]);
            let dr = box_d2(&self.nodes[r as usize]);
            let (near, far, dn, df) = if dr < dl {
                (r, l, dr, dl)
            } else {
                (l, r, dl, dr)
            };
            if df < best {
                stack[top] = far;
                top += 1;
            }
            if dn < best {
                stack[top] = near;
                top += 1;
            }
        }
        let (d2, t, feature) = sign_of;
        let tri = &self.triangles[t as usize];
        let q = point_of(tri, p, feature);
        let normal = if feature == FACE {
            let a = tri[0].map(f);
            let (u, v) = (sub3(tri[1].map(f), a), sub3(tri[2].map(f), a));
            [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ]
        } else {
            tri[3 + feature].map(f)
        };
        let w = sub3(p, q);
        let s = w[0] * normal[0] + w[1] * normal[1] + w[2] * normal[2];
        let d = d2.sqrt();
        (if s < zero { -d } else { d }, t)
    }
}

/// Orders the triangles into a hierarchy: each node's triangles are split at the median of
/// their centres along the longest axis of the centres' box, until at most [`LEAF`] remain.
fn hierarchy(triangles: Vec<Triangle>) -> (Vec<Triangle>, Vec<Node>) {
    let centre = |t: &Triangle| [0, 1, 2].map(|i| (t[0][i] + t[1][i] + t[2][i]) / 3.0);
    let centres: Vec<[f64; 3]> = triangles.iter().map(centre).collect();
    let mut order: Vec<u32> = (0..triangles.len() as u32).collect();
    let empty = Node {
        lo: [0.0; 3],
        hi: [0.0; 3],
        first: 0,
        count: 0,
    };
    let mut nodes = vec![empty];
    let mut work = vec![(0usize, 0usize, triangles.len())];
    while let Some((at, s, e)) = work.pop() {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let (mut clo, mut chi) = (lo, hi);
        for &t in &order[s..e] {
            for v in &triangles[t as usize][..3] {
                for i in 0..3 {
                    lo[i] = lo[i].min(v[i]);
                    hi[i] = hi[i].max(v[i]);
                }
            }
            let c = centres[t as usize];
            for i in 0..3 {
                clo[i] = clo[i].min(c[i]);
                chi[i] = chi[i].max(c[i]);
            }
        }
        nodes[at].lo = lo.map(f32_down);
        nodes[at].hi = hi.map(f32_up);
        if e - s <= LEAF {
            nodes[at].first = s as u32;
            nodes[at].count = (e - s) as u32;
            continue;
        }
        let axis = (0..3)
            .max_by(|&i, &j| (chi[i] - clo[i]).total_cmp(&(chi[j] - clo[j])))
            .unwrap_or(0);
        let mid = (s + e) / 2;
        order[s..e].select_nth_unstable_by(mid - s, |&x, &y| {
            centres[x as usize][axis].total_cmp(&centres[y as usize][axis])
        });
        let left = nodes.len();
        nodes.push(empty);
        nodes.push(empty);
        nodes[at].first = left as u32;
        work.push((left, s, mid));
        work.push((left + 1, mid, e));
    }
    let triangles = order.iter().map(|&t| triangles[t as usize]).collect();
    (triangles, nodes)
}

#[cfg(test)]
mod tests;
