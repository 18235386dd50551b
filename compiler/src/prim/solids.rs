//! Primitives of round cross-section and the planes' kin, each with its entry and its
//! distance (Quilez's distance functions, written over the program's operations): capped and
//! round cones, segments, rounded cylinders, chain links, infinite cylinders and slabs; and
//! the helpers other distances share (an extrusion, the tail of the cones' distances).

use super::Kind::{Float as F, Vec3 as V};
use super::Range::{Any, NonNeg, NonZero, Pos};
use super::{any, num, param, unit, Args, Def, Extent, Field, Prim};
use crate::program::builder::{Builder, Slots, P};
use crate::program::Reg;

type V3 = [f64; 3];

pub(super) static PRIMS: &[Prim] = &[
    Prim {
        name: "capped_cone",
        profile: false,
        params: &[
            param("height", F, Def::Num(1.0), Pos),
            param("bottom", F, Def::Num(0.5), NonNeg),
            param("top", F, Def::Num(0.25), NonNeg),
        ],
        accepts: "`height` > 0; `bottom`, `top` ≥ 0, not both 0",
        doc: "A cone along y cut at both ends (a frustum): radius `bottom` at `-height/2`, `top` at `height/2`.",
        check: no_volume::<1, 2>,
        field: Field::Exact,
        extent: |a| {
            let (h, r) = (a.f(0) / 2.0, a.f(1).max(a.f(2)));
            Extent::centred([r, h, r], r.hypot(h), [true, false, true])
        },
        cost: |_| 40.0,
        distance: |b, p, a| capped_cone(b, p, &capped_cone_slots(a.f(0) / 2.0, a.f(1), a.f(2))),
    },
    Prim {
        name: "round_cone",
        profile: false,
        params: &[
            param("bottom", F, Def::Num(0.5), NonNeg),
            param("top", F, Def::Num(0.25), NonNeg),
            param("height", F, Def::Num(1.0), Pos),
        ],
        accepts: "`bottom`, `top` ≥ 0, not both 0; `height` > 0 and above \\|`bottom` − `top`\\|",
        doc: "The hull of a sphere of radius `bottom` at `-height/2` and one of radius `top` at `height/2` on the y axis.",
        check: |a| {
            let (bottom, top, height) = (a.f(0), a.f(1), a.f(2));
            no_volume::<0, 1>(a).or_else(|| {
                ((bottom - top).abs() >= height).then(|| format!(
                    "the radii differ by {} but the height is {}: one sphere would hold the other (a round cone needs |bottom - top| < height)",
                    num((bottom - top).abs()),
                    num(height)
                ))
            })
        },
        field: Field::Exact,
        extent: |a| {
            let (bottom, top, h) = (a.f(0), a.f(1), a.f(2) / 2.0);
            let r = bottom.max(top);
            let c = (top - bottom) / 2.0;
            Extent {
                min: [-r, -h - bottom, -r],
                max: [r, h + top, r],
                radius: (h + c + bottom).max(h - c + top),
                symmetric: [true, false, true],
            }
        },
        cost: |_| 30.0,
        distance: |b, p, a| round_cone(b, p, &round_cone_slots(a.f(0), a.f(1), a.f(2) / 2.0)),
    },
    Prim {
        name: "segment",
        profile: false,
        params: &[
            param("a", V, Def::Req, Any),
            param("b", V, Def::Req, Any),
            param("radius", F, Def::Num(0.25), Pos),
        ],
        accepts: "`radius` > 0",
        doc: "A capsule between the points `a` and `b`: every point within `radius` of the segment.",
        check: any,
        field: Field::Exact,
        extent: |args| {
            let (a, b, r) = (args.v3(0), args.v3(1), args.f(2));
            // Across plane i: the segment lies in it, or the plane swaps its ends.
            let mirrored =
                |i: usize| (0..3).all(|j| if j == i { a[j] == -b[j] } else { a[j] == b[j] });
            let l = (0..3).map(|i| (b[i] - a[i]).powi(2)).sum::<f64>().sqrt();
            Extent {
                min: [0, 1, 2].map(|i| a[i].min(b[i]) - r),
                max: [0, 1, 2].map(|i| a[i].max(b[i]) + r),
                radius: l / 2.0 + r,
                symmetric: [0, 1, 2].map(|i| (a[i] == 0.0 && b[i] == 0.0) || mirrored(i)),
            }
        },
        cost: |_| 20.0,
        distance: |b, p, a| segment(b, p, a.v3(0), a.v3(1), a.f(2)),
    },
    Prim {
        name: "rounded_cylinder",
        profile: false,
        params: &[
            param("radius", F, Def::Num(0.5), Pos),
            param("round", F, Def::Num(0.1), NonNeg),
            param("height", F, Def::Num(1.0), Pos),
        ],
        accepts: "`radius`, `height` > 0; `round` 0 … min(`radius`, `height/2`)",
        doc: "A cylinder like `cylinder(radius, height)` with its two rims rounded by `round`, within the same extents.",
        check: |a| {
            let (radius, round, height) = (a.f(0), a.f(1), a.f(2));
            (round > radius || round > height / 2.0).then(|| {
                format!(
                    "the rounding {} is larger than the radius or half the height",
                    num(round)
                )
            })
        },
        field: Field::Exact,
        extent: |a| {
            let (r, h) = (a.f(0), a.f(2) / 2.0);
            Extent::centred([r, h, r], r.hypot(h), [true; 3])
        },
        cost: |_| 18.0,
        distance: |b, p, a| rounded_cylinder(b, p, a.f(0), a.f(1), a.f(2) / 2.0),
    },
    Prim {
        name: "link",
        profile: false,
        params: &[
            param("length", F, Def::Num(1.0), NonNeg),
            param("major", F, Def::Num(0.5), Pos),
            param("minor", F, Def::Num(0.1), Pos),
        ],
        accepts: "`length` ≥ 0; `major`, `minor` > 0",
        doc: "A chain link in the xy plane: a torus of radii `major` and `minor` opened along y by straight parts `length` long.",
        check: any,
        field: Field::Exact,
        extent: |a| {
            let (l, r, minor) = (a.f(0) / 2.0, a.f(1) + a.f(2), a.f(2));
            Extent::centred([r, l + r, minor], l + r, [true; 3])
        },
        cost: |_| 14.0,
        distance: |b, p, a| link(b, p, a.f(0) / 2.0, a.f(1), a.f(2)),
    },
    Prim {
        name: "infinite_cylinder",
        profile: false,
        params: &[
            param("radius", F, Def::Num(0.5), Pos),
            param("axis", V, Def::V3([0.0, 1.0, 0.0]), NonZero),
        ],
        accepts: "`radius` > 0; `axis` not (0, 0, 0)",
        doc: "A cylinder without ends about the line through the origin along `axis` (normalised).",
        check: any,
        field: Field::Exact,
        extent: |a| {
            let (r, axis) = (a.f(0), unit(a.v3(1)));
            // ±r across an axis the line is normal to, unbounded along the others.
            let across = |i: usize| axis[i] == 0.0;
            Extent {
                min: [0, 1, 2].map(|i| if across(i) { -r } else { f64::NEG_INFINITY }),
                max: [0, 1, 2].map(|i| if across(i) { r } else { f64::INFINITY }),
                radius: f64::INFINITY,
                symmetric: line_symmetry(axis),
            }
        },
        cost: |_| 14.0,
        distance: |b, p, a| infinite_cylinder(b, p, a.f(0), unit(a.v3(1))),
    },
    Prim {
        name: "slab",
        profile: false,
        params: &[
            param("thickness", F, Def::Num(1.0), Pos),
            param("normal", V, Def::V3([0.0, 1.0, 0.0]), NonZero),
        ],
        accepts: "`thickness` > 0; `normal` not (0, 0, 0)",
        doc: "The space between two parallel planes `thickness` apart, centred on the origin, normal to `normal` (normalised).",
        check: any,
        field: Field::Exact,
        extent: |a| {
            let (h, n) = (a.f(0) / 2.0, unit(a.v3(1)));
            // ±h along an axis-aligned normal, unbounded otherwise.
            let along = |i: usize| n[i] != 0.0 && (0..3).all(|j| j == i || n[j] == 0.0);
            Extent {
                min: [0, 1, 2].map(|i| if along(i) { -h } else { f64::NEG_INFINITY }),
                max: [0, 1, 2].map(|i| if along(i) { h } else { f64::INFINITY }),
                radius: f64::INFINITY,
                symmetric: line_symmetry(n),
            }
        },
        cost: |_| 7.0,
        distance: |b, p, a| slab(b, p, a.f(0), unit(a.v3(1))),
    },
];

/// Refuses a cone whose radii, arguments `B` and `T`, are both 0.
fn no_volume<const B: usize, const T: usize>(a: &Args) -> Option<String> {
    (a.f(B) == 0.0 && a.f(T) == 0.0)
        .then(|| "`bottom` and `top` are both 0: the cone has no volume".to_string())
}

/// The mirror symmetries of a shape about a line or plane through the origin along or
/// normal to `v`: across plane i when `v` lies in it or along its normal.
fn line_symmetry(v: V3) -> [bool; 3] {
    [0, 1, 2].map(|i| v[i] == 0.0 || (0..3).filter(|&j| j != i).all(|j| v[j] == 0.0))
}

/// -1 where `x < 0`, else 1 (GLSL's `sign` but for 0, where every use below multiplies a
/// zero length).
pub(super) fn sign(b: &mut Builder, x: Reg) -> Reg {
    let zero = b.c(0.0);
    let neg = b.lt(x, zero);
    let minus = b.c(-1.0);
    let one = b.c(1.0);
    b.select(neg, minus, one)
}

/// The exact distance of a 2D field `d` extruded along a coordinate `y` to half-height `h`
/// (Quilez's `opExtrusion`): w = (d, |y| - h); min(max(w.x, w.y), 0) + |max(w, 0)|.
pub(crate) fn extrude(b: &mut Builder, d: Reg, y: Reg, h: f64) -> Reg {
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
pub(crate) fn nearer_signed(
    b: &mut Builder,
    zero: Reg,
    [cax, cay]: [Reg; 2],
    [cbx, cby]: [Reg; 2],
) -> Reg {
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

/// The constants of [`capped_cone`] of half-height h, radius r1 at y = -h and r2 at y = +h:
/// (h, r1, r2, k2x, dot(k1, k2), 1 / dot(k2, k2)) with k1 = (r2, h), k2 = (r2 - r1, 2h).
pub(crate) fn capped_cone_slots(h: f64, r1: f64, r2: f64) -> Slots {
    let (k2x, k2y) = (r2 - r1, 2.0 * h);
    let c = r2 * k2x + h * k2y;
    let inv = 1.0 / (k2x * k2x + k2y * k2y);
    [h, r1, r2, k2x, c, inv, 0.0, 0.0]
}

/// Quilez's exact capped cone (`sdCappedCone`) along y, radius r1 at y = -h and r2 at y = +h,
/// its constants `s` ([`capped_cone_slots`]) read through [`Builder::param`]:
/// q = (|p.xz|, p.y), k1 = (r2, h), k2 = (r2 - r1, 2h),
/// ca = (q.x - min(q.x, q.y < 0 ? r1 : r2), |q.y| - h),
/// cb = q - k1 + k2·clamp(dot(k1 - q, k2) / dot(k2, k2), 0, 1),
/// d = ±√min(|ca|², |cb|²), negative where cb.x < 0 and ca.y < 0.
pub(crate) fn capped_cone(b: &mut Builder, p: P, s: &Slots) -> Reg {
    let qx = b.len2(p[0], p[2]);
    let qy = p[1];
    let zero = b.c(0.0);
    let below = b.lt(qy, zero);
    let (c1, c2) = (b.param(s, 1, 1.0), b.param(s, 2, 1.0));
    let cap = b.select(below, c1, c2);
    let cap = b.min(qx, cap);
    let cax = b.sub(qx, cap);
    let ay = b.abs(qy);
    let h = b.param(s, 0, 1.0);
    let cay = b.sub(ay, h);
    // dot(k1 - q, k2) = (r2 - qx)·k2x + (h - qy)·k2y = -k2x·qx - 2h·qy + dot(k1, k2)
    let minus_k2x = b.param(s, 3, -1.0);
    let tx = b.mul(qx, minus_k2x);
    let minus_k2y = b.param(s, 0, -2.0);
    let ty = b.mul(qy, minus_k2y);
    let t = b.add(tx, ty);
    let c = b.param(s, 4, 1.0);
    let t = b.add(t, c);
    let inv = b.param(s, 5, 1.0);
    let t = b.mul(t, inv);
    let t = b.clampc(t, 0.0, 1.0);
    let k2x = b.param(s, 3, 1.0);
    let cbx = b.mul(t, k2x);
    let cbx = b.add(qx, cbx);
    let r2 = b.param(s, 2, 1.0);
    let cbx = b.sub(cbx, r2);
    let k2y = b.param(s, 0, 2.0);
    let cby = b.mul(t, k2y);
    let cby = b.add(qy, cby);
    let h = b.param(s, 0, 1.0);
    let cby = b.sub(cby, h);
    nearer_signed(b, zero, [cax, cay], [cbx, cby])
}

/// The constants of [`round_cone`] of radius r1 at y = -h and r2 at y = +h:
/// (r1, r2, h, s, c, 2h·c) with s = (r1 - r2) / 2h and c = √(1 - s²).
pub(crate) fn round_cone_slots(r1: f64, r2: f64, h: f64) -> Slots {
    let sn = (r1 - r2) / (2.0 * h);
    let cs = (1.0 - sn * sn).max(0.0).sqrt();
    [r1, r2, h, sn, cs, 2.0 * h * cs, 0.0, 0.0]
}

/// Quilez's exact round cone (`sdRoundCone`): the hull of spheres of radii r1 at y = -h and
/// r2 at y = +h, its constants `s` ([`round_cone_slots`]) read through [`Builder::param`].
/// With q = (|p.xz|, p.y + h), s = (r1 - r2) / 2h, c = √(1 - s²) and k = dot(q, (-s, c)):
/// |q| - r1 where k < 0, |q - (0, 2h)| - r2 where k > 2h·c, else dot(q, (c, s)) - r1.
pub(crate) fn round_cone(b: &mut Builder, p: P, s: &Slots) -> Reg {
    let qx = b.len2(p[0], p[2]);
    let h = b.param(s, 2, 1.0);
    let qy = b.add(p[1], h);
    let minus_sn = b.param(s, 3, -1.0);
    let kx = b.mul(qx, minus_sn);
    let cs = b.param(s, 4, 1.0);
    let ky = b.mul(qy, cs);
    let k = b.add(kx, ky);
    let lower = b.len2(qx, qy);
    let r1 = b.param(s, 0, 1.0);
    let lower = b.sub(lower, r1);
    let two_h = b.param(s, 2, 2.0);
    let ty = b.sub(qy, two_h);
    let upper = b.len2(qx, ty);
    let r2 = b.param(s, 1, 1.0);
    let upper = b.sub(upper, r2);
    let cs = b.param(s, 4, 1.0);
    let sx = b.mul(qx, cs);
    let sn = b.param(s, 3, 1.0);
    let sy = b.mul(qy, sn);
    let side = b.add(sx, sy);
    let r1 = b.param(s, 0, 1.0);
    let side = b.sub(side, r1);
    let zero = b.c(0.0);
    let below = b.lt(k, zero);
    let top = b.param(s, 5, 1.0);
    let above = b.lt(top, k);
    let d = b.select(above, upper, side);
    b.select(below, lower, d)
}

/// The capsule between two points (Quilez's `sdCapsule`): |pa - ba·clamp(pa·ba / ba·ba, 0, 1)| - r
/// with pa = p - a, ba = b - a (a sphere where a = b).
fn segment(b: &mut Builder, p: P, a: V3, e: V3, r: f64) -> Reg {
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
fn rounded_cylinder(b: &mut Builder, p: P, r: f64, e: f64, h: f64) -> Reg {
    let d = cylinder(b, p, &[r - e, h - e, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    b.subc(d, e)
}

/// Quilez's exact link (`sdLink`): q = (p.x, max(|p.y| - l, 0), p.z);
/// |(|q.xy| - R, q.z)| - r.
fn link(b: &mut Builder, p: P, l: f64, major: f64, minor: f64) -> Reg {
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
fn infinite_cylinder(b: &mut Builder, p: P, r: f64, axis: V3) -> Reg {
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
fn slab(b: &mut Builder, p: P, t: f64, n: V3) -> Reg {
    let n = b.c3(n);
    let d = b.dot3(p, n);
    let d = b.abs(d);
    b.subc(d, t * 0.5)
}

/// The box distance from q = |p| - half: |max(q, 0)| + min(maxcomp(q), 0).
pub(crate) fn box_from_q(b: &mut Builder, q: P) -> Reg {
    let outside = b.max3c(q, 0.0);
    let outside = b.len3(outside);
    let inside = b.max_comp(q);
    let inside = b.minc(inside, 0.0);
    b.add(outside, inside)
}

/// Capped cylinder along y, with s = (r, h, ·, ·): d = |(|p.xz|, p.y)| - (r, h);
/// min(max(d.x, d.y), 0) + |max(d, 0)|
pub(crate) fn cylinder(b: &mut Builder, p: P, s: &Slots) -> Reg {
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
