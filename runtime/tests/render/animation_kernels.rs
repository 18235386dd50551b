//! One kernel per sequence: frames that differ only in numbers keep one structure and one
//! kernel text (on the CPU and wgpu alike), and the parametric lowering computes what the usual
//! one does.

use crate::animation::{scene, BASE};
use crate::common::assert_has;
use crate::sequence::{dir, sdfc, sdfc_env, text};
use sdfc_compiler::{Limits, Scene};
use std::path::Path;
use std::process::Command;

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
    assert_has(
        &out,
        &["moving.sdf: animated, numbers only", "36 frames at 12 fps"],
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
