//! The checker: resolves imports and names, type-checks every item, evaluates every constant
//! expression and builds the scene IR.
//!
//! Order: load and parse all files (imports first, depth first); collect declarations
//! (duplicates are errors); check each function body on its own (a function may call itself:
//! evaluated within the `call_depth` limit); then
//! evaluate items in source order, and the scene last.

mod blocks;
pub mod builtins;
pub mod colour;
mod eval;
pub mod field;
pub mod font;
mod hull;
mod items;
mod lights;
mod load;
mod materials;
pub mod meshfile;
mod ops;
mod params;
mod polygon;
mod suggest;
pub mod types;

use crate::diagnostics::Diagnostic;
// The loader is the file system's interface (`files`); the checker reads through it.
pub use crate::files::{LoadError, Loader, NoImports};
use crate::limits::Limits;
use crate::scene::{Method, Scene, Settings};
use crate::span::{FileId, SourceMap, Span};
use crate::syntax::ast;
use eval::Ctx;
use items::check_items;
pub(crate) use load::Files;
use load::Load;

/// The value of a global constant, as an editor's hover shows it.
#[derive(Debug, Clone, PartialEq)]
pub struct Constant {
    /// The constant's name where it is declared.
    pub at: Span,
    /// Its value written as in the language (`6`, `(1, 2, 0.5)`, `45deg`, `"poly"`,
    /// `[1, 2]`).
    pub value: String,
    /// Its type (`int`, `vec3`, `[float]`).
    pub ty: String,
}

/// Where the parts of a scene that have a position were written, for the warnings' spans.
#[derive(Debug, Default)]
pub struct Places {
    /// The camera's `position` (its value, or the `camera` keyword when it is left out);
    /// `None` without a `camera` block.
    pub camera: Option<Span>,
    /// Per light of `Scene::lights`, in order: its `position` value, or its kind.
    pub lights: Vec<Span>,
    /// The `scene` keyword.
    pub scene: Option<Span>,
}

/// The warnings of the passes after the checker, given a scene without errors and where its
/// parts were written; the front end passes the placement warnings (`front/placement.rs`).
pub type After<'a> = &'a dyn Fn(&Scene, &Places) -> Vec<Diagnostic>;

/// Checks the file `entry` of `sources` and everything it imports (added to `sources`),
/// within `limits`, at the time `time`: the scene when there are no errors, all diagnostics
/// in source order (those of `after` too), and the values of the global constants.
pub fn check_files(
    sources: &mut SourceMap,
    entry: FileId,
    loader: &mut dyn Loader,
    limits: &Limits,
    time: f64,
    after: After,
) -> (Option<Scene>, Vec<Diagnostic>, Vec<Constant>) {
    let mut diags = Vec::new();
    let mut items = Vec::new();
    let mut load = Load {
        sources,
        loader,
        limits,
        stack: Vec::new(),
        items: &mut items,
        diags: &mut diags,
        depth: 0,
        imports: Vec::new(),
    };
    load.file(entry);
    let depth = load.depth;
    let imports = std::mem::take(&mut load.imports);
    let names = (0..sources.len() as u32)
        .map(|f| sources.name(FileId(f)).to_string())
        .collect();
    let files = Files {
        loader: Some(loader),
        names,
        ..Files::default()
    };
    // The checker's walks of the syntax tree, and of the scene built from it, recurse as
    // deeply as the files nest (within the `nesting` limit the parser enforced): they run on
    // a stack that fits, and so does the drop of the tree.
    crate::syntax::with_stack_for(depth, move || {
        check_loaded(entry, limits, time, (diags, items, imports), files, after)
    })
}

/// The checks after the files are read and parsed.
fn check_loaded(
    entry: FileId,
    limits: &Limits,
    time: f64,
    (mut diags, items, imports): (Vec<Diagnostic>, Vec<ast::Item>, Vec<(FileId, FileId)>),
    files: Files,
    after: After,
) -> (Option<Scene>, Vec<Diagnostic>, Vec<Constant>) {
    if crate::diagnostics::has_errors(&diags) {
        // After a lexical, syntax or import error, names and items may be missing: checking
        // would report mistakes that are only echoes of the first ones.
        diags.sort_by_key(|d| (d.span().file, d.span().start));
        return (None, diags, Vec::new());
    }
    let mut cx = Ctx::default();
    cx.files = files;
    cx.imports = imports;
    cx.diags = diags;
    cx.limits = limits.clone();
    cx.time = time;
    let mut scene = check_items(&mut cx, &items, entry);
    let mut constants: Vec<Constant> = cx
        .globals
        .values()
        .filter_map(|(v, at)| {
            Some(Constant {
                at: *at,
                value: v.show()?,
                ty: v.type_name(),
            })
        })
        .collect();
    constants.sort_by_key(|c| (c.at.file, c.at.start));
    scene.limits = limits.clone();
    scene.animation.time = time;
    scene.animation.reads_time = cx.first_time_read;
    if !crate::diagnostics::has_errors(&cx.diags) {
        // Before any pass walks the shapes as a tree: a small graph of shared shapes can
        // expand exponentially.
        if let Some(e) = scene.over_expanded() {
            cx.error(scene.expansion_error(&e));
        }
    }
    if !crate::diagnostics::has_errors(&cx.diags) {
        // Distance semantics: warnings where a construct makes the field unreliable.
        let analysis = crate::scene::analysis::analyse(&scene);
        cx.diags.extend_from_slice(analysis.diagnostics());
        if analysis.root().is_some_and(|root| !root.proven) {
            unbounded_defaults(&cx, &mut scene.settings);
        }
        reach(&mut cx, &mut scene);
        analytic_method(&mut cx, &scene);
    }
    if !crate::diagnostics::has_errors(&cx.diags) {
        // The passes after the checker: where the camera and lights stand, and whether
        // there are any lights.
        let places = std::mem::take(&mut cx.places);
        cx.diags.extend(after(&scene, &places));
    }
    // Diagnostics in source order, whatever stage found them.
    cx.diags.sort_by_key(|d| (d.span().file, d.span().start));
    let errors = crate::diagnostics::has_errors(&cx.diags);
    (if errors { None } else { Some(scene) }, cx.diags, constants)
}

/// The defaults of a field with no proven distance bound, for the settings the file does not
/// give (docs/accuracy.md, "Fields without a bound"): such a field has detail below any ε, so
/// ε follows the pixel footprint; and over-relaxation, whose fallback relies on a bound, is off.
fn unbounded_defaults(cx: &Ctx, settings: &mut Settings) {
    settings.footprint = given(cx, "epsilon").is_none();
    if given(cx, "relaxation").is_none() {
        settings.relaxation = 1.0;
    }
}

/// Where the render block sets the setting `name`, if it does.
fn given(cx: &Ctx, name: &str) -> Option<Span> {
    cx.settings_given
        .iter()
        .find(|(n, _)| n == name)
        .map(|(_, at)| *at)
}

/// `max_dist` and the scene's bounded parts (docs/rendering.md, "Marching"): unless the file
/// sets it, it covers every one of them as seen from the camera; where the file sets it
/// short of one, W0017 says so.
fn reach(cx: &mut Ctx, scene: &mut Scene) {
    use crate::scene::reach;
    let parts = reach::parts(scene);
    match given(cx, "max_dist") {
        None => {
            scene.settings.max_dist = reach::default_max_dist(&parts, scene.settings.max_dist);
        }
        Some(at) => {
            let far = reach::beyond(&parts, scene.settings.max_dist, at);
            cx.diags.extend(far);
        }
    }
}

/// `method: "trace"` on a scene that cannot be ray traced analytically is an error at the
/// setting, pointing at what prevents it.
fn analytic_method(cx: &mut Ctx, scene: &Scene) {
    use crate::scene::analytic::{choose, Choice, Reason};
    let (Method::Trace, Some(at)) = (scene.settings.method, given(cx, "method")) else {
        return;
    };
    let Choice::March(reason) = choose(scene) else {
        return;
    };
    let mut d = Diagnostic::error("E0405", "this scene cannot be ray traced analytically", at)
        .with_label("analytic tracing is asked for here")
        .with_help("use `method: \"auto\"` to sphere trace such scenes");
    d = match reason {
        Reason::Node { span, what } => d.with_secondary(
            span,
            format!("`{what}` has no closed-form ray intersection"),
        ),
        Reason::Overlap { span } => d.with_secondary(
            span,
            "this transparent shape overlaps or touches another transparent one",
        ),
        other => d.with_note(other.describe()),
    };
    cx.error(d);
}

fn dup(cx: &mut Ctx, what: &str, name: &ast::Ident, first: Span) {
    cx.error(
        Diagnostic::error(
            "E0207",
            format!("duplicate definition of {what} `{}`", name.name),
            name.span,
        )
        .with_label("defined again here")
        .with_secondary(first, "first defined here"),
    );
}

/// E0211: `kind` names none of `records`, the kinds of `what` (light, material) that `note`
/// lists; the nearest name as help.
fn unknown_kind(
    cx: &mut Ctx,
    what: &str,
    kind: &ast::Ident,
    records: &[builtins::Record],
    note: &str,
) {
    let mut d = Diagnostic::error(
        "E0211",
        format!("unknown {what} kind `{}`", kind.name),
        kind.span,
    )
    .with_label(format!("not a {what} kind"))
    .with_note(note);
    if let Some(s) = suggest::closest(&kind.name, records.iter().map(|r| r.name)) {
        d = d.with_help(format!("did you mean `{s}`?"));
    }
    cx.error(d);
}

/// The span of the value of the field `name` of a block, when it is given.
pub(super) fn field_span(fields: &[ast::Field], name: &str) -> Option<Span> {
    fields
        .iter()
        .find(|f| f.name.name == name)
        .map(|f| f.value.span)
}

#[cfg(test)]
mod tests;
