//! The optimisation passes and bounding-volume culling: culling never changes an image (bit
//! for bit on the CPU), the passes keep the distance field (to rounding) at random points,
//! the batch interpreter runs guarded blocks exactly as the reference path, and instruction
//! counts drop. `cargo test --release --test render -- optimise:: --ignored --nocapture` prints the
//! tables of instruction counts and frame times with the passes off and on.

use crate::common;

use common::*;
use glam::DVec3;
use sdfc_compiler::{
    eval_point, lower_scene, lower_with, rust, wgsl, Evaluator, LowerOptions, Lowered, Method, Op,
    Outputs, Program, Rng, Scene, Step, Tape,
};
use sdfc_runtime::cpu::{self, Options, Precision};
use sdfc_runtime::frontend;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The lowering at `level`, culling or not, with local bounds or not, not parametric.
const fn lowering(level: u8, cull: bool, local: bool) -> LowerOptions {
    LowerOptions {
        level,
        cull,
        local,
        parametric: false,
    }
}

const CULL: LowerOptions = lowering(1, true, true);
const NO_CULL: LowerOptions = lowering(1, false, true);
/// Every pass, without local bounds: the field as written, for comparing values.
const WRITTEN: LowerOptions = lowering(1, true, false);
/// The passes alone: no culling and no local bounds, which add instructions on purpose.
const PASSES: LowerOptions = lowering(1, false, false);
const LITERAL: LowerOptions = lowering(0, false, false);

/// The `.sdf` files directly inside `dir` (relative to the workspace root), sorted.
fn sdf_files(dir: &str) -> Vec<PathBuf> {
    sdf_files_in(&Path::new("..").join(dir))
}

/// A scene, sphere traced (`method: "march"`) whatever it allows: these tests are about the
/// distance program, which analytic tracing does not run.
fn load(path: &Path) -> Scene {
    let mut scene = frontend::load(path)
        .expect("readable")
        .scene
        .unwrap_or_else(|| panic!("{} has errors", path.display()));
    scene.settings.method = Method::March;
    scene
}

fn name(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// The examples plus the small scaling scenes (with the Voronoi cells, intersections raised
/// to the boxes their planes cut, and the small tree of shapes between points).
fn scenes() -> Vec<(String, Scene)> {
    let mut files = sdf_files("examples");
    files.extend(sdf_files("examples/scaling").into_iter().filter(|p| {
        let n = name(p);
        n.ends_with("_10") || n.ends_with("_100") || n == "voronoi" || n == "tree_small"
    }));
    files.iter().map(|p| (name(p), load(p))).collect()
}

/// Points around what the camera looks at.
fn points(scene: &Scene, seed: u64, n: usize) -> Vec<[f64; 3]> {
    let c = scene.camera.look_at;
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|_| {
            let q = rng.point(8.0);
            [c[0] + q[0], c[1] + q[1], c[2] + q[2]]
        })
        .collect()
}

#[test]
fn culling_never_changes_an_image() {
    for (name, mut scene) in scenes() {
        scene.settings.width = 64;
        scene.settings.height = 48;
        scene.settings.aa = 1;
        let (on, off) = (lower_scene(&scene, &CULL), lower_scene(&scene, &NO_CULL));
        for precision in [Precision::F32, Precision::F64] {
            let options = Options {
                precision,
                ..Options::default()
            };
            let a = cpu::render(&scene, &on, &options, &|| {});
            let b = cpu::render(&scene, &off, &options, &|| {});
            let same = a
                .image
                .linear
                .iter()
                .zip(&b.image.linear)
                .all(|(x, y)| x.map(f32::to_bits) == y.map(f32::to_bits));
            assert!(same, "{name} ({precision:?}): culling changed the image");
            assert_eq!(a.stats.counters.steps, b.stats.counters.steps, "{name}");
        }
    }
}

#[test]
fn culling_gives_the_same_field_bit_for_bit() {
    for (name, scene) in scenes() {
        let (on, off) = (lower_with(&scene, &CULL), lower_with(&scene, &NO_CULL));
        let pts = points(&scene, 3, 3000);
        for p in &pts {
            let (a, b) = (eval_point::<f64>(&on, *p), eval_point::<f64>(&off, *p));
            assert_eq!(
                (a.0.to_bits(), a.1),
                (b.0.to_bits(), b.1),
                "{name} f64 at {p:?}"
            );
            let q = p.map(|v| v as f32);
            let (a, b) = (eval_point::<f32>(&on, q), eval_point::<f32>(&off, q));
            assert_eq!(
                (a.0.to_bits(), a.1),
                (b.0.to_bits(), b.1),
                "{name} f32 at {p:?}"
            );
        }
    }
}

#[test]
fn the_batch_interpreter_runs_blocks_like_the_reference_path() {
    for (name, scene) in scenes() {
        let program = lower_with(&scene, &CULL);
        let pts = points(&scene, 5, 700);
        for chunk in [1, 7, 64, 256] {
            let (d, m) = run_batch::<f32>(&program, Outputs::DistanceAndMaterial, chunk, &pts);
            for (i, p) in pts.iter().enumerate() {
                let (rd, rm) = eval_point::<f32>(&program, p.map(|v| v as f32));
                assert!(
                    rd.to_bits() == d[i].to_bits() && rm == m[i],
                    "{name}, chunk {chunk}, point {p:?}: {rd} {rm} vs {} {}",
                    d[i],
                    m[i]
                );
            }
        }
        let dist = Tape::new(&program, Outputs::Distance);
        let mut ev = Evaluator::<f64>::new(&dist, 32);
        let c = |i: usize| pts.iter().map(|p| p[i]).collect::<Vec<f64>>();
        let mut d = vec![0.0; pts.len()];
        ev.eval(&c(0), &c(1), &c(2), &mut d, None);
        for (i, p) in pts.iter().enumerate() {
            assert_eq!(
                d[i].to_bits(),
                eval_point::<f64>(&program, *p).0.to_bits(),
                "{name}"
            );
        }
    }
}

#[test]
fn the_passes_keep_the_distance_field() {
    for (name, scene) in scenes() {
        let (opt, literal) = (lower_with(&scene, &WRITTEN), lower_with(&scene, &LITERAL));
        let local = lower_with(&scene, &CULL);
        let pts = points(&scene, 9, 2000);
        let mut materials = 0;
        for p in &pts {
            let (a, ma) = eval_point::<f64>(&opt, *p);
            let (b, mb) = eval_point::<f64>(&literal, *p);
            let scale = 1.0 + len3(*p) + b.abs();
            assert!(
                (a - b).abs() <= 1e-9 * scale,
                "{name} f64 at {p:?}: {a} vs {b}"
            );
            materials += usize::from(ma != mb);
            // Local bounds change the values, not the solid.
            let (c, _) = eval_point::<f64>(&local, *p);
            assert!(
                b.abs() <= 1e-9 * scale || c.signum() == b.signum(),
                "{name} with local bounds at {p:?}: {c} vs {b}"
            );
        }
        // Materials can differ only where two children are exactly as near (none here).
        assert_eq!(materials, 0, "{name}");
        let (d1, _) = run_batch::<f32>(&opt, Outputs::DistanceAndMaterial, 256, &pts);
        let (d0, _) = run_batch::<f32>(&literal, Outputs::DistanceAndMaterial, 256, &pts);
        for (i, p) in pts.iter().enumerate() {
            let scale = 1.0 + len3(*p) + (d0[i] as f64).abs();
            let diff = (d1[i] as f64 - d0[i] as f64).abs();
            assert!(
                diff <= 4e-5 * scale,
                "{name} f32 at {p:?}: {} vs {}",
                d1[i],
                d0[i]
            );
        }
    }
}

/// Instructions other than constants, inputs and phis.
fn operations(program: &Program) -> usize {
    program
        .ops()
        .iter()
        .filter(|op| !matches!(op, Op::Const(_) | Op::Input(_) | Op::Phi(..)))
        .count()
}

/// Operations executed at `p` (a guarded block's test counts as one).
fn executed(program: &Program, p: [f32; 3]) -> usize {
    let ops = program.ops();
    let mut count = 0;
    program.run(p, |step| {
        count += usize::from(match step {
            Step::Test(_) => true,
            Step::Op(i) => !matches!(ops[i], Op::Const(_) | Op::Input(_) | Op::Phi(..)),
        })
    });
    count
}

/// The points a camera ray of each pixel of a `w × h` grid visits while sphere tracing.
fn ray_points(scene: &Scene, program: &Program, w: u32, h: u32) -> Vec<[f32; 3]> {
    let cam = &scene.camera;
    let eye = cam.position;
    let f = (DVec3::from(cam.look_at) - DVec3::from(eye)).normalize();
    let u = f.cross(DVec3::Y).normalize();
    let v = u.cross(f);
    let tan = (cam.fov * 0.5).tan();
    let aspect = scene.settings.width as f64 / scene.settings.height as f64;
    let mut out = Vec::new();
    for j in 0..h {
        for i in 0..w {
            let sx = ((i as f64 + 0.5) / w as f64 * 2.0 - 1.0) * tan * aspect;
            let sy = (1.0 - (j as f64 + 0.5) / h as f64 * 2.0) * tan;
            let d = (f + u * sx + v * sy).normalize();
            let mut t = 0.0;
            for _ in 0..scene.settings.max_steps {
                let p = [0, 1, 2].map(|k| (eye[k] + t * d[k]) as f32);
                out.push(p);
                let (dist, _) = eval_point::<f32>(program, p);
                if (dist as f64).abs() < scene.settings.epsilon * t.max(1.0)
                    || t > scene.settings.max_dist
                {
                    break;
                }
                t += dist as f64;
            }
        }
    }
    out
}

/// Mean operations executed per evaluation along camera rays.
fn mean_executed(scene: &Scene, program: &Program, rays: &[[f32; 3]]) -> f64 {
    let _ = scene;
    rays.iter()
        .map(|&p| executed(program, p) as f64)
        .sum::<f64>()
        / rays.len().max(1) as f64
}

#[test]
fn instruction_counts_drop() {
    for (name, scene) in scenes() {
        // Local bounds (a stretched shape divided by its L, raised to its box's distance)
        // cost instructions of their own; the passes are compared without them.
        let (literal, plain) = (lower_with(&scene, &LITERAL), lower_with(&scene, &PASSES));
        assert!(
            operations(&plain) < operations(&literal),
            "{name}: {} operations optimised, {} literal",
            operations(&plain),
            operations(&literal)
        );
    }
    for file in [
        "../examples/lattice.sdf",
        "../examples/scaling/random_100.sdf",
    ] {
        let scene = load(Path::new(file));
        let (culled, plain) = (lower_with(&scene, &CULL), lower_with(&scene, &NO_CULL));
        let rays = ray_points(&scene, &plain, 16, 12);
        let (a, b) = (
            mean_executed(&scene, &culled, &rays),
            mean_executed(&scene, &plain, &rays),
        );
        assert!(
            a * 3.0 < b,
            "{file}: {a:.0} operations per point culled, {b:.0} not"
        );
    }
}

#[test]
fn generated_code_handles_blocks() {
    let scene = load(Path::new("../examples/scaling/random_100.sdf"));
    let lowered = lower_scene(&scene, &CULL);
    let program = &lowered.program;
    assert!(!program.blocks().is_empty());
    let kernel = wgsl::write(&scene, &lowered).expect("naga accepts the kernel");
    let ifs = kernel.source.matches("if !(r").count();
    assert!(ifs >= program.blocks().len(), "{ifs} ifs");
    let text = rust::write(program);
    // Two functions (f32 and f64), one `if` per block in each.
    assert_eq!(text.matches("if !(r").count(), 2 * program.blocks().len());
    let dump = program.dump();
    assert_eq!(dump.matches("if !(%").count(), program.blocks().len());
    let results: usize = program.blocks().iter().map(|b| b.results).sum();
    assert_eq!(dump.matches(" = phi %").count(), results);
}

/// Median time of `frames` CPU frames (after one untimed frame) at the given size.
fn time_frames(scene: &Scene, lowered: &Lowered, frames: usize) -> f64 {
    let options = Options::default();
    let _ = cpu::render(scene, lowered, &options, &|| {});
    let mut times: Vec<f64> = (0..frames)
        .map(|_| {
            let start = Instant::now();
            let _ = cpu::render(scene, lowered, &options, &|| {});
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

/// The passes' tables: instruction counts (static, WGSL, executed per evaluation
/// along camera rays) and CPU frame times with the passes off and on.
#[test]
#[ignore]
fn report() {
    let only = std::env::var("SDFC_REPORT").unwrap_or_default();
    let time_limit: usize = std::env::var("SDFC_REPORT_TIME_LIMIT")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1000);
    let mut files = sdf_files("examples");
    files.extend(sdf_files("examples/scaling"));
    println!("| scene | ops opt 0 | ops opt 1 no cull | ops opt 1 | WGSL lines opt 0 | WGSL lines opt 1 | executed opt 0 | executed opt 1 | blocks | ms opt 0 | ms opt 1 |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for path in files {
        let n = name(&path);
        if !only.is_empty() && !n.contains(&only) {
            continue;
        }
        let mut scene = load(&path);
        scene.settings.width = 640;
        scene.settings.height = 480;
        scene.settings.aa = 1;
        let literal = lower_with(&scene, &LITERAL);
        let plain = lower_with(&scene, &NO_CULL);
        let culled = lower_with(&scene, &CULL);
        let size =
            |p: &Program| wgsl::write_map(p).lines().count() + wgsl::write_sdf(p).lines().count();
        let rays = ray_points(&scene, &plain, 24, 18);
        let big = literal.len() > 30_000;
        let (e0, e1) = (
            if big {
                f64::NAN
            } else {
                mean_executed(&scene, &literal, &rays)
            },
            mean_executed(&scene, &culled, &rays),
        );
        let slow = literal.len() > time_limit * 10;
        let t0 = if slow {
            f64::NAN
        } else {
            time_frames(&scene, &lower_scene(&scene, &LITERAL), 3)
        };
        let t1 = if std::env::var("SDFC_REPORT_NO_TIME").is_ok() {
            f64::NAN
        } else {
            time_frames(&scene, &lower_scene(&scene, &CULL), 3)
        };

        println!(
            "| {n} | {} | {} | {} | {} | {} | {e0:.0} | {e1:.0} | {} | {t0:.0} | {t1:.0} |",
            operations(&literal),
            operations(&plain),
            operations(&culled),
            size(&literal),
            size(&culled),
            culled.blocks().len(),
        );
    }
}
