//! Lowering of the node graph: point transforms are applied on the way down, distance and
//! material combinations on the way up. A node reached again at the same point (a shared
//! sub-shape) is lowered once.

use super::builder::{Builder, P};
use super::{shapes, Reg, Unary, EMPTY_DISTANCE};
use crate::scene::{Combine, Graph, Node, NodeId, Smooth, V3};
use std::collections::HashMap;

/// The material register value of a shape no `paint` has reached yet.
pub(super) const UNPAINTED: f64 = -1.0;

/// A lowered field: distance and material registers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Field {
    pub d: Reg,
    pub m: Reg,
}

/// Walks the graph, emitting into a builder.
#[derive(Debug)]
pub(super) struct Lowerer<'a> {
    graph: &'a Graph,
    b: &'a mut Builder,
    memo: HashMap<(NodeId, P), Field>,
}

impl<'a> Lowerer<'a> {
    pub fn new(graph: &'a Graph, b: &'a mut Builder) -> Self {
        Lowerer {
            graph,
            b,
            memo: HashMap::new(),
        }
    }

    /// Lowers node `id` evaluated at point `p`.
    pub fn node(&mut self, id: NodeId, p: P) -> Field {
        if let Some(&f) = self.memo.get(&(id, p)) {
            return f;
        }
        let graph = self.graph;
        let node = graph.node(id);
        self.b.note(format!("node {} {}", id.0, kind(node)));
        let f = match node {
            Node::Combine { op, children } => self.combine(id, *op, children, p),
            Node::SmoothCombine {
                op,
                k,
                variant,
                a,
                b,
            } => self.smooth(id, *op, *k, *variant, [*a, *b], p),
            Node::Paint { material, child } => {
                let f = self.node(*child, p);
                self.resume(id, node);
                Field {
                    d: f.d,
                    m: self.b.paint(f.m, material.0 as f64),
                }
            }
            Node::Round { radius, child } => self.post(id, *child, p, |b, d| b.subc(d, *radius)),
            Node::Shell { thickness, child } => self.post(id, *child, p, |b, d| {
                let a = b.abs(d);
                b.subc(a, *thickness)
            }),
            Node::Scale { factor, child } => {
                let q = self.b.map3(p, |b, x, _| b.mulc(x, 1.0 / factor));
                self.post(id, *child, q, |b, d| b.mulc(d, factor.abs()))
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
        };
        self.memo.insert((id, p), f);
        f
    }

    /// Notes that the instructions that follow belong to `id` again, after its children.
    fn resume(&mut self, id: NodeId, node: &Node) {
        self.b
            .note_resume(format!("node {} {} (after its children)", id.0, kind(node)));
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
        let b = &mut *self.b;
        let q = match node {
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
            Node::Elongate { half, child } => (*child, elongate(b, p, *half)),
            _ => return None,
        };
        Some(q)
    }

    /// Lowers a primitive (unpainted).
    fn primitive(&mut self, node: &Node, p: P) -> Field {
        let b = &mut *self.b;
        let d = match *node {
            Node::Sphere { radius } => shapes::sphere(b, p, radius),
            Node::Box { half } => shapes::boxed(b, p, half),
            Node::RoundBox { half, radius } => shapes::round_box(b, p, half, radius),
            Node::Plane { normal, height } => shapes::plane(b, p, normal, height),
            Node::Torus { major, minor } => shapes::torus(b, p, major, minor),
            Node::Cylinder {
                radius,
                half_height,
            } => shapes::cylinder(b, p, radius, half_height),
            Node::Capsule {
                radius,
                half_height,
            } => shapes::capsule(b, p, radius, half_height),
            Node::Cone {
                radius,
                half_height,
            } => shapes::cone(b, p, radius, half_height),
            Node::Ellipsoid { radii } => shapes::ellipsoid(b, p, radii),
            Node::Mandelbulb { power, iterations } => shapes::mandelbulb(b, p, power, iterations),
            _ => b.c(EMPTY_DISTANCE),
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
        let d = match op {
            Combine::Union => smin(b, fa.d, fb.d, k, v),
            Combine::Intersect => smax(b, fa.d, fb.d, k, v),
            Combine::Subtract => {
                let nb = b.neg(fb.d);
                smax(b, fa.d, nb, k, v)
            }
        };
        Field {
            d,
            m: self.material(op, fa, fb),
        }
    }
}

/// The smooth minimum. Poly: h = max(k - |a - b|, 0) / k, min(a, b) - h²·k/4 (Quilez's
/// quadratic). Exp: -k·ln(e^(-a/k) + e^(-b/k)), computed as m - k·ln(e^((m-a)/k) + e^((m-b)/k))
/// with m = min(a, b) so that it cannot overflow. k ≤ 0 is the plain minimum.
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

/// The inverse rotation (transpose of the rows `m`): q_j = Σ_i p_i·m[i][j].
fn rotate(b: &mut Builder, p: P, m: &[V3; 3]) -> P {
    [0, 1, 2].map(|j| {
        let terms: Vec<Reg> = (0..3).map(|i| b.mulc(p[i], m[i][j])).collect();
        let s = b.add(terms[0], terms[1]);
        b.add(s, terms[2])
    })
}

/// Domain repetition per axis with period s (0: none). Infinite: p - s·round(p/s). Finite
/// with n copies: u = p/s + (n-1)/2, id = clamp(round(u), 0, n-1), q = p - s·(id - (n-1)/2).
fn repeat(b: &mut Builder, p: P, period: V3, count: Option<V3>) -> P {
    b.map3(p, |b, x, i| {
        let s = period[i];
        if s == 0.0 {
            return x;
        }
        let u = b.mulc(x, 1.0 / s);
        let cell = match count {
            None => b.un(Unary::Round, u),
            Some(n) => {
                let half = (n[i] - 1.0) * 0.5;
                let u = b.addc(u, half);
                let id = b.un(Unary::Round, u);
                let id = b.clampc(id, 0.0, n[i] - 1.0);
                b.subc(id, half)
            }
        };
        let off = b.mulc(cell, s);
        b.sub(x, off)
    })
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

fn rot2(b: &mut Builder, c: Reg, s: Reg, u: Reg, v: Reg) -> (Reg, Reg) {
    let (cu, sv, su, cv) = (b.mul(c, u), b.mul(s, v), b.mul(s, u), b.mul(c, v));
    (b.sub(cu, sv), b.add(su, cv))
}

/// Elongation: q = p - clamp(p, -h, h), which stretches any child (symmetric or not).
fn elongate(b: &mut Builder, p: P, h: V3) -> P {
    b.map3(p, |b, x, i| {
        let c = b.clampc(x, -h[i], h[i]);
        b.sub(x, c)
    })
}

/// A short name of a node's kind, for the program's comments.
fn kind(node: &Node) -> &'static str {
    match node {
        Node::Sphere { .. } => "sphere",
        Node::Box { .. } => "box",
        Node::RoundBox { .. } => "round_box",
        Node::Plane { .. } => "plane",
        Node::Torus { .. } => "torus",
        Node::Cylinder { .. } => "cylinder",
        Node::Capsule { .. } => "capsule",
        Node::Cone { .. } => "cone",
        Node::Ellipsoid { .. } => "ellipsoid",
        Node::Mandelbulb { .. } => "mandelbulb",
        Node::Combine {
            op: Combine::Union, ..
        } => "union",
        Node::Combine {
            op: Combine::Intersect,
            ..
        } => "intersect",
        Node::Combine {
            op: Combine::Subtract,
            ..
        } => "subtract",
        Node::SmoothCombine {
            op: Combine::Union, ..
        } => "smooth_union",
        Node::SmoothCombine {
            op: Combine::Intersect,
            ..
        } => "smooth_intersect",
        Node::SmoothCombine {
            op: Combine::Subtract,
            ..
        } => "smooth_subtract",
        Node::Translate { .. } => "translate",
        Node::Rotate { .. } => "rotate",
        Node::Scale { .. } => "scale",
        Node::ScaleXyz { .. } => "scale_xyz",
        Node::Repeat { .. } => "repeat",
        Node::Mirror { .. } => "mirror",
        Node::Twist { .. } => "twist",
        Node::Bend { .. } => "bend",
        Node::Round { .. } => "round",
        Node::Shell { .. } => "shell",
        Node::Elongate { .. } => "elongate",
        Node::Paint { .. } => "paint",
    }
}
