//! Snapshot tests of every textual output: the AST, IR, distance program and WGSL kernel of
//! every example and `tests/in/ok` file, the PTX of every example (for the default target,
//! sm_70), and the rendered diagnostics of every `tests/in/err` and `tests/in/warn` file.
//! Every WGSL kernel is also validated by naga (inside `back::wgsl::write`).

mod common;

use sdfc_compiler::lower::Lowered;
use sdfc_compiler::{back, diagnostics, scene, syntax, FileId};
use sdfc_runtime::frontend;
use std::path::{Path, PathBuf};

/// The `.sdf` files directly inside `dir` (relative to the workspace root), sorted.
fn sdf_files(dir: &str) -> Vec<PathBuf> {
    let root = Path::new("..");
    let mut files: Vec<PathBuf> = std::fs::read_dir(root.join(dir))
        .unwrap_or_else(|e| panic!("cannot list {dir}: {e}"))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "sdf"))
        .collect();
    files.sort();
    files
}

fn stem(p: &Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

fn snapshot(folder: &str, name: &str, text: &str) {
    insta::with_settings!({
        snapshot_path => format!("snapshots/{folder}"),
        prepend_module_to_snapshot => false,
        omit_expression => true,
    }, {
        insta::assert_snapshot!(name.to_string(), text);
    });
}

/// Snapshots every file of `dir`; with `ptx`, its PTX kernel too.
fn check_valid(dir: &str, prefix: &str, ptx: bool) {
    let files = sdf_files(dir);
    assert!(!files.is_empty(), "no .sdf files in {dir}");
    for path in files {
        let loaded = frontend::load(&path).expect("readable");
        let rendered = diagnostics::render(&loaded.diagnostics, &loaded.sources, false);
        let scene = loaded
            .scene
            .unwrap_or_else(|| panic!("{} has errors:\n{rendered}", path.display()));
        let (ast, diags) = syntax::parse(FileId(0), loaded.sources.text(FileId(0)));
        assert!(diags.is_empty(), "{}: {diags:?}", path.display());
        let name = format!("{prefix}{}", stem(&path));
        snapshot("ast", &name, &syntax::dump(&ast));
        snapshot("ir", &name, &scene::dump(&scene));
        let lowered = Lowered::new(&scene);
        snapshot("program", &name, &lowered.program.dump());
        let kernel = back::wgsl::write(&scene, &lowered)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        snapshot("wgsl", &name, &kernel.source);
        if ptx {
            let options = back::ptx::Options::default();
            let text = back::ptx::write(&kernel.module, &kernel.info, &options)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
                .text;
            snapshot("ptx", &name, &text);
        }
    }
}

#[test]
fn examples() {
    check_valid("examples", "", true);
}

#[test]
fn ok_inputs() {
    check_valid("tests/in/ok", "ok_", false);
}

#[test]
fn error_inputs() {
    let files = sdf_files("tests/in/err");
    assert!(
        files.len() >= 40,
        "expected at least 40 error cases, found {}",
        files.len()
    );
    let mut codes = std::collections::BTreeSet::new();
    for path in files {
        let loaded = frontend::load(&path).expect("readable");
        assert!(
            loaded.scene.is_none(),
            "{} compiled without errors",
            path.display()
        );
        assert!(diagnostics::has_errors(&loaded.diagnostics));
        codes.extend(loaded.diagnostics.iter().map(|d| d.code));
        let source = loaded.sources.text(FileId(0));
        let rendered = diagnostics::render(&loaded.diagnostics, &loaded.sources, false);
        snapshot(
            "err",
            &stem(&path),
            &format!("{source}\n----- diagnostics -----\n{rendered}"),
        );
    }
    // Every error code the compiler can emit has an input here that produces it.
    let mut emitted = std::collections::BTreeSet::new();
    common::codes_in(Path::new("../compiler/src"), &mut emitted);
    let missing: Vec<&String> = emitted
        .iter()
        .filter(|c| c.starts_with('E') && !codes.contains(c.as_str()))
        .collect();
    assert!(
        emitted.len() > 30 && missing.is_empty(),
        "no file in tests/in/err produces the error codes {missing:?}"
    );
}

/// Every `tests/in/warn` file compiles with warnings and no error; its rendered warnings are
/// snapshotted, and it shows the code its name promises in its first line.
#[test]
fn warning_inputs() {
    let files = sdf_files("tests/in/warn");
    assert!(files.len() >= 4, "expected warning cases in tests/in/warn");
    for path in files {
        let loaded = frontend::load(&path).expect("readable");
        let rendered = diagnostics::render(&loaded.diagnostics, &loaded.sources, false);
        assert!(
            loaded.scene.is_some(),
            "{} has errors:\n{rendered}",
            path.display()
        );
        let source = loaded.sources.text(FileId(0));
        let first = source.lines().next().unwrap_or_default();
        assert!(
            loaded
                .diagnostics
                .iter()
                .any(|d| first.contains(&format!("({})", d.code))),
            "{}: no warning with the code its first line names:\n{rendered}",
            path.display()
        );
        snapshot(
            "warn",
            &stem(&path),
            &format!("{source}\n----- diagnostics -----\n{rendered}"),
        );
    }
}

#[test]
fn json_diagnostics_are_one_object_per_line() {
    let (_, diags, sources) =
        sdfc_compiler::check::check_str("t.sdf", "scene { spher(1); sphere(-1); }");
    let json = diagnostics::to_json(&diags, &sources);
    let lines: Vec<&str> = json.lines().collect();
    assert_eq!(lines.len(), 2);
    let first: serde_json::Value = serde_json::from_str(lines[0]).expect("valid JSON");
    assert_eq!(first["code"], "E0201");
    assert_eq!(first["labels"][0]["line"], 1);
    assert_eq!(first["labels"][0]["column"], 9);
}
