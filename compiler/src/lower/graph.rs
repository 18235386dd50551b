//! Lowering of the node graph: point transforms are applied on the way down, distance and
//! material combinations on the way up. A node reached again at the same point (a shared
//! sub-shape) is lowered once where its registers are visible.
//!
//! When optimising, a union evaluates its unbounded children first, then its bounded ones
//! in a bounding volume hierarchy ([`super::bvh`]) whose groups are guarded blocks: a group
//! runs only where its bounding volume is nearer than the best distance so far (see
//! `docs/optimisation.md` for why the result is the same).

use super::bvh::{self, Kind, Tree};
use super::shapes::{cell_index, repeat, rotate};
use super::{blends, field, shapes, Binary, Reg, Unary, EMPTY_DISTANCE};
use crate::program::builder::{Builder, P};
use crate::scene::analysis::{self, Analysis, Window};
use crate::scene::bounds::{Aabb, Bound, Bounds};
use crate::scene::field::{FOp, FieldFn};
use crate::scene::{Combine, Feature, Graph, Node, NodeId, Smooth, V3};
use glam::DVec3;
use std::collections::HashMap;

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

    /// Where the field is read for its zero set alone, an intersection whose planes cut its
    /// box smaller (`Bounds::raised`) raised to the distance to that box, `max(f, β, β_box)`:
    /// both are distance bounds, so their maximum is one, with f's solid, and at least the
    /// distance to the box the unions around it guard it by (`Bounds::zero_set`).
    fn raise(&mut self, id: NodeId, f: Field, p: P) -> Field {
        if !self.zero_set || self.b.parametric {
            return f;
        }
        let Some(bound) = self.config.bounds.and_then(|b| b.raised(id)) else {
            return f;
        };
        let text = format!(
            "node {} intersection: at least the distance to the box its planes cut",
            self.number(id)
        );
        self.b.note(text);
        let beta = bound_distance(self.b, &bound, p);
        let (slab, _) = slab_distance(self.b, &bound, None, p);
        let d = self.b.max(f.d, beta);
        let d = self.b.max(d, slab);
        Field { d, m: f.m }
    }

    /// The bound a union's child is guarded by: where the child's field is read for its zero
    /// set alone, the one that counts its intersections raised ([`Lowerer::raise`]).
    fn guard_bound(&self, bounds: &Bounds, c: NodeId) -> Option<Bound> {
        if self.zero_set && !self.b.parametric {
            bounds.zero_set(c)
        } else {
            bounds.get(c)
        }
    }

    /// The neighbouring cells repetition `id` evaluates, if any.
    fn window(&self, id: NodeId) -> Option<Window> {
        self.config.analysis.and_then(|a| a.window(id))
    }

    /// A repetition whose copies reach out of their cells: the minimum over the copies of the
    /// cells within `w.reach` of the point's own cell (clamped to those that exist), and
    /// `w.beyond`, a lower bound of the distance to the others.
    fn windowed(
        &mut self,
        id: NodeId,
        child: NodeId,
        period: V3,
        count: Option<V3>,
        w: Window,
        p: P,
    ) -> Field {
        let b = &mut *self.b;
        // The own cell's index per axis, centred (−(n−1)/2 … (n−1)/2 for n copies).
        let cell: [Option<Reg>; 3] = [0, 1, 2].map(|i| {
            (period[i] != 0.0).then(|| cell_index(b, p[i], period[i], count.map(|n| n[i])))
        });
        let r = w.reach.map(|x| x as i64);
        let mut acc: Option<Field> = None;
        for i in -r[0]..=r[0] {
            for j in -r[1]..=r[1] {
                for k in -r[2]..=r[2] {
                    let offset = [i, j, k];
                    let b = &mut *self.b;
                    let q = b.map3(p, |b, x, a| {
                        let Some(c) = cell[a] else { return x };
                        let mut c = b.addc(c, offset[a] as f64);
                        if let Some(n) = count {
                            let half = (n[a] - 1.0) * 0.5;
                            c = b.clampc(c, -half, half);
                        }
                        let off = b.mulc(c, period[a]);
                        b.sub(x, off)
                    });
                    let f = self.node(child, q);
                    acc = Some(self.fold(acc, f));
                }
            }
        }
        self.resume(id, self.graph.node(id));
        let f = acc.expect("a window holds the own cell");
        if w.beyond.is_finite() {
            let cap = self.b.c(w.beyond);
            Field {
                d: self.b.min(f.d, cap),
                m: f.m,
            }
        } else {
            f
        }
    }

    /// A polar repetition about y: the copies of the sectors around the point's own, k + j
    /// for j in the window ([`analysis::polar_window`]), each the child at the point rotated
    /// back by (k + j)·360°/count (and mirrored across z = 0 for odd copies with `mirror`);
    /// where the window leaves copies out, the minimum with a lower bound of the distance to
    /// them: ρ·sin γ, and the distances to the node's bounding volumes, which hold every copy.
    fn polar(&mut self, id: NodeId, count: u32, mirror: bool, child: NodeId, p: P) -> Field {
        if count <= 1 {
            return self.node(child, p);
        }
        let step = std::f64::consts::TAU / f64::from(count);
        let (below, above) = ((count as i64 - 1) / 2, count as i64 / 2);
        let (lo, hi, beyond) = match self.window(id) {
            Some(w) if w.beyond.is_finite() => {
                let r = i64::from(w.reach[0]);
                (-r, r, Some(w.beyond))
            }
            Some(_) => (-below, above, None),
            // No window: the analysis found none that bounds the field (reported), or there
            // is no analysis; the sector and its neighbours.
            None => (-below.min(1), above.min(1), None),
        };
        let b = &mut *self.b;
        let nz = b.neg(p[2]);
        let phi = b.bin(Binary::Atan2, nz, p[0]);
        let u = b.mulc(phi, 1.0 / step);
        let k = b.un(Unary::Round, u);
        // The point rotated into its own sector once (one cosine and one sine a point); the
        // other copies of the window are that point turned by constant rotations.
        let theta = b.mulc(k, step);
        let (c, s) = (b.un(Unary::Cos, theta), b.un(Unary::Sin, theta));
        let own = rot2(b, c, s, p[0], p[2]);
        let mut acc: Option<Field> = None;
        for j in lo..=hi {
            let b = &mut *self.b;
            let (x, mut z) = match j {
                0 => own,
                _ => {
                    let turn = j as f64 * step;
                    rot2c(b, turn.cos(), turn.sin(), own.0, own.1)
                }
            };
            if mirror {
                let kj = b.addc(k, j as f64);
                // The copy's parity: kj − 2·⌊kj/2⌋, with ⌊kj/2⌋ = round(kj/2 − 1/4).
                let half = b.mulc(kj, 0.5);
                let half = b.subc(half, 0.25);
                let floor = b.un(Unary::Round, half);
                let twice = b.mulc(floor, 2.0);
                let odd = b.sub(kj, twice);
                let sign = b.mulc(odd, -2.0);
                let sign = b.addc(sign, 1.0);
                z = b.mul(z, sign);
            }
            let f = self.node(child, [x, p[1], z]);
            acc = Some(self.fold(acc, f));
        }
        self.resume(id, self.graph.node(id));
        let f = acc.expect("a window holds the own sector");
        let Some(sin_gamma) = beyond else { return f };
        let b = &mut *self.b;
        let rho = b.len2(p[0], p[2]);
        let mut cap = b.mulc(rho, sin_gamma);
        if let Some(a) = self.config.analysis {
            // Every copy lies in the repetition's box, so the distance to the box is a lower
            // bound too, and the field stays above it as a bound's guarantee requires. The
            // box comes from the analysis, which every lowering has, so that the field does
            // not depend on whether culling volumes were computed.
            let bounds = a.node(id).bounds;
            let axes: Vec<usize> = (0..3)
                .filter(|&i| bounds.min[i].is_finite() && bounds.max[i].is_finite())
                .collect();
            if !axes.is_empty() {
                let extent = axes
                    .iter()
                    .map(|&i| bounds.min[i].abs().max(bounds.max[i].abs()))
                    .fold(0.0, f64::max);
                let b = &mut *self.b;
                let mut sum: Option<Reg> = None;
                for &i in &axes {
                    let above = b.subc(p[i], bounds.max[i]);
                    let below = b.subc(p[i], bounds.min[i]);
                    let below = b.neg(below);
                    let out = b.max(above, below);
                    let out = b.maxc(out, 0.0);
                    let sq = b.mul(out, out);
                    sum = Some(match sum {
                        Some(s) => b.add(s, sq),
                        None => sq,
                    });
                }
                let d = b.sqrt(sum.expect("an axis"));
                // A margin for the rounding of f32 evaluation.
                let d = b.subc(d, 1e-4 * (1.0 + extent));
                cap = b.max(cap, d);
            }
        }
        Field {
            d: self.b.min(f.d, cap),
            m: f.m,
        }
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

    /// `max(f / l, β)` for node `id`'s field `f` and β the distance to its bound; where not
    /// `used` (a parametric program's operand whose L is 1 in this frame), both and `f`
    /// chosen by a constant, so that the program has the shape of the frames that use it.
    fn local_bound(&mut self, id: NodeId, l: f64, p: P, used: bool) -> Field {
        self.zero_set = false;
        let f = self.node(id, p);
        self.zero_set = true;
        // A parametric program's comments name no number: the kernel's text is a function of
        // the frame's structure.
        let l_text = if self.b.parametric {
            "L".to_string()
        } else {
            format!("L = {}", crate::scene::dump_num(l))
        };
        let text = format!(
            "node {} local bound: the field divided by its {l_text}, at least the distance to its bound",
            self.number(id),
        );
        self.b.note(text);
        let scaled = self.b.mulc(f.d, 1.0 / l);
        let d = match self.config.bounds.and_then(|b| b.get(id)) {
            Some(bound) => {
                // Both the guard distance of the node's own bound and that of its box: a
                // union's guards skip the node where either is not nearer than the best
                // distance (its own guard, and the boxes of the groups around it), and the
                // result must then not be nearer either, so that culling keeps the field.
                let beta = bound_distance(self.b, &bound, p);
                let (slab, _) = slab_distance(self.b, &bound, None, p);
                let d = self.b.max(scaled, beta);
                self.b.max(d, slab)
            }
            None => scaled,
        };
        if self.b.parametric {
            let c = self.b.c(if used { 1.0 } else { 0.0 });
            let d = self.b.select(c, d, f.d);
            return Field { d, m: f.m };
        }
        Field { d, m: f.m }
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
            Node::Paint { material, child } => {
                let f = self.node(*child, p);
                self.resume(id, node);
                Field {
                    d: f.d,
                    m: self.b.paint(f.m, material.0 as f64),
                }
            }
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
            Node::Shear { matrix, child } => {
                // f(S⁻¹p)·σmin(S): a bound with the child's L (docs/analysis.md).
                let inverse = analysis::invert(matrix).unwrap_or(IDENTITY);
                let (smin, _) = crate::scene::bounds::singular_range(matrix);
                let transposed = [0, 1, 2].map(|i| [0, 1, 2].map(|j| inverse[j][i]));
                let q = rotate(self.b, p, &transposed);
                self.post(id, *child, q, |b, d| b.mulc(d, smin))
            }
            Node::Taper { rate, child } => {
                // f(x/s, y, z/s)·s with s = 1 + rate·y, clamped above 0 where the taper folds.
                let b = &mut *self.b;
                let s = b.mulc(p[1], *rate);
                let s = b.addc(s, 1.0);
                let s = b.maxc(s, analysis::TAPER_FLOOR);
                let q = [b.div(p[0], s), p[1], b.div(p[2], s)];
                self.post(id, *child, q, |b, d| b.mul(d, s))
            }
            Node::Morph { t, a, b } => {
                let (fa, fb) = (self.node(*a, p), self.node(*b, p));
                self.resume(id, node);
                let wa = self.b.mulc(fa.d, 1.0 - t);
                let wb = self.b.mulc(fb.d, *t);
                Field {
                    d: self.b.add(wa, wb),
                    m: self.material(Combine::Union, fa, fb),
                }
            }
            Node::Field { f, .. } => self.field(id, f, p),
            Node::Extrude {
                half_height,
                round,
                child,
            } => {
                // The profile is read in the plane z = 0.
                let (h, r) = (*half_height, *round);
                let q = [p[0], p[1], self.b.c(0.0)];
                self.post(id, *child, q, |b, d| {
                    if r > 0.0 {
                        let d = b.addc(d, r);
                        let e = crate::prim::extrude(b, d, p[2], h - r);
                        b.subc(e, r)
                    } else {
                        crate::prim::extrude(b, d, p[2], h)
                    }
                })
            }
            Node::Revolve { offset, child } => {
                let b = &mut *self.b;
                let r = b.len2(p[0], p[2]);
                let x = b.subc(r, *offset);
                let q = [x, p[1], b.c(0.0)];
                let f = self.node(*child, q);
                Field { d: f.d, m: f.m }
            }
            Node::Loft {
                half_height,
                spread,
                bottom,
                top,
            } => {
                // Both profiles in the plane z = 0, mixed by the height's fraction t, the
                // difference clamped to ±spread (docs/analysis.md, "Loft"), then extruded.
                let (h, s) = (*half_height, *spread);
                let q = [p[0], p[1], self.b.c(0.0)];
                let (fa, fb) = (self.node(*bottom, q), self.node(*top, q));
                self.resume(id, node);
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
            } => {
                // The profile read in its plane z = 0 at the point's place about the path.
                let hit = super::sweep::locate(self.b, p, &path.0);
                let q = [hit.u, hit.v, self.b.c(0.0)];
                let f = self.node(*child, q);
                self.resume(id, node);
                let d = super::sweep::finish(self.b, f.d, &hit, *inner, *extent);
                Field { d, m: f.m }
            }
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

    /// Union, intersection or subtraction of any number of children, left to right.
    fn combine(&mut self, id: NodeId, op: Combine, children: &[NodeId], p: P) -> Field {
        let fields: Vec<Field> = children.iter().map(|&c| self.node(c, p)).collect();
        self.resume(id, self.graph.node(id));
        let Some((&first, rest)) = fields.split_first() else {
            return Field {
                d: self.b.c(EMPTY_DISTANCE),
                m: self.b.c(UNPAINTED),
            };
        };
        rest.iter().fold(first, |acc, &f| {
            let d = match op {
                Combine::Union => self.b.min(acc.d, f.d),
                Combine::Intersect => self.b.max(acc.d, f.d),
                Combine::Subtract => {
                    let nb = self.b.neg(f.d);
                    self.b.max(acc.d, nb)
                }
            };
            Field {
                d,
                m: self.material(op, acc, f),
            }
        })
    }

    /// An optimised union: unbounded children first, then children bounded by a slab one by
    /// one, then the hierarchy of the children with finite bounds, each group guarded by its
    /// bound where culling is on.
    fn union(&mut self, id: NodeId, children: &[NodeId], p: P) -> Field {
        let Some(bounds) = self.config.bounds else {
            return self.combine(id, Combine::Union, children, p);
        };
        self.share_rotations(children, p);
        let (mut free, mut slabs, mut finite) = (Vec::new(), Vec::new(), Vec::new());
        for (index, &c) in children.iter().enumerate() {
            let item = |bound| bvh::Item {
                id: c,
                bound,
                cost: bounds.cost(c),
                index,
            };
            match self.guard_bound(bounds, c) {
                None => free.push(c),
                Some(b) if b.finite() => finite.push(item(b)),
                Some(b) => slabs.push(item(b)),
            }
        }
        let mut acc = None;
        for c in free {
            let f = self.node(c, p);
            acc = Some(self.fold(acc, f));
        }
        let shape = if self.b.parametric {
            bvh::Shape::Fixed
        } else {
            bvh::Shape::Sah {
                eye: self.config.camera,
            }
        };
        let tree = (!finite.is_empty()).then(|| bvh::build(finite, shape));
        let split = tree
            .as_ref()
            .is_some_and(|t| matches!(t.kind, Kind::Split(..)));
        // The upper bound costs one child per point (the cheapest of a leaf): not where that
        // is a child as costly as a Voronoi cell, whose code it would also copy.
        let cheap = tree
            .as_ref()
            .is_some_and(|t| descent_cost(t) <= DESCENT_BUDGET);
        let upper = (self.config.cull && split && cheap)
            .then(|| tree.as_ref().map(|t| self.descend(t, p)))
            .flatten()
            .map(|u| {
                // Raised a little above the child it is: the guards compare bounds with it,
                // and a child whose field equals its own bound (a local bound at the
                // distance to its volume) must not be skipped by a tie with itself, as it
                // is not yet in the union's accumulated field.
                let b = &mut *self.b;
                let a = b.abs(u);
                let a = b.mulc(a, 1.0 / 1_048_576.0);
                let a = b.addc(a, 1e-30);
                b.add(u, a)
            });
        if acc.is_none() && (split || !slabs.is_empty()) {
            // A starting value, so that every group can be guarded (the same with culling
            // off, so that both programs compute the same).
            acc = Some(Field {
                d: self.b.c(EMPTY_DISTANCE),
                m: self.b.c(UNPAINTED),
            });
        }
        for item in slabs {
            self.child(id, &item, p, &mut acc, true, upper);
        }
        if let Some(tree) = &tree {
            self.tree(id, tree, None, p, &mut acc, upper);
        }
        acc.unwrap_or_else(|| Field {
            d: self.b.c(EMPTY_DISTANCE),
            m: self.b.c(UNPAINTED),
        })
    }

    /// An upper bound of a hierarchy's union at `p` ([`descent_cost`] at most
    /// [`DESCENT_BUDGET`]): the distance of one child of the group
    /// found by descending from the root into the half on the point's side of each splitting
    /// plane. Any child's distance is at least the union's, so the guards may compare with it
    /// before the nearest child is reached.
    fn descend(&mut self, t: &Tree, p: P) -> Reg {
        if self.b.over() {
            return p[0];
        }
        match &t.kind {
            Kind::Leaf(items) => {
                // One child is enough for an upper bound: the cheapest.
                let cheapest = items
                    .iter()
                    .min_by(|a, b| a.cost.total_cmp(&b.cost).then(a.index.cmp(&b.index)));
                match cheapest {
                    Some(item) => self.node(item.id, p).d,
                    None => self.b.c(f64::INFINITY),
                }
            }
            Kind::Split(a, b, plane) => {
                // The half on the point's side of the plane between the halves.
                let at = self.b.c(plane.at);
                let x = p[plane.axis];
                let (a_side, b_side) = if plane.first_low { (x, at) } else { (at, x) };
                let none = self.b.c(f64::INFINITY);
                let first = self.b.open_block(a_side, b_side);
                let ua = self.descend(a, p);
                let ua = self.b.close_block(first, &[(ua, none)])[0];
                let second = self.b.open_block(b_side, a_side);
                let ub = self.descend(b, p);
                self.b.close_block(second, &[(ub, ua)])[0]
            }
        }
    }

    /// Adds a field to a union's accumulated field.
    fn fold(&mut self, acc: Option<Field>, f: Field) -> Field {
        match acc {
            None => f,
            Some(a) => Field {
                d: self.b.min(a.d, f.d),
                m: self.material(Combine::Union, a, f),
            },
        }
    }

    /// Evaluates one child of a union into `acc`, guarded by its bound when `alone` (not
    /// already inside a guard of its own) and worth it.
    fn child(
        &mut self,
        id: NodeId,
        item: &bvh::Item,
        p: P,
        acc: &mut Option<Field>,
        alone: bool,
        upper: Option<Reg>,
    ) {
        if self.b.over() {
            return;
        }
        if alone && self.guards(acc, item.cost) {
            let text = format!("node {} union: child culled by its bound", self.number(id));
            self.b.note(text);
            let beta = bound_distance(self.b, &item.bound, p);
            self.guarded(beta, p, acc, upper, |me, acc| {
                me.child(id, item, p, acc, false, upper)
            });
            return;
        }
        let f = self.node(item.id, p);
        *acc = Some(self.fold(*acc, f));
    }

    /// Whether a subtree of this cost gets a guard (there must be a best distance already).
    fn guards(&self, acc: &Option<Field>, cost: f64) -> bool {
        self.config.cull && acc.is_some() && cost >= GUARD_COST
    }

    /// Evaluates a node of a union's hierarchy into `acc`; `tested` is what the guards above
    /// have computed already.
    fn tree(
        &mut self,
        id: NodeId,
        t: &Tree,
        tested: Option<Tested>,
        p: P,
        acc: &mut Option<Field>,
        upper: Option<Reg>,
    ) {
        if self.b.over() {
            return;
        }
        if !self.guards(acc, t.cost) {
            return self.tree_body(id, t, tested, p, acc, upper);
        }
        let n = leaves(t);
        let text = format!(
            "node {} union: group of {n} children culled by its bound",
            self.number(id)
        );
        self.b.note(text);
        let (beta, tested) = slab_distance(self.b, &t.bound, tested.as_ref(), p);
        self.guarded(beta, p, acc, upper, |me, acc| {
            me.tree_body(id, t, Some(tested), p, acc, upper)
        });
    }

    fn tree_body(
        &mut self,
        id: NodeId,
        t: &Tree,
        tested: Option<Tested>,
        p: P,
        acc: &mut Option<Field>,
        upper: Option<Reg>,
    ) {
        match &t.kind {
            Kind::Leaf(items) => {
                for item in items {
                    self.child(id, item, p, acc, items.len() > 1, upper);
                }
            }
            Kind::Split(a, b, _) => {
                self.tree(id, a, tested, p, acc, upper);
                self.tree(id, b, tested, p, acc, upper);
            }
        }
    }

    /// Runs `body` in a block guarded by the bound distance `beta`: where it is not nearer
    /// than the accumulated distance (or the upper bound of the union, when known), the
    /// block is skipped and `acc` keeps its value.
    fn guarded(
        &mut self,
        beta: Reg,
        p: P,
        acc: &mut Option<Field>,
        upper: Option<Reg>,
        body: impl FnOnce(&mut Self, &mut Option<Field>),
    ) {
        let _ = p;
        let Some(outer) = *acc else {
            return body(self, acc);
        };
        let best = match upper {
            Some(u) => self.b.min(outer.d, u),
            None => outer.d,
        };
        let block = self.b.open_block(beta, best);
        let mut inner = Some(outer);
        body(self, &mut inner);
        let inner = inner.unwrap_or(outer);
        let r = self
            .b
            .close_block(block, &[(inner.d, outer.d), (inner.m, outer.m)]);
        *acc = Some(Field { d: r[0], m: r[1] });
    }

    /// Computes, before the children of a union, the rotated point Mᵀp of every rotation
    /// that two or more children start with, so that they share it.
    fn share_rotations(&mut self, children: &[NodeId], p: P) {
        if self.b.parametric {
            // Which rotations are equal is a matter of numbers.
            return;
        }
        let mut count: HashMap<[u64; 9], (usize, [V3; 3])> = HashMap::new();
        for &c in children {
            if let Some(m) = self.leading_rotation(c) {
                let key = [0, 1, 2, 3, 4, 5, 6, 7, 8].map(|k| m[k / 3][k % 3].to_bits());
                count.entry(key).or_insert((0, m)).0 += 1;
            }
        }
        let mut shared: Vec<_> = count.into_iter().filter(|(_, (n, _))| *n >= 2).collect();
        shared.sort_by_key(|(k, _)| *k);
        for (_, (_, m)) in shared {
            rotate(self.b, p, &m);
        }
    }

    /// The rotation a node starts with, under paint and a translation.
    fn leading_rotation(&self, mut id: NodeId) -> Option<[V3; 3]> {
        loop {
            match self.graph.node(id) {
                Node::Paint { child, .. } | Node::Translate { child, .. } => id = *child,
                Node::Rotate { matrix, .. } => return Some(*matrix),
                _ => return None,
            }
        }
    }

    /// The material of a combination: a union takes the nearer child's, an intersection the
    /// farther child's (the one whose surface it is), a subtraction keeps the first child's.
    fn material(&mut self, op: Combine, a: Field, f: Field) -> Reg {
        let b = &mut *self.b;
        match op {
            Combine::Union => {
                let nearer = b.lt(f.d, a.d);
                b.select(nearer, f.m, a.m)
            }
            Combine::Intersect => {
                let farther = b.lt(a.d, f.d);
                b.select(farther, f.m, a.m)
            }
            Combine::Subtract => a.m,
        }
    }

    /// A smooth combination of two children.
    fn smooth(
        &mut self,
        id: NodeId,
        op: Combine,
        k: f64,
        v: Smooth,
        ch: [NodeId; 2],
        p: P,
    ) -> Field {
        let fa = self.node(ch[0], p);
        let fb = self.node(ch[1], p);
        self.resume(id, self.graph.node(id));
        let b = &mut *self.b;
        // k = 0 is the plain combination. A sequence's frames keep the blend's formula at
        // every k (a radius passing through 0 keeps one structure), at a radius of at least
        // LEAST_BLEND, and choose the plain combination by a constant where k is 0.
        let kb = if b.parametric { k.max(LEAST_BLEND) } else { k };
        let blend = if kb > 0.0 {
            blends::combine(b, op, fa.d, fb.d, kb, v)
        } else {
            None
        };
        let d = match (blend, op) {
            (Some(d), _) => d,
            (None, Combine::Union) => smin(b, fa.d, fb.d, kb, v),
            (None, Combine::Intersect) => smax(b, fa.d, fb.d, kb, v),
            (None, Combine::Subtract) => {
                let nb = b.neg(fb.d);
                smax(b, fa.d, nb, kb, v)
            }
        };
        let d = if b.parametric {
            let plain = match op {
                Combine::Union => b.min(fa.d, fb.d),
                Combine::Intersect => b.max(fa.d, fb.d),
                Combine::Subtract => {
                    let nb = b.neg(fb.d);
                    b.max(fa.d, nb)
                }
            };
            let at_zero = b.c(if k > 0.0 { 0.0 } else { 1.0 });
            b.select(at_zero, plain, d)
        } else {
            d
        };
        Field {
            d,
            m: self.material(op, fa, fb),
        }
    }
}

impl Lowerer<'_> {
    /// A feature of `a` along the surface of `b`; the result has `a`'s material.
    fn feature(&mut self, id: NodeId, f: Feature, ch: [NodeId; 2], p: P) -> Field {
        let fa = self.node(ch[0], p);
        let fb = self.node(ch[1], p);
        self.resume(id, self.graph.node(id));
        Field {
            d: blends::feature(self.b, f, fa.d, fb.d),
            m: fa.m,
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

/// Whether only the zero set of a node's children matters when only its own does: true for
/// plain combinations (a minimum or maximum of bounds is a bound), paint, translation,
/// rotation and uniform scale; false where the children's values are read (offsets, smooth
/// combinations) or the point map stretches (repetition, twist, bend, per-axis scale).
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

/// The most a union's upper bound ([`Lowerer::descend`]) may cost at a leaf: a few guards.
const DESCENT_BUDGET: f64 = 192.0;

/// The most costly child [`Lowerer::descend`] evaluates at a leaf of `t` (the cheapest of
/// each leaf).
fn descent_cost(t: &Tree) -> f64 {
    match &t.kind {
        Kind::Leaf(items) => items.iter().map(|i| i.cost).fold(f64::INFINITY, f64::min),
        Kind::Split(a, b, _) => descent_cost(a).max(descent_cost(b)),
    }
}
/// The number of children below a node of a hierarchy.
fn leaves(t: &Tree) -> usize {
    match &t.kind {
        Kind::Leaf(items) => items.len(),
        Kind::Split(a, b, _) => leaves(a) + leaves(b),
    }
}

/// A lower bound of the field of a node with bound `b` at `p`: the signed distance `s` to the
/// sphere, or a lower bound of it for the box (the largest of the per-axis distances, over
/// its finite axes), with the volume padded by 10⁻³ of its size plus 10⁻⁴·(1 + |centre|),
/// then `SHRINK·s` (scale 1) or `min(s, SHRINK·scale·s)`. The padding and the shrinking
/// cover the rounding of both this value and the field (`docs/optimisation.md`).
fn bound_distance(b: &mut Builder, bound: &Bound, p: P) -> Reg {
    let (box_volume, sphere_volume) = bound.volumes();
    let sphere = |b: &mut Builder| {
        let sp = bound.sphere;
        let pad = 1e-3 * sp.r + 1e-4 * (1.0 + DVec3::from(sp.c).length());
        let q = b.sub3c(p, sp.c);
        let l = b.len3(q);
        let s = b.subc(l, sp.r + pad);
        shrink(b, s, bound.scale)
    };
    let axes: Vec<usize> = (0..3).filter(|&i| bound.aabb.h[i].is_finite()).collect();
    let use_sphere = bound.finite() && sphere_volume <= 1.5 * box_volume;
    if bound.finite() && b.parametric {
        // Which volume is the smaller is a matter of numbers: both, and the choice a
        // constant (the same distance as the usual program's).
        let s = sphere(b);
        let x = box_distance(b, bound, &axes, p);
        let c = b.c(if use_sphere { 1.0 } else { 0.0 });
        return b.select(c, s, x);
    }
    if use_sphere {
        return sphere(b);
    }
    box_distance(b, bound, &axes, p)
}

/// What the guards on the path to a hierarchy node have computed: the box they narrowed the
/// point to, and per axis the registers of the last per-axis distance computed (to a box
/// containing the node's, so a lower bound of the distance to the node's box along that
/// axis) and of its positive part squared.
#[derive(Debug, Clone, Copy)]
struct Tested {
    region: Aabb,
    terms: [Option<(Reg, Reg)>; 3],
}

/// The bound distance of a hierarchy node: the distance to its box, `|max(q, 0)| +
/// min(max q_i, 0)` with `q_i` the per-axis distance, computed afresh along the axes where the
/// box is narrower than the region tested above (by a tenth) and taken from the guards above
/// along the others. The distance along an axis to a larger box is a lower bound of the one to
/// this box, and the formula grows with every `q_i`, so the result is a lower bound of the
/// distance to the box. Returns the distance and what the guards below will know.
fn slab_distance(b: &mut Builder, bound: &Bound, tested: Option<&Tested>, p: P) -> (Reg, Tested) {
    let (c, h) = (bound.aabb.c, bound.aabb.h);
    let mut state = tested.copied().unwrap_or(Tested {
        region: bound.aabb,
        terms: [None; 3],
    });
    let parametric = b.parametric;
    let fresh = |i: usize| match tested {
        // Whether a box is narrower than the region tested is a matter of numbers: every
        // finite axis afresh (a distance to the node's own box is as low a bound).
        _ if parametric => h[i].is_finite(),
        None => h[i].is_finite(),
        Some(t) => {
            let margin = 0.1 * t.region.h[i];
            c[i] - h[i] > t.region.c[i] - t.region.h[i] + margin
                || c[i] + h[i] < t.region.c[i] + t.region.h[i] - margin
        }
    };
    let size = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
    let pad = 1e-3 * size + 1e-4 * (1.0 + DVec3::from(c).length());
    for i in (0..3).filter(|&i| fresh(i)) {
        let d = b.subc(p[i], c[i]);
        let d = b.abs(d);
        let q = b.subc(d, h[i] + pad);
        let o = b.maxc(q, 0.0);
        state.terms[i] = Some((q, b.mul(o, o)));
        state.region.c[i] = c[i];
        state.region.h[i] = h[i];
    }
    let terms: Vec<(Reg, Reg)> = state.terms.iter().flatten().copied().collect();
    let s = match terms.split_first() {
        None => b.c(f64::NEG_INFINITY),
        Some((&(q0, o0), rest)) => {
            let (q, o) = rest
                .iter()
                .fold((q0, o0), |(q, o), &(qi, oi)| (b.max(q, qi), b.add(o, oi)));
            let outside = b.sqrt(o);
            let inside = b.minc(q, 0.0);
            b.add(outside, inside)
        }
    };
    (shrink(b, s, bound.scale), state)
}

/// The largest per-axis distance to the box over `axes` (a lower bound of the distance to
/// the box), padded and shrunk.
fn box_distance(b: &mut Builder, bound: &Bound, axes: &[usize], p: P) -> Reg {
    let bx = bound.aabb;
    let size = axes.iter().map(|&i| bx.h[i] * bx.h[i]).sum::<f64>().sqrt();
    let centre = axes.iter().map(|&i| bx.c[i] * bx.c[i]).sum::<f64>().sqrt();
    let pad = 1e-3 * size + 1e-4 * (1.0 + centre);
    let per_axis: Vec<Reg> = axes
        .iter()
        .map(|&i| {
            let d = b.subc(p[i], bx.c[i]);
            let d = b.abs(d);
            b.subc(d, bx.h[i] + pad)
        })
        .collect();
    let s = per_axis
        .into_iter()
        .reduce(|x, y| b.max(x, y))
        .unwrap_or_else(|| b.c(f64::NEG_INFINITY));
    shrink(b, s, bound.scale)
}

/// `SHRINK·s` for a bound of scale 1, else `min(s, SHRINK·scale·s)`.
fn shrink(b: &mut Builder, s: Reg, scale: f64) -> Reg {
    if b.parametric {
        // Whether the scale is 1 is a matter of numbers: both, and the choice a constant.
        let one = b.mulc(s, SHRINK);
        let t = b.mulc(s, SHRINK * scale);
        let less = b.min(s, t);
        let c = b.c(if scale >= 1.0 { 1.0 } else { 0.0 });
        return b.select(c, one, less);
    }
    if scale >= 1.0 {
        b.mulc(s, SHRINK)
    } else {
        let t = b.mulc(s, SHRINK * scale);
        b.min(s, t)
    }
}

/// The least blend radius of a parametric program's smooth combinations: at k = 0 the blend
/// is computed at this radius (and not chosen), so that its formula stays that of every other
/// k and its values finite: its reciprocal is far inside f32's range.
const LEAST_BLEND: f64 = 1e-12;

/// The smooth minimum. Poly: h = max(k - |a - b|, 0) / k, min(a, b) - h²·k/4 (Quilez's
/// quadratic). Exp: -k·ln(e^(-a/k) + e^(-b/k)), computed as m - k·ln(e^((m-a)/k) + e^((m-b)/k))
/// with m = min(a, b) so that it cannot overflow. k ≤ 0 is the plain minimum. (hg_sdf's
/// variants are `blends::combine`'s: they never come here with k > 0.)
fn smin(b: &mut Builder, x: Reg, y: Reg, k: f64, v: Smooth) -> Reg {
    if k <= 0.0 {
        return b.min(x, y);
    }
    let m = b.min(x, y);
    match v {
        Smooth::Poly => {
            let h = poly_h(b, x, y, k);
            b.sub(m, h)
        }
        Smooth::Exp => {
            let s = exp_sum(b, m, x, y, k);
            b.sub(m, s)
        }
        _ => m,
    }
}

/// The smooth maximum, -smin(-a, -b): max(a, b) + h²·k/4, or M + k·ln(e^((a-M)/k) + e^((b-M)/k)).
fn smax(b: &mut Builder, x: Reg, y: Reg, k: f64, v: Smooth) -> Reg {
    if k <= 0.0 {
        return b.max(x, y);
    }
    let m = b.max(x, y);
    match v {
        Smooth::Poly => {
            let h = poly_h(b, x, y, k);
            b.add(m, h)
        }
        Smooth::Exp => {
            let s = exp_sum(b, m, x, y, k);
            b.add(m, s)
        }
        _ => m,
    }
}

/// h²·k/4 with h = max(k - |a - b|, 0) / k.
fn poly_h(b: &mut Builder, x: Reg, y: Reg, k: f64) -> Reg {
    let diff = b.sub(x, y);
    let diff = b.abs(diff);
    let kc = b.c(k);
    let h = b.sub(kc, diff);
    let h = b.maxc(h, 0.0);
    let h = b.mulc(h, 1.0 / k);
    let h2 = b.mul(h, h);
    b.mulc(h2, k * 0.25)
}

/// k·ln(e^(-|x-m|/k) + e^(-|y-m|/k)): the correction term of both exponential variants
/// (m is the min or the max of x and y, so both exponents are ≤ 0).
fn exp_sum(b: &mut Builder, m: Reg, x: Reg, y: Reg, k: f64) -> Reg {
    let mut term = |r: Reg| {
        let d = b.sub(r, m);
        let d = b.abs(d);
        let d = b.mulc(d, -1.0 / k);
        b.un(Unary::Exp, d)
    };
    let (ex, ey) = (term(x), term(y));
    let s = b.add(ex, ey);
    let l = b.un(Unary::Log, s);
    b.mulc(l, k)
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
