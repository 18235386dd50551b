//! Lowering rules of the primitives: Quilez's distance functions written as scalar code.
//! Every primitive is centred on the origin; `p` is the point in the primitive's frame. The
//! exact primitives that a marched scene's instances may be read their constants through
//! [`Builder::param`] from their [`slots`], so that the same rules give both the program and
//! the GPU walk's shape functions (back/wgsl/march.rs), which read the slots from `scene_data`.

use super::builder::{Builder, Slots, P};
use super::{Binary, Reg, Unary};
use crate::scene::{Node, V3};

/// The constants of an exact primitive, four numbers: what its formula below reads as
/// `s[0..4]` ([`Builder::param`]), and what the GPU's walk over a marched scene's instances
/// reads from `scene_data` (back/wgsl/march.rs). Derived constants are computed here, in f64,
/// once: a round box's inner half-extents, a cone's 2h² and 1 / (r² + 4h²). `None` for the
/// other primitives (a plane, an ellipsoid, a Mandelbulb, which no instance is).
pub fn slots(node: &Node) -> Option<Slots> {
    Some(match *node {
        Node::Sphere { radius } => [radius, 0.0, 0.0, 0.0],
        Node::Box { half } => [half[0], half[1], half[2], 0.0],
        Node::RoundBox { half, radius: r } => [half[0] - r, half[1] - r, half[2] - r, r],
        Node::Torus { major, minor } => [major, minor, 0.0, 0.0],
        Node::Cylinder {
            radius,
            half_height,
        }
        | Node::Capsule {
            radius,
            half_height,
        } => [radius, half_height, 0.0, 0.0],
        Node::Cone {
            radius: r,
            half_height: h,
        } => [r, h, 2.0 * h * h, 1.0 / (r * r + 4.0 * h * h)],
        _ => return None,
    })
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

fn box_from_q(b: &mut Builder, q: P) -> Reg {
    let outside = b.max3c(q, 0.0);
    let outside = b.len3(outside);
    let inside = b.max_comp(q);
    let inside = b.minc(inside, 0.0);
    b.add(outside, inside)
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

/// Capped cylinder along y, with s = (r, h, ·, ·): d = |(|p.xz|, p.y)| - (r, h);
/// min(max(d.x, d.y), 0) + |max(d, 0)|
fn cylinder(b: &mut Builder, p: P, s: &Slots) -> Reg {
    let xz = b.len2(p[0], p[2]);
    let r = b.param(s, 0, 1.0);
    let dx = b.sub(xz, r);
    let ay = b.abs(p[1]);
    let h = b.param(s, 1, 1.0);
    let dy = b.sub(ay, h);
    let inside = b.max(dx, dy);
    let inside = b.minc(inside, 0.0);
    let ox = b.maxc(dx, 0.0);
    let oy = b.maxc(dy, 0.0);
    let outside = b.len2(ox, oy);
    b.add(inside, outside)
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
    let inside_x = b.lt(cbx, zero);
    let inside_y = b.lt(cay, zero);
    let inside = b.mul(inside_x, inside_y);
    let one = b.c(1.0);
    let minus = b.c(-1.0);
    let s = b.select(inside, minus, one);
    let da = b.dot2(cax, cay, cax, cay);
    let db = b.dot2(cbx, cby, cbx, cby);
    let m = b.min(da, db);
    let m = b.sqrt(m);
    b.mul(s, m)
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

/// Escape radius of the Mandelbulb iteration.
const BAILOUT: f64 = 2.0;

/// The Mandelbulb distance estimator 0.5·ln(r)·r/dr, with `iterations` unrolled steps of
/// z ← zⁿ + p in spherical coordinates (y up). A point escapes when r > 2; from then on
/// `select` keeps its state. Beyond |p| > 4 the field is |p| - 2 (the set lies inside the
/// ball of radius 2), which keeps the far field a bound where the estimator would overstate.
pub(super) fn mandelbulb(b: &mut Builder, p: P, power: f64, iterations: u32) -> Reg {
    let mut z = p;
    let mut dr = b.c(1.0);
    for _ in 0..iterations {
        let r = b.len3(z);
        let bailout = b.c(BAILOUT);
        let escaped = b.lt(bailout, r);
        let (nz, ndr) = bulb_step(b, p, z, r, dr, power);
        z = [0, 1, 2].map(|i| b.select(escaped, z[i], nz[i]));
        dr = b.select(escaped, dr, ndr);
    }
    let r = b.len3(z);
    let r = b.maxc(r, 1e-30);
    let lr = b.un(Unary::Log, r);
    let d = b.mul(lr, r);
    let d = b.mulc(d, 0.5);
    let de = b.div(d, dr);
    let r0 = b.len3(p);
    let four = b.c(4.0);
    let far = b.lt(four, r0);
    let sphere = b.subc(r0, BAILOUT);
    b.select(far, sphere, de)
}

/// One iteration: dr ← n·rⁿ⁻¹·dr + 1, z ← rⁿ·(sin nθ cos nφ, cos nθ, sin nθ sin nφ) + p with
/// θ = acos(z.y / r), φ = atan2(z.z, z.x).
fn bulb_step(b: &mut Builder, p: P, z: P, r: Reg, dr: Reg, n: f64) -> (P, Reg) {
    let ((cos_nt, sin_nt), (cos_np, sin_np), rn1) = match integer_power(n) {
        Some(k) => bulb_angles_algebraic(b, z, r, k),
        None => bulb_angles_trig(b, z, r, n),
    };
    let ndr = b.mul(rn1, dr);
    let ndr = b.mulc(ndr, n);
    let ndr = b.addc(ndr, 1.0);
    let rn = b.mul(rn1, r);
    let x = b.mul(sin_nt, cos_np);
    let z2 = b.mul(sin_nt, sin_np);
    let dir = [x, cos_nt, z2];
    let nz = [0, 1, 2].map(|i| {
        let s = b.mul(rn, dir[i]);
        b.add(s, p[i])
    });
    (nz, ndr)
}

/// Powers the algebraic iteration handles: whole numbers from 2 to 64.
fn integer_power(n: f64) -> Option<u32> {
    (n.fract() == 0.0 && (2.0..=64.0).contains(&n)).then_some(n as u32)
}

/// A pair of registers: (cos, sin) of an angle.
type Angle = (Reg, Reg);

/// (cos nθ, sin nθ), (cos nφ, sin nφ) and rⁿ⁻¹ by acos, atan2 and pow.
fn bulb_angles_trig(b: &mut Builder, z: P, r: Reg, n: f64) -> (Angle, Angle, Reg) {
    let safe_r = b.maxc(r, 1e-30);
    let cos_t = b.div(z[1], safe_r);
    let cos_t = b.clampc(cos_t, -1.0, 1.0);
    let theta = b.un(Unary::Acos, cos_t);
    let theta = b.mulc(theta, n);
    let phi = b.bin(Binary::Atan2, z[2], z[0]);
    let phi = b.mulc(phi, n);
    let e = b.c(n - 1.0);
    let rn1 = b.bin(Binary::Pow, r, e);
    let t = (b.un(Unary::Cos, theta), b.un(Unary::Sin, theta));
    let f = (b.un(Unary::Cos, phi), b.un(Unary::Sin, phi));
    (t, f, rn1)
}

/// The same without trigonometry, for a whole power k (de Moivre): cos θ = z.y / r,
/// sin θ = √(1 - cos²θ) (θ ∈ [0, π]), cos φ = z.x / ρ, sin φ = z.z / ρ with ρ = |z.xz|, then
/// (cos + i·sin)^k and r^(k-1) by repeated squaring.
fn bulb_angles_algebraic(b: &mut Builder, z: P, r: Reg, k: u32) -> (Angle, Angle, Reg) {
    let safe_r = b.maxc(r, 1e-30);
    let cos_t = b.div(z[1], safe_r);
    let cos_t = b.clampc(cos_t, -1.0, 1.0);
    let c2 = b.mul(cos_t, cos_t);
    let one = b.c(1.0);
    let s2 = b.sub(one, c2);
    let s2 = b.maxc(s2, 0.0);
    let sin_t = b.sqrt(s2);
    let rho = b.len2(z[0], z[2]);
    let rho = b.maxc(rho, 1e-30);
    let cos_p = b.div(z[0], rho);
    let sin_p = b.div(z[2], rho);
    let t = complex_pow(b, (cos_t, sin_t), k);
    let f = complex_pow(b, (cos_p, sin_p), k);
    let rn1 = real_pow(b, r, k - 1);
    (t, f, rn1)
}

/// (a + ib)^k by squaring.
fn complex_pow(b: &mut Builder, base: Angle, k: u32) -> Angle {
    let mut acc = (b.c(1.0), b.c(0.0));
    let mut base = base;
    let mut k = k;
    while k > 0 {
        if k & 1 == 1 {
            acc = complex_mul(b, acc, base);
        }
        k >>= 1;
        if k > 0 {
            base = complex_square(b, base);
        }
    }
    acc
}

/// (a + ib)² = (a - b)(a + b) + i·2ab, in five operations.
fn complex_square(b: &mut Builder, (a, c): Angle) -> Angle {
    let (d, s) = (b.sub(a, c), b.add(a, c));
    let re = b.mul(d, s);
    let ac = b.mul(a, c);
    (re, b.add(ac, ac))
}

fn complex_mul(b: &mut Builder, (a, c): Angle, (d, e): Angle) -> Angle {
    let (ad, ce, ae, cd) = (b.mul(a, d), b.mul(c, e), b.mul(a, e), b.mul(c, d));
    (b.sub(ad, ce), b.add(ae, cd))
}

/// x^k by squaring.
fn real_pow(b: &mut Builder, x: Reg, k: u32) -> Reg {
    let mut acc = b.c(1.0);
    let mut base = x;
    let mut k = k;
    while k > 0 {
        if k & 1 == 1 {
            acc = b.mul(acc, base);
        }
        k >>= 1;
        if k > 0 {
            base = b.mul(base, base);
        }
    }
    acc
}
