//! Lowering rules of the edge blends and features of Mercury's hg_sdf library (the chamfer,
//! round, stairs and columns forms of union, intersection and difference; engrave, groove,
//! tongue and pipe), written as scalar code over the two operands' distances `a` and `b`.
//! Each names the hg_sdf function it follows; `docs/analysis.md` gives their Lipschitz bounds.

use super::{Reg, Unary};
use crate::program::builder::Builder;
use crate::scene::{Combine, Feature, Smooth};
use std::f64::consts::{FRAC_1_SQRT_2, SQRT_2};

/// The blend of `a` and `b` by `op` with hg_sdf's variant `v` and size `r` (> 0); `None` for
/// the smooth minima (poly, exp), which `graph.rs` lowers.
pub(super) fn combine(
    b: &mut Builder,
    op: Combine,
    x: Reg,
    y: Reg,
    r: f64,
    v: Smooth,
) -> Option<Reg> {
    Some(match (v, op) {
        (Smooth::Chamfer, Combine::Union) => chamfer(b, x, y, r, true),
        (Smooth::Chamfer, Combine::Intersect) => chamfer(b, x, y, r, false),
        (Smooth::Chamfer, Combine::Subtract) => {
            let ny = b.neg(y);
            chamfer(b, x, ny, r, false)
        }
        (Smooth::Round, Combine::Union) => round_union(b, x, y, r),
        (Smooth::Round, Combine::Intersect) => round_intersect(b, x, y, r),
        (Smooth::Round, Combine::Subtract) => {
            let ny = b.neg(y);
            round_intersect(b, x, ny, r)
        }
        (Smooth::Stairs(n), _) => by_union(b, op, x, y, |b, x, y| stairs_union(b, x, y, r, n)),
        // hg_sdf's `fOpDifferenceColumns` is evaluated only near the edge and jumps at the
        // border of that region; the union of the complements, as for the stairs, is
        // continuous and cuts the same columns as grooves.
        (Smooth::Columns(n), _) => by_union(b, op, x, y, |b, x, y| columns_union(b, x, y, r, n)),
        (Smooth::Poly | Smooth::Exp, _) => return None,
    })
}

/// `op` of `x` and `y` through a blended `union`: the union itself, else the complement of
/// the union of complements, -union(-a, -b) for the intersection and -union(-a, b) for the
/// difference.
fn by_union(
    b: &mut Builder,
    op: Combine,
    x: Reg,
    y: Reg,
    union: impl FnOnce(&mut Builder, Reg, Reg) -> Reg,
) -> Reg {
    let (nx, ny) = match op {
        Combine::Union => return union(b, x, y),
        Combine::Intersect => (b.neg(x), b.neg(y)),
        Combine::Subtract => (b.neg(x), y),
    };
    let u = union(b, nx, ny);
    b.neg(u)
}

/// `fOpUnionChamfer`: min(min(a, b), (a + b - r)·√½); with `union` false,
/// `fOpIntersectionChamfer`: max(max(a, b), (a + b + r)·√½).
fn chamfer(b: &mut Builder, x: Reg, y: Reg, r: f64, union: bool) -> Reg {
    let pick = if union { Builder::min } else { Builder::max };
    let m = pick(b, x, y);
    let s = b.add(x, y);
    let s = if union { b.subc(s, r) } else { b.addc(s, r) };
    let s = b.mulc(s, FRAC_1_SQRT_2);
    pick(b, m, s)
}

/// |max((u(a), u(b)), 0)|.
fn positive_len(b: &mut Builder, x: Reg, y: Reg, u: impl Fn(&mut Builder, Reg) -> Reg) -> Reg {
    let ux = u(b, x);
    let ux = b.maxc(ux, 0.0);
    let uy = u(b, y);
    let uy = b.maxc(uy, 0.0);
    b.len2(ux, uy)
}

/// `fOpUnionRound`: max(r, min(a, b)) - |max((r - a, r - b), 0)|.
fn round_union(b: &mut Builder, x: Reg, y: Reg, r: f64) -> Reg {
    let m = b.min(x, y);
    let m = b.maxc(m, r);
    let rc = b.c(r);
    let l = positive_len(b, x, y, |b, v| b.sub(rc, v));
    b.sub(m, l)
}

/// `fOpIntersectionRound`: min(-r, max(a, b)) + |max((r + a, r + b), 0)|.
fn round_intersect(b: &mut Builder, x: Reg, y: Reg, r: f64) -> Reg {
    let m = b.max(x, y);
    let m = b.minc(m, -r);
    let l = positive_len(b, x, y, |b, v| b.addc(v, r));
    b.add(m, l)
}

/// GLSL's mod(x, m) = x - m·⌊x / m⌋ for a constant m > 0 (⌊v⌋ as round(v - ½)).
fn modulo(b: &mut Builder, x: Reg, m: f64) -> Reg {
    let q = b.mulc(x, 1.0 / m);
    let q = b.subc(q, 0.5);
    let q = b.un(Unary::Round, q);
    let q = b.mulc(q, m);
    b.sub(x, q)
}

/// `fOpUnionStairs` (after paniq): with s = r / n and u = b - r,
/// min(min(a, b), (u + a + |mod(u - a + s, 2s) - s|) / 2).
fn stairs_union(b: &mut Builder, x: Reg, y: Reg, r: f64, n: u32) -> Reg {
    let s = r / f64::from(n);
    let m = b.min(x, y);
    let u = b.subc(y, r);
    let w = b.sub(u, x);
    let w = b.addc(w, s);
    let w = modulo(b, w, 2.0 * s);
    let w = b.subc(w, s);
    let w = b.abs(w);
    let t = b.add(u, x);
    let t = b.add(t, w);
    let t = b.mulc(t, 0.5);
    b.min(m, t)
}

/// The radius of each of the n columns within r: r·√2 / (2(n - 1) + √2).
fn column_radius(r: f64, n: u32) -> f64 {
    r * SQRT_2 / (2.0 * (f64::from(n) - 1.0) + SQRT_2)
}

/// The point (a, b) turned by 45° (hg_sdf's `pR45`): ((a + b)·√½, (b - a)·√½).
fn turn45(b: &mut Builder, x: Reg, y: Reg) -> (Reg, Reg) {
    let s = b.add(x, y);
    let px = b.mulc(s, FRAC_1_SQRT_2);
    let d = b.sub(y, x);
    let py = b.mulc(d, FRAC_1_SQRT_2);
    (px, py)
}

/// hg_sdf's `pMod1`: the coordinate within its cell of `size`, centred.
fn cell(b: &mut Builder, y: Reg, size: f64) -> Reg {
    let y = b.addc(y, size * 0.5);
    let y = modulo(b, y, size);
    b.subc(y, size * 0.5)
}

/// `fOpUnionColumns`: the point (a, b) turned by 45° and moved onto the diagonal where the
/// columns stand, repeated along it, then min(|p| - c, p.x, a, b) for the column radius c.
/// hg_sdf evaluates this only where a < r and b < r and takes min(a, b) elsewhere, which makes
/// the field jump there; it is evaluated everywhere here: where a ≥ r or b ≥ r every point
/// with p.x < 0 or within a column lies inside the other operand, so the surface is the same
/// and the field continuous, never above min(a, b).
fn columns_union(b: &mut Builder, x: Reg, y: Reg, r: f64, n: u32) -> Reg {
    let c = column_radius(r, n);
    let (px, py) = turn45(b, x, y);
    let px = b.addc(px, -FRAC_1_SQRT_2 * r + c * SQRT_2);
    let py = if n % 2 == 1 { b.addc(py, c) } else { py };
    let py = cell(b, py, 2.0 * c);
    let l = b.len2(px, py);
    let l = b.subc(l, c);
    let m = b.min(l, px);
    let m = b.min(m, x);
    b.min(m, y)
}

/// A feature of `a` along the surface of `b`: hg_sdf's `fOpEngrave`
/// max(a, (a + d - |b|)·√½), `fOpGroove` max(a, min(a + d, w/2 - |b|)), `fOpTongue`
/// min(a, max(a - h, |b| - w/2)) and `fOpPipe` |(a, b)| - r.
pub(super) fn feature(b: &mut Builder, f: Feature, x: Reg, y: Reg) -> Reg {
    match f {
        Feature::Engrave { depth } => {
            let ay = b.abs(y);
            let t = b.addc(x, depth);
            let t = b.sub(t, ay);
            let t = b.mulc(t, FRAC_1_SQRT_2);
            b.max(x, t)
        }
        Feature::Groove { width, depth } => {
            let ay = b.abs(y);
            let t = b.addc(x, depth);
            let w = b.c(width * 0.5);
            let u = b.sub(w, ay);
            let t = b.min(t, u);
            b.max(x, t)
        }
        Feature::Tongue { width, height } => {
            let ay = b.abs(y);
            let t = b.subc(x, height);
            let u = b.subc(ay, width * 0.5);
            let t = b.max(t, u);
            b.min(x, t)
        }
        Feature::Pipe { radius } => {
            let l = b.len2(x, y);
            b.subc(l, radius)
        }
    }
}
