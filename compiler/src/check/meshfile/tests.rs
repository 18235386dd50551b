//! The mesh readers' tests: each format read, and hostile files (counts that lie, offsets
//! near 2⁶⁴, truncations) refused with their place.

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

/// The sample glTF with `nodes` (and `scenes`, where given) added, read within `max`.
fn glb_placed(nodes: &str, max: u64) -> Result<Read, Error> {
    glb_edited(r#""meshes":"#, &format!(r#"{nodes},"meshes":"#), max)
}

/// Each node that names a mesh places it through its transform and its ancestors':
/// translation, rotation, scale and matrix; a mirroring transform keeps the triangles
/// counter-clockwise seen from outside.
#[test]
fn glb_nodes_place_their_meshes() {
    let r = |x: &[[f64; 3]]| {
        x.iter()
            .map(|p| p.map(|c| (c * 1e9).round() / 1e9))
            .collect::<Vec<_>>()
    };
    // A translated copy and a mirrored one, the scene's two nodes.
    let got = glb_placed(
        r#""scenes":[{"nodes":[0,1]}],"nodes":[{"mesh":0,"translation":[1,2,3]},{"mesh":0,"scale":[-1,1,1]}]"#,
        100,
    )
    .unwrap();
    assert_eq!(
        r(&got.positions),
        [
            [1.0, 2.0, 3.0],
            [2.0, 2.0, 3.0],
            [1.0, 3.0, 3.0],
            [0.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0]
        ]
    );
    assert_eq!(got.faces, [[0, 1, 2], [3, 5, 4]]);
    // A child's rotation (a quarter turn about z) inside its parent's translation.
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let got = glb_placed(
        &format!(r#""nodes":[{{"translation":[1,0,0],"children":[1]}},{{"mesh":0,"rotation":[0,0,{h},{h}]}}]"#),
        100,
    )
    .unwrap();
    assert_eq!(
        r(&got.positions),
        [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 0.0]]
    );
    // A matrix, column by column; `scene` picks the second scene.
    let got = glb_placed(
        r#""scene":1,"scenes":[{"nodes":[0]},{"nodes":[1]}],"nodes":[{"mesh":0},{"mesh":0,"matrix":[2,0,0,0, 0,2,0,0, 0,0,2,0, 5,0,0,1]}]"#,
        100,
    )
    .unwrap();
    assert_eq!(
        r(&got.positions),
        [[5.0, 0.0, 0.0], [7.0, 0.0, 0.0], [5.0, 2.0, 0.0]]
    );
    // Without nodes, the meshes as they are (the sample itself).
    assert_eq!(
        read(Format::Glb, &glb_bytes(2, GLB_JSON, &glb_bin()), 100)
            .unwrap()
            .faces
            .len(),
        1
    );
}

/// Nodes that do not form trees, name what does not exist or hold transforms that are not
/// numbers are errors naming the member; every placement counts against the limit.
#[test]
fn bad_glb_nodes_are_located_errors() {
    let message = |nodes: &str, max: u64| glb_placed(nodes, max).unwrap_err().to_string();
    let cycle = message(
        r#""scenes":[{"nodes":[0]}],"nodes":[{"children":[1]},{"children":[0],"mesh":0}]"#,
        100,
    );
    assert!(
        cycle.contains("`nodes[0]`") && cycle.contains("reached twice"),
        "{cycle}"
    );
    let shared = message(
        r#""nodes":[{"children":[2]},{"children":[2]},{"mesh":0}]"#,
        100,
    );
    assert!(
        shared.contains("`nodes[2]`") && shared.contains("reached twice"),
        "{shared}"
    );
    let child = message(r#""nodes":[{"children":[7]}]"#, 100);
    assert!(
        child.contains("`nodes[0].children[0]`") && child.contains("not a node"),
        "{child}"
    );
    let mesh = message(r#""nodes":[{"mesh":3}]"#, 100);
    assert!(mesh.contains("`nodes[0].mesh`"), "{mesh}");
    let matrix = message(r#""nodes":[{"mesh":0,"matrix":[1,0,0]}]"#, 100);
    assert!(
        matrix.contains("`nodes[0].matrix`") && matrix.contains("16 numbers"),
        "{matrix}"
    );
    let rotation = message(r#""nodes":[{"mesh":0,"rotation":[0,0,0,0]}]"#, 100);
    assert!(rotation.contains("`nodes[0].rotation`"), "{rotation}");
    let scene = message(
        r#""scene":4,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}]"#,
        100,
    );
    assert!(scene.contains("`scene`"), "{scene}");
    match glb_placed(
        r#""nodes":[{"mesh":0},{"mesh":0,"translation":[3,0,0]}]"#,
        1,
    ) {
        Err(Error::Limit {
            triangles: 2,
            max: 1,
            ..
        }) => {}
        other => panic!("{other:?}"),
    }
}
