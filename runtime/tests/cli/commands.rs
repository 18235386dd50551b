//! The smaller commands: `sdfc bench`, `pareto`'s limits, `compile` (binary output, `--set`),
//! `fmt`, and a scene's parameters (`--param`) as `check` lists them and `render` refuses them.

use crate::cli::{dir, entries, exits, ok, png_size, put, scene_dir, sdfc};
use crate::common::assert_has;
use crate::common::words;
use std::path::Path;
use std::process::Command;

#[test]
fn bench_prints_a_table_or_json() {
    let d = scene_dir("bench");
    let out = ok(
        &d,
        &words("bench ball.sdf --backend cpu --size 16x12 --frames 2"),
    );
    let table = String::from_utf8_lossy(&out.stdout);
    assert_has(&table, &["Mrays/s", "ball.sdf"]);
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
    let out = ok(
        &d,
        &words("bench ball.sdf --backend cpu --size 16x12 --frames 1 --set method=path --set samples=1 --json"),
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    let method = v[0]["method"].as_str().unwrap_or("").to_string();
    assert!(method == "path+trace" || method == "path+march", "{method}");
}

/// issue 16, item 2: `sdfc pareto` counts the combinations of its sweeps before building
/// them, against the `sweep_points` limit, and each sweep against `sweep_values`.
#[test]
fn pareto_sweeps_are_bounded_by_limits() {
    let d = scene_dir("pareto-limits");
    let err = exits(
        &d,
        &words("pareto ball.sdf --sweep epsilon=1e-2..1e-6:100 --sweep max_steps=32..1024:100 --sweep relaxation=1..1.8:100"),
        2,
    );
    assert_has(
        &err,
        &[
            "combinations of settings, more than 1000",
            "--limit sweep_points=",
        ],
    );
    let err = exits(&d, &["pareto", "ball.sdf", "--sweep", "aa=1..2000"], 2);
    assert_has(&err, &["--limit sweep_values="]);
}

/// `--emit spirv` (and `params`) writes binary: to a terminal it is refused (exit 2, pointing at `-o`),
/// while to a pipe or a file it is written. The terminal is a pseudo-terminal from
/// util-linux's `script`.
#[test]
fn spirv_is_not_written_to_a_terminal() {
    let d = scene_dir("spirv-tty");
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
    assert_has(&text, &["-o FILE"]);
    assert!(
        !text.contains('\u{0}'),
        "binary reached the terminal: {text:?}"
    );
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
        let out = ok(&d, args);
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
    put(&d, "a.sdf", messy);
    put(&sub, "b.sdf", tidy);
    put(&sub, "c.sdf", messy);
    put(&d, "broken.sdf", "let r = ;\n");

    let out = sdfc(&d, &["fmt", "--check", "a.sdf", "more"]);
    assert_eq!(out.status.code(), Some(1));
    let named = String::from_utf8_lossy(&out.stdout).replace('\\', "/");
    assert_eq!(named, "a.sdf\nmore/c.sdf\n");
    assert_eq!(
        std::fs::read_to_string(d.join("a.sdf")).expect("read"),
        messy
    );

    exits(&d, &["fmt", "a.sdf", "more"], 0);
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
        put(&sub, "c.sdf", messy);
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
        put(&sub, "c.sdf", tidy);
    }

    let out = sdfc(&d, &["fmt", "broken.sdf"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_has(&err, &["E0100", "not formatted"]);
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
}

#[test]
fn parameters_are_listed_set_and_refused_before_any_work() {
    let d = dir("params");
    put(
        &d,
        "part.sdf",
        "param width = 40.0 in 10..100 \"Box width (mm)\";\n\
         light point { position: (0, 5, -5) }\n\
         scene { box((width / 100, 0.5, 0.5)); }\n",
    );
    let out = sdfc(&d, &["check", "part.sdf", "--param", "width=60"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert_has(
        &err,
        &["param width = 60 (default 40) in 10..100: Box width (mm)"],
    );
    let out = sdfc(&d, &["check", "part.sdf", "--diagnostics", "json"]);
    let json = String::from_utf8_lossy(&out.stdout);
    assert_has(&json, &["\"name\":\"width\"", "\"max\":100.0"]);
    // Out of range: refused at the declaration, nothing written.
    let err = exits(
        &d,
        &words("render part.sdf -o part.png --param width=500"),
        1,
    );
    assert_has(&err, &["`--param width=500` is outside", "part.sdf:1:7"]);
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
    ok(
        &d,
        &[
            "render", "part.sdf", "-o", "part.png", "--param", "width=80", "--size", "32x24",
        ],
    );
    assert_eq!(png_size(&d.join("part.png")), (32, 24));
}
