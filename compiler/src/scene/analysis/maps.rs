//! The bottom-up rules of the nodes that map space for their child (rotations, scales,
//! repetitions, mirrors, twists and bends, polar repetitions, wraps, shears, tapers, lofts,
//! screws, sweeps, offsets): the child's facts carried through the map.

use super::derive::merge;
use super::geometry::{angular_half_extent, TAPER_FLOOR};
use super::regions::down;
use super::window::{polar_window, repeated_axes, window};
use super::{
    at_most_bound, bend_stretch, classify, fmt, twist_stretch, unproven, Aabb, Derived, Pass,
    MAX_WINDOW_CELLS, TOLERANCE, WARN_SCALE_RATIO, WARN_STRETCH,
};
use crate::scene::bounds::singular_range;
use crate::scene::ir::{Exactness, V3};
use crate::scene::NodeId;
use crate::scene::Path;

impl Pass<'_> {
    pub(super) fn rotate(&self, matrix: &[V3; 3], child: NodeId) -> Derived {
        let mut d = self.get(child);
        let c = d.symmetric;
        d.bounds = d.bounds.transform(matrix, false);
        // A mirror plane of the child with normal e_j becomes one with normal M·e_j.
        d.symmetric =
            [0, 1, 2].map(|i| (0..3).any(|j| c[j] && (matrix[i][j].abs() - 1.0).abs() < 1e-12));
        d
    }

    /// `f(p / s)·min|s|`: a bound (the point map stretches by at most 1 / min|s|), no steeper
    /// than the child; it underestimates by up to max|s| / min|s|.
    pub(super) fn scale_xyz(&mut self, id: NodeId, s: V3, child: NodeId) -> Derived {
        let mut d = at_most_bound(self.get(child));
        let smin = s.iter().fold(f64::INFINITY, |a, f| a.min(f.abs()));
        let smax = s.iter().fold(0.0f64, |a, f| a.max(f.abs()));
        let ratio = smax / smin;
        d.bounds = d.bounds.scale(s);
        d.growth *= ratio;
        if ratio >= WARN_SCALE_RATIO {
            self.warn_scale(id, s, ratio);
        }
        d
    }

    /// Domain repetition evaluates only the copy in the point's own cell. That is the nearest
    /// copy, and the field keeps its facts (at every level, so offsets above need no margin),
    /// when the child fits in its cell and is symmetric about the cell's centre on every
    /// repeated axis.
    pub(super) fn repeat(
        &mut self,
        id: NodeId,
        period: V3,
        count: Option<V3>,
        child: NodeId,
    ) -> Derived {
        let c = self.get(child);
        let extent = c.bounds;
        let mut d = c;
        let mut strict = true;
        let (mut overlap, mut off_centre) = (None, None);
        for (i, s, n) in repeated_axes(&extent, period, count) {
            let (lo, hi, half) = (extent.min[i], extent.max[i], s * 0.5);
            strict &= lo > -half && hi < half;
            if lo < -half - TOLERANCE || hi > half + TOLERANCE {
                overlap = overlap.or(Some(i));
            } else if !c.symmetric[i] {
                off_centre = off_centre.or(Some(i));
            }
            let reach = s * (n - 1.0) * 0.5;
            (d.bounds.min[i], d.bounds.max[i]) = (c.bounds.min[i] - reach, c.bounds.max[i] + reach);
        }
        if overlap.is_some() || off_centre.is_some() {
            // The neighbouring cells, far enough that the levels ancestors read stay right.
            // Windows nested in windows multiply: their product is bounded too.
            let margin = self.usage.margin[id.0 as usize];
            let below = self.copies[child.0 as usize];
            if let Some(w) = window(&extent, c.symmetric, period, count, margin) {
                if w.cells() * below <= MAX_WINDOW_CELLS {
                    self.windows[id.0 as usize] = Some(w);
                    return at_most_bound(d);
                }
            }
        }
        if let Some(axis) = overlap {
            self.warn_overlap(id, axis, extent.min[axis], extent.max[axis], period[axis]);
            unproven(d, id)
        } else if let Some(axis) = off_centre {
            self.warn_off_centre(id, axis);
            unproven(d, id)
        } else if strict {
            d
        } else {
            at_most_bound(d)
        }
    }

    /// `f(|x|, y, z)`: the child where x ≥ 0, mirrored. A bound whatever the child (the
    /// mirrored copy is never nearer than the child's own part); exact when the child lies on
    /// the kept side or is symmetric already.
    pub(super) fn mirror(&self, axes: [bool; 3], child: NodeId) -> Derived {
        let c = self.get(child);
        let mut d = c;
        for i in (0..3).filter(|&i| axes[i]) {
            if !(c.bounds.min[i] >= 0.0 || c.symmetric[i] || c.bounds.is_empty()) {
                d = at_most_bound(d);
            }
            d.symmetric[i] = true;
            if c.bounds.max[i] < 0.0 {
                d.bounds = Aabb::EMPTY;
            } else if !d.bounds.is_empty() {
                (d.bounds.min[i], d.bounds.max[i]) = (-c.bounds.max[i], c.bounds.max[i]);
            }
        }
        d
    }

    /// Twist (about y, `keep` = 1) and bend (about z, `keep` = 2): the point map stretches by
    /// at most σ(|rate|·ρ), ρ the largest distance from the axis of the child's surface (the
    /// levels its ancestors read, within the region rays reach); so `f/(σ·L)` is a bound.
    pub(super) fn distort(&mut self, id: NodeId, rate: f64, child: NodeId, keep: usize) -> Derived {
        let c = self.get(child);
        let (a, b) = if keep == 1 { (0, 2) } else { (0, 1) };
        let i = id.0 as usize;
        let extent = c.bounds.grow(c.growth * self.usage.margin[i]);
        let region = down(self.scene.graph.node(id), 0.0, self.usage.region[i])
            .first()
            .map_or(Aabb::ALL, |x| x.2);
        let seen = if self.usage.reachable[i] {
            extent.intersect(region)
        } else {
            extent
        };
        let rho = seen.radius(a, b);
        if rate == 0.0 || c.bounds.is_empty() {
            return c;
        }
        let x = rate.abs() * rho;
        let sigma = if keep == 1 {
            twist_stretch(x)
        } else {
            bend_stretch(x)
        };
        let mut d = c;
        let rb = c.bounds.radius(a, b);
        d.bounds = c
            .bounds
            .map(|j, lo, hi| if j == keep { (lo, hi) } else { (-rb, rb) });
        d.symmetric = [false, false, keep == 2 && c.symmetric[2]];
        stretch(&mut d, sigma, id);
        let what = if keep == 1 { "twist" } else { "bend" };
        if !extent.radius(a, b).is_finite() {
            self.warn_unbounded(id, what, sigma, rho);
        } else if sigma >= WARN_STRETCH {
            self.warn_stretch(id, what, rate, rho, sigma);
        }
        d
    }

    /// Polar repetition: the copies in the point's sector and its neighbours, enough of them
    /// that every copy left out is farther than ρ·sin γ ([`polar_window`]); the minimum with
    /// that is a bound, exact wherever the nearest copy is in the window and nearer than it.
    /// The window counts towards [`MAX_WINDOW_CELLS`] like a repetition's.
    pub(super) fn polar(&mut self, id: NodeId, count: u32, child: NodeId) -> Derived {
        let c = self.get(child);
        if count <= 1 || c.bounds.is_empty() {
            return c;
        }
        let margin = self.usage.margin[id.0 as usize];
        let extent = c.bounds.grow(c.growth * margin);
        let w = polar_window(count, angular_half_extent(&extent));
        let mut d = at_most_bound(c);
        let rb = c.bounds.radius(0, 2);
        d.bounds = c
            .bounds
            .map(|j, lo, hi| if j == 1 { (lo, hi) } else { (-rb, rb) });
        d.symmetric = [false, c.symmetric[1], false];
        let cells = w.cells().min(count);
        if cells * self.copies[child.0 as usize] > MAX_WINDOW_CELLS {
            self.warn_polar(id, count, cells);
            return unproven(d, id);
        }
        self.windows[id.0 as usize] = Some(w);
        d
    }

    /// Wrap: the map from space to the child stretches arcs at distance ρ from the axis by
    /// R/ρ; over the child's surface (w ≤ w_max, so ρ ≥ R − w_max) that is at most
    /// σ = R/(R − w_max), and `f/(σ·L)` is a bound. A child reaching the axis (w_max ≥ R)
    /// or longer than the circle (|u| > π·R) folds (W0014).
    pub(super) fn wrap(&mut self, id: NodeId, radius: f64, child: NodeId) -> Derived {
        let c = self.get(child);
        if c.bounds.is_empty() {
            return c;
        }
        let extent = c.bounds.grow(c.growth * self.usage.margin[id.0 as usize]);
        let mut d = c;
        let rho = (radius - c.bounds.min[2])
            .abs()
            .max((radius - c.bounds.max[2]).abs());
        d.bounds = Aabb {
            min: [-rho, c.bounds.min[1], -rho],
            max: [rho, c.bounds.max[1], rho],
        };
        d.symmetric = [true, c.symmetric[1], false];
        let inner = radius - extent.max[2];
        // The shape itself, not its levels that ancestors read: a bar of exactly the circle's
        // length closes, and its offsets (a `round` above) meet at the seam as its faces do.
        let half = std::f64::consts::PI * radius * (1.0 + 1e-12) + TOLERANCE;
        let long = c.bounds.min[0] < -half || c.bounds.max[0] > half;
        if !(inner > 0.0) || long {
            let how = if long {
                format!(
                    "the shape spans {} … {} on x, more than the circle's length 2π·{} = {}",
                    fmt(c.bounds.min[0]),
                    fmt(c.bounds.max[0]),
                    fmt(radius),
                    fmt(2.0 * std::f64::consts::PI * radius)
                )
            } else {
                format!(
                    "the shape reaches z = {}, across the wrap's axis at z = {}",
                    fmt(extent.max[2]),
                    fmt(radius)
                )
            };
            self.warn_fold(
                id,
                "wrap",
                how,
                "wrap a shape that lies within −π·radius … π·radius on x and below z = radius",
            );
            return unproven(d, id);
        }
        let sigma = (radius / inner).max(1.0);
        stretch(&mut d, sigma, id);
        d
    }

    /// Shear S: the lowering multiplies f(S⁻¹p) by σmin(S), which makes it a bound with the
    /// child's L (the map S⁻¹ stretches by at most 1/σmin); it underestimates by up to
    /// σmax/σmin, reported like a scale's ratio (W0007).
    pub(super) fn shear(&mut self, id: NodeId, matrix: &[V3; 3], child: NodeId) -> Derived {
        let c = self.get(child);
        let mut d = at_most_bound(c);
        let (smin, smax) = singular_range(matrix);
        d.bounds = c.bounds.transform(matrix, false);
        d.symmetric = [false; 3];
        let ratio = smax / smin;
        d.growth *= ratio;
        if ratio >= WARN_SCALE_RATIO {
            self.warn_scale(id, [smin, smax, smax], ratio);
        }
        d
    }

    /// Taper: f(q)·s with q = (x/s, y, z/s), s = 1 + rate·y. Near the surface the gradient is
    /// s·Jᵀ∇f, and s·J is diag(1, s, 1) plus a column of norm |rate|·ρ_q (ρ_q the child's
    /// distance from the y axis), so σ = max(1, s_max) + |rate|·ρ_q; `f/(σ·L)` is a bound
    /// there. Where s ≤ 0 over the child's heights the taper folds (W0014).
    pub(super) fn taper(&mut self, id: NodeId, rate: f64, child: NodeId) -> Derived {
        let c = self.get(child);
        if rate == 0.0 || c.bounds.is_empty() {
            return c;
        }
        let extent = c.bounds.grow(c.growth * self.usage.margin[id.0 as usize]);
        let (y0, y1) = (extent.min[1], extent.max[1]);
        let s_lo = (1.0 + rate * y0).min(1.0 + rate * y1);
        let s_hi = (1.0 + rate * y0).max(1.0 + rate * y1);
        let mut d = c;
        d.bounds = c.bounds.map(|j, lo, hi| {
            if j == 1 {
                (lo, hi)
            } else {
                (lo * s_hi.max(0.0), hi * s_hi.max(0.0))
            }
        });
        d.symmetric = [c.symmetric[0], false, c.symmetric[2]];
        if !(s_lo > TAPER_FLOOR) {
            self.warn_fold(
                id,
                "taper",
                format!(
                    "its scale 1 + rate·y falls to {} over the shape's heights {} … {}",
                    fmt(s_lo),
                    fmt(y0),
                    fmt(y1)
                ),
                "lower the rate so that 1 + rate·y stays above 0 over the shape",
            );
            return unproven(d, id);
        }
        let rho = extent.radius(0, 2);
        let sigma = s_hi.max(1.0) + rate.abs() * rho;
        if !sigma.is_finite() {
            return unproven(d, id);
        }
        d.growth *= sigma;
        d.facts.lipschitz *= sigma;
        d.gradient *= sigma;
        d.facts.exactness = classify(d.facts.lipschitz, d.proven);
        if d.proven {
            d.cause = Some(id);
        }
        if sigma >= WARN_STRETCH {
            self.warn_stretch(id, "taper", rate, rho, sigma);
        }
        d
    }

    /// Round (`f − r`) and shell (`|f| − t`): the surface is a level set of the child, so only
    /// the child's Lipschitz constant makes the result a bound.
    /// A loft: at height z the profile a + t·clamp(b - a, ±s), extruded. Across the
    /// profiles' plane the gradient is a convex combination of theirs (or a's alone where
    /// the clamp holds); along z it is the clamped difference over the height, at most
    /// s / (2h). Outside |z| ≤ h the extrusion's two terms are orthogonal. So L is
    /// max(1, √(G² + (s / 2h)²)), G the profiles' larger constant; the same profile at both
    /// ends is its extrusion (docs/analysis.md, "Loft").
    pub(super) fn loft(
        &mut self,
        id: NodeId,
        h: f64,
        spread: f64,
        bottom: NodeId,
        top: NodeId,
    ) -> Derived {
        let (da, db) = (self.get(bottom), self.get(top));
        let mut d = merge(&[da, db]);
        if bottom == top {
            d = da;
        }
        d.bounds = da.bounds.union(db.bounds);
        d.bounds.min[2] = -h;
        d.bounds.max[2] = h;
        d.symmetric = [d.symmetric[0], d.symmetric[1], bottom == top];
        if !d.gradient.is_finite() {
            return if d.proven { unproven(d, id) } else { d };
        }
        let slope = if bottom == top {
            0.0
        } else {
            spread / (2.0 * h)
        };
        let g = d.gradient.hypot(slope).max(1.0);
        d.gradient = g;
        d.facts.lipschitz = d.facts.lipschitz.max(g);
        if bottom != top {
            d.facts.exactness = classify(d.facts.lipschitz, d.proven);
            if d.proven && d.cause.is_none() {
                d.cause = Some(id);
            }
        }
        d
    }

    /// A screw: the profile read at (r, w), r the distance from the y axis and w the height
    /// less pitch·φ/2π folded into one pitch, the nearer of its two nearest turns. Moving
    /// by s round the axis at radius r moves w by pitch·s / (2π·r), so the map stretches by
    /// √(1 + (pitch / 2πr)²); the field below r = inner / 2 is floor·max(inner - r, r),
    /// never above the profile's there, so the profile's is read only at r ≥ inner / 2.
    /// The nearer turn's minimum is continuous, and the distance to the profile's turns, only
    /// for an exact profile (docs/analysis.md, "Screw").
    pub(super) fn screw(
        &mut self,
        id: NodeId,
        pitch: f64,
        half_height: f64,
        inner: f64,
        floor: f64,
        child: NodeId,
    ) -> Derived {
        let c = self.get(child);
        let r = c.bounds.max[0].max(0.0);
        let bounds = Aabb {
            min: [-r, -half_height, -r],
            max: [r, half_height, r],
        };
        let d = carried(c, bounds, 1.0 / floor);
        if c.facts.exactness != Exactness::Exact {
            return unproven(d, id);
        }
        let k = pitch / std::f64::consts::TAU;
        let stretch = (k / (0.5 * inner)).hypot(1.0);
        of_gradient(d, (c.gradient * stretch).max(1.0), id)
    }

    /// A sweep (docs/analysis.md, "Sweep"): a disc about the origin swept is the distance to
    /// the path less its radius, exact; another profile's field is read at coordinates that
    /// change as the point moves across the path and not along it (the frame does not turn
    /// about the path), but for the twist that closes a closed path: L is the profile's times
    /// √(1 + (twist·extent)²), a bound within `inner` of the path and the tube's distance
    /// beyond. Where the profile reaches past half the path's reach (`inner` below `extent`;
    /// past the whole of it, the sweep `folds`) nothing is proven.
    pub(super) fn sweep(
        &mut self,
        id: NodeId,
        path: &Path,
        folds: bool,
        extent: f64,
        child: NodeId,
    ) -> Derived {
        let c = self.get(child);
        let (lo, hi) = path.aabb();
        let bounds = Aabb {
            min: lo.map(|x| x - extent),
            max: hi.map(|x| x + extent),
        };
        let mut d = carried(c, bounds, 1.0);
        if crate::scene::path::round_profile(&self.scene.graph, child) {
            d.gradient = 1.0;
            d.facts.lipschitz = 1.0;
            return d;
        }
        if !c.proven || folds || c.facts.exactness == Exactness::Approximate {
            return unproven(d, id);
        }
        of_gradient(
            d,
            (c.gradient * (path.twist * extent).hypot(1.0)).max(1.0),
            id,
        )
    }

    pub(super) fn offset(&self, id: NodeId, child: NodeId, by: f64) -> Derived {
        let c = self.get(child);
        let mut d = at_most_bound(c);
        // An inset (a 2D `offset` below 0) lies within the child's box.
        d.bounds = c.bounds.grow(c.growth * by.max(0.0));
        if c.gradient.is_finite() {
            d.facts.lipschitz = c.facts.lipschitz.max(c.gradient);
            d.facts.exactness = classify(d.facts.lipschitz, d.proven);
            d
        } else if c.proven {
            unproven(d, id)
        } else {
            d
        }
    }
}

/// The child's facts `c` carried round an axis or along a path (a screw, a sweep): within
/// `bounds`, symmetric across no plane, growing at least `growth`-fold.
fn carried(c: Derived, bounds: Aabb, growth: f64) -> Derived {
    Derived {
        bounds,
        symmetric: [false; 3],
        growth: c.growth.max(growth),
        ..c
    }
}

/// `d` with the gradient bound and L `g`, classified, the node `id` its cause.
fn of_gradient(mut d: Derived, g: f64, id: NodeId) -> Derived {
    d.gradient = g;
    d.facts.lipschitz = g;
    d.facts.exactness = classify(g, d.proven);
    d.cause = Some(id);
    d
}

/// The child's facts `d` under a map `id` that stretches distances up to `sigma`-fold (≥ 1):
/// its growth, L and gradient times `sigma`, the node the cause of an L above the child's.
fn stretch(d: &mut Derived, sigma: f64, id: NodeId) {
    d.growth *= sigma;
    d.facts.lipschitz *= sigma;
    d.gradient *= sigma;
    d.facts.exactness = classify(d.facts.lipschitz, d.proven);
    if sigma > 1.0 && d.proven {
        d.cause = Some(id);
    }
}
