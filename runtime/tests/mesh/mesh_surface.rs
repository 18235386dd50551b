//! How close `sdfc mesh`'s meshes lie to the surface: sphere vertices on it, a box's edges and
//! corners kept, the mesh within half a voxel of the surface both ways (Hausdorff).

use crate::mesh::{hausdorff, read_obj, to_mesh};
use crate::meshes;
use meshes::*;

/// A sphere's vertices lie within 1 % of a voxel of the surface (the f64 distance program),
/// and the mesh is within half a voxel of the surface both ways.
#[test]
fn sphere_vertices_lie_on_the_surface() {
    let body = "scene { sphere(0.5).translate(0.1, -0.2, 0.3); }\n";
    let (_, scene, out) = scene_in("sphere", "ball.sdf", body, "ball.obj");
    let voxel = 0.03;
    mesh(&[s(&scene), "-o", s(&out), "--voxel", "0.03"]);
    let m = read_obj(&out);
    assert_eq!(manifold(&m, "sphere"), 2);
    let p = program(&scene);
    let worst = m
        .positions
        .iter()
        .map(|&q| distance(&p, q).abs())
        .fold(0.0, f64::max);
    assert!(worst <= 0.01 * voxel, "a vertex is {worst} from the sphere");
    hausdorff(&m, &p, voxel, [0.1, -0.2, 0.3], 0.5);
}

/// Sharp features: a box's corners are vertices within 5 % of a voxel, and its edges lie in
/// the mesh to within 5 % of a voxel along their length.
#[test]
fn box_edges_and_corners_are_kept() {
    let d = dir("box");
    let (c, h) = ([0.013, -0.021, 0.007], [0.33, 0.26, 0.19]);
    let scene = write_scene(
        &d,
        "box.sdf",
        &format!(
            "scene {{ box(({}, {}, {})).translate({}, {}, {}); }}\n",
            h[0], h[1], h[2], c[0], c[1], c[2]
        ),
    );
    let voxel = 0.04;
    let out = d.join("box.stl");
    mesh(&[s(&scene), "-o", s(&out), "--voxel", "0.04"]);
    let m = read_stl(&out);
    assert_eq!(manifold(&m, "box"), 2);
    let corner = |k: usize| [0, 1, 2].map(|i| c[i] + if k >> i & 1 == 1 { h[i] } else { -h[i] });
    for k in 0..8 {
        let q = corner(k);
        let near = m
            .positions
            .iter()
            .map(|v| {
                let d: f64 = (0..3).map(|i| (f64::from(v[i]) - q[i]).powi(2)).sum();
                d.sqrt()
            })
            .fold(f64::INFINITY, f64::min);
        assert!(near <= 0.05 * voxel, "corner {q:?}: nearest vertex {near}");
    }
    let mut worst = 0.0f64;
    for a in 0..8 {
        for axis in 0..3 {
            if a >> axis & 1 == 1 {
                continue;
            }
            let (p, q) = (corner(a), corner(a | 1 << axis));
            for s in 0..=24 {
                let t = s as f64 / 24.0;
                let x = [0, 1, 2].map(|i| p[i] + t * (q[i] - p[i]));
                worst = worst.max(to_mesh(&m, x));
            }
        }
    }
    assert!(
        worst <= 0.05 * voxel,
        "a point of an edge is {worst} from the mesh"
    );
    hausdorff(&m, &program(&scene), voxel, c, 0.4);
}

/// The torus and the thin plate of the benchmark, alone: within half a voxel both ways.
#[test]
fn torus_and_plate_are_within_half_a_voxel() {
    let d = dir("torus");
    for (name, body, centre) in [
        (
            "torus",
            "torus(0.35, 0.12).translate(0, 0.5, 0)",
            [0.0, 0.5, 0.0],
        ),
        (
            "plate",
            "box((0.9, 0.025, 0.9)).translate(0, -0.575, 0)",
            [0.0, -0.575, 0.0],
        ),
    ] {
        let scene = write_scene(
            &d,
            &format!("{name}.sdf"),
            &format!("scene {{ {body}; }}\n"),
        );
        let out = d.join(format!("{name}.stl"));
        let voxel = 2.0 / 64.0;
        mesh(&[s(&scene), "-o", s(&out), "--voxel", &voxel.to_string()]);
        let m = read_stl(&out);
        let chi = manifold(&m, name);
        assert_eq!(chi, if name == "torus" { 0 } else { 2 }, "{name}");
        hausdorff(&m, &program(&scene), voxel, centre, 0.6);
    }
}
