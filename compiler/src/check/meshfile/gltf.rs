//! Binary glTF 2.0 (`.glb`) for `mesh(path)`: the JSON chunk's accessors checked against
//! the BIN chunk, and the triangle primitives of the meshes the scene's nodes place.

use super::{bad, bad_file, f32_at, u32_at, Error, Place, Read};
use std::collections::HashMap;

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
pub(super) fn glb(b: &[u8], max: u64) -> Result<Read, Error> {
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
