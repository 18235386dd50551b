//! Speed against accuracy: the image and depth metrics on tiny hand-computed images, the depth
//! buffers of CPU renders and their sidecar, the reference render, the sweep parser and the
//! Pareto front of `sdfc pareto`, and its charts (valid SVG and PNG).

use crate::cli::{put, TestDir};
use crate::common;
use crate::common::assert_has;
use crate::common::words;

use common::*;
use sdfc_compiler::{lower, Node, Settings};
use sdfc_runtime::chart::{self, Accuracy, Chart, Panel, Point};
use sdfc_runtime::cpu::{self, reference};
use sdfc_runtime::depth::{self, Depth};
use sdfc_runtime::fp32;
use sdfc_runtime::image::Image;
use sdfc_runtime::metrics::{compare, compare_depth};
use sdfc_runtime::pareto::{self, front, parse_sweep, Key};
use std::path::Path;
use std::process::{Command, Output};

fn image(pixels: &[[f32; 3]]) -> Image {
    Image {
        width: pixels.len() as u32,
        height: 1,
        linear: pixels.to_vec(),
    }
}

fn depth(distance: &[f32], coverage: &[f32]) -> Depth {
    Depth {
        width: distance.len() as u32,
        height: 1,
        samples: 1,
        distance: distance.to_vec(),
        coverage: coverage.to_vec(),
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

#[test]
fn colour_metrics_match_hand_computed_values() {
    // Four pixels, twelve channels; differences 0.2 (one channel) and 0.5 (one channel).
    let a = image(&[[0.0; 3], [1.0; 3], [0.5; 3], [0.25; 3]]);
    let b = image(&[[0.2, 0.0, 0.0], [1.0; 3], [0.5, 0.5, 0.0], [0.25; 3]]);
    let d = compare(&a, &b, 0.3).expect("same size");
    let mse = (0.2f64 * 0.2 + 0.5 * 0.5) / 12.0;
    assert!((d.rmse - mse.sqrt()).abs() < 1e-7, "{d:?}");
    assert!((d.psnr - (-10.0 * mse.log10())).abs() < 1e-5, "{d:?}");
    assert!((d.max - 0.5).abs() < 1e-7, "{d:?}");
    assert!(close(d.differing, 0.25), "{d:?}");
    assert_eq!(
        compare(&a, &a, 0.0).map(|d| (d.psnr, d.max)),
        Some((f64::INFINITY, 0.0))
    );
}

#[test]
fn depth_metrics_match_hand_computed_values() {
    // Pixel 0: both hit, test 1% behind (beyond the 0.1% tolerance).
    // Pixel 1: both hit, test 0.05% in front.   Pixel 2: reference hit, test missed.
    // Pixel 3: test hit, reference missed.      Pixel 4: both missed.
    // Pixel 5: half the rays hit in both (a hit), equal distances.
    let nan = f32::NAN;
    let r = depth(
        &[2.0, 4.0, 1.0, nan, nan, 8.0],
        &[1.0, 1.0, 1.0, 0.0, 0.0, 0.5],
    );
    let t = depth(
        &[2.02, 3.998, nan, 5.0, nan, 8.0],
        &[1.0, 1.0, 0.25, 1.0, 0.0, 0.5],
    );
    let d = compare_depth(&r, &t, 1e-3).expect("same size");
    assert!(close(d.missed, 1.0 / 6.0), "{d:?}");
    assert!(close(d.false_hit, 1.0 / 6.0), "{d:?}");
    assert!(close(d.behind, 1.0 / 6.0), "{d:?}");
    assert!(close(d.both_hit, 3.0 / 6.0), "{d:?}");
    let mean = (0.02f64 / 2.0 + 0.002 / 4.0 + 0.0) / 3.0;
    let got = d.mean_relative_error.expect("some pixels hit by both");
    assert!((got - mean).abs() < 1e-6, "{got} against {mean}");
    let none =
        compare_depth(&depth(&[nan], &[0.0]), &depth(&[1.0], &[1.0]), 1e-3).expect("same size");
    assert_eq!((none.false_hit, none.mean_relative_error), (1.0, None));
    assert!(compare_depth(&r, &depth(&[1.0], &[1.0]), 1e-3).is_none());
}

fn sphere_scene(w: u32, h: u32) -> sdfc_compiler::Scene {
    let mut scene = single(Node::Sphere { radius: 1.0 });
    scene.camera.position = [0.0, 0.0, -5.0];
    scene.camera.look_at = [0.0, 0.0, 0.0];
    scene.settings.width = w;
    scene.settings.height = h;
    scene
}

#[test]
fn cpu_renders_carry_first_hit_depths() {
    let scene = sphere_scene(33, 33);
    let r = cpu_render(&scene);
    let d = r.depth.expect("the CPU renderer fills in depth");
    assert_eq!((d.width, d.height, d.samples), (33, 33, 1));
    // The centre ray meets the sphere 4 units from the eye, within the hit tolerance ε·t.
    let centre = 16 * 33 + 16;
    assert!(d.hit(centre));
    assert!(
        (d.distance[centre] - 4.0).abs() < 1e-3,
        "{}",
        d.distance[centre]
    );
    // Corners see the background.
    assert!(!d.hit(0) && d.distance[0].is_nan() && d.coverage[0] == 0.0);
    // With 2×2 supersampling coverage is a fraction and the mean stays near 4 (the samples
    // are a quarter pixel off centre, where the sphere is a little farther).
    let mut aa = scene.clone();
    aa.settings.aa = 2;
    let r2 = cpu_render(&aa);
    let d2 = r2.depth.expect("depth");
    assert_eq!(d2.samples, 4);
    assert!(d2
        .coverage
        .iter()
        .all(|c| [0.0, 0.25, 0.5, 0.75, 1.0].contains(c)));
    assert!(
        d2.coverage.iter().any(|&c| c > 0.0 && c < 1.0),
        "an edge pixel is partly covered"
    );
    assert!(
        (d2.distance[centre] - 4.0).abs() < 1e-2,
        "{}",
        d2.distance[centre]
    );
}

#[test]
fn depth_buffers_are_identical_whatever_the_number_of_threads() {
    let scene = sphere_scene(70, 45);
    let render = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| cpu_render(&scene))
    };
    let (a, b) = (render(1), render(3));
    let (da, db) = (a.depth.expect("depth"), b.depth.expect("depth"));
    let bits = |d: &Depth| {
        d.distance
            .iter()
            .chain(&d.coverage)
            .map(|v| v.to_bits())
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&da), bits(&db));
}

#[test]
fn reference_settings() {
    let s = Settings {
        relaxation: 1.6,
        aa: 2,
        ..Settings::default()
    };
    let r = reference::settings(&s, true);
    assert_eq!(
        (r.epsilon, r.footprint, r.max_steps, r.relaxation, r.aa),
        (1e-6, false, 100_000, 1.0, 2)
    );
    let c = reference::check_settings(&r);
    assert_eq!((c.epsilon, c.aa), (1e-7, 2));
    // No proven bound: the area average at the footprint's ε, checked with twice the samples.
    let r = reference::settings(&s, false);
    assert_eq!(
        (r.footprint, r.max_steps, r.relaxation, r.aa),
        (true, 100_000, 1.0, reference::AREA_AA)
    );
    let c = reference::check_settings(&r);
    assert_eq!((c.footprint, c.aa), (true, 2 * reference::AREA_AA));
}

#[test]
fn sweep_ranges_follow_the_documented_rule() {
    let eps = parse_sweep("epsilon=1e-2..1e-6").expect("parses");
    assert_eq!(eps.key, Key::Epsilon);
    assert_eq!(
        eps.values,
        [1e-2, 3.16e-3, 1e-3, 3.16e-4, 1e-4, 3.16e-5, 1e-5, 3.16e-6, 1e-6]
    );
    let steps = parse_sweep("max_steps=32..1024").expect("parses");
    assert_eq!(steps.values, [32.0, 64.0, 128.0, 256.0, 512.0, 1024.0]);
    let omega = parse_sweep("relaxation=1..1.8").expect("parses");
    assert_eq!(omega.values, [1.0, 1.2, 1.4, 1.6, 1.8]);
    assert_eq!(
        parse_sweep("aa=1..4").expect("parses").values,
        [1.0, 2.0, 3.0, 4.0]
    );
    assert_eq!(
        parse_sweep("epsilon=1e-2..1e-4:3").expect("parses").values,
        [1e-2, 1e-3, 1e-4]
    );
    assert_eq!(
        parse_sweep("max_steps=100..1000:3").expect("parses").values,
        [100.0, 316.0, 1000.0]
    );
    assert_eq!(
        parse_sweep("relaxation=1..1.5:3").expect("parses").values,
        [1.0, 1.25, 1.5]
    );
    assert_eq!(
        parse_sweep("epsilon=1e-3,1e-4, 1e-3")
            .expect("parses")
            .values,
        [1e-3, 1e-4]
    );
    assert_eq!(parse_sweep("aa=2").expect("parses").values, [2.0]);
}

#[test]
fn bad_sweeps_are_refused() {
    for (spec, needle) in [
        ("colour=1..2", "cannot sweep `colour`"),
        ("epsilon", "KEY=LO..HI"),
        ("epsilon=abc", "not a number"),
        ("relaxation=1..2.5", "relaxation must be"),
        ("epsilon=0..1e-3", "positive"),
        ("max_steps=32..64:0", "count"),
        ("aa=0,1", "aa must be"),
    ] {
        let e = parse_sweep(spec).expect_err(spec).to_string();
        assert!(e.contains(needle), "{spec}: {e}");
    }
    // A value the setting refuses is the setting's error, as `--set` gives it.
    let refused = parse_sweep("aa=0,1").expect_err("aa 0");
    assert!(matches!(refused, pareto::Error::Setting(_)), "{refused:?}");
}

#[test]
fn combinations_vary_the_first_sweep_slowest() {
    let sweeps = [
        parse_sweep("epsilon=1e-3,1e-4").expect("parses"),
        parse_sweep("relaxation=1,1.5").expect("parses"),
    ];
    let all =
        pareto::combinations(&Settings::default(), &sweeps, &Default::default()).expect("valid");
    let pairs: Vec<(f64, f64)> = all.iter().map(|s| (s.epsilon, s.relaxation)).collect();
    assert_eq!(pairs, [(1e-3, 1.0), (1e-3, 1.5), (1e-4, 1.0), (1e-4, 1.5)]);
    assert!(all
        .iter()
        .all(|s| s.max_steps == Settings::default().max_steps));
}

#[test]
fn the_pareto_front() {
    // (cost, PSNR). 1 dominates 2 (cheaper, better); 3 is the most accurate; 4 is worse than
    // 0 in both, but only by less than the margins (1% of cost against 3%, 0.01 dB against
    // PSNR_MARGIN), so it counts as a tie unless the cost margin is 0; NaN never counts.
    let points = [
        (1.0, 20.0),
        (2.0, 30.0),
        (3.0, 25.0),
        (4.0, 40.0),
        (1.01, 19.99),
        (0.5, f64::NAN),
    ];
    assert_eq!(front(&points, 0.03), [true, true, false, true, true, false]);
    assert_eq!(front(&points, 0.0), [true, true, false, true, false, false]);
}

fn sample_chart() -> Chart {
    let point = |ms: f64, steps: f64, psnr: f64, front: bool, default: bool| Point {
        cost: [ms, steps],
        accuracy: psnr,
        front: [front, front],
        default,
    };
    let panel = |caption: &str, cost: &str| Panel {
        caption: caption.into(),
        cost: cost.into(),
    };
    Chart {
        title: "test chart".into(),
        subtitle: "three points".into(),
        default_label: "defaults".into(),
        panels: [panel("time", "ms"), panel("work", "steps")],
        accuracy: Accuracy {
            label: "PSNR (dB)".into(),
            lower_is_better: false,
            target: Some((40.0, "40 dB target".into())),
        },
        points: vec![
            point(10.0, 20.0, 25.0, true, false),
            point(20.0, 40.0, 42.0, true, true),
            point(30.0, 35.0, f64::INFINITY, true, false),
        ],
    }
}

#[test]
fn charts_are_valid_svg_and_png() {
    let svg = chart::svg(&sample_chart()).expect("draws");
    assert!(
        svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
        "{}",
        &svg[..80]
    );
    for text in ["test chart", "Pareto front", "defaults", "PSNR"] {
        assert!(svg.contains(text), "{text}");
    }
    let png = chart::png(&sample_chart()).expect("draws");
    let decoder = png::Decoder::new(std::io::Cursor::new(png));
    let reader = decoder.read_info().expect("a PNG");
    assert_eq!((reader.info().width, reader.info().height), chart::SIZE);
    // A mesh's chart: a distance on a log axis, lower is better, a zero at the bottom.
    let mut mesh = sample_chart();
    mesh.accuracy = Accuracy {
        label: "largest distance to the surface".into(),
        lower_is_better: true,
        target: None,
    };
    for (p, d) in mesh.points.iter_mut().zip([1e-2, 1e-3, 0.0]) {
        p.accuracy = d;
    }
    let svg = chart::svg(&mesh).expect("draws");
    assert_has(&svg, &["largest distance", "0.001"]);
    chart::png(&mesh).expect("draws");
}

#[test]
fn distance_ops_count_transcendentals() {
    let scene = single(Node::Sphere { radius: 1.0 });
    let ops = fp32::distance_ops(&lower(&scene));
    // |p| - r needs a square root and at least five arithmetic operations.
    assert!(ops >= fp32::TRANSCENDENTAL + 5.0, "{ops}");
    let c = cpu::Counters {
        steps: 10,
        hits: 2,
        ..Default::default()
    };
    assert_eq!(fp32::evaluations(&c), 18);
    // 10 operations × 100 evaluations in 1 µs is 1 GFLOP/s, a thousandth of 1 TFLOP/s.
    assert!(close(
        fp32::fraction(10.0, 100, 1e-6, 1e12).expect("below 1"),
        1e-3
    ));
    // A count that implies more than the peak is not a fraction of it.
    assert_eq!(fp32::fraction(10.0, 1_000_000, 1e-6, 1e12), None);
}

/// issue 16, item 4: `fp32_fraction` is never above 1. The guarded blocks of culling run
/// only where their bounds are near, which the statistics do not count: 1 000 spheres lower
/// to a program whose blocks hold nearly all of it, and a frame that evaluated the distance
/// as often as a GPU's run of `compound_1000.sdf` (5.63 of the peak when every block was
/// counted) gets no fraction. A program without blocks runs all of it at every evaluation:
/// its fraction is exact.
#[test]
fn fp32_fraction_is_given_only_where_what_runs_is_counted_and_never_above_1() {
    let mut text = String::from("scene {\n");
    for i in 0..1000 {
        let (x, z) = ((i % 40) as f64 * 0.5, (i / 40) as f64 * 0.5);
        text.push_str(&format!("  sphere(0.2).translate({x}, 0, {z});\n"));
    }
    text.push('}');
    let (scene, diags, _) = sdfc_compiler::check_str("many.sdf", &text);
    let program = lower(&scene.unwrap_or_else(|| panic!("{diags:?}")));
    assert!(!program.blocks().is_empty(), "culling makes guarded blocks");
    let all = fp32::distance_ops(&program);
    // Evaluations and time such that every block counted gives 5.63 of the peak.
    let (seconds, peak) = (1e-3, 67e12);
    let evaluations = (5.63 * seconds * peak / all) as u64;
    assert!(all * evaluations as f64 / (seconds * peak) > 5.0);
    assert_eq!(fp32::fraction(all, evaluations, seconds, peak), None);
    assert_eq!(
        fp32::fraction_of_peak(&program, evaluations, seconds, peak),
        None
    );
    // Fewer evaluations: still none, as what ran is not known.
    assert_eq!(
        fp32::fraction_of_peak(&program, evaluations / 100, seconds, peak),
        None
    );
    // One sphere: no blocks, every operation runs at every evaluation.
    let one = lower(&single(Node::Sphere { radius: 1.0 }));
    assert!(one.blocks().is_empty());
    let ops = fp32::distance_ops(&one);
    let f = fp32::fraction_of_peak(&one, 1_000_000, seconds, peak).expect("a fraction");
    assert!(
        (f - ops * 1e6 / (seconds * peak)).abs() < 1e-12 && f <= 1.0,
        "{f}"
    );
    assert_eq!(fp32::fraction_of_peak(&one, u64::MAX, seconds, peak), None);
}

// The command line: `render --reference/--aux`, `compare` with sidecars, `pareto`.

const SCENE: &str = "material red = phong { color: (1, 0.2, 0.1) };
camera { position: (0, 1, -5), look_at: (0, 0.5, 0), fov: 50deg }
light point { position: (2, 4, -3), intensity: 1, radius: 50 }
render { width: 24, height: 16 }
scene {
  plane();
  sphere(1).translate(0, 1, 0) @ red;
}
";

fn dir(name: &str) -> TestDir {
    let path = std::env::temp_dir().join(format!("sdfc-accuracy-{name}-{}", std::process::id()));
    let d = TestDir::fresh(path);
    put(&d, "ball.sdf", SCENE);
    d
}

fn sdfc(cwd: &Path, args: &[&str]) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_sdfc"));
    run_ok(command.current_dir(cwd).args(args), &format!("{args:?}"))
}

#[test]
fn reference_renders_with_sidecars_compare_by_depth() {
    let d = dir("compare");
    let out = sdfc(
        &d,
        &words("render ball.sdf --reference --aux --stats -o ref.png"),
    );
    let stats = String::from_utf8_lossy(&out.stdout);
    assert_has(&stats, &["against ε 1e-7", "converged"]);
    assert!(d.join("ref.aux").exists());
    let reference = Depth::read(&d.join("ref.aux")).expect("a sidecar");
    assert_eq!((reference.width, reference.height), (24, 16));
    sdfc(
        &d,
        &words("render ball.sdf --backend cpu --set epsilon=1e-2 --aux -o coarse.png"),
    );
    let out = sdfc(&d, &["compare", "ref.png", "coarse.png", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    assert!(v["psnr"].as_f64().is_some_and(|p| p > 10.0), "{v}");
    assert!(v["max"].as_f64().is_some(), "{v}");
    for key in [
        "missed",
        "false_hit",
        "behind",
        "both_hit",
        "mean_relative_error",
    ] {
        assert!(v["depth"][key].as_f64().is_some(), "{key}: {v}");
    }
    // Without a sidecar the depth comparison is absent, and the report says why.
    sdfc(
        &d,
        &["render", "ball.sdf", "--backend", "cpu", "-o", "plain.png"],
    );
    let out = sdfc(&d, &["compare", "ref.png", "plain.png"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("not compared")
            && text.contains(
                &depth::sidecar_path(Path::new("plain.png"))
                    .display()
                    .to_string()
            ),
        "{text}"
    );
    let out = sdfc(&d, &["compare", "ref.png", "plain.png", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    assert!(v["depth"].is_null() && v["depth_note"].is_string(), "{v}");
}

#[test]
fn reference_needs_the_cpu() {
    let d = dir("reference-gpu");
    let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&d)
        .args(["render", "ball.sdf", "--reference", "--backend", "wgpu"])
        .output()
        .expect("run sdfc");
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--reference renders on the CPU"));
}

#[test]
fn pareto_measures_points_and_draws_charts() {
    let d = dir("pareto");
    let args = [
        "pareto",
        "ball.sdf",
        "--backend",
        "cpu",
        "--frames",
        "1",
        "--sweep",
        "epsilon=1e-2,1e-4",
        "--sweep",
        "max_steps=64,128",
        "--json",
        "-o",
    ];
    let mut svg_args = args.to_vec();
    svg_args.push("chart.svg");
    let out = sdfc(&d, &svg_args);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    let points = v["points"].as_array().expect("points");
    // Four combinations, plus the scene's own settings (the defaults) which the sweep lacks.
    assert_eq!(points.len(), 5, "{v}");
    assert_eq!(points.iter().filter(|p| p["default"] == true).count(), 1);
    assert!(points.iter().any(|p| p["front_time"] == true));
    assert!(points
        .iter()
        .all(|p| p["median_s"].as_f64().is_some_and(|s| s > 0.0)));
    assert!(points
        .iter()
        .all(|p| p["depth"]["missed"].as_f64().is_some()));
    assert_eq!(
        v["reference"]["convergence"]["epsilon"].as_f64(),
        Some(1e-6)
    );
    let svg = std::fs::read_to_string(d.join("chart.svg")).expect("chart written");
    assert!(svg.starts_with("<svg") && svg.contains("ball.sdf"));
    let mut png_args = args.to_vec();
    png_args.push("chart.png");
    sdfc(&d, &png_args);
    let bytes = std::fs::read(d.join("chart.png")).expect("chart written");
    assert!(png::Decoder::new(std::io::Cursor::new(bytes))
        .read_info()
        .is_ok());
    let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&d)
        .args(["pareto", "ball.sdf", "-o", "chart.txt", "--sweep", "aa=1"])
        .output()
        .expect("run sdfc");
    assert!(String::from_utf8_lossy(&out.stderr).contains(".svg or .png"));
}

/// `sdfc pareto --mesh`: a part meshed at three resolutions, each with its time, triangles
/// and largest distance to the surface, which falls as the cells shrink; the chart is drawn;
/// a render sweep with --mesh, and a resolution without it, are refused.
#[test]
fn pareto_mesh_measures_meshing_speed_against_accuracy() {
    let d = dir("pareto-mesh");
    put(
        &d,
        "part.sdf",
        "scene { union(box((1, 0.5, 0.7)), sphere(0.6).translate(0.9, 0.4, 0)); }",
    );
    let out = sdfc(
        &d,
        &words("pareto part.sdf --mesh --sweep resolution=8..32 --frames 1 --json -o mesh.svg"),
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    let points = v["points"].as_array().expect("points");
    let get = |p: &serde_json::Value, k: &str| p[k].as_f64().unwrap_or(f64::NAN);
    assert_eq!(
        points
            .iter()
            .map(|p| get(p, "resolution"))
            .collect::<Vec<_>>(),
        [8.0, 16.0, 32.0],
        "{v}"
    );
    for w in points.windows(2) {
        assert!(get(&w[1], "triangles") > get(&w[0], "triangles"), "{v}");
        assert!(get(&w[1], "cell") < get(&w[0], "cell"), "{v}");
    }
    let (coarse, fine) = (get(&points[0], "distance"), get(&points[2], "distance"));
    assert!(fine > 0.0 && fine < coarse, "{v}");
    assert!(points.iter().all(|p| get(p, "median_s") > 0.0));
    assert!(points.iter().any(|p| p["front_time"] == true));
    let svg = std::fs::read_to_string(d.join("mesh.svg")).expect("chart written");
    assert!(svg.contains("meshing speed against accuracy") && svg.contains("triangles"));
    let refused = |args: &[&str], says: &str| {
        let out = Command::new(env!("CARGO_BIN_EXE_sdfc"))
            .current_dir(&d)
            .args(args)
            .output()
            .expect("run sdfc");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
    };
    refused(
        &["pareto", "part.sdf", "--mesh", "--sweep", "epsilon=1e-3"],
        "with --mesh the swept setting is resolution",
    );
    refused(
        &["pareto", "ball.sdf", "--sweep", "resolution=8"],
        "sdfc pareto --mesh",
    );
}

/// The scene of a file of `examples/`, checked.
fn example(name: &str) -> sdfc_compiler::Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples")
        .join(name);
    sdfc_runtime::frontend::load(&path)
        .expect("readable")
        .scene
        .expect("a valid scene")
}

#[test]
fn a_field_without_a_proven_bound_gets_the_pixel_footprints_epsilon() {
    // seed6's Mandelbulb has no proven bound and the file gives no ε: ε is tan(fov/2)/height.
    let mut scene = example("seed6.sdf");
    assert!(scene.settings.footprint);
    assert_eq!(
        scene.settings.relaxation, 1.0,
        "no over-relaxation without a bound"
    );
    let footprint = (scene.camera.fov / 2.0).tan() / scene.settings.height as f64;
    assert!(close(scene.epsilon(), footprint));
    scene.settings.height *= 2;
    assert!(
        close(scene.epsilon(), footprint / 2.0),
        "it follows the size"
    );
    // A proven field keeps the default ε; so does an ε the file or `--set` gives.
    let proven = example("seed3.sdf");
    assert!(!proven.settings.footprint);
    assert_eq!((proven.epsilon(), proven.settings.relaxation), (1e-5, 1.4));
    let limits = sdfc_compiler::Limits::default();
    sdfc_runtime::settings::set(&mut scene.settings, "epsilon", "1e-4", &limits)
        .expect("a valid ε");
    assert!(!scene.settings.footprint);
    assert_eq!(scene.epsilon(), 1e-4);
}

#[test]
fn the_area_averaged_reference_of_a_fractal_converges() {
    // At 80×60 (CI's budget; docs/accuracy.md has 320×240): 8×8 samples at the footprint's ε,
    // checked against 16×16.
    let dir = std::env::temp_dir().join(format!("sdfc-area-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/seed6.sdf");
    let out = sdfc(
        &dir,
        &[
            "render",
            scene.to_str().expect("utf-8 path"),
            "--reference",
            "--size",
            "80x60",
            "--stats",
            "-o",
            "ref.png",
        ],
    );
    let text =
        String::from_utf8_lossy(&out.stderr).to_string() + &String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains("aa 8,"),
        "the reference averages 8×8 samples: {text}"
    );
    assert_has(&text, &["against ε", "aa 16"]);
    assert_has(&text, &["converged       yes"]);
    let _ = std::fs::remove_dir_all(&dir);
}
