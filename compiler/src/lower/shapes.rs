//! Lowering rules of the primitives that keep their own nodes (those of the table in
//! `prim/` lower through its entries): Quilez's distance functions written as scalar code.
//! Every primitive is centred on the origin; `p` is the point in the primitive's frame. The
//! exact primitives that a marched scene's instances may be read their constants through
//! [`Builder::param`] from their [`slots`], so that the same rules give both the program and
//! the GPU walk's shape functions (back/wgsl/march.rs), which read the slots from `scene_data`.

use super::{Binary, Reg, Unary};
use crate::prim::{box_from_q, cylinder, nearer_signed};
use crate::program::builder::{Builder, Slots, P};
use crate::scene::{Node, V3};

/// The constants of an exact primitive, four numbers (six for the capped and round cones along
/// y of the table, `prim::slots`): what its formula below reads as `s[0..8]`
/// ([`Builder::param`]), and what the GPU's walk over a marched scene's instances reads from
/// `scene_data` (back/wgsl/march.rs). Derived constants are computed here, in f64, once: a
/// round box's inner half-extents, a cone's 2h² and 1 / (r² + 4h²). `None` for the other
/// primitives (a plane, an ellipsoid, a Mandelbulb, which no instance is).
pub fn slots(node: &Node) -> Option<Slots> {
    Some(match *node {
        Node::Sphere { radius } => four([radius, 0.0, 0.0, 0.0]),
        Node::Box { half } => four([half[0], half[1], half[2], 0.0]),
        Node::RoundBox { half, radius: r } => four([half[0] - r, half[1] - r, half[2] - r, r]),
        Node::Torus { major, minor } => four([major, minor, 0.0, 0.0]),
        Node::Cylinder {
            radius,
            half_height,
        }
        | Node::Capsule {
            radius,
            half_height,
        } => four([radius, half_height, 0.0, 0.0]),
        Node::Cone {
            radius: r,
            half_height: h,
        } => four([r, h, 2.0 * h * h, 1.0 / (r * r + 4.0 * h * h)]),
        Node::Prim { prim, ref args } => return crate::prim::slots(prim, args),
        _ => return None,
    })
}

/// Four constants as [`Slots`], the rest 0.
pub(crate) fn four(s: [f64; 4]) -> Slots {
    [s[0], s[1], s[2], s[3], 0.0, 0.0, 0.0, 0.0]
}

/// The distance of the exact primitive `node` (one [`slots`] knows) at `p`, its constants
/// `s` read through [`Builder::param`]: with `s = slots(node)` the lowering's program, with
/// placeholder constants recorded as parameters the GPU walk's shape function
/// ([`super::shape_program`]).
pub(super) fn exact(b: &mut Builder, p: P, node: &Node, s: &Slots) -> Option<Reg> {
    Some(match node {
        Node::Sphere { .. } => sphere(b, p, s),
        Node::Box { .. } => boxed(b, p, s),
        Node::RoundBox { .. } => round_box(b, p, s),
        Node::Torus { .. } => torus(b, p, s),
        Node::Cylinder { .. } => cylinder(b, p, s),
        Node::Capsule { .. } => capsule(b, p, s),
        Node::Cone { .. } => cone(b, p, s),
        Node::Prim { prim, .. } => return crate::prim::exact(b, p, *prim, s),
        _ => return None,
    })
}

/// |p| - r, with s = (r, ·, ·, ·).
fn sphere(b: &mut Builder, p: P, s: &Slots) -> Reg {
    let l = b.len3(p);
    let r = b.param(s, 0, 1.0);
    b.sub(l, r)
}

/// q = |p| - h; |max(q, 0)| + min(maxcomp(q), 0), with s = (h, ·).
fn boxed(b: &mut Builder, p: P, s: &Slots) -> Reg {
    let a = b.abs3(p);
    let q = sub_slots(b, a, s);
    box_from_q(b, q)
}

/// p - s.xyz.
fn sub_slots(b: &mut Builder, p: P, s: &Slots) -> P {
    b.map3(p, |b, x, i| {
        let k = b.param(s, i, 1.0);
        b.sub(x, k)
    })
}

/// A box with edges rounded by r, with s = (half-extents − r, r): the box of the inner
/// half-extents, less r.
fn round_box(b: &mut Builder, p: P, s: &Slots) -> Reg {
    let a = b.abs3(p);
    let q = sub_slots(b, a, s);
    let d = box_from_q(b, q);
    let r = b.param(s, 3, 1.0);
    b.sub(d, r)
}

/// dot(p, n) - h: the half-space below the plane.
pub(super) fn plane(b: &mut Builder, p: P, n: V3, h: f64) -> Reg {
    let n = b.c3(n);
    let d = b.dot3(p, n);
    b.subc(d, h)
}

/// |(|p.xz| - R, p.y)| - r, with s = (R, r, ·, ·).
fn torus(b: &mut Builder, p: P, s: &Slots) -> Reg {
    let xz = b.len2(p[0], p[2]);
    let major = b.param(s, 0, 1.0);
    let qx = b.sub(xz, major);
    let l = b.len2(qx, p[1]);
    let minor = b.param(s, 1, 1.0);
    b.sub(l, minor)
}

/// Capsule along y, with s = (r, h, ·, ·): |p - (0, clamp(p.y, -h, h), 0)| - r
fn capsule(b: &mut Builder, p: P, s: &Slots) -> Reg {
    let lo = b.param(s, 1, -1.0);
    let cy = b.max(p[1], lo);
    let hi = b.param(s, 1, 1.0);
    let cy = b.min(cy, hi);
    let y = b.sub(p[1], cy);
    let l = b.len3([p[0], y, p[2]]);
    let r = b.param(s, 0, 1.0);
    b.sub(l, r)
}

/// Quilez's exact capped cone with radius `r` at y = -h and radius 0 at y = +h, with
/// s = (r, h, 2h², 1 / (r² + 4h²)):
/// q = (|p.xz|, p.y), k1 = (0, h), k2 = (-r, 2h),
/// ca = (q.x - min(q.x, q.y < 0 ? r : 0), |q.y| - h),
/// cb = q - k1 + k2·clamp(dot(k1 - q, k2) / dot(k2, k2), 0, 1),
/// s = (cb.x < 0 and ca.y < 0) ? -1 : 1,  d = s·√min(|ca|², |cb|²).
fn cone(b: &mut Builder, p: P, s: &Slots) -> Reg {
    let qx = b.len2(p[0], p[2]);
    let qy = p[1];
    let zero = b.c(0.0);
    let below = b.lt(qy, zero);
    let rc = b.param(s, 0, 1.0);
    let cap = b.select(below, rc, zero);
    let cap = b.min(qx, cap);
    let cax = b.sub(qx, cap);
    let ay = b.abs(qy);
    let h = b.param(s, 1, 1.0);
    let cay = b.sub(ay, h);
    // dot(k1 - q, k2) = (0 - qx)(-r) + (h - qy)(2h) = r·qx + 2h² - 2h·qy
    let r = b.param(s, 0, 1.0);
    let t1 = b.mul(qx, r);
    let minus_2h = b.param(s, 1, -2.0);
    let t2 = b.mul(qy, minus_2h);
    let t = b.add(t1, t2);
    let h2 = b.param(s, 2, 1.0);
    let t = b.add(t, h2);
    let inv = b.param(s, 3, 1.0);
    let t = b.mul(t, inv);
    let t = b.clampc(t, 0.0, 1.0);
    let minus_r = b.param(s, 0, -1.0);
    let kx = b.mul(t, minus_r);
    let cbx = b.add(qx, kx);
    let two_h = b.param(s, 1, 2.0);
    let ky = b.mul(t, two_h);
    let h = b.param(s, 1, 1.0);
    let cby = b.sub(qy, h);
    let cby = b.add(cby, ky);
    nearer_signed(b, zero, [cax, cay], [cbx, cby])
}

/// Quilez's ellipsoid bound: k0 = |p / r|, k1 = |p / r²|, d = k0 (k0 - 1) / k1.
/// k1 is kept above a tiny floor so that the centre gives a finite value.
pub(super) fn ellipsoid(b: &mut Builder, p: P, radii: V3) -> Reg {
    let q0 = b.map3(p, |b, x, i| b.mulc(x, 1.0 / radii[i]));
    let q1 = b.map3(p, |b, x, i| b.mulc(x, 1.0 / (radii[i] * radii[i])));
    let k0 = b.len3(q0);
    let k1 = b.len3(q1);
    let k1 = b.maxc(k1, 1e-30);
    let k = b.subc(k0, 1.0);
    let n = b.mul(k0, k);
    b.div(n, k1)
}

/// The exact signed distance to the simple polygon through `v` in the xy plane (Quilez's
/// `sdPolygon`): the nearest of its edges, negative where a ray along +x from the point
/// crosses the edges an odd number of times. Edge i (from v_i to v_j, j = i - 1) crosses when
/// v_i.y ≤ y, y < v_j.y and the point is left of it, or all three are false.
pub(super) fn polygon(b: &mut Builder, p: P, v: &[[f64; 2]]) -> Reg {
    let (x, y) = (p[0], p[1]);
    let mut best: Option<Reg> = None;
    let mut sign = b.c(1.0);
    let n = v.len();
    for i in 0..n {
        let j = (i + n - 1) % n;
        let (vi, vj) = (v[i], v[j]);
        let e = [vj[0] - vi[0], vj[1] - vi[1]];
        let ee = e[0] * e[0] + e[1] * e[1];
        let wx = b.subc(x, vi[0]);
        let wy = b.subc(y, vi[1]);
        // The nearest point of the edge: w - e·clamp(w·e / e·e, 0, 1).
        let t = if ee > 0.0 {
            let ex = b.mulc(wx, e[0] / ee);
            let ey = b.mulc(wy, e[1] / ee);
            let t = b.add(ex, ey);
            b.clampc(t, 0.0, 1.0)
        } else {
            b.c(0.0)
        };
        let tx = b.mulc(t, e[0]);
        let ty = b.mulc(t, e[1]);
        let dx = b.sub(wx, tx);
        let dy = b.sub(wy, ty);
        let dd = b.dot2(dx, dy, dx, dy);
        best = Some(match best {
            Some(m) => b.min(m, dd),
            None => dd,
        });
        // The three conditions as 0 or 1; the edge flips the sign when they agree.
        let (yi, yj) = (b.c(vi[1]), b.c(vj[1]));
        let below_i = b.lt(y, yi);
        let one = b.c(1.0);
        let c1 = b.sub(one, below_i);
        let c2 = b.lt(y, yj);
        let l = b.mulc(wx, e[1]);
        let r = b.mulc(wy, e[0]);
        let c3 = b.lt(l, r);
        let s12 = b.add(c1, c2);
        let sum = b.add(s12, c3);
        // sum is 0 or 3 exactly when |sum - 1.5| > 1.
        let off = b.subc(sum, 1.5);
        let off = b.abs(off);
        let one = b.c(1.0);
        let flip = b.lt(one, off);
        let neg = b.neg(sign);
        sign = b.select(flip, neg, sign);
    }
    let d = match best {
        Some(m) => b.sqrt(m),
        None => b.c(f64::INFINITY),
    };
    b.mul(sign, d)
}

/// The exact distance to the quadratic Bézier curve through `v` = (A, B, C) (B the control
/// point, A - 2B + C not zero), after Quilez's `sdBezier`: the nearest parameter t solves
/// the cubic t³ + 3·kx·t² + … = 0, in closed form. Where its discriminant h = q² + 4p³ is
/// ≥ 0 the one real root is Cardano's (cube roots of (±√h - q)/2); otherwise of its three
/// roots, by the trigonometric form, the two that can be nearest. Both forms are computed
/// and the discriminant selects one; their arguments are clamped so the other stays finite.
pub(super) fn bezier(b: &mut Builder, p: P, v: [[f64; 2]; 3]) -> Reg {
    let [pa, pb, pc] = v;
    let a = [pb[0] - pa[0], pb[1] - pa[1]];
    let bb = [pa[0] - 2.0 * pb[0] + pc[0], pa[1] - 2.0 * pb[1] + pc[1]];
    let c = [2.0 * a[0], 2.0 * a[1]];
    let kk = 1.0 / (bb[0] * bb[0] + bb[1] * bb[1]);
    let kx = kk * (a[0] * bb[0] + a[1] * bb[1]);
    let aa = a[0] * a[0] + a[1] * a[1];
    // d = A - p.
    let dx = b.neg(p[0]);
    let dx = b.addc(dx, pa[0]);
    let dy = b.neg(p[1]);
    let dy = b.addc(dy, pa[1]);
    // ky = kk·(2·a·a + d·b) / 3, kz = kk·(d·a).
    let db0 = b.mulc(dx, kk * bb[0] / 3.0);
    let db1 = b.mulc(dy, kk * bb[1] / 3.0);
    let ky = b.add(db0, db1);
    let ky = b.addc(ky, kk * 2.0 * aa / 3.0);
    let da0 = b.mulc(dx, kk * a[0]);
    let da1 = b.mulc(dy, kk * a[1]);
    let kz = b.add(da0, da1);
    // p = ky - kx², q = kx·(2kx² - 3ky) + kz, h = q² + 4p³.
    let pp = b.subc(ky, kx * kx);
    let q = b.mulc(ky, -3.0 * kx);
    let q = b.addc(q, 2.0 * kx * kx * kx);
    let q = b.add(q, kz);
    let p2 = b.mul(pp, pp);
    let p3 = b.mul(p2, pp);
    let p34 = b.mulc(p3, 4.0);
    let q2 = b.mul(q, q);
    let h = b.add(q2, p34);
    // The squared distance to the curve's point at t: |d + (c + b·t)·t|².
    let at = |b: &mut Builder, t: Reg| {
        let ux = b.mulc(t, bb[0]);
        let ux = b.addc(ux, c[0]);
        let ux = b.mul(ux, t);
        let ux = b.add(ux, dx);
        let uy = b.mulc(t, bb[1]);
        let uy = b.addc(uy, c[1]);
        let uy = b.mul(uy, t);
        let uy = b.add(uy, dy);
        b.dot2(ux, uy, ux, uy)
    };
    // One real root: t = ∛((√h - q)/2) + ∛((-√h - q)/2) - kx.
    let hp = b.maxc(h, 0.0);
    let sh = b.sqrt(hp);
    let third = b.c(1.0 / 3.0);
    let zero = b.c(0.0);
    let mut t = b.c(-kx);
    for sign in [1.0, -1.0] {
        let x = b.mulc(sh, sign);
        let x = b.sub(x, q);
        let x = b.mulc(x, 0.5);
        let ax = b.abs(x);
        let root = b.bin(Binary::Pow, ax, third);
        let neg = b.lt(x, zero);
        let minus = b.neg(root);
        let root = b.select(neg, minus, root);
        t = b.add(t, root);
    }
    let t = b.clampc(t, 0.0, 1.0);
    let one = at(b, t);
    // Three real roots (h < 0, so p < 0): z = √-p, v = acos(q / (2p·z)) / 3.
    let np = b.neg(pp);
    let np = b.maxc(np, 0.0);
    let z = b.sqrt(np);
    let den = b.mul(pp, z);
    let den = b.mulc(den, 2.0);
    let den = b.minc(den, -1e-30);
    let ratio = b.div(q, den);
    let ratio = b.clampc(ratio, -1.0, 1.0);
    let angle = b.un(Unary::Acos, ratio);
    let angle = b.mulc(angle, 1.0 / 3.0);
    let m = b.un(Unary::Cos, angle);
    let n = b.un(Unary::Sin, angle);
    let n = b.mulc(n, 3f64.sqrt());
    // t₁ = 2m·z - kx, t₂ = -(n + m)·z - kx (the third root is never the nearest).
    let t1 = b.mulc(m, 2.0);
    let t1 = b.mul(t1, z);
    let t1 = b.subc(t1, kx);
    let t1 = b.clampc(t1, 0.0, 1.0);
    let nm = b.add(n, m);
    let t2 = b.mul(nm, z);
    let t2 = b.neg(t2);
    let t2 = b.subc(t2, kx);
    let t2 = b.clampc(t2, 0.0, 1.0);
    let d1 = at(b, t1);
    let d2 = at(b, t2);
    let three = b.min(d1, d2);
    let cubic = b.lt(h, zero);
    let dd = b.select(cubic, three, one);
    b.sqrt(dd)
}

/// The inverse rotation (transpose of the rows `m`): q_j = Σ_i p_i·m[i][j].
pub(super) fn rotate(b: &mut Builder, p: P, m: &[V3; 3]) -> P {
    [0, 1, 2].map(|j| {
        let terms: Vec<Reg> = (0..3).map(|i| b.mulc(p[i], m[i][j])).collect();
        let s = b.add(terms[0], terms[1]);
        b.add(s, terms[2])
    })
}

/// Domain repetition per axis with period s (0: none). Infinite: p - s·round(p/s). Finite
/// with n copies: u = p/s + (n-1)/2, id = clamp(round(u), 0, n-1), q = p - s·(id - (n-1)/2).
pub(super) fn repeat(b: &mut Builder, p: P, period: V3, count: Option<V3>) -> P {
    b.map3(p, |b, x, i| {
        let s = period[i];
        if s == 0.0 {
            return x;
        }
        let cell = cell_index(b, x, s, count.map(|n| n[i]));
        let off = b.mulc(cell, s);
        b.sub(x, off)
    })
}

/// The index of the cell holding coordinate `x` along an axis of period `s` ≠ 0, centred on
/// the middle copy: −(n−1)/2 … (n−1)/2 for `n` copies, any integer for infinitely many.
pub(super) fn cell_index(b: &mut Builder, x: Reg, s: f64, n: Option<f64>) -> Reg {
    let u = b.mulc(x, 1.0 / s);
    match n {
        None => b.un(Unary::Round, u),
        Some(n) => {
            let half = (n - 1.0) * 0.5;
            let u = b.addc(u, half);
            let id = b.un(Unary::Round, u);
            let id = b.clampc(id, 0.0, n - 1.0);
            b.subc(id, half)
        }
    }
}
