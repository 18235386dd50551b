//! Shapes between two points (issue 50, item 3): `cylinder(a, b, radius)`,
//! `cone(a, b, radius_a, radius_b)` and `round_cone(a, b, radius_a, radius_b)`, overloads
//! beside the shapes along y. Each is its shape along y in the frame of the segment from `a`
//! to `b` (centred on its midpoint, the segment along y): a rotation and a translation keep
//! distances, so each is exact as its shape along y is.

use super::solids::{
    capped_cone, capped_cone_slots, cylinder, round_cone, round_cone_slots, PRIMS as ALONG_Y,
};
use super::Kind::{Float as F, Vec3 as V};
use super::Range::{Any, NonNeg, Pos};
use super::{num, param, Args, Def, Extent, Field, Prim, PrimRef};
use crate::program::builder::{Builder, P};
use glam::DVec3;

type V3 = [f64; 3];

pub(super) static PRIMS: &[Prim] = &[
    Prim {
        name: "cylinder",
        profile: false,
        params: &[
            param("a", V, Def::Req, Any),
            param("b", V, Def::Req, Any),
            param("radius", F, Def::Num(0.5), Pos),
        ],
        accepts: "`a` ≠ `b`; `radius` > 0",
        doc: "A capped cylinder whose axis runs from the point `a` to the point `b`.",
        check: apart,
        field: Field::Exact,
        extent: |args| discs(args, args.f(2), args.f(2)),
        cost: |_| 32.0,
        distance: |b, p, args| {
            let (q, h) = frame(b, p, args);
            cylinder(b, q, &[args.f(2), h, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
        },
    },
    Prim {
        name: "cone",
        profile: false,
        params: &[
            param("a", V, Def::Req, Any),
            param("b", V, Def::Req, Any),
            param("radius_a", F, Def::Num(0.5), NonNeg),
            param("radius_b", F, Def::Num(0.0), NonNeg),
        ],
        accepts: "`a` ≠ `b`; `radius_a`, `radius_b` ≥ 0, not both 0",
        doc: "A cone (a frustum where both radii are above 0) whose axis runs from `a`, where its radius is `radius_a`, to `b`, where it is `radius_b`.",
        check: |args| apart(args).or_else(|| no_volume(args)),
        field: Field::Exact,
        extent: |args| discs(args, args.f(2), args.f(3)),
        cost: |_| 55.0,
        distance: |b, p, args| {
            let (q, h) = frame(b, p, args);
            capped_cone(b, q, &capped_cone_slots(h, args.f(2), args.f(3)))
        },
    },
    Prim {
        name: "round_cone",
        profile: false,
        params: &[
            param("a", V, Def::Req, Any),
            param("b", V, Def::Req, Any),
            param("radius_a", F, Def::Num(0.5), NonNeg),
            param("radius_b", F, Def::Num(0.25), NonNeg),
        ],
        accepts: "`radius_a`, `radius_b` ≥ 0, not both 0; \\|`a` − `b`\\| above \\|`radius_a` − `radius_b`\\|",
        doc: "The hull of the ball of radius `radius_a` about `a` and that of radius `radius_b` about `b`.",
        check: |args| {
            apart(args).or_else(|| no_volume(args)).or_else(|| {
                let (l, d) = (length(args), (args.f(2) - args.f(3)).abs());
                (d >= l).then(|| {
                    format!(
                        "the radii differ by {} but the points are {} apart: one ball would hold the other (a round cone needs |radius_a - radius_b| < |a - b|)",
                        num(d),
                        num(l)
                    )
                })
            })
        },
        field: Field::Exact,
        extent: |args| {
            let (a, b, ra, rb) = (args.v3(0), args.v3(1), args.f(2), args.f(3));
            Extent {
                min: [0, 1, 2].map(|i| (a[i] - ra).min(b[i] - rb)),
                max: [0, 1, 2].map(|i| (a[i] + ra).max(b[i] + rb)),
                radius: length(args) / 2.0 + ra.max(rb),
                symmetric: symmetric(args),
            }
        },
        cost: |_| 42.0,
        distance: |b, p, args| {
            let (q, h) = frame(b, p, args);
            round_cone(b, q, &round_cone_slots(args.f(2), args.f(3), h))
        },
    },
];

/// |b - a| of arguments `a` and `b`.
fn length(args: &Args) -> f64 {
    let (a, b) = (args.v3(0), args.v3(1));
    (0..3).map(|i| (b[i] - a[i]).powi(2)).sum::<f64>().sqrt()
}

/// Refuses two points that are one: the axis has no direction.
fn apart(args: &Args) -> Option<String> {
    (length(args) == 0.0).then(|| {
        "`a` and `b` are the same point: the axis between them has no direction".to_string()
    })
}

/// Refuses radii (arguments 2 and 3) that are both 0.
fn no_volume(args: &Args) -> Option<String> {
    (args.f(2) == 0.0 && args.f(3) == 0.0)
        .then(|| "`radius_a` and `radius_b` are both 0: the shape has no volume".to_string())
}

/// The planes across which the shape is its own mirror image: those that hold its axis, and
/// those that swap its ends when its two radii are equal.
fn symmetric(args: &Args) -> [bool; 3] {
    let (a, b) = (args.v3(0), args.v3(1));
    let equal = args.f(2) == args.f(args.0.len() - 1);
    let mirrored = |i: usize| (0..3).all(|j| if j == i { a[j] == -b[j] } else { a[j] == b[j] });
    [0, 1, 2].map(|i| (a[i] == 0.0 && b[i] == 0.0) || (equal && mirrored(i)))
}

/// The box and sphere around the discs of radius `ra` about `a` and `rb` about `b`, normal to
/// the axis (a disc of radius r normal to the unit u reaches r·√(1 − u_i²) along axis i).
fn discs(args: &Args, ra: f64, rb: f64) -> Extent {
    let (a, b, l) = (args.v3(0), args.v3(1), length(args));
    let reach = |i: usize, r: f64| r * (1.0 - ((b[i] - a[i]) / l).powi(2)).max(0.0).sqrt();
    Extent {
        min: [0, 1, 2].map(|i| (a[i] - reach(i, ra)).min(b[i] - reach(i, rb))),
        max: [0, 1, 2].map(|i| (a[i] + reach(i, ra)).max(b[i] + reach(i, rb))),
        radius: (l / 2.0).hypot(ra.max(rb)),
        symmetric: symmetric(args),
    }
}

/// The frame of the segment from argument `a` to argument `b`: the rows of the rotation that
/// turns the segment onto y (`a` below), its midpoint and its half-length.
fn axes(args: &Args) -> ([V3; 3], V3, f64) {
    let (from, to) = (args.v3(0), args.v3(1));
    let l = length(args);
    let u: V3 = [0, 1, 2].map(|i| (to[i] - from[i]) / l);
    // e1 ⟂ u from the axis u is least along; e3 = e1 × u, so the rows e1, u, e3 are a rotation.
    let k = (0..3)
        .min_by(|&i, &j| u[i].abs().total_cmp(&u[j].abs()))
        .unwrap_or(0);
    let mut axis = DVec3::ZERO;
    axis[k] = 1.0;
    let e1 = axis.cross(DVec3::from(u)).normalize();
    let e3 = e1.cross(DVec3::from(u));
    let (e1, e3) = (e1.to_array(), e3.to_array());
    let mid: V3 = [0, 1, 2].map(|i| (from[i] + to[i]) / 2.0);
    ([e1, u, e3], mid, l / 2.0)
}

/// The point in the frame of the segment from argument `a` to argument `b`: about its
/// midpoint, turned so that `a` lies at y = -h and `b` at y = +h; and h.
fn frame(b: &mut Builder, p: P, args: &Args) -> (P, f64) {
    let (rows, mid, h) = axes(args);
    let d = b.sub3c(p, mid);
    let q = rows.map(|row| {
        let terms = [0, 1, 2].map(|j| b.mulc(d[j], row[j]));
        let s = b.add(terms[0], terms[1]);
        b.add(s, terms[2])
    });
    (q, h)
}

/// Whether `prim` is `segment(a, b, radius)`, the capsule between two points (an entry of
/// solids.rs, whose formula is Quilez's `sdCapsule`: its field is the capsule's along y in
/// the segment's frame, up to rounding).
fn is_segment(prim: PrimRef) -> bool {
    ALONG_Y
        .iter()
        .any(|e| std::ptr::eq(e, prim.0) && e.name == "segment")
}

/// A shape along y that a shape between two points is in its frame.
#[derive(Debug, Clone)]
pub enum AlongY {
    /// A capped cylinder (the scene graph's own node).
    Cylinder { radius: f64, half_height: f64 },
    /// A capsule (the scene graph's own node): a segment's.
    Capsule { radius: f64, half_height: f64 },
    /// An entry of the table along y (`capped_cone`, `round_cone`) and its arguments.
    Entry(PrimRef, Args),
}

/// A shape between two points as its shape along y at `q = rows·(p − mid)`.
#[derive(Debug, Clone)]
pub struct Placed {
    /// The rotation's rows (e1, the unit axis from `a` to `b`, e3).
    pub rows: [V3; 3],
    /// The midpoint of the segment.
    pub mid: V3,
    pub shape: AlongY,
}

/// A primitive of this file, or a segment, as its shape along y in its frame, whose distance
/// there is the primitive's (the same formula and constants; for a segment the capsule's
/// formula, equal up to rounding); `None` for the other primitives. A marched
/// scene's instances take shapes between points so (`lower::instances`).
pub fn placed(prim: PrimRef, args: &Args) -> Option<Placed> {
    if is_segment(prim) {
        // A capsule between two points, unless they are one (a ball).
        if length(args) == 0.0 {
            return None;
        }
        let (rows, mid, h) = axes(args);
        let shape = AlongY::Capsule {
            radius: args.f(2),
            half_height: h,
        };
        return Some(Placed { rows, mid, shape });
    }
    let index = PRIMS.iter().position(|e| std::ptr::eq(e, prim.0))?;
    let (rows, mid, h) = axes(args);
    let entry = |name: &str| {
        ALONG_Y
            .iter()
            .find(|e| e.name == name && e.params[0].ty == F)
            .map(PrimRef)
    };
    let (ra, rb) = (args.f(2), args.f(args.0.len() - 1));
    let shape = match PRIMS[index].name {
        "cylinder" => AlongY::Cylinder {
            radius: ra,
            half_height: h,
        },
        // capped_cone(height, bottom, top) and round_cone(bottom, top, height), the height
        // 2h: their half-height is h, as here.
        "cone" => AlongY::Entry(entry("capped_cone")?, Args::numbers(&[2.0 * h, ra, rb])),
        "round_cone" => AlongY::Entry(entry("round_cone")?, Args::numbers(&[ra, rb, 2.0 * h])),
        _ => return None,
    };
    Some(Placed { rows, mid, shape })
}

/// The arguments of a primitive of this file or a segment scaled by `s` > 0 (its points and
/// radii), the
/// primitive scaled by `s`: a scale above one is absorbed into it (`lower::simplify`).
pub fn scaled(prim: PrimRef, args: &Args, s: f64) -> Option<Args> {
    let between = PRIMS.iter().any(|e| std::ptr::eq(e, prim.0)) || is_segment(prim);
    between.then(|| {
        Args(
            args.0
                .iter()
                .enumerate()
                .map(|(i, v)| {
                    if i < 2 {
                        v.map(|x| x * s)
                    } else {
                        [v[0] * s, v[1], v[2]]
                    }
                })
                .collect(),
        )
    })
}
