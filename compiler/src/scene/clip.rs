//! The box around a box cut by half-spaces, and the half-spaces that cut nothing of it: the
//! bounds of an intersection of bounded shapes and planes and the planes it can do without
//! (`bounds.rs`, a Voronoi cell cut from a sphere). The box is a convex polyhedron
//! held as the vertex loops of its faces; each half-space clips every face (Sutherland and
//! Hodgman's polygon clipping) and closes the cut with a face of the points on its plane, so
//! the polyhedron stays convex and closed, and the box around its vertices holds the
//! intersection.

use crate::scene::{Combine, Graph, Node, NodeId, V3};
use glam::DVec3;

/// What the planes of an intersection of planes and bounded children do to the children's
/// boxes (centre and half-extents, as `boxes` gives them), intersected.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Cuts {
    /// The box (centre and half-extents) around what the planes' half-spaces leave of them,
    /// grown a little for the rounding of the cut; `None` when they leave nothing.
    pub bound: Option<(V3, V3)>,
    /// The plane children that cut nothing: the polyhedron lies strictly inside each one's
    /// half-space, and so does the solid. Without them the intersection has the same solid,
    /// and its field, a maximum of fewer distance bounds, is still one (lower only away from
    /// the solid).
    pub uncut: Vec<NodeId>,
}

/// [`Cuts`] of an intersection `node`; `None` for any other node, or one without planes or
/// bounded children.
pub(crate) fn intersection(
    graph: &Graph,
    node: &Node,
    boxes: &dyn Fn(&NodeId) -> Option<(V3, V3)>,
) -> Option<Cuts> {
    let (lo, hi, planes) = parts(graph, node, boxes)?;
    let units: Vec<_> = planes.iter().map(|&(_, n, h)| unit(n, h)).collect();
    let vertices = polyhedron(lo, hi, units.iter().flatten().copied());
    let Some((vlo, vhi)) = extent(&vertices) else {
        return Some(Cuts {
            bound: None,
            uncut: Vec::new(),
        });
    };
    let size = (0..3).map(|k| vhi[k] - vlo[k]).fold(0.0, f64::max);
    let g = 1e-9 * size.max(1e-9);
    let bound = Some((
        [0, 1, 2].map(|k| (vlo[k] + vhi[k]) / 2.0),
        [0, 1, 2].map(|k| (vhi[k] - vlo[k]) / 2.0 + g),
    ));
    let reach = vertices
        .iter()
        .map(|v| v.abs().max_element())
        .fold(DVec3::from(hi).abs().max_element(), f64::max);
    // Far enough inside that the rounding of the cut points cannot be what separates them.
    let margin = 1e-9 * reach.max(1e-9);
    let uncut = (planes.iter().zip(&units))
        .filter(|(_, u)| u.is_some_and(|(n, h)| vertices.iter().all(|v| n.dot(*v) - h < -margin)))
        .map(|(&(id, ..), _)| id)
        .collect();
    Some(Cuts { bound, uncut })
}

/// A plane child of an intersection: the child, its normal and its height.
type PlaneChild = (NodeId, V3, f64);

/// An intersection's children's boxes intersected (low and high corners) and its planes:
/// `None` for any other node, or one without planes or bounded children.
fn parts(
    graph: &Graph,
    node: &Node,
    boxes: &dyn Fn(&NodeId) -> Option<(V3, V3)>,
) -> Option<(V3, V3, Vec<PlaneChild>)> {
    let Node::Combine {
        op: Combine::Intersect,
        children,
    } = node
    else {
        return None;
    };
    let (mut lo, mut hi) = ([f64::NEG_INFINITY; 3], [f64::INFINITY; 3]);
    let mut planes = Vec::new();
    for c in children {
        if let Node::Plane { normal, height } = graph.node(*c) {
            planes.push((*c, *normal, *height));
        } else if let Some((c, h)) = boxes(c) {
            for k in 0..3 {
                lo[k] = lo[k].max(c[k] - h[k]);
                hi[k] = hi[k].min(c[k] + h[k]);
            }
        }
    }
    let finite = (0..3).all(|k| lo[k].is_finite() && hi[k].is_finite() && lo[k] <= hi[k]);
    (!planes.is_empty() && finite).then_some((lo, hi, planes))
}

/// The faces of a convex polyhedron, each a loop of vertices.
type Faces = Vec<Vec<DVec3>>;

/// The half-space `dot(p, n) ≤ h` with a normal of length 1; `None` for a normal of length 0
/// or a height that is not finite (such a plane is passed over).
fn unit(n: V3, h: f64) -> Option<(DVec3, f64)> {
    let n = DVec3::from(n);
    let len = n.length();
    (len > 0.0 && h.is_finite()).then(|| (n / len, h / len))
}

/// The vertices of the box `lo..hi` cut by the half-spaces `planes` (normals of length 1);
/// none when nothing is left.
fn polyhedron(lo: V3, hi: V3, planes: impl Iterator<Item = (DVec3, f64)>) -> Vec<DVec3> {
    let mut faces = cube(DVec3::from(lo), DVec3::from(hi));
    for (n, h) in planes {
        faces = cut(&faces, n, h);
        if faces.is_empty() {
            break;
        }
    }
    faces.into_iter().flatten().collect()
}

/// The low and high corners of the box around `vertices`; `None` for none.
fn extent(vertices: &[DVec3]) -> Option<(V3, V3)> {
    let lo = vertices.iter().copied().reduce(DVec3::min)?;
    let hi = vertices.iter().copied().reduce(DVec3::max)?;
    Some((lo.to_array(), hi.to_array()))
}

/// The six faces of the box `lo..hi`.
fn cube(lo: DVec3, hi: DVec3) -> Faces {
    let corner = |i: usize| {
        DVec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    };
    [
        [0, 2, 6, 4],
        [1, 5, 7, 3],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 1, 3, 2],
        [4, 6, 7, 5],
    ]
    .iter()
    .map(|f| f.iter().map(|&i| corner(i)).collect())
    .collect()
}

/// The polyhedron `faces` cut by the half-space `dot(p, n) ≤ h` (n of length 1), the cut
/// closed by a face on the plane.
fn cut(faces: &Faces, n: DVec3, h: f64) -> Faces {
    let mut out = Vec::with_capacity(faces.len() + 1);
    let mut on_plane = Vec::new();
    for face in faces {
        let mut kept = Vec::with_capacity(face.len() + 1);
        for (k, &a) in face.iter().enumerate() {
            let b = face[(k + 1) % face.len()];
            let (da, db) = (n.dot(a) - h, n.dot(b) - h);
            if da <= 0.0 {
                kept.push(a);
            }
            if (da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0) {
                let x = a + (b - a) * (da / (da - db));
                kept.push(x);
                on_plane.push(x);
            } else if da == 0.0 {
                on_plane.push(a);
            }
        }
        if kept.len() >= 3 {
            out.push(kept);
        }
    }
    if on_plane.len() >= 3 {
        out.push(around(on_plane, n));
    }
    out
}

/// Points on a plane of normal `n` in order around their centroid (a convex polygon's loop).
fn around(points: Vec<DVec3>, n: DVec3) -> Vec<DVec3> {
    let centre = points.iter().copied().sum::<DVec3>() / points.len() as f64;
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    let mut keyed: Vec<(f64, DVec3)> = points
        .into_iter()
        .map(|p| ((p - centre).dot(v).atan2((p - centre).dot(u)), p))
        .collect();
    keyed.sort_by(|a, b| a.0.total_cmp(&b.0));
    keyed.into_iter().map(|(_, p)| p).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The box (low and high corners) around the part of the box `lo..hi` where
    /// `dot(p, n) ≤ h` for every `(n, h)` of `planes`; `None` when nothing is left.
    fn clipped(lo: V3, hi: V3, planes: &[(V3, f64)]) -> Option<(V3, V3)> {
        let vertices = polyhedron(lo, hi, planes.iter().filter_map(|&(n, h)| unit(n, h)));
        extent(&vertices)
    }

    /// A cube cut by the planes of an octahedron's faces keeps the octahedron's box; a
    /// corner cut off by x + y + z ≤ −2.5 leaves the box of that corner; half-spaces that
    /// leave nothing give `None`; a plane the box lies inside changes nothing.
    #[test]
    fn a_box_cut_by_half_spaces_keeps_the_box_of_what_is_left() {
        let mut planes = Vec::new();
        for sx in [-1.0, 1.0] {
            for sy in [-1.0, 1.0] {
                for sz in [-1.0, 1.0] {
                    planes.push(([sx, sy, sz], 1.0));
                }
            }
        }
        let (lo, hi) = clipped([-5.0; 3], [5.0; 3], &planes).expect("an octahedron");
        for k in 0..3 {
            assert!((lo[k] + 1.0).abs() < 1e-12 && (hi[k] - 1.0).abs() < 1e-12);
        }
        let corner = clipped([-1.0; 3], [1.0; 3], &[([1.0, 1.0, 1.0], -2.5)]).expect("a corner");
        for k in 0..3 {
            assert!((corner.0[k] + 1.0).abs() < 1e-12);
            assert!((corner.1[k] + 0.5).abs() < 1e-12, "{corner:?}");
        }
        let gone = [([1.0, 0.0, 0.0], 0.0), ([-1.0, 0.0, 0.0], -0.5)];
        assert!(clipped([-1.0; 3], [1.0; 3], &gone).is_none());
        let same = clipped([-1.0; 3], [1.0; 3], &[([0.0, 1.0, 0.0], 3.0)]).expect("the box");
        assert_eq!(same, ([-1.0; 3], [1.0; 3]));
    }

    /// Of a box's planes, those that cut a corner off or touch it are kept and those the box
    /// lies inside are left out.
    #[test]
    fn planes_the_solid_lies_inside_cut_nothing() {
        let mut graph = Graph::default();
        let span = crate::Span::new(crate::FileId(0), 0..0);
        let cube = graph.add(Node::Box { half: [1.0; 3] }, span);
        let mut plane = |normal: V3, height: f64| graph.add(Node::Plane { normal, height }, span);
        let corner = plane([1.0, 1.0, 1.0], 2.5);
        let touching = plane([0.0, 1.0, 0.0], 1.0);
        let far = plane([0.0, 0.0, -2.0], 2.5);
        let beyond = plane([1.0, 1.0, 1.0], 3.5);
        let node = Node::Combine {
            op: Combine::Intersect,
            children: vec![cube, corner, touching, far, beyond],
        };
        let boxes = |c: &NodeId| (*c == cube).then_some(([0.0; 3], [1.0; 3]));
        let cuts = intersection(&graph, &node, &boxes).expect("an intersection");
        assert_eq!(cuts.uncut, vec![far, beyond]);
    }

    /// Cells of a sphere cut by the planes halfway between seeds: every point of a cell
    /// (sampled inside the sphere, on the seed's side of every plane) lies in its box.
    #[test]
    fn every_point_of_a_cell_lies_in_its_box() {
        let mut rng = crate::Rng::new(5);
        let seeds: Vec<DVec3> = (0..12)
            .map(|_| {
                DVec3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                )
            })
            .collect();
        for (i, &s) in seeds.iter().enumerate() {
            let planes: Vec<(V3, f64)> = seeds
                .iter()
                .enumerate()
                .filter(|&(j, _)| j != i)
                .map(|(_, &t)| {
                    let m = (t - s).normalize();
                    (m.to_array(), m.dot((s + t) / 2.0))
                })
                .collect();
            let (lo, hi) = clipped([-1.0; 3], [1.0; 3], &planes).expect("the seed's cell");
            for _ in 0..2000 {
                let p = DVec3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                );
                let inside = planes.iter().all(|(n, h)| DVec3::from(*n).dot(p) <= *h);
                if inside {
                    for k in 0..3 {
                        assert!(
                            p[k] >= lo[k] - 1e-12 && p[k] <= hi[k] + 1e-12,
                            "{p} {lo:?} {hi:?}"
                        );
                    }
                }
            }
        }
    }
}
