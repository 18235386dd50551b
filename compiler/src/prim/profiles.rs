//! The profiles (2D shapes in the xy plane) marched by formula, each with its entry and its
//! distance: the circle, the rounded rectangle and the arc; and the rectangle's distance,
//! which the rectangle profile and the extrusions share.

use super::Kind::{Angle as A, Float as F, Vec2 as V2};
use super::Range::{NonNeg, Pos, Within};
use super::{any, param, within_halves, Def, Extent, Field, Prim};
use crate::program::builder::{Builder, P};
use crate::program::Reg;

pub(super) static PRIMS: &[Prim] = &[
    Prim {
        name: "circle",
        profile: true,
        params: &[param("radius", F, Def::Num(0.5), Pos)],
        accepts: "`radius` > 0",
        doc: "A disc about the origin.",
        check: any,
        field: Field::Exact,
        extent: |a| Extent::centred([a.f(0), a.f(0), 0.0], a.f(0), [true; 3]),
        cost: |_| 4.0,
        distance: |b, p, a| {
            let l = b.len2(p[0], p[1]);
            b.subc(l, a.f(0))
        },
    },
    Prim {
        name: "round_rect",
        profile: true,
        params: &[
            param("half", V2, Def::Req, Pos),
            param("radius", F, Def::Num(0.05), NonNeg),
        ],
        accepts: "`half` > 0; `radius` ≥ 0 and at most each half-extent",
        doc: "A rectangle with its corners rounded by `radius`, inside the extents.",
        check: |a| within_halves(&a.v2(0), a.f(1), "rounding radius", "rectangle"),
        field: Field::Exact,
        extent: |a| {
            let h = a.v2(0);
            Extent::centred([h[0], h[1], 0.0], h[0].hypot(h[1]), [true; 3])
        },
        cost: |_| 12.0,
        distance: |b, p, a| {
            let r = a.f(1);
            let d = rect(b, p, a.v2(0).map(|h| h - r));
            b.subc(d, r)
        },
    },
    Prim {
        name: "arc",
        profile: true,
        params: &[
            param("radius", F, Def::Num(0.5), Pos),
            param("angle", A, Def::Req, Within(0.0, std::f64::consts::TAU)),
            param("thickness", F, Def::Num(0.1), Pos),
        ],
        accepts: "`radius`, `thickness` > 0; `angle` 0 … 360deg",
        doc: "The arc of the circle of `radius` about the origin spanning `angle`, centred on +y (from 90° − angle/2 to 90° + angle/2), stroked `thickness` wide with round ends (Quilez's `sdArc`). `arc(r, 360deg, t)` is `ring(r, t)`.",
        check: any,
        field: Field::Exact,
        extent: |a| {
            let r = a.f(0) + a.f(2) / 2.0;
            Extent::centred([r, r, 0.0], r, [true, false, true])
        },
        cost: |_| 20.0,
        distance: |b, p, a| arc(b, p, a.f(0), a.f(1) / 2.0, a.f(2) / 2.0),
    },
];

/// The exact distance to the rectangle of half-extents `h` in the xy plane (Quilez's
/// `sdBox` in 2D): q = |p.xy| - h; |max(q, 0)| + min(max(q.x, q.y), 0).
pub(crate) fn rect(b: &mut Builder, p: P, h: [f64; 2]) -> Reg {
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

/// The exact distance to the arc of radius `r` within `half` of +y on either side, stroked
/// to `w` (Quilez's `sdArc`): with x folded to |x| and (s, c) = (sin half, cos half), the
/// distance to the arc's end r·(s, c) where the point lies beyond it (c·x > s·y), else
/// ||p| - r|; less w.
fn arc(b: &mut Builder, p: P, r: f64, half: f64, w: f64) -> Reg {
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
