//! Simplification of the scene graph before lowering (optimisation level 1): every rewrite is
//! an identity of the fields (equal up to rounding), and the result is a new graph holding
//! only the nodes the root reaches (dead nodes are never copied).
//!
//! - Identities vanish: translation by 0, rotation by the identity, scaling by 1, rounding
//!   by 0, twist and bend at rate 0, elongation by 0, repetition with one copy, mirroring of
//!   a shape that is already symmetric, a combination of one child.
//! - Transforms compose: nested translations, rotations and uniform scales become at most
//!   one of each, in the order translate(rotate(scale(x))); paint moves outside them.
//! - Primitives absorb what they can exactly: a rotation they are symmetric under (any for
//!   a sphere, about y for the shapes of revolution, quarter turns for boxes and
//!   ellipsoids, which permute their extents), a uniform scale (into their sizes; a shape
//!   between two points, into its points and radii), rounding
//!   (into a sphere's, capsule's or torus's radius), and a plane absorbs any rigid motion.
//! - Unions flatten: a union inside a union (also through paint, translation, rotation and
//!   uniform scale, which distribute over a union) gives its children to the outer one;
//!   repeated children are dropped; paint on a shape painted everywhere is dropped.
//! - A smooth combination with k ≤ 0 is the plain combination.

use crate::scene::{mat_vec, Combine, Graph, MaterialId, Node, NodeId, V3};
use glam::DVec3;
use std::collections::{HashMap, HashSet};

/// A simplified scene graph.
#[derive(Debug)]
pub(super) struct Simple {
    /// The new graph (children before parents).
    pub graph: Graph,
    /// Its root.
    pub root: NodeId,
    /// For every new node, the node of the original graph it comes from (for comments and
    /// spans).
    pub origin: Vec<NodeId>,
}

/// Simplifies the graph below `root`.
pub(super) fn simplify(graph: &Graph, root: NodeId, parametric: bool) -> Simple {
    let mut s = Simplifier {
        parametric,
        src: graph,
        out: Graph::default(),
        origin: Vec::new(),
        memo: HashMap::new(),
        current: root,
    };
    let root = s.node(root);
    Simple {
        graph: s.out,
        root,
        origin: s.origin,
    }
}

/// Entries below this are taken as 0 in rotation matrices (rounding noise of quarter turns).
const TINY: f64 = 1e-12;

#[derive(Debug)]
struct Simplifier<'a> {
    /// Only rewrites that do not depend on a number's value (`LowerOptions::parametric`):
    /// identities stay, and rotations are absorbed only by spheres and planes.
    parametric: bool,
    src: &'a Graph,
    out: Graph,
    origin: Vec<NodeId>,
    memo: HashMap<NodeId, NodeId>,
    /// The original node being simplified (the origin of new nodes).
    current: NodeId,
}

impl Simplifier<'_> {
    /// Adds a node to the new graph.
    fn add(&mut self, node: Node) -> NodeId {
        let id = self.out.add(node, self.src.span(self.current));
        if id.0 as usize == self.origin.len() {
            self.origin.push(self.current);
        }
        id
    }

    fn get(&self, id: NodeId) -> Node {
        self.out.node(id).clone()
    }

    /// The simplified form of an original node.
    fn node(&mut self, id: NodeId) -> NodeId {
        if let Some(&n) = self.memo.get(&id) {
            return n;
        }
        let saved = std::mem::replace(&mut self.current, id);
        let n = self.rebuild(self.src.node(id).clone());
        self.current = saved;
        self.memo.insert(id, n);
        n
    }

    fn rebuild(&mut self, node: Node) -> NodeId {
        match node {
            Node::Combine { op, children } => {
                let kids: Vec<NodeId> = children.iter().map(|&c| self.node(c)).collect();
                self.combine(op, kids)
            }
            Node::SmoothCombine {
                op,
                k,
                variant,
                a,
                b,
            } => {
                let (a, b) = (self.node(a), self.node(b));
                if k <= 0.0 && !self.parametric {
                    return self.combine(op, vec![a, b]);
                }
                self.add(Node::SmoothCombine {
                    op,
                    k,
                    variant,
                    a,
                    b,
                })
            }
            Node::Morph { t, a, b } => {
                let (a, b) = (self.node(a), self.node(b));
                if !self.parametric && (t == 0.0 || a == b) {
                    return a;
                }
                if !self.parametric && t == 1.0 {
                    return b;
                }
                self.add(Node::Morph { t, a, b })
            }
            Node::Feature { op, a, b } => {
                let (a, b) = (self.node(a), self.node(b));
                self.add(Node::Feature { op, a, b })
            }
            Node::Loft {
                half_height,
                spread,
                bottom,
                top,
            } => {
                let (bottom, top) = (self.node(bottom), self.node(top));
                self.add(Node::Loft {
                    half_height,
                    spread,
                    bottom,
                    top,
                })
            }
            Node::Translate { offset, child } => {
                let c = self.node(child);
                self.translate(offset, c)
            }
            Node::Rotate { matrix, child } => {
                let c = self.node(child);
                self.rotate(matrix, c)
            }
            Node::Scale { factor, child } => {
                let c = self.node(child);
                self.scale(factor, c)
            }
            Node::Round { radius, child } => {
                let c = self.node(child);
                self.round(radius, c)
            }
            Node::Paint { material, child } => {
                let c = self.node(child);
                self.paint(material, c)
            }
            Node::Field {
                f,
                lipschitz,
                plane,
            } => {
                let f = f.remap(|id| self.node(id));
                self.add(Node::Field {
                    f,
                    lipschitz,
                    plane,
                })
            }
            other => self.unary(other),
        }
    }

    /// The remaining nodes: primitives, and operations that are simplified only when they
    /// do nothing.
    fn unary(&mut self, node: Node) -> NodeId {
        let children = node.children();
        let Some(&child) = children.first() else {
            return self.add(node);
        };
        let c = self.node(child);
        if let Node::Paint { material, child } = self.get(c) {
            // Paint moves outside: the material does not depend on the point.
            let inner = self.unary_on(node, child);
            return self.paint(material, inner);
        }
        self.unary_on(node, c)
    }

    /// `node` rebuilt over the simplified child `c`, or `c` where the node does nothing.
    fn unary_on(&mut self, node: Node, c: NodeId) -> NodeId {
        let node = match node {
            Node::ScaleXyz { factors, .. }
                if factors[0] == factors[1] && factors[1] == factors[2] && !self.parametric =>
            {
                return self.scale(factors[0], c)
            }
            Node::Repeat { period, count, .. } => {
                let period = [0, 1, 2].map(|i| match count {
                    Some(n) if n[i] <= 1.0 => 0.0,
                    _ => period[i],
                });
                if period == [0.0; 3] && !self.parametric {
                    return c;
                }
                Node::Repeat {
                    period,
                    count,
                    child: c,
                }
            }
            Node::Mirror { axes, .. } => {
                let axes = [0, 1, 2].map(|i| axes[i] && !self.symmetric(c, i));
                if axes == [false; 3] {
                    return c;
                }
                Node::Mirror { axes, child: c }
            }
            Node::Twist { rate, .. } | Node::Bend { rate, .. } | Node::Taper { rate, .. }
                if rate == 0.0 && !self.parametric =>
            {
                return c
            }
            Node::Elongate { half, .. } if half == [0.0; 3] && !self.parametric => return c,
            Node::RepeatPolar { count: 1, .. } if !self.parametric => return c,
            other => with_child(other, c),
        };
        self.add(node)
    }

    /// Whether the field of `c` is even in coordinate `axis` (mirroring it does nothing).
    fn symmetric(&self, c: NodeId, axis: usize) -> bool {
        match self.out.node(c) {
            Node::Sphere { .. }
            | Node::Box { .. }
            | Node::RoundBox { .. }
            | Node::Ellipsoid { .. }
            | Node::Torus { .. }
            | Node::Cylinder { .. }
            | Node::Capsule { .. } => true,
            Node::Cone { .. } => axis != 1,
            Node::Plane { normal, .. } => normal[axis] == 0.0,
            _ => false,
        }
    }

    /// A combination of simplified children.
    fn combine(&mut self, op: Combine, kids: Vec<NodeId>) -> NodeId {
        let kids = if op == Combine::Union {
            self.flat_union(kids)
        } else {
            kids
        };
        if kids.len() == 1 {
            return kids[0];
        }
        self.add(Node::Combine { op, children: kids })
    }

    /// The children of a union, with nested unions spliced in and repeats dropped.
    fn flat_union(&mut self, kids: Vec<NodeId>) -> Vec<NodeId> {
        let mut flat = Vec::new();
        for k in kids {
            self.flatten(k, &mut flat);
        }
        let mut seen = HashSet::new();
        flat.retain(|k| seen.insert(*k));
        flat
    }

    /// Appends the union children `k` stands for: `k` itself unless it is a union, maybe
    /// under paint and rigid motions or scales, which distribute over its children.
    fn flatten(&mut self, k: NodeId, out: &mut Vec<NodeId>) {
        let node = self.get(k);
        if let Node::Combine {
            op: Combine::Union,
            children,
        } = node
        {
            out.extend(children);
            return;
        }
        let child = match node {
            Node::Paint { child, .. }
            | Node::Translate { child, .. }
            | Node::Rotate { child, .. }
            | Node::Scale { child, .. } => child,
            _ => {
                out.push(k);
                return;
            }
        };
        let mut inner = Vec::new();
        self.flatten(child, &mut inner);
        if inner.len() < 2 {
            out.push(k);
            return;
        }
        for c in inner {
            let pushed = match node {
                Node::Paint { material, .. } => self.paint(material, c),
                Node::Translate { offset, .. } => self.translate(offset, c),
                Node::Rotate { matrix, .. } => self.rotate(matrix, c),
                Node::Scale { factor, .. } => self.scale(factor, c),
                _ => c,
            };
            out.push(pushed);
        }
    }

    /// `c` painted with `m`: nothing when every part of `c` is painted already.
    fn paint(&mut self, m: MaterialId, c: NodeId) -> NodeId {
        if self.painted(c) {
            return c;
        }
        self.add(Node::Paint {
            material: m,
            child: c,
        })
    }

    /// Whether no point of `c` has the unpainted material.
    fn painted(&self, c: NodeId) -> bool {
        match self.out.node(c) {
            Node::Paint { .. } => true,
            Node::Combine {
                op: Combine::Subtract,
                children,
            } => children.first().is_some_and(|&k| self.painted(k)),
            Node::Combine { children, .. } => {
                !children.is_empty() && children.iter().all(|&k| self.painted(k))
            }
            Node::SmoothCombine {
                op: Combine::Subtract,
                a,
                ..
            } => self.painted(*a),
            Node::SmoothCombine { a, b, .. } | Node::Morph { a, b, .. } => {
                self.painted(*a) && self.painted(*b)
            }
            Node::Feature { a, .. } => self.painted(*a),
            node => node.children().first().is_some_and(|&k| {
                node.children().len() == 1 && !is_primitive(node) && self.painted(k)
            }),
        }
    }

    /// `c` translated by `t`.
    fn translate(&mut self, t: V3, c: NodeId) -> NodeId {
        if t == [0.0; 3] && !self.parametric {
            return c;
        }
        match self.get(c) {
            Node::Paint { material, child } => {
                let inner = self.translate(t, child);
                self.paint(material, inner)
            }
            Node::Translate { offset, child } => {
                self.translate((DVec3::from(t) + DVec3::from(offset)).to_array(), child)
            }
            Node::Plane { normal, height } => self.add(Node::Plane {
                normal,
                height: height + DVec3::from(normal).dot(DVec3::from(t)),
            }),
            _ => self.add(Node::Translate {
                offset: t,
                child: c,
            }),
        }
    }

    /// `c` rotated by `m` (child points x go to m·x).
    fn rotate(&mut self, m: [V3; 3], c: NodeId) -> NodeId {
        if is_identity(&m) && !self.parametric {
            return c;
        }
        let node = self.get(c);
        match node {
            // Which rotations the rest absorb depends on the angle.
            Node::Cone { .. }
            | Node::Torus { .. }
            | Node::Cylinder { .. }
            | Node::Capsule { .. }
            | Node::Box { .. }
            | Node::RoundBox { .. }
            | Node::Ellipsoid { .. }
                if self.parametric =>
            {
                self.add(Node::Rotate {
                    matrix: m,
                    child: c,
                })
            }
            Node::Paint { material, child } => {
                let inner = self.rotate(m, child);
                self.paint(material, inner)
            }
            Node::Rotate { matrix, child } => self.rotate(mat_mul(&m, &matrix), child),
            Node::Translate { offset, child } => {
                let inner = self.rotate(m, child);
                self.translate(mat_vec(&m, offset), inner)
            }
            Node::Sphere { .. } => c,
            Node::Plane { normal, height } => self.add(Node::Plane {
                normal: mat_vec(&m, normal),
                height,
            }),
            Node::Cone { .. } if close(column(&m, 1), [0.0, 1.0, 0.0]) => c,
            Node::Torus { .. } | Node::Cylinder { .. } | Node::Capsule { .. }
                if close(column(&m, 1).map(f64::abs), [0.0, 1.0, 0.0]) =>
            {
                c
            }
            Node::Box { .. } | Node::RoundBox { .. } | Node::Ellipsoid { .. } => {
                match permutation(&m) {
                    Some(perm) => self.add(permute(node, perm)),
                    None => self.add(Node::Rotate {
                        matrix: m,
                        child: c,
                    }),
                }
            }
            _ => self.add(Node::Rotate {
                matrix: m,
                child: c,
            }),
        }
    }

    /// `c` scaled uniformly by `s`.
    fn scale(&mut self, s: f64, c: NodeId) -> NodeId {
        if s == 1.0 && !self.parametric {
            return c;
        }
        let a = s.abs();
        let node = self.get(c);
        let absorbed = match node {
            Node::Paint { material, child } => {
                let inner = self.scale(s, child);
                return self.paint(material, inner);
            }
            Node::Scale { factor, child } => return self.scale(s * factor, child),
            Node::Translate { offset, child } => {
                let inner = self.scale(s, child);
                return self.translate(offset.map(|x| x * s), inner);
            }
            Node::Rotate { matrix, child } => {
                let inner = self.scale(s, child);
                return self.rotate(matrix, inner);
            }
            Node::Round { radius, child } => {
                let inner = self.scale(s, child);
                return self.round(radius * a, inner);
            }
            Node::Sphere { radius } => Node::Sphere { radius: radius * a },
            Node::Box { half } => Node::Box {
                half: half.map(|h| h * a),
            },
            Node::RoundBox { half, radius } => Node::RoundBox {
                half: half.map(|h| h * a),
                radius: radius * a,
            },
            Node::Ellipsoid { radii } => Node::Ellipsoid {
                radii: radii.map(|r| r * a),
            },
            Node::Torus { major, minor } => Node::Torus {
                major: major * a,
                minor: minor * a,
            },
            Node::Cylinder {
                radius,
                half_height,
            } => Node::Cylinder {
                radius: radius * a,
                half_height: half_height * a,
            },
            Node::Capsule {
                radius,
                half_height,
            } => Node::Capsule {
                radius: radius * a,
                half_height: half_height * a,
            },
            Node::Cone {
                radius,
                half_height,
            } if s > 0.0 => Node::Cone {
                radius: radius * s,
                half_height: half_height * s,
            },
            Node::Plane { normal, height } => Node::Plane {
                normal: normal.map(|n| n * s.signum()),
                height: height * a,
            },
            // A shape between two points: its points and radii (`prim::scaled`).
            Node::Prim { prim, ref args } if s > 0.0 => match crate::prim::scaled(prim, args, s) {
                Some(args) => Node::Prim { prim, args },
                None => Node::Scale {
                    factor: s,
                    child: c,
                },
            },
            _ => Node::Scale {
                factor: s,
                child: c,
            },
        };
        self.add(absorbed)
    }

    /// `c` rounded by `r` (its surface moved outwards by r).
    fn round(&mut self, r: f64, c: NodeId) -> NodeId {
        if r == 0.0 && !self.parametric {
            return c;
        }
        let node = match self.get(c) {
            Node::Paint { material, child } => {
                let inner = self.round(r, child);
                return self.paint(material, inner);
            }
            Node::Translate { offset, child } => {
                let inner = self.round(r, child);
                return self.translate(offset, inner);
            }
            Node::Rotate { matrix, child } => {
                let inner = self.round(r, child);
                return self.rotate(matrix, inner);
            }
            Node::Scale { factor, child } if factor != 0.0 => {
                let inner = self.round(r / factor.abs(), child);
                return self.scale(factor, inner);
            }
            Node::Round { radius, child } => return self.round(radius + r, child),
            Node::Sphere { radius } => Node::Sphere { radius: radius + r },
            Node::Capsule {
                radius,
                half_height,
            } => Node::Capsule {
                radius: radius + r,
                half_height,
            },
            Node::Torus { major, minor } => Node::Torus {
                major,
                minor: minor + r,
            },
            Node::RoundBox { half, radius } => Node::RoundBox {
                half: half.map(|h| h + r),
                radius: radius + r,
            },
            _ => Node::Round {
                radius: r,
                child: c,
            },
        };
        self.add(node)
    }
}

fn is_primitive(node: &Node) -> bool {
    node.children().is_empty()
}

/// `node` with its single child replaced.
fn with_child(node: Node, c: NodeId) -> Node {
    let mut node = node;
    if let Some(child) = node.child_mut() {
        *child = c;
    }
    node
}

/// For a signed permutation matrix, the column of the non-zero entry of each row.
fn permutation(m: &[V3; 3]) -> Option<[usize; 3]> {
    let mut perm = [0; 3];
    for (i, row) in m.iter().enumerate() {
        let big: Vec<usize> = (0..3).filter(|&j| row[j].abs() > TINY).collect();
        if big.len() != 1 || (row[big[0]].abs() - 1.0).abs() > TINY {
            return None;
        }
        perm[i] = big[0];
    }
    Some(perm)
}

/// A box-like shape whose axes are permuted: extent i of the result is extent perm[i].
fn permute(node: Node, perm: [usize; 3]) -> Node {
    let p = |v: V3| [v[perm[0]], v[perm[1]], v[perm[2]]];
    match node {
        Node::Box { half } => Node::Box { half: p(half) },
        Node::RoundBox { half, radius } => Node::RoundBox {
            half: p(half),
            radius,
        },
        Node::Ellipsoid { radii } => Node::Ellipsoid { radii: p(radii) },
        other => other,
    }
}

fn is_identity(m: &[V3; 3]) -> bool {
    (0..3).all(|i| (0..3).all(|j| (m[i][j] - if i == j { 1.0 } else { 0.0 }).abs() <= TINY))
}

fn column(m: &[V3; 3], j: usize) -> V3 {
    [m[0][j], m[1][j], m[2][j]]
}

fn close(a: V3, b: V3) -> bool {
    (0..3).all(|i| (a[i] - b[i]).abs() <= TINY)
}

fn mat_mul(a: &[V3; 3], b: &[V3; 3]) -> [V3; 3] {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}
