//! Smooth combinations and features: the blends (smooth minimum and maximum, chamfers,
//! rounds, columns, stairs) and the engravings, grooves, tongues and pipes.

use super::{Field, Lowerer};
use crate::lower::{blends, Reg, Unary};
use crate::program::builder::{Builder, P};
use crate::scene::{Combine, Feature, NodeId, Smooth};

impl Lowerer<'_> {
    /// A smooth combination of two children.
    pub(super) fn smooth(
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
            (None, Combine::Union) => smooth_extreme(b, fa.d, fb.d, kb, v, false),
            (None, Combine::Intersect) => smooth_extreme(b, fa.d, fb.d, kb, v, true),
            (None, Combine::Subtract) => {
                let nb = b.neg(fb.d);
                smooth_extreme(b, fa.d, nb, kb, v, true)
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

    /// A feature of `a` along the surface of `b`; the result has `a`'s material.
    pub(super) fn feature(&mut self, id: NodeId, f: Feature, ch: [NodeId; 2], p: P) -> Field {
        let fa = self.node(ch[0], p);
        let fb = self.node(ch[1], p);
        self.resume(id, self.graph.node(id));
        Field {
            d: blends::feature(self.b, f, fa.d, fb.d),
            m: fa.m,
        }
    }
}

/// The least blend radius of a parametric program's smooth combinations: at k = 0 the blend
/// is computed at this radius (and not chosen), so that its formula stays that of every other
/// k and its values finite: its reciprocal is far inside f32's range.
const LEAST_BLEND: f64 = 1e-12;

/// The smooth minimum, or with `max` the smooth maximum -smin(-a, -b). Poly: h = max(k - |a -
/// b|, 0) / k, min(a, b) - h²·k/4 (Quilez's quadratic), or max(a, b) + h²·k/4. Exp:
/// -k·ln(e^(-a/k) + e^(-b/k)), computed as m - k·ln(e^((m-a)/k) + e^((m-b)/k)) with m = min(a,
/// b) so that it cannot overflow, or M + k·ln(e^((a-M)/k) + e^((b-M)/k)) with M = max(a, b).
/// k ≤ 0 is the plain minimum or maximum. (hg_sdf's variants are `blends::combine`'s: they
/// never come here with k > 0.)
fn smooth_extreme(b: &mut Builder, x: Reg, y: Reg, k: f64, v: Smooth, max: bool) -> Reg {
    let m = if max { b.max(x, y) } else { b.min(x, y) };
    let s = match v {
        _ if k <= 0.0 => return m,
        Smooth::Poly => poly_h(b, x, y, k),
        Smooth::Exp => exp_sum(b, m, x, y, k),
        _ => return m,
    };
    if max {
        b.add(m, s)
    } else {
        b.sub(m, s)
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
