//! Lowering of the node graph: point transforms are applied on the way down, distance and
//! material combinations on the way up. A node reached again at the same point (a shared
//! sub-shape) is lowered once where its registers are visible.
//!
//! When optimising, a union evaluates its unbounded children first, then its bounded ones
//! in a bounding volume hierarchy ([`super::bvh`]) whose groups are guarded blocks: a group
//! runs only where its bounding volume is nearer than the best distance so far (see
//! `docs/optimisation.md` for why the result is the same).

use super::shapes::{repeat, rotate};
use super::{field, shapes, Binary, Reg, Unary, EMPTY_DISTANCE};
use crate::program::builder::{Builder, P};
use crate::scene::analysis::{self, Analysis};
use crate::scene::bounds::Bounds;
use crate::scene::field::{FOp, FieldFn};
use crate::scene::{Combine, Graph, Node, NodeId, V3};
use std::collections::HashMap;

mod blend;
mod bounds;
mod union;
mod window;

#[cfg(test)]
use bounds::bound_distance;

/// The material register value of a shape no `paint` has reached yet.
pub(super) const UNPAINTED: f64 = -1.0;

/// A subtree is guarded by a bound only when it costs at least this many instructions per
/// point. A guard costs the distance to a box (up to about 25 instructions) and the block's
/// bookkeeping, and it saves only where the subtree is skipped: below about three times its
/// own cost it is a loss on the report's scenes, whose one guard each guards little, while
/// the scaling scenes' groups cost far more (measured).
const GUARD_COST: f64 = 80.0;

/// 1 - 2⁻¹²: bounds are shrunk by this factor, and padded, so that rounding can never make
/// a bound exceed the field it bounds.
const SHRINK: f64 = 1.0 - 1.0 / 4096.0;

/// A lowered field: distance and material registers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Field {
    pub d: Reg,
    pub m: Reg,
}

/// How the graph is lowered.
#[derive(Debug, Clone, Copy)]
pub(super) struct Config<'a> {
    /// Guard union groups by their bounds.
    pub cull: bool,
    /// The camera position (the hierarchy puts nearer groups first).
    pub camera: V3,
    /// For a simplified graph: the original node of each node (for comments).
    pub origin: Option<&'a [NodeId]>,
    /// Bounds and costs of the nodes (when optimising).
    pub bounds: Option<&'a Bounds>,
    /// Optimisation level ≥ 1: unions get a hierarchy, rotations are shared.
    pub optimise: bool,
    /// The analysis of the graph: the neighbouring cells of repetitions, and for local
    /// bounds the L of each node.
    pub analysis: Option<&'a Analysis>,
    /// Local bounds: an operand whose zero set is all that matters is divided by its own L
    /// (see [`Lowerer::node`]).
    pub local: bool,
}

/// Walks the graph, emitting into a builder.
#[derive(Debug)]
pub(super) struct Lowerer<'a> {
    graph: &'a Graph,
    b: &'a mut Builder,
    memo: HashMap<(NodeId, P, bool), Field>,
    config: Config<'a>,
    /// Whether only the zero set of the node being lowered matters (its ancestors are
    /// plain combinations, paint and rigid or uniformly scaling transforms): where local
    /// bounds are on, its operands may then be divided by their own L.
    zero_set: bool,
    /// With a parametric builder, whether each node's L may differ from 1 for some values of
    /// its numbers ([`steepening`]): such an operand keeps its local bound even where its L is
    /// 1, so that a frame where a twist's rate passes through 0 keeps the program's shape.
    steepens: Vec<bool>,
}

impl<'a> Lowerer<'a> {
    pub fn new(graph: &'a Graph, b: &'a mut Builder, config: Config<'a>) -> Self {
        let steepens = if b.parametric {
            steepening(graph)
        } else {
            Vec::new()
        };
        Lowerer {
            graph,
            b,
            memo: HashMap::new(),
            zero_set: config.local && config.analysis.is_some(),
            steepens,
            config,
        }
    }

    /// The number of a node in comments: its original node.
    fn number(&self, id: NodeId) -> u32 {
        self.config
            .origin
            .and_then(|o| o.get(id.0 as usize))
            .map_or(id.0, |n| n.0)
    }

    /// Lowers node `id` evaluated at point `p`.
    ///
    /// With local bounds, an operand whose L exceeds 1 and whose zero set is all that matters
    /// (see [`Lowerer::zero_set`]) is lowered as `max(f / L, β)`, β the distance to its
    /// bounding volume: both are distance bounds, so their maximum is one, and it steps as far
    /// as the volume allows away from the operand. A chain of paint and transforms over a
    /// plain combination is not such an operand: the combination's own operands are.
    pub fn node(&mut self, id: NodeId, p: P) -> Field {
        if self.b.over() {
            // Past the `program` limit the program is dropped: stop descending (any
            // register defined outside every block stands in for the field).
            return Field { d: p[0], m: p[0] };
        }
        let key = (id, p, self.zero_set);
        if let Some(&f) = self.memo.get(&key) {
            if self.b.visible(f.d) && self.b.visible(f.m) {
                return f;
            }
        }
        let divide = match self.config.analysis {
            Some(a) if self.zero_set => a.node(id).step(),
            _ => 1.0,
        };
        let steep = divide > 1.0
            || (self.zero_set
                && self.config.analysis.is_some()
                && self.steepens.get(id.0 as usize) == Some(&true));
        let f = if steep && !self.spine(id) {
            self.local_bound(id, divide, p, divide > 1.0)
        } else {
            let zero_set = self.zero_set;
            self.zero_set = zero_set && keeps_zero_set(self.graph.node(id));
            let f = self.lower_node(id, p);
            self.zero_set = zero_set;
            f
        };
        let f = self.raise(id, f, p);
        self.memo.insert(key, f);
        f
    }

    /// Whether paint and transforms below `id` lead to a plain combination.
    fn spine(&self, mut id: NodeId) -> bool {
        loop {
            match self.graph.node(id) {
                Node::Combine { .. } => return true,
                Node::Paint { child, .. }
                | Node::Translate { child, .. }
                | Node::Rotate { child, .. }
                | Node::Scale { child, .. } => id = *child,
                _ => return false,
            }
        }
    }

    /// Lowers node `id` at `p` (the body of [`Lowerer::node`]).
    fn lower_node(&mut self, id: NodeId, p: P) -> Field {
        let graph = self.graph;
        let node = graph.node(id);
        self.b
            .note(format!("node {} {}", self.number(id), node.kind()));
        match node {
            Node::Combine {
                op: Combine::Union,
                children,
            } if self.config.optimise => self.union(id, children, p),
            Node::Combine { op, children } => self.combine(id, *op, children, p),
            Node::SmoothCombine {
                op,
                k,
                variant,
                a,
                b,
            } => self.smooth(id, *op, *k, *variant, [*a, *b], p),
            Node::Feature { op, a, b } => self.feature(id, *op, [*a, *b], p),
            Node::Paint { material, child } => self.paint(id, material.0 as f64, *child, p),
            Node::Round { radius, child } => self.post(id, *child, p, |b, d| b.subc(d, *radius)),
            Node::Shell { half, child } => self.post(id, *child, p, |b, d| {
                let a = b.abs(d);
                b.subc(a, *half)
            }),
            Node::Scale { factor, child } => {
                let q = self.b.map3(p, |b, x, _| b.mulc(x, 1.0 / factor));
                self.post(id, *child, q, |b, d| b.mulc(d, factor.abs()))
            }
            Node::Repeat {
                period,
                count,
                child,
            } if self.window(id).is_some() => {
                let w = self.window(id).expect("checked");
                self.windowed(id, *child, *period, *count, w, p)
            }
            Node::RepeatPolar {
                count,
                mirror,
                child,
            } => self.polar(id, *count, *mirror, *child, p),
            Node::Shear { matrix, child } => self.shear(id, matrix, *child, p),
            Node::Taper { rate, child } => self.taper(id, *rate, *child, p),
            Node::Morph { t, a, b } => self.morph(id, *t, [*a, *b], p),
            Node::Field { f, .. } => self.field(id, f, p),
            Node::Extrude {
                half_height,
                round,
                child,
            } => self.extrude(id, *half_height, *round, *child, p),
            Node::Revolve { offset, child } => self.revolve(*offset, *child, p),
            Node::Loft {
                half_height,
                spread,
                bottom,
                top,
            } => self.loft(id, [*half_height, *spread], [*bottom, *top], p),
            Node::Screw {
                pitch,
                half_height,
                inner,
                floor,
                child,
            } => self.screw(id, [*pitch, *half_height, *inner, *floor], *child, p),
            Node::Sweep {
                path,
                inner,
                extent,
                child,
                ..
            } => self.sweep(id, &path.0, [*inner, *extent], *child, p),
            Node::ScaleXyz { factors, child } => {
                let q = self.b.map3(p, |b, x, i| b.mulc(x, 1.0 / factors[i]));
                let s = factors.iter().fold(f64::INFINITY, |m, f| m.min(f.abs()));
                self.post(id, *child, q, |b, d| b.mulc(d, s))
            }
            _ => match self.domain(node, p) {
                Some((child, q)) => self.node(child, q),
                None => self.primitive(node, p),
            },
        }
    }

    /// Paint: the child's field, its material register painted `material`.
    fn paint(&mut self, id: NodeId, material: f64, child: NodeId, p: P) -> Field {
        let f = self.node(child, p);
        self.resume(id, self.graph.node(id));
        Field {
            d: f.d,
            m: self.b.paint(f.m, material),
        }
    }

    /// A shear S: f(S⁻¹p)·σmin(S), a bound with the child's L (docs/analysis.md).
    fn shear(&mut self, id: NodeId, matrix: &[V3; 3], child: NodeId, p: P) -> Field {
        let inverse = analysis::invert(matrix).unwrap_or(IDENTITY);
        let (smin, _) = crate::scene::bounds::singular_range(matrix);
        let transposed = [0, 1, 2].map(|i| [0, 1, 2].map(|j| inverse[j][i]));
        let q = rotate(self.b, p, &transposed);
        self.post(id, child, q, |b, d| b.mulc(d, smin))
    }

    /// A taper: f(x/s, y, z/s)·s with s = 1 + rate·y, clamped above 0 where the taper folds.
    fn taper(&mut self, id: NodeId, rate: f64, child: NodeId, p: P) -> Field {
        let b = &mut *self.b;
        let s = b.mulc(p[1], rate);
        let s = b.addc(s, 1.0);
        let s = b.maxc(s, analysis::TAPER_FLOOR);
        let q = [b.div(p[0], s), p[1], b.div(p[2], s)];
        self.post(id, child, q, |b, d| b.mul(d, s))
    }

    /// A morph: the mix (1 - t)·a + t·b of the two fields, the nearer's material.
    fn morph(&mut self, id: NodeId, t: f64, [a, b]: [NodeId; 2], p: P) -> Field {
        let (fa, fb) = (self.node(a, p), self.node(b, p));
        self.resume(id, self.graph.node(id));
        let wa = self.b.mulc(fa.d, 1.0 - t);
        let wb = self.b.mulc(fb.d, t);
        Field {
            d: self.b.add(wa, wb),
            m: self.material(Combine::Union, fa, fb),
        }
    }

    /// An extrusion of `half_height`, its edges rounded by `round`: the profile is read in
    /// the plane z = 0.
    fn extrude(&mut self, id: NodeId, half_height: f64, round: f64, child: NodeId, p: P) -> Field {
        let (h, r) = (half_height, round);
        let q = [p[0], p[1], self.b.c(0.0)];
        self.post(id, child, q, |b, d| {
            if r > 0.0 {
                let d = b.addc(d, r);
                let e = crate::prim::extrude(b, d, p[2], h - r);
                b.subc(e, r)
            } else {
                crate::prim::extrude(b, d, p[2], h)
            }
        })
    }

    /// A revolution about the y axis: the profile read at (r - offset, y) in the plane z = 0,
    /// r the distance from the axis.
    fn revolve(&mut self, offset: f64, child: NodeId, p: P) -> Field {
        let b = &mut *self.b;
        let r = b.len2(p[0], p[2]);
        let x = b.subc(r, offset);
        let q = [x, p[1], b.c(0.0)];
        let f = self.node(child, q);
        Field { d: f.d, m: f.m }
    }

    /// A loft: both profiles in the plane z = 0, mixed by the height's fraction t, the
    /// difference clamped to ±spread (docs/analysis.md, "Loft"), then extruded.
    fn loft(&mut self, id: NodeId, [h, s]: [f64; 2], [bottom, top]: [NodeId; 2], p: P) -> Field {
        let q = [p[0], p[1], self.b.c(0.0)];
        let (fa, fb) = (self.node(bottom, q), self.node(top, q));
        self.resume(id, self.graph.node(id));
        let b = &mut *self.b;
        let t = b.mulc(p[2], 0.5 / h);
        let t = b.addc(t, 0.5);
        let t = b.clampc(t, 0.0, 1.0);
        let diff = b.sub(fb.d, fa.d);
        let diff = b.clampc(diff, -s, s);
        let step = b.mul(t, diff);
        let d = b.add(fa.d, step);
        let d = crate::prim::extrude(b, d, p[2], h);
        let upper = b.c(0.5);
        let upper = b.lt(upper, t);
        Field {
            d,
            m: b.select(upper, fb.m, fa.m),
        }
    }

    /// A sweep along `path`: the profile read in its plane z = 0 at the point's place about
    /// the path, then cut to the sweep's `inner` and `extent`.
    fn sweep(
        &mut self,
        id: NodeId,
        path: &crate::scene::path::Path,
        [inner, extent]: [f64; 2],
        child: NodeId,
        p: P,
    ) -> Field {
        let hit = super::sweep::locate(self.b, p, path);
        let q = [hit.u, hit.v, self.b.c(0.0)];
        let f = self.node(child, q);
        self.resume(id, self.graph.node(id));
        let d = super::sweep::finish(self.b, f.d, &hit, inner, extent);
        Field { d, m: f.m }
    }

    /// A screw (docs/analysis.md, "Screw"): the profile read at (r, w), r the distance from
    /// the y axis, w the height less pitch·φ/2π (φ the angle about +y, so the thread is
    /// right-handed) folded into [-pitch/2, pitch/2], and at the nearer neighbouring turn;
    /// their minimum, below floor·max(inner - r, r) near the axis, cut to |y| ≤ half_height.
    fn screw(
        &mut self,
        id: NodeId,
        [pitch, half_height, inner, floor]: [f64; 4],
        child: NodeId,
        p: P,
    ) -> Field {
        let b = &mut *self.b;
        let r = b.len2(p[0], p[2]);
        let nz = b.neg(p[2]);
        let phi = b.bin(Binary::Atan2, nz, p[0]);
        let rise = b.mulc(phi, pitch / std::f64::consts::TAU);
        let v = b.sub(p[1], rise);
        let turns = b.mulc(v, 1.0 / pitch);
        let turns = b.un(Unary::Round, turns);
        let back = b.mulc(turns, pitch);
        let w = b.sub(v, back);
        // The nearer neighbour: w - pitch above the middle of the turn, w + pitch below it.
        let zero = b.c(0.0);
        let below = b.lt(w, zero);
        let up = b.mulc(below, 2.0 * pitch);
        let next = b.subc(w, pitch);
        let next = b.add(next, up);
        let z = b.c(0.0);
        let f0 = self.node(child, [r, w, z]);
        let f1 = self.node(child, [r, next, z]);
        self.resume(id, self.graph.node(id));
        let m = self.material(Combine::Union, f0, f1);
        let b = &mut *self.b;
        let g = b.min(f0.d, f1.d);
        let i = b.c(inner);
        let toward = b.sub(i, r);
        let near = b.max(toward, r);
        let near = b.mulc(near, floor);
        let g = b.min(g, near);
        let ay = b.abs(p[1]);
        let cap = b.subc(ay, half_height);
        Field {
            d: b.max(g, cap),
            m,
        }
    }

    /// A user field: its operations in order, the shapes it reads lowered at their points.
    fn field(&mut self, id: NodeId, f: &FieldFn, p: P) -> Field {
        let mut regs: Vec<Reg> = Vec::with_capacity(f.ops.len());
        let mut resumed = true;
        // The shapes read, for the field's material: a warp written as a field,
        // `distance(s, q(p))`, keeps `s`'s materials as a transform does; of several shapes
        // read, the nearest's, as in a union.
        let mut read: Option<Field> = None;
        for op in &f.ops {
            let r = match op {
                FOp::Distance(shape, q) => {
                    let q = q.map(|s| regs[s as usize]);
                    let shape = self.node(*shape, q);
                    resumed = false;
                    read = Some(match read {
                        None => shape,
                        Some(before) => Field {
                            m: self.material(Combine::Union, before, shape),
                            d: self.b.min(before.d, shape.d),
                        },
                    });
                    shape.d
                }
                other => {
                    if !resumed {
                        self.resume(id, self.graph.node(id));
                        resumed = true;
                    }
                    field::op(self.b, other, p, &regs)
                }
            };
            regs.push(r);
        }
        let d = f.out.first().map_or(p[0], |&s| regs[s as usize]);
        let m = match read {
            Some(shape) => shape.m,
            None => self.b.c(UNPAINTED),
        };
        Field { d, m }
    }

    /// Notes that the instructions that follow belong to `id` again, after its children.
    fn resume(&mut self, id: NodeId, node: &Node) {
        self.b.note_resume(format!(
            "node {} {} (after its children)",
            id.0,
            node.kind()
        ));
    }

    /// Lowers `child` at `q`, then maps its distance with `f` (material unchanged).
    fn post(
        &mut self,
        id: NodeId,
        child: NodeId,
        q: P,
        f: impl FnOnce(&mut Builder, Reg) -> Reg,
    ) -> Field {
        let c = self.node(child, q);
        self.resume(id, self.graph.node(id));
        Field {
            d: f(self.b, c.d),
            m: c.m,
        }
    }

    /// For a domain transform: its child and the transformed point.
    fn domain(&mut self, node: &Node, p: P) -> Option<(NodeId, P)> {
        let optimise = self.config.optimise;
        let graph = self.graph;
        let b = &mut *self.b;
        let q = match node {
            Node::Translate { offset, child } if optimise => match graph.node(*child) {
                // Mᵀ(p - t) as Mᵀp - Mᵀt, so that children rotated alike share Mᵀp.
                Node::Rotate { matrix, child } => {
                    let r = rotate(b, p, matrix);
                    let t = [0, 1, 2].map(|j| (0..3).map(|i| offset[i] * matrix[i][j]).sum());
                    (*child, b.sub3c(r, t))
                }
                _ => (*child, b.sub3c(p, *offset)),
            },
            Node::Translate { offset, child } => (*child, b.sub3c(p, *offset)),
            Node::Rotate { matrix, child } => (*child, rotate(b, p, matrix)),
            Node::Repeat {
                period,
                count,
                child,
            } => (*child, repeat(b, p, *period, *count)),
            Node::Mirror { axes, child } => (
                *child,
                b.map3(p, |b, x, i| if axes[i] { b.abs(x) } else { x }),
            ),
            Node::Twist { rate, child } => (*child, twist(b, p, *rate)),
            Node::Bend { rate, child } => (*child, bend(b, p, *rate)),
            Node::Wrap { radius, child } => (*child, wrap(b, p, *radius)),
            Node::Elongate { half, child } => (*child, elongate(b, p, *half)),
            _ => return None,
        };
        Some(q)
    }

    /// Lowers a primitive (unpainted).
    fn primitive(&mut self, node: &Node, p: P) -> Field {
        let b = &mut *self.b;
        let d = match *node {
            Node::Plane { normal, height } => shapes::plane(b, p, normal, height),
            Node::Ellipsoid { radii } => shapes::ellipsoid(b, p, radii),
            Node::Rect { half } => crate::prim::rect(b, p, half),
            Node::Polygon { ref points } => shapes::polygon(b, p, points),
            Node::Mesh { ref mesh } => b.mesh(&mesh.0, p),
            Node::Bezier {
                a,
                control,
                b: end,
                radius,
            } => {
                let d = shapes::bezier(b, p, [a, control, end]);
                b.subc(d, radius)
            }
            Node::Text { ref outline, .. } => b.outline(outline, p[0], p[1]),
            Node::Prim { prim, ref args } => (prim.distance)(b, p, args),
            _ => match shapes::slots(node) {
                Some(s) => shapes::exact(b, p, node, &s).unwrap_or_else(|| b.c(EMPTY_DISTANCE)),
                None => b.c(EMPTY_DISTANCE),
            },
        };
        Field {
            d,
            m: b.c(UNPAINTED),
        }
    }
}

/// For tests: a program computing node `id`'s field (as its distance) and the guard distance
/// of its bound (as its material register).
#[cfg(test)]
pub(super) fn field_and_bound(
    graph: &Graph,
    bounds: &Bounds,
    id: NodeId,
) -> Option<super::Program> {
    let bound = bounds.get(id)?;
    let mut b = Builder::new(true);
    let p = b.input_point();
    let beta = bound_distance(&mut b, &bound, p);
    let config = Config {
        cull: false,
        camera: [0.0; 3],
        origin: None,
        bounds: Some(bounds),
        optimise: true,
        analysis: None,
        local: false,
    };
    let f = Lowerer::new(graph, &mut b, config).node(id, p);
    Some(b.finish(f.d, beta))
}

/// For each node of `graph`, whether its L may exceed 1 for some values of its numbers (and of
/// its descendants'): the maps that stretch distances by an amount their numbers set (twist,
/// bend, taper, shear, wrap, a scale per axis, a screw, a loft) and user fields do; shapes,
/// combinations, rigid and uniform transforms, offsets, folds and repetitions pass their
/// children's on, and a blend's or a feature's steepness is a matter of its kind.
fn steepening(graph: &Graph) -> Vec<bool> {
    let mut out: Vec<bool> = Vec::with_capacity(graph.len());
    for id in graph.ids() {
        let node = graph.node(id);
        let own = matches!(
            node,
            Node::Field { .. }
                | Node::Twist { .. }
                | Node::Bend { .. }
                | Node::Taper { .. }
                | Node::Shear { .. }
                | Node::Wrap { .. }
                | Node::ScaleXyz { .. }
                | Node::Screw { .. }
                | Node::Loft { .. }
        ) || matches!(node,
            // L is 1 at k = 0, the plain combination, and the variant's steepness above.
            Node::SmoothCombine { variant, .. } if analysis::blend_steepness(*variant) > 1.0
        );
        let below = node.children().iter().any(|c| out[c.0 as usize]);
        out.push(own || below);
    }
    out
}

/// Whether only the zero set of a node's children matters when only its own does: true for
/// plain combinations (a minimum or maximum of bounds is a bound), paint, translation,
/// rotation and uniform scale; false where the children's values are read (offsets, smooth
/// combinations) or the point map stretches (repetition, twist, bend, per-axis scale).
fn keeps_zero_set(node: &Node) -> bool {
    matches!(
        node,
        Node::Combine { .. }
            | Node::Paint { .. }
            | Node::Translate { .. }
            | Node::Rotate { .. }
            | Node::Scale { .. }
    )
}

/// Rotation of the xz plane by k·y: q = (c·x - s·z, y, s·x + c·z).
fn twist(b: &mut Builder, p: P, k: f64) -> P {
    let a = b.mulc(p[1], k);
    let (c, s) = (b.un(Unary::Cos, a), b.un(Unary::Sin, a));
    let (x, z) = rot2(b, c, s, p[0], p[2]);
    [x, p[1], z]
}

/// Rotation of the xy plane by k·x: q = (c·x - s·y, s·x + c·y, z).
fn bend(b: &mut Builder, p: P, k: f64) -> P {
    let a = b.mulc(p[0], k);
    let (c, s) = (b.un(Unary::Cos, a), b.un(Unary::Sin, a));
    let (x, y) = rot2(b, c, s, p[0], p[1]);
    [x, y, p[2]]
}

/// The wrap's map to its child: q = (R·atan2(x, −z), y, R − √(x² + z²)).
fn wrap(b: &mut Builder, p: P, radius: f64) -> P {
    let nz = b.neg(p[2]);
    let angle = b.bin(Binary::Atan2, p[0], nz);
    let u = b.mulc(angle, radius);
    let rho = b.len2(p[0], p[2]);
    let w = b.neg(rho);
    [u, p[1], b.addc(w, radius)]
}

/// The identity matrix.
const IDENTITY: [V3; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

fn rot2(b: &mut Builder, c: Reg, s: Reg, u: Reg, v: Reg) -> (Reg, Reg) {
    let (cu, sv, su, cv) = (b.mul(c, u), b.mul(s, v), b.mul(s, u), b.mul(c, v));
    (b.sub(cu, sv), b.add(su, cv))
}

/// [`rot2`] by a constant angle, of cosine `c` and sine `s`.
fn rot2c(b: &mut Builder, c: f64, s: f64, u: Reg, v: Reg) -> (Reg, Reg) {
    let (cu, sv, su, cv) = (b.mulc(u, c), b.mulc(v, s), b.mulc(u, s), b.mulc(v, c));
    (b.sub(cu, sv), b.add(su, cv))
}

/// Elongation: q = p - clamp(p, -h, h), which stretches any child (symmetric or not).
fn elongate(b: &mut Builder, p: P, h: V3) -> P {
    b.map3(p, |b, x, i| {
        let c = b.clampc(x, -h[i], h[i]);
        b.sub(x, c)
    })
}
