//! The geometry the analysis's rules share: a 3×3 matrix's inverse, a taper's smallest
//! factor, and the angle about y a box lies within.

use super::Aabb;
use crate::scene::ir::V3;

/// The identity matrix.
pub(super) const IDENTITY: [V3; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// The inverse of a 3×3 matrix (rows), or `None` when it is singular.
pub(crate) fn invert(m: &[V3; 3]) -> Option<[V3; 3]> {
    let c = |i: usize, j: usize| {
        let (a, b) = ((i + 1) % 3, (i + 2) % 3);
        let (x, y) = ((j + 1) % 3, (j + 2) % 3);
        m[a][x] * m[b][y] - m[a][y] * m[b][x]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    if det.abs() < 1e-12 || !det.is_finite() {
        return None;
    }
    // The inverse is the transposed cofactor matrix over the determinant.
    Some([0, 1, 2].map(|i| [0, 1, 2].map(|j| c(j, i) / det)))
}

/// The smallest factor 1 + rate·y a taper divides by over heights y0 … y1: the factor there,
/// but never below [`TAPER_FLOOR`] (where the factor falls below it the lowering clamps it).
pub(super) fn taper_floor(rate: f64, y0: f64, y1: f64) -> f64 {
    let s = (1.0 + rate * y0).min(1.0 + rate * y1);
    if s.is_finite() {
        s.max(TAPER_FLOOR)
    } else {
        TAPER_FLOOR
    }
}

/// The smallest scale factor of a taper: below it (the cross-section shrunk to a point and
/// beyond, where the taper folds) the factor is clamped.
pub(crate) const TAPER_FLOOR: f64 = 1e-3;

/// The angle ±α about y, in the sense of `rotate_y`, within which a box lies; π when it
/// reaches the y axis or beyond (on the side x ≤ 0).
pub(super) fn angular_half_extent(b: &Aabb) -> f64 {
    if b.is_empty() || !(b.min[0] > 0.0) || !b.is_bounded() {
        return std::f64::consts::PI;
    }
    let mut alpha = 0.0f64;
    for x in [b.min[0], b.max[0]] {
        for z in [b.min[2], b.max[2]] {
            alpha = alpha.max(z.atan2(x).abs());
        }
    }
    alpha
}
