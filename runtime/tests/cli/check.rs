//! `sdfc check`: diagnostics as text and JSON, imports, the intersection method it reports,
//! `--verify-bounds`, and scenes built to exhaust the checker and the lowering within their limits.

use crate::cli::{dir, entries, exits, ok, put, scene_dir, sdfc, SCENE};
use crate::common::assert_has;
use crate::common::words;

#[test]
fn json_diagnostics_and_io_errors_go_to_stdout() {
    let d = dir("json");
    put(&d, "bad.sdf", "scene { sphre(1); }\n");
    let out = sdfc(
        &d,
        &["check", "--diagnostics", "json", "bad.sdf", "nope.sdf"],
    );
    // The worst of the files: one could not be read.
    assert_eq!(out.status.code(), Some(2));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<serde_json::Value> = stdout
        .lines()
        .map(|l| serde_json::from_str(l).expect("each line is JSON"))
        .collect();
    assert!(
        lines.iter().any(|v| v["severity"] == "error"
            && v["labels"][0]["file"]
                .as_str()
                .is_some_and(|f| f.ends_with("bad.sdf"))),
        "{stdout}"
    );
    let io = lines
        .iter()
        .find(|v| v["code"] == "io")
        .expect("the IO error");
    assert!(
        io["message"]
            .as_str()
            .is_some_and(|m| m.contains("cannot read `nope.sdf`")),
        "{io}"
    );
    assert!(
        !String::from_utf8_lossy(&out.stderr).contains("cannot read"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A library imported by its path and through a symbolic link to it is read once (no
/// duplicate definitions).
#[cfg(unix)]
#[test]
fn a_library_imported_through_a_symbolic_link_is_read_once() {
    let d = dir("symlink");
    std::fs::create_dir(d.join("lib")).expect("dir");
    put(&d, "lib/shapes.sdf", "let r = 1;\n");
    std::os::unix::fs::symlink("lib/shapes.sdf", d.join("alias.sdf")).expect("link");
    std::os::unix::fs::symlink("lib", d.join("linked")).expect("link");
    put(&d, "main.sdf", "import \"lib/shapes.sdf\";\nimport \"alias.sdf\";\nimport \"linked/shapes.sdf\";\nscene { sphere(r); }\n");
    let err = exits(&d, &["check", "main.sdf"], 0);
    assert!(!err.contains("E0207"), "{err}");
}

/// A one-line file with 20 000 duplicate definitions: the human form shows the first 100
/// diagnostics, each with an excerpt of the line, and counts the rest; checking stops after
/// 1 000 errors and says so.
#[test]
fn twenty_thousand_errors_on_one_line_are_capped() {
    let d = dir("many");
    let text = format!("{}scene {{ sphere(a); }}", "let a = 1; ".repeat(20_000));
    put(&d, "many.sdf", text);
    let out = sdfc(&d, &["check", "many.sdf"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(err.len() < 200_000, "{} bytes of diagnostics", err.len());
    assert_eq!(err.matches("error[E0207]").count(), 100);
    assert!(
        err.contains("… and 900 more diagnostics (900 errors) not shown; the first 100 are above; checking stopped after these"),
        "{}",
        &err[err.len().saturating_sub(400)..]
    );
}

#[test]
fn an_unreadable_import_is_a_diagnostic() {
    let d = dir("import");
    put(&d, "lib.sdf", b"let r = 1; // caf\xe9\n");
    put(
        &d,
        "main.sdf",
        "import \"lib.sdf\";\nscene { sphere(r); }\n",
    );
    let out = sdfc(&d, &["check", "main.sdf"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_has(&err, &["E0501", "not valid UTF-8"]);
}

/// `sdfc check` says which intersection method a scene gets and why; `--set method=trace`
/// on a scene that does not allow it is an error that writes nothing.
#[test]
fn the_method_setting_and_what_check_says_about_it() {
    let d = scene_dir("method");
    let out = sdfc(&d, &["check", "ball.sdf"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_has(&err, &["method: march (light 1 casts soft shadows"]);
    let err = exits(&d, &["render", "ball.sdf", "--set", "method=trace"], 1);
    assert_has(&err, &["cannot be ray traced analytically"]);
    let out = sdfc(&d, &["render", "ball.sdf", "--set", "method=fast"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("method must be one of"));
    assert_eq!(entries(&d), ["ball.sdf"]);
    put(
        &d,
        "hard.sdf",
        SCENE.replace("penumbra: 7.125deg", "penumbra: 0deg"),
    );
    let out = sdfc(&d, &["check", "hard.sdf"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_has(&err, &["method: trace (2 primitives"]);
    let out = sdfc(
        &d,
        &["render", "hard.sdf", "--set", "method=trace", "--stats"],
    );
    assert_eq!(out.status.code(), Some(0));
    assert!(d.join("hard.png").exists());
}

/// The 42-line file of issue 16, item 1: forty functions, each using the one below twice,
/// make 2⁴⁰ spheres as a tree from a graph of 121 nodes. Every pass that walked the scene
/// as a tree (the method choice, simplification, lowering) hung on it; now the checker
/// counts the tree once per node and stops at the `expansion` limit.
fn exponential(levels: usize) -> String {
    let mut text = String::from("fn f0() -> shape { sphere(0.1) }\n");
    for i in 1..=levels {
        let j = i - 1;
        text.push_str(&format!(
            "fn f{i}() -> shape {{ union(f{j}().translate(0.001, 0, 0), f{j}().translate(0, 0.001, 0)) }}\n"
        ));
    }
    text.push_str(&format!("scene {{ f{levels}(); }}\n"));
    text
}

#[test]
fn exponential_expansion_is_a_located_limit_error_in_well_under_a_second() {
    let d = dir("expansion");
    put(&d, "exp.sdf", exponential(40));
    assert_eq!(exponential(40).lines().count(), 42);
    let start = std::time::Instant::now();
    let out = sdfc(&d, &["check", "exp.sdf"]);
    let took = start.elapsed();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    // At the union of f20, the first level whose tree (2²² − 3 nodes) is over 4 000 000.
    assert_has(&err, &["E0507", "exp.sdf:21:", "--limit expansion="]);
    assert!(took.as_secs_f64() < 1.0, "took {took:?}");
    // Raised, the same limit lets a smaller tree through; lowered, it stops a small one.
    put(&d, "small.sdf", exponential(8));
    ok(&d, &["check", "small.sdf"]);
    let low = sdfc(&d, &["check", "small.sdf", "--limit", "expansion=100"]);
    assert_eq!(low.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&low.stderr).contains("--limit expansion="));
}

/// issue 16, item 2: the `program` limit, counted by the builder as it emits, on a scene of
/// 2¹⁴ distinct spheres (within the `expansion` limit): an E0507 error and no output. (That
/// lowering stops at the limit is `lowering_stops_at_the_program_limit` in
/// `compiler/src/lower/tests.rs`.)
#[test]
fn the_program_limit_stops_lowering_at_the_limit() {
    let mut text = String::from("fn f0() -> shape { sphere(0.004) }\n");
    for i in 1..=14 {
        let (j, o) = (i - 1, f64::from(1u32 << i) * 1e-3);
        text.push_str(&format!(
            "fn f{i}() -> shape {{ union(f{j}().translate({o}, 0, 0), f{j}().translate(0, 0, {o})) }}\n"
        ));
    }
    text.push_str("scene { f14(); }\n");
    let d = dir("program-limit");
    put(&d, "big.sdf", text);
    let err = exits(
        &d,
        &words("compile big.sdf --emit program --limit program=1000 -o p.txt"),
        1,
    );
    assert_has(
        &err,
        &["E0507", "more than 1000 operations", "--limit program=2000"],
    );
    assert!(!d.join("p.txt").exists());
    ok(
        &d,
        &["compile", "big.sdf", "--emit", "program", "-o", "p.txt"],
    );
}

/// `sdfc check --verify-bounds`: a field whose declared L is too small is reported at its
/// place with exit 1; fields whose bounds hold (declared or derived) pass.
#[test]
fn check_verify_bounds_reports_a_field_steeper_than_its_bound() {
    let d = dir("verify-bounds");
    put(
        &d,
        "steep.sdf",
        "scene {\n  field(lipschitz: 1) { 3 * (length(p) - 1) };\n}\n",
    );
    put(&d, "fine.sdf", "scene {\n  field { 2 * (length(p) - 1) };\n  field(lipschitz: 3) { 3 * (length(p) - 1) }.translate(3, 0, 0);\n}\n");
    let err = exits(&d, &["check", "--verify-bounds", "steep.sdf"], 1);
    assert_has(
        &err,
        &[
            "steep.sdf:2:3: this field has a slope of",
            "above its L = 1",
        ],
    );
    let err = exits(&d, &["check", "--verify-bounds", "fine.sdf"], 0);
    assert_has(
        &err,
        &["bounds sampled, not proven: 2 field(s), none steeper than its L"],
    );
    assert!(!err.contains("verified"), "{err}");
    // A profile is named as one.
    put(
        &d,
        "flat.sdf",
        "scene {\n  revolve(profile(lipschitz: 0.1) { length(p) - 0.5 });\n}\n",
    );
    let err = exits(&d, &["check", "--verify-bounds", "flat.sdf"], 1);
    assert_has(&err, &["flat.sdf:2:11: this profile has a slope of"]);
}

/// `--verify-bounds` samples the whole of the scene's bounded region, in each field's own
/// coordinates, not only near the camera's target: a field steeper than its L only 6 units
/// and more from the target, inside the box it is cut to, is caught; the output names the
/// boxes sampled and the pairs of points, and where an unbounded scene was clipped.
#[test]
fn check_verify_bounds_samples_the_scene_and_says_where() {
    let d = dir("verify-bounds-far");
    put(&d, "far.sdf", "camera { position: (0, 0, -5), look_at: (0, 0, 0) }\nscene {\n  intersect(field(lipschitz: 1) { length(p) - 1 + 0.5 * max(p.x - 6, 0) }, box(9));\n}\n");
    let err = exits(&d, &["check", "--verify-bounds", "far.sdf"], 1);
    assert_has(
        &err,
        &["far.sdf:3:13: this field has a slope of", "above its L = 1"],
    );
    assert!(
        err.contains(
            "found in 20000 pairs of points over the scene's box [(-9, -9, -9), (9, 9, 9)]"
        ),
        "{err}"
    );
    assert!(!err.contains("verified"), "{err}");
    // A scene unbounded along every axis: sampled within max_dist of the camera, and said so.
    put(&d, "open.sdf", "camera { position: (0, 0, -5), look_at: (0, 0, 0) }\nrender { max_dist: 50 }\nscene {\n  field { length(p) - 1 };\n  field { p.x * p.y };\n}\n");
    let err = exits(&d, &["check", "--verify-bounds", "open.sdf"], 0);
    assert_has(&err, &["open.sdf:4:3: this field: no slope above its L = 1 in 20000 pairs of points over the scene's box [(-50, -50, -55), (50, 50, 45)]"]);
    assert_has(
        &err,
        &["open.sdf:5:3: this field has no declared or proven L: nothing to sample"],
    );
    assert_has(&err, &["the scene is unbounded along x, y, z, sampled within max_dist = 50 of the camera there, and not beyond"]);
}

/// 10 000 nested `union(…)` with the `nesting` limit raised, as the error suggests, check
/// without overflowing the stack (the parser and the checker run on a stack grown to fit).
#[test]
fn ten_thousand_nested_unions_check_with_the_limit_raised() {
    let d = dir("nested");
    let n = 10_000;
    let text = format!(
        "scene {{ {}sphere(1){}; }}\n",
        "union(sphere(1), ".repeat(n),
        ")".repeat(n)
    );
    put(&d, "deep.sdf", text);
    let err = exits(&d, &["check", "deep.sdf"], 1);
    assert_has(&err, &["`--limit nesting=2000`"]);
    let err = exits(&d, &["check", "deep.sdf", "--limit", "nesting=20000"], 0);
    assert_has(&err, &["deep.sdf: ok"]);
}
