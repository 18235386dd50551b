//! One triangle of a mesh: its nearest point to `p` and the feature that holds it (the face,
//! an edge or a vertex), and the bound a walk of the hierarchy starts with.

use super::Triangle;
use crate::program::Float;

/// What [`TriMesh::distance_from`] starts its walk with, given `d2`, the squared distance
/// from `p` to one triangle: `d2` raised by [`bound_pad`] over its root, so that no node or
/// triangle nearer than the nearest triangle is skipped for rounding (a box's distance and
/// a triangle's in it differ by a few ulps of the coordinates); infinity where `d2` or `p` is
/// not finite, as the walk from the root alone starts.
pub(super) fn bound<T: Float>(d2: T, p: [T; 3], reach: T) -> T {
    let d = d2.sqrt() + bound_pad(p, reach, d2.sqrt());
    let b = d * d;
    let inf = T::from_f64(f64::INFINITY);
    if b < inf {
        b
    } else {
        inf
    }
}

/// The margin added to a triangle's distance `d` from `p` before it bounds a walk: 10⁻⁵ of
/// the sizes in play (the mesh's reach from the origin, `p`'s and `d`), some hundred f32
/// ulps of them, far above the rounding of a box's or a triangle's distance.
pub fn bound_pad<T: Float>(p: [T; 3], reach: T, d: T) -> T {
    let m = p[0].abs().max(p[1].abs()).max(p[2].abs());
    T::from_f64(1e-5) * (reach + m + d)
}

/// The feature of the face itself (the corners are 0–2, the edges ab, bc, ca 3–5).
pub const FACE: usize = 6;

pub(super) fn sub3<T: Float>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot3<T: Float>(a: [T; 3], b: [T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The squared distance from `p` to the triangle and the feature its nearest point lies on
/// (Ericson's regions: corners 0–2, edges ab, bc, ca 3–5, the face [`FACE`]).
pub fn nearest<T: Float>(tri: &Triangle, p: [T; 3]) -> (T, usize) {
    let feature = feature_of(tri, p);
    let q = point_of(tri, p, feature);
    let w = sub3(p, q);
    (dot3(w, w), feature)
}

/// The feature of the triangle nearest to `p` (Ericson 2005, §5.1.5).
fn feature_of<T: Float>(tri: &Triangle, p: [T; 3]) -> usize {
    let zero = T::zero();
    let [a, b, c] = [0, 1, 2].map(|k| tri[k].map(T::from_f64));
    let (ab, ac) = (sub3(b, a), sub3(c, a));
    let ap = sub3(p, a);
    let (d1, d2) = (dot3(ab, ap), dot3(ac, ap));
    if d1 <= zero && d2 <= zero {
        return 0;
    }
    let bp = sub3(p, b);
    let (d3, d4) = (dot3(ab, bp), dot3(ac, bp));
    if d3 >= zero && d4 <= d3 {
        return 1;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= zero && d1 >= zero && d3 <= zero {
        return 3;
    }
    let cp = sub3(p, c);
    let (d5, d6) = (dot3(ab, cp), dot3(ac, cp));
    if d6 >= zero && d5 <= d6 {
        return 2;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= zero && d2 >= zero && d6 <= zero {
        return 5;
    }
    let va = d3 * d6 - d5 * d4;
    if va <= zero && d4 - d3 >= zero && d5 - d6 >= zero {
        return 4;
    }
    FACE
}

/// The nearest point to `p` on `feature` of the triangle: the corner, the nearest point of
/// the edge's segment, or of the face's plane.
pub(super) fn point_of<T: Float>(tri: &Triangle, p: [T; 3], feature: usize) -> [T; 3] {
    let [a, b, c] = [0, 1, 2].map(|k| tri[k].map(T::from_f64));
    let on_segment = |s: [T; 3], e: [T; 3]| {
        let d = sub3(e, s);
        let t = (dot3(sub3(p, s), d) / dot3(d, d)).clamp(T::zero(), T::one());
        [s[0] + d[0] * t, s[1] + d[1] * t, s[2] + d[2] * t]
    };
    match feature {
        0 => a,
        1 => b,
        2 => c,
        3 => on_segment(a, b),
        4 => on_segment(b, c),
        5 => on_segment(c, a),
        _ => {
            let n = {
                let (u, v) = (sub3(b, a), sub3(c, a));
                [
                    u[1] * v[2] - u[2] * v[1],
                    u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0],
                ]
            };
            let t = dot3(sub3(p, a), n) / dot3(n, n);
            [p[0] - n[0] * t, p[1] - n[1] * t, p[2] - n[2] * t]
        }
    }
}
