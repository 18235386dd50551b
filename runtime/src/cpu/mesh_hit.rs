//! A ray's nearest crossing of a triangle mesh's triangles, for analytic ray tracing
//! (`analytic.rs`): the mesh's hierarchy walked nearer box first, each box entered before the
//! best crossing so far (slab test), each triangle by Möller and Trumbore's test ("Fast,
//! minimum storage ray/triangle intersection", Journal of Graphics Tools, 1997), as the WGSL
//! kernel's `mesh_interval` walks it (compiler/src/back/wgsl/mesh.rs).

use super::vec::V3;
use sdfc_compiler::{Float, TriMesh};

fn cross<T: Float>(a: V3<T>, b: V3<T>) -> V3<T> {
    V3::new(
        a.y * b.z - a.z * b.y,
        a.z * b.x - a.x * b.z,
        a.x * b.y - a.y * b.x,
    )
}

/// Where `o + t·d` enters the box `lo`–`hi` (t >= 0), given `inv` = 1/d, or `None` when it
/// misses it.
fn enter<T: Float>(o: V3<T>, inv: V3<T>, lo: [f64; 3], hi: [f64; 3]) -> Option<T> {
    let (o, inv) = ([o.x, o.y, o.z], [inv.x, inv.y, inv.z]);
    let (mut near, mut far) = (T::zero(), T::from_f64(f64::INFINITY));
    for k in 0..3 {
        let t1 = (T::from_f64(lo[k]) - o[k]) * inv[k];
        let t2 = (T::from_f64(hi[k]) - o[k]) * inv[k];
        near = near.max(t1.min(t2));
        far = far.min(t1.max(t2));
    }
    (near <= far).then_some(near)
}

/// Where `o + t·d` crosses the triangle, 0 < t < `limit` (Möller and Trumbore), with the
/// triangle's normal `(b − a) × (c − a)`.
fn triangle<T: Float>(t: &[[f64; 3]; 9], o: V3<T>, d: V3<T>, limit: T) -> Option<(T, V3<T>)> {
    let edge = T::from_f64(TriMesh::EDGE);
    let a = V3::from_f64(t[0]);
    let (e1, e2) = (V3::from_f64(t[1]) - a, V3::from_f64(t[2]) - a);
    let q = cross(d, e2);
    let det = e1.dot(q);
    if det == T::zero() {
        return None;
    }
    let f = T::one() / det;
    let s = o - a;
    let u = f * s.dot(q);
    let r = cross(s, e1);
    let v = f * d.dot(r);
    let h = f * e2.dot(r);
    let inside = u >= -edge && v >= -edge && u + v <= T::one() + edge;
    (inside && h > T::zero() && h < limit).then(|| (h, cross(e1, e2)))
}

/// The nearest crossing of `o + t·d` with the triangles of `mesh` for 0 < t < `limit`: its t
/// and the triangle's outward normal (not of unit length).
pub(super) fn crossing<T: Float>(
    mesh: &TriMesh,
    o: V3<T>,
    d: V3<T>,
    limit: T,
) -> Option<(T, V3<T>)> {
    let tiny = T::from_f64(1e-30);
    // A zero component of d as a tiny one, so that no slab computes 0 · inf.
    let safe = |x: T| if x.abs() < tiny { tiny } else { x };
    let inv = V3::new(
        T::one() / safe(d.x),
        T::one() / safe(d.y),
        T::one() / safe(d.z),
    );
    let (nodes, tris) = (mesh.nodes(), mesh.triangles());
    let mut best = limit;
    let mut hit = None;
    let mut stack = vec![0u32];
    let entry = |i: u32| {
        let n = &nodes[i as usize];
        enter(o, inv, n.lo, n.hi)
    };
    while let Some(i) = stack.pop() {
        let n = &nodes[i as usize];
        if !entry(i).is_some_and(|t| t < best) {
            continue;
        }
        if n.count > 0 {
            for k in n.first..n.first + n.count {
                if let Some((h, normal)) = triangle(&tris[k as usize], o, d, best) {
                    best = h;
                    hit = Some(normal);
                }
            }
            continue;
        }
        let (l, r) = (n.first, n.first + 1);
        let big = T::from_f64(f64::INFINITY);
        let (tl, tr) = (entry(l).unwrap_or(big), entry(r).unwrap_or(big));
        let (near, far) = if tr < tl { (r, l) } else { (l, r) };
        if tl.max(tr) < best {
            stack.push(far);
        }
        if tl.min(tr) < best {
            stack.push(near);
        }
    }
    hit.map(|n| (best, n))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed torus of radii 1 and 0.4 in the xz plane, `n` × `m` quads split in two.
    fn torus(n: usize, m: usize) -> TriMesh {
        let mut v = Vec::new();
        for i in 0..n {
            let u = i as f64 / n as f64 * std::f64::consts::TAU;
            for j in 0..m {
                let w = j as f64 / m as f64 * std::f64::consts::TAU;
                let r = 1.0 + 0.4 * w.cos();
                v.push([r * u.cos(), 0.4 * w.sin(), r * u.sin()]);
            }
        }
        let at = |i: usize, j: usize| ((i % n) * m + j % m) as u32;
        let mut f = Vec::new();
        for i in 0..n {
            for j in 0..m {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                f.push([a, c, b]);
                f.push([a, d, c]);
            }
        }
        TriMesh::new("torus", &v, &f, 1.0).expect("a mesh")
    }

    /// The walk through the hierarchy finds the crossing that testing every triangle finds,
    /// from outside, inside the tube and within a short limit; the normal points out of the
    /// side the ray meets.
    #[test]
    fn the_hierarchy_finds_the_nearest_crossing() {
        let mesh = torus(48, 24);
        let mut rng = sdfc_compiler::Rng::new(52);
        let mut hits = 0;
        for k in 0..3000 {
            let o = rng.point(if k % 3 == 0 { 1.2 } else { 3.0 });
            let d = rng.point(1.0);
            let (o, d) = (V3::new(o[0], o[1], o[2]), V3::new(d[0], d[1], d[2]));
            let limit = if k % 5 == 0 { 0.5 } else { 100.0 };
            let brute = mesh
                .triangles()
                .iter()
                .filter_map(|t| triangle(t, o, d, limit))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            let walked = crossing(&mesh, o, d, limit);
            assert_eq!(walked.map(|h| h.0), brute.map(|h| h.0), "{o:?} {d:?}");
            if let Some((t, n)) = walked {
                hits += 1;
                // Outside the solid just before the crossing exactly when the ray enters.
                let before = o + d * (t * 0.999);
                let outside = mesh.distance([before.x, before.y, before.z]) > 0.0;
                assert_eq!(d.dot(n) < 0.0, outside, "{o:?} {d:?}");
            }
        }
        assert!(hits > 300, "{hits} hits");
    }
}
