//! The bottom-up pass of the analysis: each node's [`Derived`] facts from its children's,
//! for the primitives, the combinations, blends and features (the maps of space in
//! `maps.rs`).

use super::{
    at_most_bound, blend_reach, blend_steepness, classify, exact, feature_steepness,
    profile_bounds, unproven, Aabb, Derived, Pass,
};
use crate::prim::{Args, Field as PrimField, PrimRef};
use crate::scene::field::FieldFn;
use crate::scene::ir::{Combine, Exactness, Feature, Node, Smooth, V3};
use crate::scene::NodeId;

impl Pass<'_> {
    pub(super) fn get(&self, id: NodeId) -> Derived {
        self.nodes[id.0 as usize]
    }

    pub(super) fn derive(&mut self, id: NodeId) -> Derived {
        let node = self.scene.graph.node(id);
        match node {
            Node::Sphere { radius } => exact(Aabb::centred([*radius; 3]), [true; 3]),
            Node::Box { half } | Node::RoundBox { half, .. } => {
                exact(Aabb::centred(*half), [true; 3])
            }
            Node::Plane { normal, height } => {
                exact(plane_bounds(*normal, *height), normal.map(|n| n == 0.0))
            }
            Node::Torus { major, minor } => exact(
                Aabb::centred([major + minor, *minor, major + minor]),
                [true; 3],
            ),
            Node::Cylinder {
                radius,
                half_height,
            } => exact(Aabb::centred([*radius, *half_height, *radius]), [true; 3]),
            Node::Capsule {
                radius,
                half_height,
            } => exact(
                Aabb::centred([*radius, half_height + radius, *radius]),
                [true; 3],
            ),
            Node::Cone {
                radius,
                half_height,
            } => exact(
                Aabb::centred([*radius, *half_height, *radius]),
                [true, false, true],
            ),
            Node::Ellipsoid { radii } => ellipsoid(*radii),
            Node::Rect { half } => exact(profile_bounds(*half), [true; 3]),
            Node::Prim { prim, args } => table_prim(id, prim, args),
            Node::Mesh { mesh } => {
                let (min, max) = mesh.0.aabb();
                exact(Aabb { min, max }, [false; 3])
            }
            Node::Bezier {
                a,
                control,
                b,
                radius,
            } => bezier(*a, *control, *b, *radius),
            Node::Polygon { points } => polygon(points),
            Node::Text { outline, .. } => {
                let (lo, hi) = outline.bounds();
                plane_profile(lo, hi)
            }
            Node::Extrude {
                half_height,
                round,
                child,
            } => self.extrude(*half_height, *round, *child),
            Node::Revolve { offset, child } => self.revolve(*offset, *child),
            Node::Loft {
                half_height,
                spread,
                bottom,
                top,
            } => self.loft(id, *half_height, *spread, *bottom, *top),
            Node::Screw {
                pitch,
                half_height,
                inner,
                floor,
                child,
            } => self.screw(id, *pitch, *half_height, *inner, *floor, *child),
            Node::Sweep {
                path,
                inner,
                extent,
                folds,
                child,
            } => self.sweep(id, &path.0, *folds || inner < extent, *extent, *child),
            Node::Feature { op, a, b } => self.feature(id, *op, *a, *b),
            Node::Combine { op, children } => self.combine(*op, children),
            Node::SmoothCombine {
                op,
                k,
                variant,
                a,
                b,
            } => self.smooth(id, *op, *k, *variant, *a, *b),
            Node::Morph { a, b, .. } => self.morph(id, *a, *b),
            Node::Translate { offset, child } => self.translate(*offset, *child),
            Node::Rotate { matrix, child } => self.rotate(matrix, *child),
            Node::Scale { factor, child } => {
                let mut d = self.get(*child);
                d.bounds = d.bounds.scale([*factor; 3]);
                d
            }
            Node::ScaleXyz { factors, child } => self.scale_xyz(id, *factors, *child),
            Node::Repeat {
                period,
                count,
                child,
            } => self.repeat(id, *period, *count, *child),
            Node::Mirror { axes, child } => self.mirror(*axes, *child),
            Node::RepeatPolar { count, child, .. } => self.polar(id, *count, *child),
            Node::Wrap { radius, child } => self.wrap(id, *radius, *child),
            Node::Shear { matrix, child } => self.shear(id, matrix, *child),
            Node::Taper { rate, child } => self.taper(id, *rate, *child),
            Node::Twist { rate, child } => self.distort(id, *rate, *child, 1),
            Node::Bend { rate, child } => self.distort(id, *rate, *child, 2),
            Node::Round { radius, child } => self.offset(id, *child, *radius),
            Node::Shell { half, child } => self.offset(id, *child, *half),
            Node::Elongate { half, child } => {
                let mut d = at_most_bound(self.get(*child));
                d.bounds = d.bounds.map(|i, lo, hi| (lo - half[i], hi + half[i]));
                d
            }
            Node::Paint { child, .. } => self.get(*child),
            Node::Field { f, lipschitz, .. } => self.field(id, f, *lipschitz),
        }
    }

    /// A profile extruded along z: the profile's facts, at most a bound when its edges are
    /// rounded, at least as steep as 1, its box cut at the half-height.
    fn extrude(&self, half_height: f64, round: f64, child: NodeId) -> Derived {
        let mut d = self.get(child);
        if round > 0.0 {
            // The profile shrunk by `round` is a bound outside its solid.
            d = at_most_bound(d);
        }
        // |(a, b)| of a field a of the plane and b = |z| - h: as steep as the steeper.
        d.facts.lipschitz = d.facts.lipschitz.max(1.0);
        d.gradient = d.gradient.max(1.0);
        d.bounds.min[2] = -half_height;
        d.bounds.max[2] = half_height;
        d.symmetric[2] = true;
        d
    }

    /// A profile revolved about the y axis at `offset`: a bound where a part of the profile
    /// is never read; the box of the swept profile, symmetric in x and z.
    fn revolve(&self, offset: f64, child: NodeId) -> Derived {
        let mut d = self.get(child);
        let c = d.bounds;
        // The profile is read at x = r - offset for r ≥ 0; a part of it at smaller x
        // is never read, but may be nearer than the part that is: then a bound.
        let read_only = c.min[0] >= -offset || (d.symmetric[0] && offset == 0.0);
        if !read_only {
            d = at_most_bound(d);
        }
        let r = (c.max[0] + offset).max(0.0);
        d.bounds = if c.max[0] + offset < 0.0 || c.is_empty() {
            Aabb::EMPTY
        } else {
            Aabb {
                min: [-r, c.min[1], -r],
                max: [r, c.max[1], r],
            }
        };
        d.symmetric = [true, d.symmetric[1], true];
        d
    }

    /// A morph between `a` and `b`: approximate, as steep as the steeper operand, its solid
    /// within the union of theirs.
    fn morph(&self, id: NodeId, a: NodeId, b: NodeId) -> Derived {
        // A convex combination of L-Lipschitz fields is L-Lipschitz, so f / L is a
        // bound of its own zero set; the solid lies where either operand's does.
        let (da, db) = (self.get(a), self.get(b));
        let mut d = merge(&[da, db]);
        d.facts.exactness = Exactness::Approximate;
        if d.gradient.is_finite() {
            d.facts.lipschitz = d.facts.lipschitz.max(d.gradient);
            d.facts.exactness = classify(d.facts.lipschitz, d.proven);
        } else if d.proven {
            d = unproven(d, id);
        }
        d.bounds = da.bounds.union(db.bounds);
        d
    }

    /// A translation: the child's facts, its box moved, symmetric only across the planes
    /// the offset keeps.
    fn translate(&self, offset: V3, child: NodeId) -> Derived {
        let mut d = self.get(child);
        d.bounds = d.bounds.translate(offset);
        d.symmetric = [0, 1, 2].map(|i| d.symmetric[i] && offset[i] == 0.0);
        d
    }

    /// A user field: its declared L, or the one derived from its expression (the shapes it
    /// reads contributing their own proven constants), or nothing proven. Its solid lies in
    /// the box its expression proves by interval arithmetic ([`field::solid_box`]), with the
    /// shapes it reads bounded by their boxes: outside a shape's box its field is above 0,
    /// and an exact one's at least the distance to the box.
    fn field(&self, id: NodeId, f: &FieldFn, declared: Option<f64>) -> Derived {
        let (min, max) = super::field::solid_box(f, |s, q| {
            let c = self.get(s);
            let b = c.bounds;
            if b.is_empty() {
                return f64::MIN_POSITIVE;
            }
            let gap = (0..3)
                .map(|i| {
                    (b.min[i] - q[i][1])
                        .max(q[i][0] - b.max[i])
                        .max(0.0)
                        .powi(2)
                })
                .sum::<f64>()
                .sqrt();
            match gap > 0.0 {
                true if c.proven && c.facts.exactness == Exactness::Exact => gap,
                true => f64::MIN_POSITIVE,
                false => f64::NEG_INFINITY,
            }
        });
        let mut d = exact(Aabb { min, max }, [false; 3]);
        let l = declared.unwrap_or_else(|| {
            super::field::lipschitz(f, |s| {
                let c = self.get(s);
                if c.proven {
                    c.gradient
                } else {
                    f64::INFINITY
                }
            })
        });
        if !l.is_finite() {
            return unproven(d, id);
        }
        d.facts.lipschitz = l;
        d.gradient = l;
        d.facts.exactness = classify(l, true);
        if d.facts.exactness != Exactness::Exact {
            d.cause = Some(id);
        }
        d
    }

    /// Union, intersection, subtraction: L is the largest of the children's (a min or max of
    /// L-Lipschitz fields is L-Lipschitz); exact only outside (union) or inside
    /// (intersection), so a bound.
    fn combine(&mut self, op: Combine, children: &[NodeId]) -> Derived {
        let ds: Vec<Derived> = children.iter().map(|&c| self.get(c)).collect();
        let Some(first) = ds.first() else {
            return exact(Aabb::EMPTY, [true; 3]);
        };
        if ds.len() == 1 {
            return *first;
        }
        let mut d = merge(&ds);
        d.bounds = match op {
            Combine::Union => ds.iter().fold(Aabb::EMPTY, |b, c| b.union(c.bounds)),
            Combine::Intersect => ds
                .iter()
                .skip(1)
                .fold(first.bounds, |b, c| b.intersect(c.bounds)),
            Combine::Subtract => first.bounds,
        };
        d
    }

    /// Smooth combinations: the gradient is a convex combination of the children's, so the
    /// Lipschitz constant is the larger one, and a Lipschitz field divided by its constant is
    /// a bound (Hart 1996). The surface moves by at most `blend_reach`.
    fn smooth(
        &mut self,
        id: NodeId,
        op: Combine,
        k: f64,
        v: Smooth,
        a: NodeId,
        b: NodeId,
    ) -> Derived {
        // A radius of 0 is the plain combination (an animated radius passing through 0).
        if k <= 0.0 {
            return self.combine(op, &[a, b]);
        }
        let (da, db) = (self.get(a), self.get(b));
        let reach = blend_reach(k, v);
        let mut d = steeper(da, db, blend_steepness(v), id);
        d.bounds = match op {
            Combine::Union => da
                .bounds
                .grow(da.growth * reach)
                .union(db.bounds.grow(db.growth * reach)),
            Combine::Intersect => da.bounds.intersect(db.bounds),
            Combine::Subtract => da.bounds,
        };
        let size = da.bounds.half_min().min(db.bounds.half_min());
        if v == Smooth::Exp && reach > size {
            self.warn_exp(id, op, k, reach, size);
        }
        d
    }

    /// A feature of `a` along `b`'s surface: like a blend, L is the operands' times the
    /// feature's steepness; the solid lies within `a`'s, grown by what stands out of it.
    fn feature(&mut self, id: NodeId, f: Feature, a: NodeId, b: NodeId) -> Derived {
        let (da, db) = (self.get(a), self.get(b));
        let mut d = steeper(da, db, feature_steepness(f), id);
        d.bounds = da.bounds.grow(da.growth * f.outset());
        d
    }
}

/// The facts of `da` and `db` blended (or one along the other's surface, a feature, of node
/// `id`) by a rule `steep` times as steep as theirs: approximate, or a bound where its L,
/// their L times `steep`, proves one.
fn steeper(da: Derived, db: Derived, steep: f64, id: NodeId) -> Derived {
    let mut d = merge(&[da, db]);
    d.facts.exactness = Exactness::Approximate;
    if d.gradient.is_finite() {
        d.gradient *= steep;
        d.facts.lipschitz = (d.facts.lipschitz * steep).max(d.gradient);
        d.facts.exactness = classify(d.facts.lipschitz, d.proven);
    } else if d.proven {
        d = unproven(d, id);
    }
    d
}

/// The facts of a combination of several fields (before its own rule): the largest L and
/// gradient, proven when all are, exactness at most a bound, the cause of the worst child.
pub(super) fn merge(ds: &[Derived]) -> Derived {
    let mut d = exact(Aabb::EMPTY, [true; 3]);
    d.facts.exactness = Exactness::Bound;
    d.gradient = 0.0;
    d.facts.lipschitz = 0.0;
    d.growth = 0.0;
    // The worst child with a cause: unproven first, then the largest L.
    let key = |c: &Derived| (!c.proven, c.facts.lipschitz);
    let mut worst: Option<&Derived> = None;
    for c in ds {
        d.facts.lipschitz = d.facts.lipschitz.max(c.facts.lipschitz);
        d.gradient = d.gradient.max(c.gradient);
        d.proven &= c.proven;
        d.growth = d.growth.max(c.growth);
        d.symmetric = [0, 1, 2].map(|i| d.symmetric[i] && c.symmetric[i]);
        if c.facts.exactness == Exactness::Approximate {
            d.facts.exactness = Exactness::Approximate;
        }
        if c.cause.is_some() && worst.is_none_or(|w| key(c) > key(w)) {
            worst = Some(c);
        }
    }
    d.cause = worst.and_then(|w| w.cause);
    d
}

/// A primitive of the table: exact unless its field is unproven, within its extent
/// (unbounded along z for a profile).
fn table_prim(id: NodeId, prim: &PrimRef, args: &Args) -> Derived {
    let e = (prim.extent)(args);
    let mut bounds = Aabb {
        min: e.min,
        max: e.max,
    };
    if prim.profile {
        (bounds.min[2], bounds.max[2]) = (f64::NEG_INFINITY, f64::INFINITY);
    }
    let d = exact(bounds, e.symmetric);
    match prim.field {
        PrimField::Exact => d,
        PrimField::Unproven => unproven(d, id),
    }
}

/// A profile's facts from its box in the plane, `lo` to `hi`: exact, unbounded along z
/// (and symmetric across z = 0).
fn plane_profile(lo: [f64; 2], hi: [f64; 2]) -> Derived {
    let bounds = Aabb {
        min: [lo[0], lo[1], f64::NEG_INFINITY],
        max: [hi[0], hi[1], f64::INFINITY],
    };
    exact(bounds, [false, false, true])
}

/// The quadratic Bézier profile from `a` to `b` through `control`, thickened by `radius`:
/// within the box of its three points, grown by the radius.
fn bezier(a: [f64; 2], control: [f64; 2], b: [f64; 2], radius: f64) -> Derived {
    let lo = [0, 1].map(|i| a[i].min(control[i]).min(b[i]) - radius);
    let hi = [0, 1].map(|i| a[i].max(control[i]).max(b[i]) + radius);
    plane_profile(lo, hi)
}

/// A polygon profile: within the box of its points, unbounded along z.
fn polygon(points: &[[f64; 2]]) -> Derived {
    let mut b = Aabb::EMPTY;
    for q in points {
        b = b.union(Aabb {
            min: [q[0], q[1], f64::NEG_INFINITY],
            max: [q[0], q[1], f64::INFINITY],
        });
    }
    exact(b, [false, false, true])
}

/// The half-space `dot(p, n) ≤ h`: bounded on one side when `n` is an axis.
fn plane_bounds(n: V3, h: f64) -> Aabb {
    let mut b = Aabb::ALL;
    for i in 0..3 {
        let others = (0..3).filter(|&j| j != i).all(|j| n[j] == 0.0);
        if others && n[i] != 0.0 {
            if n[i] > 0.0 {
                b.max[i] = h / n[i];
            } else {
                b.min[i] = h / n[i];
            }
        }
    }
    b
}

/// Quilez's ellipsoid bound `k0·(k0 − 1)/k1`: never above the distance, but not Lipschitz
/// (it jumps at the centre and steepens along the long axes), and its level sets reach up to
/// max r / min r times further than the distance's.
fn ellipsoid(radii: V3) -> Derived {
    let mut d = exact(Aabb::centred(radii), [true; 3]);
    d.facts.exactness = Exactness::Bound;
    d.gradient = f64::INFINITY;
    let rmin = radii.iter().fold(f64::INFINITY, |a, r| a.min(*r));
    let rmax = radii.iter().fold(0.0f64, |a, r| a.max(*r));
    d.growth = rmax / rmin;
    d
}
