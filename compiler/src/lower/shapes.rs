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
    nearer_signed(b, zero, [cax, cay], [cbx, cby])
}

/// -1 where `x < 0`, else 1 (GLSL's `sign` but for 0, where every use below multiplies a
/// zero length).
fn sign(b: &mut Builder, x: Reg) -> Reg {
    let zero = b.c(0.0);
    let neg = b.lt(x, zero);
    let minus = b.c(-1.0);
    let one = b.c(1.0);
    b.select(neg, minus, one)
}

/// The exact distance of a 2D field `d` extruded along a coordinate `y` to half-height `h`
/// (Quilez's `opExtrusion`): w = (d, |y| - h); min(max(w.x, w.y), 0) + |max(w, 0)|.
pub(super) fn extrude(b: &mut Builder, d: Reg, y: Reg, h: f64) -> Reg {
    let ay = b.abs(y);
    let wy = b.subc(ay, h);
    let inside = b.max(d, wy);
    let inside = b.minc(inside, 0.0);
    let ox = b.maxc(d, 0.0);
    let oy = b.maxc(wy, 0.0);
    let outside = b.len2(ox, oy);
    b.add(inside, outside)
}

/// The tail of Quilez's cone distances: the nearer of the offsets `ca` (to the caps) and
/// `cb` (to the slanted side), negative where both place the point inside (cb.x < 0 and
/// ca.y < 0).
fn nearer_signed(b: &mut Builder, zero: Reg, [cax, cay]: [Reg; 2], [cbx, cby]: [Reg; 2]) -> Reg {
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

/// Quilez's exact capped cone (`sdCappedCone`) along y, radius r1 at y = -h and r2 at y = +h:
/// q = (|p.xz|, p.y), k1 = (r2, h), k2 = (r2 - r1, 2h),
/// ca = (q.x - min(q.x, q.y < 0 ? r1 : r2), |q.y| - h),
/// cb = q - k1 + k2·clamp(dot(k1 - q, k2) / dot(k2, k2), 0, 1),
/// d = ±√min(|ca|², |cb|²), negative where cb.x < 0 and ca.y < 0.
pub(super) fn capped_cone(b: &mut Builder, p: P, h: f64, r1: f64, r2: f64) -> Reg {
    let qx = b.len2(p[0], p[2]);
    let qy = p[1];
    let zero = b.c(0.0);
    let below = b.lt(qy, zero);
    let (c1, c2) = (b.c(r1), b.c(r2));
    let cap = b.select(below, c1, c2);
    let cap = b.min(qx, cap);
    let cax = b.sub(qx, cap);
    let ay = b.abs(qy);
    let cay = b.subc(ay, h);
    let (k2x, k2y) = (r2 - r1, 2.0 * h);
    // dot(k1 - q, k2) = (r2 - qx)·k2x + (h - qy)·k2y
    let tx = b.mulc(qx, -k2x);
    let ty = b.mulc(qy, -k2y);
    let t = b.add(tx, ty);
    let t = b.addc(t, r2 * k2x + h * k2y);
    let t = b.mulc(t, 1.0 / (k2x * k2x + k2y * k2y));
    let t = b.clampc(t, 0.0, 1.0);
    let cbx = b.mulc(t, k2x);
    let cbx = b.add(qx, cbx);
    let cbx = b.subc(cbx, r2);
    let cby = b.mulc(t, k2y);
    let cby = b.add(qy, cby);
    let cby = b.subc(cby, h);
    nearer_signed(b, zero, [cax, cay], [cbx, cby])
}

/// Quilez's exact round cone (`sdRoundCone`): the hull of spheres of radii r1 at y = -h and
/// r2 at y = +h. With q = (|p.xz|, p.y + h), s = (r1 - r2) / 2h, c = √(1 - s²) and
/// k = dot(q, (-s, c)): |q| - r1 where k < 0, |q - (0, 2h)| - r2 where k > 2h·c, else
/// dot(q, (c, s)) - r1.
pub(super) fn round_cone(b: &mut Builder, p: P, r1: f64, r2: f64, h: f64) -> Reg {
    let sn = (r1 - r2) / (2.0 * h);
    let cs = (1.0 - sn * sn).max(0.0).sqrt();
    let qx = b.len2(p[0], p[2]);
    let qy = b.addc(p[1], h);
    let kx = b.mulc(qx, -sn);
    let ky = b.mulc(qy, cs);
    let k = b.add(kx, ky);
    let lower = b.len2(qx, qy);
    let lower = b.subc(lower, r1);
    let ty = b.subc(qy, 2.0 * h);
    let upper = b.len2(qx, ty);
    let upper = b.subc(upper, r2);
    let sx = b.mulc(qx, cs);
    let sy = b.mulc(qy, sn);
    let side = b.add(sx, sy);
    let side = b.subc(side, r1);
    let zero = b.c(0.0);
    let below = b.lt(k, zero);
    let top = b.c(2.0 * h * cs);
    let above = b.lt(top, k);
    let d = b.select(above, upper, side);
    b.select(below, lower, d)
}

/// The capsule between two points (Quilez's `sdCapsule`): |pa - ba·clamp(pa·ba / ba·ba, 0, 1)| - r
/// with pa = p - a, ba = b - a (a sphere where a = b).
pub(super) fn segment(b: &mut Builder, p: P, a: V3, e: V3, r: f64) -> Reg {
    let pa = b.sub3c(p, a);
    let ba = [0, 1, 2].map(|i| e[i] - a[i]);
    let bb: f64 = ba.iter().map(|x| x * x).sum();
    if bb == 0.0 {
        let l = b.len3(pa);
        return b.subc(l, r);
    }
    let dir = ba.map(|x| x / bb);
    let dir = b.c3(dir);
    let t = b.dot3(pa, dir);
    let t = b.clampc(t, 0.0, 1.0);
    let q = b.map3(pa, |b, x, i| {
        let o = b.mulc(t, ba[i]);
        b.sub(x, o)
    });
    let l = b.len3(q);
    b.subc(l, r)
}

/// A cylinder of radius `r` and half-height `h` with its rims rounded by `e` (Quilez's
/// `sdRoundedCylinder`): the cylinder of radius r - e and half-height h - e, less e.
pub(super) fn rounded_cylinder(b: &mut Builder, p: P, r: f64, e: f64, h: f64) -> Reg {
    let d = cylinder(b, p, &[r - e, h - e, 0.0, 0.0]);
    b.subc(d, e)
}

/// Quilez's exact hexagonal prism (`sdHexPrism`), its axis along y and its hexagon in the xz
/// plane with flat sides at z = ±r: with k = (-√3/2, 1/2, 1/√3) and p = |p|,
/// p.xz -= 2·min(dot(k.xy, p.xz), 0)·k.xy,
/// d2 = |p.xz - (clamp(p.x, -k.z·r, k.z·r), r)|·sign(p.z - r), then extruded to half-height h.
pub(super) fn hex_prism(b: &mut Builder, p: P, r: f64, h: f64) -> Reg {
    let (kx, ky, kz) = (-(3f64.sqrt()) * 0.5, 0.5, 1.0 / 3f64.sqrt());
    let x = b.abs(p[0]);
    let z = b.abs(p[2]);
    let (kxc, kyc) = (b.c(kx), b.c(ky));
    let dot = b.dot2(x, z, kxc, kyc);
    let dot = b.minc(dot, 0.0);
    let dot = b.mulc(dot, 2.0);
    let ox = b.mulc(dot, kx);
    let x = b.sub(x, ox);
    let oz = b.mulc(dot, ky);
    let z = b.sub(z, oz);
    let cx = b.clampc(x, -kz * r, kz * r);
    let dx = b.sub(x, cx);
    let dz = b.subc(z, r);
    let l = b.len2(dx, dz);
    let s = sign(b, dz);
    let d = b.mul(l, s);
    extrude(b, d, p[1], h)
}

/// An exact triangular prism: Quilez's exact equilateral triangle (`sdEquilateralTriangle`)
/// in the xz plane, its corner towards +z and its sides `r` from the axis (half a side
/// R = √3·r), extruded along y to half-height h. With (x, y) = (|p.x| - R, p.z + r): where
/// x + √3·y > 0, (x, y) = ((x - √3·y) / 2, (-√3·x - y) / 2); then x -= clamp(x, -2R, 0) and
/// d2 = -|(x, y)|·sign(y).
pub(super) fn tri_prism(b: &mut Builder, p: P, r: f64, h: f64) -> Reg {
    let k = 3f64.sqrt();
    let big = k * r;
    let x = b.abs(p[0]);
    let x = b.subc(x, big);
    let y = b.addc(p[2], r);
    let ky = b.mulc(y, k);
    let test = b.add(x, ky);
    let zero = b.c(0.0);
    let fold = b.lt(zero, test);
    let fx = b.sub(x, ky);
    let fx = b.mulc(fx, 0.5);
    let kx = b.mulc(x, -k);
    let fy = b.sub(kx, y);
    let fy = b.mulc(fy, 0.5);
    let x = b.select(fold, fx, x);
    let y = b.select(fold, fy, y);
    let c = b.clampc(x, -2.0 * big, 0.0);
    let x = b.sub(x, c);
    let l = b.len2(x, y);
    let s = sign(b, y);
    let d = b.mul(l, s);
    let d = b.neg(d);
    extrude(b, d, p[1], h)
}

/// Quilez's exact octahedron (`sdOctahedron`): with p = |p| and m = p.x + p.y + p.z - s, the
/// first of p.xyz, p.yzx, p.zxy whose first component is below m / 3 gives q, and
/// k = clamp((q.z - q.y + s) / 2, 0, s), d = |(q.x, q.y - s + k, q.z - k)|; where none is,
/// d = m / √3.
pub(super) fn octahedron(b: &mut Builder, p: P, s: f64) -> Reg {
    let a = b.abs3(p);
    let sum = b.add(a[0], a[1]);
    let sum = b.add(sum, a[2]);
    let m = b.subc(sum, s);
    let c = [0, 1, 2].map(|i| {
        let t = b.mulc(a[i], 3.0);
        b.lt(t, m)
    });
    let pick = |b: &mut Builder, i: usize| {
        let second = b.select(c[1], a[(i + 1) % 3], a[(i + 2) % 3]);
        b.select(c[0], a[i], second)
    };
    let q = [pick(b, 0), pick(b, 1), pick(b, 2)];
    let k = b.sub(q[2], q[1]);
    let k = b.addc(k, s);
    let k = b.mulc(k, 0.5);
    let k = b.clampc(k, 0.0, s);
    let y = b.subc(q[1], s);
    let y = b.add(y, k);
    let z = b.sub(q[2], k);
    let near = b.len3([q[0], y, z]);
    let far = b.mulc(m, 1.0 / 3f64.sqrt());
    let any = b.max(c[1], c[2]);
    let any = b.max(c[0], any);
    b.select(any, near, far)
}

/// Quilez's exact pyramid (`sdPyramid`, a base of side 1 at y = 0 and its apex at height
/// h), scaled by the side `base` and moved down by half its height:
/// m2 = h² + 1/4; p.xz = |p.xz| sorted so that x ≥ z, less 1/2;
/// q = (p.z, h·p.y - p.x / 2, h·p.x + p.y / 2), s = max(-q.x, 0),
/// t = clamp((q.y - p.z / 2) / (m2 + 1/4), 0, 1),
/// a = m2·(q.x + s)² + q.y², b = m2·(q.x + t/2)² + (q.y - m2·t)²,
/// d2 = 0 where min(q.y, -q.x·m2 - q.y/2) > 0, else min(a, b);
/// d = √((d2 + q.z²) / m2)·sign(max(q.z, -p.y)). That is the distance to the sides; the
/// base is added here: max(d, -p.y) where p.y ≥ 0, and below the base's plane the distance
/// to the base square, |(max(|p.x| - ½, 0), p.y, max(|p.z| - ½, 0))|.
pub(super) fn pyramid(b: &mut Builder, p: P, base: f64, height: f64) -> Reg {
    let h = height / base;
    let m2 = h * h + 0.25;
    let inv = 1.0 / base;
    let px = b.mulc(p[0], inv);
    let py = b.addc(p[1], height * 0.5);
    let py = b.mulc(py, inv);
    let pz = b.mulc(p[2], inv);
    let ax = b.abs(px);
    let az = b.abs(pz);
    let x = b.max(ax, az);
    let z = b.min(ax, az);
    let x = b.subc(x, 0.5);
    let z = b.subc(z, 0.5);
    let qx = z;
    let hy = b.mulc(py, h);
    let hx = b.mulc(x, 0.5);
    let qy = b.sub(hy, hx);
    let hx = b.mulc(x, h);
    let hy = b.mulc(py, 0.5);
    let qz = b.add(hx, hy);
    let s = b.neg(qx);
    let s = b.maxc(s, 0.0);
    let hz = b.mulc(z, 0.5);
    let t = b.sub(qy, hz);
    let t = b.mulc(t, 1.0 / (m2 + 0.25));
    let t = b.clampc(t, 0.0, 1.0);
    let qs = b.add(qx, s);
    let qs2 = b.mul(qs, qs);
    let qy2 = b.mul(qy, qy);
    let a = b.mulc(qs2, m2);
    let a = b.add(a, qy2);
    let ht = b.mulc(t, 0.5);
    let qt = b.add(qx, ht);
    let qt2 = b.mul(qt, qt);
    let mt = b.mulc(t, m2);
    let ym = b.sub(qy, mt);
    let ym2 = b.mul(ym, ym);
    let bb = b.mulc(qt2, m2);
    let bb = b.add(bb, ym2);
    let l = b.mulc(qx, -m2);
    let half_y = b.mulc(qy, 0.5);
    let l = b.sub(l, half_y);
    let l = b.min(qy, l);
    let zero = b.c(0.0);
    let flat = b.lt(zero, l);
    let ab = b.min(a, bb);
    let d2 = b.select(flat, zero, ab);
    let qz2 = b.mul(qz, qz);
    let d2 = b.add(d2, qz2);
    let d2 = b.mulc(d2, 1.0 / m2);
    let d = b.sqrt(d2);
    let ny = b.neg(py);
    let sg = b.max(qz, ny);
    let sg = sign(b, sg);
    let d = b.mul(d, sg);
    // Quilez's value is the distance to the sides alone: inside, the base may be nearer;
    // below the base's plane the nearest point is on the base.
    let lateral = b.max(d, ny);
    let bx = b.subc(ax, 0.5);
    let bx = b.maxc(bx, 0.0);
    let bz = b.subc(az, 0.5);
    let bz = b.maxc(bz, 0.0);
    let below = b.len3([bx, py, bz]);
    let under = b.lt(py, zero);
    let d = b.select(under, below, lateral);
    b.mulc(d, base)
}

/// Quilez's exact box frame (`sdBoxFrame`): with p = |p| - half and q = |p + e| - e, the
/// nearest of the three groups of bars, each the box formula over one component of p and two
/// of q.
pub(super) fn box_frame(b: &mut Builder, p: P, half: V3, e: f64) -> Reg {
    let a = b.abs3(p);
    let p = b.sub3c(a, half);
    let q = b.map3(p, |b, x, _| {
        let x = b.addc(x, e);
        let x = b.abs(x);
        b.subc(x, e)
    });
    let x = box_from_q(b, [p[0], q[1], q[2]]);
    let y = box_from_q(b, [q[0], p[1], q[2]]);
    let z = box_from_q(b, [q[0], q[1], p[2]]);
    let m = b.min(x, y);
    b.min(m, z)
}

/// Quilez's exact link (`sdLink`): q = (p.x, max(|p.y| - l, 0), p.z);
/// |(|q.xy| - R, q.z)| - r.
pub(super) fn link(b: &mut Builder, p: P, l: f64, major: f64, minor: f64) -> Reg {
    let ay = b.abs(p[1]);
    let y = b.subc(ay, l);
    let y = b.maxc(y, 0.0);
    let xy = b.len2(p[0], y);
    let x = b.subc(xy, major);
    let d = b.len2(x, p[2]);
    b.subc(d, minor)
}

/// |p - (p·a)·a| - r: the distance to the line through the origin along the unit axis a,
/// less the radius.
pub(super) fn infinite_cylinder(b: &mut Builder, p: P, r: f64, axis: V3) -> Reg {
    let a = b.c3(axis);
    let t = b.dot3(p, a);
    let q = b.map3(p, |b, x, i| {
        let o = b.mulc(t, axis[i]);
        b.sub(x, o)
    });
    let l = b.len3(q);
    b.subc(l, r)
}

/// |p·n| - t/2: the slab of thickness t about the plane through the origin with unit normal n.
pub(super) fn slab(b: &mut Builder, p: P, t: f64, n: V3) -> Reg {
    let n = b.c3(n);
    let d = b.dot3(p, n);
    let d = b.abs(d);
    b.subc(d, t * 0.5)
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

/// The exact distance to the rectangle of half-extents `h` in the xy plane (Quilez's
/// `sdBox` in 2D): q = |p.xy| - h; |max(q, 0)| + min(max(q.x, q.y), 0).
pub(super) fn rect(b: &mut Builder, p: P, h: [f64; 2]) -> Reg {
    let q = [0, 1].map(|i| {
        let a = b.abs(p[i]);
        b.subc(a, h[i])
    });
    let ox = b.maxc(q[0], 0.0);
    let oy = b.maxc(q[1], 0.0);
    let outside = b.len2(ox, oy);
    let inside = b.max(q[0], q[1]);
    let inside = b.minc(inside, 0.0);
    b.add(outside, inside)
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

/// The exact distance to the arc of radius `r` within `half` of +y on either side, stroked
/// to `w` (Quilez's `sdArc`): with x folded to |x| and (s, c) = (sin half, cos half), the
/// distance to the arc's end r·(s, c) where the point lies beyond it (c·x > s·y), else
/// ||p| - r|; less w.
pub(super) fn arc(b: &mut Builder, p: P, r: f64, half: f64, w: f64) -> Reg {
    let (s, c) = half.sin_cos();
    let x = b.abs(p[0]);
    let y = p[1];
    let sy = b.mulc(y, s);
    let cx = b.mulc(x, c);
    let beyond = b.lt(sy, cx);
    let ex = b.subc(x, r * s);
    let ey = b.subc(y, r * c);
    let end = b.len2(ex, ey);
    let l = b.len2(x, y);
    let ring = b.subc(l, r);
    let ring = b.abs(ring);
    let d = b.select(beyond, end, ring);
    b.subc(d, w)
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
