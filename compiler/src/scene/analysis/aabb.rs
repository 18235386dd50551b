//! Axis-aligned boxes with infinite sides: the extents the analysis reasons about.

use crate::scene::V3;

/// An axis-aligned box; infinite coordinates for unbounded shapes, `min > max` when empty.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: V3,
    /// Upper corner.
    pub max: V3,
}

impl Aabb {
    /// Contains nothing.
    pub const EMPTY: Aabb = Aabb {
        min: [f64::INFINITY; 3],
        max: [f64::NEG_INFINITY; 3],
    };

    /// Contains everything.
    pub const ALL: Aabb = Aabb {
        min: [f64::NEG_INFINITY; 3],
        max: [f64::INFINITY; 3],
    };

    /// The box `[-half, half]`.
    pub fn centred(half: V3) -> Aabb {
        Aabb {
            min: half.map(|h| -h),
            max: half,
        }
    }

    /// True when the box contains no point.
    pub fn is_empty(&self) -> bool {
        (0..3).any(|i| self.min[i] > self.max[i])
    }

    /// True when the box is finite on every axis (an empty box is bounded).
    pub fn is_bounded(&self) -> bool {
        self.is_empty() || (0..3).all(|i| self.min[i].is_finite() && self.max[i].is_finite())
    }

    pub(super) fn map(self, f: impl Fn(usize, f64, f64) -> (f64, f64)) -> Aabb {
        if self.is_empty() {
            return self;
        }
        let mut out = self;
        for i in 0..3 {
            (out.min[i], out.max[i]) = f(i, self.min[i], self.max[i]);
        }
        out
    }

    /// The smallest box containing both.
    pub fn union(self, o: Aabb) -> Aabb {
        if self.is_empty() {
            return o;
        }
        o.map(|i, lo, hi| (lo.min(self.min[i]), hi.max(self.max[i])))
    }

    /// The common part.
    pub fn intersect(self, o: Aabb) -> Aabb {
        if self.is_empty() || o.is_empty() {
            return Aabb::EMPTY;
        }
        let b = self.map(|i, lo, hi| (lo.max(o.min[i]), hi.min(o.max[i])));
        if b.is_empty() {
            Aabb::EMPTY
        } else {
            b
        }
    }

    /// Grown by `r ≥ 0` on every side.
    pub fn grow(self, r: f64) -> Aabb {
        if r <= 0.0 || r.is_nan() {
            return self;
        }
        self.map(|_, lo, hi| (lo - r, hi + r))
    }

    pub(super) fn translate(self, v: V3) -> Aabb {
        self.map(|i, lo, hi| (lo + v[i], hi + v[i]))
    }

    /// Scaled per axis by positive factors.
    pub(super) fn scale(self, s: V3) -> Aabb {
        self.map(|i, lo, hi| (lo * s[i], hi * s[i]))
    }

    /// The box around `M·b` (`transpose`: `Mᵀ·b`), `M` given by rows. Entries below 1e-12
    /// count as 0, so that an infinite side stays on its own axis.
    pub(super) fn transform(self, m: &[V3; 3], transpose: bool) -> Aabb {
        if self.is_empty() {
            return self;
        }
        let at = |i: usize, j: usize| if transpose { m[j][i] } else { m[i][j] };
        let mut out = Aabb::EMPTY;
        for i in 0..3 {
            let (mut lo, mut hi) = (0.0, 0.0);
            for j in 0..3 {
                let a = at(i, j);
                if a.abs() < 1e-12 {
                    continue;
                }
                let (p, q) = (a * self.min[j], a * self.max[j]);
                lo += p.min(q);
                hi += p.max(q);
            }
            (out.min[i], out.max[i]) = (lo, hi);
        }
        out
    }

    /// The largest distance from the axis normal to the plane of axes `a` and `b`.
    pub fn radius(&self, a: usize, b: usize) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        let far = |i: usize| self.min[i].abs().max(self.max[i].abs());
        far(a).hypot(far(b))
    }

    /// Half of the smallest side (infinite for an empty or unbounded box).
    pub(super) fn half_min(&self) -> f64 {
        if self.is_empty() {
            return f64::INFINITY;
        }
        (0..3)
            .map(|i| (self.max[i] - self.min[i]) * 0.5)
            .fold(f64::INFINITY, f64::min)
    }
}
