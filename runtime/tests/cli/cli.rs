//! The `sdfc render`, `sdfc bench` and `sdfc fmt` commands: outputs, atomic writes, settings
//! overrides and exit codes (1 for errors in the scene, 2 for usage and IO problems).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const SCENE: &str = "material red = phong { color: (1, 0.2, 0.1), reflect: 0.2 };
camera { position: (0, 1, -5), look_at: (0, 0, 0), fov: 50deg }
light point { position: (2, 4, -3), intensity: 1, radius: 50, penumbra: 7.125deg }
render { width: 40, height: 30 }
scene {
  plane() ;
  sphere(1).translate(0, 1, 0) @ red;
}
";

/// A fresh directory for one test.
fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sdfc-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

fn sdfc(cwd: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(cwd)
        .args(args)
        .output()
        .expect("run sdfc")
}

fn scene_file(d: &Path) -> PathBuf {
    let p = d.join("ball.sdf");
    std::fs::write(&p, SCENE).expect("write scene");
    p
}

fn entries(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .expect("read dir")
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn png_size(p: &Path) -> (u32, u32) {
    let bytes = std::fs::read(p).expect("png");
    assert_eq!(&bytes[1..4], b"PNG");
    let be = |o: usize| u32::from_be_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
    (be(16), be(20))
}

#[test]
fn render_writes_the_default_output_in_the_current_directory() {
    let d = dir("default");
    scene_file(&d);
    let out = sdfc(&d, &["render", "ball.sdf", "--stats"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(png_size(&d.join("ball.png")), (40, 30));
    assert_eq!(
        entries(&d),
        ["ball.png", "ball.sdf"],
        "no temporary file left"
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("steps/pixel") && stdout.contains("overshoots"),
        "{stdout}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn size_aa_set_and_output_options() {
    let d = dir("options");
    scene_file(&d);
    let out = sdfc(
        &d,
        &[
            "render",
            "ball.sdf",
            "--size",
            "24x16",
            "--aa",
            "2",
            "--set",
            "max_steps=64",
            "--set",
            "epsilon=1e-3",
            "-o",
            "x.png",
            "--precision",
            "f64",
            "--threads",
            "1",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(png_size(&d.join("x.png")), (24, 16));
    let out = sdfc(
        &d,
        &[
            "render", "ball.sdf", "--set", "width=8", "--set", "height=6", "-o", "y.png",
        ],
    );
    assert!(out.status.success());
    assert_eq!(png_size(&d.join("y.png")), (8, 6));
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bad_settings_are_usage_errors() {
    let d = dir("bad-set");
    scene_file(&d);
    for (args, needle) in [
        (vec!["--set", "colour=1"], "unknown render setting `colour`"),
        (vec!["--set", "max_steps=-3"], "max_steps must be"),
        (vec!["--set", "relaxation=2.5"], "relaxation must be"),
        (vec!["--set", "epsilon"], "KEY=VALUE"),
        (vec!["--size", "0x10"], "1 to"),
        (vec!["--threads", "0"], "at least 1"),
        (vec!["--threads", "100000"], "from 1 to 1024"),
    ] {
        let mut all = vec!["render", "ball.sdf"];
        all.extend(args.iter().copied());
        let out = sdfc(&d, &all);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
    assert_eq!(entries(&d), ["ball.sdf"]);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn scene_errors_exit_1_and_io_errors_exit_2() {
    let d = dir("errors");
    std::fs::write(d.join("broken.sdf"), "scene { sphere(; }").expect("write");
    assert_eq!(sdfc(&d, &["render", "broken.sdf"]).status.code(), Some(1));
    assert_eq!(sdfc(&d, &["render", "missing.sdf"]).status.code(), Some(2));
    scene_file(&d);
    let out = sdfc(&d, &["render", "ball.sdf", "-o", "no/such/dir/x.png"]);
    assert_eq!(
        out.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(entries(&d), ["ball.sdf", "broken.sdf"]);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bench_prints_a_table_or_json() {
    let d = dir("bench");
    scene_file(&d);
    let out = sdfc(
        &d,
        &[
            "bench",
            "ball.sdf",
            "--backend",
            "cpu",
            "--size",
            "16x12",
            "--frames",
            "2",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.contains("Mrays/s") && table.contains("ball.sdf"),
        "{table}"
    );
    let out = sdfc(
        &d,
        &[
            "bench", "ball.sdf", "ball.sdf", "--size", "16x12", "--frames", "1", "--json",
        ],
    );
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    let runs = v.as_array().expect("array");
    assert_eq!(runs.len(), 2);
    assert!(runs[0]["median_s"].as_f64().is_some_and(|s| s > 0.0));
    assert_eq!(runs[0]["width"], 16);
    assert!(runs[0]["stats"]["steps_mean"].as_f64().is_some());
    assert!(["trace", "march"].contains(&runs[0]["method"].as_str().unwrap_or("")));
    // A path-traced scene says so (it said "march").
    let out = sdfc(
        &d,
        &[
            "bench",
            "ball.sdf",
            "--backend",
            "cpu",
            "--size",
            "16x12",
            "--frames",
            "1",
            "--set",
            "method=path",
            "--set",
            "samples=1",
            "--json",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    let method = v[0]["method"].as_str().unwrap_or("").to_string();
    assert!(method == "path+trace" || method == "path+march", "{method}");
    let _ = std::fs::remove_dir_all(&d);
}

// ---- Failure paths (docs/failures.md lists each with its test) ----

#[test]
fn missing_unreadable_and_non_utf8_inputs_exit_2() {
    let d = dir("inputs");
    for args in [
        &["check", "nope.sdf"][..],
        &["render", "nope.sdf"],
        &["compile", "nope.sdf", "--emit", "ir"],
    ] {
        let out = sdfc(&d, args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(String::from_utf8_lossy(&out.stderr).contains("cannot read `nope.sdf`"));
    }
    std::fs::create_dir(d.join("folder.sdf")).expect("dir");
    assert_eq!(sdfc(&d, &["check", "folder.sdf"]).status.code(), Some(2));
    std::fs::write(d.join("latin1.sdf"), b"scene { sphere(); } // caf\xe9\n").expect("write");
    let out = sdfc(&d, &["render", "latin1.sdf"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("not valid UTF-8"));
    assert_eq!(entries(&d), ["folder.sdf", "latin1.sdf"]);
}

#[test]
fn json_diagnostics_and_io_errors_go_to_stdout() {
    let d = dir("json");
    std::fs::write(d.join("bad.sdf"), "scene { sphre(1); }\n").expect("write");
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
    let _ = std::fs::remove_dir_all(&d);
}

/// A library imported by its path and through a symbolic link to it is read once (no
/// duplicate definitions).
#[cfg(unix)]
#[test]
fn a_library_imported_through_a_symbolic_link_is_read_once() {
    let d = dir("symlink");
    std::fs::create_dir(d.join("lib")).expect("dir");
    std::fs::write(d.join("lib/shapes.sdf"), "let r = 1;\n").expect("write");
    std::os::unix::fs::symlink("lib/shapes.sdf", d.join("alias.sdf")).expect("link");
    std::os::unix::fs::symlink("lib", d.join("linked")).expect("link");
    std::fs::write(
        d.join("main.sdf"),
        "import \"lib/shapes.sdf\";\nimport \"alias.sdf\";\nimport \"linked/shapes.sdf\";\nscene { sphere(r); }\n",
    )
    .expect("write");
    let out = sdfc(&d, &["check", "main.sdf"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(!err.contains("E0207"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

/// A one-line file with 20 000 duplicate definitions: the human form shows the first 100
/// diagnostics, each with an excerpt of the line, and counts the rest; checking stops after
/// 1 000 errors and says so.
#[test]
fn twenty_thousand_errors_on_one_line_are_capped() {
    let d = dir("many");
    let text = format!("{}scene {{ sphere(a); }}", "let a = 1; ".repeat(20_000));
    std::fs::write(d.join("many.sdf"), text).expect("write");
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
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn an_unreadable_import_is_a_diagnostic() {
    let d = dir("import");
    std::fs::write(d.join("lib.sdf"), b"let r = 1; // caf\xe9\n").expect("write");
    std::fs::write(
        d.join("main.sdf"),
        "import \"lib.sdf\";\nscene { sphere(r); }\n",
    )
    .expect("write");
    let out = sdfc(&d, &["check", "main.sdf"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("E0501") && err.contains("not valid UTF-8"),
        "{err}"
    );
}

#[test]
fn a_missing_or_invalid_output_directory_leaves_nothing() {
    let d = dir("outputs");
    scene_file(&d);
    std::fs::write(d.join("plain-file"), "x").expect("write");
    for target in ["missing/out.png", "plain-file/out.png"] {
        let out = sdfc(&d, &["render", "ball.sdf", "-o", target]);
        assert_eq!(out.status.code(), Some(2), "{target}");
        assert!(
            String::from_utf8_lossy(&out.stderr).contains("cannot write"),
            "{target}"
        );
    }
    let out = sdfc(
        &d,
        &[
            "compile",
            "ball.sdf",
            "--emit",
            "wgsl",
            "-o",
            "missing/k.wgsl",
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(entries(&d), ["ball.sdf", "plain-file"]);
}

#[test]
fn an_unwritable_output_is_refused_before_the_render() {
    let d = dir("early");
    scene_file(&d);
    // A render that would take long: refused before it is lowered or announced.
    let out = sdfc(
        &d,
        &[
            "render",
            "ball.sdf",
            "--size",
            "4000x4000",
            "--aa",
            "4",
            "-o",
            "/nonexistent/x.png",
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("cannot write `/nonexistent/x.png`") && err.contains("does not exist"),
        "{err}"
    );
    assert!(!err.contains("allocating"), "the render started: {err}");
    // `pareto` checks its chart's place before its sweeps.
    let out = sdfc(
        &d,
        &[
            "pareto",
            "ball.sdf",
            "--frames",
            "1",
            "-o",
            "missing/chart.svg",
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty(), "the sweeps ran");
    assert!(String::from_utf8_lossy(&out.stderr).contains("does not exist"));
    assert_eq!(entries(&d), ["ball.sdf"]);
    let _ = std::fs::remove_dir_all(&d);
}

/// A read-only output file is refused (exit 2, saying so) and left as it was, by `render`
/// before the render starts and by `compile`.
#[test]
fn a_read_only_output_is_refused_and_left_unchanged() {
    use std::os::unix::fs::PermissionsExt;
    let d = dir("read-only");
    scene_file(&d);
    for (name, args) in [
        (
            "x.png",
            vec!["render", "ball.sdf", "--size", "8x8", "-o", "x.png"],
        ),
        (
            "x.wgsl",
            vec!["compile", "ball.sdf", "--emit", "wgsl", "-o", "x.wgsl"],
        ),
    ] {
        let out = d.join(name);
        std::fs::write(&out, b"keep me").expect("old file");
        std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o444)).expect("chmod");
        let o = sdfc(&d, &args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains("read-only"), "{name}: {err}");
        assert!(
            !err.contains("allocating"),
            "{name}: the render started: {err}"
        );
        assert_eq!(std::fs::read(&out).expect("kept"), b"keep me", "{name}");
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn render_prints_the_warnings_of_check() {
    let d = dir("warnings");
    std::fs::write(
        d.join("dark.sdf"),
        "render { width: 8, height: 6 }\nscene { sphere(1); }\n",
    )
    .expect("write scene");
    let out = sdfc(&d, &["render", "dark.sdf"]);
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("[W0008]") && err.contains("no lights"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn outputs_are_written_in_the_format_their_extension_names() {
    let d = dir("formats");
    scene_file(&d);
    for name in ["out.jpg", "out.JPEG"] {
        let out = sdfc(&d, &["render", "ball.sdf", "-o", name]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let bytes = std::fs::read(d.join(name)).expect("jpeg");
        assert_eq!(&bytes[..3], &[0xFF, 0xD8, 0xFF], "{name} is not a JPEG");
        assert_eq!(&bytes[bytes.len() - 2..], &[0xFF, 0xD9]);
    }
    // OpenEXR: magic number, version 2 (single-part scanline), a header of 305 bytes, the
    // offset table and 30 rows of 40 float RGB pixels (runtime/src/output.rs).
    let out = sdfc(&d, &["render", "ball.sdf", "-o", "out.exr"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let exr = std::fs::read(d.join("out.exr")).expect("exr");
    assert_eq!(&exr[..8], &[0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0]);
    assert!(String::from_utf8_lossy(&exr[..100]).contains("channels\0chlist"));
    assert_eq!(exr.len(), 8 + 305 + 30 * 8 + 30 * (8 + 40 * 12));
    // Unknown formats are refused before the render, leaving nothing.
    for name in ["out.tiff", "out"] {
        let out = sdfc(&d, &["render", "ball.sdf", "-o", name]);
        assert_eq!(out.status.code(), Some(2), "{name}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(".png`, `.jpg`"), "{err}");
        assert!(!err.contains("allocating"), "{err}");
    }
    // `-o -`: the PNG on standard output (statistics on standard error), no file named `-`.
    let out = sdfc(&d, &["render", "ball.sdf", "-o", "-", "--stats"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(&out.stdout[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(
        &out.stdout[out.stdout.len() - 8..out.stdout.len() - 4],
        b"IEND"
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("steps/pixel"));
    let out = sdfc(&d, &["render", "ball.sdf", "-o", "-", "--aux"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        entries(&d),
        ["ball.sdf", "out.JPEG", "out.exr", "out.jpg"],
        "no other file, no temporary file left"
    );
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn no_gpu_adapter_is_a_clear_error() {
    let d = dir("adapter");
    scene_file(&d);
    let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&d)
        .args(["render", "ball.sdf", "--backend", "wgpu"])
        .env("WGPU_BACKEND", "vulkan")
        .env("VK_ICD_FILENAMES", "/nonexistent.json")
        .env("VK_DRIVER_FILES", "/nonexistent.json")
        .output()
        .expect("run sdfc");
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("no wgpu adapter found") && err.contains("mesa-vulkan-drivers"),
        "{err}"
    );
    assert_eq!(entries(&d), ["ball.sdf"]);
}

#[test]
fn no_cuda_driver_is_a_clear_error() {
    let d = dir("cuda");
    scene_file(&d);
    let out = sdfc(&d, &["render", "ball.sdf", "--backend", "cuda"]);
    if out.status.success() {
        println!("SKIPPED: a CUDA driver and device are present here");
        return;
    }
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("CUDA"), "{err}");
    assert_eq!(entries(&d), ["ball.sdf"]);
}

#[test]
fn an_interrupt_stops_a_render_and_leaves_no_file() {
    let d = dir("interrupt");
    scene_file(&d);
    let mut child = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&d)
        .args([
            "render",
            "ball.sdf",
            "--backend",
            "cpu",
            "--size",
            "4000x3000",
            "--aa",
            "4",
            "-o",
            "big.png",
        ])
        .spawn()
        .expect("spawn");
    std::thread::sleep(std::time::Duration::from_millis(500));
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill");
    assert!(killed.success());
    let status = child.wait().expect("wait");
    assert!(!status.success());
    assert_eq!(entries(&d), ["ball.sdf"], "no output and no temporary file");
}

/// `sdfc check` says which intersection method a scene gets and why; `--set method=trace`
/// on a scene that does not allow it is an error that writes nothing.
#[test]
fn the_method_setting_and_what_check_says_about_it() {
    let d = dir("method");
    scene_file(&d);
    let out = sdfc(&d, &["check", "ball.sdf"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("method: march (light 1 casts soft shadows"),
        "{err}"
    );
    let out = sdfc(&d, &["render", "ball.sdf", "--set", "method=trace"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("cannot be ray traced analytically"), "{err}");
    let out = sdfc(&d, &["render", "ball.sdf", "--set", "method=fast"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("method must be one of"));
    assert_eq!(entries(&d), ["ball.sdf"]);
    std::fs::write(
        d.join("hard.sdf"),
        SCENE.replace("penumbra: 7.125deg", "penumbra: 0deg"),
    )
    .expect("write");
    let out = sdfc(&d, &["check", "hard.sdf"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("method: trace (2 primitives"), "{err}");
    let out = sdfc(
        &d,
        &["render", "hard.sdf", "--set", "method=trace", "--stats"],
    );
    assert_eq!(out.status.code(), Some(0));
    assert!(d.join("hard.png").exists());
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_render_announces_its_memory_and_stops_above_the_memory_limit() {
    let d = dir("memory");
    scene_file(&d);
    let out = sdfc(
        &d,
        &["render", "ball.sdf", "--backend", "cpu", "-o", "a.png"],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("render: 40x30, aa 1, cpu: allocating at most ") && err.contains(" MiB"),
        "{err}"
    );
    let out = sdfc(
        &d,
        &[
            "render",
            "ball.sdf",
            "--backend",
            "cpu",
            "--limit",
            "memory=1",
            "--size",
            "2000x2000",
            "-o",
            "b.png",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("more than the memory limit of 1 MiB") && err.contains("--limit memory="),
        "{err}"
    );
    assert_eq!(entries(&d), ["a.png", "ball.sdf"], "no file written");
}

#[test]
fn limits_are_set_by_name_and_named_when_exceeded() {
    let d = dir("limits");
    scene_file(&d);
    let out = sdfc(&d, &["render", "ball.sdf", "--limit", "speed=3"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("unknown limit `speed`") && err.contains("fuel"),
        "{err}"
    );
    for bad in ["aa=0", "aa=x", "aa"] {
        let out = sdfc(&d, &["check", "ball.sdf", "--limit", bad]);
        assert_eq!(out.status.code(), Some(2), "{bad}");
    }
    // A loop over the objects limit: E0507 naming the flag with the value that would do
    // (the loop's count, not twice the limit), and the flag raises it.
    let many = "scene { for i in 0..50 { sphere(0.1).translate(i, 0, 0); } }\n";
    std::fs::write(d.join("many.sdf"), many).expect("write");
    let out = sdfc(&d, &["check", "many.sdf", "--limit", "objects=20"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("E0507") && err.contains("--limit objects=50"),
        "{err}"
    );
    let out = sdfc(&d, &["check", "many.sdf", "--limit", "objects=50"]);
    assert!(out.status.success());
    // The render settings' limits: in the scene (E0400) and on the command line (exit 2).
    let out = sdfc(&d, &["render", "ball.sdf", "--aa", "20"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("--limit aa=20"), "{err}");
    for (set, flag) in [
        ("max_steps=2000000", "--limit max_steps=2000000"),
        ("max_depth=100", "--limit max_depth=100"),
        ("width=20000", "--limit edge=20000"),
        ("samples=70000", "--limit samples=70000"),
        ("bounces=100", "--limit bounces=100"),
    ] {
        let out = sdfc(&d, &["render", "ball.sdf", "--set", set]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains(flag), "{set}: {err}");
    }
    // The path tracer's samples and bounces in the scene: located errors naming the limit
    // (or, below the least value, the range).
    for (setting, wanted) in [
        ("samples: 100000", "--limit samples="),
        ("bounces: 2000", "--limit bounces="),
        ("samples: 0", "samples"),
    ] {
        let text = format!("render {{ method: \"path\", {setting} }}\nscene {{ sphere(); }}\n");
        std::fs::write(d.join("path.sdf"), text).expect("write");
        let out = sdfc(&d, &["check", "path.sdf"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{setting}: {err}");
        assert!(
            err.contains("E0400") && err.contains("path.sdf:1:") && err.contains(wanted),
            "{setting}: {err}"
        );
    }
    std::fs::remove_file(d.join("path.sdf")).expect("remove");
    let out = sdfc(
        &d,
        &[
            "render", "ball.sdf", "--aa", "20", "--limit", "aa=20", "--size", "4x4",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The program limit, after lowering and before any output.
    for args in [
        &[
            "compile",
            "ball.sdf",
            "--emit",
            "wgsl",
            "--limit",
            "program=10",
            "-o",
            "k.wgsl",
        ][..],
        &["render", "ball.sdf", "--limit", "program=10", "-o", "p.png"],
    ] {
        let out = sdfc(&d, args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains("E0507")
                && err.contains("distance program has")
                && err.contains("--limit program="),
            "{err}"
        );
    }
    // `check` passes the scene and warns, located, that a render will refuse it (issue 37).
    let out = sdfc(&d, &["check", "many.sdf", "--limit", "program=100"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(
        err.contains("[E0507] Warning")
            && err.contains("will refuse this scene")
            && err.contains("many.sdf:1:1")
            && err.contains("--limit program=")
            && err.contains("many.sdf: ok"),
        "{err}"
    );
    let out = sdfc(&d, &["check", "many.sdf"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && !err.contains("E0507"), "{err}");
    assert_eq!(entries(&d), ["ball.png", "ball.sdf", "many.sdf"]);
}

#[test]
fn debug_nan_paints_nan_pixels_magenta_in_the_written_image() {
    let d = dir("debug-nan");
    let scene =
        std::fs::canonicalize("../compiler/tests/in/ok/nan_at_run_time.sdf").expect("scene");
    let scene = scene.to_string_lossy();
    let magenta = |png: &str| {
        let image = sdfc_runtime::image::read_png(&d.join(png)).expect("png");
        image
            .linear
            .iter()
            .filter(|c| c[0] > 0.99 && c[1] < 0.01 && c[2] > 0.99)
            .count()
    };
    for (flag, png) in [(None, "plain.png"), (Some("--debug-nan"), "debug.png")] {
        let mut args = vec!["render", &scene, "--backend", "cpu", "-o", png];
        args.extend(flag);
        let out = sdfc(&d, &args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    assert_eq!(magenta("plain.png"), 0);
    assert!(magenta("debug.png") > 100);
}

/// Whether `sdfc` finds a wgpu adapter here; if not, the caller skips (saying so) unless
/// SDFC_REQUIRE_DEVICES=1 (set by CI, which installs lavapipe).
fn wgpu_available(d: &Path) -> bool {
    let out = sdfc(
        d,
        &[
            "render",
            "ball.sdf",
            "--backend",
            "wgpu",
            "--size",
            "8x8",
            "-o",
            "probe.png",
        ],
    );
    let _ = std::fs::remove_file(d.join("probe.png"));
    if out.status.success() {
        return true;
    }
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        std::env::var("SDFC_REQUIRE_DEVICES").as_deref() != Ok("1"),
        "SDFC_REQUIRE_DEVICES=1 but wgpu failed: {err}"
    );
    println!("SKIPPED: no wgpu adapter: {err}");
    false
}

#[test]
fn a_gpu_error_mid_render_is_one_message_and_leaves_no_file() {
    let d = dir("gpu-fault");
    scene_file(&d);
    if !wgpu_available(&d) {
        return;
    }
    // 4100x16 is three tiles of 2048 pixels: the second fails after the first rendered.
    let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&d)
        .args([
            "render",
            "ball.sdf",
            "--backend",
            "wgpu",
            "--size",
            "4100x16",
        ])
        .args(["-o", "fault.png"])
        .env("SDFC_FAULT_AFTER_TILES", "1")
        // Mesa's window-system code complains on stderr without it.
        .env("XDG_RUNTIME_DIR", &d)
        .output()
        .expect("run sdfc");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    let errors: Vec<&str> = err.lines().filter(|l| l.starts_with("error")).collect();
    assert_eq!(
        errors,
        ["error: GPU error while rendering: device error injected at tile 2 by SDFC_FAULT_AFTER_TILES=1 (a testing aid)"],
        "{err}"
    );
    assert_eq!(entries(&d), ["ball.sdf"], "no output and no temporary file");
}

/// A wgpu render on a Vulkan adapter stores the driver's pipeline cache data for its kernel
/// in the cache directory (`SDFC_CACHE_DIR`, as the CUDA JIT cache), in a file named by the
/// kernel and the device; a second process rendering the same kernel finds it and gives it to
/// the driver, and a render of another kernel gets a file of its own. (Lavapipe stores no
/// compiled code in it, 96 bytes of headers, so this shows the files are found, not that
/// the driver's compile gets faster: that is a GPU's measurement,
/// scripts/device-first-second.sh.) `--stats` also reduces the frame's statistics on the
/// device, whose pipeline keeps a file of its own, the same for every scene.
#[test]
fn a_second_process_finds_the_wgpu_pipeline_cache() {
    let d = dir("pipeline-cache");
    scene_file(&d);
    if !wgpu_available(&d) {
        return;
    }
    let cache = d.join("cache");
    let render = |size: &str| {
        let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
            .current_dir(&d)
            .args(["render", "ball.sdf", "--backend", "wgpu", "--stats"])
            .args(["--size", size, "-o", "out.png"])
            .env("SDFC_CACHE_DIR", &cache)
            .env("XDG_RUNTIME_DIR", &d)
            .output()
            .expect("run sdfc");
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let line = text
            .lines()
            .find(|l| l.trim_start().starts_with("driver compile"))
            .unwrap_or_else(|| panic!("no driver compile line: {text}"))
            .to_string();
        (line, entries(&cache))
    };
    let (first, files) = render("16x16");
    assert!(
        first.contains("bytes of driver cache data stored"),
        "{first}"
    );
    assert_eq!(
        files.len(),
        2,
        "the kernel's and the reduction's: {files:?}"
    );
    assert!(files.iter().all(|f| f.ends_with(".pipeline")), "{files:?}");
    let (second, again) = render("24x16");
    assert!(
        second.contains("pipeline created from")
            && second.contains("bytes of stored driver cache data"),
        "{second}"
    );
    assert_eq!(again, files, "the same kernel, the same file");
    // Another kernel (a box in place of the sphere) gets a file of its own.
    let scene = std::fs::read_to_string(d.join("ball.sdf")).expect("scene");
    let boxed = scene.replace("sphere(1)", "box((0.5, 0.5, 0.5))");
    std::fs::write(d.join("ball.sdf"), boxed).expect("write");
    let (third, more) = render("16x16");
    assert!(third.contains("stored"), "{third}");
    assert_eq!(more.len(), 3, "{more:?}");
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
    std::fs::write(d.join("exp.sdf"), exponential(40)).expect("write");
    assert_eq!(exponential(40).lines().count(), 42);
    let start = std::time::Instant::now();
    let out = sdfc(&d, &["check", "exp.sdf"]);
    let took = start.elapsed();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    // At the union of f20, the first level whose tree (2²² − 3 nodes) is over 4 000 000.
    assert!(
        err.contains("E0507") && err.contains("exp.sdf:21:") && err.contains("--limit expansion="),
        "{err}"
    );
    assert!(took.as_secs_f64() < 1.0, "took {took:?}");
    // Raised, the same limit lets a smaller tree through; lowered, it stops a small one.
    std::fs::write(d.join("small.sdf"), exponential(8)).expect("write");
    let ok = sdfc(&d, &["check", "small.sdf"]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
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
    std::fs::write(d.join("big.sdf"), text).expect("write");
    let out = sdfc(
        &d,
        &[
            "compile",
            "big.sdf",
            "--emit",
            "program",
            "--limit",
            "program=1000",
            "-o",
            "p.txt",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("E0507")
            && err.contains("more than 1000 operations")
            && err.contains("--limit program=2000"),
        "{err}"
    );
    assert!(!d.join("p.txt").exists());
    let out = sdfc(
        &d,
        &["compile", "big.sdf", "--emit", "program", "-o", "p.txt"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// issue 16, item 2: `sdfc pareto` counts the combinations of its sweeps before building
/// them, against the `sweep_points` limit, and each sweep against `sweep_values`.
#[test]
fn pareto_sweeps_are_bounded_by_limits() {
    let d = dir("pareto-limits");
    scene_file(&d);
    let out = sdfc(
        &d,
        &[
            "pareto",
            "ball.sdf",
            "--sweep",
            "epsilon=1e-2..1e-6:100",
            "--sweep",
            "max_steps=32..1024:100",
            "--sweep",
            "relaxation=1..1.8:100",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("combinations of settings, more than 1000")
            && err.contains("--limit sweep_points="),
        "{err}"
    );
    let out = sdfc(&d, &["pareto", "ball.sdf", "--sweep", "aa=1..2000"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("--limit sweep_values="), "{err}");
}

/// `--emit spirv` (and `params`) writes binary: to a terminal it is refused (exit 2, pointing at `-o`),
/// while to a pipe or a file it is written. The terminal is a pseudo-terminal from
/// util-linux's `script`.
#[test]
fn spirv_is_not_written_to_a_terminal() {
    let d = dir("spirv-tty");
    scene_file(&d);
    let piped = sdfc(&d, &["compile", "ball.sdf", "--emit", "spirv"]);
    assert!(piped.status.success());
    assert_eq!(&piped.stdout[..4], &0x0723_0203u32.to_le_bytes());
    let filed = sdfc(
        &d,
        &["compile", "ball.sdf", "--emit", "spirv", "-o", "k.spv"],
    );
    assert!(filed.status.success());
    assert_eq!(std::fs::read(d.join("k.spv")).expect("k.spv"), piped.stdout);
    let command = format!(
        "'{0}' compile ball.sdf --emit spirv; echo \"exit=$?\"; '{0}' compile ball.sdf --emit params; echo \"exit=$?\"",
        env!("CARGO_BIN_EXE_sdfc")
    );
    let tty = Command::new("script")
        .current_dir(&d)
        .args(["-qec", &command, "/dev/null"])
        .output()
        .expect("util-linux `script` runs a command on a pseudo-terminal");
    let text = String::from_utf8_lossy(&tty.stdout);
    assert_eq!(text.matches("exit=2").count(), 2, "{text}");
    assert!(text.contains("-o FILE"), "{text}");
    assert!(
        !text.contains('\u{0}'),
        "binary reached the terminal: {text:?}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// `compile --set` specialises the kernel as `render --set` would: the method, here marching a
/// scene the file leaves to analytic tracing; a bad key or a method the scene does not allow
/// is a usage error.
#[test]
fn compile_applies_set_before_specialising_the_kernel() {
    let d = dir("compile-set");
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/seed1.sdf");
    let example = example.to_str().expect("utf-8 path");
    let features = |args: &[&str]| {
        let out = sdfc(&d, args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        text.lines().nth(1).expect("features line").to_string()
    };
    assert!(features(&["compile", example, "--emit", "wgsl"]).contains("+ANALYTIC"));
    assert!(features(&[
        "compile",
        example,
        "--emit",
        "wgsl",
        "--set",
        "method=march"
    ])
    .contains("-ANALYTIC"));
    let bad = sdfc(
        &d,
        &["compile", example, "--emit", "wgsl", "--set", "methd=march"],
    );
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("unknown render setting `methd`"));
    let seed3 = example.replace("seed1", "seed3");
    let refused = sdfc(
        &d,
        &["compile", &seed3, "--emit", "wgsl", "--set", "method=trace"],
    );
    assert_eq!(refused.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&refused.stderr).contains("cannot be ray traced"));
}

/// The device opens on a thread of its own while the scene is read and checked (`Opening`):
/// a scene with errors still prints its diagnostics and exits 1 whatever the device does (no
/// adapter, no CUDA driver, or a device still opening when the process ends), and the
/// arguments' own errors still come after the scene's.
#[test]
fn a_scene_with_errors_exits_1_whatever_the_device_does() {
    let d = dir("errors-device");
    std::fs::write(d.join("broken.sdf"), "scene { sphere(; }").expect("write");
    let diagnostics = |out: &Output| {
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(err.contains("broken.sdf") && err.contains("E0101"), "{err}");
        assert!(!err.contains("adapter") && !err.contains("CUDA"), "{err}");
        err
    };
    // No wgpu adapter at all.
    let no_adapter = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&d)
        .args(["render", "broken.sdf", "--backend", "wgpu"])
        .env("WGPU_BACKEND", "vulkan")
        .env("VK_ICD_FILENAMES", "/nonexistent.json")
        .env("VK_DRIVER_FILES", "/nonexistent.json")
        .output()
        .expect("run sdfc");
    diagnostics(&no_adapter);
    // Whatever this machine has: a device opening (lavapipe, a GPU) or none.
    for backend in ["wgpu", "cuda", "auto"] {
        let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
            .current_dir(&d)
            .args(["render", "broken.sdf", "--backend", backend, "--stats"])
            .env("XDG_RUNTIME_DIR", &d)
            .output()
            .expect("run sdfc");
        diagnostics(&out);
        assert!(
            out.stdout.is_empty(),
            "no statistics for a scene with errors"
        );
    }
    // Scene errors come before the arguments' (`--reference` renders on the CPU alone).
    let both = sdfc(
        &d,
        &["render", "broken.sdf", "--reference", "--backend", "wgpu"],
    );
    diagnostics(&both);
    scene_file(&d);
    let usage = sdfc(
        &d,
        &["render", "ball.sdf", "--reference", "--backend", "wgpu"],
    );
    let err = String::from_utf8_lossy(&usage.stderr);
    assert_eq!(usage.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--reference renders on the CPU in f64"),
        "{err}"
    );
    let kernel = sdfc(
        &d,
        &[
            "render",
            "broken.sdf",
            "--backend",
            "cpu",
            "--kernel",
            "interpreted",
        ],
    );
    diagnostics(&kernel);
    assert_eq!(
        entries(&d),
        ["ball.sdf", "broken.sdf"],
        "no image, no temporary file"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// `--stats`'s breakdown of the whole run: its phases add up to its total, a device opened
/// beside the front end says so with its own time, and the image's steps (sRGB, PNG, write,
/// rename; a still is not synced to the disk) are listed; the device is left to the operating system at the end.
#[test]
fn the_run_breakdown_adds_up_and_names_the_overlapped_device() {
    let d = dir("breakdown");
    scene_file(&d);
    let backends: &[&str] = if wgpu_available(&d) {
        &["cpu", "wgpu"]
    } else {
        &["cpu"]
    };
    for backend in backends {
        let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
            .current_dir(&d)
            .args(["render", "ball.sdf", "--backend", backend, "--stats"])
            .args(["-o", "out.png"])
            .env("XDG_RUNTIME_DIR", &d)
            .output()
            .expect("run sdfc");
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{text}{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let block: Vec<&str> = text
            .lines()
            .skip_while(|l| !l.starts_with("run "))
            .collect();
        let total: f64 = block[0]
            .split_whitespace()
            .nth(1)
            .expect("total")
            .parse()
            .expect("ms");
        let mut sum = 0.0;
        let mut names = Vec::new();
        for line in &block[1..] {
            let name = line[2..18].trim();
            names.push(name);
            if let Ok(ms) = line[18..]
                .split(" ms")
                .next()
                .expect("ms")
                .trim()
                .parse::<f64>()
            {
                sum += ms;
            }
        }
        // Each phase is rounded to 0.1 ms.
        assert!(
            (sum - total).abs() <= 0.05 * names.len() as f64 + 0.1,
            "{text}"
        );
        for step in ["scene", "sRGB", "PNG", "write", "rename", "image", "exit"] {
            assert!(names.contains(&step), "{step} in {text}");
        }
        // A still image is not synced to the disk (`AtomicFile::unsynced`).
        assert!(!names.contains(&"fsync"), "{text}");
        let device = block.iter().find(|l| l.trim_start().starts_with("device "));
        match *backend {
            "cpu" => assert!(device.is_none(), "{text}"),
            _ => {
                let line = device.expect("a device phase");
                assert!(line.contains("overlapped with the front end"), "{text}");
            }
        }
        assert_eq!(png_size(&d.join("out.png")), (40, 30));
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// `sdfc check --verify-bounds`: a field whose declared L is too small is reported at its
/// place with exit 1; fields whose bounds hold (declared or derived) pass.
#[test]
fn check_verify_bounds_reports_a_field_steeper_than_its_bound() {
    let d = dir("verify-bounds");
    std::fs::write(
        d.join("steep.sdf"),
        "scene {\n  field(lipschitz: 1) { 3 * (length(p) - 1) };\n}\n",
    )
    .expect("write");
    std::fs::write(
        d.join("fine.sdf"),
        "scene {\n  field { 2 * (length(p) - 1) };\n  field(lipschitz: 3) { 3 * (length(p) - 1) }.translate(3, 0, 0);\n}\n",
    )
    .expect("write");
    let out = sdfc(&d, &["check", "--verify-bounds", "steep.sdf"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("steep.sdf:2:3: this field has a slope of") && err.contains("above its L = 1"),
        "{err}"
    );
    let out = sdfc(&d, &["check", "--verify-bounds", "fine.sdf"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(
        err.contains("bounds sampled, not proven: 2 field(s), none steeper than its L"),
        "{err}"
    );
    assert!(!err.contains("verified"), "{err}");
    // A profile is named as one.
    std::fs::write(
        d.join("flat.sdf"),
        "scene {\n  revolve(profile(lipschitz: 0.1) { length(p) - 0.5 });\n}\n",
    )
    .expect("write");
    let out = sdfc(&d, &["check", "--verify-bounds", "flat.sdf"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("flat.sdf:2:11: this profile has a slope of"),
        "{err}"
    );
}

/// `--verify-bounds` samples the whole of the scene's bounded region, in each field's own
/// coordinates, not only near the camera's target: a field steeper than its L only 6 units
/// and more from the target, inside the box it is cut to, is caught; the output names the
/// boxes sampled and the pairs of points, and where an unbounded scene was clipped.
#[test]
fn check_verify_bounds_samples_the_scene_and_says_where() {
    let d = dir("verify-bounds-far");
    std::fs::write(
        d.join("far.sdf"),
        "camera { position: (0, 0, -5), look_at: (0, 0, 0) }\nscene {\n  intersect(field(lipschitz: 1) { length(p) - 1 + 0.5 * max(p.x - 6, 0) }, box(9));\n}\n",
    )
    .expect("write");
    let out = sdfc(&d, &["check", "--verify-bounds", "far.sdf"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("far.sdf:3:13: this field has a slope of") && err.contains("above its L = 1"),
        "{err}"
    );
    assert!(
        err.contains(
            "found in 20000 pairs of points over the scene's box [(-9, -9, -9), (9, 9, 9)]"
        ),
        "{err}"
    );
    assert!(!err.contains("verified"), "{err}");
    // A scene unbounded along every axis: sampled within max_dist of the camera, and said so.
    std::fs::write(
        d.join("open.sdf"),
        "camera { position: (0, 0, -5), look_at: (0, 0, 0) }\nrender { max_dist: 50 }\nscene {\n  field { length(p) - 1 };\n  field { p.x * p.y };\n}\n",
    )
    .expect("write");
    let out = sdfc(&d, &["check", "--verify-bounds", "open.sdf"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(
        err.contains("open.sdf:4:3: this field: no slope above its L = 1 in 20000 pairs of points over the scene's box [(-50, -50, -55), (50, 50, 45)]"),
        "{err}"
    );
    assert!(
        err.contains("open.sdf:5:3: this field has no declared or proven L: nothing to sample"),
        "{err}"
    );
    assert!(
        err.contains("the scene is unbounded along x, y, z, sampled within max_dist = 50 of the camera there, and not beyond"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&d);
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
    std::fs::write(d.join("deep.sdf"), text).expect("write");
    let out = sdfc(&d, &["check", "deep.sdf"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("`--limit nesting=2000`"), "{err}");
    let out = sdfc(&d, &["check", "deep.sdf", "--limit", "nesting=20000"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(err.contains("deep.sdf: ok"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

/// `sdfc fmt`: files rewritten in place (only those that change), folders searched for `.sdf`
/// files, `--check` naming the files that would change without writing, syntax errors and
/// missing files refused, standard input to standard output.
#[test]
fn fmt_rewrites_checks_and_filters() {
    let d = dir("fmt");
    let sub = d.join("more");
    std::fs::create_dir_all(&sub).expect("dir");
    let messy = "let r=2*3;\nscene { sphere( r ) ; }\n";
    let tidy = "let r = 2 * 3;\nscene {\n  sphere(r);\n}\n";
    std::fs::write(d.join("a.sdf"), messy).expect("write");
    std::fs::write(sub.join("b.sdf"), tidy).expect("write");
    std::fs::write(sub.join("c.sdf"), messy).expect("write");
    std::fs::write(d.join("broken.sdf"), "let r = ;\n").expect("write");

    let out = sdfc(&d, &["fmt", "--check", "a.sdf", "more"]);
    assert_eq!(out.status.code(), Some(1));
    let named = String::from_utf8_lossy(&out.stdout).replace('\\', "/");
    assert_eq!(named, "a.sdf\nmore/c.sdf\n");
    assert_eq!(
        std::fs::read_to_string(d.join("a.sdf")).expect("read"),
        messy
    );

    let out = sdfc(&d, &["fmt", "a.sdf", "more"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in ["a.sdf", "more/b.sdf", "more/c.sdf"] {
        assert_eq!(
            std::fs::read_to_string(d.join(f)).expect("read"),
            tidy,
            "{f}"
        );
    }
    assert_eq!(entries(&sub), ["b.sdf", "c.sdf"], "no temporary file left");
    assert_eq!(
        sdfc(&d, &["fmt", "--check", "."]).status.code(),
        Some(1),
        "broken.sdf"
    );
    assert_eq!(
        sdfc(&d, &["fmt", "--check", "a.sdf", "more"]).status.code(),
        Some(0)
    );
    // Links to a folder above are entered once: each file is named once (it was listed 40
    // times over `more/up/more/up/…`, and two such links never ended).
    #[cfg(unix)]
    {
        std::fs::write(sub.join("c.sdf"), messy).expect("write");
        std::os::unix::fs::symlink("..", sub.join("up")).expect("link");
        std::os::unix::fs::symlink("..", sub.join("up2")).expect("link");
        let out = sdfc(&d, &["fmt", "--check", "more"]);
        let (named, err) = (
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr),
        );
        assert_eq!(named, "more/c.sdf\n", "{err}");
        assert_eq!(err.matches("broken.sdf: not formatted").count(), 1, "{err}");
        std::fs::remove_file(sub.join("up")).expect("unlink");
        std::fs::remove_file(sub.join("up2")).expect("unlink");
        std::fs::write(sub.join("c.sdf"), tidy).expect("write");
    }

    let out = sdfc(&d, &["fmt", "broken.sdf"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("E0100") && err.contains("not formatted"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(d.join("broken.sdf")).expect("read"),
        "let r = ;\n"
    );
    // Named twice, and through its folder: its error is reported once.
    let out = sdfc(&d, &["fmt", "broken.sdf", ".", "./broken.sdf"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.matches("E0100").count(), 1, "{err}");
    assert_eq!(err.matches("not formatted").count(), 1, "{err}");
    assert_eq!(sdfc(&d, &["fmt", "missing.sdf"]).status.code(), Some(2));

    let run = |args: &[&str], input: &str| {
        let mut child = Command::new(env!("CARGO_BIN_EXE_sdfc"))
            .args(args)
            .stdin(std::process::Stdio::piped())
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("run sdfc");
        use std::io::Write;
        child
            .stdin
            .take()
            .expect("stdin")
            .write_all(input.as_bytes())
            .expect("write");
        child.wait_with_output().expect("wait")
    };
    let out = run(&["fmt"], messy);
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(String::from_utf8_lossy(&out.stdout), tidy);
    let out = run(&["fmt", "--check", "-"], messy);
    assert_eq!(
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stdout).as_ref()
        ),
        (Some(1), "<stdin>\n")
    );
    assert_eq!(run(&["fmt", "--check"], tidy).status.code(), Some(0));
    let _ = std::fs::remove_dir_all(&d);
}

/// The help and completions of issue 37, item 8: `sdfc completions` writes a script for each
/// shell that knows the subcommands and their flags; the limits' table is in `sdfc --help`
/// once and in no subcommand's help; `view --help` lists every key the window handles (read
/// from its source); `render` is not described as writing only PNG; `mesh --help` says how
/// importers load a multi-material glTF.
#[test]
fn help_and_completions() {
    let d = dir("help");
    for (shell, marker) in [
        ("bash", "complete"),
        ("zsh", "#compdef"),
        ("fish", "complete -c sdfc"),
    ] {
        let out = sdfc(&d, &["completions", shell]);
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{shell}");
        for word in [marker, "render", "mesh", "limit", "backend"] {
            assert!(text.contains(word), "{shell}: no `{word}`");
        }
    }
    let out = sdfc(&d, &["completions", "powershell"]);
    assert_eq!(out.status.code(), Some(2));

    let help = |args: &[&str]| {
        let out = sdfc(&d, args);
        assert!(out.status.success(), "{args:?}");
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let top = help(&["--help"]);
    for limit in ["nesting", "sweep_points", "registers"] {
        assert_eq!(
            top.lines()
                .filter(|l| l.trim_start().starts_with(limit))
                .count(),
            1,
            "{limit} in: {top}"
        );
    }
    let subcommands = [
        "check",
        "compile",
        "render",
        "bench",
        "compare",
        "pareto",
        "mesh",
        "devices",
        "view",
        "lsp",
        "completions",
    ];
    for sub in subcommands {
        let text = help(&[sub, "--help"]);
        assert!(
            !text.contains("sweep_points") && !text.contains("registers of the interpreted"),
            "{sub} --help repeats the limits' table"
        );
    }
    assert!(help(&["render", "--help"]).contains("sdfc --help"));

    // Every key the window's event handler matches is in `view --help`.
    let window =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("src/view/window.rs"))
            .expect("window.rs");
    let mut keys: Vec<String> = window
        .split("eq_ignore_ascii_case(\"")
        .skip(1)
        .map(|rest| rest[..1].to_uppercase())
        .collect();
    keys.extend(
        window
            .split("NamedKey::")
            .skip(1)
            .map(|rest| {
                rest.split(|c: char| !c.is_alphanumeric())
                    .next()
                    .unwrap_or("")
            })
            .filter(|k| !k.is_empty())
            .map(|k| {
                if k == "Escape" {
                    "Esc".to_string()
                } else {
                    k.to_string()
                }
            }),
    );
    assert!(keys.len() >= 5, "{keys:?}");
    let view = help(&["view", "--help"]);
    let table = view
        .split("In the window:")
        .nth(1)
        .expect("view --help lists the keys");
    for key in &keys {
        assert!(
            table
                .lines()
                .any(|l| l.split_whitespace().any(|w| w.trim_end_matches(',') == key)),
            "`{key}` is not in view --help: {table}"
        );
    }

    let top_lines: Vec<&str> = top
        .lines()
        .filter(|l| l.trim_start().starts_with("render"))
        .collect();
    assert!(
        top_lines
            .iter()
            .any(|l| l.contains("JPEG") && !l.contains("to a PNG image")),
        "{top_lines:?}"
    );
    assert!(help(&["mesh", "--help"]).contains("importers load as separate parts"));
    let _ = std::fs::remove_dir_all(&d);
}

/// A standard output closed before the command is done (`sdfc completions bash | head -1`)
/// ends it quietly, as it ends `cat`: no message, and no failure but the signal's.
#[cfg(unix)]
#[test]
fn a_closed_standard_output_ends_a_command_quietly() {
    use std::os::unix::process::ExitStatusExt;
    use std::process::Stdio;
    let d = dir("closed-stdout");
    let scene = scene_file(&d);
    let scene = scene.to_str().expect("utf-8 path");
    let runs: [(&[&str], bool); 4] = [
        (&["completions", "bash"], false),
        (&["compile", scene, "--emit", "wgsl"], false),
        (&["compile", scene, "--emit", "ir"], false),
        (&["fmt", "-"], true),
    ];
    for (args, stdin) in runs {
        // The writing end of a pipe whose reader has exited.
        let mut reader = Command::new("true")
            .stdin(Stdio::piped())
            .spawn()
            .expect("run true");
        let closed = reader.stdin.take().expect("pipe");
        reader.wait().expect("true exits");
        let input = match stdin {
            true => Stdio::from(std::fs::File::open(scene).expect("scene")),
            false => Stdio::null(),
        };
        let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
            .current_dir(&d)
            .args(args)
            .stdin(input)
            .stdout(closed)
            .output()
            .expect("run sdfc");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.is_empty(), "sdfc {args:?} printed: {err}");
        assert!(
            out.status.success() || out.status.signal() == Some(libc::SIGPIPE),
            "sdfc {args:?}: {:?}",
            out.status
        );
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// Runs sdfc in `cwd` with standard input from `stdin` and standard output to `stdout` (files
/// or devices), returning its exit status and standard error.
#[cfg(unix)]
fn sdfc_redirected(
    cwd: &Path,
    args: &[&str],
    stdin: &Path,
    stdout: &Path,
) -> (Option<i32>, String) {
    let input = std::fs::File::open(stdin).expect("stdin");
    let output = std::fs::OpenOptions::new()
        .write(true)
        .open(stdout)
        .expect("stdout");
    let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(cwd)
        .args(args)
        .stdin(input)
        .stdout(output)
        .output()
        .expect("run sdfc");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A FIFO, `/dev/zero` or `/dev/urandom` as a scene, an import, a mesh or a file `fmt` reads
/// is refused at once (a FIFO with no writer would block, a device be read forever): `it is a
/// FIFO, not a regular file`, exit 2 for the command's own file, E0501/E0400 at the `import`
/// or `mesh` call; a file or standard input over the `file_size` limit is refused, naming the
/// value that would do.
#[cfg(unix)]
#[test]
fn special_files_are_refused_and_files_are_read_within_the_file_size_limit() {
    let d = dir("special");
    let fifo = |name: &str| {
        let made = Command::new("mkfifo")
            .arg(d.join(name))
            .status()
            .expect("mkfifo");
        assert!(made.success(), "mkfifo {name}");
    };
    fifo("pipe.sdf");
    fifo("pipe.stl");
    std::fs::create_dir(d.join("tree")).expect("dir");
    fifo("tree/x.sdf");
    std::fs::write(d.join("tree/ok.sdf"), "scene {\n  sphere(1);\n}\n").expect("write");
    for (args, what) in [
        (
            &["check", "pipe.sdf"][..],
            "`pipe.sdf`: it is a FIFO, not a regular file",
        ),
        (
            &["check", "/dev/zero"],
            "`/dev/zero`: it is a character device, not a regular file",
        ),
        (
            &["render", "/dev/urandom"],
            "it is a character device, not a regular file",
        ),
        (&["compile", "pipe.sdf", "--emit", "ir"], "it is a FIFO"),
        (
            &["fmt", "pipe.sdf"],
            "pipe.sdf: it is a FIFO, not a regular file",
        ),
        (
            &["fmt", "--check", "tree"],
            "tree/x.sdf: it is a FIFO, not a regular file",
        ),
    ] {
        let out = sdfc(&d, args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(what), "{args:?}: {err}");
    }
    std::fs::write(
        d.join("imports.sdf"),
        "import \"pipe.sdf\";\nscene {\n  sphere(1);\n}\n",
    )
    .expect("write");
    std::fs::write(d.join("meshes.sdf"), "scene {\n  mesh(\"pipe.stl\");\n}\n").expect("write");
    for (file, code) in [("imports.sdf", "E0501"), ("meshes.sdf", "E0400")] {
        let out = sdfc(&d, &["check", file]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{file}: {err}");
        assert!(
            err.contains(code) && err.contains("it is a FIFO, not a regular file"),
            "{file}: {err}"
        );
    }
    // Over the limit: a file by its size, standard input by what was read (at most the limit
    // and a byte: /dev/zero ends there).
    std::fs::write(
        d.join("big.sdf"),
        format!("// {}\nscene {{\n  sphere(1);\n}}\n", "x".repeat(3 << 20)),
    )
    .expect("write");
    let out = sdfc(&d, &["check", "--limit", "file_size=2", "big.sdf"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("over the file_size limit of 2 MiB; raise it with `--limit file_size=4`"),
        "{err}"
    );
    assert_eq!(
        sdfc(&d, &["check", "--limit", "file_size=4", "big.sdf"])
            .status
            .code(),
        Some(0)
    );
    let (code, err) = sdfc_redirected(
        &d,
        &["fmt", "--limit", "file_size=1"],
        Path::new("/dev/zero"),
        Path::new("/dev/null"),
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("standard input: it is over the file_size limit of 1 MiB"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// Output that cannot be written (`> /dev/full`) is an error, not a silent success:
/// `error: cannot write to standard output: No space left on device`, exit 2; and `sdfc fmt`
/// keeps the permissions of a file it rewrites.
#[cfg(unix)]
#[test]
fn output_that_cannot_be_written_is_an_error_and_fmt_keeps_permissions() {
    use std::os::unix::fs::PermissionsExt;
    let d = dir("full");
    let messy = d.join("messy.sdf");
    std::fs::write(&messy, "scene{sphere(1);}\n").expect("write");
    scene_file(&d);
    if Path::new("/dev/full").exists() {
        std::fs::write(d.join("bad.sdf"), "scene { sphre(1); }\n").expect("write");
        for (args, input) in [
            (&["fmt"][..], &messy),
            (&["compile", "ball.sdf", "--emit", "wgsl"], &messy),
            (&["fmt", "--check", "messy.sdf"], &messy),
            // JSON diagnostics, `println!` (here `--help`'s text) alike.
            (&["check", "--diagnostics", "json", "bad.sdf"], &messy),
            (&["--help"], &messy),
        ] {
            let (code, err) = sdfc_redirected(&d, args, input, Path::new("/dev/full"));
            assert_eq!(code, Some(2), "{args:?}: {err}");
            assert!(
                err.contains("error: cannot write to standard output: No space left on device"),
                "{args:?}: {err}"
            );
        }
    } else {
        eprintln!("/dev/full checks SKIPPED: there is no /dev/full");
    }
    std::fs::set_permissions(&messy, std::fs::Permissions::from_mode(0o600)).expect("chmod");
    let out = sdfc(&d, &["fmt", "messy.sdf"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        std::fs::read_to_string(&messy).expect("read"),
        "scene {\n  sphere(1);\n}\n"
    );
    let mode = std::fs::metadata(&messy)
        .expect("stat")
        .permissions()
        .mode();
    assert_eq!(mode & 0o777, 0o600, "{mode:o}");
    let _ = std::fs::remove_dir_all(&d);
}

/// A UTF-8 byte-order mark at the start of a file (some editors write one) is skipped: the
/// file checks, compiles and formats, and a diagnostic on its first line is at the column of
/// the visible character.
#[test]
fn a_byte_order_mark_is_skipped() {
    let d = dir("bom");
    std::fs::write(d.join("bom.sdf"), "\u{feff}scene {\n  sphre(1);\n}\n").expect("write");
    std::fs::write(
        d.join("ok.sdf"),
        "\u{feff}import \"lib.sdf\";\nscene {\n  ball;\n}\n",
    )
    .expect("write");
    std::fs::write(d.join("lib.sdf"), "\u{feff}let ball = sphere(1);\n").expect("write");
    let out = sdfc(&d, &["check", "--diagnostics", "json", "bom.sdf"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(!stdout.contains("E0001"), "{stdout}");
    assert!(stdout.contains("E0201"), "the misspelt sphere: {stdout}");
    let out = sdfc(&d, &["check", "ok.sdf"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = sdfc(&d, &["compile", "ok.sdf", "--emit", "ir"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = sdfc(&d, &["fmt", "ok.sdf"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        std::fs::read_to_string(d.join("ok.sdf")).expect("read"),
        "import \"lib.sdf\";\nscene {\n  ball;\n}\n"
    );
    std::fs::write(d.join("first.sdf"), "\u{feff}scene { sphre(1); }\n").expect("write");
    let out = sdfc(&d, &["check", "first.sdf"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("first.sdf:1:9"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn parameters_are_listed_set_and_refused_before_any_work() {
    let d = dir("params");
    std::fs::write(
        d.join("part.sdf"),
        "param width = 40.0 in 10..100 \"Box width (mm)\";\n\
         light point { position: (0, 5, -5) }\n\
         scene { box((width / 100, 0.5, 0.5)); }\n",
    )
    .expect("write scene");
    let out = sdfc(&d, &["check", "part.sdf", "--param", "width=60"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("param width = 60 (default 40) in 10..100: Box width (mm)"),
        "{err}"
    );
    let out = sdfc(&d, &["check", "part.sdf", "--diagnostics", "json"]);
    let json = String::from_utf8_lossy(&out.stdout);
    assert!(
        json.contains("\"name\":\"width\"") && json.contains("\"max\":100.0"),
        "{json}"
    );
    // Out of range: refused at the declaration, nothing written.
    let out = sdfc(
        &d,
        &[
            "render",
            "part.sdf",
            "-o",
            "part.png",
            "--param",
            "width=500",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("`--param width=500` is outside") && err.contains("part.sdf:1:7"),
        "{err}"
    );
    assert!(!d.join("part.png").exists());
    let out = sdfc(
        &d,
        &["mesh", "part.sdf", "-o", "part.stl", "--param", "depth=3"],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no parameter `depth`"));
    // Not NAME=VALUE: refused by the command line.
    let out = sdfc(&d, &["check", "part.sdf", "--param", "width"]);
    assert_eq!(out.status.code(), Some(2));
    // Given: the render is of the part that wide.
    let out = sdfc(
        &d,
        &[
            "render", "part.sdf", "-o", "part.png", "--param", "width=80", "--size", "32x24",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(png_size(&d.join("part.png")), (32, 24));
}
