//! Binary glTF 2.0 (`.glb`) for `mesh(path)`: the JSON chunk's accessors checked against
//! the BIN chunk, and the triangle primitives of the meshes the scene's nodes place, each
//! where its node's transforms put it.

use super::{bad, bad_file, f32_at, u32_at, Error, Place, Read};
use glam::{DMat4, DQuat, DVec3};
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
/// the BIN chunk, once for each node of the scene that places the mesh, through that node's
/// transform and its ancestors' ([`placed`]); a file without nodes, its meshes in their own
/// space. Every accessor is checked and the triangles of every placed primitive counted
/// against the limit before any is read; the positions read are those the triangles use.
pub(super) fn glb(b: &[u8], max: u64) -> Result<Read, Error> {
    let b = header(b)?;
    let (doc, bin) = chunks(b)?;
    let meshes = array(&doc, "meshes", "")?;
    let primitives = meshes
        .iter()
        .enumerate()
        .map(|(m, mesh)| triangle_primitives(&doc, bin, mesh, m))
        .collect::<Result<Vec<_>, _>>()?;
    let placements = placed(&doc, meshes.len())?;
    let mut triangles: u64 = 0;
    for (mesh, _) in &placements {
        for t in &primitives[*mesh] {
            triangles = triangles.saturating_add(t.corners() as u64 / 3);
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
    for (mesh, transform) in &placements {
        read_placed(&mut read, &primitives[*mesh], transform)?;
    }
    Ok(read)
}

/// The bytes of a binary glTF file that its 12-byte header declares, checked: its magic,
/// version 2, and a length within the file.
fn header(b: &[u8]) -> Result<&[u8], Error> {
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
    Ok(&b[..total])
}

/// The file's chunks after its header: the JSON document (an object), and the BIN chunk's
/// bytes (none without one); buffer 0 must be the BIN chunk, not a file of its own.
fn chunks(b: &[u8]) -> Result<(Json, &[u8]), Error> {
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
    Ok((doc, bin))
}

/// The member `key` of `v` (at `path`): absent, an empty list; else an array.
fn array(v: &Json, key: &str, path: &str) -> Result<Vec<Json>, Error> {
    match v.get(key) {
        None => Ok(Vec::new()),
        Some(Json::Array(items)) => Ok(items.clone()),
        Some(_) => Err(bad(
            Place::Json(format!("{path}.{key}")),
            "it is not an array",
        )),
    }
}

/// A triangle primitive of a mesh, checked: its `POSITION` accessor (numbered `pos`) and its
/// indices, if any.
struct Triangles<'a> {
    pos: u64,
    positions: Accessor<'a>,
    indices: Option<Accessor<'a>>,
}

impl Triangles<'_> {
    /// The corners of its triangles: one per index, or per position without indices.
    fn corners(&self) -> usize {
        self.indices
            .as_ref()
            .map_or(self.positions.count, |i| i.count)
    }
}

/// The triangle primitives (mode 4) of mesh `m`, `mesh`, their accessors checked over `bin`.
fn triangle_primitives<'a>(
    doc: &Json,
    bin: &'a [u8],
    mesh: &Json,
    m: usize,
) -> Result<Vec<Triangles<'a>>, Error> {
    let mpath = format!("meshes[{m}]");
    let mut list = Vec::new();
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
        let positions = accessor(doc, bin, pos, format!("{apath}.POSITION"))?;
        if positions.component != 5126 || positions.components != 3 {
            return Err(bad(
                Place::Json(format!("accessors[{pos}]")),
                "a POSITION accessor is of f32 VEC3",
            ));
        }
        let indices = match uint(prim, &path, "indices")? {
            Some(ix) => {
                let indices = accessor(doc, bin, ix, format!("{path}.indices"))?;
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
        let t = Triangles {
            pos,
            positions,
            indices,
        };
        let corners = t.corners();
        if corners % 3 != 0 {
            return Err(bad(
                Place::Json(path),
                format!("{corners} corners of triangles, not a multiple of 3"),
            ));
        }
        list.push(t);
    }
    Ok(list)
}

/// The triangles of one placement of a mesh, its `primitives` through `transform`, added to
/// `read`: the positions their indices use (each once), and their faces.
fn read_placed(read: &mut Read, primitives: &[Triangles], transform: &DMat4) -> Result<(), Error> {
    // A transform that mirrors turns the triangles inside out: their corners are
    // taken in the other order, so that they stay counter-clockwise seen from outside.
    let mirrored = transform.determinant() < 0.0;
    // The positions read for this placement: (accessor, element) to the index in
    // `read.positions`.
    let mut used: HashMap<(u64, usize), u32> = HashMap::new();
    for t in primitives {
        let (pos, positions) = (t.pos, &t.positions);
        let mut face = [0u32; 3];
        for c in 0..t.corners() {
            let i = match &t.indices {
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
            let v = *used.entry((pos, i)).or_insert_with(|| {
                let local = DVec3::from_array([0, 1, 2].map(|k| positions.get(i, k)));
                read.positions
                    .push(transform.transform_point3(local).to_array());
                next
            });
            face[c % 3] = v;
            if c % 3 == 2 {
                if mirrored {
                    face.swap(1, 2);
                }
                read.faces.push(face);
            }
        }
    }
    Ok(())
}

/// The meshes the file's scene places, each with its world transform: the nodes of the scene
/// `scene` names (or the first of `scenes`; or, without scenes, every node that is no node's
/// child) walked down their `children`, each node's transform (`matrix`, or `translation`,
/// `rotation` and `scale`) applied after its children's. A file without nodes places each of
/// its `meshes` as it is. The nodes must form trees, as glTF requires: a node reached twice
/// (a cycle, or two parents) is an error naming it, so the walk visits each node once.
fn placed(doc: &Json, meshes: usize) -> Result<Vec<(usize, DMat4)>, Error> {
    let nodes = match doc.get("nodes") {
        None => return Ok((0..meshes).map(|m| (m, DMat4::IDENTITY)).collect()),
        Some(Json::Array(nodes)) => nodes,
        Some(_) => return Err(bad(Place::Json("nodes".into()), "it is not an array")),
    };
    let index = |v: &Json, path: String| -> Result<usize, Error> {
        v.as_u64()
            .and_then(|i| usize::try_from(i).ok())
            .filter(|&i| i < nodes.len())
            .ok_or_else(|| {
                bad(
                    Place::Json(path),
                    format!("`{v}` is not a node (the file has {})", nodes.len()),
                )
            })
    };
    let list = |v: Option<&Json>, path: &str| -> Result<Vec<usize>, Error> {
        match v {
            None => Ok(Vec::new()),
            Some(Json::Array(items)) => items
                .iter()
                .enumerate()
                .map(|(i, x)| index(x, format!("{path}[{i}]")))
                .collect(),
            Some(_) => Err(bad(Place::Json(path.to_string()), "it is not an array")),
        }
    };
    let roots = match (doc.get("scene"), doc.get("scenes")) {
        (chosen, Some(Json::Array(scenes))) if !scenes.is_empty() => {
            let s = match chosen {
                None => 0,
                Some(v) => v
                    .as_u64()
                    .and_then(|i| usize::try_from(i).ok())
                    .filter(|&i| i < scenes.len())
                    .ok_or_else(|| {
                        bad(
                            Place::Json("scene".into()),
                            format!("`{v}` is not a scene (the file has {})", scenes.len()),
                        )
                    })?,
            };
            list(scenes[s].get("nodes"), &format!("scenes[{s}].nodes"))?
        }
        _ => {
            let mut child = vec![false; nodes.len()];
            for (n, node) in nodes.iter().enumerate() {
                for c in list(node.get("children"), &format!("nodes[{n}].children"))? {
                    child[c] = true;
                }
            }
            (0..nodes.len()).filter(|&n| !child[n]).collect()
        }
    };
    let mut seen = vec![false; nodes.len()];
    let mut out = Vec::new();
    let mut stack: Vec<(usize, DMat4)> = roots
        .into_iter()
        .rev()
        .map(|n| (n, DMat4::IDENTITY))
        .collect();
    while let Some((n, parent)) = stack.pop() {
        let path = format!("nodes[{n}]");
        if std::mem::replace(&mut seen[n], true) {
            return Err(bad(
                Place::Json(path),
                "the node is reached twice (glTF's nodes form trees: no cycles, one parent each)",
            ));
        }
        let node = &nodes[n];
        let world = parent * local(node, &path)?;
        if let Some(m) = uint(node, &path, "mesh")? {
            let m = usize::try_from(m)
                .ok()
                .filter(|&m| m < meshes)
                .ok_or_else(|| {
                    bad(
                        Place::Json(format!("{path}.mesh")),
                        format!("it names `meshes[{m}]`, which does not exist"),
                    )
                })?;
            out.push((m, world));
        }
        let children = list(node.get("children"), &format!("{path}.children"))?;
        stack.extend(children.into_iter().rev().map(|c| (c, world)));
    }
    Ok(out)
}

/// A node's own transform: its `matrix` (16 numbers, column by column), or its
/// `translation`, `rotation` (a quaternion x, y, z, w) and `scale`, applied scale first.
fn local(node: &Json, path: &str) -> Result<DMat4, Error> {
    let numbers = |key: &str, n: usize| -> Result<Option<Vec<f64>>, Error> {
        let Some(v) = node.get(key) else {
            return Ok(None);
        };
        let xs: Option<Vec<f64>> = v.as_array().filter(|a| a.len() == n).and_then(|a| {
            a.iter()
                .map(|x| x.as_f64().filter(|x| x.is_finite()))
                .collect()
        });
        xs.map(Some).ok_or_else(|| {
            bad(
                Place::Json(format!("{path}.{key}")),
                format!("it is not an array of {n} numbers"),
            )
        })
    };
    if let Some(m) = numbers("matrix", 16)? {
        let mut cols = [0.0; 16];
        cols.copy_from_slice(&m);
        return Ok(DMat4::from_cols_array(&cols));
    }
    let t = numbers("translation", 3)?.map_or(DVec3::ZERO, |v| DVec3::new(v[0], v[1], v[2]));
    let s = numbers("scale", 3)?.map_or(DVec3::ONE, |v| DVec3::new(v[0], v[1], v[2]));
    let r = match numbers("rotation", 4)? {
        None => DQuat::IDENTITY,
        Some(q) => {
            let q = DQuat::from_xyzw(q[0], q[1], q[2], q[3]);
            if q.length() < 1e-6 {
                return Err(bad(
                    Place::Json(format!("{path}.rotation")),
                    "a rotation is a unit quaternion; this one has length 0",
                ));
            }
            q.normalize()
        }
    };
    Ok(DMat4::from_scale_rotation_translation(s, r, t))
}
