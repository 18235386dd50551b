//! Readers of triangle mesh files for `mesh(path)`: STL (binary and ASCII), OBJ, PLY (ASCII
//! and binary, either byte order) and binary glTF (`.glb`), each a few dozen lines over the
//! bytes the checker's `Loader` read, since the compiler does no IO. Every reader checks a
//! count it is told against the bytes that are there, and against the `triangles` limit,
//! before it allocates for it, so a file declaring 10⁸ triangles in a few bytes is an error,
//! not an allocation; past the limit a reader only counts (the error says how many the file
//! has), so what it holds stays within the limit. Offsets and sizes a file gives are added
//! and multiplied with checks: one near 2⁶⁴ is an error, never a wrapped index. Every error
//! says where in the file it is (a byte offset, a line or a member of glTF's JSON).
//! The formats `sdfc mesh` writes (runtime/src/mesh/write.rs) read back to the same
//! triangles.

use std::collections::HashMap;
use std::fmt;

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

/// Where in a file a problem is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Place {
    /// A byte, counting from 0.
    Byte(u64),
    /// A line, counting from 1.
    Line(usize),
    /// A member of a glTF file's JSON chunk, as a path (`accessors[0].byteOffset`).
    Json(String),
}

impl fmt::Display for Place {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Place::Byte(b) => write!(f, "at byte {b}"),
            Place::Line(l) => write!(f, "line {l}"),
            Place::Json(path) => write!(f, "at `{path}` of the JSON chunk"),
        }
    }
}

/// Why a file gives no mesh.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Error {
    /// The file has (or, where its counts are read first, declares) `triangles` triangles,
    /// more than the `max` the reader was given.
    Limit {
        triangles: u64,
        max: u64,
        at: Option<Place>,
    },
    /// The file is truncated or malformed at `at`.
    Malformed { at: Option<Place>, what: String },
    /// The file holds no triangles.
    Empty,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let at = |f: &mut fmt::Formatter<'_>, at: &Option<Place>| match at {
            Some(p) => write!(f, "{p}: "),
            None => Ok(()),
        };
        match self {
            Error::Limit {
                triangles,
                max,
                at: place,
            } => {
                at(f, place)?;
                write!(
                    f,
                    "the file has {triangles} triangles, more than the `triangles` limit of {max}"
                )
            }
            Error::Malformed { at: place, what } => {
                at(f, place)?;
                f.write_str(what)
            }
            Error::Empty => f.write_str("the file has no triangles"),
        }
    }
}

impl std::error::Error for Error {}

/// A malformed file at `at`.
fn bad(at: Place, what: impl Into<String>) -> Error {
    Error::Malformed {
        at: Some(at),
        what: what.into(),
    }
}

/// A malformed file, as a whole.
fn bad_file(what: impl Into<String>) -> Error {
    Error::Malformed {
        at: None,
        what: what.into(),
    }
}

/// Reads `bytes` in `format`, with at most `max` triangles.
pub fn read(format: Format, bytes: &[u8], max: u64) -> Result<Read, Error> {
    let read = match format {
        Format::Stl => stl(bytes, max),
        Format::Obj => obj(bytes, max),
        Format::Ply => ply(bytes, max),
        Format::Glb => glb(bytes, max),
    }?;
    if read.faces.is_empty() {
        return Err(Error::Empty);
    }
    Ok(read)
}

/// Triangles as they are read: up to `max` kept, past it only counted, so that the error
/// says how many the file has while what is held stays within the limit.
struct Faces {
    kept: Vec<[u32; 3]>,
    count: u64,
    max: u64,
}

impl Faces {
    fn new(max: u64) -> Faces {
        Faces {
            kept: Vec::new(),
            count: 0,
            max,
        }
    }

    /// Whether the limit is passed: from then on triangles are only counted.
    fn over(&self) -> bool {
        self.count > self.max
    }

    /// One more triangle; kept while within the limit.
    fn push(&mut self, face: [u32; 3]) {
        self.count += 1;
        if !self.over() {
            self.kept.push(face);
        }
    }

    /// `n` more triangles, counted only (past the limit).
    fn skip(&mut self, n: u64) {
        self.count = self.count.saturating_add(n);
    }

    /// The triangles, or the limit's error.
    fn done(self) -> Result<Vec<[u32; 3]>, Error> {
        if self.over() {
            return Err(Error::Limit {
                triangles: self.count,
                max: self.max,
                at: None,
            });
        }
        Ok(self.kept)
    }
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
    positions: Vec<[f64; 3]>,
    index: HashMap<[u64; 3], u32>,
}

impl Weld {
    fn vertex(&mut self, p: [f64; 3]) -> u32 {
        let positions = &mut self.positions;
        *self.index.entry(p.map(f64::to_bits)).or_insert_with(|| {
            positions.push(p);
            positions.len() as u32 - 1
        })
    }
}

/// STL: ASCII when it starts with `solid`, is text, and its size is not that of the binary
/// form its count declares; else binary (80-byte header, a count, 50 bytes a triangle).
fn stl(b: &[u8], max: u64) -> Result<Read, Error> {
    let declared = (b.len() >= 84).then(|| u64::from(u32_at(b, 80)));
    let binary_size = declared.map(|n| 84 + 50 * n);
    // A binary header may begin with `solid` too: a file that is not text (a NUL byte, or
    // bytes that are not UTF-8) is binary whatever its first word.
    let text = !b.contains(&0) && std::str::from_utf8(b).is_ok();
    if b.starts_with(b"solid") && binary_size != Some(b.len() as u64) && text {
        return stl_ascii(b, max);
    }
    let (Some(n), Some(size)) = (declared, binary_size) else {
        return Err(bad_file(format!(
            "a binary STL file has at least 84 bytes (a header and a count); this one has {}",
            b.len()
        )));
    };
    // A count the bytes do not hold is a truncated (or lying) file, whatever the limit.
    if size != b.len() as u64 {
        return Err(bad(
            Place::Byte(80),
            format!(
                "truncated binary STL: it declares {n} triangles, which take {size} bytes, but the file has {}",
                b.len()
            ),
        ));
    }
    if n > max {
        return Err(Error::Limit {
            triangles: n,
            max,
            at: Some(Place::Byte(80)),
        });
    }
    let mut weld = Weld::default();
    let mut faces = Vec::with_capacity(n as usize);
    for t in 0..n as usize {
        let at = 84 + 50 * t + 12;
        let mut face = [0u32; 3];
        for (k, v) in face.iter_mut().enumerate() {
            let p = [0, 1, 2].map(|i| f32_at(b, at + 12 * k + 4 * i));
            *v = weld.vertex(p);
        }
        faces.push(face);
    }
    Ok(Read {
        positions: weld.positions,
        faces,
    })
}

/// Where an ASCII STL reader is: what the next line must begin with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum StlState {
    /// Before a `solid` (at the start, or after an `endsolid`).
    Solid,
    /// Inside a solid: `facet` or `endsolid`.
    Facet,
    /// After `facet`: `outer loop`.
    Outer,
    /// Inside a loop, after this many `vertex` lines: another, or `endloop` after three.
    Vertex(u8),
    /// After `endloop`: `endfacet`.
    EndFacet,
}

/// ASCII STL, read by its grammar: `solid`, then `facet normal`, `outer loop`, three
/// `vertex` lines, `endloop` and `endfacet` for each triangle, and `endsolid`. A file cut
/// anywhere, even mid-word, is an error at the line where it breaks off.
fn stl_ascii(b: &[u8], max: u64) -> Result<Read, Error> {
    let text = std::str::from_utf8(b).map_err(|e| {
        bad(
            Place::Byte(e.valid_up_to() as u64),
            "an ASCII STL file must be text, and this byte is not UTF-8",
        )
    })?;
    let mut weld = Weld::default();
    let mut faces = Faces::new(max);
    let mut corners = [0u32; 3];
    let mut state = StlState::Solid;
    let mut last = 0;
    for (n, line) in text.lines().enumerate() {
        let line_no = n + 1;
        let mut words = line.split_whitespace();
        let Some(word) = words.next() else { continue };
        last = line_no;
        let expect = |what: &str| {
            bad(
                Place::Line(line_no),
                format!("ASCII STL: expected {what}, found `{word}`"),
            )
        };
        state = match (state, word) {
            (StlState::Solid, "solid") => StlState::Facet,
            (StlState::Solid, _) => return Err(expect("`solid`")),
            (StlState::Facet, "facet") => StlState::Outer,
            (StlState::Facet, "endsolid") => StlState::Solid,
            (StlState::Facet, _) => return Err(expect("`facet` or `endsolid`")),
            (StlState::Outer, "outer") if words.next() == Some("loop") => StlState::Vertex(0),
            (StlState::Outer, _) => return Err(expect("`outer loop`")),
            (StlState::Vertex(k), "vertex") if k < 3 => {
                let p = numbers(&mut words, line_no)?;
                if !faces.over() {
                    corners[k as usize] = weld.vertex(p);
                }
                StlState::Vertex(k + 1)
            }
            (StlState::Vertex(3), "endloop") => {
                faces.push(corners);
                StlState::EndFacet
            }
            (StlState::Vertex(3), _) => {
                return Err(expect("`endloop` (a facet has three vertices)"))
            }
            (StlState::Vertex(_), _) => return Err(expect("`vertex`")),
            (StlState::EndFacet, "endfacet") => StlState::Facet,
            (StlState::EndFacet, _) => return Err(expect("`endfacet`")),
        };
    }
    if state != StlState::Solid {
        let inside = if state == StlState::Facet {
            "before its `endsolid`"
        } else {
            "inside a facet"
        };
        return Err(bad(
            Place::Line(last.max(1)),
            format!("truncated ASCII STL: the file ends here, {inside}"),
        ));
    }
    Ok(Read {
        faces: faces.done()?,
        positions: weld.positions,
    })
}

/// Three numbers from `words`, on line `line`.
fn numbers<'a>(words: &mut impl Iterator<Item = &'a str>, line: usize) -> Result<[f64; 3], Error> {
    let mut p = [0.0; 3];
    for x in &mut p {
        let w = words
            .next()
            .ok_or_else(|| bad(Place::Line(line), "a vertex needs three coordinates"))?;
        *x = w
            .parse()
            .map_err(|_| bad(Place::Line(line), format!("`{w}` is not a number")))?;
    }
    Ok(p)
}

/// OBJ: `v x y z` vertices and `f` faces of three or more corners (`i`, `i/t`, `i/t/n` or
/// `i//n`, 1-based or negative, relative to the end), fanned into triangles as the corners
/// are read.
fn obj(b: &[u8], max: u64) -> Result<Read, Error> {
    let text = std::str::from_utf8(b).map_err(|e| {
        bad(
            Place::Byte(e.valid_up_to() as u64),
            "an OBJ file must be text, and this byte is not UTF-8",
        )
    })?;
    let mut positions = Vec::new();
    let mut faces = Faces::new(max);
    for (n, line) in text.lines().enumerate() {
        let line_no = n + 1;
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => positions.push(numbers(&mut words, line_no)?),
            Some("f") => {
                // The fan's first corner and the last one read.
                let (mut first, mut previous) = (0, 0);
                let mut corners = 0u64;
                for w in words {
                    corners += 1;
                    if faces.over() {
                        // Past the limit the triangles are only counted.
                        if corners >= 3 {
                            faces.skip(1);
                        }
                        continue;
                    }
                    let index = obj_index(w, positions.len(), line_no)?;
                    match corners {
                        1 => first = index,
                        2 => previous = index,
                        _ => {
                            faces.push([first, previous, index]);
                            previous = index;
                        }
                    }
                }
                if corners < 3 {
                    return Err(bad(Place::Line(line_no), "a face needs three corners"));
                }
            }
            _ => {}
        }
    }
    Ok(Read {
        faces: faces.done()?,
        positions,
    })
}

/// The 0-based vertex of an OBJ corner `w` (`i`, `i/t`, …), with `count` vertices so far.
fn obj_index(w: &str, count: usize, line: usize) -> Result<u32, Error> {
    let first = w.split('/').next().unwrap_or("");
    let i: i64 = first
        .parse()
        .map_err(|_| bad(Place::Line(line), format!("`{w}` is not a vertex index")))?;
    let count_i = i64::try_from(count).unwrap_or(i64::MAX);
    let index = if i < 0 {
        count_i.checked_add(i)
    } else {
        i.checked_sub(1)
    };
    index
        .filter(|&k| (0..count_i).contains(&k))
        .and_then(|k| u32::try_from(k).ok())
        .ok_or_else(|| {
            bad(
                Place::Line(line),
                format!("vertex {i} does not exist ({count} vertices so far)"),
            )
        })
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
fn ply(b: &[u8], max: u64) -> Result<Read, Error> {
    const END: &[u8] = b"end_header";
    let end = b
        .windows(END.len())
        .position(|w| w == END)
        .ok_or_else(|| bad_file("a PLY file's header ends with `end_header`; this one has none"))?;
    let mut body = end + END.len();
    while body < b.len() && (b[body] == b'\r' || b[body] == b' ') {
        body += 1;
    }
    if body < b.len() && b[body] == b'\n' {
        body += 1;
    }
    let header = std::str::from_utf8(&b[..end]).map_err(|e| {
        bad(
            Place::Byte(e.valid_up_to() as u64),
            "the PLY header must be text, and this byte is not UTF-8",
        )
    })?;
    let mut lines = header.lines();
    if lines.next().map(str::trim) != Some("ply") {
        return Err(bad(Place::Line(1), "a PLY file starts with the line `ply`"));
    }
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    for (n, line) in header.lines().enumerate().skip(1) {
        let line_no = n + 1;
        let at = || Place::Line(line_no);
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.as_slice() {
            ["format", f, _] => format = Some(f.to_string()),
            ["element", name, count] => elements.push(Element {
                name: name.to_string(),
                count: count
                    .parse()
                    .map_err(|_| bad(at(), format!("`{count}` is not a count")))?,
                properties: Vec::new(),
            }),
            ["property", "list", c, t, name] => {
                let (Some(c), Some(t)) = (Scalar::named(c), Scalar::named(t)) else {
                    return Err(bad(at(), "unknown property type"));
                };
                let e = elements
                    .last_mut()
                    .ok_or_else(|| bad(at(), "a property before any element"))?;
                e.properties.push(Property {
                    name: name.to_string(),
                    ty: t,
                    list: Some(c),
                });
            }
            ["property", t, name] => {
                let t = Scalar::named(t)
                    .ok_or_else(|| bad(at(), format!("unknown property type `{t}`")))?;
                let e = elements
                    .last_mut()
                    .ok_or_else(|| bad(at(), "a property before any element"))?;
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
        _ => return Err(bad_file("the PLY header has no known `format` line")),
    };
    // Every element takes at least a byte (or a character) per property: a count beyond
    // the bytes left is a truncated or lying file, refused before anything is allocated,
    // and before the limit (whose error would suggest a count the file does not hold).
    let rest = (b.len() - body) as u64;
    for e in &elements {
        if e.count.saturating_mul(e.properties.len().max(1) as u64) > rest {
            return Err(bad(
                Place::Byte(body as u64),
                format!(
                    "truncated PLY: the header declares {} `{}` elements, more than the {rest} bytes after it hold",
                    e.count, e.name
                ),
            ));
        }
    }
    // Each face is at least a triangle: a file declaring more faces than the limit is
    // refused before its body is read.
    if let Some(f) = elements.iter().find(|e| e.name == "face") {
        if f.count > max {
            return Err(Error::Limit {
                triangles: f.count,
                max,
                at: None,
            });
        }
    }
    let mut values = Values { b, at: body, big };
    let mut positions = Vec::new();
    let mut faces = Faces::new(max);
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
                        let at = values.at;
                        let n = values.next(c)?;
                        if !(0.0..=1024.0).contains(&n) {
                            return Err(bad(
                                Place::Byte(at as u64),
                                format!("a list of {n} items is not a face"),
                            ));
                        }
                        let indices = prop.name == "vertex_indices" || prop.name == "vertex_index";
                        let face = e.name == "face" && indices;
                        if face && n < 3.0 {
                            return Err(bad(Place::Byte(at as u64), "a face needs three corners"));
                        }
                        // The fan's first corner and the last one read.
                        let (mut first, mut previous) = (0, 0);
                        for k in 0..n as usize {
                            let c = values.next(prop.ty)?;
                            if !face {
                                continue;
                            }
                            if faces.over() {
                                // Past the limit the triangles are only counted.
                                if k >= 2 {
                                    faces.skip(1);
                                }
                                continue;
                            }
                            // A negative or fractional index names no vertex: u32::MAX is
                            // refused as such when the mesh is built.
                            let ix = if c >= 0.0 && c.fract() == 0.0 {
                                c as u32
                            } else {
                                u32::MAX
                            };
                            match k {
                                0 => first = ix,
                                1 => previous = ix,
                                _ => {
                                    faces.push([first, previous, ix]);
                                    previous = ix;
                                }
                            }
                        }
                    }
                }
            }
            if e.name == "vertex" {
                positions.push(p);
            }
        }
    }
    Ok(Read {
        faces: faces.done()?,
        positions,
    })
}

/// The values of a PLY body, read one by one.
struct Values<'a> {
    b: &'a [u8],
    at: usize,
    /// `None` for ASCII, else whether big-endian.
    big: Option<bool>,
}

impl Values<'_> {
    fn next(&mut self, ty: Scalar) -> Result<f64, Error> {
        let truncated = || {
            bad(
                Place::Byte(self.b.len() as u64),
                "truncated PLY: the data ends inside an element",
            )
        };
        match self.big {
            Some(big) => {
                let n = ty.size();
                if self.at + n > self.b.len() {
                    return Err(truncated());
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
                    return Err(truncated());
                }
                let w = String::from_utf8_lossy(&self.b[start..self.at]);
                w.parse()
                    .map_err(|_| bad(Place::Byte(start as u64), format!("`{w}` is not a number")))
            }
        }
    }
}

type Json = serde_json::Value;

/// The member `key` of the JSON object `v` (at `path`): absent, or a whole number from 0;
/// anything else (negative, fractional, a string) is an error naming it.
fn uint(v: &Json, path: &str, key: &str) -> Result<Option<u64>, Error> {
    match v.get(key) {
        None => Ok(None),
        Some(x) => x.as_u64().map(Some).ok_or_else(|| {
            bad(
                Place::Json(format!("{path}.{key}")),
                format!("`{x}` is not a whole number from 0"),
            )
        }),
    }
}

/// The member `key` of `v`, which must be there.
fn need(v: &Json, path: &str, key: &str) -> Result<u64, Error> {
    uint(v, path, key)?
        .ok_or_else(|| bad(Place::Json(path.to_string()), format!("it has no `{key}`")))
}

/// Element `i` of the array `name` of the document, at `path` where it is named.
fn entry<'a>(doc: &'a Json, name: &str, i: u64, path: String) -> Result<&'a Json, Error> {
    usize::try_from(i)
        .ok()
        .and_then(|i| doc.get(name)?.as_array()?.get(i))
        .filter(|v| v.is_object())
        .ok_or_else(|| {
            bad(
                Place::Json(path),
                format!("it names `{name}[{i}]`, which does not exist"),
            )
        })
}

/// An accessor of a glTF file, checked: its elements lie within its buffer view, which
/// lies within the BIN chunk.
struct Accessor<'a> {
    /// The bytes from its first element to the end of its buffer view.
    data: &'a [u8],
    count: usize,
    component: u64,
    components: usize,
    stride: usize,
}

impl Accessor<'_> {
    /// Component `k` of element `i`, as the index it is (u8, u16 or u32) or an f32.
    fn get(&self, i: usize, k: usize) -> f64 {
        let at = i * self.stride;
        match self.component {
            5121 => f64::from(self.data[at + k]),
            5123 => f64::from(u16::from_le_bytes([
                self.data[at + 2 * k],
                self.data[at + 2 * k + 1],
            ])),
            5125 => f64::from(u32_at(self.data, at + 4 * k)),
            _ => f32_at(self.data, at + 4 * k),
        }
    }
}

/// Accessor `a` of `doc` over `bin`, named at `from` (where the primitive names it).
fn accessor<'a>(doc: &Json, bin: &'a [u8], a: u64, from: String) -> Result<Accessor<'a>, Error> {
    let acc = entry(doc, "accessors", a, from)?;
    let path = format!("accessors[{a}]");
    if acc.get("sparse").is_some() {
        return Err(bad(
            Place::Json(format!("{path}.sparse")),
            "a sparse accessor, which `mesh` does not read",
        ));
    }
    let count = need(acc, &path, "count")?;
    let component = need(acc, &path, "componentType")?;
    let components = match acc.get("type").and_then(Json::as_str) {
        Some("SCALAR") => 1,
        Some("VEC3") => 3,
        _ => {
            return Err(bad(
                Place::Json(format!("{path}.type")),
                "the type is not SCALAR or VEC3, the types `mesh` reads",
            ))
        }
    };
    let size = match component {
        5121 => 1,
        5123 => 2,
        5125 | 5126 => 4,
        _ => {
            return Err(bad(
                Place::Json(format!("{path}.componentType")),
                format!("component type {component} is not an unsigned byte, short or int (5121, 5123, 5125) or a float (5126)"),
            ))
        }
    };
    let element = size * components;
    // The glTF specification lets an accessor without a buffer view stand for zeros (with
    // sparse values); `mesh` needs its data.
    let v = need(acc, &path, "bufferView")?;
    let view = entry(doc, "bufferViews", v, format!("{path}.bufferView"))?;
    let vpath = format!("bufferViews[{v}]");
    if need(view, &vpath, "buffer")? != 0 {
        return Err(bad(
            Place::Json(format!("{vpath}.buffer")),
            "the buffer is not buffer 0, the file's BIN chunk",
        ));
    }
    let view_offset = uint(view, &vpath, "byteOffset")?.unwrap_or(0);
    let view_length = need(view, &vpath, "byteLength")?;
    let view_end = view_offset
        .checked_add(view_length)
        .filter(|&end| end <= bin.len() as u64)
        .ok_or_else(|| {
            bad(
                Place::Json(vpath.clone()),
                format!(
                    "truncated glTF: the view's {view_length} bytes from byte {view_offset} are not within the BIN chunk's {}",
                    bin.len()
                ),
            )
        })?;
    let stride = match uint(view, &vpath, "byteStride")? {
        None => element,
        Some(s) if (element as u64..=252).contains(&s) => s as usize,
        Some(s) => {
            return Err(bad(
                Place::Json(format!("{vpath}.byteStride")),
                format!("a stride of {s} bytes, where accessor {a}'s elements take {element} (a stride is from an element's size to 252)"),
            ))
        }
    };
    let offset = uint(acc, &path, "byteOffset")?.unwrap_or(0);
    let need = match count {
        0 => Some(0),
        n => (n - 1)
            .checked_mul(stride as u64)
            .and_then(|x| x.checked_add(element as u64)),
    };
    let end = need.and_then(|n| offset.checked_add(n));
    if end.is_none_or(|end| end > view_length) {
        return Err(bad(
            Place::Json(path),
            format!(
                "truncated glTF: its {count} elements from byte {offset} are not within the {view_length} bytes of buffer view {v}"
            ),
        ));
    }
    // Within the view, which is within the chunk: both were checked above.
    let start = (view_offset + offset) as usize;
    Ok(Accessor {
        data: &bin[start..view_end as usize],
        count: count as usize,
        component,
        components,
        stride,
    })
}

/// Binary glTF 2.0: every primitive of mode 4 (triangles) of the JSON chunk's meshes, with
/// its `POSITION` accessor (f32 VEC3) and its indices (u8, u16 or u32) or none, read from
/// the BIN chunk. The nodes' transforms are not applied: the meshes are read in their own
/// space. Every accessor is checked and the triangles of all primitives counted against the
/// limit before any is read; the positions read are those the triangles use.
fn glb(b: &[u8], max: u64) -> Result<Read, Error> {
    if b.len() < 12 || &b[..4] != b"glTF" {
        return Err(bad_file(
            "a binary glTF file starts with `glTF` and a 12-byte header",
        ));
    }
    let version = u32_at(b, 4);
    if version != 2 {
        return Err(bad(
            Place::Byte(4),
            format!("glTF version {version}; `mesh` reads version 2"),
        ));
    }
    let total = u32_at(b, 8) as usize;
    if total > b.len() {
        return Err(bad(
            Place::Byte(8),
            format!(
                "truncated glTF: the header declares {total} bytes, the file has {}",
                b.len()
            ),
        ));
    }
    let b = &b[..total];
    if b.len() < 20 || &b[16..20] != b"JSON" {
        return Err(bad(
            Place::Byte(12),
            "the first chunk of a glTF file is its JSON",
        ));
    }
    let json_end = 20 + u32_at(b, 12) as usize;
    if json_end > b.len() {
        return Err(bad(
            Place::Byte(12),
            format!(
                "truncated glTF: the JSON chunk declares {} bytes, the file has {} after its header",
                json_end - 20,
                b.len() - 20
            ),
        ));
    }
    let doc: Json = serde_json::from_slice(&b[20..json_end])
        .map_err(|e| bad(Place::Byte(20), format!("the JSON chunk is not JSON: {e}")))?;
    if !doc.is_object() {
        return Err(bad(Place::Byte(20), "the JSON chunk is not an object"));
    }
    let bin: &[u8] = if json_end + 8 <= b.len() && &b[json_end + 4..json_end + 8] == b"BIN\0" {
        let n = u32_at(b, json_end) as usize;
        let start = json_end + 8;
        if n > b.len() - start {
            return Err(bad(
                Place::Byte(json_end as u64),
                format!(
                    "truncated glTF: the BIN chunk declares {n} bytes, the file has {} after its header",
                    b.len() - start
                ),
            ));
        }
        &b[start..start + n]
    } else {
        &[]
    };
    if let Some(uri) = doc
        .get("buffers")
        .and_then(|x| x.get(0))
        .and_then(|x| x.get("uri"))
    {
        return Err(bad(
            Place::Json("buffers[0].uri".into()),
            format!(
                "buffer 0 is the file {uri}; `mesh` reads a .glb whose data is in its BIN chunk"
            ),
        ));
    }
    // The triangle primitives: where each is, its positions and its indices.
    let array = |v: &Json, key: &str, path: &str| -> Result<Vec<Json>, Error> {
        match v.get(key) {
            None => Ok(Vec::new()),
            Some(Json::Array(items)) => Ok(items.clone()),
            Some(_) => Err(bad(
                Place::Json(format!("{path}.{key}")),
                "it is not an array",
            )),
        }
    };
    let mut primitives = Vec::new();
    let mut triangles: u64 = 0;
    for (m, mesh) in array(&doc, "meshes", "")?.iter().enumerate() {
        let mpath = format!("meshes[{m}]");
        for (p, prim) in array(mesh, "primitives", &mpath)?.iter().enumerate() {
            let path = format!("{mpath}.primitives[{p}]");
            if uint(prim, &path, "mode")?.unwrap_or(4) != 4 {
                continue;
            }
            let apath = format!("{path}.attributes");
            let attributes = prim
                .get("attributes")
                .ok_or_else(|| bad(Place::Json(path.clone()), "it has no `attributes`"))?;
            let pos = need(attributes, &apath, "POSITION")?;
            let positions = accessor(&doc, bin, pos, format!("{apath}.POSITION"))?;
            if positions.component != 5126 || positions.components != 3 {
                return Err(bad(
                    Place::Json(format!("accessors[{pos}]")),
                    "a POSITION accessor is of f32 VEC3",
                ));
            }
            let indices = match uint(prim, &path, "indices")? {
                Some(ix) => {
                    let indices = accessor(&doc, bin, ix, format!("{path}.indices"))?;
                    if indices.component == 5126 || indices.components != 1 {
                        return Err(bad(
                            Place::Json(format!("accessors[{ix}]")),
                            "indices are an accessor of unsigned byte, short or int SCALAR",
                        ));
                    }
                    Some(indices)
                }
                None => None,
            };
            let corners = indices.as_ref().map_or(positions.count, |i| i.count);
            if corners % 3 != 0 {
                return Err(bad(
                    Place::Json(path),
                    format!("{corners} corners of triangles, not a multiple of 3"),
                ));
            }
            triangles = triangles.saturating_add(corners as u64 / 3);
            primitives.push((pos, positions, indices));
        }
    }
    if triangles > max {
        return Err(Error::Limit {
            triangles,
            max,
            at: Some(Place::Json("meshes".into())),
        });
    }
    let mut read = Read::default();
    // The positions read so far: (accessor, element) to the index in `read.positions`.
    let mut used: HashMap<(u64, usize), u32> = HashMap::new();
    for (pos, positions, indices) in &primitives {
        let corners = indices.as_ref().map_or(positions.count, |i| i.count);
        let mut face = [0u32; 3];
        for c in 0..corners {
            let i = match indices {
                Some(ix) => ix.get(c, 0) as usize,
                None => c,
            };
            if i >= positions.count {
                return Err(bad(
                    Place::Json(format!("accessors[{pos}]")),
                    format!("index {i} is past its {} positions", positions.count),
                ));
            }
            let next = read.positions.len() as u32;
            let v = *used.entry((*pos, i)).or_insert_with(|| {
                read.positions.push([0, 1, 2].map(|k| positions.get(i, k)));
                next
            });
            face[c % 3] = v;
            if c % 3 == 2 {
                read.faces.push(face);
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
        let e = read(Format::Stl, &stl_bytes(&[TRI], 2), 10)
            .expect_err("truncated")
            .to_string();
        assert!(e.contains("truncated") && e.contains("byte 80"), "{e}");
        // A count the bytes do not hold is a truncated file, not one above the limit.
        let e = read(Format::Stl, &stl_bytes(&[TRI], 100_000_000), 1_000_000).expect_err("huge");
        assert!(e.to_string().contains("truncated"), "{e}");
        let e = read(Format::Stl, &stl_bytes(&[TRI, TRI], 2), 1).expect_err("over");
        assert!(
            matches!(
                e,
                Error::Limit {
                    triangles: 2,
                    max: 1,
                    ..
                }
            ),
            "{e}"
        );
        let e = read(Format::Stl, &stl_bytes(&[], 0), 10)
            .expect_err("empty")
            .to_string();
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
        let e = read(
            Format::Stl,
            b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 1 0 zz\n",
            10,
        )
        .expect_err("bad")
        .to_string();
        assert!(e.contains("line 4"), "{e}");
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1/1 2//3 4 3\n";
        let r = read(Format::Obj, obj.as_bytes(), 10).expect("reads");
        assert_eq!(r.faces, vec![[0, 1, 3], [0, 3, 2]]);
        let e = read(Format::Obj, b"v 0 0 0\nf 1 2 3\n", 10)
            .expect_err("bad index")
            .to_string();
        assert!(e.contains("line 2"), "{e}");
        let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        let r = read(Format::Ply, ply.as_bytes(), 10).expect("reads");
        assert_eq!(r.faces, vec![[0, 1, 2]]);
        let lie = ply.replace("element face 1", "element face 100000000");
        let e = read(Format::Ply, lie.as_bytes(), 1_000_000_000)
            .expect_err("lies")
            .to_string();
        assert!(e.contains("truncated PLY"), "{e}");
    }

    /// The JSON of a small binary glTF: a triangle's positions (36 bytes) and its three
    /// u32 indices (12 bytes) in two buffer views of the BIN chunk.
    const GLB_JSON: &str = r#"{"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":12}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},{"bufferView":1,"componentType":5125,"count":3,"type":"SCALAR"}]}"#;

    /// The BIN chunk of [`GLB_JSON`].
    fn glb_bin() -> Vec<u8> {
        let mut bin = Vec::new();
        for v in TRI {
            for x in v {
                bin.extend_from_slice(&x.to_le_bytes());
            }
        }
        for i in 0u32..3 {
            bin.extend_from_slice(&i.to_le_bytes());
        }
        bin
    }

    /// A binary glTF file of header version `version`, `json` and `bin`.
    fn glb_bytes(version: u32, json: &str, bin: &[u8]) -> Vec<u8> {
        let mut json = json.as_bytes().to_vec();
        while json.len() % 4 != 0 {
            json.push(b' ');
        }
        let mut b = b"glTF".to_vec();
        b.extend_from_slice(&version.to_le_bytes());
        b.extend_from_slice(&((20 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
        b.extend_from_slice(&(json.len() as u32).to_le_bytes());
        b.extend_from_slice(b"JSON");
        b.extend_from_slice(&json);
        b.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        b.extend_from_slice(b"BIN\0");
        b.extend_from_slice(bin);
        b
    }

    /// The sample glTF with `from` in its JSON replaced by `to`, read within `max`.
    fn glb_edited(from: &str, to: &str, max: u64) -> Result<Read, Error> {
        assert!(GLB_JSON.contains(from), "{from}");
        let json = GLB_JSON.replacen(from, to, 1);
        read(Format::Glb, &glb_bytes(2, &json, &glb_bin()), max)
    }

    /// Offsets near 2⁶⁴ in a buffer view or an accessor, of the positions or the indices,
    /// are errors naming the member, not an index that wraps (which panicked).
    #[test]
    fn glb_offsets_near_two_to_the_64_are_errors() {
        for huge in [
            "18446744073709551615",
            "18446744073709551604",
            "9223372036854775808",
        ] {
            for (from, to, names) in [
                (
                    r#""byteOffset":36"#,
                    format!(r#""byteOffset":{huge}"#),
                    "bufferViews[1]",
                ),
                (
                    r#""byteOffset":0"#,
                    format!(r#""byteOffset":{huge}"#),
                    "bufferViews[0]",
                ),
                (
                    r#""bufferView":0,"#,
                    format!(r#""bufferView":0,"byteOffset":{huge},"#),
                    "accessors[0]",
                ),
                (
                    r#""bufferView":1,"#,
                    format!(r#""bufferView":1,"byteOffset":{huge},"#),
                    "accessors[1]",
                ),
                (
                    r#""byteLength":12"#,
                    format!(r#""byteLength":{huge}"#),
                    "bufferViews[1]",
                ),
                (
                    r#""count":3,"type":"VEC3""#,
                    format!(r#""count":{huge},"type":"VEC3""#),
                    "accessors[0]",
                ),
            ] {
                let e = glb_edited(from, &to, 1000).expect_err(&to);
                let Error::Malformed {
                    at: Some(Place::Json(path)),
                    ..
                } = &e
                else {
                    panic!("{to}: {e:?}");
                };
                assert!(path.starts_with(names), "{to}: {e}");
            }
        }
    }

    /// glTF files the reader read as if whole before: each is refused, saying where.
    #[test]
    fn corrupt_glb_files_are_refused() {
        let cases = [
            // An accessor naming a buffer view that does not exist.
            (
                r#""bufferView":1,"#,
                r#""bufferView":7,"#,
                "accessors[1].bufferView",
            ),
            // Offsets that are negative, fractional or strings.
            (
                r#""byteOffset":36"#,
                r#""byteOffset":-4"#,
                "bufferViews[1].byteOffset",
            ),
            (
                r#""byteOffset":36"#,
                r#""byteOffset":4.5"#,
                "bufferViews[1].byteOffset",
            ),
            (
                r#""byteOffset":36"#,
                r#""byteOffset":"36""#,
                "bufferViews[1].byteOffset",
            ),
            (
                r#""bufferView":0,"#,
                r#""bufferView":0,"byteOffset":-12,"#,
                "accessors[0].byteOffset",
            ),
            // A sparse accessor.
            (
                r#""count":3,"type":"SCALAR""#,
                r#""count":3,"type":"SCALAR","sparse":{"count":1}"#,
                "accessors[1].sparse",
            ),
            // A stride of 0 (every element the same bytes) and one below an element's size.
            (
                r#""byteLength":36}"#,
                r#""byteLength":36,"byteStride":0}"#,
                "bufferViews[0].byteStride",
            ),
            (
                r#""byteLength":36}"#,
                r#""byteLength":36,"byteStride":8}"#,
                "bufferViews[0].byteStride",
            ),
            // More positions than the view holds.
            (
                r#""count":3,"type":"VEC3""#,
                r#""count":4,"type":"VEC3""#,
                "accessors[0]",
            ),
            // An accessor that is not there.
            (
                r#""POSITION":0"#,
                r#""POSITION":5"#,
                "meshes[0].primitives[0].attributes.POSITION",
            ),
            // Indices that are not whole triangles.
            (
                r#""count":3,"type":"SCALAR""#,
                r#""count":2,"type":"SCALAR""#,
                "meshes[0].primitives[0]",
            ),
        ];
        for (from, to, at) in cases {
            let e = glb_edited(from, to, 1000).expect_err(to);
            assert_eq!(
                e,
                Error::Malformed {
                    at: Some(Place::Json(at.into())),
                    what: match &e {
                        Error::Malformed { what, .. } => what.clone(),
                        _ => String::new(),
                    }
                },
                "{to}: {e}"
            );
        }
        // A header of version 1.
        let e = read(Format::Glb, &glb_bytes(1, GLB_JSON, &glb_bin()), 1000).expect_err("v1");
        assert!(
            matches!(&e, Error::Malformed { at: Some(Place::Byte(4)), what } if what.contains("version 1")),
            "{e}"
        );
    }

    /// The triangles of every primitive are counted against the limit before any position
    /// is read: a file of a million triangles over 36 bytes is refused, with its count.
    #[test]
    fn glb_triangles_are_counted_before_reading() {
        let e = glb_edited(
            r#""meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}]"#,
            r#""meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1},{"attributes":{"POSITION":0},"indices":1},{"attributes":{"POSITION":0}}]}]"#,
            2,
        )
        .expect_err("three triangles");
        assert!(
            matches!(
                e,
                Error::Limit {
                    triangles: 3,
                    max: 2,
                    ..
                }
            ),
            "{e}"
        );
        let r = glb_edited(
            r#""meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}]"#,
            r#""meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1},{"attributes":{"POSITION":0}}]}]"#,
            2,
        )
        .expect("two triangles");
        // The positions the two primitives share are read once.
        assert_eq!((r.positions.len(), r.faces.len()), (3, 2));
    }

    /// An ASCII STL cut anywhere before its `endsolid` is an error (a file cut after a
    /// whole facet read as a mesh with a hole before), and one whose first word is `solid`
    /// but whose bytes are binary is a truncated binary STL, not text that is not UTF-8.
    #[test]
    fn cut_stl_files_are_errors() {
        let ascii = "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nvertex 0 0 1\nendloop\nendfacet\nendsolid x\n";
        assert_eq!(
            read(Format::Stl, ascii.as_bytes(), 10).map(|r| r.faces.len()),
            Ok(2)
        );
        let whole = ascii.find("endsolid").expect("endsolid") + "endsolid".len();
        for cut in 1..whole {
            let e = read(Format::Stl, &ascii.as_bytes()[..cut], 10);
            assert!(e.is_err(), "cut at {cut}: {:?}", &ascii[..cut]);
        }
        let e = read(
            Format::Stl,
            &ascii.as_bytes()[..ascii.find("endfacet\nfacet").expect("x") + 5],
            10,
        )
        .expect_err("mid-word");
        assert!(e.to_string().contains("line 8"), "{e}");
        let mut binary = stl_bytes(&[TRI, TRI], 2);
        binary[..5].copy_from_slice(b"solid");
        assert_eq!(read(Format::Stl, &binary, 10).map(|r| r.faces.len()), Ok(2));
        binary.truncate(120);
        let e = read(Format::Stl, &binary, 10)
            .expect_err("truncated")
            .to_string();
        assert!(e.contains("truncated binary STL"), "{e}");
    }

    /// Past the limit a reader counts the triangles without holding them: an OBJ face of
    /// 100 000 corners is refused with its 99 998 triangles, one PLY face likewise.
    #[test]
    fn triangles_past_the_limit_are_counted_not_held() {
        let mut obj = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nf");
        for k in 0..100_000 {
            obj.push_str([" 1", " 2", " 3"][k % 3]);
        }
        let e = read(Format::Obj, obj.as_bytes(), 10).expect_err("over");
        assert_eq!(
            e,
            Error::Limit {
                triangles: 99_998,
                max: 10,
                at: None
            }
        );
        let mut ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 2\nproperty list ushort uchar vertex_indices\nend_header\n".to_vec();
        for v in TRI {
            for x in v {
                ply.extend_from_slice(&x.to_le_bytes());
            }
        }
        for corners in [3u16, 1000] {
            ply.extend_from_slice(&corners.to_le_bytes());
            ply.extend((0..corners).map(|k| (k % 3) as u8));
        }
        let e = read(Format::Ply, &ply, 10).expect_err("over");
        assert_eq!(
            e,
            Error::Limit {
                triangles: 999,
                max: 10,
                at: None
            }
        );
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
        let glb = glb_bytes(2, GLB_JSON, &glb_bin());
        vec![
            (Format::Stl, stl_bytes(&[TRI, TRI], 2)),
            (Format::Stl, b"solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid\n".to_vec()),
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
