//! Primitives with flat faces, each with its entry and its distance (Quilez's distance
//! functions, written over the program's operations): hexagonal and triangular prisms, the
//! octahedron, the pyramid and the box frame.

use super::solids::{box_from_q, extrude, sign};
use super::Kind::{Float as F, Vec3 as V};
use super::Range::Pos;
use super::{any, param, within_halves, Def, Extent, Field, Prim};
use crate::program::builder::{Builder, P};
use crate::program::Reg;

type V3 = [f64; 3];

pub(super) static PRIMS: &[Prim] = &[
    Prim {
        name: "hex_prism",
        profile: false,
        params: &[
            param("radius", F, Def::Num(0.5), Pos),
            param("height", F, Def::Num(1.0), Pos),
        ],
        accepts: "`radius` > 0; `height` > 0",
        doc: "A hexagonal prism along y; `radius` is the distance from the axis to each flat side (two of them face ±z).",
        check: any,
        field: Field::Exact,
        extent: |a| {
            let (r, h) = (a.f(0), a.f(1) / 2.0);
            let corner = r * 2.0 / 3f64.sqrt();
            Extent::centred([corner, h, r], corner.hypot(h), [true; 3])
        },
        cost: |_| 32.0,
        distance: |b, p, a| hex_prism(b, p, a.f(0), a.f(1) / 2.0),
    },
    Prim {
        name: "tri_prism",
        profile: false,
        params: &[
            param("radius", F, Def::Num(0.5), Pos),
            param("height", F, Def::Num(1.0), Pos),
        ],
        accepts: "`radius` > 0; `height` > 0",
        doc: "A prism along y of an equilateral triangle, a corner towards +z; `radius` is the distance from the axis to each side.",
        check: any,
        field: Field::Exact,
        extent: |a| {
            let (r, h) = (a.f(0), a.f(1) / 2.0);
            // From z = -r to the corner at z = 2r, x within ±√3·r: about (0, 0, r/2).
            let w = 3f64.sqrt() * r;
            Extent {
                min: [-w, -h, -r],
                max: [w, h, 2.0 * r],
                radius: (5.25f64.sqrt() * r).hypot(h),
                symmetric: [true, true, false],
            }
        },
        cost: |_| 32.0,
        distance: |b, p, a| tri_prism(b, p, a.f(0), a.f(1) / 2.0),
    },
    Prim {
        name: "octahedron",
        profile: false,
        params: &[param("radius", F, Def::Num(1.0), Pos)],
        accepts: "`radius` > 0",
        doc: "A regular octahedron with its corners on the axes, `radius` from the centre.",
        check: any,
        field: Field::Exact,
        extent: |a| Extent::centred([a.f(0); 3], a.f(0), [true; 3]),
        cost: |_| 35.0,
        distance: |b, p, a| octahedron(b, p, a.f(0)),
    },
    Prim {
        name: "pyramid",
        profile: false,
        params: &[
            param("base", F, Def::Num(1.0), Pos),
            param("height", F, Def::Num(1.0), Pos),
        ],
        accepts: "`base` > 0; `height` > 0",
        doc: "A pyramid along y: a square base of side `base` at `-height/2`, its apex at `height/2`.",
        check: any,
        field: Field::Exact,
        extent: |a| {
            let (b, h) = (a.f(0) / 2.0, a.f(1) / 2.0);
            Extent::centred([b, h, b], (2.0 * b * b + h * h).sqrt(), [true, false, true])
        },
        cost: |_| 55.0,
        distance: |b, p, a| pyramid(b, p, a.f(0), a.f(1)),
    },
    Prim {
        name: "box_frame",
        profile: false,
        params: &[
            param("half", V, Def::V3([0.5, 0.5, 0.5]), Pos),
            param("edge", F, Def::Num(0.05), Pos),
        ],
        accepts: "`half` > 0; `edge` > 0, at most every half-extent",
        doc: "The twelve edges of the box of half-extents `half`, as square bars `2·edge` thick inside it.",
        check: |a| within_halves(&a.v3(0), a.f(1), "edge", "frame"),
        field: Field::Exact,
        extent: |a| {
            let h = a.v3(0);
            let r = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
            Extent::centred(h, r, [true; 3])
        },
        cost: |_| 60.0,
        distance: |b, p, a| box_frame(b, p, a.v3(0), a.f(1)),
    },
];

/// Quilez's exact hexagonal prism (`sdHexPrism`), its axis along y and its hexagon in the xz
/// plane with flat sides at z = ±r: with k = (-√3/2, 1/2, 1/√3) and p = |p|,
/// p.xz -= 2·min(dot(k.xy, p.xz), 0)·k.xy,
/// d2 = |p.xz - (clamp(p.x, -k.z·r, k.z·r), r)|·sign(p.z - r), then extruded to half-height h.
fn hex_prism(b: &mut Builder, p: P, r: f64, h: f64) -> Reg {
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
fn tri_prism(b: &mut Builder, p: P, r: f64, h: f64) -> Reg {
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
fn octahedron(b: &mut Builder, p: P, s: f64) -> Reg {
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
fn pyramid(b: &mut Builder, p: P, base: f64, height: f64) -> Reg {
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
fn box_frame(b: &mut Builder, p: P, half: V3, e: f64) -> Reg {
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
