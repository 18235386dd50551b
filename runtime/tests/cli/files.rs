//! The files every command reads and writes: missing, unreadable and special inputs, the
//! `file_size` limit, outputs that cannot be written (a missing folder, a read-only file, a full
//! device), and a byte-order mark. Failure paths: docs/failures.md lists each with its test.

use crate::cli::{dir, entries, exits, put, scene_dir, scene_file, sdfc};
use crate::common::assert_has;
use crate::common::words;
use std::path::Path;
use std::process::Command;

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
    put(&d, "latin1.sdf", b"scene { sphere(); } // caf\xe9\n");
    let out = sdfc(&d, &["render", "latin1.sdf"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("not valid UTF-8"));
    assert_eq!(entries(&d), ["folder.sdf", "latin1.sdf"]);
}

#[test]
fn a_missing_or_invalid_output_directory_leaves_nothing() {
    let d = scene_dir("outputs");
    put(&d, "plain-file", "x");
    for target in ["missing/out.png", "plain-file/out.png"] {
        let out = sdfc(&d, &["render", "ball.sdf", "-o", target]);
        assert_eq!(out.status.code(), Some(2), "{target}");
        assert!(
            String::from_utf8_lossy(&out.stderr).contains("cannot write"),
            "{target}"
        );
    }
    let out = sdfc(&d, &words("compile ball.sdf --emit wgsl -o missing/k.wgsl"));
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(entries(&d), ["ball.sdf", "plain-file"]);
}

#[test]
fn an_unwritable_output_is_refused_before_the_render() {
    let d = scene_dir("early");
    // A render that would take long: refused before it is lowered or announced.
    let out = sdfc(
        &d,
        &words("render ball.sdf --size 4000x4000 --aa 4 -o /nonexistent/x.png"),
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_has(
        &err,
        &["cannot write `/nonexistent/x.png`", "does not exist"],
    );
    assert!(!err.contains("allocating"), "the render started: {err}");
    // `pareto` checks its chart's place before its sweeps.
    let out = sdfc(
        &d,
        &words("pareto ball.sdf --frames 1 -o missing/chart.svg"),
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty(), "the sweeps ran");
    assert!(String::from_utf8_lossy(&out.stderr).contains("does not exist"));
    assert_eq!(entries(&d), ["ball.sdf"]);
}

/// A read-only output file is refused (exit 2, saying so) and left as it was, by `render`
/// before the render starts and by `compile`.
#[test]
fn a_read_only_output_is_refused_and_left_unchanged() {
    use std::os::unix::fs::PermissionsExt;
    let d = scene_dir("read-only");
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
    put(&d, "tree/ok.sdf", "scene {\n  sphere(1);\n}\n");
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
    put(
        &d,
        "imports.sdf",
        "import \"pipe.sdf\";\nscene {\n  sphere(1);\n}\n",
    );
    put(&d, "meshes.sdf", "scene {\n  mesh(\"pipe.stl\");\n}\n");
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
    put(
        &d,
        "big.sdf",
        format!("// {}\nscene {{\n  sphere(1);\n}}\n", "x".repeat(3 << 20)),
    );
    let err = exits(&d, &["check", "--limit", "file_size=2", "big.sdf"], 2);
    assert_has(
        &err,
        &["over the file_size limit of 2 MiB; raise it with `--limit file_size=4`"],
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
    assert_has(
        &err,
        &["standard input: it is over the file_size limit of 1 MiB"],
    );
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
        put(&d, "bad.sdf", "scene { sphre(1); }\n");
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
    exits(&d, &["fmt", "messy.sdf"], 0);
    assert_eq!(
        std::fs::read_to_string(&messy).expect("read"),
        "scene {\n  sphere(1);\n}\n"
    );
    let mode = std::fs::metadata(&messy)
        .expect("stat")
        .permissions()
        .mode();
    assert_eq!(mode & 0o777, 0o600, "{mode:o}");
}

/// A UTF-8 byte-order mark at the start of a file (some editors write one) is skipped: the
/// file checks, compiles and formats, and a diagnostic on its first line is at the column of
/// the visible character.
#[test]
fn a_byte_order_mark_is_skipped() {
    let d = dir("bom");
    put(&d, "bom.sdf", "\u{feff}scene {\n  sphre(1);\n}\n");
    put(
        &d,
        "ok.sdf",
        "\u{feff}import \"lib.sdf\";\nscene {\n  ball;\n}\n",
    );
    put(&d, "lib.sdf", "\u{feff}let ball = sphere(1);\n");
    let out = sdfc(&d, &["check", "--diagnostics", "json", "bom.sdf"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(!stdout.contains("E0001"), "{stdout}");
    assert!(stdout.contains("E0201"), "the misspelt sphere: {stdout}");
    exits(&d, &["check", "ok.sdf"], 0);
    exits(&d, &["compile", "ok.sdf", "--emit", "ir"], 0);
    exits(&d, &["fmt", "ok.sdf"], 0);
    assert_eq!(
        std::fs::read_to_string(d.join("ok.sdf")).expect("read"),
        "import \"lib.sdf\";\nscene {\n  ball;\n}\n"
    );
    put(&d, "first.sdf", "\u{feff}scene { sphre(1); }\n");
    let out = sdfc(&d, &["check", "first.sdf"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_has(&err, &["first.sdf:1:9"]);
}
