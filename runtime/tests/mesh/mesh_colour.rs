//! Colour from the surface in meshes' vertex colours: a colour field of the normal `n` takes
//! each vertex's normal, and a painted shape moved afterwards carries its pattern along, as
//! the renderers paint them (docs/language.md, "Colour fields").

use crate::meshes;

use meshes::*;

/// The positions and linear `COLOR_0` colours of the one primitive of a `.glb`.
fn coloured(path: &std::path::Path) -> Vec<([f32; 3], [f32; 3])> {
    let (positions, colours, _) = glb_colours(path);
    positions.into_iter().zip(colours).collect()
}

/// A sphere painted with its normal's colours and its own height, then moved: each vertex's
/// colour is 0.5 + 0.5·(its normal) in red and green, within the mesh's normal error, and
/// its height above the sphere's centre in blue, exactly.
#[test]
fn vertex_colours_take_the_normal_and_move_with_the_painted_shape() {
    let d = dir("colour-normal");
    let body = "material m = phong { color: field { vec3(0.5 + 0.5 * n.x, 0.5 + 0.5 * n.y, 0.5 + 0.4 * p.y) } };\n\
         scene { (sphere(1) @ m).translate(2, 1, 0); }\n";
    let scene = write_scene(&d, "normals.sdf", body);
    let glb = d.join("n.glb");
    mesh(&[s(&scene), "-o", s(&glb), "--resolution", "24"]);
    let vertices = coloured(&glb);
    assert!(vertices.len() > 100);
    let mut worst = 0.0f32;
    for (p, c) in &vertices {
        let q = [p[0] - 2.0, p[1] - 1.0, p[2]];
        let r = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
        let n = q.map(|x| x / r);
        worst = worst.max((c[0] - (0.5 + 0.5 * n[0])).abs());
        worst = worst.max((c[1] - (0.5 + 0.5 * n[1])).abs());
        assert!((c[2] - (0.5 + 0.4 * q[1])).abs() < 1e-5, "{p:?}: {c:?}");
    }
    assert!(worst < 0.03, "normals off by {worst}");
    let _ = std::fs::remove_dir_all(&d);
}
