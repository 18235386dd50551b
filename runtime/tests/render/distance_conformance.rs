//! One conformance suite for every evaluator of the distance program: the scenes of
//! `compiler/tests/in/feature` (one primitive, operator, blend, domain operation or transform each),
//! `tests/in/conformance` and the random scenes of `common::random_scene`, evaluated at one
//! fixed set of points by the f64 reference, the f32 and f64 interpreter, the emitted Rust
//! (f32 and f64), and through wgpu and CUDA (its PTX) the WGSL part's two functions and the
//! renderer kernel's walk over instances in `scene_data` (`common/evaluators.rs`). The f64
//! evaluators are the reference bit for bit; the f32 ones are compared with the f32
//! interpreter in ulps ([`ulps`]), and each with the f64 reference within a relative bound,
//! both bounds stated by the functions a program uses ([`CLASSES`]); a failure reports the
//! worst case of every comparison. Without a wgpu adapter, `rustc`, `ptxas` or a CUDA device
//! the part that needs it says it skipped; SDFC_REQUIRE_DEVICES=1 makes a missing adapter,
//! `rustc` or `ptxas` fail, SDFC_REQUIRE_CUDA=1 (scripts/device-conformance.sh, on the GPU
//! machine) a missing CUDA device.

use crate::common;
use crate::evaluators;

use evaluators::Value;
use sdfc_compiler::{Binary, Lowered, Node, Op, Rng, Scene, Unary};
use std::path::PathBuf;

/// Most ulps ([`ulps`]) by which the emitted Rust may differ from the interpreter: none, it
/// performs the same operations in the same order (docs/embedding.md: bit for bit).
const RUST_ULPS: f64 = 0.0;
/// The classes of programs, by the operations they use, with the most ulps by which wgpu and
/// CUDA may differ from the interpreter and the bound of every f32 evaluator against the f64
/// reference, |d₃₂ − d₆₄| ≤ bound × s (s as in [`ulps`]). Measured on lavapipe (LLVM 15,
/// 2026-11-24), in the comments: the worst over the part, its distance alone and the
/// instance walk.
///
/// - Arithmetic, square roots, minima and maxima alone: WGSL lets a driver contract a
///   product and a sum into one rounding and compute division and square roots within 2.5
///   ulps, and differences of larger values carry such errors into the distance. Measured:
///   3 ulps, 5.4e-7 against f64.
/// - With sin, cos, exp or log (twists, bends, exponential blends): WGSL allows these
///   absolute errors near zero and errors of a few ulps elsewhere. Measured: 5 ulps, 8.6e-7 against f64.
/// - With pow, acos or atan2 (the Mandelbulb of a fractional power): pow's error grows with
///   the exponent, and the distance estimate amplifies it. Measured: 375 ulps, 4.5e-5
///   against f64.
const CLASSES: [Bounds; 3] = [
    Bounds {
        name: "arithmetic",
        ulps: 16.0,
        reference: 2e-5,
    },
    Bounds {
        name: "with sin, cos, exp or log",
        ulps: 64.0,
        reference: 2e-5,
    },
    Bounds {
        name: "with pow, acos or atan2",
        ulps: 1024.0,
        reference: 2e-4,
    },
];

/// The bounds of a class of programs ([`CLASSES`]).
#[derive(Debug, Clone, Copy)]
struct Bounds {
    name: &'static str,
    ulps: f64,
    reference: f64,
}

/// The class of a program ([`CLASSES`]): 2 where it computes pow, acos or atan2, 1 where it
/// computes sin, cos, exp or log, 0 otherwise.
fn class(program: &sdfc_compiler::Program) -> usize {
    let has = |f: &dyn Fn(&Op) -> bool| program.ops().iter().any(f);
    if has(&|op| {
        matches!(
            op,
            Op::Unary(Unary::Acos, _) | Op::Binary(Binary::Pow | Binary::Atan2, ..)
        )
    }) {
        2
    } else if has(&|op| {
        matches!(
            op,
            Op::Unary(Unary::Sin | Unary::Cos | Unary::Exp | Unary::Log, _)
        )
    }) {
        1
    } else {
        0
    }
}

/// A scene of the suite, lowered once: every evaluator runs this program.
struct Case {
    name: String,
    scene: Scene,
    lowered: Lowered,
}

/// The feature scenes: one primitive, operator, blend, domain operation or transform each (the
/// compiler's snapshot inputs).
const FEATURES: &str = "../compiler/tests/in/feature";

/// The scenes of the folder `dir` (relative to the runtime crate), lowered.
fn scenes(dir: &str) -> Vec<Case> {
    common::sdf_files_in(std::path::Path::new(dir))
        .into_iter()
        .map(|path| {
            let scene = sdfc_runtime::frontend::load(&path)
                .expect("readable")
                .scene
                .unwrap_or_else(|| panic!("{} has errors", path.display()));
            let lowered = Lowered::new(&scene);
            let name = path.file_stem().expect("name").to_string_lossy().into();
            Case {
                name,
                scene,
                lowered,
            }
        })
        .collect()
}

/// The feature scenes (`compiler/tests/in/feature`, one feature each), the scenes that combine
/// features for an evaluator (`tests/in/conformance`: every primitive the instance walk
/// knows; issue 33's primitives and blends moved and rotated), then 40 random scenes of 1
/// to 6 primitives.
fn cases() -> Vec<Case> {
    let mut cases = scenes(FEATURES);
    assert!(cases.len() >= 25, "{} feature scenes", cases.len());
    cases.extend(scenes("tests/in/conformance"));
    let mut rng = Rng::new(2026);
    for i in 0..40 {
        let scene = common::random_scene(&mut rng, 1 + i % 6);
        let lowered = Lowered::new(&scene);
        cases.push(Case {
            name: format!("random {i}"),
            scene,
            lowered,
        });
    }
    cases
}

/// The points: 512 uniform in [-3, 3]³ (where the scenes are) and 64 in [-12, 12]³.
fn points() -> Vec<[f64; 3]> {
    let mut rng = Rng::new(17);
    let mut pts: Vec<[f64; 3]> = (0..512).map(|_| rng.point(3.0)).collect();
    pts.extend((0..64).map(|_| rng.point(12.0)));
    pts
}

/// The scale of a point: the largest of 1 and its coordinates' magnitudes. A distance is
/// a difference of values of about this size, so its rounding error is in ulps of it.
fn scale(p: [f64; 3]) -> f64 {
    p.iter().fold(1.0f64, |s, c| s.max(c.abs()))
}

/// How far apart two f32 distances are, in ulps of the larger of |a|, |b| and the point's
/// scale `s` (a distance near a surface is a small difference of larger numbers, so its
/// error is counted in the ulps of those): 0 when equal (or both NaN), infinite when one
/// alone is NaN.
fn ulps(a: f32, b: f32, s: f64) -> f64 {
    if a == b || (a.is_nan() && b.is_nan()) {
        return 0.0;
    }
    if a.is_nan() || b.is_nan() {
        return f64::INFINITY;
    }
    let m = (a.abs().max(b.abs()) as f64).max(s) as f32;
    let ulp = f32::from_bits(m.to_bits() + 1) - m;
    (a as f64 - b as f64).abs() / ulp as f64
}

/// The worst disagreement found by one comparison, and the failures beyond its bound.
#[derive(Default)]
struct Worst {
    error: f64,
    at: String,
    failures: usize,
}

impl Worst {
    fn see(&mut self, error: f64, bound: f64, at: impl FnOnce() -> String) {
        if error > bound {
            self.failures += 1;
        }
        if error > self.error || (error.is_nan() && !self.error.is_nan()) {
            self.error = error;
            self.at = at();
        }
    }
}

/// The comparisons of one f32 evaluator over the cases of one class ([`CLASSES`]): against
/// the interpreter in ulps, material ids, and against the f64 reference.
struct Class {
    name: &'static str,
    max_ulps: f64,
    bound: f64,
    ulps: Worst,
    materials: Worst,
    reference: Worst,
    exact: usize,
    total: usize,
}

impl Class {
    fn new(name: &'static str, max_ulps: f64, bound: f64) -> Self {
        Class {
            name,
            max_ulps,
            bound,
            ulps: Worst::default(),
            materials: Worst::default(),
            reference: Worst::default(),
            exact: 0,
            total: 0,
        }
    }

    /// Compares `got` with the interpreter's `base` and the reference `truth` at `points`.
    fn compare(
        &mut self,
        case: &str,
        points: &[[f64; 3]],
        got: &[Value<f32>],
        base: &[Value<f32>],
        truth: &[Value<f64>],
    ) {
        assert_eq!(got.len(), points.len(), "{case}: one result per point");
        for (i, &p) in points.iter().enumerate() {
            let ((d, m), (b, bm), (t, _)) = (got[i], base[i], truth[i]);
            let s = scale(p);
            let u = ulps(d, b, s);
            self.total += 1;
            self.exact += (d.to_bits() == b.to_bits()) as usize;
            let at = || format!("{case} at {p:?}: {d:e} against {b:e} (f64 {t:e})");
            self.ulps.see(u, self.max_ulps, at);
            // A material may differ only where the distances do (two children about equally
            // near, and the evaluators' roundings part them).
            let wrong = if m != bm && u == 0.0 { 1.0 } else { 0.0 };
            self.materials.see(wrong, 0.0, || {
                format!("{case} at {p:?}: material {m} against {bm}")
            });
            let r = (d as f64 - t).abs() / s;
            self.reference.see(r, self.bound, || {
                format!("{case} at {p:?}: {d:e} against f64 {t:e}")
            });
        }
    }

    fn summary(&self) -> String {
        format!(
            "  {}: {} of {} values bit for bit; worst {:.1} ulps (bound {}): {}; worst against f64 {:.2e}·s (bound {:.0e}): {}; {} material ids differ where distances agree {}",
            self.name,
            self.exact,
            self.total,
            self.ulps.error,
            self.max_ulps,
            self.ulps.at,
            self.reference.error,
            self.bound,
            self.reference.at,
            self.materials.failures,
            self.materials.at,
        )
    }

    fn failed(&self) -> bool {
        self.ulps.failures + self.reference.failures + self.materials.failures > 0
    }
}

/// The comparisons of one f32 evaluator: a [`Class`] for each of [`CLASSES`].
struct Report {
    evaluator: &'static str,
    classes: Vec<Class>,
}

impl Report {
    /// A report with the bounds of [`CLASSES`].
    fn gpu(evaluator: &'static str) -> Self {
        Self::with_ulps(evaluator, CLASSES.map(|c| c.ulps))
    }

    /// A report with the given ulps per class and the reference bounds of [`CLASSES`].
    fn with_ulps(evaluator: &'static str, ulps: [f64; 3]) -> Self {
        Report {
            evaluator,
            classes: CLASSES
                .iter()
                .zip(ulps)
                .map(|(c, u)| Class::new(c.name, u, c.reference))
                .collect(),
        }
    }

    /// Compares one case's results (see [`Class::compare`]).
    fn compare(
        &mut self,
        case: &Case,
        points: &[[f64; 3]],
        got: &[Value<f32>],
        (base, truth): &Baseline,
    ) {
        self.classes[class(&case.lowered.program)].compare(&case.name, points, got, base, truth);
    }

    /// Prints the worst cases, and panics with them where a bound was passed.
    fn check(&self) {
        let lines: Vec<String> = self.classes.iter().map(Class::summary).collect();
        let text = format!("{}:\n{}", self.evaluator, lines.join("\n"));
        println!("{text}");
        assert!(
            !self.classes.iter().any(Class::failed),
            "{} values beyond the ulps bound, {} beyond the f64 bound, {} material ids differ:\n{text}",
            self.classes.iter().map(|c| c.ulps.failures).sum::<usize>(),
            self.classes.iter().map(|c| c.reference.failures).sum::<usize>(),
            self.classes.iter().map(|c| c.materials.failures).sum::<usize>(),
        );
    }

    /// Whether every value was the interpreter's, bit for bit.
    fn all_exact(&self) -> bool {
        self.classes.iter().all(|c| c.exact == c.total)
    }
}

/// The f32 interpreter's and the f64 reference's results of one case.
type Baseline = (Vec<Value<f32>>, Vec<Value<f64>>);

/// The interpreter and reference results of every case, computed once per test.
fn baseline(cases: &[Case], points: &[[f64; 3]]) -> Vec<Baseline> {
    cases
        .iter()
        .map(|c| {
            (
                evaluators::interpreter::<f32>(&c.lowered.program, points),
                evaluators::reference(&c.lowered.program, points),
            )
        })
        .collect()
}

/// A scratch folder of this process (the test binary also runs on the GPU machine, away from
/// its build folder).
fn scratch(what: &str) -> PathBuf {
    std::env::temp_dir().join(format!(
        "sdfc-distance-conformance-{what}-{}",
        std::process::id()
    ))
}

/// Skips (saying so) or, where `var` asks for every device, fails.
fn skip(var: &str, what: &str) {
    assert!(!evaluators::required(var), "{var}=1, but {what}");
    println!("SKIPPED: {what}");
}

#[test]
fn the_interpreter_agrees_with_the_f64_reference() {
    let (cases, points) = (cases(), points());
    let mut report = Report::with_ulps("f32 interpreter", [0.0; 3]);
    for (case, results) in cases.iter().zip(baseline(&cases, &points)) {
        report.compare(case, &points, &results.0, &results);
    }
    report.check();
}

#[test]
fn the_emitted_rust_is_the_interpreter_bit_for_bit() {
    // A scene with a mesh has no Rust form (`sdfc compile --emit rust` refuses it).
    let cases: Vec<Case> = cases()
        .into_iter()
        .filter(|c| c.lowered.program.meshes().next().is_none())
        .collect();
    let points = points();
    let programs: Vec<_> = cases.iter().map(|c| &c.lowered.program).collect();
    let dir = scratch("rust");
    let results = match evaluators::emitted_rust(&programs, &points, &dir) {
        Ok(r) => r,
        Err(why) => return skip("SDFC_REQUIRE_DEVICES", &format!("emitted Rust: {why}")),
    };
    let mut report = Report::with_ulps("emitted Rust", [RUST_ULPS; 3]);
    for ((case, got), base) in cases
        .iter()
        .zip(&results.f32)
        .zip(baseline(&cases, &points))
    {
        report.compare(case, &points, got, &base);
    }
    report.check();
    assert!(report.all_exact());
    // `map_f64` is the f64 reference, bit for bit (NaN as NaN).
    for ((case, got), truth) in cases
        .iter()
        .zip(&results.f64)
        .zip(&baseline(&cases, &points))
    {
        for (i, (&(d, m), &(t, tm))) in got.iter().zip(&truth.1).enumerate() {
            assert!(
                (d.to_bits() == t.to_bits() || (d.is_nan() && t.is_nan())) && m == tm,
                "{}: map_f64 at {:?}: ({d:e}, {m}) against the reference ({t:e}, {tm})",
                case.name,
                points[i]
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The f64 batch interpreter is the f64 reference (`Program::run`), bit for bit.
#[test]
fn the_f64_interpreter_is_the_reference_bit_for_bit() {
    let (cases, points) = (cases(), points());
    for case in &cases {
        let batch = evaluators::interpreter::<f64>(&case.lowered.program, &points);
        let truth = evaluators::reference(&case.lowered.program, &points);
        for (i, (&(d, m), &(t, tm))) in batch.iter().zip(&truth).enumerate() {
            assert!(
                (d.to_bits() == t.to_bits() || (d.is_nan() && t.is_nan())) && m == tm,
                "{} at {:?}: ({d:e}, {m}) against the reference ({t:e}, {tm})",
                case.name,
                points[i]
            );
        }
    }
}

/// The distance alone of a WGSL module as values with the interpreter's materials (it has
/// none of its own).
fn alone(distances: &[f32], base: &[Value<f32>]) -> Vec<Value<f32>> {
    distances
        .iter()
        .zip(base)
        .map(|(&d, &(_, m))| (d, m))
        .collect()
}

/// The reports of the GPU evaluators of one backend: the part's `map` and `map_distance`,
/// and the instance walk's `map` and `sdf`.
struct Gpu {
    part: Report,
    part_alone: Report,
    walk: Report,
    walk_alone: Report,
    walked: Vec<String>,
}

impl Gpu {
    fn new(
        part: &'static str,
        part_alone: &'static str,
        walk: &'static str,
        walk_alone: &'static str,
    ) -> Self {
        Gpu {
            part: Report::gpu(part),
            part_alone: Report::gpu(part_alone),
            walk: Report::gpu(walk),
            walk_alone: Report::gpu(walk_alone),
            walked: Vec::new(),
        }
    }

    /// Runs every case's part, and its instance walk where it has instances, through `run`.
    fn run(
        &mut self,
        cases: &[Case],
        points: &[[f64; 3]],
        mut run: impl FnMut(&evaluators::PointsModule) -> evaluators::Results,
    ) {
        for (case, base) in cases.iter().zip(baseline(cases, points)) {
            let part = evaluators::points_module(&case.scene, &case.lowered, true);
            let (map, distance) = run(&part);
            self.part.compare(case, points, &map, &base);
            self.part_alone
                .compare(case, points, &alone(&distance, &base.0), &base);
            if let Some(walk) = evaluators::walk_module(&case.scene) {
                let (map, distance) = run(&walk);
                self.walk.compare(case, points, &map, &base);
                self.walk_alone
                    .compare(case, points, &alone(&distance, &base.0), &base);
                self.walked.push(case.name.clone());
            }
        }
    }

    fn check(&self) {
        println!("instances walked in: {}", self.walked.join(", "));
        assert!(
            self.walked.iter().any(|n| n == "instances") && self.walked.len() >= 5,
            "too few cases with instances: {:?}",
            self.walked
        );
        for r in [&self.part, &self.part_alone, &self.walk, &self.walk_alone] {
            r.check();
        }
    }
}

#[test]
fn wgpu_agrees_with_the_interpreter_in_ulps() {
    let gpu = match sdfc_runtime::gpu::Gpu::open(false) {
        Ok(g) => g,
        Err(e) => return skip("SDFC_REQUIRE_DEVICES", &format!("wgpu: no adapter ({e})")),
    };
    println!("adapter: {}", gpu.describe());
    let (cases, points) = (cases(), points());
    let mut reports = Gpu::new(
        "wgpu, the part's map",
        "wgpu, the part's map_distance",
        "wgpu, the kernel's instance walk, map",
        "wgpu, the kernel's instance walk, sdf",
    );
    reports.run(&cases, &points, |m| evaluators::run_wgpu(&gpu, m, &points));
    reports.check();
}

/// Every case's part and instance walk translate to PTX that `ptxas` assembles (for sm_80: the oldest target every ptxas from CUDA 12 to 13 knows), and
/// where a CUDA device is present they run there and agree with the interpreter.
#[test]
fn the_ptx_assembles_and_cuda_agrees_with_the_interpreter_in_ulps() {
    let (cases, points) = (cases(), points());
    let dir = scratch("ptx");
    std::fs::create_dir_all(&dir).expect("scratch folder");
    match evaluators::ptxas() {
        None => skip("SDFC_REQUIRE_DEVICES", "ptxas: not on the PATH"),
        Some(ptxas) => {
            for (i, case) in cases.iter().enumerate() {
                let walk = evaluators::walk_module(&case.scene);
                let part = evaluators::points_module(&case.scene, &case.lowered, true);
                for (what, m) in [("part", Some(part)), ("walk", walk)] {
                    let Some(m) = m else { continue };
                    let file = dir.join(format!("case{i}_{what}.ptx"));
                    std::fs::write(&file, evaluators::points_ptx(&m, 70)).expect("PTX");
                    let cubin = dir.join(format!("case{i}_{what}.cubin"));
                    let named = format!("{} ({what}): {}", case.name, file.display());
                    evaluators::assemble(&ptxas, &file, &cubin, &named);
                }
            }
            let _ = std::fs::remove_dir_all(&dir);
        }
    }
    let (ctx, sm) = match evaluators::open_cuda() {
        Ok(c) => c,
        Err(why) => return skip("SDFC_REQUIRE_CUDA", &format!("CUDA: {why}")),
    };
    let mut reports = Gpu::new(
        "CUDA, the part's map",
        "CUDA, the part's map_distance",
        "CUDA, the kernel's instance walk, map",
        "CUDA, the kernel's instance walk, sdf",
    );
    reports.run(&cases, &points, |m| {
        evaluators::run_cuda(&ctx, m, &evaluators::points_ptx(m, sm), &points)
    });
    reports.check();
}

/// The feature scenes hold every kind of scene node and their programs every operation,
/// so that each evaluator meets each.
#[test]
fn the_feature_scenes_cover_every_node_and_operation() {
    let features = scenes(FEATURES);
    let mut nodes = std::collections::BTreeSet::new();
    let mut ops = std::collections::BTreeSet::new();
    for case in &features {
        for id in case.scene.graph.ids() {
            nodes.insert(node_kind(case.scene.graph.node(id)));
        }
        for op in case.lowered.program.ops() {
            ops.insert(op_kind(op));
        }
    }
    let all_nodes = [
        "sphere",
        "box",
        "round_box",
        "plane",
        "torus",
        "cylinder",
        "capsule",
        "cone",
        "ellipsoid",
        "rect",
        "polygon",
        "bezier",
        "text",
        "extrude",
        "revolve",
        "loft",
        "screw",
        "sweep",
        "combine",
        "smooth_combine",
        "feature",
        "translate",
        "rotate",
        "scale",
        "scale_xyz",
        "repeat",
        "repeat_polar",
        "mirror",
        "twist",
        "bend",
        "wrap",
        "shear",
        "taper",
        "morph",
        "round",
        "shell",
        "elongate",
        "paint",
        "field",
        "mesh",
    ];
    // And every primitive of the table.
    let table = sdfc_compiler::prim::all().map(|p| p.name);
    let missing: Vec<_> = all_nodes
        .into_iter()
        .chain(table)
        .filter(|n| !nodes.contains(n))
        .collect();
    assert!(missing.is_empty(), "no feature scene has {missing:?}");
    // Every operation.
    let all_ops = [
        "const", "input", "neg", "abs", "sqrt", "sin", "cos", "acos", "exp", "log", "floor",
        "round", "add", "sub", "mul", "div", "min", "max", "pow", "atan2", "lt", "select", "phi",
        "mesh", "outline",
    ];
    let missing: Vec<_> = all_ops.iter().filter(|o| !ops.contains(*o)).collect();
    assert!(
        missing.is_empty(),
        "no feature scene's program has {missing:?}"
    );
}

/// A node's kind, named; every variant is listed, so a new one fails to compile here.
fn node_kind(node: &Node) -> &'static str {
    match node {
        Node::Sphere { .. } => "sphere",
        Node::Box { .. } => "box",
        Node::RoundBox { .. } => "round_box",
        Node::Plane { .. } => "plane",
        Node::Torus { .. } => "torus",
        Node::Cylinder { .. } => "cylinder",
        Node::Capsule { .. } => "capsule",
        Node::Cone { .. } => "cone",
        Node::Ellipsoid { .. } => "ellipsoid",
        Node::Combine { .. } => "combine",
        Node::SmoothCombine { .. } => "smooth_combine",
        Node::Feature { .. } => "feature",
        Node::Translate { .. } => "translate",
        Node::Rotate { .. } => "rotate",
        Node::Scale { .. } => "scale",
        Node::ScaleXyz { .. } => "scale_xyz",
        Node::Repeat { .. } => "repeat",
        Node::RepeatPolar { .. } => "repeat_polar",
        Node::Mirror { .. } => "mirror",
        Node::Twist { .. } => "twist",
        Node::Bend { .. } => "bend",
        Node::Wrap { .. } => "wrap",
        Node::Shear { .. } => "shear",
        Node::Taper { .. } => "taper",
        Node::Morph { .. } => "morph",
        Node::Round { .. } => "round",
        Node::Shell { .. } => "shell",
        Node::Elongate { .. } => "elongate",
        Node::Paint { .. } => "paint",
        Node::Field { .. } => "field",
        Node::Rect { .. } => "rect",
        Node::Polygon { .. } => "polygon",
        Node::Bezier { .. } => "bezier",
        Node::Text { .. } => "text",
        Node::Extrude { .. } => "extrude",
        Node::Revolve { .. } => "revolve",
        Node::Mesh { .. } => "mesh",
        Node::Loft { .. } => "loft",
        Node::Screw { .. } => "screw",
        Node::Sweep { .. } => "sweep",
        Node::Prim { prim, .. } => prim.name,
    }
}

/// An operation's kind, named; every variant is listed, so a new one fails to compile here.
fn op_kind(op: &Op) -> &'static str {
    match op {
        Op::Const(_) => "const",
        Op::Input(_) => "input",
        Op::Unary(u, _) => match u {
            Unary::Neg => "neg",
            Unary::Abs => "abs",
            Unary::Sqrt => "sqrt",
            Unary::Sin => "sin",
            Unary::Cos => "cos",
            Unary::Acos => "acos",
            Unary::Exp => "exp",
            Unary::Log => "log",
            Unary::Floor => "floor",
            Unary::Round => "round",
        },
        Op::Binary(b, ..) => match b {
            Binary::Add => "add",
            Binary::Sub => "sub",
            Binary::Mul => "mul",
            Binary::Div => "div",
            Binary::Min => "min",
            Binary::Max => "max",
            Binary::Pow => "pow",
            Binary::Atan2 => "atan2",
            Binary::Lt => "lt",
        },
        Op::Select(..) => "select",
        Op::Phi(..) => "phi",
        Op::Mesh(..) => "mesh",
        Op::Outline(..) => "outline",
    }
}
