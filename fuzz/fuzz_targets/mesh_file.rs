//! Fuzz target: any bytes as a mesh file of each format (STL, OBJ, PLY, binary glTF)
//! through its reader, and as the file of a scene's `mesh(path)` through the checker (the
//! first byte picks the format), within a small `triangles` limit. Nothing may panic, hang
//! or allocate beyond what the bytes and the limit allow.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sdfc_compiler::meshfile::{read, Format};
use sdfc_compiler::{check_with, Limit, Limits, LoadError, Loader, SourceMap};

const FORMATS: [(Format, &str); 4] = [
    (Format::Stl, "stl"),
    (Format::Obj, "obj"),
    (Format::Ply, "ply"),
    (Format::Glb, "glb"),
];

/// The limit of the fuzzed files' triangles: enough for every seed, small enough that a
/// mesh of that many builds quickly under the fuzzer's instrumentation.
const TRIANGLES: u64 = 10_000;

/// A loader with one mesh file, `bytes`.
struct One<'a>(&'a [u8]);

impl Loader for One<'_> {
    fn load(&mut self, _from: &str, path: &str) -> Result<(String, String), LoadError> {
        Err(LoadError::NoImports { path: path.into() })
    }

    fn load_bytes(&mut self, _from: &str, path: &str) -> Result<(String, Vec<u8>), LoadError> {
        Ok((path.to_string(), self.0.to_vec()))
    }
}

fuzz_target!(|data: &[u8]| {
    let Some((&pick, bytes)) = data.split_first() else {
        return;
    };
    for (format, _) in FORMATS {
        if let Ok(r) = read(format, bytes, TRIANGLES) {
            assert!(r.faces.len() as u64 <= TRIANGLES);
            // A reader holds no more positions than its bytes could give (three per
            // triangle for the formats that weld or read only what triangles use).
            assert!(r.positions.len() <= bytes.len().max(3 * r.faces.len()));
        }
    }
    let (_, ext) = FORMATS[pick as usize % FORMATS.len()];
    let mut limits = Limits::default();
    limits
        .set(Limit::Triangles, TRIANGLES)
        .expect("a valid limit");
    let mut sources = SourceMap::new();
    let text = format!("scene {{ mesh(\"m.{ext}\"); }}");
    let entry = sources.add("fuzz.sdf", &text);
    let (_scene, diags) = check_with(&mut sources, entry, &mut One(bytes), &limits);
    let _ = sdfc_compiler::diagnostics::render(&diags, &sources, false);
});
