//! `sdfc check`: report every mistake in one or more scene files, and what the analysis
//! derived about each scene's distance field.

use crate::frontend::{self, DiagnosticFormat, Loaded};
use sdfc_compiler::scene::analysis::{self, Analysis};
use sdfc_compiler::scene::analytic::{self, Choice, Reason};
use sdfc_compiler::scene::{Exactness, Scene};
use sdfc_compiler::Span;
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
            Err(msg) => {
                eprintln!("error: {msg}");
                code = 2;
            }
            Ok(loaded) => {
                frontend::report(&loaded, args.diagnostics);
                match &loaded.scene {
                    None => code = code.max(1),
                    Some(scene) if args.diagnostics == DiagnosticFormat::Human => {
                        eprintln!(
                            "{}: ok; {}; {}",
                            file.display(),
                            summary(&loaded, scene),
                            method(&loaded, scene)
                        );
                    }
                    Some(_) => {}
                }
            }
        }
    }
    ExitCode::from(code)
}

/// What the analysis derived for the scene, in one clause: `distance field: bound (L = 1)`,
/// or, when inexact, with the construct responsible, and, where L > 1, that the lowering
/// divides it out locally (each operand by its own L, `docs/analysis.md`).
pub fn summary(loaded: &Loaded, scene: &Scene) -> String {
    let analysis = analysis::analyse(scene);
    let Some(root) = analysis.root() else {
        return "no objects".into();
    };
    let facts = root.facts;
    let word = analysis::describe(facts.exactness);
    let l = facts.lipschitz;
    let cause = cause(loaded, scene, &analysis);
    let step = analysis.step_lipschitz();
    match facts.exactness {
        Exactness::Exact | Exactness::Bound => format!("distance field: {word} (L = {})", num(l)),
        Exactness::Approximate if !root.proven => format!(
            "distance field: {word}, no bound proven{cause}; steps with L = {}{}",
            num(step),
            if scene.settings.footprint {
                "; ε follows the pixel footprint"
            } else {
                ""
            }
        ),
        Exactness::Approximate if step < l => format!(
            "distance field: {word}, L = {}{cause}, clamped to {}; divided out locally",
            num(l),
            num(step)
        ),
        Exactness::Approximate if l > 1.0 => format!(
            "distance field: {word}, L = {}{cause}; divided out locally",
            num(l)
        ),
        Exactness::Approximate => format!("distance field: {word}, L = {}{cause}", num(l)),
    }
}

/// How the scene is rendered and why: `method: trace (...)` or `method: march (...)`, with
/// the location of the node that rules out analytic tracing.
pub fn method(loaded: &Loaded, scene: &Scene) -> String {
    match analytic::choose(scene) {
        Choice::March(Reason::Node { what, span }) => format!(
            "method: march (the {what} at {} has no closed-form ray intersection)",
            at(loaded, span)
        ),
        Choice::March(Reason::Overlap { span }) => format!(
            "method: march (the transparent shape at {} overlaps or touches another one)",
            at(loaded, span)
        ),
        choice => choice.describe(),
    }
}

/// `FILE:LINE:COL` of a span.
fn at(loaded: &Loaded, span: Span) -> String {
    let (line, col) = loaded.sources.line_col(span);
    format!("{}:{line}:{col}", loaded.sources.name(span.file))
}

/// ` (the twist at FILE:LINE:COL)` for the node that made the field inexact, or nothing.
fn cause(loaded: &Loaded, scene: &Scene, analysis: &Analysis) -> String {
    let Some(id) = analysis.root().and_then(|r| r.cause) else {
        return String::new();
    };
    let kind = analysis::kind(scene.graph.node(id));
    format!(" (the {kind} at {})", at(loaded, scene.graph.span(id)))
}

/// A number with at most three decimals and no trailing zeros.
fn num(x: f64) -> String {
    let s = format!("{x:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}
