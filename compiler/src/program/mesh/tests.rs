//! Tests of triangle meshes: exact distances and signs against brute force (an octahedron, a
//! torus), meshes turned inside out and holes counted, hinted walks.

use super::*;

/// A closed octahedron of radius 1.
fn octahedron() -> TriMesh {
    let v = [
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    let f = [
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    TriMesh::new("octahedron", &v, &f, 1.0).expect("a mesh")
}

#[test]
fn an_octahedron_is_exact_inside_and_out() {
    let m = octahedron();
    assert_eq!(m.report, Report::default());
    let exact = |p: [f64; 3]| {
        // The octahedron's distance is exact along the face normals and at the corners.
        (p[0].abs() + p[1].abs() + p[2].abs() - 1.0) / 3f64.sqrt()
    };
    for p in [[0.0, 0.0, 0.0], [0.2, 0.1, 0.3], [1.0, 1.0, 1.0]] {
        assert!((m.distance(p) - exact(p)).abs() < 1e-12, "{p:?}");
    }
    assert!((m.distance([2.0, 0.0, 0.0]) - 1.0).abs() < 1e-12);
    assert!((m.distance([2.0f32, 0.0, 0.0]) - 1.0).abs() < 1e-6);
}

#[test]
fn inside_out_meshes_are_turned_and_holes_counted() {
    let v = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let inward = [[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]];
    let m = TriMesh::new("t", &v, &inward, 1.0).expect("a mesh");
    assert!(m.report.flipped);
    assert!(m.distance([0.1, 0.1, 0.1]) < 0.0);
    let open = TriMesh::new("t", &v, &inward[..3], 1.0).expect("a mesh");
    assert_eq!(open.report.open_edges, 3);
    assert!(matches!(
        TriMesh::new("t", &v, &[[0, 0, 1]], 1.0),
        Err(Invalid::Empty)
    ));
    assert!(matches!(
        TriMesh::new("t", &v, &[[0, 1, 9]], 1.0),
        Err(Invalid::Index(0, 9))
    ));
}

/// A torus of radii 1 and 0.4 in the xz plane, `n` × `m` quads split in two: closed,
/// of genus 1, wound outwards.
pub(crate) fn torus(n: usize, m: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut v = Vec::new();
    for i in 0..n {
        let u = i as f64 / n as f64 * std::f64::consts::TAU;
        for j in 0..m {
            let w = j as f64 / m as f64 * std::f64::consts::TAU;
            let r = 1.0 + 0.4 * w.cos();
            v.push([r * u.cos(), 0.4 * w.sin(), r * u.sin()]);
        }
    }
    let at = |i: usize, j: usize| ((i % n) * m + j % m) as u32;
    let mut f = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            f.push([a, c, b]);
            f.push([a, d, c]);
        }
    }
    (v, f)
}

/// The distance from `p` to a triangle, computed another way than Ericson's regions: the
/// projection onto the plane where it falls inside, else the nearest of the three edges.
fn brute_triangle(p: [f64; 3], t: [[f64; 3]; 3]) -> f64 {
    let p = DVec3::from(p);
    let t = t.map(DVec3::from);
    let seg = |a: DVec3, b: DVec3| {
        let d = b - a;
        let s = ((p - a).dot(d) / d.length_squared()).clamp(0.0, 1.0);
        p.distance(a + d * s)
    };
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let q = p - n * ((p - t[0]).dot(n) / n.length_squared());
    let inside = (0..3).all(|k| {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        (b - a).cross(q - a).dot(n) >= 0.0
    });
    if inside {
        p.distance(q)
    } else {
        seg(t[0], t[1]).min(seg(t[1], t[2])).min(seg(t[2], t[0]))
    }
}

/// The generalised winding number of the triangles at `p`: the sum of their solid angles
/// over 4π (Van Oosterom and Strackee, IEEE Trans. Biomed. Eng., 1983), 1 inside a
/// closed mesh and 0 outside.
fn winding(p: [f64; 3], tris: &[[[f64; 3]; 3]]) -> f64 {
    let mut sum = 0.0;
    for t in tris {
        let [a, b, c] = t.map(|v| DVec3::from(v) - DVec3::from(p));
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let det = a.dot(b.cross(c));
        let div = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        sum += 2.0 * det.atan2(div);
    }
    sum / (4.0 * std::f64::consts::PI)
}

/// Points to test at: random ones around the mesh, ones near and on its corners and
/// edges, and the corners and edge midpoints themselves.
fn probes(tris: &[[[f64; 3]; 3]], rng: &mut crate::rng::Rng) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    for _ in 0..200 {
        out.push(rng.point(2.0));
    }
    for _ in 0..200 {
        let t = tris[rng.below(tris.len())];
        let k = rng.below(3);
        let mid = [0, 1, 2].map(|i| 0.5 * (t[k][i] + t[(k + 1) % 3][i]));
        let bary = {
            let (u, v) = (rng.uniform(), rng.uniform());
            let (u, v) = if u + v > 1.0 {
                (1.0 - u, 1.0 - v)
            } else {
                (u, v)
            };
            [0, 1, 2].map(|i| t[0][i] + u * (t[1][i] - t[0][i]) + v * (t[2][i] - t[0][i]))
        };
        for base in [t[k], mid, bary] {
            out.push(base);
            let e = rng.range(1e-4, 0.05);
            let o = rng.point(e);
            out.push([base[0] + o[0], base[1] + o[1], base[2] + o[2]]);
        }
    }
    out
}

#[test]
fn distances_and_signs_match_brute_force() {
    let (v, f) = torus(24, 12);
    let m = TriMesh::new("torus", &v, &f, 1.0).expect("a mesh");
    assert_eq!(m.report, Report::default());
    let tris: Vec<[[f64; 3]; 3]> = m.triangles().iter().map(|t| [t[0], t[1], t[2]]).collect();
    let mut rng = crate::rng::Rng::new(40);
    for p in probes(&tris, &mut rng) {
        let brute = tris
            .iter()
            .map(|t| brute_triangle(p, *t))
            .fold(f64::INFINITY, f64::min);
        let inside = winding(p, &tris) > 0.5;
        let d = m.distance(p);
        assert!(
            (d.abs() - brute).abs() <= 1e-12,
            "f64 at {p:?}: {d} against {brute}"
        );
        if brute > 1e-9 {
            assert_eq!(d < 0.0, inside, "sign at {p:?}: {d}");
        }
        let d32 = m.distance(p.map(|x| x as f32));
        assert!(
            (f64::from(d32.abs()) - brute).abs() <= 2e-6,
            "f32 at {p:?}: {d32} against {brute}"
        );
        if brute > 1e-4 {
            assert_eq!(d32 < 0.0, inside, "f32 sign at {p:?}: {d32}");
        }
    }
}

/// A walk bounded from its start by any triangle's distance gives what the walk from the
/// root alone gives, bit for bit, in f64 and f32, and names the nearest triangle as the
/// next hint.
#[test]
fn a_hinted_walk_is_the_walk_from_the_root() {
    let (v, f) = torus(40, 20);
    let m = TriMesh::new("torus", &v, &f, 1.0).expect("a mesh");
    let tris: Vec<[[f64; 3]; 3]> = m.triangles().iter().map(|t| [t[0], t[1], t[2]]).collect();
    let mut rng = crate::rng::Rng::new(42);
    let n = m.triangles().len();
    let mut chained = 0u32;
    for p in probes(&tris, &mut rng) {
        let (d, d32) = (m.distance(p), m.distance(p.map(|x| x as f32)));
        for hint in [rng.below(n) as u32, 0, n as u32 + 7] {
            let mut h = hint;
            assert_eq!(m.distance_from(p, &mut h).to_bits(), d.to_bits(), "{p:?}");
            let near = nearest(&m.triangles()[h as usize], p).0.sqrt();
            assert!((near - d.abs()).abs() <= 1e-12, "{p:?}: hint {h}");
            let mut h = hint;
            let q = p.map(|x| x as f32);
            assert_eq!(m.distance_from(q, &mut h).to_bits(), d32.to_bits(), "{p:?}");
        }
        // As along a ray: each query hinted by the one before.
        assert_eq!(m.distance_from(p, &mut chained).to_bits(), d.to_bits());
    }
}

#[test]
fn a_hole_leaves_the_sign_right_away_from_it() {
    let (v, f) = torus(24, 12);
    // The quads of one cell of the tube, around (1, 0, 0) outside: a hole there.
    let open: Vec<[u32; 3]> = f
        .iter()
        .enumerate()
        .filter(|(k, _)| !(*k < 2 * 12 && (k / 2) % 12 < 2))
        .map(|(_, t)| *t)
        .collect();
    let m = TriMesh::new("open torus", &v, &open, 1.0).expect("a mesh");
    assert!(m.report.open_edges > 0);
    let closed = TriMesh::new("torus", &v, &f, 1.0).expect("a mesh");
    let closed_tris: Vec<[[f64; 3]; 3]> = closed
        .triangles()
        .iter()
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    let mut rng = crate::rng::Rng::new(41);
    let mut checked = 0;
    for p in probes(&closed_tris, &mut rng) {
        // Away from the hole, whose rim lies within 0.55 of (1.4, 0, 0).
        if DVec3::from(p).distance(DVec3::new(1.4, 0.0, 0.0)) < 1.2
            || closed.distance(p).abs() < 1e-9
        {
            continue;
        }
        let inside = winding(p, &closed_tris) > 0.5;
        assert_eq!(m.distance(p) < 0.0, inside, "sign at {p:?}");
        checked += 1;
    }
    assert!(checked > 300, "{checked} points checked");
}
