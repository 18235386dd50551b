//! `hull(points, radius)` (issue 50, item 4): the convex hull of points, grown by a radius.
//! The hull is found when the scene is checked (incremental, over the points in order) as
//! faces (coplanar triangles merged into one convex polygon) and their edges; its distance
//! is exact: inside, the largest of the face planes' distances; outside, the nearest face
//! whose polygon holds the point's projection, or the nearest edge. Grown by `radius`, it is
//! the hull of equal balls about the points, exact too (the distance less the radius). Points
//! in one plane, on one line or all one hull a flat polygon, a segment or a point: nothing
//! without a radius, a rounded plate, capsule or ball with one.

use super::Kind::{Float as F, Points};
use super::Range::{Any, NonNeg};
use super::{param, Def, Extent, Field, Prim};
use crate::program::builder::{Builder, P};
use crate::program::Reg;
use glam::DVec3;

pub(super) static PRIMS: &[Prim] = &[Prim {
    name: "hull",
    profile: false,
    params: &[
        param("points", Points, Def::Req, Any),
        param("radius", F, Def::Num(0.0), NonNeg),
    ],
    accepts: "4 points or more not in one plane, or `radius` > 0",
    doc: "The convex hull of the points; with a `radius`, the hull of balls of that radius about them.",
    check: |args| {
        let hull = Hull::of(args.list(0));
        (hull.dims < 3 && args.f(1) == 0.0).then(|| {
            let what = match hull.dims {
                0 => "the points are all one point",
                1 => "the points lie on one line",
                _ => "the points lie in one plane",
            };
            format!(
                "{what}: their hull has no volume (give it a `radius` above 0 to make it a {}, or add a point off the {})",
                ["ball", "capsule", "rounded plate"][hull.dims],
                ["point", "line", "plane"][hull.dims],
            )
        })
    },
    field: Field::Exact,
    extent: |args| {
        let (pts, r) = (args.list(0), args.f(1));
        let min = [0, 1, 2].map(|i| pts.iter().map(|q| q[i]).fold(f64::INFINITY, f64::min) - r);
        let max =
            [0, 1, 2].map(|i| pts.iter().map(|q| q[i]).fold(f64::NEG_INFINITY, f64::max) + r);
        let centre = DVec3::from(min).lerp(DVec3::from(max), 0.5);
        let reach = pts
            .iter()
            .map(|q| DVec3::from(*q).distance(centre))
            .fold(0.0, f64::max);
        Extent {
            min,
            max,
            radius: reach + r,
            symmetric: [false; 3],
        }
    },
    cost: |args| {
        let hull = Hull::of(args.list(0));
        let sides: usize = hull.faces.iter().map(|f| f.sides.len()).sum();
        6.0 * hull.faces.len() as f64 + 7.0 * sides as f64 + 20.0 * hull.edges.len() as f64
    },
    distance: |b, p, args| {
        let hull = Hull::of(args.list(0));
        let d = hull.distance(b, p);
        b.subc(d, args.f(1))
    },
}];

/// Farther than any distance: a face that does not hold the point's projection.
const FAR: f64 = 1e30;

/// A face of the hull: its plane (outward unit normal `n`, offset `d`: n·x = d on it) and
/// the planes of its polygon's sides within it (outward unit normal, offset).
#[derive(Debug, Clone)]
struct Face {
    n: DVec3,
    d: f64,
    sides: Vec<(DVec3, f64)>,
}

/// The convex hull of points: its dimension (0 a point, 1 a segment, 2 a flat polygon, 3 a
/// solid), its faces (one for a flat polygon) and its edges (for a point, one of length 0).
#[derive(Debug, Clone)]
pub(crate) struct Hull {
    dims: usize,
    faces: Vec<Face>,
    edges: Vec<(DVec3, DVec3)>,
}

impl Hull {
    /// The hull of `points` (at least one).
    pub(crate) fn of(points: &[[f64; 3]]) -> Hull {
        let pts: Vec<DVec3> = points.iter().map(|q| DVec3::from(*q)).collect();
        let size = pts.iter().map(|q| q.distance(pts[0])).fold(0.0, f64::max);
        let eps = 1e-9 * size.max(f64::MIN_POSITIVE);
        let farthest = |f: &dyn Fn(DVec3) -> f64| {
            (0..pts.len())
                .max_by(|&i, &j| f(pts[i]).total_cmp(&f(pts[j])))
                .unwrap_or(0)
        };
        let a = pts[0];
        let i1 = farthest(&|q| q.distance(a));
        let b = pts[i1];
        if b.distance(a) <= eps {
            return Hull {
                dims: 0,
                faces: Vec::new(),
                edges: vec![(a, a)],
            };
        }
        let u = (b - a).normalize();
        let off_line = |q: DVec3| (q - a).reject_from_normalized(u).length();
        let i2 = farthest(&off_line);
        if off_line(pts[i2]) <= eps {
            let t = |q: &DVec3| (*q - a).dot(u);
            let lo = pts.iter().copied().min_by(|x, y| t(x).total_cmp(&t(y)));
            let hi = pts.iter().copied().max_by(|x, y| t(x).total_cmp(&t(y)));
            return Hull {
                dims: 1,
                faces: Vec::new(),
                edges: vec![(lo.unwrap_or(a), hi.unwrap_or(b))],
            };
        }
        let c = pts[i2];
        let n = (b - a).cross(c - a).normalize();
        let i3 = farthest(&|q| (q - a).dot(n).abs());
        if (pts[i3] - a).dot(n).abs() <= eps {
            return flat(&pts, n, eps);
        }
        solid(&pts, [0, i1, i2, i3], eps)
    }

    /// The hull's distance at `p`: signed for a solid, unsigned for a flat one.
    fn distance(&self, b: &mut Builder, p: P) -> Reg {
        // The nearest edge.
        let mut best: Option<Reg> = None;
        let mut nearer = |b: &mut Builder, d: Reg| {
            best = Some(match best {
                None => d,
                Some(x) => b.min(x, d),
            })
        };
        for &(x, y) in &self.edges {
            let d = segment(b, p, x, y);
            nearer(b, d);
        }
        // The faces whose polygon holds the projection of `p`; and the largest plane value.
        let mut planes: Option<Reg> = None;
        for f in &self.faces {
            let h = plane(b, p, f.n, f.d);
            planes = Some(match planes {
                None => h,
                Some(x) => b.max(x, h),
            });
            let mut out: Option<Reg> = None;
            for &(m, e) in &f.sides {
                let s = plane(b, p, m, e);
                out = Some(match out {
                    None => s,
                    Some(x) => b.max(x, s),
                });
            }
            let Some(out) = out else { continue };
            let zero = b.c(0.0);
            let within = b.lt(out, zero);
            let far = b.c(FAR);
            let habs = b.abs(h);
            let d = b.select(within, habs, far);
            nearer(b, d);
        }
        let unsigned = best.unwrap_or_else(|| b.c(0.0));
        match (self.dims, planes) {
            (3, Some(inside)) => {
                let zero = b.c(0.0);
                let outside = b.lt(zero, inside);
                b.select(outside, unsigned, inside)
            }
            _ => unsigned,
        }
    }
}

/// n·p − d.
fn plane(b: &mut Builder, p: P, n: DVec3, d: f64) -> Reg {
    let x = b.mulc(p[0], n.x);
    let y = b.mulc(p[1], n.y);
    let z = b.mulc(p[2], n.z);
    let s = b.add(x, y);
    let s = b.add(s, z);
    b.subc(s, d)
}

/// The distance from `p` to the segment from `x` to `y` (a point where they are one).
fn segment(b: &mut Builder, p: P, x: DVec3, y: DVec3) -> Reg {
    let q = b.sub3c(p, x.to_array());
    let e = y - x;
    let l2 = e.length_squared();
    if l2 == 0.0 {
        return b.len3(q);
    }
    let ec = b.c3((e / l2).to_array());
    let t = b.dot3(q, ec);
    let t = b.clampc(t, 0.0, 1.0);
    let r = b.map3(q, |b, v, i| {
        let s = b.mulc(t, e[i]);
        b.sub(v, s)
    });
    b.len3(r)
}

/// The hull of points that lie in the plane through `pts[0]` of unit normal `n`: one face,
/// the convex polygon of their 2D hull (monotone chain), and its sides as edges.
fn flat(pts: &[DVec3], n: DVec3, eps: f64) -> Hull {
    let e1 = n.any_orthonormal_vector();
    let e2 = n.cross(e1);
    let o = pts[0];
    let mut q: Vec<(f64, f64, DVec3)> = pts
        .iter()
        .map(|&x| ((x - o).dot(e1), (x - o).dot(e2), x))
        .collect();
    q.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let cross = |o: &(f64, f64, DVec3), a: &(f64, f64, DVec3), b: &(f64, f64, DVec3)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut ring: Vec<(f64, f64, DVec3)> = Vec::new();
    for pass in 0..2 {
        let start = ring.len();
        let iter: Box<dyn Iterator<Item = &(f64, f64, DVec3)>> = if pass == 0 {
            Box::new(q.iter())
        } else {
            Box::new(q.iter().rev())
        };
        for x in iter {
            while ring.len() >= start + 2
                && cross(&ring[ring.len() - 2], &ring[ring.len() - 1], x) <= eps * eps
            {
                ring.pop();
            }
            ring.push(*x);
        }
        ring.pop();
    }
    let corners: Vec<DVec3> = ring.iter().map(|x| x.2).collect();
    let edges: Vec<(DVec3, DVec3)> = (0..corners.len())
        .map(|i| (corners[i], corners[(i + 1) % corners.len()]))
        .collect();
    // Counter-clockwise about n: each side's outward normal is its direction × n.
    let sides = edges
        .iter()
        .map(|&(x, y)| {
            let m = (y - x).cross(n).normalize();
            (m, m.dot(x))
        })
        .collect();
    Hull {
        dims: 2,
        faces: vec![Face {
            n,
            d: n.dot(o),
            sides,
        }],
        edges,
    }
}

/// A triangle of the growing hull: its corners (indices), counter-clockwise seen from
/// outside, and its plane.
#[derive(Debug, Clone, Copy)]
struct Tri {
    v: [usize; 3],
    n: DVec3,
    d: f64,
}

impl Tri {
    fn new(pts: &[DVec3], v: [usize; 3]) -> Tri {
        let n = (pts[v[1]] - pts[v[0]])
            .cross(pts[v[2]] - pts[v[0]])
            .normalize();
        Tri {
            v,
            n,
            d: n.dot(pts[v[0]]),
        }
    }
}

/// The hull of points not in one plane, from the tetrahedron of `start` on, adding the
/// others one at a time; then its coplanar triangles merged into faces.
fn solid(pts: &[DVec3], start: [usize; 4], eps: f64) -> Hull {
    let [a, b, c, d] = start;
    let centre = (pts[a] + pts[b] + pts[c] + pts[d]) / 4.0;
    let mut tris: Vec<Tri> = [[a, b, c], [a, c, d], [a, d, b], [b, d, c]]
        .into_iter()
        .map(|v| {
            let t = Tri::new(pts, v);
            if t.n.dot(centre) > t.d {
                Tri::new(pts, [v[0], v[2], v[1]])
            } else {
                t
            }
        })
        .collect();
    for (i, &x) in pts.iter().enumerate() {
        if start.contains(&i) {
            continue;
        }
        let seen: Vec<bool> = tris.iter().map(|t| t.n.dot(x) - t.d > eps).collect();
        if !seen.contains(&true) {
            continue;
        }
        // The horizon: edges of seen triangles whose other triangle is not seen.
        let mut horizon = Vec::new();
        for (t, _) in tris.iter().zip(&seen).filter(|(_, s)| **s) {
            for k in 0..3 {
                let (u, v) = (t.v[k], t.v[(k + 1) % 3]);
                let twin_seen = tris
                    .iter()
                    .zip(&seen)
                    .any(|(o, s)| *s && (0..3).any(|j| o.v[j] == v && o.v[(j + 1) % 3] == u));
                if !twin_seen {
                    horizon.push((u, v));
                }
            }
        }
        let mut kept: Vec<Tri> = tris
            .iter()
            .zip(&seen)
            .filter(|(_, s)| !**s)
            .map(|(t, _)| *t)
            .collect();
        kept.extend(horizon.into_iter().map(|(u, v)| Tri::new(pts, [u, v, i])));
        tris = kept;
    }
    merge(pts, &tris, eps)
}

/// Faces from triangles: those of one plane (normals and offsets within `eps`) make one
/// convex polygon, whose sides are the edges not shared within it.
fn merge(pts: &[DVec3], tris: &[Tri], eps: f64) -> Hull {
    let mut groups: Vec<Vec<Tri>> = Vec::new();
    for t in tris {
        match groups
            .iter_mut()
            .find(|g| g[0].n.dot(t.n) > 1.0 - 1e-12 && (g[0].d - t.d).abs() <= eps)
        {
            Some(g) => g.push(*t),
            None => groups.push(vec![*t]),
        }
    }
    let mut faces = Vec::with_capacity(groups.len());
    let mut edges = Vec::new();
    for g in &groups {
        let directed: Vec<(usize, usize)> = g
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t.v[k], t.v[(k + 1) % 3])))
            .collect();
        let n = g[0].n;
        let mut sides = Vec::new();
        for &(u, v) in &directed {
            if directed.contains(&(v, u)) {
                continue;
            }
            let (x, y) = (pts[u], pts[v]);
            let m = (y - x).cross(n).normalize();
            sides.push((m, m.dot(x)));
            // Each edge of the solid borders two faces: kept once, from its lower index.
            if u < v {
                edges.push((x, y));
            }
        }
        faces.push(Face {
            n,
            d: g[0].d,
            sides,
        });
    }
    Hull {
        dims: 3,
        faces,
        edges,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prim::Args;
    use crate::program::Float;

    fn distance(points: &[[f64; 3]], radius: f64, at: [f64; 3]) -> f64 {
        let args = Args::with_list(&[radius], 0, points);
        let mut b = Builder::new(true);
        let p = b.input_point();
        let d = (PRIMS[0].distance)(&mut b, p, &args);
        let m = b.c(-1.0);
        let program = b.finish(d, m);
        let regs = program.run::<f64>(at, |_| {});
        regs[program.distance().0 as usize].to_f64()
    }

    #[test]
    fn the_hull_of_a_cube_s_corners_is_the_cube() {
        let mut corners = Vec::new();
        for i in 0..8 {
            corners.push([0, 1, 2].map(|k| if i >> k & 1 == 1 { 1.0 } else { -1.0 }));
        }
        // Points inside change nothing.
        corners.push([0.2, -0.3, 0.5]);
        corners.push([0.0, 0.0, 0.0]);
        let hull = Hull::of(&corners);
        assert_eq!((hull.dims, hull.faces.len(), hull.edges.len()), (3, 6, 12));
        let mut rng = crate::Rng::new(7);
        for _ in 0..2000 {
            let at = [0, 1, 2].map(|_| rng.range(-3.0, 3.0));
            let q = at.map(|x: f64| x.abs() - 1.0);
            let outside = q.iter().map(|x| x.max(0.0).powi(2)).sum::<f64>().sqrt();
            let inside = q[0].max(q[1]).max(q[2]).min(0.0);
            let exact = outside + inside;
            let d = distance(&corners, 0.0, at);
            assert!((d - exact).abs() < 1e-12, "{at:?}: {d} against {exact}");
            let rounded = distance(&corners, 0.25, at);
            assert!((rounded - (exact - 0.25)).abs() < 1e-12, "{at:?}");
        }
    }

    #[test]
    fn flat_and_thinner_hulls_need_a_radius_and_then_are_exact() {
        let plate = [
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 0.5],
        ];
        assert!((PRIMS[0].check)(&Args::with_list(&[0.0], 0, &plate))
            .is_some_and(|m| m.contains("one plane")));
        assert!((PRIMS[0].check)(&Args::with_list(&[0.1], 0, &plate)).is_none());
        // Above the plate's middle, beside an edge, off a corner.
        for (at, exact) in [
            ([1.0, 0.7, 0.5], 0.7),
            ([1.0, 0.3, -0.4], 0.5),
            ([3.0, 0.0, 2.0], 2.0_f64.sqrt()),
        ] {
            let d = distance(&plate, 0.1, at);
            assert!((d - (exact - 0.1)).abs() < 1e-12, "{at:?}: {d}");
        }
        let line = [[0.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 1.0, 0.0]];
        assert!((PRIMS[0].check)(&Args::with_list(&[0.0], 0, &line))
            .is_some_and(|m| m.contains("one line")));
        let d = distance(&line, 0.5, [1.0, 1.0, 0.0]);
        assert!((d - 0.5).abs() < 1e-12, "{d}");
        let one = [[1.0, 1.0, 1.0], [1.0, 1.0, 1.0]];
        let d = distance(&one, 0.5, [1.0, 3.0, 1.0]);
        assert!((d - 1.5).abs() < 1e-12, "{d}");
    }

    #[test]
    fn a_random_hull_holds_its_points_and_lies_between_its_planes_and_its_corners() {
        // A random cloud: every point is inside its hull; outside, the distance is at least
        // the largest plane value and at most the nearest corner's distance.
        let mut rng = crate::Rng::new(11);
        let pts: Vec<[f64; 3]> = (0..40)
            .map(|_| [0, 1, 2].map(|_| rng.range(-1.0, 1.0)))
            .collect();
        let hull = Hull::of(&pts);
        assert_eq!(hull.dims, 3);
        // Euler: V − E + F = 2 with triangular faces counted as merged polygons.
        let v: std::collections::BTreeSet<[u64; 3]> = hull
            .edges
            .iter()
            .flat_map(|(a, b)| [a.to_array(), b.to_array()])
            .map(|x| x.map(f64::to_bits))
            .collect();
        assert_eq!(v.len() + hull.faces.len(), hull.edges.len() + 2);
        for _ in 0..300 {
            let at = [0, 1, 2].map(|_| rng.range(-2.5, 2.5));
            let d = distance(&pts, 0.0, at);
            let planes = hull
                .faces
                .iter()
                .map(|f| f.n.dot(DVec3::from(at)) - f.d)
                .fold(f64::NEG_INFINITY, f64::max);
            if d > 0.0 {
                let corner = pts
                    .iter()
                    .map(|q| DVec3::from(*q).distance(DVec3::from(at)))
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    planes <= d + 1e-12 && d <= corner + 1e-12,
                    "{at:?}: {planes} {d} {corner}"
                );
            } else {
                assert!((d - planes).abs() < 1e-12, "{at:?}: {d} {planes}");
            }
        }
        for q in &pts {
            assert!(distance(&pts, 0.0, *q) <= 1e-12, "{q:?}");
        }
    }
}
