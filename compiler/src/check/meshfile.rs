//! Readers of triangle mesh files for `mesh(path)`: STL (binary and ASCII), OBJ, PLY (ASCII
//! and binary, either byte order) and binary glTF (`.glb`), each a few dozen lines over the
//! bytes the checker's `Loader` read, since the compiler does no IO. Every reader checks a
//! count it is told against the bytes that are there, and against the `triangles` limit,
//! before it allocates for it, so a file declaring 10⁸ triangles in a few bytes is an error,
//! not an allocation; every error says where in the file it is (a byte offset or a line).
//! The formats `sdfc mesh` writes (runtime/src/mesh/write.rs) read back to the same
//! triangles.

use std::collections::HashMap;

/// A mesh as read: positions and triangles (indices into them, counter-clockwise seen from
/// outside, as each format specifies).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Read {
    pub positions: Vec<[f64; 3]>,
    pub faces: Vec<[u32; 3]>,
}

/// The formats, by the file's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Stl,
    Obj,
    Ply,
    Glb,
}

impl Format {
    /// The format of a path's extension (case-insensitive).
    pub fn of(path: &str) -> Option<Format> {
        let ext = path.rsplit_once('.')?.1.to_ascii_lowercase();
        Some(match ext.as_str() {
            "stl" => Format::Stl,
            "obj" => Format::Obj,
            "ply" => Format::Ply,
            "glb" => Format::Glb,
            _ => return None,
        })
    }
}

/// Reads `bytes` in `format`, with at most `max` triangles.
pub fn read(format: Format, bytes: &[u8], max: u64) -> Result<Read, String> {
    let read = match format {
        Format::Stl => stl(bytes, max),
        Format::Obj => obj(bytes, max),
        Format::Ply => ply(bytes, max),
        Format::Glb => glb(bytes, max),
    }?;
    if read.faces.is_empty() {
        return Err("the file has no triangles".into());
    }
    Ok(read)
}

fn over(count: u64, max: u64) -> String {
    format!("the file has {count} triangles, more than the `triangles` limit of {max}")
}

fn f32_at(b: &[u8], at: usize) -> f64 {
    let mut w = [0u8; 4];
    w.copy_from_slice(&b[at..at + 4]);
    f64::from(f32::from_le_bytes(w))
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    let mut w = [0u8; 4];
    w.copy_from_slice(&b[at..at + 4]);
    u32::from_le_bytes(w)
}

/// Positions welded by their bits, for the formats that repeat corners per triangle.
#[derive(Default)]
struct Weld {
    read: Read,
    index: HashMap<[u64; 3], u32>,
}

impl Weld {
    fn vertex(&mut self, p: [f64; 3]) -> u32 {
        let read = &mut self.read;
        *self.index.entry(p.map(f64::to_bits)).or_insert_with(|| {
            read.positions.push(p);
            read.positions.len() as u32 - 1
        })
    }
}

/// STL: ASCII when it starts with `solid` and its size is not that of the binary form its
/// count declares, else binary (80-byte header, a count, 50 bytes a triangle).
fn stl(b: &[u8], max: u64) -> Result<Read, String> {
    let declared = (b.len() >= 84).then(|| u64::from(u32_at(b, 80)));
    let binary_size = declared.map(|n| 84 + 50 * n);
    if b.starts_with(b"solid") && binary_size != Some(b.len() as u64) {
        return stl_ascii(b, max);
    }
    let (Some(n), Some(size)) = (declared, binary_size) else {
        return Err(format!(
            "a binary STL file has at least 84 bytes (a header and a count); this one has {}",
            b.len()
        ));
    };
    if n > max {
        return Err(format!("at byte 80: {}", over(n, max)));
    }
    if size != b.len() as u64 {
        return Err(format!(
            "truncated binary STL: it declares {n} triangles at byte 80, which take {size} bytes, \
             but the file has {}",
            b.len()
        ));
    }
    let mut weld = Weld::default();
    for t in 0..n as usize {
        let at = 84 + 50 * t + 12;
        let mut face = [0u32; 3];
        for (k, v) in face.iter_mut().enumerate() {
            let p = [0, 1, 2].map(|i| f32_at(b, at + 12 * k + 4 * i));
            *v = weld.vertex(p);
        }
        weld.read.faces.push(face);
    }
    Ok(weld.read)
}

fn stl_ascii(b: &[u8], max: u64) -> Result<Read, String> {
    let text = std::str::from_utf8(b).map_err(|e| {
        format!(
            "an ASCII STL file must be text; byte {} is not UTF-8",
            e.valid_up_to()
        )
    })?;
    let mut weld = Weld::default();
    let mut corners: Vec<u32> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() != Some("vertex") {
            continue;
        }
        let p = numbers(&mut words, n + 1)?;
        corners.push(weld.vertex(p));
        if corners.len() % 3 == 0 {
            if (corners.len() / 3) as u64 > max {
                return Err(over(corners.len() as u64 / 3, max));
            }
            let c = &corners[corners.len() - 3..];
            weld.read.faces.push([c[0], c[1], c[2]]);
        }
    }
    if corners.len() % 3 != 0 {
        return Err(format!(
            "truncated ASCII STL: {} `vertex` lines, not a multiple of 3",
            corners.len()
        ));
    }
    Ok(weld.read)
}

/// Three numbers from `words`, on line `line`.
fn numbers<'a>(words: &mut impl Iterator<Item = &'a str>, line: usize) -> Result<[f64; 3], String> {
    let mut p = [0.0; 3];
    for x in &mut p {
        let w = words
            .next()
            .ok_or_else(|| format!("line {line}: a vertex needs three coordinates"))?;
        *x = w
            .parse()
            .map_err(|_| format!("line {line}: `{w}` is not a number"))?;
    }
    Ok(p)
}

/// OBJ: `v x y z` vertices and `f` faces of three or more corners (`i`, `i/t`, `i/t/n` or
/// `i//n`, 1-based or negative, relative to the end), fanned into triangles.
fn obj(b: &[u8], max: u64) -> Result<Read, String> {
    let text = std::str::from_utf8(b).map_err(|e| {
        format!(
            "an OBJ file must be text; byte {} is not UTF-8",
            e.valid_up_to()
        )
    })?;
    let mut read = Read::default();
    for (n, line) in text.lines().enumerate() {
        let line_no = n + 1;
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => read.positions.push(numbers(&mut words, line_no)?),
            Some("f") => {
                let mut corners = Vec::new();
                for w in words {
                    let first = w.split('/').next().unwrap_or("");
                    let i: i64 = first
                        .parse()
                        .map_err(|_| format!("line {line_no}: `{w}` is not a vertex index"))?;
                    let count = read.positions.len() as i64;
                    let index = if i < 0 { count + i } else { i - 1 };
                    if index < 0 || index >= count {
                        return Err(format!(
                            "line {line_no}: vertex {i} does not exist ({count} vertices so far)"
                        ));
                    }
                    corners.push(index as u32);
                }
                if corners.len() < 3 {
                    return Err(format!("line {line_no}: a face needs three corners"));
                }
                for k in 1..corners.len() - 1 {
                    read.faces.push([corners[0], corners[k], corners[k + 1]]);
                }
                if read.faces.len() as u64 > max {
                    return Err(over(read.faces.len() as u64, max));
                }
            }
            _ => {}
        }
    }
    Ok(read)
}

/// A scalar type of PLY.
#[derive(Debug, Clone, Copy)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn named(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn decode(self, w: &[u8], big: bool) -> f64 {
        macro_rules! get {
            ($t:ty, $n:expr) => {{
                let mut a = [0u8; $n];
                a.copy_from_slice(&w[..$n]);
                f64::from(if big {
                    <$t>::from_be_bytes(a)
                } else {
                    <$t>::from_le_bytes(a)
                })
            }};
        }
        match self {
            Scalar::I8 => f64::from(w[0] as i8),
            Scalar::U8 => f64::from(w[0]),
            Scalar::I16 => get!(i16, 2),
            Scalar::U16 => get!(u16, 2),
            Scalar::I32 => get!(i32, 4),
            Scalar::U32 => get!(u32, 4),
            Scalar::F32 => get!(f32, 4),
            Scalar::F64 => get!(f64, 8),
        }
    }
}

/// A property of a PLY element: a scalar, or a list (count type, item type).
#[derive(Debug, Clone)]
struct Property {
    name: String,
    ty: Scalar,
    list: Option<Scalar>,
}

#[derive(Debug, Clone)]
struct Element {
    name: String,
    count: u64,
    properties: Vec<Property>,
}

/// PLY: a text header, then the elements in ASCII or binary; the `vertex` element's `x`,
/// `y`, `z` and the `face` element's list `vertex_indices` (or `vertex_index`) are read,
/// faces of more than three corners fanned.
fn ply(b: &[u8], max: u64) -> Result<Read, String> {
    const END: &[u8] = b"end_header";
    let end = b
        .windows(END.len())
        .position(|w| w == END)
        .ok_or("a PLY file's header ends with `end_header`; this one has none")?;
    let mut body = end + END.len();
    while body < b.len() && (b[body] == b'\r' || b[body] == b' ') {
        body += 1;
    }
    if body < b.len() && b[body] == b'\n' {
        body += 1;
    }
    let header = std::str::from_utf8(&b[..end]).map_err(|_| "the PLY header is not text")?;
    let mut lines = header.lines();
    if lines.next().map(str::trim) != Some("ply") {
        return Err("a PLY file starts with the line `ply`".into());
    }
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    for (n, line) in header.lines().enumerate().skip(1) {
        let line_no = n + 1;
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.as_slice() {
            ["format", f, _] => format = Some(f.to_string()),
            ["element", name, count] => elements.push(Element {
                name: name.to_string(),
                count: count
                    .parse()
                    .map_err(|_| format!("line {line_no}: `{count}` is not a count"))?,
                properties: Vec::new(),
            }),
            ["property", "list", c, t, name] => {
                let (Some(c), Some(t)) = (Scalar::named(c), Scalar::named(t)) else {
                    return Err(format!("line {line_no}: unknown property type"));
                };
                let e = elements
                    .last_mut()
                    .ok_or(format!("line {line_no}: a property before any element"))?;
                e.properties.push(Property {
                    name: name.to_string(),
                    ty: t,
                    list: Some(c),
                });
            }
            ["property", t, name] => {
                let t = Scalar::named(t)
                    .ok_or(format!("line {line_no}: unknown property type `{t}`"))?;
                let e = elements
                    .last_mut()
                    .ok_or(format!("line {line_no}: a property before any element"))?;
                e.properties.push(Property {
                    name: name.to_string(),
                    ty: t,
                    list: None,
                });
            }
            _ => {}
        }
    }
    let big = match format.as_deref() {
        Some("ascii") => None,
        Some("binary_little_endian") => Some(false),
        Some("binary_big_endian") => Some(true),
        _ => return Err("the PLY header has no known `format` line".into()),
    };
    if let Some(f) = elements.iter().find(|e| e.name == "face") {
        if f.count > max {
            return Err(over(f.count, max));
        }
    }
    // Every element takes at least a byte (or a character) per property: a count beyond
    // the bytes left is a truncated or lying file, refused before anything is allocated.
    let rest = (b.len() - body) as u64;
    for e in &elements {
        if e.count.saturating_mul(e.properties.len().max(1) as u64) > rest {
            return Err(format!(
                "truncated PLY: the header declares {} `{}` elements, more than the {rest} bytes after it hold",
                e.count, e.name
            ));
        }
    }
    let mut values = Values { b, at: body, big };
    let mut read = Read::default();
    for e in &elements {
        for _ in 0..e.count {
            let mut p = [0.0; 3];
            for prop in &e.properties {
                match prop.list {
                    None => {
                        let v = values.next(prop.ty)?;
                        if e.name == "vertex" {
                            match prop.name.as_str() {
                                "x" => p[0] = v,
                                "y" => p[1] = v,
                                "z" => p[2] = v,
                                _ => {}
                            }
                        }
                    }
                    Some(c) => {
                        let n = values.next(c)?;
                        if !(0.0..=1024.0).contains(&n) {
                            return Err(format!(
                                "byte {}: a list of {n} items is not a face",
                                values.at
                            ));
                        }
                        let mut corners = Vec::with_capacity(n as usize);
                        for _ in 0..n as usize {
                            corners.push(values.next(prop.ty)?);
                        }
                        let indices = prop.name == "vertex_indices" || prop.name == "vertex_index";
                        if e.name == "face" && indices {
                            if corners.len() < 3 {
                                return Err(format!(
                                    "byte {}: a face needs three corners",
                                    values.at
                                ));
                            }
                            let ix: Vec<u32> = corners
                                .iter()
                                .map(|&c| if c >= 0.0 { c as u32 } else { u32::MAX })
                                .collect();
                            for k in 1..ix.len() - 1 {
                                read.faces.push([ix[0], ix[k], ix[k + 1]]);
                            }
                        }
                    }
                }
            }
            if e.name == "vertex" {
                read.positions.push(p);
            }
        }
    }
    if read.faces.len() as u64 > max {
        return Err(over(read.faces.len() as u64, max));
    }
    Ok(read)
}

/// The values of a PLY body, read one by one.
struct Values<'a> {
    b: &'a [u8],
    at: usize,
    /// `None` for ASCII, else whether big-endian.
    big: Option<bool>,
}

impl Values<'_> {
    fn next(&mut self, ty: Scalar) -> Result<f64, String> {
        match self.big {
            Some(big) => {
                let n = ty.size();
                if self.at + n > self.b.len() {
                    return Err(format!(
                        "truncated PLY: the data ends at byte {} inside an element",
                        self.b.len()
                    ));
                }
                let v = ty.decode(&self.b[self.at..], big);
                self.at += n;
                Ok(v)
            }
            None => {
                while self.at < self.b.len() && self.b[self.at].is_ascii_whitespace() {
                    self.at += 1;
                }
                let start = self.at;
                while self.at < self.b.len() && !self.b[self.at].is_ascii_whitespace() {
                    self.at += 1;
                }
                if start == self.at {
                    return Err(format!(
                        "truncated PLY: the data ends at byte {} inside an element",
                        self.b.len()
                    ));
                }
                let w = String::from_utf8_lossy(&self.b[start..self.at]);
                w.parse()
                    .map_err(|_| format!("byte {start}: `{w}` is not a number"))
            }
        }
    }
}

/// Binary glTF: every primitive of mode 4 (triangles) of the JSON chunk's meshes, with its
/// `POSITION` accessor (f32 VEC3) and its indices (u8, u16 or u32) or none, read from the
/// BIN chunk. The nodes' transforms are not applied: the meshes are read in their own space.
fn glb(b: &[u8], max: u64) -> Result<Read, String> {
    if b.len() < 20 || &b[..4] != b"glTF" {
        return Err("a binary glTF file starts with `glTF` and a 12-byte header".into());
    }
    let total = u32_at(b, 8) as usize;
    if total > b.len() {
        return Err(format!(
            "truncated glTF: the header declares {total} bytes at byte 8, the file has {}",
            b.len()
        ));
    }
    let json_len = u32_at(b, 12) as usize;
    if &b[16..20] != b"JSON" || 20 + json_len > b.len() {
        return Err("the first chunk of a glTF file, at byte 12, is its JSON".into());
    }
    let doc: serde_json::Value = serde_json::from_slice(&b[20..20 + json_len])
        .map_err(|e| format!("the JSON chunk at byte 20 is not JSON: {e}"))?;
    let bin_at = 20 + json_len;
    let bin: &[u8] = if bin_at + 8 <= b.len() && &b[bin_at + 4..bin_at + 8] == b"BIN\0" {
        let n = u32_at(b, bin_at) as usize;
        let start = bin_at + 8;
        if start + n > b.len() {
            return Err(format!(
                "truncated glTF: the BIN chunk at byte {bin_at} declares {n} bytes, the file has {}",
                b.len() - start
            ));
        }
        &b[start..start + n]
    } else {
        &[]
    };
    let get = |v: &serde_json::Value, k: &str| v.get(k).and_then(serde_json::Value::as_u64);
    // The bytes of accessor `a`: (its bytes from its first element, count, component type,
    // stride, components).
    let accessor = |a: u64| -> Result<(&[u8], usize, u64, usize, usize), String> {
        let acc = &doc["accessors"][a as usize];
        let count = get(acc, "count").ok_or(format!("accessor {a} has no count"))?;
        // Elements may overlap (a stride of 0), but no more of them than bytes are read.
        if count > bin.len() as u64 {
            return Err(format!(
                "accessor {a} declares {count} elements, more than the {} bytes of the BIN chunk",
                bin.len()
            ));
        }
        let count = count as usize;
        let ty = get(acc, "componentType").ok_or(format!("accessor {a} has no componentType"))?;
        let comps = match acc["type"].as_str() {
            Some("SCALAR") => 1,
            Some("VEC3") => 3,
            other => return Err(format!("accessor {a} has type {other:?}")),
        };
        let size = match ty {
            5121 => 1,
            5123 => 2,
            5125 | 5126 => 4,
            _ => return Err(format!("accessor {a} has component type {ty}")),
        };
        let view_index = get(acc, "bufferView").ok_or(format!("accessor {a} has no bufferView"))?;
        let view = &doc["bufferViews"][view_index as usize];
        if get(view, "buffer").unwrap_or(0) != 0 {
            return Err(format!(
                "buffer view {view_index} is not in the file's BIN chunk"
            ));
        }
        let start =
            (get(view, "byteOffset").unwrap_or(0) + get(acc, "byteOffset").unwrap_or(0)) as usize;
        let stride = get(view, "byteStride").map_or(size * comps, |s| s as usize);
        let need = if count == 0 {
            0
        } else {
            (count as u64 - 1)
                .saturating_mul(stride as u64)
                .saturating_add((size * comps) as u64)
        };
        if start as u64 + need > bin.len() as u64 {
            return Err(format!(
                "truncated glTF: accessor {a} needs {need} bytes from byte {start} of the BIN chunk, which has {}",
                bin.len()
            ));
        }
        Ok((&bin[start..], count, ty, stride, comps))
    };
    let mut read = Read::default();
    let meshes = doc["meshes"].as_array().cloned().unwrap_or_default();
    for mesh in &meshes {
        for prim in mesh["primitives"].as_array().cloned().unwrap_or_default() {
            if get(&prim, "mode").unwrap_or(4) != 4 {
                continue;
            }
            let pos = get(&prim["attributes"], "POSITION")
                .ok_or("a primitive has no POSITION attribute")?;
            let (data, count, ty, stride, comps) = accessor(pos)?;
            if ty != 5126 || comps != 3 {
                return Err(format!("accessor {pos} (POSITION) is not of f32 VEC3"));
            }
            let base = read.positions.len() as u32;
            for i in 0..count {
                read.positions
                    .push([0, 1, 2].map(|k| f32_at(data, i * stride + 4 * k)));
            }
            let indices: Vec<u32> = match get(&prim, "indices") {
                Some(ix) => {
                    let (data, count, ty, stride, _) = accessor(ix)?;
                    if count as u64 / 3 > max {
                        return Err(over(count as u64 / 3, max));
                    }
                    (0..count)
                        .map(|i| match ty {
                            5121 => u32::from(data[i * stride]),
                            5123 => u32::from(u16::from_le_bytes([
                                data[i * stride],
                                data[i * stride + 1],
                            ])),
                            _ => u32_at(data, i * stride),
                        })
                        .collect()
                }
                None => (0..count as u32).collect(),
            };
            for t in indices.chunks_exact(3) {
                for &i in t {
                    if i as usize >= count {
                        return Err(format!(
                            "accessor {pos}: index {i} is past its {count} positions"
                        ));
                    }
                }
                read.faces.push([base + t[0], base + t[1], base + t[2]]);
            }
            if read.faces.len() as u64 > max {
                return Err(over(read.faces.len() as u64, max));
            }
        }
    }
    Ok(read)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A binary STL of `tris`, with a count that may lie.
    fn stl_bytes(tris: &[[[f32; 3]; 3]], count: u32) -> Vec<u8> {
        let mut b = vec![b' '; 80];
        b.extend_from_slice(&count.to_le_bytes());
        for t in tris {
            b.extend_from_slice(&[0u8; 12]);
            for v in t {
                for x in v {
                    b.extend_from_slice(&x.to_le_bytes());
                }
            }
            b.extend_from_slice(&[0, 0]);
        }
        b
    }

    const TRI: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

    #[test]
    fn binary_stl_reads_and_refuses_lies() {
        let r = read(Format::Stl, &stl_bytes(&[TRI, TRI], 2), 10).expect("reads");
        assert_eq!((r.positions.len(), r.faces.len()), (3, 2));
        let e = read(Format::Stl, &stl_bytes(&[TRI], 2), 10).expect_err("truncated");
        assert!(e.contains("truncated") && e.contains("byte 80"), "{e}");
        let e = read(Format::Stl, &stl_bytes(&[TRI], 100_000_000), 1_000_000).expect_err("huge");
        assert!(e.contains("`triangles` limit"), "{e}");
        let e = read(Format::Stl, &stl_bytes(&[], 0), 10).expect_err("empty");
        assert!(e.contains("no triangles"), "{e}");
        assert!(read(Format::Stl, b"abc", 10).is_err());
    }

    #[test]
    fn text_formats_read() {
        let ascii = "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid x\n";
        assert_eq!(
            read(Format::Stl, ascii.as_bytes(), 10)
                .expect("reads")
                .faces
                .len(),
            1
        );
        let e = read(Format::Stl, b"solid x\nvertex 0 0 0\nvertex 1 0 zz\n", 10).expect_err("bad");
        assert!(e.contains("line 3"), "{e}");
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1/1 2//3 4 3\n";
        let r = read(Format::Obj, obj.as_bytes(), 10).expect("reads");
        assert_eq!(r.faces, vec![[0, 1, 3], [0, 3, 2]]);
        let e = read(Format::Obj, b"v 0 0 0\nf 1 2 3\n", 10).expect_err("bad index");
        assert!(e.contains("line 2"), "{e}");
        let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        let r = read(Format::Ply, ply.as_bytes(), 10).expect("reads");
        assert_eq!(r.faces, vec![[0, 1, 2]]);
        let lie = ply.replace("element face 1", "element face 100000000");
        let e = read(Format::Ply, lie.as_bytes(), 1_000_000_000).expect_err("lies");
        assert!(e.contains("truncated PLY"), "{e}");
    }

    /// A small valid file of each format, as `sdfc mesh` writes them where it does.
    fn samples() -> Vec<(Format, Vec<u8>)> {
        let ply_binary = {
            let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n".to_vec();
            for v in TRI {
                for x in v {
                    b.extend_from_slice(&x.to_le_bytes());
                }
            }
            b.push(3);
            for i in 0i32..3 {
                b.extend_from_slice(&i.to_le_bytes());
            }
            b
        };
        let glb = {
            let mut bin = Vec::new();
            for v in TRI {
                for x in v {
                    bin.extend_from_slice(&x.to_le_bytes());
                }
            }
            for i in 0u32..3 {
                bin.extend_from_slice(&i.to_le_bytes());
            }
            let json = br#"{"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":12}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},{"bufferView":1,"componentType":5125,"count":3,"type":"SCALAR"}]}"#;
            let mut json = json.to_vec();
            while json.len() % 4 != 0 {
                json.push(b' ');
            }
            let mut b = b"glTF".to_vec();
            b.extend_from_slice(&2u32.to_le_bytes());
            b.extend_from_slice(&((20 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
            b.extend_from_slice(&(json.len() as u32).to_le_bytes());
            b.extend_from_slice(b"JSON");
            b.extend_from_slice(&json);
            b.extend_from_slice(&(bin.len() as u32).to_le_bytes());
            b.extend_from_slice(b"BIN\0");
            b.extend_from_slice(&bin);
            b
        };
        vec![
            (Format::Stl, stl_bytes(&[TRI, TRI], 2)),
            (Format::Stl, b"solid a\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendsolid\n".to_vec()),
            (Format::Obj, b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf -1 -2 -3\n".to_vec()),
            (Format::Ply, b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n".to_vec()),
            (Format::Ply, ply_binary),
            (Format::Glb, glb),
        ]
    }

    /// Every sample reads, and thousands of mutations of them (bytes changed, counts made
    /// huge, the file cut short) read or fail, and never panic, allocate for a count the
    /// bytes do not hold, or make a mesh that panics.
    #[test]
    fn mutated_files_never_panic() {
        use crate::program::mesh::TriMesh;
        let mut rng = crate::rng::Rng::new(40);
        for (format, bytes) in samples() {
            let r = read(format, &bytes, 1000).unwrap_or_else(|e| panic!("{format:?}: {e}"));
            assert!(!r.faces.is_empty());
            for _ in 0..1500 {
                let mut b = bytes.clone();
                for _ in 0..1 + rng.below(4) {
                    let at = rng.below(b.len());
                    match rng.below(4) {
                        0 => b[at] = rng.below(256) as u8,
                        1 => {
                            let chars = b"0123456789-.e \nfv/";
                            b[at] = chars[rng.below(chars.len())];
                        }
                        2 => {
                            let n = [u32::MAX, 1 << 31, 100_000_000, 0][rng.below(4)];
                            let end = (at + 4).min(b.len());
                            b[at..end].copy_from_slice(&n.to_le_bytes()[..end - at]);
                        }
                        _ => b.truncate(at),
                    }
                    if b.is_empty() {
                        break;
                    }
                }
                if let Ok(r) = read(format, &b, 1000) {
                    assert!(r.positions.len() <= b.len() && r.faces.len() <= 1000);
                    if let Ok(m) = TriMesh::new("m", &r.positions, &r.faces, 1.0) {
                        let _ = m.distance([0.1, 0.2, 0.3]);
                    }
                }
            }
        }
    }
}
