//! Combinations: unions, intersections and subtractions, and the union's bounding volume
//! hierarchy of guarded groups (its children ordered, guarded and bounded from above), with
//! the material each combination keeps.

use super::bounds::{bound_distance, slab_distance, Tested};
use super::{Field, Lowerer, GUARD_COST, UNPAINTED};
use crate::lower::bvh::{self, Kind, Tree};
use crate::lower::shapes::rotate;
use crate::lower::{Reg, EMPTY_DISTANCE};
use crate::program::builder::P;
use crate::scene::{Combine, Node, NodeId, V3};
use std::collections::HashMap;

impl Lowerer<'_> {
    /// Union, intersection or subtraction of any number of children, left to right.
    pub(super) fn combine(&mut self, id: NodeId, op: Combine, children: &[NodeId], p: P) -> Field {
        let uncut = match op {
            Combine::Intersect => self.uncut(id),
            _ => Vec::new(),
        };
        let fields: Vec<Field> = children
            .iter()
            .filter(|c| !uncut.contains(c))
            .map(|&c| self.node(c, p))
            .collect();
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
    pub(super) fn union(&mut self, id: NodeId, children: &[NodeId], p: P) -> Field {
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
    pub(super) fn fold(&mut self, acc: Option<Field>, f: Field) -> Field {
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
    pub(super) fn material(&mut self, op: Combine, a: Field, f: Field) -> Reg {
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
