//! Animation (docs/animation.md): the time `t` in every kind of field, what reads it and what
//! may not, `sdfc check`'s still / numbers only / structure varies, and `sdfc render
//! --frames`: numbering, shards (every frame exactly once), skipping written frames and
//! resuming after a killed render, animated PNG, the video's `ffmpeg`; and the job-array
//! files of examples/jobs parsed by the tools of their ecosystems.

use sdfc_compiler::{
    check_at, Colour, Diagnostic, Light, Limits, NoImports, Node, Pattern, Scene, SourceMap,
};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Checks `text` at the time `t`.
fn at(text: &str, t: f64) -> (Option<Scene>, Vec<Diagnostic>) {
    let mut sources = SourceMap::new();
    let entry = sources.add("anim.sdf", text);
    check_at(&mut sources, entry, &mut NoImports, &Limits::default(), t)
}

/// The scene of `text` at `t`, which must check cleanly.
fn scene(text: &str, t: f64) -> Scene {
    let (s, d) = at(text, t);
    assert!(
        d.iter().all(|d| !d.is_error()),
        "{text} at t = {t}: {:?}",
        d.iter().map(|d| &d.message).collect::<Vec<_>>()
    );
    s.expect("scene")
}

const BASE: &str = "material m = phong { color: (0.8, 0.2, 0.2) };
light point { position: (2, 4, -3) }
";

/// Reads a number out of a checked scene.
type Read = fn(&Scene) -> f64;

#[test]
fn t_reaches_every_kind_of_field() {
    // Each case: a scene reading `t` in one place, and what it must read at t = 0.5.
    let cases: &[(&str, Read)] = &[
        ("scene { sphere(1 + t) @ m; }", |s| match s.graph.node(s.root.unwrap()) {
            Node::Paint { child, .. } => match s.graph.node(*child) {
                Node::Sphere { radius } => *radius,
                n => panic!("{n:?}"),
            },
            n => panic!("{n:?}"),
        }),
        (
            "camera { position: (0, 1, -5 - t), look_at: (0, 0, 0) } scene { sphere(1); }",
            |s| s.camera.position[2],
        ),
        (
            "camera { fov: degrees(40 + 20 * t) } scene { sphere(1); }",
            |s| s.camera.fov.to_degrees(),
        ),
        (
            "material n = phong { color: (t, 0.5, 0.5), reflect: t / 2 } scene { sphere(1) @ n; }",
            |s| s.materials[2].reflect + 10.0 * pattern_red(s),
        ),
        (
            "material n = checker { size: 1 + t } scene { sphere(1) @ n; }",
            |s| match s.materials[2].pattern {
                Pattern::Checker { size, .. } => size,
                _ => panic!("not a checker"),
            },
        ),
        (
            "light directional { direction: (0, -1, 0), intensity: t, penumbra: degrees(4 * t) } scene { sphere(1); }",
            |s| match s.lights[1] {
                Light::Directional {
                    intensity, penumbra, ..
                } => intensity + penumbra.to_degrees(),
                _ => panic!("not directional"),
            },
        ),
        (
            "render { max_steps: 100 + int(t * 100), epsilon: 0.001 * (1 + t), background: (t, t, t) } scene { sphere(1); }",
            |s| s.settings.max_steps as f64 + 1000.0 * s.settings.epsilon + s.settings.background[0],
        ),
        (
            "scene { for i in 0..int(4 * t) + 1 { sphere(0.2).translate(i, 0, 0); } }",
            |s| match s.graph.node(s.root.unwrap()) {
                Node::Combine { children, .. } => children.len() as f64,
                _ => 1.0,
            },
        ),
        (
            "scene { if t > 0.25 { box(1) } else { sphere(1) }; }",
            |s| match s.graph.node(s.root.unwrap()) {
                Node::Box { .. } => 1.0,
                _ => 0.0,
            },
        ),
        (
            "fn grow(r: float) -> shape { sphere(r + t + 1) } let size = 2 * t; scene { grow(size); grow(size); }",
            |s| match s.graph.node(s.root.unwrap()) {
                Node::Combine { children, .. } => match s.graph.node(children[0]) {
                    Node::Sphere { radius } => *radius,
                    n => panic!("{n:?}"),
                },
                // Both objects are the same sphere, hash-consed.
                Node::Sphere { radius } => *radius,
                n => panic!("{n:?}"),
            },
        ),
    ];
    let expected = [
        1.5,
        -5.5,
        50.0,
        5.0 + 0.25,
        1.5,
        0.5 + 2.0,
        150.0 + 1.5 + 0.5,
        3.0,
        1.0,
        2.5,
    ];
    for ((text, read), want) in cases.iter().zip(expected) {
        let text = format!("{BASE}{text}");
        let s = scene(&text, 0.5);
        assert!(s.animation.animated(), "{text} does not read t");
        assert_eq!(s.animation.time, 0.5);
        let got = read(&s);
        assert!((got - want).abs() < 1e-9, "{text}: {got}, expected {want}");
        // At another time the value differs: the scene was checked at that time.
        let other = read(&scene(&text, 0.0));
        assert!((other - want).abs() > 1e-6, "{text}: the same at t = 0");
    }
}

fn pattern_red(s: &Scene) -> f64 {
    match s.materials[2].pattern {
        Pattern::Solid(Colour::Const(c)) => c[0],
        _ => panic!("not solid"),
    }
}

#[test]
fn scenes_that_do_not_evaluate_t_are_stills() {
    for text in [
        "scene { sphere(1); }",
        // A constant, parameter or loop variable named `t` hides the time.
        "let t = 2; scene { sphere(t); }",
        "fn f(t: float) -> shape { sphere(t) } scene { f(1); }",
        "scene { for t in 1..3 { sphere(t); } }",
        // A function that reads `t` but is never called: checked, not evaluated.
        "fn pulse() -> shape { sphere(1 + t) } scene { sphere(1); }",
    ] {
        let s = scene(&format!("{BASE}{text}"), 1.0);
        assert!(!s.animation.animated(), "{text} is animated");
    }
    // A memoised call still reports that it reads the time, at every use.
    let s = scene(
        &format!("{BASE}fn f(r: float) -> float {{ r + t }} let a = f(1); let b = f(1); render {{ epsilon: 0.001 * b }} scene {{ sphere(1); }}"),
        0.5,
    );
    assert!(s.animation.animated());
    assert!((s.settings.epsilon - 0.0015).abs() < 1e-12);
}

#[test]
fn the_sequence_settings_cannot_read_t() {
    for (text, field) in [
        (
            "render { width: 100 + int(t) } scene { sphere(1); }",
            "width",
        ),
        ("render { fps: 30 + t } scene { sphere(1); }", "fps"),
        // Through a constant and through a function: the secondary label points at `t`.
        (
            "let d = 2 + t; render { duration: d } scene { sphere(1); }",
            "duration",
        ),
        (
            "fn h() -> int { int(t) + 50 } render { height: h() } scene { sphere(1); }",
            "height",
        ),
    ] {
        let text = format!("{BASE}{text}");
        let (s, d) = at(&text, 0.0);
        assert!(s.is_none(), "{text}");
        let e = d
            .iter()
            .find(|d| d.code == "E0406")
            .unwrap_or_else(|| panic!("{text}: {d:?}"));
        assert!(e.message.contains(field), "{}", e.message);
        let read = e.labels.get(1).expect("secondary label").span;
        assert_eq!(&text[read.start as usize..read.end as usize], "t", "{text}");
    }
    // `t` elsewhere in `render` is fine.
    let s = scene(
        &format!(
            "{BASE}render {{ max_depth: 2 + int(t), fps: 24, duration: 2 }} scene {{ sphere(1); }}"
        ),
        1.0,
    );
    assert_eq!(s.settings.max_depth, 3);
    assert_eq!(s.animation.frames(), 48);
}

#[test]
fn too_many_frames_is_a_limit() {
    let (s, d) = at(
        &format!("{BASE}render {{ fps: 1000, duration: 1e6 }} scene {{ sphere(1); }}"),
        0.0,
    );
    assert!(s.is_none());
    let e = d.iter().find(|d| d.code == "E0507").expect("E0507");
    assert!(
        e.notes.iter().any(|n| n.contains("--limit frames=")),
        "{e:?}"
    );
}

// ---- the CLI ----

/// A small animated scene: a sphere moving along x.
const MOVING: &str = "material red = phong { color: (1, 0.2, 0.1) };
camera { position: (0, 1, -5), look_at: (0, 0.5, 0), fov: 50deg }
light point { position: (2, 4, -3) }
render { width: 32, height: 24, fps: 10, duration: 1 }
scene { plane(); sphere(0.5).translate(-1 + 0.2 * t * 10, 0.5, 0) @ red; }
";

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sdfc-anim-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

fn sdfc(cwd: &Path, args: &[&str]) -> Output {
    sdfc_env(cwd, args, &[])
}

fn sdfc_env(cwd: &Path, args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_sdfc"));
    c.current_dir(cwd).args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("run sdfc")
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn files(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .map(|r| {
            r.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

#[test]
fn frames_are_numbered_by_the_pattern_in_a_new_directory() {
    let d = dir("numbered");
    std::fs::write(d.join("moving.sdf"), MOVING).unwrap();
    let o = sdfc(
        &d,
        &[
            "render",
            "moving.sdf",
            "--backend",
            "cpu",
            "--frames",
            "8..11",
            "-o",
            "out/sub/f_###.png",
        ],
    );
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(
        files(&d.join("out/sub")),
        ["f_008.png", "f_009.png", "f_010.png"]
    );
    // The frames differ: the sphere moves.
    let a = std::fs::read(d.join("out/sub/f_008.png")).unwrap();
    let b = std::fs::read(d.join("out/sub/f_010.png")).unwrap();
    assert_ne!(a, b);
    // Without --frames, the pattern renders the scene's fps × duration; numbers wider than
    // the run are written in full.
    let o = sdfc(
        &d,
        &[
            "render",
            "moving.sdf",
            "--backend",
            "cpu",
            "-o",
            "all/#.png",
        ],
    );
    assert!(o.status.success(), "{}", text(&o));
    let want: Vec<String> = (0..10).map(|k| format!("{k}.png")).collect::<Vec<_>>();
    let mut want = want;
    want.sort();
    assert_eq!(files(&d.join("all")), want);
    // A second run of `#`, or an extension that is no image, is refused before rendering.
    for bad in ["x/#_#.png", "x/f_##.txt"] {
        let o = sdfc(&d, &["render", "moving.sdf", "--frames", "0..2", "-o", bad]);
        assert_eq!(o.status.code(), Some(2), "{bad}: {}", text(&o));
        assert!(
            !d.join("x").exists() || files(&d.join("x")).is_empty(),
            "{bad}"
        );
    }
}

#[test]
fn shards_render_every_frame_exactly_once() {
    let d = dir("shards");
    std::fs::write(d.join("moving.sdf"), MOVING).unwrap();
    let n = 3;
    for i in 0..n {
        let o = sdfc(
            &d,
            &[
                "render",
                "moving.sdf",
                "--backend",
                "cpu",
                "--frames",
                "0..10",
                "--shard",
                &format!("{i}/{n}"),
                "-o",
                &format!("s{i}/f_##.png"),
            ],
        );
        assert!(o.status.success(), "{}", text(&o));
    }
    let mut all = Vec::new();
    for i in 0..n {
        for f in files(&d.join(format!("s{i}"))) {
            let k: u64 = f[2..4].parse().unwrap();
            assert_eq!(k % n, i, "shard {i} rendered frame {k}");
            all.push(k);
        }
    }
    all.sort();
    assert_eq!(all, (0..10).collect::<Vec<u64>>());
    // A shard's frames are the frames its index picks out, whatever the others did.
    let o = sdfc(
        &d,
        &[
            "render",
            "moving.sdf",
            "--frames",
            "0..4",
            "--shard",
            "3/3",
            "-o",
            "x_#.png",
        ],
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    // An animated PNG cannot be sharded.
    let o = sdfc(
        &d,
        &[
            "render",
            "moving.sdf",
            "--frames",
            "0..4",
            "--shard",
            "0/2",
            "-o",
            "a.png",
        ],
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
}

#[test]
fn a_killed_render_resumes_where_it_stopped() {
    let d = dir("resume");
    std::fs::write(d.join("moving.sdf"), MOVING).unwrap();
    let out = d.join("out");
    // Slow frames (big, supersampled) so that the kill lands mid-sequence.
    let mut child = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&d)
        .args([
            "render",
            "moving.sdf",
            "--backend",
            "cpu",
            "--frames",
            "0..40",
            "--size",
            "320x240",
            "--aa",
            "3",
            "-o",
            "out/f_##.png",
        ])
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("spawn");
    let start = std::time::Instant::now();
    while files(&out)
        .iter()
        .filter(|f| f.ends_with(".png") && !f.starts_with('.'))
        .count()
        < 2
    {
        assert!(start.elapsed().as_secs() < 120, "no frames written");
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    child.kill().expect("kill");
    child.wait().expect("wait");
    let written: Vec<String> = files(&out)
        .into_iter()
        .filter(|f| !f.starts_with('.'))
        .collect();
    assert!(written.len() >= 2 && written.len() < 40, "{written:?}");
    // Every file there is a whole PNG: frames are written to a temporary file and renamed.
    for f in &written {
        sdfc_runtime::image::read_png(&out.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
    }
    // A temporary file left by a kill during a write does not count as a frame.
    std::fs::write(out.join(".f_39.png.999999.tmp"), b"partial").unwrap();
    let before: Vec<_> = written
        .iter()
        .map(|f| std::fs::metadata(out.join(f)).unwrap().modified().unwrap())
        .collect();
    let o = sdfc(
        &d,
        &[
            "render",
            "moving.sdf",
            "--backend",
            "cpu",
            "--frames",
            "0..40",
            "--size",
            "320x240",
            "--aa",
            "3",
            "-o",
            "out/f_##.png",
        ],
    );
    assert!(o.status.success(), "{}", text(&o));
    let log = text(&o);
    assert!(
        log.contains(&format!(
            "{} to render, {} already written",
            40 - written.len(),
            written.len()
        )),
        "{log}"
    );
    let done: Vec<String> = files(&out)
        .into_iter()
        .filter(|f| !f.starts_with('.'))
        .collect();
    assert_eq!(done.len(), 40);
    // The frames written before were not written again; --force writes them all.
    for (f, t) in written.iter().zip(&before) {
        assert_eq!(
            std::fs::metadata(out.join(f)).unwrap().modified().unwrap(),
            *t,
            "{f}"
        );
    }
    let o = sdfc(
        &d,
        &[
            "render",
            "moving.sdf",
            "--backend",
            "cpu",
            "--frames",
            "0..3",
            "-o",
            "out/f_##.png",
            "--force",
        ],
    );
    assert!(
        text(&o).contains("3 to render, 0 already written"),
        "{}",
        text(&o)
    );
}

#[test]
fn an_animated_png_holds_every_frame() {
    let d = dir("apng");
    std::fs::write(d.join("moving.sdf"), MOVING).unwrap();
    let o = sdfc(
        &d,
        &[
            "render",
            "moving.sdf",
            "--backend",
            "cpu",
            "--frames",
            "0..6",
            "-o",
            "loop.png",
        ],
    );
    assert!(o.status.success(), "{}", text(&o));
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(d.join("loop.png")).unwrap(),
    ));
    let mut reader = decoder.read_info().unwrap();
    let info = reader.info();
    let control = *info.animation_control().expect("an APNG");
    assert_eq!(control.num_frames, 6);
    assert_eq!((info.width, info.height), (32, 24));
    let fc = *info.frame_control().expect("frame control");
    assert_eq!((fc.delay_num, fc.delay_den), (100, 1000));
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let mut frames = Vec::new();
    while reader.next_frame(&mut buf).is_ok() {
        frames.push(buf.clone());
    }
    assert_eq!(frames.len(), 6);
    assert_ne!(frames[0], frames[5]);
    assert_eq!(files(&d), ["loop.png", "moving.sdf"]);
}

#[test]
fn a_video_needs_ffmpeg_on_path() {
    let d = dir("video");
    std::fs::write(d.join("moving.sdf"), MOVING).unwrap();
    let empty = d.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let o = sdfc_env(
        &d,
        &["render", "moving.sdf", "--frames", "0..3", "-o", "clip.mp4"],
        &[("PATH", empty.to_str().unwrap())],
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).contains("needs `ffmpeg` on PATH"), "{}", text(&o));
    // A stand-in ffmpeg that keeps the raw frames it reads and its arguments: the frames
    // arrive as raw RGB of the image's size, and the file appears only when it succeeds.
    let bin = d.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    let fake = bin.join("ffmpeg");
    std::fs::write(
        &fake,
        "#!/bin/sh\nPATH=/usr/bin:/bin\nfor a; do last=$a; done\necho \"$@\" > \"$(dirname \"$last\")/args.txt\"\ncat > \"$last\"\n",
    )
    .unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).unwrap();
    let o = sdfc_env(
        &d,
        &[
            "render",
            "moving.sdf",
            "--backend",
            "cpu",
            "--frames",
            "0..3",
            "-o",
            "clip.mp4",
        ],
        &[("PATH", bin.to_str().unwrap())],
    );
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(
        std::fs::metadata(d.join("clip.mp4")).unwrap().len(),
        3 * 32 * 24 * 3
    );
    let args = std::fs::read_to_string(d.join("args.txt")).unwrap();
    assert!(
        args.contains("-s 32x24") && args.contains("-framerate 10"),
        "{args}"
    );
}

#[test]
fn check_says_still_numbers_or_structure() {
    let d = dir("check");
    let write = |name: &str, body: &str| {
        std::fs::write(d.join(name), format!("{BASE}{body}")).unwrap();
    };
    write("still.sdf", "render { duration: 2 } scene { sphere(1); }");
    write(
        "numbers.sdf",
        "render { fps: 4, duration: 2 } scene { sphere(1).translate(0, 1 + t, 0) @ m; }",
    );
    write(
        "structure.sdf",
        "render { fps: 4, duration: 2 } scene { if t < 1 { sphere(1) } else { box(1) }; for i in 0..int(2 * t) + 1 { sphere(0.1).translate(i, 2, 0); } }",
    );
    write(
        "broken.sdf",
        "render { fps: 4, duration: 2 } scene { sphere(1.5 - t); }",
    );
    let line = |f: &str| {
        let o = sdfc(&d, &["check", f]);
        (o.status.code(), text(&o))
    };
    let (code, out) = line("still.sdf");
    assert_eq!(code, Some(0));
    assert!(out.contains("still.sdf: still"), "{out}");
    let (code, out) = line("numbers.sdf");
    assert_eq!(code, Some(0));
    assert!(out.contains("animated, numbers only"), "{out}");
    assert!(out.contains("8 frames at 4 fps"), "{out}");
    let (code, out) = line("structure.sdf");
    assert_eq!(code, Some(0));
    assert!(
        out.contains("structure varies: 4 structures, changing at frames 2, 4, 6"),
        "{out}"
    );
    // Each change is said where it happens in the source, and how.
    for said in [
        "[N0001] Advice: the structure changes at frame 2 (t = 0.5 s)",
        "has 3 parts, 2 in the frame before",
        "[N0001] Advice: the structure changes at frame 4 (t = 1 s)",
        "`box` here was `sphere`",
        "structure.sdf:",
    ] {
        assert!(out.contains(said), "{said}: {out}");
    }
    // A frame whose scene does not check is reported with its time.
    let (code, out) = line("broken.sdf");
    assert_eq!(code, Some(1));
    assert!(out.contains("frame 6 (t = 1.5 s) has errors"), "{out}");
}

/// A sequence whose source changes only in numbers: a radius, an offset, a rotation passing
/// through 0 and a quarter turn, a twist whose rate passes through 0 (its L through 1), a ring
/// of shapes turning past each other (a union's hierarchy), a moving camera and light. Every
/// frame has one structure and one kernel text: the lowering's choices that depend on numbers
/// (a local bound where L > 1, the hierarchy's splits and order, the nearer volume of a
/// bound, the comments' numbers) are constants of the program, not its shape.
const NUMBERS_ONLY: &str = "material m = phong { color: (0.8, 0.2, 0.2) };
let a = degrees(90 * t - 90);
let o = sin(degrees(120 * t));
camera { position: (7 * sin(a), 2.5, -7 * cos(a)), look_at: (0, 0.5, 0) }
light point { position: (4 * cos(a), 5, -4 + o) }
render { fps: 12, duration: 3 }
scene {
  plane((0, 1, 0), 0);
  sphere(0.4 + 0.2 * o).translate(o, 0.6, 0) @ m;
  box((0.3, 0.2 + 0.1 * t, 0.3)).rotate_y(a).translate(-1.5, 0.3, 0);
  torus(0.5, 0.1).twist(0.8 * o).translate(1.5, 0.5, 0);
  for i in 0..24 {
    sphere(0.15).translate(3 * cos(degrees(15 * i) + a), 0.3 + 0.1 * sin(degrees(40 * i) + a),
      3 * sin(degrees(15 * i) + a));
  }
}
";

#[test]
fn a_sequence_that_moves_only_numbers_keeps_one_structure_and_one_kernel() {
    let d = dir("moving");
    std::fs::write(d.join("moving.sdf"), NUMBERS_ONLY).unwrap();
    let o = sdfc(&d, &["check", "moving.sdf"]);
    let out = text(&o);
    assert_eq!(o.status.code(), Some(0), "{out}");
    assert!(
        out.contains("moving.sdf: animated, numbers only") && out.contains("36 frames at 12 fps"),
        "{out}"
    );
    // The kernels of frames at the rotation's 0 and quarter turn, the twist's 0 and between.
    let texts: Vec<String> = [0u64, 1, 12, 24, 35]
        .iter()
        .map(|&k| {
            let s = scene(NUMBERS_ONLY, sdfc_compiler::Animation::time_of(12.0, k));
            let l = sdfc_compiler::lower_scene(&s, &sdfc_compiler::LowerOptions::parametric());
            kernel(&s, &l, true).source
        })
        .collect();
    for (k, t) in texts.iter().enumerate() {
        assert!(*t == texts[0], "the kernel of the {k}th frame differs");
    }
}

/// The job-array files of the README: the Slurm script parses with `bash -n`, the
/// Kubernetes manifest with a YAML parser (python3's `yaml`), and both run `sdfc render`
/// with the shard of their index.
#[test]
fn job_array_files_parse() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let slurm = root.join("examples/jobs/slurm.sh");
    let o = Command::new("bash")
        .arg("-n")
        .arg(&slurm)
        .output()
        .expect("bash");
    assert!(o.status.success(), "{}", text(&o));
    let script = std::fs::read_to_string(&slurm).unwrap();
    assert!(script.contains("#SBATCH --array="));
    assert!(script.contains("--shard \"$SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT\""));
    let k8s = root.join("examples/jobs/kubernetes.yaml");
    // The README shows both files as they are.
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    for f in [&slurm, &k8s] {
        let text = std::fs::read_to_string(f).unwrap();
        assert!(
            readme.contains(&text),
            "README.md does not show {} as it is",
            f.display()
        );
    }
    let check = "import sys, yaml\n\
                 docs = list(yaml.safe_load_all(open(sys.argv[1])))\n\
                 job = [d for d in docs if d['kind'] == 'Job'][0]\n\
                 spec = job['spec']\n\
                 assert spec['completionMode'] == 'Indexed', spec\n\
                 assert spec['completions'] == spec['parallelism'] or spec['parallelism'] >= 1\n\
                 c = spec['template']['spec']['containers'][0]\n\
                 cmd = ' '.join(c['command'] + c.get('args', []))\n\
                 assert '--shard' in cmd and 'JOB_COMPLETION_INDEX' in cmd, cmd\n\
                 assert str(spec['completions']) in cmd, cmd\n\
                 print('ok', spec['completions'])\n";
    let o = Command::new("python3")
        .args(["-c", check])
        .arg(&k8s)
        .output()
        .expect("python3");
    if String::from_utf8_lossy(&o.stderr).contains("No module named 'yaml'") {
        assert!(
            std::env::var_os("SDFC_REQUIRE_DEVICES").is_none(),
            "python3's yaml module is missing"
        );
        eprintln!("skipped: python3 has no yaml module");
        return;
    }
    assert!(o.status.success(), "{}", text(&o));
}

#[test]
fn bench_times_a_sequence_and_counts_its_kernels() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let o = sdfc(
        &root,
        &[
            "bench",
            "--frames-per-second",
            "--backend",
            "cpu",
            "--size",
            "64x48",
            "--sequence",
            "0..5",
            "--json",
            "examples/animation/orbit.sdf",
        ],
    );
    assert!(o.status.success(), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    let t = &v[0];
    assert_eq!(t["timed"], 4);
    assert_eq!(
        (t["width"].as_u64(), t["height"].as_u64()),
        (Some(64), Some(48))
    );
    // Only the camera moves: one program, one preparation for the whole sequence.
    assert_eq!(t["kernels"], 1, "{t}");
    assert!(t["frames_per_s"].as_f64().unwrap() > 0.0);
    // A scene without a duration needs --sequence.
    let d = dir("bench");
    std::fs::write(d.join("still.sdf"), format!("{BASE}scene {{ sphere(1); }}")).unwrap();
    let o = sdfc(&d, &["bench", "--frames-per-second", "still.sdf"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
}

// ---- one kernel per sequence (stage B) ----

/// The frames `ks` of `file` checked at their times and lowered.
fn frames_of(file: &str, ks: &[u64]) -> Vec<(Scene, sdfc_compiler::Lowered)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut source = sdfc_runtime::frontend::Source::read(&root.join(file)).expect("read");
    ks.iter()
        .map(|&k| {
            let first = source.check(&Limits::default(), 0.0).scene.expect("checks");
            let t = sdfc_compiler::Animation::time_of(first.animation.fps, k);
            let s = source.check(&Limits::default(), t).scene.expect("checks");
            let p = sdfc_compiler::Lowered::new(&s);
            (s, p)
        })
        .collect()
}

fn kernel(s: &Scene, p: &sdfc_compiler::Lowered, parameters: bool) -> sdfc_compiler::wgsl::Kernel {
    let options = sdfc_compiler::wgsl::Options {
        parameters,
        ..Default::default()
    };
    sdfc_compiler::wgsl::write_with(s, p, &options).expect("valid kernel")
}

#[test]
fn frames_that_differ_in_numbers_share_one_kernel_text() {
    // Frame 0 of bounce.sdf has the sphere on the floor, where its height equals its radius
    // and the lowering shares the two constants: the kernel's text is still the same.
    let frames = frames_of("examples/animation/bounce.sdf", &[0, 1, 7, 18]);
    let with: Vec<_> = frames.iter().map(|(s, p)| kernel(s, p, true)).collect();
    for k in &with[1..] {
        assert_eq!(k.source, with[0].source);
        assert!(k.contract.features.contains(&("PARAMS", true)));
    }
    assert_ne!(with[0].data, with[1].data, "the constants differ");
    let literal: Vec<_> = frames.iter().map(|(s, p)| kernel(s, p, false)).collect();
    assert_ne!(literal[1].source, literal[2].source);
    assert!(literal[0].data.is_none());
    // The structure check agrees.
    let structures: Vec<_> = frames
        .iter()
        .map(|(s, p)| sdfc_compiler::animation::Structure::of(s, p))
        .collect();
    assert!(structures.iter().all(|s| *s == structures[0]));
    // Another structure is another text.
    let d = dir("kernels");
    std::fs::write(
        d.join("grow.sdf"),
        format!("{BASE}render {{ fps: 1, duration: 3 }} scene {{ for i in 0..int(t) + 1 {{ sphere(0.3).translate(i, 0, 0) @ m; }} }}"),
    )
    .unwrap();
    let mut source = sdfc_runtime::frontend::Source::read(&d.join("grow.sdf")).unwrap();
    let texts: Vec<String> = [0.0, 1.0]
        .iter()
        .map(|&t| {
            let s = source.check(&Limits::default(), t).scene.unwrap();
            kernel(&s, &sdfc_compiler::Lowered::new(&s), true).source
        })
        .collect();
    assert_ne!(texts[0], texts[1]);
    // The parameter kernel translates to PTX, which ptxas assembles where it is installed.
    let k = &with[1];
    let options = sdfc_compiler::ptx::Options {
        sm: 70,
        entry_point: "main".into(),
    };
    let ptx = sdfc_compiler::ptx::write(&k.module, &k.info, &options)
        .expect("ptx")
        .text;
    let found = std::env::var_os("PATH").and_then(|p| {
        std::env::split_paths(&p)
            .map(|d| d.join("ptxas"))
            .find(|p| p.is_file())
    });
    match found {
        Some(ptxas) => {
            let path = d.join("bounce.ptx");
            std::fs::write(&path, ptx).unwrap();
            let o = Command::new(ptxas)
                .args(["-arch=sm_80", "-o", "/dev/null"])
                .arg(&path)
                .output()
                .expect("ptxas");
            assert!(o.status.success(), "{}", text(&o));
        }
        None => {
            assert!(
                std::env::var("SDFC_REQUIRE_DEVICES").as_deref() != Ok("1"),
                "SDFC_REQUIRE_DEVICES=1 but no ptxas on PATH"
            );
            println!("SKIPPED: no ptxas on PATH; the PTX was written but not assembled");
        }
    }
}

#[test]
fn a_sequence_on_wgpu_compiles_one_kernel_and_matches_the_cpu() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let d = dir("wgpu");
    let scene = root.join("examples/animation/bounce.sdf");
    let scene = scene.to_str().unwrap();
    let run = |backend: &str| {
        sdfc_env(
            &d,
            &[
                "render",
                scene,
                "--backend",
                backend,
                "--frames",
                "0..6",
                "--size",
                "96x72",
                "-o",
                &format!("{backend}/f_#.png"),
            ],
            &[("XDG_RUNTIME_DIR", "/tmp")],
        )
    };
    let o = run("wgpu");
    if !o.status.success() && text(&o).contains("not available") {
        assert!(
            std::env::var("SDFC_REQUIRE_DEVICES").as_deref() != Ok("1"),
            "SDFC_REQUIRE_DEVICES=1 but wgpu is not available: {}",
            text(&o)
        );
        println!("SKIPPED: no wgpu adapter: {}", text(&o));
        return;
    }
    assert!(o.status.success(), "{}", text(&o));
    assert!(
        text(&o).contains("6 frames") && text(&o).contains("1 kernel prepared"),
        "{}",
        text(&o)
    );
    let o = run("cpu");
    assert!(o.status.success(), "{}", text(&o));
    for k in 0..6 {
        let read =
            |b: &str| sdfc_runtime::image::read_png(&d.join(format!("{b}/f_{k}.png"))).unwrap();
        let diff =
            sdfc_runtime::metrics::compare(&read("cpu"), &read("wgpu"), 0.1).expect("same size");
        assert!(diff.psnr > 40.0, "frame {k}: {} dB", diff.psnr);
    }
}

/// Distances and materials of `program` at `points`, in f64.
fn evaluate(program: &sdfc_compiler::Program, points: &[[f64; 3]]) -> (Vec<f64>, Vec<u32>) {
    use sdfc_compiler::{Evaluator, Outputs, Tape};
    let tape = Tape::new(program, Outputs::DistanceAndMaterial);
    let mut ev = Evaluator::<f64>::new(&tape, 64);
    let coord = |i: usize| points.iter().map(|p| p[i]).collect::<Vec<f64>>();
    let (x, y, z) = (coord(0), coord(1), coord(2));
    let mut d = vec![0.0; points.len()];
    let mut m = vec![0u32; points.len()];
    ev.eval(&x, &y, &z, &mut d, Some(&mut m));
    (d, m)
}

/// The lowering of an animation's frames keeps the structure whatever the numbers: a
/// translation through 0 or across it, a rotation through the identity and a quarter turn,
/// a scale through 1, a blend radius through 0 have the structure of every other frame; and the program computes the
/// same distances and materials as the usual lowering, on these and on every example.
#[test]
fn parametric_lowering_keeps_the_structure_and_the_values() {
    use sdfc_compiler::animation::Structure;
    use sdfc_compiler::{lower_scene, lower_with, LowerOptions};
    // At t = 1 the rotation is the identity, the scale 1, the rounding and the blend radii 0
    // (the plain union and subtraction); at t = 2 the
    // translation is 0 and the rotation a quarter turn; the translation is negative before.
    let text = format!(
        "{BASE}scene {{ sphere(0.5).translate(t - 2, 0.5, 0) @ m; \
         box(0.3).rotate_y(degrees(90 * (t - 1))).translate(0, 0.3, 1); \
         torus(1, 0.2).rotate_x(degrees(90 * (t - 1))).scale(t).translate(2, 1, 0); \
         capsule(0.2, 1).round(t - 1).translate(-2, 0.6, 0); \
         smooth_intersect(0.3 * abs(t - 1), sphere(0.4), box(0.3).translate(0.2, 0, 0)).translate(0, 0.4, -2); \
         smooth_subtract(0.2 * abs(t - 1), box(0.4), sphere(0.3).translate(0.3, 0.3, 0), \"chamfer\").translate(1.5, 0.4, -2); }}"
    );
    let times = [1.0, 1.5, 2.0, 3.0];
    let structures = |options: &LowerOptions| -> Vec<Structure> {
        times
            .iter()
            .map(|&t| {
                let s = scene(&text, t);
                Structure::of(&s, &lower_scene(&s, options))
            })
            .collect()
    };
    let parametric = structures(&LowerOptions::parametric());
    assert!(
        parametric.iter().all(|s| *s == parametric[0]),
        "parametric structures differ"
    );
    let usual = structures(&LowerOptions::default());
    assert!(
        usual.iter().any(|s| *s != usual[1]),
        "the usual lowering folds no frame"
    );
    // The same values.
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut scenes: Vec<Scene> = times.iter().map(|&t| scene(&text, t)).collect();
    for dir in ["examples", "examples/animation"] {
        for e in std::fs::read_dir(root.join(dir)).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "sdf") {
                scenes.push(sdfc_runtime::frontend::load(&p).unwrap().scene.unwrap());
            }
        }
    }
    let mut rng = sdfc_compiler::Rng::new(0x2545f4914f6cdd1d);
    let points: Vec<[f64; 3]> = (0..400).map(|_| rng.point(4.0)).collect();
    for (i, s) in scenes.iter().enumerate() {
        let a = evaluate(&sdfc_compiler::lower(s), &points);
        let b = evaluate(&lower_with(s, &LowerOptions::parametric()), &points);
        for ((p, x), y) in points.iter().zip(&a.0).zip(&b.0) {
            assert!(
                (x - y).abs() <= 1e-9 * (1.0 + x.abs()),
                "scene {i}: {p:?}: {x} against {y}"
            );
        }
        assert_eq!(a.1, b.1);
    }
}
