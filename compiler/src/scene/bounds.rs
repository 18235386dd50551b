//! Bounding volumes of the nodes of a scene graph (the guarantee the lowering's culling relies
//! on, and the checker's test that a profile is finite), and a cost estimate of each node.
//!
//! A node's [`Bound`] is a sphere and an axis-aligned box, each with the guarantee that the
//! culling of guarded blocks relies on (`docs/optimisation.md`): at every point p, the
//! field `f` the lowering computes for the node satisfies `f(p) ≥ min(s, c·s)`, where `s` is
//! the signed distance from p to the volume and `c ∈ (0, 1]` the bound's `scale`. For a field
//! that is an exact distance, any volume containing the shape does (with `c = 1`); the rules
//! below keep the guarantee through every operation, including those whose field is only a
//! bound or an estimate. A box may be infinite along some axes (a slab); a node with no
//! bound at all (a plane, infinite repetition in every direction) has `None`.

use super::cost::own_cost;
use super::ir::{mat_vec, Combine, Graph, Node, Smooth, V3};
use super::NodeId;
use glam::DVec3;

/// A sphere: centre and radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    pub c: V3,
    pub r: f64,
}

/// An axis-aligned box: centre and half extents (infinite along an unbounded axis).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    pub c: V3,
    pub h: V3,
}

/// The bounding volumes of a node: `f(p) ≥ min(s, scale·s)` for `s` the signed distance to
/// either volume. `sphere` is infinite (`r = ∞`) when the box is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound {
    pub sphere: Sphere,
    pub aabb: Aabb,
    pub scale: f64,
}

impl Bound {
    fn of_sphere(r: f64) -> Bound {
        Bound {
            sphere: Sphere { c: [0.0; 3], r },
            aabb: Aabb {
                c: [0.0; 3],
                h: [r; 3],
            },
            scale: 1.0,
        }
    }

    /// A shape centred on the origin inside the box of half extents `h` and the sphere of
    /// radius `r`.
    fn of_box(h: V3, r: f64) -> Bound {
        Bound {
            sphere: Sphere { c: [0.0; 3], r },
            aabb: Aabb { c: [0.0; 3], h },
            scale: 1.0,
        }
    }

    /// Whether the box is finite along every axis.
    pub fn finite(&self) -> bool {
        self.aabb.h.iter().all(|h| h.is_finite())
    }

    /// Replaces each volume by the one around the other where that is smaller. (A volume
    /// containing a valid volume is valid; the intersection of two valid volumes need not
    /// be, so volumes are only ever replaced, never intersected.)
    fn tight(mut self) -> Bound {
        if !self.finite() {
            self.sphere.r = f64::INFINITY;
            return self;
        }
        let around_box = DVec3::from(self.aabb.h).length();
        let old_sphere = self.sphere;
        if around_box < self.sphere.r {
            self.sphere = Sphere {
                c: self.aabb.c,
                r: around_box,
            };
        }
        let r = old_sphere.r;
        if 8.0 * r * r * r < 8.0 * self.aabb.h[0] * self.aabb.h[1] * self.aabb.h[2] {
            self.aabb = Aabb {
                c: old_sphere.c,
                h: [r; 3],
            };
        }
        self
    }

    /// Both volumes grown by `g / scale` (so that `f ≥ min(s, c·s) - g` becomes a bound of
    /// the same form).
    fn grow(mut self, g: f64) -> Bound {
        let g = g.max(0.0) / self.scale;
        self.sphere.r += g;
        self.aabb.h = self.aabb.h.map(|h| h + g);
        self
    }

    /// The bound of a point map p ↦ s·p + t with a uniform s (the field scaled by |s|).
    fn similar(self, s: f64, t: V3) -> Bound {
        Bound {
            sphere: Sphere {
                c: (DVec3::from(self.sphere.c) * s + DVec3::from(t)).to_array(),
                r: self.sphere.r * s.abs(),
            },
            aabb: Aabb {
                c: (DVec3::from(self.aabb.c) * s + DVec3::from(t)).to_array(),
                h: self.aabb.h.map(|h| h * s.abs()),
            },
            scale: self.scale,
        }
    }

    /// The volume of the box (∞ for a slab) and of the sphere, for choosing between them.
    pub fn volumes(&self) -> (f64, f64) {
        let b = 8.0 * self.aabb.h[0] * self.aabb.h[1] * self.aabb.h[2];
        let r = self.sphere.r;
        (b, 4.0 / 3.0 * std::f64::consts::PI * r * r * r)
    }
}

/// Joins two bounds: volumes containing both, the smaller scale.
pub fn hull(a: &Bound, b: &Bound) -> Bound {
    let mut aabb = a.aabb;
    for i in 0..3 {
        let lo = (a.aabb.c[i] - a.aabb.h[i]).min(b.aabb.c[i] - b.aabb.h[i]);
        let hi = (a.aabb.c[i] + a.aabb.h[i]).max(b.aabb.c[i] + b.aabb.h[i]);
        if lo.is_finite() && hi.is_finite() {
            aabb.c[i] = (lo + hi) * 0.5;
            aabb.h[i] = (hi - lo) * 0.5;
        } else {
            aabb.c[i] = 0.0;
            aabb.h[i] = f64::INFINITY;
        }
    }
    Bound {
        sphere: sphere_hull(&a.sphere, &b.sphere),
        aabb,
        scale: a.scale.min(b.scale),
    }
    .tight()
}

/// The smallest sphere containing two spheres.
fn sphere_hull(a: &Sphere, b: &Sphere) -> Sphere {
    if !(a.r.is_finite() && b.r.is_finite()) {
        return Sphere {
            c: [0.0; 3],
            r: f64::INFINITY,
        };
    }
    let d = (DVec3::from(b.c) - DVec3::from(a.c)).length();
    if d + b.r <= a.r {
        return *a;
    }
    if d + a.r <= b.r {
        return *b;
    }
    let r = (d + a.r + b.r) * 0.5;
    let t = (r - a.r) / d;
    Sphere {
        c: (DVec3::from(a.c) + (DVec3::from(b.c) - DVec3::from(a.c)) * t).to_array(),
        r: r * (1.0 + 1e-12),
    }
}

/// The bound and the estimated cost (instructions per point) of every node of a graph.
#[derive(Debug, Clone)]
pub struct Bounds {
    of: Vec<Option<Bound>>,
    /// Where the node's field is read for its zero set alone ([`Bounds::zero_set`]).
    zero: Vec<Option<Bound>>,
    /// The intersections of bounded shapes and planes whose box the planes cut smaller
    /// ([`Bounds::raised`]).
    raised: Vec<Option<Bound>>,
    cost: Vec<f64>,
    /// The plane children of each intersection that cut nothing ([`Bounds::uncut`]).
    uncut: Vec<Vec<NodeId>>,
}

impl Bounds {
    /// Computes every node's bound and cost (children come before parents in a graph).
    pub fn new(graph: &Graph) -> Bounds {
        let mut out = Bounds {
            of: Vec::with_capacity(graph.len()),
            zero: Vec::with_capacity(graph.len()),
            raised: Vec::with_capacity(graph.len()),
            cost: Vec::with_capacity(graph.len()),
            uncut: Vec::with_capacity(graph.len()),
        };
        for id in graph.ids() {
            let node = graph.node(id);
            let b = bound(node, &|c| out.get(*c)).map(Bound::tight);
            let boxes = |c: &NodeId| {
                (out.zero_set(*c).filter(|b| b.finite() && b.scale == 1.0))
                    .map(|b| (b.aabb.c, b.aabb.h))
            };
            let cuts = super::clip::intersection(graph, node, &boxes);
            // The cost leaves out the planes that cut nothing, as the lowering does.
            let (cut, uncut) = cuts.map_or((None, Vec::new()), |c| (c.bound, c.uncut));
            let c = own_cost(node)
                + (node.children().iter())
                    .filter(|c| !uncut.contains(c))
                    .map(|&c| out.cost(c))
                    .sum::<f64>();
            let raised = cut
                .map(|(c, h)| Bound::of_box(h, DVec3::from(h).length()).similar(1.0, c))
                .filter(|r| b.is_none_or(|b| r.volumes().0 < CUT_SMALLER * b.volumes().0));
            let zero = match node {
                _ if raised.is_some() => raised,
                Node::Paint { .. }
                | Node::Translate { .. }
                | Node::Rotate { .. }
                | Node::Scale { .. }
                | Node::Combine { .. } => bound(node, &|c| out.zero_set(*c)).map(Bound::tight),
                _ => b,
            };
            out.of.push(b);
            out.zero.push(zero);
            out.raised.push(raised);
            out.cost.push(c);
            out.uncut.push(uncut);
        }
        out
    }

    /// The bound of a node where its field is read for its zero set alone and the lowering
    /// raises the intersections [`Bounds::raised`] names to the distance to their boxes
    /// (local bounds, docs/analysis.md): through paint, rigid and uniformly scaling
    /// transforms and plain combinations, those intersections' boxes.
    pub fn zero_set(&self, id: NodeId) -> Option<Bound> {
        self.zero[id.0 as usize]
    }

    /// For an intersection of bounded shapes and planes whose planes cut its box to less than
    /// half its bound's: the box around what is left of its children's boxes on the solid
    /// side of every plane (`clip.rs`). The intersection's field need not be at least the
    /// distance to that box (near a sharp edge of half-spaces it is less), so the box is a
    /// bound only of the field raised to the distance to it, max(f, β), which has the same
    /// zero set and is a distance bound as both are.
    pub fn raised(&self, id: NodeId) -> Option<Bound> {
        self.raised[id.0 as usize]
    }

    /// The bound of a node, if it has one.
    pub fn get(&self, id: NodeId) -> Option<Bound> {
        self.of[id.0 as usize]
    }

    /// The plane children of an intersection that cut nothing (`clip::Cuts::uncut`, of its
    /// children's zero-set boxes): where only its zero set is read, the lowering drops them.
    pub fn uncut(&self, id: NodeId) -> &[NodeId] {
        &self.uncut[id.0 as usize]
    }

    /// The estimated number of instructions a node costs per point.
    pub fn cost(&self, id: NodeId) -> f64 {
        self.cost[id.0 as usize]
    }
}

/// A raised bound's box must be below this share of the bound's to be kept.
const CUT_SMALLER: f64 = 0.5;

/// The bound of a node from its children's (`get`).
fn bound(node: &Node, get: &dyn Fn(&NodeId) -> Option<Bound>) -> Option<Bound> {
    Some(match node {
        Node::Sphere { radius } => Bound::of_sphere(*radius),
        Node::Box { half } => Bound::of_box(*half, DVec3::from(*half).length()),
        Node::RoundBox { half, radius } => Bound::of_box(
            *half,
            DVec3::from(half.map(|h| (h - radius).max(0.0))).length() + radius,
        ),
        Node::Plane { .. } | Node::Field { .. } => return None,
        Node::Torus { major, minor } => {
            Bound::of_box([major + minor, *minor, major + minor], major + minor)
        }
        Node::Cylinder {
            radius,
            half_height,
        }
        | Node::Cone {
            radius,
            half_height,
        } => Bound::of_box([*radius, *half_height, *radius], radius.hypot(*half_height)),
        Node::Capsule {
            radius,
            half_height,
        } => Bound::of_box(
            [*radius, half_height + radius, *radius],
            half_height + radius,
        ),
        Node::Ellipsoid { radii } => ellipsoid(*radii),
        // f ≥ |p| - 2 beyond radius 2, and f ≥ -0.5/e everywhere (see the docs).
        Node::Mesh { mesh } => {
            let (lo, hi) = mesh.0.aabb();
            let c = [0, 1, 2].map(|i| (lo[i] + hi[i]) * 0.5);
            let h = [0, 1, 2].map(|i| (hi[i] - lo[i]) * 0.5);
            Bound {
                sphere: Sphere {
                    c,
                    r: (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt(),
                },
                aabb: Aabb { c, h },
                scale: 1.0,
            }
        }
        // A profile read as a field of space is a prism along z.
        Node::Rect { half } => profile([0.0; 2], *half),
        Node::Prim { prim, args } => {
            let e = (prim.extent)(args);
            let c = [0, 1, 2].map(|i| (e.min[i] + e.max[i]) * 0.5);
            let h = [0, 1, 2].map(|i| (e.max[i] - e.min[i]) * 0.5);
            if prim.profile {
                profile([c[0], c[1]], [h[0], h[1]])
            } else if h.iter().all(|h| h.is_finite()) {
                Bound::of_box(h, e.radius).similar(1.0, c)
            } else {
                return None;
            }
        }
        // A quadratic Bézier curve lies in the triangle of its points.
        Node::Bezier {
            a,
            control,
            b,
            radius,
        } => {
            let lo = [0, 1].map(|i| a[i].min(control[i]).min(b[i]) - radius);
            let hi = [0, 1].map(|i| a[i].max(control[i]).max(b[i]) + radius);
            profile(
                [0, 1].map(|i| (lo[i] + hi[i]) * 0.5),
                [0, 1].map(|i| (hi[i] - lo[i]) * 0.5),
            )
        }
        Node::Polygon { points } => {
            let lo = [0, 1].map(|i| points.iter().fold(f64::INFINITY, |m, q| m.min(q[i])));
            let hi = [0, 1].map(|i| points.iter().fold(f64::NEG_INFINITY, |m, q| m.max(q[i])));
            profile(
                [0, 1].map(|i| (lo[i] + hi[i]) * 0.5),
                [0, 1].map(|i| (hi[i] - lo[i]) * 0.5),
            )
        }
        Node::Text { outline, .. } => {
            let (lo, hi) = outline.bounds();
            profile(
                [0, 1].map(|i| (lo[i] + hi[i]) * 0.5),
                [0, 1].map(|i| (hi[i] - lo[i]) * 0.5),
            )
        }
        Node::Extrude {
            half_height, child, ..
        } => extrude(&get(child)?, *half_height),
        Node::Revolve { offset, child } => revolve(&get(child)?, *offset)?,
        // The loft's field is at least the smaller scale times the distance to the hull
        // of its profiles' rectangles wherever both are, clamped or not, and is extruded.
        Node::Loft {
            half_height,
            bottom,
            top,
            ..
        } => extrude(&hull(&get(bottom)?, &get(top)?), *half_height),
        Node::Screw {
            half_height,
            floor,
            child,
            ..
        } => screw(&get(child)?, *half_height, *floor)?,
        Node::Sweep {
            path,
            extent,
            child,
            ..
        } => sweep(&path.0, *extent, &get(child)?),
        Node::Feature { op, a, .. } => get(a)?.grow(op.outset()),
        Node::Combine { op, children } => combine(*op, children.iter().map(get))?,
        Node::SmoothCombine {
            op,
            k,
            variant,
            a,
            b,
            ..
        } => smooth(*op, *k, *variant, get(a), get(b))?,
        Node::Translate { offset, child } => get(child)?.similar(1.0, *offset),
        Node::Rotate { matrix, child } => rotate(&get(child)?, matrix),
        Node::Scale { factor, child } => get(child)?.similar(*factor, [0.0; 3]),
        Node::ScaleXyz { factors, child } => scale_xyz(&get(child)?, factors),
        Node::Repeat {
            period,
            count,
            child,
        } => repeat(&get(child)?, period, count.as_ref())?,
        Node::Mirror { axes, child } => mirror(&get(child)?, axes),
        // Every rotation of the child about y; the lowering keeps its field above the
        // distance to these volumes where it bounds the copies it leaves out.
        Node::RepeatPolar { child, .. } => about_axis(&get(child)?, 1),
        Node::Wrap { radius, child } => wrap(&get(child)?, *radius),
        Node::Shear { matrix, child } => shear(&get(child)?, matrix),
        // No volume is proven for a taper's field (f(q)·s stretches unevenly).
        Node::Taper { .. } => return None,
        Node::Morph { a, b, .. } => hull(&get(a)?, &get(b)?),
        Node::Twist { child, .. } => about_axis(&get(child)?, 1),
        Node::Bend { child, .. } => about_axis(&get(child)?, 2),
        Node::Elongate { half, child } => elongate(&get(child)?, half),
        Node::Round { radius, child } => get(child)?.grow(*radius),
        Node::Shell { half, child } => get(child)?.grow(*half),
        Node::Paint { child, .. } => get(child)?,
    })
}

/// A profile's bound: the prism along z over the rectangle of centre `c` and half extents
/// `h` (a profile's field is at least the distance to the prism over any rectangle around it).
fn profile(c: [f64; 2], h: [f64; 2]) -> Bound {
    Bound {
        sphere: Sphere {
            c: [c[0], c[1], 0.0],
            r: f64::INFINITY,
        },
        aabb: Aabb {
            c: [c[0], c[1], 0.0],
            h: [h[0], h[1], f64::INFINITY],
        },
        scale: 1.0,
    }
}

/// An extruded profile: the field is increasing in the profile's, and the extrusion of the
/// distance to the profile's rectangle is the distance to the box over it (so the scale
/// carries over; a rounded extrusion lies inside the same box).
fn extrude(b: &Bound, h: f64) -> Bound {
    let aabb = Aabb {
        c: [b.aabb.c[0], b.aabb.c[1], 0.0],
        h: [b.aabb.h[0], b.aabb.h[1], h],
    };
    Bound {
        sphere: Sphere {
            c: aabb.c,
            r: DVec3::from(aabb.h).length(),
        },
        aabb,
        scale: b.scale,
    }
}

/// A revolved profile: read at (|p.xz| - offset, y), it lies within the distance from the
/// axis that its rectangle reaches; `None` where it reaches no point at x ≥ -offset (an
/// empty solid, which no volume describes).
fn revolve(b: &Bound, offset: f64) -> Option<Bound> {
    let r = b.aabb.c[0] + b.aabb.h[0] + offset;
    if r.is_nan() || r < 0.0 {
        return None;
    }
    let aabb = Aabb {
        c: [0.0, b.aabb.c[1], 0.0],
        h: [r, b.aabb.h[1], r],
    };
    Some(
        Bound {
            sphere: Sphere {
                c: aabb.c,
                r: if aabb.h.iter().all(|h| h.is_finite()) {
                    DVec3::from(aabb.h).length()
                } else {
                    f64::INFINITY
                },
            },
            aabb,
            scale: b.scale,
        }
        .tight(),
    )
}

/// A screw of a profile whose rectangle reaches the radius R = c.x + h.x: beyond R its
/// field is at least floor·(r - R) (the profile's rectangle and the floor term both are), and
/// beyond the slab at least |y| - half_height; their maximum is at least floor/√2 times the
/// distance to the cylinder, and so to its box and sphere. `None` for a profile without
/// finite extents.
/// The path's box grown by the profile's reach: the field is at least the distance to the tube
/// of that radius about the path (docs/analysis.md, "Sweep"), scaled as the profile's.
fn sweep(path: &super::Path, extent: f64, profile: &Bound) -> Bound {
    let (lo, hi) = path.aabb();
    let c = [0, 1, 2].map(|i| (lo[i] + hi[i]) / 2.0);
    let h = [0, 1, 2].map(|i| (hi[i] - lo[i]) / 2.0 + extent);
    Bound {
        sphere: Sphere {
            c,
            r: DVec3::from(h).length(),
        },
        aabb: Aabb { c, h },
        scale: profile.scale.min(1.0),
    }
}

fn screw(b: &Bound, half_height: f64, floor: f64) -> Option<Bound> {
    let r = b.aabb.c[0] + b.aabb.h[0];
    if !r.is_finite() || r < 0.0 {
        return None;
    }
    let h = [r, half_height, r];
    Some(Bound {
        sphere: Sphere {
            c: [0.0; 3],
            r: r.hypot(half_height),
        },
        aabb: Aabb { c: [0.0; 3], h },
        scale: (b.scale.min(floor) * std::f64::consts::FRAC_1_SQRT_2).min(1.0),
    })
}

/// The centre and half extents of a profile's rectangle and the scale of its bound
/// (`Bound`: the field is at least min(s, scale·s), s the distance to the rectangle), or
/// `None` where the profile has no finite rectangle; for the checks of `loft` and `screw`.
pub fn profile_rect(graph: &Graph, id: NodeId) -> Option<([f64; 2], [f64; 2], f64)> {
    let b = Bounds::new(graph).get(id)?;
    let (c, h) = (b.aabb.c, b.aabb.h);
    (h[0].is_finite() && h[1].is_finite()).then_some(([c[0], c[1]], [h[0], h[1]], b.scale))
}

/// Quilez's ellipsoid field k0·(k0 - 1)/k1 is at least (r_min/r_max)·(|p| - r_max) outside
/// the sphere of radius r_max, and at least |p| - r_max inside it.
fn ellipsoid(r: V3) -> Bound {
    let (lo, hi) = (r[0].min(r[1]).min(r[2]), r[0].max(r[1]).max(r[2]));
    Bound {
        scale: if hi > 0.0 {
            (lo / hi).clamp(1e-6, 1.0)
        } else {
            1.0
        },
        ..Bound::of_sphere(hi)
    }
}

/// min over children is at least the bound of their hull; max at least each child's.
fn combine(op: Combine, mut kids: impl Iterator<Item = Option<Bound>>) -> Option<Bound> {
    match op {
        Combine::Union => {
            let first = kids.next()??;
            kids.try_fold(first, |acc, b| Some(hull(&acc, &b?)))
        }
        Combine::Intersect => kids
            .flatten()
            .min_by(|a, b| a.volumes().0.total_cmp(&b.volumes().0)),
        Combine::Subtract => kids.next()?,
    }
}

/// A smooth union is at least min(a, b) minus its largest correction (k/4 for the
/// polynomial, k·ln 2 for the exponential, k/2 for hg_sdf's stairs, whatever the signs); a
/// smooth maximum is at least the maximum (hg_sdf's variants too).
fn smooth(op: Combine, k: f64, v: Smooth, a: Option<Bound>, b: Option<Bound>) -> Option<Bound> {
    match op {
        // hg_sdf's chamfer, round and columns unions read a + b (or |(a, b)|): inside both
        // operands they fall below min(a, b) by up to (√2 − 1)·|min(a, b)|, with no bound a
        // guard distance can follow, so they have none (their operands keep theirs).
        Combine::Union if matches!(v, Smooth::Chamfer | Smooth::Round | Smooth::Columns(_)) => None,
        Combine::Union => {
            let h = hull(&a?, &b?);
            let g = match v {
                _ if k <= 0.0 => 0.0,
                Smooth::Poly => k * 0.25,
                Smooth::Exp => k * std::f64::consts::LN_2,
                _ => k * 0.5,
            };
            Some(h.grow(g * (1.0 + 1e-9)))
        }
        Combine::Intersect => combine(op, [a, b].into_iter()),
        Combine::Subtract => a,
    }
}

/// The field f(Mᵀp): the sphere's centre rotated, the box around the rotated box.
fn rotate(b: &Bound, m: &[V3; 3]) -> Bound {
    let mut out = *b;
    out.sphere.c = mat_vec(m, b.sphere.c);
    if b.finite() {
        out.aabb.c = mat_vec(m, b.aabb.c);
        out.aabb.h = [0, 1, 2].map(|i| (0..3).map(|j| m[i][j].abs() * b.aabb.h[j]).sum());
    } else {
        // A slab stays a slab only when the rotation keeps every infinite axis on itself.
        let keeps = (0..3)
            .all(|i| (0..3).all(|j| b.aabb.h[j].is_finite() || i == j || m[i][j].abs() < 1e-12));
        if !keeps {
            return unbounded();
        }
        out.aabb.c = mat_vec(m, b.aabb.c.map(|c| if c.is_finite() { c } else { 0.0 }));
        // Entries below 1e-12 next to an infinite axis are rounding noise of a quarter turn.
        out.aabb.h = [0, 1, 2].map(|i| {
            (0..3)
                .filter(|&j| b.aabb.h[j].is_finite() || m[i][j].abs() >= 1e-12)
                .map(|j| m[i][j].abs() * b.aabb.h[j])
                .sum()
        });
    }
    out
}

/// A wrap: the child's w in [z0, z1] becomes the distance R − w from the y axis, and its
/// y is kept, so the wrapped shape lies within the box of half-width max |R − w| about the
/// axis. The distance from a point to that box is at most the child's distance from the
/// point's preimage (radial and vertical excesses are the same, the box has no angular
/// one), so the child's guarantee carries over unchanged.
fn wrap(b: &Bound, radius: f64) -> Bound {
    if !b.finite() {
        return unbounded();
    }
    let (z0, z1) = (b.aabb.c[2] - b.aabb.h[2], b.aabb.c[2] + b.aabb.h[2]);
    let rho = (radius - z0).abs().max((radius - z1).abs());
    let mut out = *b;
    out.aabb.c = [0.0, b.aabb.c[1], 0.0];
    out.aabb.h = [rho, b.aabb.h[1], rho];
    out.sphere = Sphere {
        c: [0.0, b.aabb.c[1], 0.0],
        r: rho.hypot(b.aabb.h[1]),
    };
    out
}

/// A shear S whose field the lowering writes f(S⁻¹p)·σmin: the box and sphere mapped by S
/// (the sphere's radius stretched by σmax), the scale reduced by σmin/σmax (the child's
/// distance from S⁻¹p is at least the distance from p to the mapped volume over σmax).
fn shear(b: &Bound, m: &[V3; 3]) -> Bound {
    if !b.finite() {
        return unbounded();
    }
    let (smin, smax) = singular_range(m);
    let mut out = *b;
    out.aabb.c = mat_vec(m, b.aabb.c);
    out.aabb.h = [0, 1, 2].map(|i| (0..3).map(|j| m[i][j].abs() * b.aabb.h[j]).sum());
    out.sphere = Sphere {
        c: mat_vec(m, b.sphere.c),
        r: b.sphere.r * smax,
    };
    out.scale = b.scale * (smin / smax);
    out
}

/// A bound with an infinite box: nothing is ever skipped by it.
fn unbounded() -> Bound {
    Bound {
        sphere: Sphere {
            c: [0.0; 3],
            r: f64::INFINITY,
        },
        aabb: Aabb {
            c: [0.0; 3],
            h: [f64::INFINITY; 3],
        },
        scale: 1.0,
    }
}

/// The field f(p/s)·min|s|: the volumes mapped by s, and the scale multiplied by
/// min|s|/max|s| (the map stretches distances by at most max|s|).
fn scale_xyz(b: &Bound, s: &V3) -> Bound {
    let a = s.map(f64::abs);
    let (lo, hi) = (a[0].min(a[1]).min(a[2]), a[0].max(a[1]).max(a[2]));
    Bound {
        sphere: Sphere {
            c: [0, 1, 2].map(|i| b.sphere.c[i] * s[i]),
            r: b.sphere.r * hi,
        },
        aabb: Aabb {
            c: [0, 1, 2].map(|i| b.aabb.c[i] * s[i]),
            h: [0, 1, 2].map(|i| b.aabb.h[i] * a[i]),
        },
        scale: if hi > 0.0 { b.scale * lo / hi } else { b.scale },
    }
}

/// Repetition: every copy's volume lies in the box stretched by the farthest cell offset
/// (infinitely along an infinitely repeated axis).
fn repeat(b: &Bound, period: &V3, count: Option<&V3>) -> Option<Bound> {
    let mut out = *b;
    let mut reach = [0.0; 3];
    for i in 0..3 {
        if period[i] == 0.0 {
            continue;
        }
        reach[i] = match count {
            Some(n) => period[i].abs() * (n[i] - 1.0).max(0.0) * 0.5,
            None => f64::INFINITY,
        };
        out.aabb.h[i] += reach[i];
        if reach[i].is_infinite() {
            out.aabb.c[i] = 0.0;
        }
    }
    out.sphere.r += DVec3::from(reach).length();
    if out.aabb.h.iter().all(|h| h.is_infinite()) {
        return None;
    }
    Some(out)
}

/// Mirroring: the volumes made symmetric about each mirrored plane.
fn mirror(b: &Bound, axes: &[bool; 3]) -> Bound {
    let mut out = *b;
    let mut moved = [0.0; 3];
    for i in (0..3).filter(|&i| axes[i]) {
        let far = b.aabb.c[i].abs() + b.aabb.h[i];
        out.aabb.c[i] = 0.0;
        out.aabb.h[i] = far;
        moved[i] = b.sphere.c[i];
        out.sphere.c[i] = 0.0;
    }
    out.sphere.r += DVec3::from(moved).length();
    out
}

/// Twist (about y, `axis` 1) and bend (about z, `axis` 2): the point is rotated about the
/// axis, so the volumes become symmetric about it.
fn about_axis(b: &Bound, axis: usize) -> Bound {
    let plane: Vec<usize> = (0..3).filter(|&i| i != axis).collect();
    let mut out = *b;
    let rho = plane
        .iter()
        .map(|&i| (b.aabb.c[i].abs() + b.aabb.h[i]).powi(2))
        .sum::<f64>()
        .sqrt();
    let off = plane
        .iter()
        .map(|&i| b.sphere.c[i].powi(2))
        .sum::<f64>()
        .sqrt();
    for &i in &plane {
        out.aabb.c[i] = 0.0;
        out.aabb.h[i] = rho;
        out.sphere.c[i] = 0.0;
    }
    out.sphere.r += off;
    out
}

/// Elongation: the child's field at p - clamp(p, -h, h), so the volumes grow by h.
fn elongate(b: &Bound, h: &V3) -> Bound {
    let mut out = *b;
    out.aabb.h = [0, 1, 2].map(|i| b.aabb.h[i] + h[i].abs());
    out.sphere.r += DVec3::from(*h).length();
    out
}

/// The smallest and largest singular values of a 3×3 matrix: the square roots of the
/// eigenvalues of MᵀM, found by Jacobi rotations (symmetric, so they converge).
pub(crate) fn singular_range(m: &[V3; 3]) -> (f64, f64) {
    let mut a = [[0.0f64; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            a[i][j] = (0..3).map(|k| m[k][i] * m[k][j]).sum();
        }
    }
    for _ in 0..64 {
        let (mut p, mut q, mut big) = (0, 1, 0.0);
        for (i, j) in [(0, 1), (0, 2), (1, 2)] {
            if a[i][j].abs() > big {
                (p, q, big) = (i, j, a[i][j].abs());
            }
        }
        if big < 1e-15 {
            break;
        }
        let theta = 0.5 * (2.0 * a[p][q]).atan2(a[q][q] - a[p][p]);
        let (s, c) = theta.sin_cos();
        let mut r = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        r[p][p] = c;
        r[q][q] = c;
        r[p][q] = s;
        r[q][p] = -s;
        // a ← Rᵀ·a·R
        let mut t = [[0.0f64; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                t[i][j] = (0..3).map(|k| a[i][k] * r[k][j]).sum();
            }
        }
        for i in 0..3 {
            for j in 0..3 {
                a[i][j] = (0..3).map(|k| r[k][i] * t[k][j]).sum();
            }
        }
    }
    let eig = [a[0][0], a[1][1], a[2][2]].map(|e| e.max(0.0).sqrt());
    let lo = eig.iter().fold(f64::INFINITY, |x, e| x.min(*e));
    let hi = eig.iter().fold(0.0f64, |x, e| x.max(*e));
    (lo, hi)
}
