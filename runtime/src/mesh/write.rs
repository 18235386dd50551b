//! Mesh files: binary STL and OBJ (geometry), binary PLY (with a colour per vertex, its
//! material's there) and binary glTF, `.glb` (one material per scene material the mesh uses,
//! one primitive each, sharing the vertex positions). Where a material's colour is a colour
//! field, OBJ's vertices carry their colours too (`v x y z r g b`), and the glTF primitives
//! of such materials a `COLOR_0` per vertex. 3MF packages are `threemf.rs`'s.
//!
//! Each format is a few dozen lines written here with `std` and `serde_json`: the crates that
//! write them would add dependencies for no less code; the tests read the files back with
//! independent readers (`stl_io`, `tobj`, `ply-rs`, `gltf`).

use super::Mesh;
use crate::image::srgb_encode;
use sdfc_compiler::{Colour, Colours, Material, Pattern, Scene, V3};
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
    /// 3MF: a ZIP package of an XML model in millimetres, an object per material
    /// (`threemf.rs`).
    ThreeMf,
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
            "3mf" => Some(Format::ThreeMf),
            _ => None,
        }
    }

    /// Whether a file of this format of `scene` carries materials, so that meshing finds
    /// them: PLY, glTF and 3MF always (colours, objects), OBJ where a material's colour is a
    /// colour field (its vertices' colours), STL never.
    pub fn carries_materials(self, scene: &Scene) -> bool {
        match self {
            Format::Ply | Format::Glb | Format::ThreeMf => true,
            Format::Stl => false,
            Format::Obj => scene.materials.iter().any(|m| {
                m.pattern
                    .colours()
                    .iter()
                    .any(|c| matches!(c, Colour::Field(_)))
            }),
        }
    }

    /// The axis a file of this format has up unless asked otherwise: z for 3MF, whose build
    /// plate is the xy plane; the scene's y for the others (glTF's up is y; STL, OBJ and PLY
    /// say nothing, and slicers reading STL take z: `sdfc mesh --up z`).
    pub fn default_up(self) -> Up {
        match self {
            Format::ThreeMf => Up::Z,
            _ => Up::Y,
        }
    }

    /// The bytes of `mesh` (in the scene's coordinates) in this format with `up` up,
    /// coloured by `palette` (3MF: one object, of the material of its first triangle). `Err`
    /// only for a 3MF package too large for a ZIP without its 64-bit extension.
    pub fn encode(self, mesh: &Mesh, palette: &Palette, up: Up) -> io::Result<Vec<u8>> {
        let mut out = Vec::new();
        match self {
            Format::Stl => out = stl(&up.orient(mesh, palette).0),
            Format::Obj => {
                let (mesh, palette) = up.orient(mesh, palette);
                obj(&mesh, &palette, &mut out)?;
            }
            Format::Ply => {
                let (mesh, palette) = up.orient(mesh, palette);
                ply(&mesh, &palette, &mut out)?;
            }
            Format::Glb => {
                let (mesh, palette) = up.orient(mesh, palette);
                glb(&mesh, &palette, &mut out)?;
            }
            Format::ThreeMf => {
                let m = mesh.materials.first().copied().unwrap_or(0);
                let name = palette
                    .materials
                    .get(m as usize)
                    .map_or("sdfc mesh", |m| &m.name);
                out = super::threemf::one(name, m, mesh, palette, up)?;
            }
        }
        Ok(out)
    }
}

/// Which of a mesh file's axes is up: the scene's y (its up, and glTF's), or z, the normal of
/// a printer's build plate, which slicers read (3MF's convention; `sdfc mesh --up`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Up {
    /// The scene's coordinates as written.
    #[default]
    Y,
    /// The scene turned a quarter turn about x, so that its +y is the file's +z: (x, y, z) is
    /// written (x, −z, y). A rotation, so triangles keep their winding and their outside.
    Z,
}

impl Up {
    /// A point of the scene in the file's axes.
    pub fn place(self, [x, y, z]: [f64; 3]) -> [f64; 3] {
        match self {
            Up::Y => [x, y, z],
            Up::Z => [x, -z, y],
        }
    }

    /// A point of the file in the scene's axes ([`Up::place`] undone).
    pub fn unplace(self, [x, y, z]: [f64; 3]) -> [f64; 3] {
        match self {
            Up::Y => [x, y, z],
            Up::Z => [x, z, -y],
        }
    }

    /// `mesh` and `palette` as a file with this axis up: the positions placed, and the palette
    /// reading each written position's colour at its point of the scene.
    pub fn orient<'m, 'a>(
        self,
        mesh: &'m Mesh,
        palette: &Palette<'a>,
    ) -> (std::borrow::Cow<'m, Mesh>, Palette<'a>) {
        let palette = Palette {
            up: self,
            ..*palette
        };
        if self == Up::Y {
            return (std::borrow::Cow::Borrowed(mesh), palette);
        }
        let mut turned = mesh.clone();
        for p in &mut turned.positions {
            *p = self.place(*p);
        }
        (std::borrow::Cow::Owned(turned), palette)
    }
}

/// What colours a mesh: the scene's materials (by id), their colour fields lowered, where the
/// scene's coordinates start in the programs' ([`Scene::origin`]), and the axes of the
/// positions it is asked about ([`Up::orient`]).
#[derive(Debug, Clone, Copy)]
pub struct Palette<'a> {
    /// The scene's materials.
    pub materials: &'a [Material],
    /// Their colour fields.
    pub colours: &'a Colours,
    /// [`Scene::origin`].
    pub origin: V3,
    /// The axes of the positions [`Palette::colour`] is given: the scene's, or a file's.
    pub up: Up,
}

impl<'a> Palette<'a> {
    /// The palette of `scene`, whose colour fields are `colours` (`Lowered::colours`).
    pub fn new(scene: &'a Scene, colours: &'a Colours) -> Self {
        Palette {
            materials: &scene.materials,
            colours,
            origin: scene.origin,
            up: Up::Y,
        }
    }

    /// Whether material `id`'s colour is or has a colour field.
    pub fn varies(&self, id: u32) -> bool {
        self.materials.get(id as usize).is_some_and(|m| {
            m.pattern
                .colours()
                .iter()
                .any(|c| matches!(c, Colour::Field(_)))
        })
    }

    /// The linear colour of every vertex of `mesh` (in the axes of [`Palette::up`]): of its
    /// material (`fallback` where the mesh names none), at its position, where the surface's
    /// normal is the vertex's ([`vertex_normals`]).
    pub fn vertex_colours(&self, mesh: &Mesh, fallback: u32) -> Vec<[f64; 3]> {
        let normals = vertex_normals(mesh);
        mesh.positions
            .iter()
            .zip(&normals)
            .enumerate()
            .map(|(i, (p, n))| {
                let id = mesh.vertex_materials.get(i).copied().unwrap_or(fallback);
                self.colour(id, *p, *n)
            })
            .collect()
    }

    /// The linear colour of material `id` at `p` where the unit surface normal is `n`, both in
    /// the axes of [`Palette::up`] (a checker by the parity of its cells, a colour field by
    /// its value, as the renderer paints them); unknown ids get the default grey.
    pub fn colour(&self, id: u32, p: [f64; 3], n: [f64; 3]) -> [f64; 3] {
        let Some(m) = self.materials.get(id as usize) else {
            return [0.8; 3];
        };
        let (file_p, file_n) = (p, n);
        let (p, n) = (self.up.unplace(p), self.up.unplace(n));
        let slot = match &m.pattern {
            // A checker of two materials: the colour of the cell's material (the checker
            // refuses such a checker within another; one is grey here).
            Pattern::Materials { a, b, size } => {
                let s: f64 = p.iter().map(|x| (x / size).floor()).sum();
                let id = if s.rem_euclid(2.0) > 0.5 { b.0 } else { a.0 };
                return match self.materials.get(id as usize).map(|m| &m.pattern) {
                    Some(Pattern::Materials { .. }) => [0.8; 3],
                    _ => self.colour(id, file_p, file_n),
                };
            }
            Pattern::Solid(_) => 0,
            Pattern::Checker { size, .. } => {
                let s: f64 = p.iter().map(|x| (x / size).floor()).sum();
                usize::from(s.rem_euclid(2.0) > 0.5)
            }
        };
        match (
            m.pattern.colours()[slot],
            self.colours.fields.get(id as usize),
        ) {
            (Colour::Const(c), _) => *c,
            (Colour::Field(_), Some(&[a, b])) => match [a, b][slot] {
                Some(k) => {
                    let q = [0, 1, 2].map(|i| p[i] - self.origin[i]);
                    self.colours.programs[k].eval(q, n)
                }
                None => [0.8; 3],
            },
            (Colour::Field(_), None) => [0.8; 3],
        }
    }
}

/// The unit normal at each vertex of `mesh`: the sum of its triangles' area vectors (each
/// triangle's `(b − a) × (c − a)`, outwards as the mesh is oriented), normalised; (0, 0, 0)
/// at a vertex of no triangle of area.
pub fn vertex_normals(mesh: &Mesh) -> Vec<[f64; 3]> {
    use glam::DVec3;
    let mut sums = vec![DVec3::ZERO; mesh.positions.len()];
    let at = |i: u32| DVec3::from(mesh.positions[i as usize]);
    for t in &mesh.triangles {
        let (a, b, c) = (at(t[0]), at(t[1]), at(t[2]));
        let area = (b - a).cross(c - a);
        for &i in t {
            sums[i as usize] += area;
        }
    }
    sums.iter()
        .map(|s| s.try_normalize().unwrap_or(DVec3::ZERO).to_array())
        .collect()
}

/// The bytes a mesh file takes at most, for the memory announcement.
pub fn encoded_bytes(vertices: u64, triangles: u64) -> u64 {
    let stl = 84 + 50 * triangles;
    let obj = 96 * vertices + 40 * triangles;
    let ply = 512 + 15 * vertices + 13 * triangles;
    let glb = 4096 + 24 * vertices + 12 * triangles;
    stl.max(obj).max(ply).max(glb)
}

fn f32s(v: [f64; 3]) -> [f32; 3] {
    v.map(|x| x as f32)
}

/// Bytes of one binary STL triangle: its normal, three corners (f32 each) and two bytes.
const STL_TRIANGLE: usize = 50;

/// Binary STL, its triangles encoded in parallel ([`stl_rows`]).
fn stl(mesh: &Mesh) -> Vec<u8> {
    let mut out = vec![0u8; 84 + STL_TRIANGLE * mesh.triangles.len()];
    out[..84].copy_from_slice(&stl_header(mesh.triangles.len()));
    stl_rows(mesh, &mesh.triangles, &mut out[84..]);
    out
}

/// The 84 bytes before a binary STL's triangles: its text and the triangles' count.
fn stl_header(triangles: usize) -> [u8; 84] {
    let mut out = [b' '; 84];
    let text = b"binary STL written by sdfc mesh";
    out[..text.len()].copy_from_slice(text);
    out[80..84].copy_from_slice(&(triangles as u32).to_le_bytes());
    out
}

/// The rows of `triangles` (of `mesh`) in `out`, [`STL_TRIANGLE`] bytes each, encoded in
/// parallel (each at a place known from its index); the attribute bytes zero.
fn stl_rows(mesh: &Mesh, triangles: &[[u32; 3]], out: &mut [u8]) {
    use rayon::prelude::*;
    out.par_chunks_mut(STL_TRIANGLE * 1024)
        .zip(triangles.par_chunks(1024))
        .for_each(|(bytes, triangles)| {
            for (row, t) in bytes.chunks_exact_mut(STL_TRIANGLE).zip(triangles) {
                let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
                let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
                let n = [
                    u[1] * v[2] - u[2] * v[1],
                    u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0],
                ];
                let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-300);
                let values = f32s(n.map(|x| x / l))
                    .into_iter()
                    .chain(f32s(a))
                    .chain(f32s(b))
                    .chain(f32s(c));
                for (to, x) in row.chunks_exact_mut(4).zip(values) {
                    to.copy_from_slice(&x.to_le_bytes());
                }
                row[48..].fill(0);
            }
        });
}

/// Triangles of a binary STL encoded at a time by [`save`] (2.5 MB).
const STL_BLOCK: usize = 1 << 16;

/// Why [`save`] wrote no file.
#[derive(Debug)]
pub enum Unsaved {
    /// The mesh cannot be encoded in the format ([`Format::encode`]'s error).
    Encode(io::Error),
    /// The file cannot be written.
    Write(io::Error),
}

/// Writes `mesh` to `path` in `format` ([`Format::encode`]'s bytes), atomically but not
/// synced to the disk, as a compiler writes its output (`image::AtomicFile::unsynced`: the
/// file is complete or untouched whatever happens to the process, and a mesh is made again
/// by running the command again). A binary STL is encoded a block of triangles at a time
/// into one buffer, never held whole.
pub fn save(
    format: Format,
    mesh: &Mesh,
    palette: &Palette,
    up: Up,
    path: &Path,
) -> Result<(), Unsaved> {
    let encoded = match format {
        Format::Stl => None,
        _ => Some(format.encode(mesh, palette, up).map_err(Unsaved::Encode)?),
    };
    let write = || -> io::Result<()> {
        if let Some(bytes) = &encoded {
            return save_bytes(path, bytes);
        }
        let mut file = crate::image::AtomicFile::unsynced(path)?;
        let mesh = up.orient(mesh, palette).0;
        file.write_all(&stl_header(mesh.triangles.len()))?;
        let mut block = vec![0u8; STL_TRIANGLE * STL_BLOCK.min(mesh.triangles.len())];
        for triangles in mesh.triangles.chunks(STL_BLOCK) {
            let bytes = &mut block[..STL_TRIANGLE * triangles.len()];
            stl_rows(&mesh, triangles, bytes);
            file.write_all(bytes)?;
        }
        file.finish()
    };
    write().map_err(Unsaved::Write)
}

/// A mesh file's bytes written to `path` as [`save`] writes them (atomically, unsynced).
pub fn save_bytes(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut file = crate::image::AtomicFile::unsynced(path)?;
    file.write_all(bytes)?;
    file.finish()
}

fn obj(mesh: &Mesh, palette: &Palette, out: &mut Vec<u8>) -> io::Result<()> {
    writeln!(out, "# written by sdfc mesh")?;
    // Vertex colours (sRGB, 0 to 1) where a material's colour is a field.
    let coloured = mesh.materials.iter().any(|&m| palette.varies(m));
    if coloured {
        writeln!(out, "# vertex colours: v x y z r g b, sRGB from 0 to 1")?;
    }
    let colours = if coloured {
        palette.vertex_colours(mesh, 0)
    } else {
        Vec::new()
    };
    for (i, p) in mesh.positions.iter().enumerate() {
        let [x, y, z] = f32s(*p);
        if let Some(c) = colours.get(i) {
            let [r, g, b] = c.map(|c| f32::from(srgb_encode(c as f32)) / 255.0);
            writeln!(out, "v {x} {y} {z} {r} {g} {b}")?;
        } else {
            writeln!(out, "v {x} {y} {z}")?;
        }
    }
    for t in &mesh.triangles {
        writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    Ok(())
}

/// The one colour glTF gives a material: its colour, or the mean of a checker's two; white
/// for a colour field, whose colours are the vertices' (`COLOR_0`, which glTF multiplies by
/// it).
pub fn base_colour(materials: &[Material], m: &Material) -> [f64; 3] {
    let c = |c: &Colour| c.constant().unwrap_or([1.0; 3]);
    match &m.pattern {
        // A checker of two materials: the mean of theirs (one that is such a checker
        // itself, which the checker refuses, is grey).
        Pattern::Materials { a, b, .. } => {
            let one = |id: &sdfc_compiler::MaterialId| match materials.get(id.0 as usize) {
                Some(m) if !matches!(m.pattern, Pattern::Materials { .. }) => {
                    base_colour(materials, m)
                }
                _ => [0.8; 3],
            };
            let (a, b) = (one(a), one(b));
            [0, 1, 2].map(|i| 0.5 * (a[i] + b[i]))
        }
        Pattern::Solid(a) => c(a),
        Pattern::Checker { a, b, .. } => {
            let (a, b) = (c(a), c(b));
            [0, 1, 2].map(|i| 0.5 * (a[i] + b[i]))
        }
    }
}

fn ply(mesh: &Mesh, palette: &Palette, out: &mut Vec<u8>) -> io::Result<()> {
    write!(
        out,
        "ply\nformat binary_little_endian 1.0\ncomment written by sdfc mesh; colours are \
         the materials', sRGB\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.positions.len(),
        mesh.triangles.len()
    )?;
    let colours = palette.vertex_colours(mesh, 0);
    for (p, c) in mesh.positions.iter().zip(&colours) {
        for x in f32s(*p) {
            out.write_all(&x.to_le_bytes())?;
        }
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

fn glb(mesh: &Mesh, palette: &Palette, out: &mut Vec<u8>) -> io::Result<()> {
    let materials = palette.materials;
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
    // The linear colour of every vertex, where a material the mesh uses is a colour field.
    let colours = used.iter().any(|&m| palette.varies(m)).then(|| {
        let start = bin.len();
        for c in palette.vertex_colours(mesh, 0) {
            for x in c {
                bin.extend_from_slice(&(x as f32).to_le_bytes());
            }
        }
        views.push(json!({"buffer": 0, "byteOffset": start, "byteLength": bin.len() - start, "target": 34962}));
        accessors.push(json!({
            "bufferView": views.len() - 1, "componentType": 5126, "count": mesh.positions.len(), "type": "VEC3"
        }));
        accessors.len() - 1
    });
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
            "bufferView": views.len() - 1, "componentType": 5125, "count": count, "type": "SCALAR"
        }));
        let attributes = match colours {
            Some(c) if palette.varies(id) => json!({"POSITION": 0, "COLOR_0": c}),
            _ => json!({"POSITION": 0}),
        };
        primitives.push(json!({
            "attributes": attributes, "indices": accessors.len() - 1, "material": k, "mode": 4
        }));
        let (name, c) = match materials.get(id as usize) {
            Some(m) => (m.name.clone(), base_colour(materials, m)),
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
