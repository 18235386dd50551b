//! The distance of `sweep(profile, path)` over the program's operations (docs/analysis.md,
//! "Sweep"): the point's nearest point on the path (a polyline's per segment and corner,
//! exactly; a helix's by Newton's method from the nearest turn and the next; a Bézier chain's
//! by the nearest of its pieces' chords, refined by Newton's method on its curve; an arc's in
//! closed form), the point's coordinates (u, v) in the frame there (`scene/path.rs`) and how
//! far beyond an open end it lies (w); the profile is read at (u, v) and capped at the ends.
//! The path's numbers are constants of the program.

use crate::program::builder::{Builder, P};
use crate::program::{Reg, Unary};
use crate::scene::path::{cubic, tangent, Path, PathKind};
use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, TAU};

/// Farther than any distance; below any end's distance.
const FAR: f64 = 1e30;

/// A point's place near the path: its squared distance to it, its coordinates in the frame
/// at its nearest point, and how far beyond the nearer open end's plane it lies (−FAR where
/// no end is near).
#[derive(Debug, Clone, Copy)]
pub(super) struct Hit {
    pub d2: Reg,
    pub u: Reg,
    pub v: Reg,
    pub w: Reg,
}

/// The nearer of two hits (the first where they tie).
fn nearer(b: &mut Builder, best: Option<Hit>, h: Hit) -> Hit {
    let Some(x) = best else { return h };
    let c = b.lt(h.d2, x.d2);
    Hit {
        d2: b.select(c, h.d2, x.d2),
        u: b.select(c, h.u, x.u),
        v: b.select(c, h.v, x.v),
        w: b.select(c, h.w, x.w),
    }
}

fn dot(b: &mut Builder, q: P, k: DVec3) -> Reg {
    let c = b.c3(k.to_array());
    b.dot3(q, c)
}

/// (u, v) turned by the angle `a` (a register): the coordinates in the frame turned by `a`.
fn turn(b: &mut Builder, u: Reg, v: Reg, a: Reg) -> (Reg, Reg) {
    let (s, c) = (b.un(Unary::Sin, a), b.un(Unary::Cos, a));
    let (cu, sv) = (b.mul(c, u), b.mul(s, v));
    let (cv, su) = (b.mul(c, v), b.mul(s, u));
    (b.add(cu, sv), b.sub(cv, su))
}

/// Where `p` lies about the path.
pub(super) fn locate(b: &mut Builder, p: P, path: &Path) -> Hit {
    match &path.kind {
        PathKind::Polyline {
            points,
            frames,
            before,
        } => polyline(b, p, points, frames, before, path.closed, path.twist),
        PathKind::Helix {
            radius,
            pitch,
            turns,
        } => helix(b, p, *radius, *pitch, *turns),
        PathKind::Bezier {
            controls,
            pieces,
            normals,
        } => bezier(b, p, controls, *pieces, normals, path.closed),
        PathKind::Arc {
            centre,
            radius,
            e1,
            e2,
            angle,
            n0,
        } => arc(
            b,
            p,
            [*centre, *e1, *e2, *n0].map(DVec3::from),
            *radius,
            *angle,
        ),
    }
}

/// The sweep's distance from the profile's `g` at the hit: capped beyond an open end (as an
/// extrusion is), and beyond `inner` from the path (but never within `extent` of it, where the
/// surface is) the distance to the tube of radius `extent` about it.
pub(super) fn finish(b: &mut Builder, g: Reg, hit: &Hit, inner: f64, extent: f64) -> Reg {
    let (gx, wx) = (b.maxc(g, 0.0), b.maxc(hit.w, 0.0));
    let out = b.len2(gx, wx);
    let gw = b.max(g, hit.w);
    let inside = b.minc(gw, 0.0);
    let d = b.add(out, inside);
    if inner.is_finite() {
        let rho = b.sqrt(hit.d2);
        let tube = b.subc(rho, extent);
        let limit = b.c(inner.max(extent));
        let near = b.lt(rho, limit);
        b.select(near, d, tube)
    } else {
        d
    }
}

fn v3(x: [f64; 3]) -> DVec3 {
    DVec3::from(x)
}

/// Per segment the nearest point (clamped to the segment, or beyond it at an open end) in the
/// segment's frame; per corner, in the wedge beyond both segments, the profile turned about
/// the corner's axis.
fn polyline(
    b: &mut Builder,
    p: P,
    points: &[[f64; 3]],
    frames: &[[[f64; 3]; 2]],
    before: &[f64],
    closed: bool,
    twist: f64,
) -> Hit {
    let n = frames.len();
    let dir = |i: usize| (v3(points[i + 1]) - v3(points[i])).normalize();
    let mut best: Option<(Hit, Reg)> = None;
    let mut keep = |b: &mut Builder, h: Hit, angle: Reg| {
        best = Some(match best {
            None => (h, angle),
            Some((x, a)) => {
                let c = b.lt(h.d2, x.d2);
                let angle = b.select(c, angle, a);
                (nearer(b, Some(x), h), angle)
            }
        })
    };
    for i in 0..n {
        let (a, e) = (v3(points[i]), v3(points[i + 1]) - v3(points[i]));
        let (len, t) = (e.length(), dir(i));
        let [nn, bb] = frames[i].map(v3);
        let q = b.sub3c(p, a.to_array());
        let along = dot(b, q, t);
        let s = b.clampc(along, 0.0, len);
        let u = dot(b, q, nn);
        let v = dot(b, q, bb);
        let r = b.map3(q, |b, x, k| {
            let m = b.mulc(s, t[k]);
            b.sub(x, m)
        });
        let mut d2 = b.dot3(r, r);
        let (first, last) = (!closed && i == 0, !closed && i + 1 == n);
        let far = b.c(FAR);
        if !first {
            let zero = b.c(0.0);
            let out = b.lt(along, zero);
            d2 = b.select(out, far, d2);
        }
        if !last {
            let top = b.c(len);
            let out = b.lt(top, along);
            d2 = b.select(out, far, d2);
        }
        let mut w = b.c(-FAR);
        if first {
            let back = b.neg(along);
            w = b.max(w, back);
        }
        if last {
            let ahead = b.subc(along, len);
            w = b.max(w, ahead);
        }
        let angle = b.addc(s, before[i]);
        let angle = b.mulc(angle, twist);
        keep(b, Hit { d2, u, v, w }, angle);
    }
    // The corners: between segment i − 1 and i.
    let corners: Vec<usize> = if closed {
        (0..n).collect()
    } else {
        (1..n).collect()
    };
    for i in corners {
        let j = (i + n - 1) % n;
        let [nn, bb] = frames[j].map(v3);
        let Some(h) = corner(b, p, v3(points[i]), [dir(j), dir(i)], [nn, bb]) else {
            continue;
        };
        let at = if i == 0 {
            before[n - 1] + (v3(points[n]) - v3(points[n - 1])).length()
        } else {
            before[i]
        };
        let angle = b.c(twist * at);
        keep(b, h, angle);
    }
    let (h, angle) = best.expect("a polyline has a segment");
    if twist == 0.0 {
        return h;
    }
    let (u, v) = turn(b, h.u, h.v, angle);
    Hit { u, v, ..h }
}

/// At the corner `x` from direction `t[0]` to `t[1]` (`None` where they are one), the point's
/// hit as the profile turned about the corner's axis (t₀ × t₁) would give it, in the frame
/// (N, B) that arrives there: its distance, the height along the axis and the distance from
/// it, away from the turn. The nearest point of a path is the corner only in the wedge
/// beyond both directions, where this holds.
fn corner(b: &mut Builder, p: P, x: DVec3, t: [DVec3; 2], [nn, bb]: [DVec3; 2]) -> Option<Hit> {
    let axis = t[0].cross(t[1]);
    if axis.length() < 1e-9 {
        return None;
    }
    let axis = axis.normalize();
    let out = -(t[1] - t[0] * t[1].dot(t[0])).normalize();
    let q = b.sub3c(p, x.to_array());
    let d2 = b.dot3(q, q);
    let a = dot(b, q, axis);
    let a2 = b.mul(a, a);
    let r2 = b.sub(d2, a2);
    let r2 = b.maxc(r2, 0.0);
    let rho = b.sqrt(r2);
    let comb = |b: &mut Builder, k: DVec3| {
        let x = b.mulc(a, axis.dot(k));
        let y = b.mulc(rho, out.dot(k));
        b.add(x, y)
    };
    let (u, v) = (comb(b, nn), comb(b, bb));
    let w = b.c(-FAR);
    Some(Hit { d2, u, v, w })
}

/// The helix: Newton's method on the squared distance from the angle of the point's own turn
/// and from the next turn towards it, each kept within the helix's ends.
fn helix(b: &mut Builder, p: P, radius: f64, pitch: f64, turns: f64) -> Hit {
    let k = pitch / TAU;
    let len = radius.hypot(k);
    let (total, y0) = (TAU * turns, -pitch * turns / 2.0);
    // py − y0, and the point's angle about y (from +x towards −z).
    let py = b.subc(p[1], y0);
    let nz = b.neg(p[2]);
    let phi0 = b.bin(crate::program::Binary::Atan2, nz, p[0]);
    let level = b.mulc(py, 1.0 / k);
    let diff = b.sub(level, phi0);
    let n = b.mulc(diff, 1.0 / TAU);
    let n = b.un(Unary::Round, n);
    // The turns the helix has at the point's angle: from the first at or after its start to
    // the last at or before its end.
    let zero = b.c(0.0);
    let negative = b.lt(phi0, zero);
    let (one, none) = (b.c(1.0), b.c(0.0));
    let lowest = b.select(negative, one, none);
    let left = b.neg(phi0);
    let left = b.addc(left, total);
    let left = b.mulc(left, 1.0 / TAU);
    let highest = b.un(Unary::Floor, left);
    let own = b.max(n, lowest);
    let own = b.min(own, highest);
    let at = b.mulc(own, TAU);
    let first = b.add(phi0, at);
    let below = b.lt(level, first);
    let (down, up) = (b.c(-1.0), b.c(1.0));
    let step = b.select(below, down, up);
    let next = b.add(own, step);
    let next = b.max(next, lowest);
    let next = b.min(next, highest);
    let at = b.mulc(next, TAU);
    let second = b.add(phi0, at);
    let (start, end) = (b.c(0.0), b.c(total));
    // At the angle φ: p's offsets sideways and towards the axis in the plane turned by φ, and
    // its height above the helix there.
    let at_angle = |b: &mut Builder, phi: Reg| {
        let (s, c) = (b.un(Unary::Sin, phi), b.un(Unary::Cos, phi));
        let (xs, zc) = (b.mul(p[0], s), b.mul(p[2], c));
        let side = b.add(xs, zc);
        let (xc, zs) = (b.mul(p[0], c), b.mul(p[2], s));
        let radial = b.sub(xc, zs);
        let kp = b.mulc(phi, k);
        let h = b.sub(py, kp);
        (side, radial, h)
    };
    let mut best = None;
    for (from, newton) in [(first, true), (second, true), (start, false), (end, false)] {
        let mut phi = b.clampc(from, 0.0, total);
        for _ in 0..if newton { 3 } else { 0 } {
            let (side, radial, h) = at_angle(b, phi);
            let f1a = b.mulc(side, radius);
            let f1b = b.mulc(h, k);
            let f1 = b.sub(f1a, f1b);
            let f2 = b.mulc(radial, radius);
            let f2 = b.addc(f2, k * k);
            let f2 = b.maxc(f2, 0.5 * k * k);
            let dphi = b.div(f1, f2);
            let dphi = b.clampc(dphi, -1.0, 1.0);
            let next = b.sub(phi, dphi);
            phi = b.clampc(next, 0.0, total);
        }
        let (side, radial, h) = at_angle(b, phi);
        // q·E1 (E1 towards the axis), q·E2 (E2 = T × E1), q·T.
        let e1 = b.neg(radial);
        let e1 = b.addc(e1, radius);
        let ks = b.mulc(side, k / len);
        let rh = b.mulc(h, radius / len);
        let e2 = b.add(ks, rh);
        let rs = b.mulc(side, -radius / len);
        let kh = b.mulc(h, k / len);
        let along = b.add(rs, kh);
        let (e1sq, e2sq, tsq) = (b.mul(e1, e1), b.mul(e2, e2), b.mul(along, along));
        let d2 = b.add(e1sq, e2sq);
        let d2 = b.add(d2, tsq);
        // The frame turns against the torsion: θ = −(k / len)·φ.
        let theta = b.mulc(phi, -k / len);
        let (u, v) = turn(b, e1, e2, theta);
        // The ends' planes, read within a quarter turn of each end.
        let mut w = b.c(-FAR);
        for (at, sign) in [(0.0, -1.0), (total, 1.0)] {
            let (x, t) = crate::scene::path::helix_at(radius, pitch, turns, at);
            let q = b.sub3c(p, x.to_array());
            let plane = dot(b, q, t * sign);
            let near = if sign < 0.0 {
                let lim = b.c(FRAC_PI_2);
                b.lt(phi, lim)
            } else {
                let lim = b.c(total - FRAC_PI_2);
                b.lt(lim, phi)
            };
            let far = b.c(-FAR);
            let plane = b.select(near, plane, far);
            w = b.max(w, plane);
        }
        best = Some(nearer(b, best, Hit { d2, u, v, w }));
    }
    best.expect("two candidates")
}

/// The polynomial coefficients of a cubic Bézier curve: B(t) = c0 + c1·t + c2·t² + c3·t³.
fn coefficients(q: &[DVec3]) -> [DVec3; 4] {
    [
        q[0],
        3.0 * (q[1] - q[0]),
        3.0 * (q[0] - 2.0 * q[1] + q[2]),
        q[3] - q[0] + 3.0 * (q[1] - q[2]),
    ]
}

/// Per curve: the nearest of its pieces' chords, Newton's method on the curve from there,
/// the frame's N interpolated between the cuts and made normal to the curve's direction.
fn bezier(
    b: &mut Builder,
    p: P,
    controls: &[[f64; 3]],
    pieces: usize,
    normals: &[[f64; 3]],
    closed: bool,
) -> Hit {
    let pts: Vec<DVec3> = controls.iter().map(|x| v3(*x)).collect();
    let k = (pts.len() - 1) / 3;
    let mut best = None;
    for c in 0..k {
        let cuts = &normals[c * (pieces + 1)..(c + 1) * (pieces + 1)];
        let h = bezier_curve(b, p, &pts, c, cuts, closed);
        best = Some(nearer(b, best, h));
    }
    for c in 0..k {
        if let Some((x, t0, t1)) = joint(&pts, c, closed) {
            let prev = (c + k - 1) % k;
            let nn = v3(normals[prev * (pieces + 1) + pieces]);
            let bb = t0.cross(nn);
            if let Some(h) = corner(b, p, x, [t0, t1], [nn, bb]) {
                best = Some(nearer(b, best, h));
            }
        }
    }
    best.expect("a Bézier path has a curve")
}

/// Where `p` lies about curve `c` of the chain `pts`, whose frame's N at its cuts is `cuts`
/// (one more than its pieces): its nearest point, the frame there, and the ends' and
/// corners' limits.
fn bezier_curve(
    b: &mut Builder,
    p: P,
    pts: &[DVec3],
    c: usize,
    cuts: &[[f64; 3]],
    closed: bool,
) -> Hit {
    let k = (pts.len() - 1) / 3;
    let pieces = cuts.len() - 1;
    let q = &pts[3 * c..3 * c + 4];
    let t = nearest_chord(b, p, q, pieces);
    let co = coefficients(q);
    let t = newton(b, p, &co, t, pieces);
    let (pos, d1, _) = curve_at(b, p, &co, t);
    let qv = b.map3(p, |b, x, i| b.sub(x, pos[i]));
    let d2 = b.dot3(qv, qv);
    let l = b.len3(d1);
    let tan = b.map3(d1, |b, x, _| b.div(x, l));
    let nn = frame_normal(b, p, cuts, t, tan);
    let bb = cross(b, tan, nn);
    let u = b.dot3(qv, nn);
    let v = b.dot3(qv, bb);
    // Beyond an end at a corner the corner's wedge holds the nearest point.
    let along = b.dot3(qv, tan);
    let mut d2 = d2;
    if joint(pts, c, closed).is_some() {
        d2 = past_end(b, d2, t, along, true);
    }
    if joint(pts, c + 1, closed).is_some() {
        d2 = past_end(b, d2, t, along, false);
    }
    let mut w = b.c(-FAR);
    if !closed && c == 0 {
        let plane = end_plane(b, p, q, t, true);
        w = b.max(w, plane);
    }
    if !closed && c + 1 == k {
        let plane = end_plane(b, p, q, t, false);
        w = b.max(w, plane);
    }
    Hit { d2, u, v, w }
}

/// The parameter of the nearest point to `p` on the chords of the curve `q`'s `pieces`
/// pieces.
fn nearest_chord(b: &mut Builder, p: P, q: &[DVec3], pieces: usize) -> Reg {
    let mut near: Option<(Reg, Reg)> = None;
    for j in 0..pieces {
        let (t0, t1) = (j as f64 / pieces as f64, (j + 1) as f64 / pieces as f64);
        let (a, e) = (cubic(q, t0), cubic(q, t1) - cubic(q, t0));
        let r = b.sub3c(p, a.to_array());
        let s = dot(b, r, e / e.length_squared().max(1e-300));
        let s = b.clampc(s, 0.0, 1.0);
        let off = b.map3(r, |b, x, i| {
            let m = b.mulc(s, e[i]);
            b.sub(x, m)
        });
        let d2 = b.dot3(off, off);
        let t = b.mulc(s, t1 - t0);
        let t = b.addc(t, t0);
        near = Some(match near {
            None => (d2, t),
            Some((bd, bt)) => {
                let cnd = b.lt(d2, bd);
                (b.select(cnd, d2, bd), b.select(cnd, t, bt))
            }
        });
    }
    near.expect("pieces").1
}

/// The curve of coefficients `co` at `t`: its point and its first and second derivatives.
fn curve_at(b: &mut Builder, p: P, co: &[DVec3; 4], t: Reg) -> (P, P, P) {
    let pos = b.map3(p, |b, _, i| {
        let x = b.mulc(t, co[3][i]);
        let x = b.addc(x, co[2][i]);
        let x = b.mul(x, t);
        let x = b.addc(x, co[1][i]);
        let x = b.mul(x, t);
        b.addc(x, co[0][i])
    });
    let d1 = b.map3(p, |b, _, i| {
        let x = b.mulc(t, 3.0 * co[3][i]);
        let x = b.addc(x, 2.0 * co[2][i]);
        let x = b.mul(x, t);
        b.addc(x, co[1][i])
    });
    let d2 = b.map3(p, |b, _, i| {
        let x = b.mulc(t, 6.0 * co[3][i]);
        b.addc(x, 2.0 * co[2][i])
    });
    (pos, d1, d2)
}

/// Three steps of Newton's method from `t` towards the parameter of the curve's point
/// nearest `p`, each at most a piece's span.
fn newton(b: &mut Builder, p: P, co: &[DVec3; 4], mut t: Reg, pieces: usize) -> Reg {
    for _ in 0..3 {
        let (pos, d1, d2) = curve_at(b, p, co, t);
        let d = b.map3(pos, |b, x, i| b.sub(x, p[i]));
        let f1 = b.dot3(d, d1);
        let g = b.dot3(d1, d1);
        let h = b.dot3(d, d2);
        // Newton's step where the squared distance curves up enough, at most a piece's
        // span (near the centre of curvature it is flat, and beyond it curves down).
        let f2 = b.add(g, h);
        let floor = b.mulc(g, 0.02);
        let f2 = b.max(f2, floor);
        let f2 = b.maxc(f2, 1e-12);
        let step = b.div(f1, f2);
        let span = 1.0 / pieces as f64;
        let step = b.clampc(step, -span, span);
        let next = b.sub(t, step);
        t = b.clampc(next, 0.0, 1.0);
    }
    t
}

/// The frame's unit N at `t` on a curve whose N at its cuts is `cuts`: interpolated between
/// the cuts, then made normal to the unit direction `tan`.
fn frame_normal(b: &mut Builder, p: P, cuts: &[[f64; 3]], t: Reg, tan: P) -> P {
    let pieces = cuts.len() - 1;
    // N between the cuts: Σ N_j·max(0, 1 − |m·t − j|).
    let mt = b.mulc(t, pieces as f64);
    let mut nv: Option<P> = None;
    for (j, nj) in cuts.iter().enumerate() {
        let x = b.subc(mt, j as f64);
        let x = b.abs(x);
        let x = b.neg(x);
        let hat = b.addc(x, 1.0);
        let hat = b.maxc(hat, 0.0);
        nv = Some(match nv {
            None => b.map3(p, |b, _, i| b.mulc(hat, nj[i])),
            Some(acc) => b.map3(acc, |b, a, i| {
                let m = b.mulc(hat, nj[i]);
                b.add(a, m)
            }),
        });
    }
    let nv = nv.expect("cuts");
    let along = b.dot3(nv, tan);
    let nv = b.map3(nv, |b, x, i| {
        let m = b.mul(along, tan[i]);
        b.sub(x, m)
    });
    let nl = b.len3(nv);
    b.map3(nv, |b, x, _| b.div(x, nl))
}

/// `d2`, or FAR where the point lies past the curve's `start` (or its end) along the curve's
/// direction there (`along`), as it does beyond a corner.
fn past_end(b: &mut Builder, d2: Reg, t: Reg, along: Reg, start: bool) -> Reg {
    let out = if start {
        let (lim, zero) = (b.c(1e-6), b.c(0.0));
        let at = b.lt(t, lim);
        let back = b.lt(along, zero);
        b.mul(at, back)
    } else {
        let (lim, zero) = (b.c(1.0 - 1e-6), b.c(0.0));
        let at = b.lt(lim, t);
        let ahead = b.lt(zero, along);
        b.mul(at, ahead)
    };
    let far = b.c(FAR);
    b.select(out, far, d2)
}

/// How far beyond the plane of the open path's `start` (or its end) on the curve `q` the point
/// lies, where its nearest point is in the curve's first (last) quarter; −FAR elsewhere.
fn end_plane(b: &mut Builder, p: P, q: &[DVec3], t: Reg, start: bool) -> Reg {
    let near = if start {
        let t0 = tangent(q, 0.0).normalize();
        let r = b.sub3c(p, q[0].to_array());
        let plane = dot(b, r, -t0);
        let lim = b.c(0.25);
        (b.lt(t, lim), plane)
    } else {
        let t1 = tangent(q, 1.0).normalize();
        let r = b.sub3c(p, q[3].to_array());
        let plane = dot(b, r, t1);
        let lim = b.c(0.75);
        (b.lt(lim, t), plane)
    };
    let (near, plane) = near;
    let far = b.c(-FAR);
    b.select(near, plane, far)
}

/// The corner where curve `c` starts, if the curve before it (the last, on a closed path)
/// ends in another direction: the point, the direction arriving and the one leaving.
fn joint(pts: &[DVec3], c: usize, closed: bool) -> Option<(DVec3, DVec3, DVec3)> {
    let k = (pts.len() - 1) / 3;
    if (c == 0 || c == k) && !closed {
        return None;
    }
    let (c, prev) = (c % k, (c + k - 1) % k);
    let t0 = tangent(&pts[3 * prev..3 * prev + 4], 1.0).normalize();
    let t1 = tangent(&pts[3 * c..3 * c + 4], 0.0).normalize();
    (t0.cross(t1).length() >= 1e-9).then_some((pts[3 * c], t0, t1))
}

fn cross(b: &mut Builder, x: P, y: P) -> P {
    let c = |b: &mut Builder, i: usize, j: usize| {
        let l = b.mul(x[i], y[j]);
        let r = b.mul(x[j], y[i]);
        b.sub(l, r)
    };
    [c(b, 1, 2), c(b, 2, 0), c(b, 0, 1)]
}

/// The arc: the point's angle in its plane, clamped to the arc's (towards the nearer end).
fn arc(b: &mut Builder, p: P, [centre, e1, e2, n0]: [DVec3; 4], radius: f64, angle: f64) -> Hit {
    let n = e1.cross(e2);
    let q = b.sub3c(p, centre.to_array());
    let (x, y, z) = (dot(b, q, e1), dot(b, q, e2), dot(b, q, n));
    let a = b.bin(crate::program::Binary::Atan2, y, x);
    let zero = b.c(0.0);
    let neg = b.lt(a, zero);
    let (full, none) = (b.c(TAU), b.c(0.0));
    let wrap = b.select(neg, full, none);
    let a = b.add(a, wrap);
    // Beyond the arc: to the end nearer in angle.
    let lim = b.c(angle);
    let beyond = b.lt(lim, a);
    let past = b.subc(a, angle);
    let back = b.neg(a);
    let back = b.addc(back, TAU);
    let to_start = b.lt(back, past);
    let (start, end) = (b.c(0.0), b.c(angle));
    let end_angle = b.select(to_start, start, end);
    let phi = b.select(beyond, end_angle, a);
    let (s, c) = (b.un(Unary::Sin, phi), b.un(Unary::Cos, phi));
    // q·E1 with E1 towards the centre, q·E2 with E2 = n, q·T.
    let (xc, ys) = (b.mul(x, c), b.mul(y, s));
    let radial = b.add(xc, ys);
    let qe1 = b.neg(radial);
    let qe1 = b.addc(qe1, radius);
    let (xs, yc) = (b.mul(x, s), b.mul(y, c));
    let along = b.sub(yc, xs);
    let (r2, z2, t2) = (b.mul(qe1, qe1), b.mul(z, z), b.mul(along, along));
    let d2 = b.add(r2, z2);
    let d2 = b.add(d2, t2);
    // The frame: N = cos θ0·E1 + sin θ0·E2 throughout (a plane curve's frame does not turn).
    let theta = n0.dot(n).atan2(n0.dot(-e1));
    let th = b.c(theta);
    let (u, v) = turn(b, qe1, z, th);
    // The ends' planes: the start's (normal −e2) within a quarter turn of it, the end's too.
    let mut w = b.c(-FAR);
    let quarter = FRAC_PI_2.min(angle / 2.0);
    let (sa, ca) = angle.sin_cos();
    for (plane_of, near) in [
        (
            (-e2, centre + e1 * radius),
            phi_near(b, phi, quarter, false, angle),
        ),
        (
            (e2 * ca - e1 * sa, centre + (e1 * ca + e2 * sa) * radius),
            phi_near(b, phi, quarter, true, angle),
        ),
    ] {
        let (normal, at) = plane_of;
        let r = b.sub3c(p, at.to_array());
        let plane = dot(b, r, normal);
        let far = b.c(-FAR);
        let plane = b.select(near, plane, far);
        w = b.max(w, plane);
    }
    Hit { d2, u, v, w }
}

/// Whether the arc's angle `phi` lies within `quarter` of its start (or, with `end`, of its
/// end at `angle`).
fn phi_near(b: &mut Builder, phi: Reg, quarter: f64, end: bool, angle: f64) -> Reg {
    if end {
        let lim = b.c(angle - quarter);
        b.lt(lim, phi)
    } else {
        let lim = b.c(quarter);
        b.lt(phi, lim)
    }
}
