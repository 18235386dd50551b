//! The formatter over every `.sdf` file of the repository and every fuzz seed: formatting
//! is idempotent, and the formatted file means what the original did (the same diagnostics,
//! the same scene IR and distance program).

use sdfc_compiler::{
    check,
    format::{format, Error},
    LoadError, Loader, SourceMap,
};
use std::path::{Path, PathBuf};

/// Imports read from disk, relative to the importing file.
struct Disk;

impl Loader for Disk {
    fn load(&mut self, from: &str, path: &str) -> Result<(String, String), LoadError> {
        let p = Path::new(from)
            .parent()
            .unwrap_or(Path::new("."))
            .join(path);
        let text = std::fs::read_to_string(&p).map_err(|e| LoadError::Read {
            path: p.clone(),
            source: std::sync::Arc::new(e.into()),
        })?;
        Ok((p.to_string_lossy().into_owned(), text))
    }
}

/// What a file means: its diagnostics (code and message, in order), and when it checks,
/// its scene IR and distance program as text.
fn meaning(name: &str, text: &str) -> (Vec<String>, Option<(String, String)>) {
    let mut sources = SourceMap::new();
    let entry = sources.add(name, text);
    let (scene, diags) = check(&mut sources, entry, &mut Disk);
    let diags = diags
        .iter()
        .map(|d| format!("{} {}", d.code, d.message))
        .collect();
    let lowered = scene.map(|s| (sdfc_compiler::dump_ir(&s), sdfc_compiler::lower(&s).dump()));
    (diags, lowered)
}

fn sdf_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            sdf_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "sdf") {
            out.push(p);
        }
    }
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Formats `text` twice; returns the formatted text (`None` for a file with syntax errors).
fn idempotent(name: &str, text: &str) -> Option<String> {
    match format(text) {
        Ok(once) => {
            let twice = format(&once)
                .unwrap_or_else(|e| panic!("{name}: the formatted text does not format: {e}"));
            assert_eq!(twice, once, "{name}: formatting is not idempotent");
            Some(once)
        }
        Err(Error::Syntax(_)) => None,
        Err(e) => panic!("{name}: {e}"),
    }
}

/// Formats `text` (as [`idempotent`] does) and checks that the formatted text means what
/// `text` does; whether it formatted (not a file with syntax errors).
fn keeps_meaning(name: &str, text: &str) -> bool {
    let Some(out) = idempotent(name, text) else {
        return false;
    };
    if out != text {
        assert_eq!(
            meaning(name, &out),
            meaning(name, text),
            "{name}: formatting changed the meaning\n{out}"
        );
    }
    true
}

#[test]
fn every_sdf_file_formats_idempotently_and_keeps_its_meaning() {
    let mut files = Vec::new();
    for dir in [
        "examples",
        "compiler/tests",
        "runtime/tests",
        "bench",
        "grammar",
        "docs",
    ] {
        sdf_files(&root().join(dir), &mut files);
    }
    files.sort();
    assert!(files.len() > 200, "found {} files", files.len());
    let mut formatted = 0;
    for path in &files {
        let name = path.to_string_lossy().into_owned();
        let text = std::fs::read_to_string(path).expect("read");
        if keeps_meaning(&name, &text) {
            formatted += 1;
        }
    }
    // The files with syntax errors are the test inputs of E01xx and the lexer's.
    assert!(
        formatted * 10 > files.len() * 7,
        "{formatted} of {}",
        files.len()
    );
}

#[test]
fn every_fuzz_seed_formats_idempotently_and_keeps_its_meaning() {
    let mut seeds = Vec::new();
    for target in ["check", "front_end", "kernel"] {
        if let Ok(entries) = std::fs::read_dir(root().join("fuzz/seeds").join(target)) {
            seeds.extend(entries.flatten().map(|e| e.path()));
        }
    }
    seeds.sort();
    assert!(!seeds.is_empty());
    let mut formatted = 0;
    for path in &seeds {
        let Ok(text) = std::fs::read_to_string(path) else {
            continue;
        };
        let name = path.to_string_lossy().into_owned();
        if keeps_meaning(&name, &text) {
            formatted += 1;
        }
    }
    println!("{formatted} of {} seeds formatted", seeds.len());
}
