//! `sdfc check`: report every mistake in one or more scene files, and what the analysis
//! derived about each scene's distance field.

use crate::frontend::{self, DiagnosticFormat};
use sdfc_compiler::{
    analysis, diagnostics::number, Accepts, Diagnostic, ParamValue, Parameter, Scene, Severity,
};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `sdfc check`.
#[derive(Debug, clap::Args)]
pub struct CheckArgs {
    /// Scene files to check.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// How to print diagnostics.
    #[arg(long, value_enum, default_value_t)]
    pub diagnostics: DiagnosticFormat,
    /// Sample the Lipschitz bound of every user field (`field { … }`), declared or derived,
    /// over the scene's bounded region and the field's own, and report where a field is
    /// steeper (exit 1), and where and how much was sampled.
    #[arg(long)]
    pub verify_bounds: bool,
    #[command(flatten)]
    pub limits: super::LimitArgs,
}

/// Checks every file; exit 0 when all are clean, 1 when any has errors, 2 when any could not
/// be read. For a clean file, the human format ends with one line: `FILE: ok` and what the
/// field is (exact, a bound or approximate) with the L the renderers step with.
pub fn run(args: CheckArgs) -> ExitCode {
    let mut code = 0u8;
    let limits = args.limits.limits();
    for file in &args.files {
        match frontend::load_with(file, &limits) {
            Err(e) => {
                frontend::print_io_error(&e, args.diagnostics);
                code = 2;
            }
            Ok(loaded) => {
                frontend::report(&loaded, args.diagnostics);
                match &loaded.scene {
                    None => code = code.max(1),
                    Some(scene) => {
                        let human = args.diagnostics == DiagnosticFormat::Human;
                        if let Some(w) = beyond_render_limits(scene, &limits) {
                            frontend::print_diagnostics(&[w], &loaded.sources, args.diagnostics);
                        }
                        if human {
                            eprintln!(
                                "{}: ok; {}; {}",
                                file.display(),
                                frontend::summary(&loaded, scene),
                                // `sdfc check` does not lower a still scene: the primitives
                                // are found here, as the lowering would find them.
                                frontend::method(
                                    &loaded,
                                    scene,
                                    &sdfc_compiler::analytic::traceable(scene)
                                )
                            );
                        }
                        if human {
                            eprintln!("{}: {}", file.display(), frontend::tone_curve(scene));
                            for p in &scene.params {
                                eprintln!("{}: {}", file.display(), param_line(p));
                            }
                        } else if !scene.params.is_empty() {
                            println!("{}", params_json(file, &scene.params));
                        }
                        if args.verify_bounds && !verify_bounds(&loaded, file, scene) {
                            code = code.max(1);
                        }
                        match animation(file, scene, &limits, args.diagnostics) {
                            Ok(line) if human => eprintln!("{}: {line}", file.display()),
                            Ok(_) => {}
                            Err(c) => code = code.max(c),
                        }
                    }
                }
            }
        }
    }
    ExitCode::from(code)
}

/// One parameter as `sdfc check` lists it: `param width = 60 (default 40) in 10..100: Box
/// width (mm)`.
fn param_line(p: &Parameter) -> String {
    let mut line = format!("param {} = {}", p.name, p.value);
    if p.value != p.default {
        line += &format!(" (default {})", p.default);
    }
    if p.accepts != Accepts::Any {
        line += &format!(" in {}", p.accepts);
    }
    if !p.doc.is_empty() {
        line += &format!(": {}", p.doc);
    }
    line
}

/// The parameters as one JSON line: `{"file": …, "params": [{"name", "type", "value",
/// "default", "doc", and "min", "max", "step" or "choices"}]}`.
fn params_json(file: &std::path::Path, params: &[Parameter]) -> String {
    let value = |v: &ParamValue| match v {
        ParamValue::Float(x) => serde_json::json!(x),
        ParamValue::Int(i) => serde_json::json!(i),
        ParamValue::Bool(b) => serde_json::json!(b),
        ParamValue::Str(s) => serde_json::json!(s),
    };
    let list: Vec<serde_json::Value> = params
        .iter()
        .map(|p| {
            let mut o = serde_json::json!({
                "name": p.name,
                "type": p.default.type_name(),
                "value": value(&p.value),
                "default": value(&p.default),
                "doc": p.doc,
            });
            match &p.accepts {
                Accepts::Any => {}
                Accepts::Range { lo, hi, step } => {
                    o["min"] = serde_json::json!(lo);
                    o["max"] = serde_json::json!(hi);
                    if let Some(s) = step {
                        o["step"] = serde_json::json!(s);
                    }
                }
                Accepts::Choices(c) => o["choices"] = serde_json::json!(c),
            }
            o
        })
        .collect();
    serde_json::json!({ "file": file.display().to_string(), "params": list }).to_string()
}

/// A warning where `scene`, which checks, is more than `sdfc render` and `sdfc mesh` accept
/// within `limits`: its shapes counted as a tree beyond `expansion`, or its distance program
/// beyond `program`. The scene is lowered as a render lowers it, and the lowering stops at
/// the limit, so this costs no more than the render would have spent before failing.
fn beyond_render_limits(scene: &Scene, limits: &sdfc_compiler::Limits) -> Option<Diagnostic> {
    let options = sdfc_compiler::LowerOptions::default();
    let error = sdfc_compiler::lower_within(scene, &options, limits).err()?;
    Some(Diagnostic {
        severity: Severity::Warning,
        message: format!(
            "`sdfc render` and `sdfc mesh` will refuse this scene: {}",
            error.message
        ),
        ..error
    })
}

/// Pairs of points sampled per field and region by `--verify-bounds`.
const VERIFY_PAIRS: usize = 20_000;

/// A box as `sdfc check` prints it: `[(x, y, z), (x, y, z)]`, its corners.
fn corners(r: &sdfc_compiler::verify::Region) -> String {
    let v = |p: [f64; 3]| {
        format!(
            "({}, {}, {})",
            number(p[0], 3),
            number(p[1], 3),
            number(p[2], 3)
        )
    };
    format!("[{}, {}]", v(r.min), v(r.max))
}

/// `--verify-bounds`: every field's bound sampled over the scene's bounded region and its
/// own; false when one is exceeded. Prints, for each field, where it was sampled and with how
/// many pairs of points, and the fields that were not; never claims more than was sampled.
fn verify_bounds(loaded: &frontend::Loaded, file: &std::path::Path, scene: &Scene) -> bool {
    use sdfc_compiler::verify::{Over, Unsampled};
    let v = sdfc_compiler::verify_fields(scene, VERIFY_PAIRS);
    let at = |id: sdfc_compiler::NodeId| {
        let span = scene.graph.span(id);
        let (line, col) = loaded.sources.line_col(span);
        format!(
            "{}:{line}:{col}: this {}",
            loaded.sources.name(span.file),
            scene.graph.node(id).kind()
        )
    };
    let over = |regions: &[(Over, sdfc_compiler::verify::Region, usize)]| {
        regions
            .iter()
            .map(|(o, r, n)| {
                let what = match o {
                    Over::Scene => "the scene's box",
                    Over::Own => "its own box",
                };
                format!("{n} pairs of points over {what} {}", corners(r))
            })
            .collect::<Vec<_>>()
            .join(" and ")
    };
    let mut clean = true;
    for f in &v.sampled {
        match &f.violation {
            Some(w) => {
                clean = false;
                eprintln!(
                    "{} has a slope of {} between {:?} and {:?}, above its L = {} (found in {}, in its coordinates)",
                    at(f.node),
                    number(w.slope, 4),
                    w.at.0,
                    w.at.1,
                    number(w.bound, 4),
                    over(&f.regions)
                );
            }
            None => eprintln!(
                "{}: no slope above its L = {} in {}, in its coordinates",
                at(f.node),
                number(f.bound, 4),
                over(&f.regions)
            ),
        }
    }
    for (id, why) in &v.unsampled {
        let why = match why {
            Unsampled::NoBound => "has no declared or proven L: nothing to sample",
            Unsampled::Unreached => "lies outside the scene's box: not sampled",
        };
        eprintln!("{} {why}", at(*id));
    }
    let axes: Vec<&str> = ["x", "y", "z"]
        .iter()
        .zip(v.scope.clipped)
        .filter(|(_, c)| *c)
        .map(|(a, _)| *a)
        .collect();
    let clipped = if axes.is_empty() {
        String::new()
    } else {
        format!(
            "; the scene is unbounded along {}, sampled within max_dist = {} of the camera there, and not beyond",
            axes.join(", "),
            number(scene.settings.max_dist, 4)
        )
    };
    eprintln!(
        "{}: bounds sampled, not proven: {} field(s), {} steeper than its L where sampled; the scene's box {}{clipped}",
        file.display(),
        v.sampled.len(),
        if clean { "none" } else { "some" },
        corners(&v.scope.region),
    );
    clean
}

/// Whether the scene is a still, an animation whose frames differ only in numbers, or one
/// whose structure changes, and the analysis of every frame (each frame is checked, analysed
/// and lowered on its own: the facts are computed per frame). `Err` is the exit code of a
/// frame that does not check or cannot be read again (its diagnostics printed).
pub fn animation(
    file: &std::path::Path,
    scene: &Scene,
    limits: &sdfc_compiler::Limits,
    format: DiagnosticFormat,
) -> Result<String, u8> {
    use sdfc_compiler::animation::{change_note, runs, Structure};
    use sdfc_compiler::Animation;
    let a = scene.animation;
    if !a.animated() {
        return Ok("still (nothing reads `t`)".into());
    }
    let n = a.frames();
    if n == 0 {
        return Ok(
            "reads `t` but `render` states no `duration`: a still at t = 0 unless rendered with --frames"
                .into(),
        );
    }
    let mut source = frontend::Source::read_within(file, limits).map_err(|e| {
        frontend::print_io_error(&e, format);
        2u8
    })?;
    // How many changes of structure are shown where they happen.
    const NOTED_CHANGES: usize = 3;
    let mut structures = Vec::new();
    let mut previous: Option<(Scene, Structure)> = None;
    let mut changes = 0usize;
    let (mut exactness, mut lmin, mut lmax, mut traced) = (Vec::new(), f64::MAX, 0f64, 0u64);
    for k in 0..n {
        let time = Animation::time_of(a.fps, k);
        let mut loaded = source.check(limits, time);
        loaded.diagnostics.retain(|d| d.is_error());
        frontend::report(&loaded, format);
        let Some(scene) = loaded.scene else {
            eprintln!("error: frame {k} (t = {time} s) has errors");
            return Err(1);
        };
        // Lowered as `sdfc render --frames` lowers a sequence's frames.
        let program = match sdfc_compiler::lower_within(
            &scene,
            &sdfc_compiler::LowerOptions::parametric(),
            limits,
        ) {
            Ok(p) => p,
            Err(d) => {
                frontend::print_diagnostics(&[d], &loaded.sources, format);
                eprintln!("error: frame {k} (t = {time} s) cannot be lowered");
                return Err(1);
            }
        };
        let analysis = analysis::analyse(&scene);
        if let Some(root) = analysis.root() {
            let word = analysis::describe(root.facts.exactness);
            if !exactness.contains(&word) {
                exactness.push(word);
            }
            lmin = lmin.min(analysis.step_lipschitz());
            lmax = lmax.max(analysis.step_lipschitz());
        }
        let structure = Structure::of(&scene, &program);
        traced += u64::from(structure.traced());
        // Where the structure changes from the frame before, said at its place in the source
        // (the first few such frames; the summary line counts them all).
        if let Some((before, was)) = &previous {
            if structures.last() != Some(&structure) {
                changes += 1;
                if changes <= NOTED_CHANGES {
                    if let Some(note) = change_note(k, time, (before, was), (&scene, &structure)) {
                        frontend::print_diagnostics(&[note], &loaded.sources, format);
                    }
                }
            }
        }
        structures.push(structure.clone());
        previous = Some((scene, structure));
    }
    if changes > NOTED_CHANGES {
        eprintln!(
            "note: the structure changes at {} more frames, not shown",
            changes - NOTED_CHANGES
        );
    }
    let starts = runs(structures.iter().enumerate().map(|(k, s)| (k as u64, s)));
    let distinct = {
        let mut d: Vec<&Structure> = Vec::new();
        for s in &structures {
            if !d.contains(&s) {
                d.push(s);
            }
        }
        d.len()
    };
    let kind = if distinct == 1 && traced > 0 {
        "animated, numbers only: every frame has the same structure (traced analytically: the GPU kernel holds the primitives' numbers and is built again for each frame whose numbers change)".to_string()
    } else if distinct == 1 {
        "animated, numbers only: every frame has the same structure (one GPU kernel for the sequence)".to_string()
    } else {
        format!(
            "animated, structure varies: {distinct} structures, changing at frame{} {} (the kernel is specialised again there)",
            if starts.len() == 2 { "" } else { "s" },
            starts[1..]
                .iter()
                .map(u64::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    let l = if lmin == lmax {
        format!("L = {}", number(lmin, 3))
    } else {
        format!("L from {} to {}", number(lmin, 3), number(lmax, 3))
    };
    let method = match traced {
        0 => "marched in every frame".to_string(),
        t if t == n => "traced in every frame".to_string(),
        t => format!("traced in {t} frames, marched in {}", n - t),
    };
    Ok(format!(
        "{kind}; {n} frames at {} fps; per frame: distance field {} ({l}), {method}",
        number(a.fps, 3),
        exactness.join(" or ")
    ))
}
