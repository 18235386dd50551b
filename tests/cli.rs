//! The `sdfc render` and `sdfc bench` commands: outputs, atomic writes, settings overrides
//! and exit codes (1 for errors in the scene, 2 for usage and IO problems).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const SCENE: &str = "material red = phong { color: (1, 0.2, 0.1), reflect: 0.2 };
camera { position: (0, 1, -5), look_at: (0, 0, 0), fov: 50deg }
light point { position: (2, 4, -3), intensity: 1, radius: 50, softness: 8 }
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
    let _ = std::fs::remove_dir_all(&d);
}
