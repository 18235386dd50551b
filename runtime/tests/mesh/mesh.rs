//! `sdfc mesh` (issue 18): every example's bounded part meshes to a closed, consistently
//! oriented 2-manifold by vertex positions as an STL reader sees them, with the Euler
//! characteristic its genus requires; the four formats are read back by independent readers
//! (`stl_io`, `tobj`, `ply-rs-bw`, `gltf`). How close the mesh lies to the surface is
//! `mesh_surface`'s, the command's failure paths `mesh_failures`'s.

use crate::common::assert_has;
use crate::meshes;
use meshes::*;
use sdfc_compiler::{eval_point, Program};
use std::path::{Path, PathBuf};

pub(crate) fn read_obj(path: &Path) -> Read {
    let (models, _) = tobj::load_obj(
        path,
        &tobj::LoadOptions {
            single_index: true,
            ..Default::default()
        },
    )
    .expect("tobj reads it");
    assert_eq!(models.len(), 1);
    let m = &models[0].mesh;
    Read {
        positions: m.positions.chunks(3).map(|c| [c[0], c[1], c[2]]).collect(),
        triangles: m
            .indices
            .chunks(3)
            .map(|c| [c[0] as usize, c[1] as usize, c[2] as usize])
            .collect(),
    }
}

/// The PLY's mesh and each vertex's colour.
fn read_ply(path: &Path) -> (Read, Vec<[u8; 3]>) {
    use ply_rs_bw::parser::Parser;
    use ply_rs_bw::ply::{DefaultElement, Property};
    let mut f = std::fs::File::open(path).expect("open ply");
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut f)
        .expect("ply-rs reads it");
    let float = |p: &Property| match p {
        Property::Float(x) => *x,
        other => panic!("expected a float, got {other:?}"),
    };
    let byte = |p: &Property| match p {
        Property::UChar(x) => *x,
        other => panic!("expected a byte, got {other:?}"),
    };
    let mut r = Read::default();
    let mut colours = Vec::new();
    for v in &ply.payload["vertex"] {
        r.positions
            .push([float(&v["x"]), float(&v["y"]), float(&v["z"])]);
        colours.push([byte(&v["red"]), byte(&v["green"]), byte(&v["blue"])]);
    }
    for f in &ply.payload["face"] {
        match &f["vertex_indices"] {
            Property::ListInt(i) if i.len() == 3 => {
                r.triangles
                    .push([i[0] as usize, i[1] as usize, i[2] as usize])
            }
            other => panic!("expected three indices, got {other:?}"),
        }
    }
    (r, colours)
}

/// The glTF's mesh and its materials' names, one per primitive.
fn read_glb(path: &Path) -> (Read, Vec<String>) {
    let bytes = std::fs::read(path).expect("read glb");
    let gltf = gltf::Gltf::from_slice(&bytes).expect("gltf reads it");
    let blob = gltf.blob.clone();
    let mut r = Read::default();
    let mut names = Vec::new();
    let meshes: Vec<_> = gltf.meshes().collect();
    assert_eq!(meshes.len(), 1);
    for p in meshes[0].primitives() {
        let reader = p.reader(|_| blob.as_deref());
        let positions: Vec<[f32; 3]> = reader.read_positions().expect("positions").collect();
        if r.positions.is_empty() {
            r.positions = positions;
        } else {
            assert_eq!(r.positions, positions, "primitives share the positions");
        }
        let idx: Vec<u32> = reader.read_indices().expect("indices").into_u32().collect();
        r.triangles.extend(
            idx.chunks(3)
                .map(|c| [c[0] as usize, c[1] as usize, c[2] as usize]),
        );
        names.push(p.material().name().unwrap_or("").to_string());
    }
    (r, names)
}

/// The distance from `p` to triangle `t` (exact, by regions).
fn point_triangle(p: [f64; 3], t: [[f64; 3]; 3]) -> f64 {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let seg = |p: [f64; 3], a: [f64; 3], b: [f64; 3]| {
        let ab = sub(b, a);
        let t = (dot(sub(p, a), ab) / dot(ab, ab).max(1e-300)).clamp(0.0, 1.0);
        let q = [0, 1, 2].map(|i| a[i] + t * ab[i]);
        dot(sub(p, q), sub(p, q)).sqrt()
    };
    let (a, b, c) = (t[0], t[1], t[2]);
    let (u, v) = (sub(b, a), sub(c, a));
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let nn = dot(n, n);
    if nn > 0.0 {
        let h = dot(sub(p, a), n) / nn;
        let q = [0, 1, 2].map(|i| p[i] - h * n[i]);
        // Barycentric test of the projection.
        let (w0, w1) = (sub(q, a), [0.0; 3]);
        let _ = w1;
        let d00 = dot(u, u);
        let d01 = dot(u, v);
        let d11 = dot(v, v);
        let d20 = dot(w0, u);
        let d21 = dot(w0, v);
        let den = d00 * d11 - d01 * d01;
        let bv = (d11 * d20 - d01 * d21) / den;
        let bw = (d00 * d21 - d01 * d20) / den;
        if bv >= 0.0 && bw >= 0.0 && bv + bw <= 1.0 {
            return (h * h * nn).sqrt();
        }
    }
    seg(p, a, b).min(seg(p, b, c)).min(seg(p, c, a))
}

/// The distance from `p` to the nearest triangle of `m`.
pub(crate) fn to_mesh(m: &Read, p: [f64; 3]) -> f64 {
    m.triangles
        .iter()
        .map(|t| t.map(|i| m.positions[i].map(f64::from)))
        .filter(|t| {
            // Skip triangles far from p cheaply (their box is farther than the best so far
            // would need; 0.5 is far beyond any distance these tests accept).
            (0..3).all(|i| {
                let lo = t.iter().map(|v| v[i]).fold(f64::INFINITY, f64::min);
                let hi = t.iter().map(|v| v[i]).fold(f64::NEG_INFINITY, f64::max);
                p[i] > lo - 0.5 && p[i] < hi + 0.5
            })
        })
        .map(|t| point_triangle(p, t))
        .fold(f64::INFINITY, f64::min)
}

/// The scene of the benchmark, read back in all four formats, one surface each time: a
/// sphere and a torus that pass through each other (genus 1), a box and a thin plate (genus
/// 0 each), so χ = 0 + 2 + 2 = 4. The plate is 0.05 thick: 1.6 cells at resolution 64, 0.8
/// at 32, where some columns of grid points miss it and holes open in it (the mesh is still
/// closed and manifold, of another genus).
#[test]
fn the_parts_scene_is_a_closed_manifold_in_every_format() {
    let d = dir("parts");
    let scene = root().join("examples/mesh/parts.sdf");
    for res in ["32", "64", "96"] {
        let mut counts = Vec::new();
        for ext in ["stl", "obj", "ply", "glb"] {
            let out = d.join(format!("parts{res}.{ext}"));
            mesh(&[
                s(&scene),
                "-o",
                s(&out),
                "--bounds=-1,-1,-1,1,1,1",
                "--resolution",
                res,
            ]);
            let (m, what) = match ext {
                "stl" => (read_stl(&out), "stl"),
                "obj" => (read_obj(&out), "obj"),
                "ply" => (read_ply(&out).0, "ply"),
                _ => (read_glb(&out).0, "glb"),
            };
            let chi = manifold(&m, &format!("parts at {res}, {what}"));
            if res != "32" {
                assert_eq!(chi, 4, "parts at {res}, {what}: Euler characteristic");
            }
            counts.push(m.triangles.len());
        }
        assert!(counts.iter().all(|&c| c == counts[0]), "{counts:?}");
        if res == "64" {
            // The union of exact fields is exact outside and a lower bound inside, so the mesh
            // points' check is exact outside; the surface points are projected exactly.
            let m = read_stl(&d.join("parts64.stl"));
            hausdorff(&m, &program(&scene), 2.0 / 64.0, [0.0; 3], 0.9);
        }
    }
}

/// glTF gets one material per scene material the mesh uses, PLY the materials' colours.
#[test]
fn materials_reach_gltf_and_ply() {
    let d = dir("materials");
    let scene = root().join("examples/mesh/parts.sdf");
    let glb = d.join("parts.glb");
    mesh(&[s(&scene), "-o", s(&glb), "--resolution", "32"]);
    let (_, mut names) = read_glb(&glb);
    names.sort();
    assert_eq!(names, ["clay", "slate", "steel", "teal"]);
    let ply = d.join("parts.ply");
    mesh(&[s(&scene), "-o", s(&ply), "--resolution", "32"]);
    let (m, colours) = read_ply(&ply);
    // Vertices on the sphere, far from the torus, are clay: (0.85, 0.45, 0.25) in sRGB bytes.
    let clay = [0.85f32, 0.45, 0.25].map(sdfc_runtime::image::srgb_encode);
    let mut seen = 0;
    for (p, c) in m.positions.iter().zip(&colours) {
        let q = [p[0] + 0.5, p[1], p[2]];
        let r = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
        if (r - 0.5).abs() < 0.01 && p[1] < 0.0 && p[0] < -0.6 {
            assert_eq!(*c, clay, "vertex {p:?}");
            seen += 1;
        }
    }
    assert!(seen > 50, "{seen} sphere vertices");
}

/// The bracket: one surface with a bore and two bolt holes through it (genus 3, χ = −4).
#[test]
fn the_bracket_has_genus_three() {
    let d = dir("bracket");
    let scene = root().join("examples/mesh/bracket.sdf");
    for res in ["48", "96"] {
        let out = d.join(format!("bracket{res}.stl"));
        mesh(&[s(&scene), "-o", s(&out), "--resolution", res]);
        assert_eq!(manifold(&read_stl(&out), "bracket"), -4, "at {res}");
    }
}

/// A bar of length 2π·R wrapped around radius R (`wrap`) closes into a ring: one closed
/// manifold of genus one (χ = 0), with no seam where the bar's ends meet.
#[test]
fn a_wrapped_bar_meshes_to_a_ring_of_genus_one() {
    let body = "scene { wrap(box((4.71238898038469, 0.2, 0.25)), 1.5); }\n";
    let (_, scene, out) = scene_in("wrap", "ring.sdf", body, "ring.stl");
    mesh(&[s(&scene), "-o", s(&out), "--resolution", "64"]);
    assert_eq!(manifold(&read_stl(&out), "wrapped bar"), 0);
}

/// Every example: the objects of finite extent (with the floor cut to a box around them, or
/// a fixed box where nothing is finite) mesh to a closed manifold with an even Euler
/// characteristic, as a closed orientable surface has.
#[test]
fn every_examples_bounded_part_meshes_to_a_closed_manifold() {
    let d = dir("examples");
    let mut files: Vec<PathBuf> = Vec::new();
    for sub in ["examples", "examples/mesh", "examples/animation"] {
        for e in std::fs::read_dir(root().join(sub)).expect("examples") {
            let p = e.expect("entry").path();
            if p.extension().is_some_and(|x| x == "sdf") {
                files.push(p);
            }
        }
    }
    files.sort();
    assert!(files.len() >= 15, "{files:?}");
    for f in &files {
        let out = d.join("ex.stl");
        let first = sdfc(&["mesh", s(f), "-o", s(&out), "--resolution", "40"]);
        let err = String::from_utf8_lossy(&first.stderr).into_owned();
        if !first.status.success() {
            assert!(
                err.contains("--bounds X0,Y0,Z0,X1,Y1,Z1"),
                "{}: {err}",
                f.display()
            );
            let bounds = err
                .split('`')
                .find(|w| w.starts_with("--bounds="))
                .unwrap_or("--bounds=-4,-1,-4,4,2,4")
                .to_string();
            mesh(&[s(f), "-o", s(&out), "--resolution", "40", &bounds]);
        }
        let chi = manifold(&read_stl(&out), &f.display().to_string());
        assert_eq!(chi % 2, 0, "{}: χ = {chi}", f.display());
    }
}

/// Checks both ways of the Hausdorff distance to half a voxel: points of the mesh (vertices,
/// edge midpoints, centroids) are within it of the surface (the field is exact), and points
/// of the surface (found by projecting points around `centre` onto it) are within it of the
/// mesh.
pub(crate) fn hausdorff(m: &Read, p: &Program, voxel: f64, centre: [f64; 3], radius: f64) {
    let mut far = 0.0f64;
    for t in &m.triangles {
        let v = t.map(|i| m.positions[i].map(f64::from));
        let pts = [
            [0, 1, 2].map(|i| (v[0][i] + v[1][i] + v[2][i]) / 3.0),
            [0, 1, 2].map(|i| (v[0][i] + v[1][i]) / 2.0),
        ];
        for q in pts {
            far = far.max(eval_point::<f64>(p, q).0.abs());
        }
    }
    assert!(far <= 0.5 * voxel, "a mesh point is {far} from the surface");
    let mut rng = sdfc_compiler::Rng::new(7);
    let mut back = 0.0f64;
    for _ in 0..150 {
        let mut q = [0, 1, 2].map(|i| centre[i] + radius * 1.5 * (2.0 * rng.uniform() - 1.0));
        for _ in 0..20 {
            let h = 1e-6;
            let f = eval_point::<f64>(p, q).0;
            let g = [0, 1, 2].map(|i| {
                let mut a = q;
                a[i] += h;
                (eval_point::<f64>(p, a).0 - f) / h
            });
            let gg: f64 = g.iter().map(|x| x * x).sum();
            q = [0, 1, 2].map(|i| q[i] - f * g[i] / gg.max(1e-12));
        }
        if eval_point::<f64>(p, q).0.abs() < 1e-9 {
            back = back.max(to_mesh(m, q));
        }
    }
    assert!(
        back <= 0.5 * voxel,
        "a surface point is {back} from the mesh"
    );
}

/// A field with no proven bound (the Mandelbulb) is meshed on the dense grid, with a warning
/// naming the node, and still closed.
#[test]
fn an_unproven_field_falls_back_to_the_dense_grid() {
    let body = "scene { mandelbulb(8, 6); }\n";
    let (_, scene, out) = scene_in("fractal", "bulb.sdf", body, "bulb.stl");
    let err = mesh(&[s(&scene), "-o", s(&out), "--resolution", "32", "--stats"]);
    assert_has(&err, &["no proven bound (the mandelbulb at", "dense grid"]);
    let chi = manifold(&read_stl(&out), "mandelbulb");
    assert_eq!(chi % 2, 0);
}

/// Faces lying on grid planes (the grid placed so, through --bounds): the corners' signs there
/// are decided by rounding, and the mesh is still a closed manifold.
#[test]
fn faces_on_grid_planes_still_give_a_closed_manifold() {
    let d = dir("aligned");
    let body = "scene { box(0.5); sphere(0.3).translate(0.5, 0.5, 0); }\n";
    let scene = write_scene(&d, "cube.sdf", body);
    // The grid starts 1.381966… cells below the bounds: here at -0.7, so that the planes
    // x, y, z = ±0.5 hold grid points.
    let lo = -0.7 + 1.381_966_011_250_105 * 0.1;
    let bounds = format!("--bounds={lo},{lo},{lo},0.9,0.9,0.9");
    let out = d.join("cube.stl");
    mesh(&[s(&scene), "-o", s(&out), "--voxel", "0.1", &bounds]);
    assert_eq!(manifold(&read_stl(&out), "aligned cube"), 2);
}

/// A colour field reaches the vertices: a gradient by height on a sphere, read back from
/// PLY (sRGB bytes), from glTF's `COLOR_0` (linear) and from OBJ's `v x y z r g b` (sRGB
/// from 0 to 1), each vertex's colour the field's at the vertex.
#[test]
fn vertex_colours_follow_a_colour_field() {
    let d = dir("colour-field");
    let body =
        "material g = phong { color: field { vec3(0.5 + 0.5 * p.y, 0.25, 0.5 - 0.5 * p.y) } };\n\
         scene { sphere(1) @ g; }\n";
    let scene = write_scene(&d, "gradient.sdf", body);
    // The field's colour at a vertex, linear.
    let field = |p: [f32; 3]| {
        let y = f64::from(p[1]);
        [0.5 + 0.5 * y, 0.25, (0.5 - 0.5 * y).max(0.0)]
    };
    let ply = d.join("g.ply");
    mesh(&[s(&scene), "-o", s(&ply), "--resolution", "16"]);
    let (m, colours) = read_ply(&ply);
    assert!(m.positions.len() > 100);
    for (p, c) in m.positions.iter().zip(&colours) {
        let want = field(*p).map(|x| sdfc_runtime::image::srgb_encode(x as f32));
        for k in 0..3 {
            assert!(
                (i32::from(c[k]) - i32::from(want[k])).abs() <= 1,
                "vertex {p:?}: {c:?}, the field gives {want:?}"
            );
        }
    }
    let glb = d.join("g.glb");
    mesh(&[s(&scene), "-o", s(&glb), "--resolution", "16"]);
    let (positions, colours, base) = glb_colours(&glb);
    assert_eq!(positions.len(), colours.len());
    for (p, c) in positions.iter().zip(&colours) {
        let want = field(*p);
        for k in 0..3 {
            assert!(
                (f64::from(c[k]) - want[k]).abs() < 1e-5,
                "{p:?}: {c:?} {want:?}"
            );
        }
    }
    assert_eq!(base, [1.0; 4], "the vertex colours are the colour");
    let obj = d.join("g.obj");
    mesh(&[s(&scene), "-o", s(&obj), "--resolution", "16"]);
    let (models, _) = tobj::load_obj(
        &obj,
        &tobj::LoadOptions {
            single_index: true,
            ..Default::default()
        },
    )
    .expect("tobj reads it");
    let m = &models[0].mesh;
    assert_eq!(m.vertex_color.len(), m.positions.len());
    for (p, c) in m.positions.chunks(3).zip(m.vertex_color.chunks(3)) {
        let want = field([p[0], p[1], p[2]]);
        for k in 0..3 {
            let byte = f32::from(sdfc_runtime::image::srgb_encode(want[k] as f32)) / 255.0;
            assert!((c[k] - byte).abs() < 1e-4, "{p:?}: {c:?}");
        }
    }
}

/// Every printable ASCII glyph of the shipped font, extruded (`text`, six lines of them),
/// meshes to a closed manifold with an even Euler characteristic, coarsely (a voxel of 0.07
/// em; the strokes are about 0.09 em wide) so that it stays quick.
#[test]
fn every_printable_ascii_glyph_meshes_closed() {
    let d = dir("text");
    let chars: Vec<char> = ('!'..='~').collect();
    let lines: Vec<String> = chars
        .chunks(16)
        .map(|l| {
            l.iter()
                .map(|c| match c {
                    '"' => "\\\"".to_string(),
                    '\\' => "\\\\".to_string(),
                    c => c.to_string(),
                })
                .collect::<Vec<_>>()
                .join(" ")
        })
        .collect();
    let body = format!(
        "scene {{ extrude(text(\"{}\", 1), 0.3); }}\n",
        lines.join("\\n")
    );
    let scene = write_scene(&d, "ascii.sdf", &body);
    let out = d.join("ascii.stl");
    mesh(&[s(&scene), "-o", s(&out), "--voxel", "0.07"]);
    let m = read_stl(&out);
    let chi = manifold(&m, "ASCII glyphs");
    assert_eq!(chi % 2, 0, "χ = {chi}");
    assert!(
        m.triangles.len() > 10_000,
        "{} triangles",
        m.triangles.len()
    );
}
