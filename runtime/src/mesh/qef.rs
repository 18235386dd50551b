//! The inner vertex of a patch: the point that best fits the tangent planes at its edge
//! vertices (a quadratic error function, solved by eigen-decomposition with small
//! eigenvalues dropped, relative to the edge vertices' centroid), which lies on the sharp
//! edge or corner the planes meet at.

/// Eigenvalues below this fraction of the largest are dropped (the planes are then treated
/// as parallel along that direction).
const DROP: f64 = 0.05;

/// The least-squares point of the planes through `points` with unit `normals`, nearest the
/// points' centroid, and the rank of the fit (1: one plane; 2: an edge; 3: a corner).
pub fn solve(points: &[[f64; 3]], normals: &[[f64; 3]]) -> ([f64; 3], usize) {
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
    let mut rank = 0;
    for k in 0..3 {
        if largest > 0.0 && values[k] > DROP * largest {
            rank += 1;
            let v = [vectors[0][k], vectors[1][k], vectors[2][k]];
            let c = (0..3).map(|i| v[i] * b[i]).sum::<f64>() / values[k];
            for i in 0..3 {
                x[i] += c * v[i];
            }
        }
    }
    (x, rank)
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
