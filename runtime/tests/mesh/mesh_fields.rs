//! Fields meshed without `--bounds` (issue 51 item 3): the box of a `field { }` solid comes
//! from its formula by interval arithmetic (`scene/analysis/field.rs`), so a rod, a blob, a
//! bumpy sphere and a repeated field mesh without bounds, their meshes holding the whole
//! solid (the rod's is the same mesh as the primitive's); a field with no bound is named in
//! the error, whose suggested bounds hold every bounded part.

use crate::meshes;

use meshes::*;
use std::path::Path;

/// The lowest and highest corner of a mesh's vertices.
fn extent(m: &Read) -> [[f32; 3]; 2] {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in &m.positions {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    [lo, hi]
}

fn close(a: [[f32; 3]; 2], b: [[f32; 3]; 2], tolerance: f32, what: &str) {
    for k in 0..2 {
        for i in 0..3 {
            assert!(
                (a[k][i] - b[k][i]).abs() <= tolerance,
                "{what}: extent {a:?}, expected {b:?}"
            );
        }
    }
}

/// Fails unless the extent of `m` is `b` within `tolerance`, saying `what`.
#[track_caller]
fn spans(m: &Read, b: [[f32; 3]; 2], tolerance: f32, what: &str) {
    close(extent(m), b, tolerance, what);
}

/// A rod of radius 0.2 along y, 2 long (`cylinder(0.2, 2)`), written as a field.
const ROD: &str = "field { max(length(p.xz) - 0.2, abs(p.y) - 1) }";

fn meshed(d: &Path, name: &str, body: &str, resolution: &str) -> Read {
    let scene = write_scene(d, &format!("{name}.sdf"), body);
    let out = d.join(format!("{name}.stl"));
    mesh(&[s(&scene), "-o", s(&out), "--resolution", resolution]);
    read_stl(&out)
}

/// A rod written as a field meshes without --bounds to the mesh of the same rod as a
/// primitive: the same grid (the same box), so the same triangles, and the whole rod.
#[test]
fn a_rod_built_as_a_field_meshes_as_the_primitive_does() {
    let d = dir("field-rod");
    let field_text = format!("scene {{ {ROD}.translate(0.5, 0, 0); }}\n");
    let field = meshed(&d, "field", &field_text, "64");
    let prim_text = "scene { cylinder(0.2, 2).translate(0.5, 0, 0); }\n";
    let prim = meshed(&d, "prim", prim_text, "64");
    assert_eq!(manifold(&field, "field rod"), 2);
    assert_eq!(field.triangles.len(), prim.triangles.len());
    // The whole rod: from y = −1 to 1, x from 0.3 to 0.7 (within a hundredth).
    spans(&field, [[0.3, -1.0, -0.2], [0.7, 1.0, 0.2]], 0.01, "rod");
    close(
        extent(&field),
        extent(&prim),
        1e-3,
        "rod against the primitive",
    );
}

/// A blob (two spheres joined by a polynomial smooth minimum) and a sphere with noise on it,
/// written as fields, mesh without --bounds, closed, to their whole extent.
#[test]
fn a_blob_and_a_bumpy_sphere_mesh_without_bounds() {
    let d = dir("field-blob");
    let blob_text = "scene { field {\n\
           let a = length(p - vec3(-0.4, 0, 0)) - 0.5;\n\
           let b = length(p - vec3(0.4, 0.2, 0)) - 0.4;\n\
           let h = max(0.3 - abs(a - b), 0) / 0.3;\n\
           min(a, b) - h * h * 0.3 / 4\n\
         }; }\n";
    let blob = meshed(&d, "blob", blob_text, "64");
    assert_eq!(manifold(&blob, "blob"), 2);
    // The spheres' far sides: x from −0.9 to 0.8, y from −0.5 to 0.6, z ±0.5; the blend
    // only adds material between them.
    spans(&blob, [[-0.9, -0.5, -0.5], [0.8, 0.6, 0.5]], 0.02, "blob");
    let bumpy_text =
        "scene { field { distance(sphere(1), p) + 0.1 * noise(p * 4) }.translate(0, 2, 0); }\n";
    let bumpy = meshed(&d, "bumpy", bumpy_text, "48");
    assert_eq!(manifold(&bumpy, "bumpy sphere"), 2);
    // Within the sphere of radius 1 ± 0.087 (the noise's range times 0.1) around (0, 2, 0).
    let [lo, hi] = extent(&bumpy);
    for i in 0..3 {
        let c = [0.0, 2.0, 0.0][i];
        assert!(lo[i] > c - 1.09 && lo[i] < c - 0.9, "bumpy: {lo:?}");
        assert!(hi[i] < c + 1.09 && hi[i] > c + 0.9, "bumpy: {hi:?}");
    }
}

/// A repeated field is bounded by its count: three rods one apart.
#[test]
fn a_repeated_field_is_bounded_by_its_count() {
    let d = dir("field-repeat");
    let rods_text = format!("scene {{ {ROD}.repeat((1, 0, 0), (3, 1, 1)); }}\n");
    let rods = meshed(&d, "rods", &rods_text, "64");
    // Three closed rods: χ = 6.
    assert_eq!(manifold(&rods, "rods"), 6);
    spans(&rods, [[-1.2, -1.0, -0.2], [1.2, 1.0, 0.2]], 0.02, "rods");
}

/// A field with no bound (a gyroid sheet fills space) is named, with its location, in the
/// error, and the bounds suggested hold the bounded parts, a field's among them.
#[test]
fn an_unbounded_field_is_named_and_the_hint_holds_the_bounded_fields() {
    let d = dir("field-unbounded");
    let body = "scene {\n  field { abs(sin(p.x) * cos(p.y) + sin(p.y) * cos(p.z) + sin(p.z) * cos(p.x)) - 0.2 };\n  \
         field { max(length(p.xz) - 0.2, abs(p.y) - 3) }.translate(4, 0, 0);\n  sphere(1);\n}\n";
    let scene = write_scene(&d, "gyroid.sdf", body);
    let out = sdfc(&["mesh", s(&scene), "-o", s(&d.join("g.stl"))]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr).replace(s(&d), "DIR");
    let err: Vec<&str> = err.lines().filter(|l| l.starts_with("error")).collect();
    // The hint: the rod's box (x 3.8 to 4.2, y ±3) and the sphere's, with a tenth of the
    // largest extent (6) around them.
    insta::assert_snapshot!(err.join("\n"), @"error: the scene is unbounded along x, y, z: the field at DIR/gyroid.sdf:2:3 (whose formula proves no bound along x, y, z); give the region to mesh with `--bounds X0,Y0,Z0,X1,Y1,Z1` (what reaches out of it is cut at its faces and the cut closed); its bounded objects with a margin are `--bounds=-1.6,-3.6,-1.6,4.8,3.6,1.6`");
}
