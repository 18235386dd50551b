//! The checker's memory on inputs built to exhaust it: a counting global allocator records
//! the peak of live heap bytes while the checker runs through the library, which must stay
//! within a small multiple of the input (a long list passed to a function call after call,
//! a literal list of millions of elements, a mesh file whose triangles are far past the
//! `triangles` limit), where each of these took gigabytes.
//!
//! The counter sees every thread of the process, so the test measures alone
//! ([`counting::alone`]).

use sdfc_compiler::{
    check_str, check_with, has_errors, Diagnostic, Limits, LoadError, Loader, SourceMap,
};

use crate::counting;
use counting::peak_of;

const MB: u64 = 1 << 20;

/// A loader with one mesh file, held in memory.
struct One(Vec<u8>);

impl Loader for One {
    fn load(&mut self, _from: &str, path: &str) -> Result<(String, String), LoadError> {
        Err(LoadError::NoImports { path: path.into() })
    }

    fn load_bytes(&mut self, _from: &str, path: &str) -> Result<(String, Vec<u8>), LoadError> {
        Ok((path.to_string(), self.0.clone()))
    }
}

/// The diagnostics of a scene reading `name` (holding `bytes`), and the peak of live heap
/// bytes while it was checked.
fn check_mesh(name: &str, bytes: Vec<u8>) -> (Vec<Diagnostic>, u64) {
    let mut loader = One(bytes);
    let mut sources = SourceMap::new();
    let entry = sources.add("m.sdf", format!("scene {{ mesh(\"{name}\"); }}"));
    let ((_, diags), peak) =
        peak_of(|| check_with(&mut sources, entry, &mut loader, &Limits::default()));
    (diags, peak)
}

/// [`check_mesh`] of `bytes`, whose error must say that the file has `triangles` triangles:
/// the file's size and the peak.
#[track_caller]
fn refused_mesh(name: &str, bytes: Vec<u8>, triangles: u64) -> (u64, u64) {
    let input = bytes.len() as u64;
    let (diags, peak) = check_mesh(name, bytes);
    let says = format!("the file has {triangles} triangles");
    assert!(
        diags.iter().any(|d| d.message.contains(&says)),
        "{diags:#?}"
    );
    (input, peak)
}

#[test]
fn hostile_inputs_are_checked_in_memory_proportional_to_them() {
    let _alone = counting::alone();
    // A list of 20 000 elements passed to a function in a loop: each call's arguments made
    // the key of the memo of calls as text (200 KB a call, 4.46 GB in all); a list of ints
    // passed where floats are expected was copied at every call.
    for elem in ["i * 1.0", "i"] {
        let src = format!(
            "let xs = [for i in 0..20000 {{ {elem} }}];\n\
             fn f(l: [float], i: int) -> float {{ l[i] }}\n\
             let total = [for i in 0..20000 {{ f(xs, i) }}];\n\
             scene {{ sphere(total[19999] + 1); }}\n"
        );
        let ((scene, diags, _), peak) = peak_of(|| check_str("list.sdf", &src));
        assert!(!has_errors(&diags), "{diags:#?}");
        assert!(scene.is_some());
        assert!(peak < 32 * MB, "`{elem}`: a peak of {} MB", peak / MB);
    }

    // A literal list of two million elements: refused at the `objects` limit before it is
    // parsed, holding the text and the tokens up to the limit (the syntax tree of the whole
    // list took 1.5 GB for 29 MB).
    let src = format!(
        "let xs = [{}];\nscene {{ sphere(1); }}\n",
        vec!["1.5"; 2_000_000].join(", ")
    );
    let ((_, diags, _), peak) = peak_of(|| check_str("big.sdf", &src));
    assert!(diags.iter().any(|d| d.code == "E0507"), "{diags:#?}");
    let input = src.len() as u64;
    // The text's copy in the source map, and 200 000 tokens and their vector's growth.
    assert!(
        peak < 2 * input + 32 * MB,
        "a peak of {} MB for {} MB of text",
        peak / MB,
        input / MB
    );

    // An OBJ face of 5 million corners: fanned as it is read and, past the `triangles`
    // limit, only counted (its corners and triangles were held before the limit was
    // checked).
    let mut obj = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nf");
    for k in 0..5_000_000 {
        obj.push_str([" 1", " 2", " 3"][k % 3]);
    }
    let (input, peak) = refused_mesh("face.obj", obj.into_bytes(), 4999998);
    // The file's copy from the loader, and the triangles kept up to the limit (800 000 of
    // 12 bytes) with their vector's growth.
    assert!(
        peak < 2 * input + 24 * MB,
        "a peak of {} MB for {} MB of OBJ",
        peak / MB,
        input / MB
    );

    // A glTF file of 900 000 triangles' positions (32 MB) and no indices: its triangles are
    // counted against the limit before any position is read.
    let count = 2_700_000;
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],"bufferViews":[{{"buffer":0,"byteLength":{}}}],"accessors":[{{"bufferView":0,"componentType":5126,"count":{count},"type":"VEC3"}}]}}"#,
        12 * count
    );
    let glb = crate::glb::glb(&json, &vec![0u8; 12 * count]);
    let (input, peak) = refused_mesh("big.glb", glb, 900000);
    assert!(
        peak < input + 8 * MB,
        "a peak of {} MB for {} MB of glTF",
        peak / MB,
        input / MB
    );
}
