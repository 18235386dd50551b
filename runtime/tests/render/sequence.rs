//! Animated sequences through the CLI (docs/animation.md): `sdfc render --frames`'s numbering,
//! shards (every frame exactly once), skipping written frames and resuming after a killed
//! render, animated PNG, the video's `ffmpeg`; `sdfc check`'s still / numbers only / structure
//! varies, `bench` of a sequence, and the job-array files of examples/jobs parsed by the tools
//! of their ecosystems.

use crate::animation::BASE;
use crate::common::assert_has;
use crate::common::words;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A small animated scene: a sphere moving along x.
const MOVING: &str = "material red = phong { color: (1, 0.2, 0.1) };
camera { position: (0, 1, -5), look_at: (0, 0.5, 0), fov: 50deg }
light point { position: (2, 4, -3) }
render { width: 32, height: 24, fps: 10, duration: 1 }
scene { plane(); sphere(0.5).translate(-1 + 0.2 * t * 10, 0.5, 0) @ red; }
";

pub(crate) fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sdfc-anim-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// A fresh directory `name` holding `moving.sdf`.
fn moving(name: &str) -> PathBuf {
    let d = dir(name);
    std::fs::write(d.join("moving.sdf"), MOVING).unwrap();
    d
}

/// `sdfc` run in `cwd` with the words of `line`, which must succeed: its output.
#[track_caller]
fn ok(cwd: &Path, line: &str) -> Output {
    let o = sdfc(cwd, &words(line));
    assert!(o.status.success(), "{}", text(&o));
    o
}

pub(crate) fn sdfc(cwd: &Path, args: &[&str]) -> Output {
    sdfc_env(cwd, args, &[])
}

pub(crate) fn sdfc_env(cwd: &Path, args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_sdfc"));
    c.current_dir(cwd).args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("run sdfc")
}

pub(crate) fn text(o: &Output) -> String {
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
    let d = moving("numbered");
    ok(
        &d,
        "render moving.sdf --backend cpu --frames 8..11 -o out/sub/f_###.png",
    );
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
    ok(&d, "render moving.sdf --backend cpu -o all/#.png");
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
    let d = moving("shards");
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
        &words("render moving.sdf --frames 0..4 --shard 3/3 -o x_#.png"),
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    // An animated PNG cannot be sharded.
    let o = sdfc(
        &d,
        &words("render moving.sdf --frames 0..4 --shard 0/2 -o a.png"),
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
}

#[test]
fn a_killed_render_resumes_where_it_stopped() {
    let d = moving("resume");
    let out = d.join("out");
    // Slow frames (big, supersampled) so that the kill lands mid-sequence.
    let mut child = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&d)
        .args(words(
            "render moving.sdf --backend cpu --frames 0..40 --size 320x240 --aa 3 -o out/f_##.png",
        ))
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
        &words(
            "render moving.sdf --backend cpu --frames 0..40 --size 320x240 --aa 3 -o out/f_##.png",
        ),
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
        &words("render moving.sdf --backend cpu --frames 0..3 -o out/f_##.png --force"),
    );
    assert!(
        text(&o).contains("3 to render, 0 already written"),
        "{}",
        text(&o)
    );
}

#[test]
fn an_animated_png_holds_every_frame() {
    let d = moving("apng");
    ok(
        &d,
        "render moving.sdf --backend cpu --frames 0..6 -o loop.png",
    );
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
    let d = moving("video");
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
        &words("render moving.sdf --backend cpu --frames 0..3 -o clip.mp4"),
        &[("PATH", bin.to_str().unwrap())],
    );
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(
        std::fs::metadata(d.join("clip.mp4")).unwrap().len(),
        3 * 32 * 24 * 3
    );
    let args = std::fs::read_to_string(d.join("args.txt")).unwrap();
    assert_has(&args, &["-s 32x24", "-framerate 10"]);
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
    assert_has(&out, &["still.sdf: still"]);
    let (code, out) = line("numbers.sdf");
    assert_eq!(code, Some(0));
    assert_has(&out, &["animated, numbers only"]);
    assert_has(&out, &["8 frames at 4 fps"]);
    let (code, out) = line("structure.sdf");
    assert_eq!(code, Some(0));
    assert_has(
        &out,
        &["structure varies: 4 structures, changing at frames 2, 4, 6"],
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
    assert_has(&out, &["frame 6 (t = 1.5 s) has errors"]);
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
    let o = ok(&root, "bench --frames-per-second --backend cpu --size 64x48 --sequence 0..5 --json examples/animation/orbit.sdf");
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
