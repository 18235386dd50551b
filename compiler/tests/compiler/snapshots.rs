//! Snapshot tests in the manner of naga's: small inputs, each showing one feature, whose
//! outputs a person can read (every snapshot within [`SNAPSHOT_LINES`], the folder within
//! [`ALL_SNAPSHOTS_LINES`]):
//! - `tests/in/ok` (one feature of the language each): the AST and the scene IR;
//! - `tests/in/feature` (one primitive, operator, blend, domain operation or transform each):
//!   the distance program and the WGSL part (`--part map`); for [`PTX_FEATURES`], which
//!   among them hold every operation of the program, the PTX of the distance over a buffer of
//!   points (`common/evaluators.rs`);
//! - `tests/in/kernel` (one feature of the renderer kernel each): the kernels of `base.sdf`
//!   (marched) and `analytic.sdf` (traced) whole, and every other as the difference from the
//!   kernel it extends ([`KERNELS`]);
//! - `tests/in/err` and `tests/in/warn`: the rendered diagnostics.
//!
//! Whole scenes are covered by behaviour, not text: every example and `tests/in/ok` file
//! checks, lowers, and its kernel and part validate with naga here; their images are compared
//! across backends in `image_conformance.rs` and their PTX assembled by `ptxas` in `ptx.rs`.

use crate::common;

use sdfc_compiler::{diagnostics, dump_ast, dump_ir, parse, points, wgsl, FileId, Lowered, Scene};
use std::path::{Path, PathBuf};

/// The most lines of one snapshot.
const SNAPSHOT_LINES: usize = 400;
/// The most lines of all snapshots together (raised from 15 000 by issue 33's primitives and
/// blends, about 2 300 lines of feature scenes, to 19 000 by issue 35's loft, screw, arc
/// and Bézier stroke, about 1 450, and to 19 500 by text's feature scene and errors, about 350
/// lines, most of them the WGSL that walks a text's outline, and to 19 800 by profiles written
/// as formulas (issue 35), their feature scene and three errors, about 250 lines), to 20 100
/// by the look and the sky (issue 49: the filtered checker, occlusion, fog, tone curves and
/// sky light in the kernels, about 100 lines, and the kernels of two feature scenes, about
/// 170), to 20 560 by the hull's feature scene, a tetrahedron, about 460 lines, and to
/// 20 620 by the physically based material's kernel (issue 49), about 150 lines, and its
/// range error with its help; 20 900 by the sweep's feature scene (a rectangle along a
/// polyline with one corner) and its warning, about 275 lines; 21 300 by the feature scene
/// of `hull(shapes…)` (two balls, about 380 lines) and its error (a box given to it).
const ALL_SNAPSHOTS_LINES: usize = 21_300;

/// The feature scenes whose distance over points is snapshotted as PTX: between them every
/// operation of the distance program (the sum of squares and square root of a sphere,
/// negation, rounding, exp and log, sin and cos, acos, atan2 and pow, comparison and
/// select of materials, and guarded blocks).
const PTX_FEATURES: &[&str] = &[
    "prim_sphere",
    "op_subtract",
    "repeat",
    "smooth_exp",
    "twist",
    "prim_mandelbulb_trig",
    "paint",
    "guard",
];

/// A kernel snapshot: the input file of `tests/in/kernel` and the writer's options.
type Written = (&'static str, Options);

/// Each kernel snapshot: its name, the kernel, and the kernel it is compared with (one
/// feature less), or none where it is snapshotted whole.
const KERNELS: &[(&str, Written, Option<Written>)] = &[
    ("base", ("base", Options::Default), None),
    (
        "relax",
        ("relax", Options::Default),
        Some(("base", Options::Default)),
    ),
    (
        "point",
        ("point", Options::Default),
        Some(("base", Options::Default)),
    ),
    (
        "directional",
        ("directional", Options::Default),
        Some(("base", Options::Default)),
    ),
    (
        "soft",
        ("soft", Options::Default),
        Some(("point", Options::Default)),
    ),
    (
        "materials",
        ("materials", Options::Default),
        Some(("base", Options::Default)),
    ),
    (
        "look",
        ("look", Options::Default),
        Some(("base", Options::Default)),
    ),
    (
        "sky",
        ("sky", Options::Default),
        Some(("base", Options::Default)),
    ),
    (
        "pbr",
        ("pbr", Options::Default),
        Some(("sky", Options::Default)),
    ),
    (
        "checker",
        ("checker", Options::Default),
        Some(("materials", Options::Default)),
    ),
    (
        "reflect",
        ("reflect", Options::Default),
        Some(("materials", Options::Default)),
    ),
    (
        "transparent",
        ("transparent", Options::Default),
        Some(("point", Options::Default)),
    ),
    (
        "refraction",
        ("refraction", Options::Default),
        Some(("materials", Options::Default)),
    ),
    (
        "media",
        ("media", Options::Default),
        Some(("refraction", Options::Default)),
    ),
    (
        "debug_nan",
        ("base", Options::DebugNan),
        Some(("base", Options::Default)),
    ),
    (
        "params",
        ("base", Options::Parameters),
        Some(("base", Options::Default)),
    ),
    ("analytic", ("analytic", Options::Default), None),
    (
        "analytic_data",
        ("analytic", Options::OneUnrolled),
        Some(("analytic", Options::Default)),
    ),
    (
        "instances_data",
        ("instances", Options::OneInstance),
        Some(("instances", Options::Default)),
    ),
];

/// The WGSL writer's options a kernel input needs.
#[derive(Debug, Clone, Copy)]
enum Options {
    Default,
    /// `debug_nan`.
    DebugNan,
    /// `parameters`.
    Parameters,
    /// `max_unrolled: 1`: the traced primitives read from `scene_data`.
    OneUnrolled,
    /// `max_instances: 1`: the instances walked in `scene_data`.
    OneInstance,
}

impl Options {
    fn get(self) -> wgsl::Options {
        let d = wgsl::Options::default();
        match self {
            Options::Default => d,
            Options::DebugNan => wgsl::Options {
                debug_nan: true,
                ..d
            },
            Options::Parameters => wgsl::Options {
                parameters: true,
                ..d
            },
            Options::OneUnrolled => wgsl::Options {
                max_unrolled: 1,
                ..d
            },
            Options::OneInstance => wgsl::Options {
                max_instances: 1,
                ..d
            },
        }
    }
}

/// The `.sdf` files directly inside `dir` (relative to this crate), sorted.
fn sdf_files(dir: &str) -> Vec<PathBuf> {
    common::sdf_files_in(Path::new(dir))
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

/// A scene file checked without errors.
fn load(path: &Path) -> Scene {
    let loaded = common::load(path).expect("readable");
    let rendered = diagnostics::render(&loaded.diagnostics, &loaded.sources, false);
    loaded
        .scene
        .unwrap_or_else(|| panic!("{} has errors:\n{rendered}", path.display()))
}

/// Every file of `dir` checks, lowers, and its kernel and part validate (naga, inside the
/// writers); with `text`, its AST and scene IR are snapshotted.
fn check_valid(dir: &str, prefix: &str, text: bool) {
    let files = sdf_files(dir);
    assert!(!files.is_empty(), "no .sdf files in {dir}");
    for path in files {
        let scene = load(&path);
        let lowered = Lowered::new(&scene);
        wgsl::write(&scene, &lowered).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        wgsl::part::write(&scene, &lowered, "map")
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        if text {
            let source = std::fs::read_to_string(&path).expect("readable");
            let (ast, diags) = parse(FileId(0), &source);
            assert!(diags.is_empty(), "{}: {diags:?}", path.display());
            let name = format!("{prefix}{}", stem(&path));
            snapshot("ast", &name, &dump_ast(&ast));
            snapshot("ir", &name, &dump_ir(&scene));
        }
    }
}

#[test]
fn examples_check_lower_and_validate() {
    check_valid("../examples", "", false);
}

#[test]
fn ok_inputs() {
    check_valid("tests/in/ok", "ok_", true);
}

/// Every `tests/in/err` file fails to compile; its source and rendered diagnostics are
/// snapshotted, and every error code the compiler can emit is produced by one of them.
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
        let loaded = common::load(&path).expect("readable");
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
    let mut emitted = std::collections::BTreeSet::new();
    common::codes_in(Path::new("src"), &mut emitted);
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
/// snapshotted, and it shows the code its first line names.
#[test]
fn warning_inputs() {
    let files = sdf_files("tests/in/warn");
    assert!(files.len() >= 4, "expected warning cases in tests/in/warn");
    for path in files {
        let loaded = common::load(&path).expect("readable");
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

/// Per feature scene: the distance program, the WGSL part, and for [`PTX_FEATURES`] the
/// PTX of the distance over points.
#[test]
fn features() {
    let files = sdf_files("tests/in/feature");
    for path in &files {
        let name = stem(path);
        let scene = load(path);
        let lowered = Lowered::new(&scene);
        let input = std::fs::read_to_string(path).expect("readable");
        let program = lowered.program.dump();
        snapshot("program", &name, &format!("{input}\n{program}"));
        // A scene with a mesh has no part: its triangles are a kernel's `scene_data`.
        if lowered.program.meshes().next().is_some() {
            continue;
        }
        let part = wgsl::part::write(&scene, &lowered, "map")
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        snapshot("part", &name, &part.source);
        if PTX_FEATURES.contains(&name.as_str()) {
            let m = points::points_module(&scene, &lowered, false)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            let ptx =
                points::points_ptx(&m, 70).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            snapshot("ptx", &name, &ptx);
        }
    }
    for name in PTX_FEATURES {
        assert!(
            files.iter().any(|f| stem(f) == *name),
            "no tests/in/feature/{name}.sdf"
        );
    }
}

/// The kernel of a `tests/in/kernel` input with the writer's options of its row.
fn kernel(name: &str, options: Options) -> wgsl::Kernel {
    let scene = load(&Path::new("tests/in/kernel").join(format!("{name}.sdf")));
    let lowered = Lowered::new(&scene);
    wgsl::write_with(&scene, &lowered, &options.get()).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The lines that differ between two texts, with two lines of context, as a unified diff.
fn diff(from: &str, to: &str, (a, b): (&str, &str)) -> String {
    similar::TextDiff::from_lines(from, to)
        .unified_diff()
        .context_radius(2)
        .header(a, b)
        .to_string()
}

/// Every kernel of [`KERNELS`], whole or as its difference from the kernel it extends; every
/// input of `tests/in/kernel` is written by some row.
#[test]
fn kernels() {
    for path in &sdf_files("tests/in/kernel") {
        let name = stem(path);
        assert!(
            KERNELS.iter().any(|(_, (file, _), _)| *file == name),
            "tests/in/kernel/{name}.sdf is in no row of KERNELS"
        );
    }
    for &(name, (file, options), from) in KERNELS {
        let new = kernel(file, options);
        let Some((from, from_options)) = from else {
            snapshot("kernel", name, &new.source);
            continue;
        };
        let old = kernel(from, from_options);
        let label = |file: &str, options: Options| match options {
            Options::Default => file.to_string(),
            other => format!("{file} ({other:?})"),
        };
        let text = diff(
            &old.source,
            &new.source,
            (&label(from, from_options), &label(file, options)),
        );
        assert!(!text.is_empty(), "{name}: the same kernel as {from}");
        snapshot("kernel", name, &text);
    }
}

/// Every snapshot stays short enough to read, and all of them together too.
#[test]
fn snapshots_stay_small() {
    let mut total = 0;
    let mut long = Vec::new();
    for folder in std::fs::read_dir("tests/compiler/snapshots").expect("tests/compiler/snapshots") {
        let folder = folder.expect("entry").path();
        for file in std::fs::read_dir(&folder).expect("folder") {
            let file = file.expect("entry").path();
            let lines = std::fs::read_to_string(&file)
                .expect("text")
                .lines()
                .count();
            total += lines;
            if lines > SNAPSHOT_LINES {
                long.push(format!("{} ({lines} lines)", file.display()));
            }
        }
    }
    assert!(
        long.is_empty(),
        "snapshots over {SNAPSHOT_LINES} lines: {long:?}"
    );
    assert!(
        total <= ALL_SNAPSHOTS_LINES,
        "{total} lines of snapshots, over {ALL_SNAPSHOTS_LINES}"
    );
}
