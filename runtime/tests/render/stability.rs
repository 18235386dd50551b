//! The stability suite: scenes where sphere tracing is known to struggle (`tests/stability/`),
//! each swept over its stress parameter, sphere traced (also those that could be traced
//! analytically) at their default settings on the CPU in f32
//! (through the backend, so stepping with the L the analysis derives) and measured against an
//! f64 reference (ε = 1e-6, a budget of 100 000 steps, no over-relaxation; steps four times
//! shorter where the analysis proves no bound).
//!
//! Every scene file names its sweep in a comment, `// sweep NAME: v1, v2, …`, and defines `let NAME
//! = …;`: each value replaces that definition. The printed table has, per scene and value, the
//! percentage of pixels the render missed, hit falsely and hit behind the reference's surface, the
//! percentage of rays that ran out of steps, the PSNR against the reference, the mean steps per
//! pixel, and, where L > 1, the steps per pixel of the field as written stepped with the scene's L
//! everywhere (no local bounds) and what stepping it with L = 1 instead would have missed and hit
//! behind. A file may name the value of its parameter at which the scene is an exact field of the
//! same layout (`// exact layout: VALUE`); the table then gives the steps per pixel relative to
//! that render. It may also name the least PSNR against the reference that every render must reach
//! (`// min psnr: DB`). With `SDFC_STABILITY_IMAGES=DIR` set, both images of every render are
//! written to `DIR`.
//!
//! Scenes that `method: auto` (the default) traces analytically are also rendered so and
//! must then miss nothing and hit nothing behind.
//!
//! What it asserts is what the analysis promises: no pixel is ever NaN; where the analysis
//! proves that `f / L` is a bound, no pixel is hit behind the surface and fewer than 0.1 % are
//! missed, except for the renderer's documented limits in [`LIMITS`] (each checked to be what
//! it claims), and a proven scene with an exact layout takes at most [`MAX_STEP_RATIO`] times
//! its steps; where the analysis proves nothing, the numbers are only reported.

use sdfc_compiler::{
    analysis,
    analytic::{self, Choice},
    check_str, lower_scene, LowerOptions, Lowered, Method, Scene, Settings,
};
use sdfc_runtime::backend::{Backend, Prepared};
use sdfc_runtime::cpu::{self, reference, Options, Precision, Render};
use sdfc_runtime::depth::Depth;
use sdfc_runtime::metrics::{self, DepthDifference};
use std::path::{Path, PathBuf};

/// Image size of every render (small: CI has two cores).
const SIZE: (u32, u32) = (64, 48);

/// Where the analysis proves no bound, the reference steps with this many times the scene's
/// L. Where it does, steps of f / L are safe and only ε and the budget matter (shorter steps
/// would also let hits lie further than the renderer's normal step h from the surface).
const REFERENCE_STEP_FACTOR: f64 = 4.0;

/// Largest fraction of pixels a proven scene may miss.
const MAX_MISSED: f64 = 0.001;

/// Most steps per pixel a proven scene may take relative to the exact scene of its layout.
const MAX_STEP_RATIO: f64 = 1.5;

/// A budget limit is checked by rendering again with this many times the step budget.
const BUDGET_FACTOR: u32 = 16;

/// Why a proven scene may still render wrongly at its default settings.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Limit {
    /// Rays run out of steps: with [`BUDGET_FACTOR`] times the budget the render is right.
    Budget,
}

/// Renders (file stem, stress value) the renderer gets wrong for a reason the field is not
/// responsible for, with the reason.
const LIMITS: &[(&str, &str, Limit, &str)] = &[(
    "horizon",
    "1000",
    Limit::Budget,
    "sphere tracing: rays grazing the ground near the horizon need more steps than the budget; \
     method auto, the default, traces this scene analytically (checked)",
)];

/// One scene file and its sweep.
#[derive(Debug)]
struct Sweep {
    stem: String,
    param: String,
    values: Vec<String>,
    /// The value at which the scene is an exact field of the same layout.
    exact: Option<String>,
    /// The least PSNR against the reference every render of the sweep must reach.
    min_psnr: Option<f64>,
    text: String,
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The scenes of `tests/stability/`, sorted by name.
fn sweeps() -> Vec<Sweep> {
    let dir = root().join("runtime/tests/stability");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "sdf"))
        .collect();
    files.sort();
    files.iter().map(|p| sweep(p)).collect()
}

fn sweep(path: &Path) -> Sweep {
    let text = std::fs::read_to_string(path).expect("readable");
    let stem = path
        .file_stem()
        .expect("a name")
        .to_string_lossy()
        .into_owned();
    let line = text
        .lines()
        .find_map(|l| l.strip_prefix("// sweep "))
        .unwrap_or_else(|| panic!("{stem}.sdf has no `// sweep NAME: values` line"));
    let (param, values) = line.split_once(':').expect("`// sweep NAME: values`");
    Sweep {
        stem,
        param: param.trim().to_string(),
        values: values.split(',').map(|v| v.trim().to_string()).collect(),
        exact: text
            .lines()
            .find_map(|l| l.strip_prefix("// exact layout:"))
            .map(|v| v.trim().to_string()),
        min_psnr: text
            .lines()
            .find_map(|l| l.strip_prefix("// min psnr:"))
            .map(|v| v.trim().parse().expect("`// min psnr: DB`")),
        text,
    }
}

/// The scene text with `let PARAM = …;` replaced by `let PARAM = VALUE;`.
fn with_value(s: &Sweep, value: &str) -> String {
    let prefix = format!("let {} =", s.param);
    assert!(
        s.text.lines().any(|l| l.starts_with(&prefix)),
        "{}.sdf does not define `{}`",
        s.stem,
        s.param
    );
    let lines: Vec<String> = s
        .text
        .lines()
        .map(|l| {
            if l.starts_with(&prefix) {
                format!("{prefix} {value};")
            } else {
                l.to_string()
            }
        })
        .collect();
    lines.join("\n")
}

/// What one render of one scene measured.
#[derive(Debug)]
struct Row {
    scene: String,
    param: String,
    value: String,
    field: &'static str,
    lipschitz: f64,
    proven: bool,
    warnings: Vec<&'static str>,
    depth: DepthDifference,
    exhausted: f64,
    psnr: f64,
    min_psnr: Option<f64>,
    steps: f64,
    reference_steps: f64,
    /// Steps per pixel of the exact scene of the same layout, where the file names one.
    exact_steps: Option<f64>,
    /// Steps per pixel without local bounds, stepping with the scene's L (only where L > 1).
    global_steps: Option<f64>,
    nan_pixels: usize,
    /// Missed and behind fractions without local bounds, stepping with L = 1 (only where
    /// L > 1).
    at_one: Option<DepthDifference>,
    /// Where `method: auto` (the default) traces the scene analytically: that render
    /// against the reference.
    traced: Option<DepthDifference>,
    /// Where the first hits differ: `m` missed, `f` false hit, `b` behind.
    map: String,
    /// The scene as rendered (for re-rendering under a limit).
    scene_ir: Scene,
    reference_depth: Depth,
}

fn nan_pixels(r: &Render) -> usize {
    r.image
        .linear
        .iter()
        .filter(|c| c.iter().any(|x| x.is_nan()))
        .count()
}

/// The f32 CPU render of `scene` as the backends render it (with local bounds).
fn render(scene: &Scene) -> Render {
    let lowered = Lowered::new(scene);
    let options = Options {
        lipschitz: lowered.program.lipschitz(),
        ..Options::default()
    };
    cpu::render(scene, &lowered, &options, &|| {})
}

/// The f32 CPU render of the field as written (no local bounds), stepping with `lipschitz`.
fn render_global(scene: &Scene, lipschitz: f64) -> Render {
    let lowered = lower_scene(
        scene,
        &LowerOptions {
            local: false,
            ..LowerOptions::default()
        },
    );
    let options = Options {
        lipschitz,
        ..Options::default()
    };
    cpu::render(scene, &lowered, &options, &|| {})
}

/// The f64 reference: ε = 1e-6, 100 000 steps, no over-relaxation, steps of f / `lipschitz`.
fn render_reference(scene: &Scene, lipschitz: f64) -> Render {
    let settings: Settings = reference::settings(&scene.settings, true);
    let scene = Scene {
        settings,
        ..scene.clone()
    };
    let options = Options {
        lipschitz,
        precision: Precision::F64,
        ..Options::default()
    };
    cpu::render(&scene, &Lowered::new(&scene), &options, &|| {})
}

fn depth(r: &Render) -> &Depth {
    r.depth.as_ref().expect("CPU renders have depth buffers")
}

fn compare_depth(reference: &Depth, test: &Render) -> DepthDifference {
    metrics::compare_depth(reference, depth(test), reference::DEPTH_TOLERANCE)
        .expect("depth buffers of the same size")
}

/// The scene of a sweep at one value, at the suite's image size, with its diagnostics.
fn scene_at(s: &Sweep, value: &str) -> (Scene, Vec<sdfc_compiler::Diagnostic>) {
    let name = format!("{}.sdf", s.stem);
    let (scene, diags, _) = check_str(&name, &with_value(s, value));
    let mut scene: Scene = scene.unwrap_or_else(|| panic!("{name} with {value}: {diags:?}"));
    (
        scene.settings.width,
        scene.settings.height,
        scene.settings.aa,
    ) = (SIZE.0, SIZE.1, 1);
    // The suite is about sphere tracing: scenes that could be traced analytically are
    // marched all the same.
    scene.settings.method = Method::March;
    (scene, diags)
}

fn measure(s: &Sweep, value: &str, exact_steps: Option<f64>) -> Row {
    let (scene, diags) = scene_at(s, value);
    let a = analysis::analyse(&scene);
    let facts = *a.root().expect("objects");
    let test = Prepared::new(Backend::Cpu, &scene, Precision::F32)
        .and_then(|p| p.render(&scene, &|_| {}))
        .expect("a CPU render")
        .render;
    let factor = if facts.proven {
        1.0
    } else {
        REFERENCE_STEP_FACTOR
    };
    let reference = render_reference(&scene, factor * a.step_lipschitz());
    if let Some(dir) = std::env::var_os("SDFC_STABILITY_IMAGES") {
        let file =
            |kind: &str| Path::new(&dir).join(format!("{}-{}-{value}-{kind}.png", s.stem, s.param));
        sdfc_runtime::image::write_png(&file("test"), &test.image).expect("writable");
        sdfc_runtime::image::write_png(&file("reference"), &reference.image).expect("writable");
    }
    let mut auto = scene.clone();
    auto.settings.method = Method::Auto;
    let traced = matches!(analytic::choose(&auto), Choice::Trace(_)).then(|| {
        let r = Prepared::new(Backend::Cpu, &auto, Precision::F32)
            .and_then(|p| p.render(&auto, &|_| {}))
            .expect("a CPU render")
            .render;
        compare_depth(depth(&reference), &r)
    });
    let global = a.step_lipschitz() > 1.0;
    let at_one = global.then(|| compare_depth(depth(&reference), &render_global(&scene, 1.0)));
    let global_steps = global.then(|| render_global(&scene, a.step_lipschitz()).stats.steps_mean);
    let c = &test.stats.counters;
    Row {
        scene: s.stem.clone(),
        param: s.param.clone(),
        value: value.to_string(),
        field: analysis::describe(facts.facts.exactness),
        lipschitz: facts.facts.lipschitz,
        proven: facts.proven,
        warnings: diags.iter().map(|d| d.code).collect(),
        depth: compare_depth(depth(&reference), &test),
        exhausted: c.budget_misses as f64 / (c.camera_rays + c.secondary_rays).max(1) as f64,
        psnr: metrics::compare(&reference.image, &test.image, 0.1).map_or(f64::NAN, |d| d.psnr),
        min_psnr: s.min_psnr,
        steps: test.stats.steps_mean,
        reference_steps: reference.stats.steps_mean,
        exact_steps,
        global_steps,
        nan_pixels: nan_pixels(&test) + nan_pixels(&reference),
        at_one,
        traced,
        map: hit_map(depth(&reference), depth(&test)),
        scene_ir: scene,
        reference_depth: depth(&reference).clone(),
    }
}

/// An ASCII map of the pixels whose first hits differ from the reference's.
fn hit_map(r: &Depth, t: &Depth) -> String {
    let mut out = String::new();
    for y in 0..r.height as usize {
        for x in 0..r.width as usize {
            let i = y * r.width as usize + x;
            let (rd, td) = (r.distance[i] as f64, t.distance[i] as f64);
            out.push(match (r.hit(i), t.hit(i)) {
                (true, false) => 'm',
                (false, true) => 'f',
                (true, true) if td - rd > reference::DEPTH_TOLERANCE * rd.abs() => 'b',
                (true, true) => '#',
                (false, false) => '.',
            });
        }
        out.push('\n');
    }
    out
}

fn pct(x: f64) -> String {
    format!("{:.2}", x * 100.0)
}

/// The table, as Markdown.
fn table(rows: &[Row]) -> String {
    let mut out = String::from(
        "| Scene | Stress | Field | L | Warnings | Missed % | False hits % | Behind % | Exhausted % | PSNR dB | Steps/px | × exact layout | Global 1/L: steps/px | Ref. steps/px | At L = 1: missed %, behind % | Traced (auto): missed %, behind % |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let field = if r.proven {
            r.field.to_string()
        } else {
            format!("{} (unproven)", r.field)
        };
        let warnings = if r.warnings.is_empty() {
            "–".to_string()
        } else {
            r.warnings.join(", ")
        };
        let at_one = r.at_one.map_or("–".to_string(), |d| {
            format!("{}, {}", pct(d.missed), pct(d.behind))
        });
        let traced = r.traced.map_or("–".to_string(), |d| {
            format!("{}, {}", pct(d.missed), pct(d.behind))
        });
        let ratio = r
            .exact_steps
            .map_or("–".to_string(), |e| format!("{:.2}", r.steps / e));
        let global = r
            .global_steps
            .map_or("–".to_string(), |g| format!("{g:.1}"));
        out += &format!(
            "| {} | {} = {} | {field} | {:.3} | {warnings} | {} | {} | {} | {} | {:.1} | {:.1} | {ratio} | {global} | {:.1} | {at_one} | {traced} |\n",
            r.scene,
            r.param,
            r.value,
            r.lipschitz,
            pct(r.depth.missed),
            pct(r.depth.false_hit),
            pct(r.depth.behind),
            pct(r.exhausted),
            r.psnr,
            r.steps,
            r.reference_steps,
        );
    }
    out
}

fn limit(r: &Row) -> Option<(Limit, &'static str)> {
    LIMITS
        .iter()
        .find(|(scene, value, ..)| *scene == r.scene && *value == r.value)
        .map(|l| (l.2, l.3))
}

/// Checks a row against the promises; returns what is wrong.
fn check(r: &Row) -> Vec<String> {
    let what = format!("{} ({} = {})", r.scene, r.param, r.value);
    let mut failures = Vec::new();
    if r.nan_pixels > 0 {
        failures.push(format!("{what}: {} NaN pixels", r.nan_pixels));
    }
    if let Some(t) = r.traced {
        if t.behind > 0.0 || t.missed >= MAX_MISSED {
            failures.push(format!(
                "{what}: traced analytically (the default method here), {}% missed and {}% hit behind",
                pct(t.missed),
                pct(t.behind)
            ));
        }
    }
    if let Some(min) = r.min_psnr {
        if r.psnr.is_nan() || r.psnr < min {
            failures.push(format!(
                "{what}: {:.1} dB against the reference, below {min} dB",
                r.psnr
            ));
        }
    }
    if let (Some(exact), true) = (r.exact_steps, r.proven) {
        if r.steps > MAX_STEP_RATIO * exact {
            failures.push(format!(
                "{what}: {:.1} steps per pixel, {:.2} times the exact layout's {exact:.1}",
                r.steps,
                r.steps / exact
            ));
        }
    }
    let wrong = r.depth.behind > 0.0 || r.depth.missed >= MAX_MISSED;
    if !wrong || !r.proven {
        if wrong {
            println!(
                "{what}: renders wrongly; the analysis proves no bound here\n{}",
                r.map
            );
        }
        return failures;
    }
    match limit(r) {
        Some((Limit::Budget, reason)) => {
            let mut scene = r.scene_ir.clone();
            scene.settings.max_steps *= BUDGET_FACTOR;
            let again = compare_depth(&r.reference_depth, &render(&scene));
            println!(
                "{what}: known limit ({reason}); with {BUDGET_FACTOR}× the budget {}% missed, {}% behind\n{}",
                pct(again.missed),
                pct(again.behind),
                r.map
            );
            if r.depth.behind > 0.0 || again.missed >= MAX_MISSED || again.behind > 0.0 {
                failures.push(format!("{what}: listed as a budget limit, but more steps do not fix it"));
            }
        }
        None => failures.push(format!(
            "{what}: the analysis proves L = {} but {}% of pixels are missed and {}% hit behind\n{}",
            r.lipschitz,
            pct(r.depth.missed),
            pct(r.depth.behind),
            r.map
        )),
    }
    failures
}

#[test]
fn stability_suite() {
    let sweeps = sweeps();
    assert!(
        sweeps.len() >= 11,
        "expected at least 11 stability scenes, found {}",
        sweeps.len()
    );
    let rows: Vec<Row> = sweeps
        .iter()
        .flat_map(|s| {
            let exact = s
                .exact
                .as_ref()
                .map(|v| render(&scene_at(s, v).0).stats.steps_mean);
            s.values.iter().map(move |v| measure(s, v, exact))
        })
        .collect();
    println!("{}", table(&rows));
    let failures: Vec<String> = rows.iter().flat_map(check).collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
