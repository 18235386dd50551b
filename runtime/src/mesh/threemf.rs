//! 3MF packages (3MF Consortium, Core Specification 1.3 and Materials and Properties
//! Extension 1.2): a ZIP (`zip.rs`) of `[Content_Types].xml`, `_rels/.rels` and
//! `3D/3dmodel.model`, the model in millimetres with one object per mesh given, each coloured
//! by its material (a `basematerials` entry with its display colour) and its triangles of
//! other materials by theirs; where a material's colour is a colour field, the triangles of
//! that material take a colour per vertex from a `m:colorgroup`.
//!
//! The model's text is written object by object into its compressed entry ([`Model`]), so
//! that a caller can drop each mesh once it is written.

use super::write::{base_colour, Palette, Up};
use super::zip::{self, Deflated, Entry};
use super::Mesh;
use crate::image::srgb_encode;
use std::io::{self, BufWriter, Write};

const CONTENT_TYPES: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">
 <Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>
 <Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>
</Types>
"#;

const RELS: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">
 <Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>
</Relationships>
"#;

/// The id of the one `basematerials` group; objects and colour groups follow it.
const BASE: u32 = 1;

/// A 3MF model being written: its `basematerials`, then its objects one at a time.
#[derive(Debug)]
pub struct Model {
    /// The model's text, buffered in blocks on its way to the compressor (a write of a few
    /// bytes per number straight into it is slow).
    text: BufWriter<Deflated>,
    /// The `basematerials` entries: the scene's materials.
    count: u32,
    /// The object ids written, for the build.
    objects: Vec<u32>,
    next: u32,
}

/// `text` with XML's five special characters escaped.
fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

/// The `basematerials` index of scene material `id` of `count` (0, the default material, for
/// an id beyond them).
fn index(count: u32, id: u32) -> u32 {
    if id < count {
        id
    } else {
        0
    }
}

/// `#RRGGBB` of a linear colour, sRGB-encoded.
fn hex(c: [f64; 3]) -> String {
    let [r, g, b] = c.map(|x| srgb_encode(x as f32));
    format!("#{r:02X}{g:02X}{b:02X}")
}

impl Model {
    /// A model whose `basematerials` are the scene's materials, in their order (entry `i` is
    /// material id `i`): the header and the `basematerials` are written. Where a material is
    /// a colour field, the Materials extension is declared required (its colour groups).
    pub fn new(palette: &Palette) -> io::Result<Model> {
        let mut text = BufWriter::with_capacity(1 << 18, Deflated::default());
        let count = palette.materials.len().max(1) as u32;
        let required = if (0..count).any(|m| palette.varies(m)) {
            r#" requiredextensions="m""#
        } else {
            ""
        };
        write!(
            text,
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model unit=\"millimeter\" xml:lang=\"en-US\" \
             xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\" \
             xmlns:m=\"http://schemas.microsoft.com/3dmanufacturing/material/2015/02\"{required}>\n \
             <metadata name=\"Application\">sdfc mesh</metadata>\n <resources>\n  \
             <basematerials id=\"{BASE}\">\n"
        )?;
        for id in 0..count {
            let (name, colour) = match palette.materials.get(id as usize) {
                Some(m) => (m.name.clone(), base_colour(palette.materials, m)),
                None => (format!("material {id}"), [0.8; 3]),
            };
            writeln!(
                text,
                "   <base name=\"{}\" displaycolor=\"{}\"/>",
                escape(&name),
                hex(colour)
            )?;
        }
        writeln!(text, "  </basematerials>")?;
        Ok(Model {
            text,
            count,
            objects: Vec::new(),
            next: BASE + 1,
        })
    }

    /// Writes `mesh` (in the scene's coordinates) as an object named `name` of material
    /// `material` (its triangles of other materials keep theirs, from `mesh.materials`), with
    /// `up` up.
    pub fn object(
        &mut self,
        name: &str,
        material: u32,
        mesh: &Mesh,
        palette: &Palette,
        up: Up,
    ) -> io::Result<()> {
        let (mesh, palette) = up.orient(mesh, palette);
        let (mesh, palette) = (&*mesh, &palette);
        let varies = |m: u32| palette.varies(m);
        // A colour per vertex, where a triangle's material is a colour field.
        let group = mesh.materials.iter().any(|&m| varies(m)).then(|| {
            let id = self.next;
            self.next += 1;
            id
        });
        let (t, materials) = (&mut self.text, self.count);
        if let Some(g) = group {
            writeln!(t, "  <m:colorgroup id=\"{g}\">")?;
            for c in palette.vertex_colours(mesh, material) {
                writeln!(t, "   <m:color color=\"{}\"/>", hex(c))?;
            }
            writeln!(t, "  </m:colorgroup>")?;
        }
        let id = self.next;
        self.next += 1;
        let own = index(materials, material);
        writeln!(
            t,
            "  <object id=\"{id}\" type=\"model\" name=\"{}\" pid=\"{BASE}\" pindex=\"{own}\">\n   <mesh>\n    <vertices>",
            escape(name)
        )?;
        for p in &mesh.positions {
            let [x, y, z] = p.map(|c| c as f32);
            writeln!(t, "     <vertex x=\"{x}\" y=\"{y}\" z=\"{z}\"/>")?;
        }
        writeln!(t, "    </vertices>\n    <triangles>")?;
        for (k, [a, b, c]) in mesh.triangles.iter().enumerate() {
            let m = mesh.materials.get(k).copied().unwrap_or(material);
            write!(t, "     <triangle v1=\"{a}\" v2=\"{b}\" v3=\"{c}\"")?;
            match group {
                Some(g) if varies(m) => write!(t, " pid=\"{g}\" p1=\"{a}\" p2=\"{b}\" p3=\"{c}\"")?,
                _ if m != material => write!(t, " pid=\"{BASE}\" p1=\"{}\"", index(materials, m))?,
                _ => {}
            }
            writeln!(t, "/>")?;
        }
        writeln!(t, "    </triangles>\n   </mesh>\n  </object>")?;
        self.objects.push(id);
        Ok(())
    }

    /// The package's bytes: the build (every object, in order), then the archive.
    pub fn finish(mut self) -> io::Result<Vec<u8>> {
        let t = &mut self.text;
        writeln!(t, " </resources>\n <build>")?;
        for id in &self.objects {
            writeln!(t, "  <item objectid=\"{id}\"/>")?;
        }
        writeln!(t, " </build>\n</model>")?;
        zip::archive(&[
            Entry::stored("[Content_Types].xml", CONTENT_TYPES.as_bytes()),
            Entry::stored("_rels/.rels", RELS.as_bytes()),
            self.text
                .into_inner()
                .map_err(|e| e.into_error())?
                .finish("3D/3dmodel.model")?,
        ])
    }
}

/// `mesh` as a 3MF package of one object, named `name`, of material `material`, with `up` up.
pub fn one(
    name: &str,
    material: u32,
    mesh: &Mesh,
    palette: &Palette,
    up: Up,
) -> io::Result<Vec<u8>> {
    let mut model = Model::new(palette)?;
    model.object(name, material, mesh, palette, up)?;
    model.finish()
}
