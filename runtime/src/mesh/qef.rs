//! The inner vertex of a patch: the point that best fits the tangent planes at its edge
//! vertices (a quadratic error function, solved by eigen-decomposition with small
//! eigenvalues dropped, relative to the edge vertices' centroid), which lies on the sharp
//! edge or corner the planes meet at. Where that point is outside the patch's cell (the
//! corner or edge is beyond it), the options in the cell: the points nearest it of the edges
//! of two groups of planes (grouped by their normals) and of each group's plane, and the
//! point clamped into the cell.

/// Eigenvalues below this fraction of the largest are dropped (the planes are then treated
/// as parallel along that direction).
const DROP: f64 = 0.05;

/// The least-squares point of the planes through `points` with unit `normals`, nearest the
/// points' centroid, and the rank of the fit (1: one plane; 2: an edge; 3: a corner).
pub fn solve(points: &[[f64; 3]], normals: &[[f64; 3]]) -> ([f64; 3], usize) {
    let (x, free) = fit(points, normals);
    (x, 3 - free.len())
}

/// The least-squares point of [`solve`] and the directions along which the fit does not
/// decide it (unit vectors: none at a corner, the edge's direction on an edge, two in a plane).
fn fit(points: &[[f64; 3]], normals: &[[f64; 3]]) -> ([f64; 3], Vec<[f64; 3]>) {
    let n = points.len().max(1) as f64;
    let mut m = [0.0; 3];
    for p in points {
        for i in 0..3 {
            m[i] += p[i] / n;
        }
    }
    let mut a = [[0.0; 3]; 3];
    let mut b = [0.0; 3];
    for (p, nv) in points.iter().zip(normals) {
        // Relative to the centroid: the plane is n · (x − m) = n · (p − m).
        let off: f64 = (0..3).map(|i| nv[i] * (p[i] - m[i])).sum();
        for i in 0..3 {
            for j in 0..3 {
                a[i][j] += nv[i] * nv[j];
            }
            b[i] += nv[i] * off;
        }
    }
    let (values, vectors) = eigen(a);
    let largest = values.iter().fold(0.0f64, |x, &y| x.max(y.abs()));
    let mut x = m;
    let mut free = Vec::new();
    for k in 0..3 {
        let v = [vectors[0][k], vectors[1][k], vectors[2][k]];
        if largest > 0.0 && values[k] > DROP * largest {
            let c = (0..3).map(|i| v[i] * b[i]).sum::<f64>() / values[k];
            for i in 0..3 {
                x[i] += c * v[i];
            }
        } else {
            free.push(v);
        }
    }
    (x, free)
}

/// Normals within this cosine of a group's first (20°) belong to its plane.
const SAME_PLANE_COS: f64 = 0.94;

/// Where the inner vertex of a sharp patch may go, in the box `[lo, hi]` (its cell less the
/// margin): the least-squares point of the planes (as [`solve`]), and when that is outside
/// the box, the points it may be replaced by.
#[derive(Debug, Clone, PartialEq)]
pub struct InBox {
    /// The least-squares point, in the box or not.
    pub fit: [f64; 3],
    /// Empty when `fit` is in the box. Otherwise, for an edge (one free direction), the point
    /// of the edge in the box nearest `fit`; then, with the planes grouped by their normals
    /// (within 20° of each other), the point nearest `fit` in the box of each edge of two
    /// groups and of each group's plane; and `fit` clamped into the box. The caller picks one
    /// that is on the surface (a point of an edge of two planes of the surface may lie beyond
    /// the surface's edge or corner; a clamped one off its faces).
    pub options: Vec<[f64; 3]>,
}

/// The least-squares point of the planes in the box `[lo, hi]`, or the options for it
/// ([`InBox`]).
pub fn solve_in_box(
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    lo: [f64; 3],
    hi: [f64; 3],
) -> InBox {
    let (x, free) = fit(points, normals);
    let inside = |y: &[f64; 3]| (0..3).all(|i| y[i] >= lo[i] && y[i] <= hi[i]);
    if inside(&x) {
        return InBox {
            fit: x,
            options: Vec::new(),
        };
    }
    let mut options: Vec<[f64; 3]> = in_box(x, &free, lo, hi).into_iter().collect();
    // Groups of normals: each joins the first group whose first normal is near it.
    let mut group = vec![0usize; normals.len()];
    let mut firsts: Vec<usize> = Vec::new();
    for (k, n) in normals.iter().enumerate() {
        let dot = |m: &[f64; 3]| n[0] * m[0] + n[1] * m[1] + n[2] * m[2];
        group[k] = match firsts
            .iter()
            .position(|&f| dot(&normals[f]) >= SAME_PLANE_COS)
        {
            Some(g) => g,
            None => {
                firsts.push(k);
                firsts.len() - 1
            }
        };
    }
    let g = firsts.len();
    for a in 0..g {
        for b in a..g {
            let (mut p, mut m) = (Vec::new(), Vec::new());
            for k in 0..points.len() {
                if group[k] == a || group[k] == b {
                    p.push(points[k]);
                    m.push(normals[k]);
                }
            }
            let (y, free) = fit(&p, &m);
            // The part of the edge or plane nearest the fit: its point nearest `x`.
            let y = nearest_to(y, &free, x);
            options.extend(in_box(y, &free, lo, hi));
        }
    }
    options.push([0, 1, 2].map(|i| x[i].clamp(lo[i], hi[i])));
    InBox { fit: x, options }
}

/// The point of `y + span(free)` nearest `x`.
fn nearest_to(y: [f64; 3], free: &[[f64; 3]], x: [f64; 3]) -> [f64; 3] {
    let mut z = y;
    for v in free {
        let t: f64 = (0..3).map(|i| v[i] * (x[i] - y[i])).sum();
        for i in 0..3 {
            z[i] += t * v[i];
        }
    }
    z
}

/// The point of `x + span(free)` in the box nearest `x`, if there is one: `x` itself; on a
/// line, the nearest point of its part in the box; on a plane, `x` clamped into the box and
/// moved back onto the plane, if that stays in the box.
fn in_box(x: [f64; 3], free: &[[f64; 3]], lo: [f64; 3], hi: [f64; 3]) -> Option<[f64; 3]> {
    let inside = |y: &[f64; 3]| (0..3).all(|i| y[i] >= lo[i] && y[i] <= hi[i]);
    if inside(&x) {
        return Some(x);
    }
    match free {
        [v] => {
            let (mut s0, mut s1) = (f64::NEG_INFINITY, f64::INFINITY);
            for i in 0..3 {
                if v[i].abs() < 1e-12 {
                    if x[i] < lo[i] || x[i] > hi[i] {
                        return None;
                    }
                    continue;
                }
                let (a, b) = ((lo[i] - x[i]) / v[i], (hi[i] - x[i]) / v[i]);
                s0 = s0.max(a.min(b));
                s1 = s1.min(a.max(b));
            }
            if s0 > s1 {
                return None;
            }
            let s = 0.0f64.clamp(s0, s1);
            let y = [0, 1, 2].map(|i| (x[i] + s * v[i]).clamp(lo[i], hi[i]));
            Some(y)
        }
        [u, v] => {
            let n = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            let c = [0, 1, 2].map(|i| x[i].clamp(lo[i], hi[i]));
            let off: f64 = (0..3).map(|i| n[i] * (c[i] - x[i])).sum();
            let y = [0, 1, 2].map(|i| c[i] - off * n[i]);
            inside(&y).then_some(y)
        }
        _ => None,
    }
}

/// Eigenvalues and eigenvectors (columns) of a symmetric 3×3 matrix, by Jacobi rotations.
pub fn eigen(mut a: [[f64; 3]; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..32 {
        let off = a[0][1].powi(2) + a[0][2].powi(2) + a[1][2].powi(2);
        let diag = a[0][0].powi(2) + a[1][1].powi(2) + a[2][2].powi(2);
        if off <= 1e-30 * diag.max(1e-300) {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A ← Jᵀ A J with J the rotation in the (p, q) plane.
            for row in &mut a {
                let (akp, akq) = (row[p], row[q]);
                row[p] = c * akp - s * akq;
                row[q] = s * akp + c * akq;
            }
            let (rp, rq) = (a[p], a[q]);
            for k in 0..3 {
                a[p][k] = c * rp[k] - s * rq[k];
                a[q][k] = s * rp[k] + c * rq[k];
            }
            for row in &mut v {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    ([a[0][0], a[1][1], a[2][2]], v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_planes_meet_at_their_corner() {
        let points = [
            [0.3, 0.1, 0.2],
            [0.0, 0.3, 0.7],
            [0.9, 0.8, 0.3],
            [0.3, 0.5, 0.6],
        ];
        let normals = [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
        ];
        let (x, rank) = solve(&points, &normals);
        assert_eq!(rank, 3);
        for (xi, want) in x.iter().zip([0.3, 0.3, 0.3]) {
            assert!((xi - want).abs() < 1e-12, "{x:?}");
        }
    }

    #[test]
    fn a_corner_beyond_the_box_gives_a_point_on_an_edge_in_it() {
        // The planes x = 1, y = 1 and z = 1 meet at (1, 1, 1), outside the box
        // [0, 0.9] × [0, 1.5]²; of their edges, only y = z = 1 crosses it.
        let points = [
            [1.0, 0.2, 0.3],
            [1.0, 0.6, 0.2],
            [0.4, 1.0, 0.5],
            [0.2, 1.0, 0.7],
            [0.5, 0.3, 1.0],
            [0.3, 0.7, 1.0],
        ];
        let normals = [
            [1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
        ];
        let r = solve_in_box(&points, &normals, [0.0; 3], [0.9, 1.5, 1.5]);
        assert!(r.fit.iter().all(|v| (v - 1.0).abs() < 1e-12), "{r:?}");
        let on_edge = |y: &&[f64; 3]| (y[1] - 1.0).abs() < 1e-12 && (y[2] - 1.0).abs() < 1e-12;
        let edge = r.options.iter().find(on_edge).expect("the edge y = z = 1");
        assert!(
            (edge[0] - 0.9).abs() < 1e-12,
            "nearest the corner: {edge:?}"
        );
        assert_eq!(r.options.last(), Some(&[0.9, 1.0, 1.0]), "clamped");
        // Inside the box, the corner itself and no options.
        let r = solve_in_box(&points, &normals, [0.0; 3], [1.5; 3]);
        assert!(
            r.fit.iter().all(|v| (v - 1.0).abs() < 1e-12) && r.options.is_empty(),
            "{r:?}"
        );
    }

    #[test]
    fn two_planes_give_the_edge_point_nearest_the_centroid() {
        let s = 0.5f64.sqrt();
        let points = [[0.5, 0.0, 0.1], [0.0, 0.5, 0.9]];
        let normals = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let (x, rank) = solve(&points, &normals);
        assert_eq!(rank, 2);
        assert!(
            (x[0] - 0.5).abs() < 1e-12 && (x[1] - 0.5).abs() < 1e-12,
            "{x:?}"
        );
        assert!((x[2] - 0.5).abs() < 1e-12, "{x:?}");
        let (e, v) = eigen([[2.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 5.0]]);
        let mut sorted = e;
        sorted.sort_by(f64::total_cmp);
        assert!((sorted[0] - 1.0).abs() < 1e-12 && (sorted[1] - 3.0).abs() < 1e-12);
        let k = e
            .iter()
            .position(|x| (x - 3.0).abs() < 1e-9)
            .expect("eigenvalue 3");
        assert!((v[0][k].abs() - s).abs() < 1e-9 && (v[1][k].abs() - s).abs() < 1e-9);
    }
}
