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

/// `b` as text, or `message` at its first byte that is not UTF-8.
fn as_text<'a>(b: &'a [u8], message: &'static str) -> Result<&'a str, Error> {
    std::str::from_utf8(b).map_err(|e| bad(Place::Byte(e.valid_up_to() as u64), message))
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
        Format::Glb => gltf::glb(bytes, max),
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

/// A polygon fanned into triangles as its corners are read: the fan's first corner and the
/// last one read.
#[derive(Default)]
struct Fan {
    first: u32,
    previous: u32,
}

impl Fan {
    /// Corner `k` (from 0), its index found by `index`: from the third on, each closes a
    /// triangle with the first and the one before. Past the limit the triangles are only
    /// counted, and the index is not read.
    fn corner(
        &mut self,
        k: u64,
        index: impl FnOnce() -> Result<u32, Error>,
        faces: &mut Faces,
    ) -> Result<(), Error> {
        if faces.over() {
            if k >= 2 {
                faces.skip(1);
            }
            return Ok(());
        }
        let index = index()?;
        match k {
            0 => self.first = index,
            1 => self.previous = index,
            _ => {
                faces.push([self.first, self.previous, index]);
                self.previous = index;
            }
        }
        Ok(())
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
    let text = as_text(
        b,
        "an ASCII STL file must be text, and this byte is not UTF-8",
    )?;
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
    let text = as_text(b, "an OBJ file must be text, and this byte is not UTF-8")?;
    let mut positions = Vec::new();
    let mut faces = Faces::new(max);
    for (n, line) in text.lines().enumerate() {
        let line_no = n + 1;
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => positions.push(numbers(&mut words, line_no)?),
            Some("f") => {
                let mut fan = Fan::default();
                let mut corners = 0u64;
                for w in words {
                    let index = || obj_index(w, positions.len(), line_no);
                    fan.corner(corners, index, &mut faces)?;
                    corners += 1;
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
    let (header, body) = ply_header(b)?;
    let (big, elements) = ply_elements(header)?;
    ply_counts(&elements, (b.len() - body) as u64, body, max)?;
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
                    Some(c) => ply_list(&mut values, e, prop, c, &mut faces)?,
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

/// A PLY file's header, as text, and where its body starts (past `end_header`, the rest of
/// its line and its line break).
fn ply_header(b: &[u8]) -> Result<(&str, usize), Error> {
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
    let header = as_text(
        &b[..end],
        "the PLY header must be text, and this byte is not UTF-8",
    )?;
    Ok((header, body))
}

/// The error of a PLY property declared before any element.
const NO_ELEMENT: &str = "a property before any element";

/// The property `name` added to the last of `elements`; `None` where there is none.
fn property(elements: &mut [Element], name: &str, ty: Scalar, list: Option<Scalar>) -> Option<()> {
    let name = name.to_string();
    elements
        .last_mut()
        .map(|e| e.properties.push(Property { name, ty, list }))
}

/// What a PLY header declares: the body's format (`None` for ASCII, else whether
/// big-endian) and its elements with their properties, in order.
fn ply_elements(header: &str) -> Result<(Option<bool>, Vec<Element>), Error> {
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
                property(&mut elements, name, t, Some(c)).ok_or_else(|| bad(at(), NO_ELEMENT))?;
            }
            ["property", t, name] => {
                let t = Scalar::named(t)
                    .ok_or_else(|| bad(at(), format!("unknown property type `{t}`")))?;
                property(&mut elements, name, t, None).ok_or_else(|| bad(at(), NO_ELEMENT))?;
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
    Ok((big, elements))
}

/// The element counts a PLY header declares, checked before its body (of `rest` bytes from
/// byte `body`) is read: within what the body can hold, and no more faces than `max`.
fn ply_counts(elements: &[Element], rest: u64, body: usize, max: u64) -> Result<(), Error> {
    // Every element takes at least a byte (or a character) per property: a count beyond
    // the bytes left is a truncated or lying file, refused before anything is allocated,
    // and before the limit (whose error would suggest a count the file does not hold).
    for e in elements {
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
    Ok(())
}

/// One list property `prop` of element `e`, its length of type `count`: read past, or, for a
/// face's corner indices, its triangles (a fan from its first corner) added to `faces`.
fn ply_list(
    values: &mut Values,
    e: &Element,
    prop: &Property,
    count: Scalar,
    faces: &mut Faces,
) -> Result<(), Error> {
    let at = values.at;
    let n = values.next(count)?;
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
    let mut fan = Fan::default();
    for k in 0..n as u64 {
        let c = values.next(prop.ty)?;
        if !face {
            continue;
        }
        // A negative or fractional index names no vertex: u32::MAX is refused as such when
        // the mesh is built.
        let index = || {
            Ok(if c >= 0.0 && c.fract() == 0.0 {
                c as u32
            } else {
                u32::MAX
            })
        };
        fan.corner(k, index, faces)?;
    }
    Ok(())
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

mod gltf;
#[cfg(test)]
mod tests;
