//! Mesh files: binary STL and OBJ (geometry), binary PLY (with a colour per vertex, its
//! material's) and binary glTF, `.glb` (one material per scene material the mesh uses, one
//! primitive each, sharing the vertex positions).
//!
//! Each format is a few dozen lines written here with `std` and `serde_json`: the crates that
//! write them would add dependencies for no less code; the tests read the files back with
//! independent readers (`stl_io`, `tobj`, `ply-rs`, `gltf`).

use super::Mesh;
use crate::image::srgb_encode;
use sdfc_compiler::scene::{Material, Pattern};
use std::io::{self, Write};
use std::path::Path;

/// A mesh file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Binary STL: triangles with facet normals, no shared vertices.
    Stl,
    /// Wavefront OBJ: vertices and faces.
    Obj,
    /// Binary little-endian PLY: vertices with colours, faces.
    Ply,
    /// Binary glTF 2.0.
    Glb,
}

impl Format {
    /// The format of a file name's extension (case-insensitive).
    pub fn of(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "stl" => Some(Format::Stl),
            "obj" => Some(Format::Obj),
            "ply" => Some(Format::Ply),
            "glb" => Some(Format::Glb),
            _ => None,
        }
    }

    /// The bytes of `mesh` in this format; `materials` are the scene's (by id).
    pub fn encode(self, mesh: &Mesh, materials: &[Material]) -> Vec<u8> {
        let mut out = Vec::new();
        // Writing to a vector cannot fail.
        let _ = match self {
            Format::Stl => stl(mesh, &mut out),
            Format::Obj => obj(mesh, &mut out),
            Format::Ply => ply(mesh, materials, &mut out),
            Format::Glb => glb(mesh, materials, &mut out),
        };
        out
    }
}

/// The bytes a mesh file takes at most, for the memory announcement.
pub fn encoded_bytes(vertices: u64, triangles: u64) -> u64 {
    let stl = 84 + 50 * triangles;
    let obj = 64 * vertices + 40 * triangles;
    let ply = 512 + 15 * vertices + 13 * triangles;
    let glb = 4096 + 12 * vertices + 12 * triangles;
    stl.max(obj).max(ply).max(glb)
}

fn f32s(v: [f64; 3]) -> [f32; 3] {
    v.map(|x| x as f32)
}

fn stl(mesh: &Mesh, out: &mut Vec<u8>) -> io::Result<()> {
    let mut header = [b' '; 80];
    let text = b"binary STL written by sdfc mesh";
    header[..text.len()].copy_from_slice(text);
    out.write_all(&header)?;
    out.write_all(&(mesh.triangles.len() as u32).to_le_bytes())?;
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-300);
        for x in f32s(n.map(|x| x / l))
            .iter()
            .chain(&f32s(a))
            .chain(&f32s(b))
            .chain(&f32s(c))
        {
            out.write_all(&x.to_le_bytes())?;
        }
        out.write_all(&[0, 0])?;
    }
    Ok(())
}

fn obj(mesh: &Mesh, out: &mut Vec<u8>) -> io::Result<()> {
    writeln!(out, "# written by sdfc mesh")?;
    for p in &mesh.positions {
        let [x, y, z] = f32s(*p);
        writeln!(out, "v {x} {y} {z}")?;
    }
    for t in &mesh.triangles {
        writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    Ok(())
}

/// The linear colour of a material at a point (a checker by the parity of its cells, as the
/// renderer paints it); unknown ids get the default grey.
pub fn colour(materials: &[Material], id: u32, p: [f64; 3]) -> [f64; 3] {
    match materials.get(id as usize).map(|m| &m.pattern) {
        Some(Pattern::Solid(c)) => *c,
        Some(Pattern::Checker { a, b, size }) => {
            let s: f64 = p.iter().map(|x| (x / size).floor()).sum();
            if s.rem_euclid(2.0) > 0.5 {
                *b
            } else {
                *a
            }
        }
        None => [0.8; 3],
    }
}

/// The one colour glTF gives a material: its colour, or the mean of a checker's two.
fn base_colour(m: &Material) -> [f64; 3] {
    match &m.pattern {
        Pattern::Solid(c) => *c,
        Pattern::Checker { a, b, .. } => [0, 1, 2].map(|i| 0.5 * (a[i] + b[i])),
    }
}

fn ply(mesh: &Mesh, materials: &[Material], out: &mut Vec<u8>) -> io::Result<()> {
    write!(
        out,
        "ply\nformat binary_little_endian 1.0\ncomment written by sdfc mesh; colours are \
         the materials', sRGB\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.positions.len(),
        mesh.triangles.len()
    )?;
    for (i, p) in mesh.positions.iter().enumerate() {
        for x in f32s(*p) {
            out.write_all(&x.to_le_bytes())?;
        }
        let id = mesh.vertex_materials.get(i).copied().unwrap_or(0);
        let c = colour(materials, id, *p);
        out.write_all(&c.map(|x| srgb_encode(x as f32)))?;
    }
    for t in &mesh.triangles {
        out.write_all(&[3])?;
        for i in t {
            out.write_all(&(*i as i32).to_le_bytes())?;
        }
    }
    Ok(())
}

fn glb(mesh: &Mesh, materials: &[Material], out: &mut Vec<u8>) -> io::Result<()> {
    use serde_json::json;
    let mut bin: Vec<u8> = Vec::new();
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in &mesh.positions {
        for (i, x) in f32s(*p).into_iter().enumerate() {
            lo[i] = lo[i].min(x);
            hi[i] = hi[i].max(x);
            bin.extend_from_slice(&x.to_le_bytes());
        }
    }
    let mut views =
        vec![json!({"buffer": 0, "byteOffset": 0, "byteLength": bin.len(), "target": 34962})];
    let mut accessors = vec![json!({
        "bufferView": 0, "componentType": 5126, "count": mesh.positions.len(), "type": "VEC3",
        "min": lo, "max": hi
    })];
    let mut used: Vec<u32> = mesh.materials.clone();
    used.sort_unstable();
    used.dedup();
    let mut primitives = Vec::new();
    let mut mats = Vec::new();
    for (k, &id) in used.iter().enumerate() {
        let start = bin.len();
        let mut count = 0;
        for (t, &m) in mesh.triangles.iter().zip(&mesh.materials) {
            if m == id {
                for i in t {
                    bin.extend_from_slice(&i.to_le_bytes());
                }
                count += 3;
            }
        }
        views.push(json!({"buffer": 0, "byteOffset": start, "byteLength": bin.len() - start, "target": 34963}));
        accessors.push(json!({
            "bufferView": k + 1, "componentType": 5125, "count": count, "type": "SCALAR"
        }));
        primitives.push(
            json!({"attributes": {"POSITION": 0}, "indices": k + 1, "material": k, "mode": 4}),
        );
        let (name, c) = match materials.get(id as usize) {
            Some(m) => (m.name.clone(), base_colour(m)),
            None => (format!("material {id}"), [0.8; 3]),
        };
        mats.push(json!({
            "name": name,
            "pbrMetallicRoughness": {
                "baseColorFactor": [c[0], c[1], c[2], 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.7
            }
        }));
    }
    let doc = json!({
        "asset": {"version": "2.0", "generator": "sdfc mesh"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": primitives}],
        "materials": mats,
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": views,
        "accessors": accessors
    });
    let mut text = doc.to_string().into_bytes();
    while text.len() % 4 != 0 {
        text.push(b' ');
    }
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let total = 12 + 8 + text.len() + 8 + bin.len();
    out.write_all(b"glTF")?;
    out.write_all(&2u32.to_le_bytes())?;
    out.write_all(&(total as u32).to_le_bytes())?;
    out.write_all(&(text.len() as u32).to_le_bytes())?;
    out.write_all(b"JSON")?;
    out.write_all(&text)?;
    out.write_all(&(bin.len() as u32).to_le_bytes())?;
    out.write_all(b"BIN\0")?;
    out.write_all(&bin)?;
    Ok(())
}
