//! What every command shares: exit codes (1 for errors in the scene, 2 for usage and IO
//! problems), settings refused, limits set and named, help and completions, a closed standard
//! output; and the helpers of the binary's modules (a test's folder, `sdfc` run in it, a scene).

use crate::common::assert_has;
use crate::common::words;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub(crate) const SCENE: &str = "material red = phong { color: (1, 0.2, 0.1), reflect: 0.2 };
camera { position: (0, 1, -5), look_at: (0, 0, 0), fov: 50deg }
light point { position: (2, 4, -3), intensity: 1, radius: 50, penumbra: 7.125deg }
render { width: 40, height: 30 }
scene {
  plane() ;
  sphere(1).translate(0, 1, 0) @ red;
}
";

/// A test's directory, removed when the test ends well (kept to look at when it fails).
pub(crate) struct TestDir(PathBuf);

impl TestDir {
    /// The directory `path`, made fresh.
    pub(crate) fn fresh(path: PathBuf) -> TestDir {
        let _ = std::fs::remove_dir_all(&path);
        std::fs::create_dir_all(&path).expect("temp dir");
        TestDir(path)
    }
}

impl std::ops::Deref for TestDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for TestDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<std::ffi::OsStr> for TestDir {
    fn as_ref(&self) -> &std::ffi::OsStr {
        self.0.as_os_str()
    }
}

impl Drop for TestDir {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// A fresh directory for one test.
pub(crate) fn dir(name: &str) -> TestDir {
    TestDir::fresh(std::env::temp_dir().join(format!("sdfc-cli-{name}-{}", std::process::id())))
}

pub(crate) fn sdfc(cwd: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(cwd)
        .args(args)
        .output()
        .expect("run sdfc")
}

/// `sdfc` run in `cwd` with `args`, which must exit with `code`: its standard error.
#[track_caller]
pub(crate) fn exits(cwd: &Path, args: &[&str], code: i32) -> String {
    let out = sdfc(cwd, args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(code), "sdfc {args:?}: {err}");
    err
}

/// `sdfc` run in `cwd` with `args`, which must succeed: its output.
#[track_caller]
pub(crate) fn ok(cwd: &Path, args: &[&str]) -> Output {
    let out = sdfc(cwd, args);
    assert!(
        out.status.success(),
        "sdfc {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// A fresh directory for one test, holding the scene `ball.sdf` (`SCENE`).
pub(crate) fn scene_dir(name: &str) -> TestDir {
    let d = dir(name);
    scene_file(&d);
    d
}

/// Writes `text` to the file `name` of the directory `d`.
#[track_caller]
pub(crate) fn put(d: &Path, name: &str, text: impl AsRef<[u8]>) {
    std::fs::write(d.join(name), text).unwrap_or_else(|e| panic!("write {name}: {e}"));
}

pub(crate) fn scene_file(d: &Path) -> PathBuf {
    let p = d.join("ball.sdf");
    std::fs::write(&p, SCENE).expect("write scene");
    p
}

pub(crate) fn entries(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .expect("read dir")
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

pub(crate) fn png_size(p: &Path) -> (u32, u32) {
    let bytes = std::fs::read(p).expect("png");
    assert_eq!(&bytes[1..4], b"PNG");
    let be = |o: usize| u32::from_be_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
    (be(16), be(20))
}

#[test]
fn bad_settings_are_usage_errors() {
    let d = scene_dir("bad-set");
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
}

#[test]
fn scene_errors_exit_1_and_io_errors_exit_2() {
    let d = dir("errors");
    put(&d, "broken.sdf", "scene { sphere(; }");
    assert_eq!(sdfc(&d, &["render", "broken.sdf"]).status.code(), Some(1));
    assert_eq!(sdfc(&d, &["render", "missing.sdf"]).status.code(), Some(2));
    scene_file(&d);
    exits(&d, &["render", "ball.sdf", "-o", "no/such/dir/x.png"], 2);
    assert_eq!(entries(&d), ["ball.sdf", "broken.sdf"]);
}

#[test]
fn limits_are_set_by_name_and_named_when_exceeded() {
    let d = scene_dir("limits");
    let err = exits(&d, &["render", "ball.sdf", "--limit", "speed=3"], 2);
    assert_has(&err, &["unknown limit `speed`", "fuel"]);
    for bad in ["aa=0", "aa=x", "aa"] {
        let out = sdfc(&d, &["check", "ball.sdf", "--limit", bad]);
        assert_eq!(out.status.code(), Some(2), "{bad}");
    }
    // A loop over the objects limit: E0507 naming the flag with the value that would do
    // (the loop's count, not twice the limit), and the flag raises it.
    let many = "scene { for i in 0..50 { sphere(0.1).translate(i, 0, 0); } }\n";
    put(&d, "many.sdf", many);
    let err = exits(&d, &["check", "many.sdf", "--limit", "objects=20"], 1);
    assert_has(&err, &["E0507", "--limit objects=50"]);
    let out = sdfc(&d, &["check", "many.sdf", "--limit", "objects=50"]);
    assert!(out.status.success());
    // The render settings' limits: in the scene (E0400) and on the command line (exit 2).
    let err = exits(&d, &["render", "ball.sdf", "--aa", "20"], 2);
    assert_has(&err, &["--limit aa=20"]);
    for (set, flag) in [
        ("max_steps=2000000", "--limit max_steps=2000000"),
        ("max_depth=100", "--limit max_depth=100"),
        ("width=20000", "--limit edge=20000"),
        ("samples=70000", "--limit samples=70000"),
        ("bounces=100", "--limit bounces=100"),
    ] {
        let err = exits(&d, &["render", "ball.sdf", "--set", set], 2);
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
        put(&d, "path.sdf", text);
        let out = sdfc(&d, &["check", "path.sdf"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{setting}: {err}");
        assert!(
            err.contains("E0400") && err.contains("path.sdf:1:") && err.contains(wanted),
            "{setting}: {err}"
        );
    }
    std::fs::remove_file(d.join("path.sdf")).expect("remove");
    ok(
        &d,
        &[
            "render", "ball.sdf", "--aa", "20", "--limit", "aa=20", "--size", "4x4",
        ],
    );
    // The program limit, after lowering and before any output.
    for args in [
        &words("compile ball.sdf --emit wgsl --limit program=10 -o k.wgsl")[..],
        &["render", "ball.sdf", "--limit", "program=10", "-o", "p.png"],
    ] {
        let out = sdfc(&d, args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert_has(&err, &["E0507", "distance program has", "--limit program="]);
    }
    // `check` passes the scene and warns, located, that a render will refuse it (issue 37).
    let err = exits(&d, &["check", "many.sdf", "--limit", "program=100"], 0);
    assert_has(
        &err,
        &[
            "[E0507] Warning",
            "will refuse this scene",
            "many.sdf:1:1",
            "--limit program=",
            "many.sdf: ok",
        ],
    );
    let out = sdfc(&d, &["check", "many.sdf"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && !err.contains("E0507"), "{err}");
    assert_eq!(entries(&d), ["ball.png", "ball.sdf", "many.sdf"]);
}

/// Whether `sdfc` finds a wgpu adapter here; if not, the caller skips (saying so) unless
/// SDFC_REQUIRE_DEVICES=1 (set by CI, which installs lavapipe).
pub(crate) fn wgpu_available(d: &Path) -> bool {
    let out = sdfc(
        d,
        &words("render ball.sdf --backend wgpu --size 8x8 -o probe.png"),
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
}
