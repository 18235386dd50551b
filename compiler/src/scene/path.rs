//! The paths a profile is swept along (`sweep(profile, path)`, issue 50 item 2): a polyline,
//! a helix, a chain of cubic Bézier curves and an arc through three points, each with the
//! rotation-minimising frame the profile's plane follows, found when the scene is checked.
//!
//! A frame is (N, B, T): T the path's direction, N and B the profile's x and y axes, with
//! N × B = T. It starts with B the world's up (+y) made normal to T (+z where the path starts
//! along y), and is carried along the path without turning about T: for a polyline by the
//! rotation about T₀ × T₁ at each corner (two reflections, as in Wang, Jüttler, Zheng and Liu,
//! "Computation of rotation minimizing frames", ACM TOG 27(1), 2008), for a Bézier chain by
//! their double reflection between samples, for a helix and an arc in closed form. On a closed
//! path the frame's turn about T on the way round is spread evenly along it (its `twist`, in
//! radians per unit of length), so that the ends meet without a seam.
//!
//! The lowering (`lower/sweep.rs`) reads these; the checks here give the messages of bad
//! paths, and [`Path::reach`] how near the path the nearest-point map is one to one.

use super::V3;
use glam::DVec3;
use std::f64::consts::{PI, TAU};

/// A path as the checker made it: its kind, its frames, and its twist.
#[derive(Debug, Clone, PartialEq)]
pub struct Path {
    pub kind: PathKind,
    /// Whether it ends where it starts (a closed polyline or Bézier chain).
    pub closed: bool,
    /// The frame's turn per unit of length that closes it (0 on an open path).
    pub twist: f64,
}

/// The kinds of path.
#[derive(Debug, Clone, PartialEq)]
pub enum PathKind {
    /// Segments between points; per segment its frame at its start (N, B; T is the segment's
    /// direction) and the length of the path before it.
    Polyline {
        points: Vec<V3>,
        frames: Vec<[V3; 2]>,
        before: Vec<f64>,
    },
    /// A right-handed helix about the y axis from (radius, −h/2, 0) rising `pitch` a turn for
    /// `turns` turns (h = pitch·turns), turning from +x towards −z.
    Helix { radius: f64, pitch: f64, turns: f64 },
    /// Cubic Bézier curves through `controls` (3k + 1 points), each cut at check time into
    /// `pieces` equal spans of its parameter; `normals` holds the frame's N at each cut of
    /// each curve, its ends included (k·(pieces + 1) of them, the twist already in them).
    Bezier {
        controls: Vec<V3>,
        pieces: usize,
        normals: Vec<V3>,
    },
    /// The arc about `centre` of `radius` in the plane of `e1` (towards its start) and `e2`,
    /// from angle 0 to `angle` (turning from e1 towards e2); `n0` the frame's first N.
    Arc {
        centre: V3,
        radius: f64,
        e1: V3,
        e2: V3,
        angle: f64,
        n0: V3,
    },
}

fn v(x: V3) -> DVec3 {
    DVec3::from(x)
}

/// The frame's first N for direction `t` (unit): B the world's up made normal to `t`.
pub fn first_normal(t: DVec3) -> DVec3 {
    let up = if t.y.abs() > 0.999 {
        DVec3::Z
    } else {
        DVec3::Y
    };
    let b = (up - t * up.dot(t)).normalize();
    b.cross(t)
}

/// `n` reflected across the plane of normal `m` (unit).
fn reflect(n: DVec3, m: DVec3) -> DVec3 {
    n - 2.0 * n.dot(m) * m
}

/// Double reflection (Wang et al. 2008) of the frame normal `n` at `x0` with tangent `t0` to
/// `x1` with tangent `t1`.
fn double_reflection(n: DVec3, x0: DVec3, t0: DVec3, x1: DVec3, t1: DVec3) -> DVec3 {
    let v1 = x1 - x0;
    let c1 = v1.length_squared();
    if c1 == 0.0 {
        return reflect_towards(n, t0, t1);
    }
    let m1 = v1 / c1.sqrt();
    let (nl, tl) = (reflect(n, m1), reflect(t0, m1));
    let v2 = t1 - tl;
    if v2.length_squared() < 1e-30 {
        return nl;
    }
    reflect(nl, v2.normalize())
}

/// The normal `n` of tangent `t0` turned by the least rotation taking `t0` to `t1` (the two
/// reflections across the planes normal to `t0` and to t0 + t1).
fn reflect_towards(n: DVec3, t0: DVec3, t1: DVec3) -> DVec3 {
    let m = t0 + t1;
    if m.length_squared() < 1e-24 {
        return n;
    }
    reflect(n, m.normalize())
}

/// The signed angle from `a` to `b` about `axis` (all unit, a and b normal to the axis).
fn angle_about(a: DVec3, b: DVec3, axis: DVec3) -> f64 {
    a.cross(b).dot(axis).atan2(a.dot(b))
}

/// A number for a message.
fn num(x: f64) -> String {
    crate::diagnostics::number(x, 4)
}

fn point(x: DVec3) -> String {
    format!("({}, {}, {})", num(x.x), num(x.y), num(x.z))
}

/// Why a path's points make no path: each the checker's message, located at the call.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PathError {
    /// A polyline of fewer than two points.
    #[error("a polyline needs at least 2 points, and this one has {0}")]
    TooFewPoints(usize),
    /// Two consecutive points of a polyline are one point.
    #[error("points {first} and {second} of the polyline are the same point {at}: its segment has no direction")]
    RepeatedPoint {
        first: usize,
        second: usize,
        /// The point, as written.
        at: String,
    },
    /// A polyline's corner that turns straight back.
    #[error("the polyline turns straight back at point {index} {at}: a profile cannot follow a turn of 180°")]
    TurnsBack { index: usize, at: String },
    /// A Bézier chain whose count of points is not 3k + 1.
    #[error("a Bézier path takes 3k + 1 control points (4 for one cubic curve, 7 for two, …: each curve after the first adds 3), and this one has {count}: give {near}")]
    BezierCount {
        count: usize,
        /// The nearest counts that are, in words.
        near: String,
    },
    /// A control point on its curve's end point.
    #[error("control point {control} is the same point as end point {end} {at}: the curve has no direction there (move it along the direction the curve should leave or reach its end)")]
    ControlAtEnd {
        control: usize,
        end: usize,
        at: String,
    },
    /// A Bézier curve whose direction vanishes inside it.
    #[error("the Bézier path stops at {at} (its direction is undefined there: its curve {curve} doubles back on itself)")]
    BezierStops { curve: usize, at: String },
    /// An arc through two equal points.
    #[error("an arc's three points must be three different points")]
    ArcPointsEqual,
    /// An arc through three points on one line.
    #[error("the arc's three points lie on one line: no circle goes through them (draw the segment with `polyline([start, end])`)")]
    ArcCollinear,
}

impl Path {
    /// `polyline(points)`: two or more points, no two consecutive ones equal, and no corner
    /// that turns straight back; closed where the last point is the first.
    pub fn polyline(points: &[V3]) -> Result<Path, PathError> {
        if points.len() < 2 {
            return Err(PathError::TooFewPoints(points.len()));
        }
        let pts: Vec<DVec3> = points.iter().map(|x| v(*x)).collect();
        for i in 1..pts.len() {
            if pts[i] == pts[i - 1] {
                return Err(PathError::RepeatedPoint {
                    first: i - 1,
                    second: i,
                    at: point(pts[i]),
                });
            }
        }
        let closed = pts.len() > 3 && pts[0] == pts[pts.len() - 1];
        let dirs: Vec<DVec3> = pts.windows(2).map(|w| (w[1] - w[0]).normalize()).collect();
        let corners = if closed { dirs.len() } else { dirs.len() - 1 };
        for i in 0..corners {
            let (a, b) = (dirs[i], dirs[(i + 1) % dirs.len()]);
            if a.dot(b) < -1.0 + 1e-9 {
                return Err(PathError::TurnsBack {
                    index: (i + 1) % dirs.len(),
                    at: point(pts[(i + 1) % dirs.len()]),
                });
            }
        }
        let mut n = vec![first_normal(dirs[0])];
        for i in 1..dirs.len() {
            n.push(reflect_towards(n[i - 1], dirs[i - 1], dirs[i]));
        }
        let mut before = vec![0.0];
        for w in pts.windows(2) {
            before.push(before[before.len() - 1] + w[0].distance(w[1]));
        }
        let length = before.pop().unwrap_or(0.0);
        let twist = if closed {
            let back = reflect_towards(n[n.len() - 1], dirs[dirs.len() - 1], dirs[0]);
            -angle_about(n[0], back, dirs[0]) / length
        } else {
            0.0
        };
        let frames = n
            .iter()
            .zip(&dirs)
            .map(|(n, t)| [n.to_array(), t.cross(*n).to_array()])
            .collect();
        Ok(Path {
            kind: PathKind::Polyline {
                points: points.to_vec(),
                frames,
                before,
            },
            closed,
            twist,
        })
    }

    /// `helix(radius, pitch, turns)`, all above 0 (the ranges say so).
    pub fn helix(radius: f64, pitch: f64, turns: f64) -> Path {
        Path {
            kind: PathKind::Helix {
                radius,
                pitch,
                turns,
            },
            closed: false,
            twist: 0.0,
        }
    }

    /// `bezier(points)`: 3k + 1 control points (k ≥ 1) of k cubic curves, each starting
    /// where the one before ends; closed where the last point is the first.
    pub fn bezier(points: &[V3]) -> Result<Path, PathError> {
        let n = points.len();
        if n < 4 || (n - 1) % 3 != 0 {
            let k = (n.max(2) - 1).div_ceil(3).max(1);
            let (lo, hi) = (3 * (n.saturating_sub(1) / 3).max(1) + 1, 3 * k + 1);
            let near = if lo == hi || n < 4 {
                format!("{hi}")
            } else {
                format!("{lo} or {hi}")
            };
            return Err(PathError::BezierCount { count: n, near });
        }
        let pts: Vec<DVec3> = points.iter().map(|x| v(*x)).collect();
        let k = (n - 1) / 3;
        for c in 0..k {
            for (i, j) in [(3 * c, 3 * c + 1), (3 * c + 3, 3 * c + 2)] {
                if pts[i] == pts[j] {
                    return Err(PathError::ControlAtEnd {
                        control: j,
                        end: i,
                        at: point(pts[i]),
                    });
                }
            }
        }
        let closed = pts[0] == pts[n - 1];
        // Dense samples: the turning of each curve picks its pieces; the frames follow.
        const DENSE: usize = 64;
        let mut pieces = 2;
        for c in 0..k {
            let mut turn = 0.0;
            let mut last = None;
            for j in 0..=DENSE {
                let t = tangent(&pts[3 * c..3 * c + 4], j as f64 / DENSE as f64);
                if t.length_squared() == 0.0 {
                    continue;
                }
                if let Some(l) = last {
                    turn += angle(l, t);
                }
                last = Some(t);
            }
            pieces = pieces.max(
                ((turn / (PI / 8.0)).ceil() as usize)
                    .clamp(2, 16)
                    .next_power_of_two(),
            );
        }
        // Frames at every dense sample of each curve (both its ends included), by double
        // reflection; from one curve to the next by the least rotation at their joint (a
        // corner where their directions differ, turned about as a polyline's).
        let mut dense: Vec<(DVec3, DVec3, DVec3)> = Vec::with_capacity(k * (DENSE + 1));
        let mut arc = Vec::with_capacity(k * (DENSE + 1));
        let mut length = 0.0;
        for c in 0..k {
            let q = &pts[3 * c..3 * c + 4];
            for j in 0..=DENSE {
                let t = j as f64 / DENSE as f64;
                let (x, d) = (cubic(q, t), tangent(q, t));
                if d.length_squared() < 1e-24 {
                    return Err(PathError::BezierStops {
                        curve: c,
                        at: point(x),
                    });
                }
                let d = d.normalize();
                let nn = match dense.last() {
                    None => first_normal(d),
                    Some(&(_, t0, n0)) if j == 0 => reflect_towards(n0, t0, d),
                    Some(&(x0, t0, n0)) => {
                        length += x.distance(x0);
                        double_reflection(n0, x0, t0, x, d)
                    }
                };
                arc.push(length);
                dense.push((x, d, (nn - d * nn.dot(d)).normalize()));
            }
        }
        let twist = if closed {
            let (_, t_end, n_end) = dense[dense.len() - 1];
            let (_, t_start, n_start) = dense[0];
            let back = reflect_towards(n_end, t_end, t_start);
            -angle_about(n_start, back, t_start) / length
        } else {
            0.0
        };
        // Each cut's normal (pieces divide the dense samples evenly), turned by the twist so
        // far: pieces + 1 of them per curve.
        let step = DENSE / pieces;
        let normals = (0..k)
            .flat_map(|c| (0..=pieces).map(move |j| c * (DENSE + 1) + j * step))
            .map(|s| {
                let (_, t, n) = dense[s];
                let nrm = rotate(n, t, twist * arc[s]);
                (nrm - t * nrm.dot(t)).normalize().to_array()
            })
            .collect();
        Ok(Path {
            kind: PathKind::Bezier {
                controls: points.to_vec(),
                pieces,
                normals,
            },
            closed,
            twist,
        })
    }

    /// `arc3(start, through, end)`: the arc of the circle through the three points from
    /// `start` to `end` passing `through`.
    pub fn arc3(a: V3, b: V3, c: V3) -> Result<Path, PathError> {
        let (a, b, c) = (v(a), v(b), v(c));
        if a == b || b == c || a == c {
            return Err(PathError::ArcPointsEqual);
        }
        let (u, w) = (b - a, c - a);
        let n = u.cross(w);
        let size = u.length().max(w.length());
        if n.length() <= 1e-9 * size * size {
            return Err(PathError::ArcCollinear);
        }
        // The circumcentre of the triangle.
        let centre = a
            + (w.length_squared() * n.cross(u) + u.length_squared() * w.cross(n))
                / (2.0 * n.length_squared());
        let n = n.normalize();
        let radius = a.distance(centre);
        let e1 = (a - centre).normalize();
        let e2 = n.cross(e1);
        let ang = |x: DVec3| {
            let d = x - centre;
            d.dot(e2).atan2(d.dot(e1)).rem_euclid(TAU)
        };
        let angle = ang(c);
        let n0 = first_normal(e2);
        Ok(Path {
            kind: PathKind::Arc {
                centre: centre.to_array(),
                radius,
                e1: e1.to_array(),
                e2: e2.to_array(),
                angle,
                n0: n0.to_array(),
            },
            closed: false,
            twist: 0.0,
        })
    }

    /// The least box about the path.
    pub fn aabb(&self) -> (V3, V3) {
        let boxed = |pts: &[V3]| {
            let lo = [0, 1, 2].map(|i| pts.iter().fold(f64::INFINITY, |m, q| m.min(q[i])));
            let hi = [0, 1, 2].map(|i| pts.iter().fold(f64::NEG_INFINITY, |m, q| m.max(q[i])));
            (lo, hi)
        };
        match &self.kind {
            PathKind::Polyline { points, .. } => boxed(points),
            // The control points' hull holds each curve.
            PathKind::Bezier { controls, .. } => boxed(controls),
            PathKind::Helix {
                radius,
                pitch,
                turns,
            } => {
                let h = pitch * turns / 2.0;
                ([-radius, -h, -radius], [*radius, h, *radius])
            }
            PathKind::Arc { centre, radius, .. } => {
                (centre.map(|c| c - radius), centre.map(|c| c + radius))
            }
        }
    }

    /// Points along the path with their direction (unit), `per` to a piece: for the reach and
    /// the tests.
    pub fn samples(&self, per: usize) -> Vec<(DVec3, DVec3)> {
        match &self.kind {
            PathKind::Polyline { points, .. } => {
                let mut out = Vec::new();
                for w in points.windows(2) {
                    let (a, b) = (v(w[0]), v(w[1]));
                    let t = (b - a).normalize();
                    for j in 0..per {
                        out.push((a.lerp(b, j as f64 / per as f64), t));
                    }
                }
                let (a, b) = (v(points[points.len() - 2]), v(points[points.len() - 1]));
                out.push((b, (b - a).normalize()));
                out
            }
            PathKind::Helix {
                radius,
                pitch,
                turns,
            } => {
                let n = ((turns * per as f64).ceil() as usize).max(2);
                let total = TAU * turns;
                (0..=n)
                    .map(|j| {
                        let phi = total * j as f64 / n as f64;
                        helix_at(*radius, *pitch, *turns, phi)
                    })
                    .collect()
            }
            PathKind::Bezier { controls, .. } => {
                let pts: Vec<DVec3> = controls.iter().map(|x| v(*x)).collect();
                let k = (pts.len() - 1) / 3;
                let mut out = Vec::new();
                for c in 0..k {
                    let q = &pts[3 * c..3 * c + 4];
                    let last = if c + 1 == k { per } else { per - 1 };
                    for j in 0..=last {
                        let t = j as f64 / per as f64;
                        out.push((cubic(q, t), tangent(q, t).normalize()));
                    }
                }
                out
            }
            PathKind::Arc {
                centre,
                radius,
                e1,
                e2,
                angle,
                ..
            } => {
                let n = ((angle / TAU * per as f64).ceil() as usize).max(2);
                (0..=n)
                    .map(|j| {
                        let a = angle * j as f64 / n as f64;
                        let (s, c) = a.sin_cos();
                        let r = v(*e1) * c + v(*e2) * s;
                        (v(*centre) + r * *radius, v(*e2) * c - v(*e1) * s)
                    })
                    .collect()
            }
        }
    }

    /// How near the path the nearest point on it is one point that moves smoothly (the
    /// path's reach): the least radius of curvature of a smooth path, and half the least
    /// distance between parts of it that are not neighbours; with where it is least.
    pub fn reach(&self) -> (f64, DVec3, &'static str) {
        match &self.kind {
            // In closed form: the radius of curvature r + (pitch/2π)²/r, and half the gap
            // between neighbouring turns, pitch·r/√(r² + (pitch/2π)²) across the wire.
            PathKind::Helix {
                radius,
                pitch,
                turns,
            } => {
                let k = pitch / TAU;
                let len = radius.hypot(k);
                let bend = len * (len / radius);
                let gap = if *turns > 1.0 {
                    pitch * (radius / len) / 2.0
                } else {
                    f64::INFINITY
                };
                let at = helix_at(*radius, *pitch, *turns, 0.0).0;
                return if bend <= gap {
                    (bend, at, "curvature")
                } else {
                    (gap, at, "closeness")
                };
            }
            PathKind::Arc {
                radius, centre, e1, ..
            } => {
                return (*radius, v(*centre) + v(*e1) * *radius, "curvature");
            }
            _ => {}
        }
        // At most some 2 000 samples, whatever the number of pieces: the pairs are compared
        // all with all.
        let pieces = match &self.kind {
            PathKind::Polyline { points, .. } => points.len() - 1,
            PathKind::Bezier { controls, .. } => (controls.len() - 1) / 3,
            _ => 1,
        };
        let per = (2000 / pieces).clamp(1, 48);
        let s = self.samples(per);
        let mut best = (f64::INFINITY, s[0].0, "");
        if matches!(self.kind, PathKind::Bezier { .. }) {
            // Within each curve (a corner where two meet is turned about, not bent).
            for (i, w) in s.windows(3).enumerate() {
                if (i + 1) % per == 0 {
                    continue;
                }
                let (a, b, c) = (w[0].0, w[1].0, w[2].0);
                // The circle through three neighbouring samples.
                let (u, x) = (b - a, c - a);
                let cr = u.cross(x).length();
                if cr > 0.0 {
                    let r = u.length() * x.length() * (c - b).length() / (2.0 * cr);
                    if r < best.0 {
                        best = (r, b, "curvature");
                    }
                }
            }
        }
        // Bottlenecks: pairs of samples farther apart along the path than π times their
        // distance, whose chord is nearly normal to the path at both.
        let mut arc = vec![0.0];
        for w in s.windows(2) {
            arc.push(arc[arc.len() - 1] + w[0].0.distance(w[1].0));
        }
        let total = arc[arc.len() - 1];
        for i in 0..s.len() {
            for j in i + 1..s.len() {
                let d = s[i].0.distance(s[j].0);
                let mut along = arc[j] - arc[i];
                if self.closed {
                    along = along.min(total - along);
                }
                if d == 0.0 || along < PI * d || d / 2.0 >= best.0 {
                    continue;
                }
                let chord = (s[j].0 - s[i].0) / d;
                if chord.dot(s[i].1).abs() < 0.3 && chord.dot(s[j].1).abs() < 0.3 {
                    best = (d / 2.0, s[i].0.lerp(s[j].0, 0.5), "closeness");
                }
            }
        }
        best
    }
}

/// Whether the profile `id` is a disc about its origin: swept, the distance to the path less
/// its radius, exact everywhere.
pub fn round_profile(graph: &super::Graph, id: super::NodeId) -> bool {
    matches!(graph.node(id), super::Node::Prim { prim, .. } if prim.name == "circle")
}

impl Path {
    /// The path in a few words, for `--emit ir`.
    pub fn describe(&self) -> String {
        let closed = if self.closed { " closed" } else { "" };
        match &self.kind {
            PathKind::Polyline { points, .. } => {
                format!("polyline{closed} of {} points", points.len())
            }
            PathKind::Helix {
                radius,
                pitch,
                turns,
            } => format!(
                "helix radius={} pitch={} turns={}",
                num(*radius),
                num(*pitch),
                num(*turns)
            ),
            PathKind::Bezier {
                controls, pieces, ..
            } => format!(
                "bezier{closed} of {} curves, {pieces} pieces each",
                (controls.len() - 1) / 3
            ),
            PathKind::Arc { radius, angle, .. } => format!(
                "arc radius={} angle={}deg",
                num(*radius),
                num(angle.to_degrees())
            ),
        }
    }

    /// The instructions its nearest point and frame cost per point, roughly.
    pub fn cost(&self) -> f64 {
        match &self.kind {
            PathKind::Polyline { points, .. } => 45.0 * points.len() as f64,
            PathKind::Helix { .. } => 220.0,
            PathKind::Bezier {
                controls, pieces, ..
            } => ((controls.len() - 1) / 3) as f64 * (25.0 * *pieces as f64 + 260.0),
            PathKind::Arc { .. } => 70.0,
        }
    }
}

/// The helix's point and unit direction at angle `phi` from its start.
pub fn helix_at(radius: f64, pitch: f64, turns: f64, phi: f64) -> (DVec3, DVec3) {
    let k = pitch / TAU;
    let (s, c) = phi.sin_cos();
    let x = DVec3::new(radius * c, k * phi - pitch * turns / 2.0, -radius * s);
    let t = DVec3::new(-radius * s, k, -radius * c).normalize();
    (x, t)
}

/// The cubic Bézier curve of `q` (4 points) at `t`.
pub fn cubic(q: &[DVec3], t: f64) -> DVec3 {
    let s = 1.0 - t;
    q[0] * (s * s * s) + q[1] * (3.0 * s * s * t) + q[2] * (3.0 * s * t * t) + q[3] * (t * t * t)
}

/// Its derivative at `t` (the second's direction where the first vanishes at an end).
pub fn tangent(q: &[DVec3], t: f64) -> DVec3 {
    let s = 1.0 - t;
    let d = (q[1] - q[0]) * (3.0 * s * s)
        + (q[2] - q[1]) * (6.0 * s * t)
        + (q[3] - q[2]) * (3.0 * t * t);
    if d.length_squared() > 1e-24 {
        return d;
    }
    // At an end whose neighbouring control point coincides with it.
    if t < 0.5 {
        q[2] - q[0]
    } else {
        q[3] - q[1]
    }
}

/// The angle between two non-zero vectors.
fn angle(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// `n` turned by `a` about the unit `axis` (Rodrigues).
fn rotate(n: DVec3, axis: DVec3, a: f64) -> DVec3 {
    let (s, c) = a.sin_cos();
    n * c + axis.cross(n) * s + axis * axis.dot(n) * (1.0 - c)
}
