//! `hull(shapes…)` (issue 50, item 4): the convex hull of balls of any radii, and the 2D hull
//! of circles that the hull of parallel cylinders extrudes. The checker (`check/hull.rs`)
//! reduces the shapes to balls or circles and builds these two entries, which are not in the
//! table (no call names them). Both fields are exact, as support functions give them
//! (docs/analysis.md, "Hull of balls"): for a convex body of support function h, the signed
//! distance is max over unit u of p·u − h(u); every u gives a value at most the distance, and
//! the value at the normal of the nearest boundary point is the distance. The hull of balls
//! has h(u) = max_k (c_k·u + r_k), and its boundary is made of pieces of the balls' spheres,
//! of the cones tangent to two balls and of the planes tangent to three, so the normals to try
//! are, at `p`: the direction from each ball's centre, the two normals of each cone in the
//! plane of its axis and `p`, and the planes' own (constant) normals. What does not depend on
//! `p` (which balls no other holds, which cones and planes touch the hull, each plane's h) is
//! found once, when the scene is lowered; the value of a normal costs one pass over the balls.

use super::Kind::Points;
use super::Range::Any;
use super::{any, param, Def, Extent, Field, Prim};
use crate::program::builder::{Builder, P};
use crate::program::Reg;
use glam::{DVec2, DVec3};

/// The hull of balls: `balls` holds each ball as two entries, its centre then its radius (the
/// first number).
pub(crate) static BALLS: Prim = Prim {
    name: "hull",
    profile: false,
    params: &[param("balls", Points, Def::Req, Any)],
    accepts: "balls: a centre, then (radius, 0, 0), per ball",
    doc: "The convex hull of balls of any radii.",
    check: any,
    field: Field::Exact,
    extent: |args| {
        let balls = balls(args.list(0));
        extent(balls.iter().map(|b| (b.c, b.r)))
    },
    cost: |args| {
        let plan = Plan::of(&balls(args.list(0)));
        let n = plan.balls.len() as f64;
        n * (15.0 + 7.0 * n)
            + plan.cones.len() as f64 * (20.0 + 14.0 * n)
            + 6.0 * plan.planes.len() as f64
    },
    distance: |b, p, args| Plan::of(&balls(args.list(0))).distance(b, p),
};

/// The 2D hull of circles in the xy plane: each entry of `circles` is (x, y, radius).
pub(crate) static CIRCLES: Prim = Prim {
    name: "hull",
    profile: true,
    params: &[param("circles", Points, Def::Req, Any)],
    accepts: "circles: (x, y, radius) each",
    doc: "The convex hull of circles of any radii.",
    check: any,
    field: Field::Exact,
    extent: |args| {
        let e = extent(
            args.list(0)
                .iter()
                .map(|c| (DVec3::new(c[0], c[1], 0.0), c[2])),
        );
        Extent {
            min: [e.min[0], e.min[1], 0.0],
            max: [e.max[0], e.max[1], 0.0],
            ..e
        }
    },
    cost: |args| {
        let (circles, lines) = circles(args.list(0));
        let n = circles.len() as f64;
        n * (12.0 + 5.0 * n) + 4.0 * lines.len() as f64
    },
    distance: |b, p, args| {
        let (circles, lines) = circles(args.list(0));
        let q: Vec<[Reg; 2]> = circles
            .iter()
            .map(|c| [b.subc(p[0], c.c.x), b.subc(p[1], c.c.y)])
            .collect();
        let mut best: Option<Reg> = None;
        let mut keep = |b: &mut Builder, v: Reg| {
            best = Some(match best {
                None => v,
                Some(x) => b.max(x, v),
            })
        };
        // Each circle's direction from its centre.
        for qi in &q {
            let l = b.len2(qi[0], qi[1]);
            let (u, ok) = unit(b, qi, l);
            let mut v: Option<Reg> = None;
            for (qk, c) in q.iter().zip(&circles) {
                let d = b.dot2(qk[0], qk[1], u[0], u[1]);
                let d = b.subc(d, c.r);
                v = Some(v.map_or(d, |x| b.min(x, d)));
            }
            if let Some(v) = v {
                let v = kept(b, ok, v);
                keep(b, v);
            }
        }
        // The tangent lines.
        for (n, h) in lines {
            let x = b.mulc(p[0], n.x);
            let y = b.mulc(p[1], n.y);
            let s = b.add(x, y);
            let v = b.subc(s, h);
            keep(b, v);
        }
        best.unwrap_or_else(|| b.c(0.0))
    },
};

/// A ball (or a circle, its `c.z` 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Ball {
    pub c: DVec3,
    pub r: f64,
}

/// The box and sphere of balls.
fn extent(balls: impl Iterator<Item = (DVec3, f64)> + Clone) -> Extent {
    let lo = balls
        .clone()
        .fold(DVec3::INFINITY, |m, (c, r)| m.min(c - r));
    let hi = balls
        .clone()
        .fold(DVec3::NEG_INFINITY, |m, (c, r)| m.max(c + r));
    let centre = (lo + hi) / 2.0;
    let radius = balls.fold(0.0, |m: f64, (c, r)| m.max(c.distance(centre) + r));
    Extent {
        min: lo.to_array(),
        max: hi.to_array(),
        radius,
        symmetric: [false; 3],
    }
}

/// The balls of the entries of `BALLS`.
fn balls(list: &[[f64; 3]]) -> Vec<Ball> {
    list.chunks_exact(2)
        .map(|e| Ball {
            c: DVec3::from(e[0]),
            r: e[1][0],
        })
        .collect()
}

/// The entries of `BALLS` for these balls.
pub(crate) fn ball_entries(balls: &[Ball]) -> Vec<[f64; 3]> {
    balls
        .iter()
        .flat_map(|b| [b.c.to_array(), [b.r, 0.0, 0.0]])
        .collect()
}

/// How near counts as touching, for balls of this size.
fn tolerance(balls: &[Ball]) -> f64 {
    let size = balls
        .iter()
        .map(|b| b.c.distance(balls[0].c) + b.r)
        .fold(0.0, f64::max);
    1e-9 * size.max(f64::MIN_POSITIVE)
}

/// The balls no other ball holds (of two that are one, the first).
pub(crate) fn outermost(balls: &[Ball]) -> Vec<Ball> {
    let eps = tolerance(balls);
    let holds =
        |i: usize, j: usize| balls[i].c.distance(balls[j].c) + balls[j].r <= balls[i].r + eps;
    (0..balls.len())
        .filter(|&j| !(0..balls.len()).any(|i| i != j && holds(i, j) && !(holds(j, i) && i > j)))
        .map(|j| balls[j])
        .collect()
}

/// The cone tangent to balls `i` and `j`: its axis `a` (from i to j), and the part of its
/// normals along the axis `s` and across it `t` (s² + t² = 1).
#[derive(Debug, Clone, Copy)]
struct Cone {
    i: usize,
    a: DVec3,
    s: f64,
    t: f64,
}

/// What the hull of balls' field reads besides the point.
#[derive(Debug, Clone)]
struct Plan {
    balls: Vec<Ball>,
    cones: Vec<Cone>,
    /// The planes tangent to three balls with every ball on one side: unit normal, h.
    planes: Vec<(DVec3, f64)>,
}

impl Plan {
    fn of(given: &[Ball]) -> Plan {
        let balls = outermost(given);
        let n = balls.len();
        let eps = tolerance(&balls);
        let support = |u: DVec3| {
            balls
                .iter()
                .map(|b| b.c.dot(u) + b.r)
                .fold(f64::NEG_INFINITY, f64::max)
        };
        let mut planes: Vec<(DVec3, f64)> = Vec::new();
        let mut edge = vec![vec![false; n]; n];
        for i in 0..n {
            for j in i + 1..n {
                for k in j + 1..n {
                    for u in tangent_planes(&balls[i], &balls[j], &balls[k]) {
                        let h = support(u);
                        if [i, j, k]
                            .iter()
                            .any(|&m| balls[m].c.dot(u) + balls[m].r < h - eps)
                        {
                            continue;
                        }
                        (edge[i][j], edge[i][k], edge[j][k]) = (true, true, true);
                        if !planes
                            .iter()
                            .any(|(m, g)| m.dot(u) > 1.0 - 1e-12 && (g - h).abs() <= eps)
                        {
                            planes.push((u, h));
                        }
                    }
                }
            }
        }
        let mut cones = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                let d = balls[j].c - balls[i].c;
                let l = d.length();
                let a = d / l;
                let s = (balls[i].r - balls[j].r) / l;
                let t = (1.0 - s * s).max(0.0).sqrt();
                // A pair no plane touches is on the hull all round its cone or nowhere: its
                // part on the hull would end where a third ball touches the cone, at a plane.
                let u = s * a + t * a.any_orthonormal_vector();
                let on = edge[i][j] || balls[i].c.dot(u) + balls[i].r >= support(u) - eps;
                if on {
                    cones.push(Cone { i, a, s, t });
                }
            }
        }
        Plan {
            balls,
            cones,
            planes,
        }
    }

    /// max over the normals tried of p·u − h(u).
    fn distance(&self, b: &mut Builder, p: P) -> Reg {
        let q: Vec<P> = self
            .balls
            .iter()
            .map(|x| b.sub3c(p, x.c.to_array()))
            .collect();
        let mut best: Option<Reg> = None;
        let mut keep = |b: &mut Builder, v: Reg| {
            best = Some(match best {
                None => v,
                Some(x) => b.max(x, v),
            })
        };
        // min over balls k of q_k·u − r_k, for u of the dot products `d` (q_k·u).
        let least = |b: &mut Builder, d: &[Reg]| {
            let mut v: Option<Reg> = None;
            for (k, &x) in d.iter().enumerate() {
                let x = b.subc(x, self.balls[k].r);
                v = Some(v.map_or(x, |m| b.min(m, x)));
            }
            v
        };
        for qi in &q {
            let l = b.len3(*qi);
            let (u, ok) = unit(b, qi, l);
            let d: Vec<Reg> = q.iter().map(|qk| b.dot3(*qk, [u[0], u[1], u[2]])).collect();
            if let Some(v) = least(b, &d) {
                let v = kept(b, ok, v);
                keep(b, v);
            }
        }
        for cone in &self.cones {
            let qi = q[cone.i];
            let a = cone.a.to_array();
            let ac = b.c3(a);
            let along = b.dot3(qi, ac);
            let perp: Vec<Reg> = (0..3)
                .map(|m| {
                    let x = b.mulc(along, a[m]);
                    b.sub(qi[m], x)
                })
                .collect();
            let rho = b.len3([perp[0], perp[1], perp[2]]);
            let (w, ok) = unit(b, &perp, rho);
            let w = [w[0], w[1], w[2]];
            let ci = self.balls[cone.i].c;
            // q_k·a = q_i·a + (c_i − c_k)·a, times s.
            let sa: Vec<Reg> = self
                .balls
                .iter()
                .map(|x| {
                    let y = b.addc(along, (ci - x.c).dot(cone.a));
                    b.mulc(y, cone.s)
                })
                .collect();
            let qw: Vec<Reg> = q.iter().map(|qk| b.dot3(*qk, w)).collect();
            for t in [cone.t, -cone.t] {
                let d: Vec<Reg> = (0..q.len())
                    .map(|k| {
                        let y = b.mulc(qw[k], t);
                        b.add(sa[k], y)
                    })
                    .collect();
                if let Some(v) = least(b, &d) {
                    let v = kept(b, ok, v);
                    keep(b, v);
                }
            }
        }
        for &(n, h) in &self.planes {
            let x = b.mulc(p[0], n.x);
            let y = b.mulc(p[1], n.y);
            let z = b.mulc(p[2], n.z);
            let s = b.add(x, y);
            let s = b.add(s, z);
            let v = b.subc(s, h);
            keep(b, v);
        }
        best.unwrap_or_else(|| b.c(0.0))
    }
}

/// The unit vector along `v` of length `l`, and whether `l` is large enough to divide by
/// (where it is not, the normal is dropped: see [`kept`]).
fn unit(b: &mut Builder, v: &[Reg], l: Reg) -> (Vec<Reg>, Reg) {
    let tiny = b.c(1e-18);
    let ok = b.lt(tiny, l);
    let safe = b.max(l, tiny);
    let one = b.c(1.0);
    let inv = b.div(one, safe);
    (v.iter().map(|&x| b.mul(x, inv)).collect(), ok)
}

/// The value `v` of a normal where `ok`, else far below any distance: where the point is a
/// ball's centre or on a cone's axis its normal has no direction, and any other value of the
/// maximum is at most the distance still.
fn kept(b: &mut Builder, ok: Reg, v: Reg) -> Reg {
    let none = b.c(-FAR);
    b.select(ok, v, none)
}

/// Below any distance.
const FAR: f64 = 1e30;

/// The unit normals u of the planes tangent to three balls with the balls on the side
/// opposite u (c·u + r equal for the three): none where the centres are on one line.
fn tangent_planes(x: &Ball, y: &Ball, z: &Ball) -> Vec<DVec3> {
    let (d1, d2) = (y.c - x.c, z.c - x.c);
    let m = d1.cross(d2);
    let scale = d1.length() * d2.length();
    if m.length() <= 1e-12 * scale {
        return Vec::new();
    }
    // u·d1 = x.r − y.r and u·d2 = x.r − z.r: the part of u in the centres' plane, then ± the
    // rest along m.
    let (e1, e2) = (x.r - y.r, x.r - z.r);
    let (g11, g12, g22) = (d1.dot(d1), d1.dot(d2), d2.dot(d2));
    let det = g11 * g22 - g12 * g12;
    let alpha = (e1 * g22 - e2 * g12) / det;
    let beta = (e2 * g11 - e1 * g12) / det;
    let within = alpha * d1 + beta * d2;
    let rest = 1.0 - within.length_squared();
    if rest < 0.0 {
        return Vec::new();
    }
    let m = m.normalize();
    let r = rest.sqrt();
    [within + r * m, within - r * m]
        .into_iter()
        .map(|u| u.normalize())
        .collect()
}

/// The circles no other holds, and the lines tangent to two with every circle on one side:
/// unit normal, h.
fn circles(list: &[[f64; 3]]) -> (Vec<Ball>, Vec<(DVec2, f64)>) {
    let given: Vec<Ball> = list
        .iter()
        .map(|e| Ball {
            c: DVec3::new(e[0], e[1], 0.0),
            r: e[2],
        })
        .collect();
    let circles = outermost(&given);
    let eps = tolerance(&circles);
    let support = |u: DVec2| {
        circles
            .iter()
            .map(|c| c.c.truncate().dot(u) + c.r)
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let mut lines = Vec::new();
    for i in 0..circles.len() {
        for j in i + 1..circles.len() {
            let d = (circles[j].c - circles[i].c).truncate();
            let l = d.length();
            let a = d / l;
            let s = (circles[i].r - circles[j].r) / l;
            let t = (1.0 - s * s).max(0.0).sqrt();
            for u in [s * a + t * a.perp(), s * a - t * a.perp()] {
                let h = support(u);
                if circles[i].c.truncate().dot(u) + circles[i].r >= h - eps {
                    lines.push((u, h));
                }
            }
        }
    }
    (circles, lines)
}

#[cfg(test)]
#[path = "hull_balls_tests.rs"]
mod tests;
