//! The checker: resolves imports and names, type-checks every item, evaluates every constant
//! expression and builds the scene IR.
//!
//! Order: load and parse all files (imports first, depth first); collect declarations
//! (duplicates are errors); check each function body on its own (a function may call itself:
//! evaluated within the `call_depth` limit); then
//! evaluate items in source order, and the scene last.

pub mod builtins;
pub mod colour;
mod eval;
pub mod field;
pub mod font;
mod hull;
mod lights;
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
use crate::limits::{Limit, Limits};
use crate::scene::{Camera, Combine, Material, Method, Node, Scene, Settings, Tonemap};
use crate::span::{FileId, SourceMap, Span};
use crate::syntax::{self, ast};
use eval::{Ctx, FnInfo};
use std::collections::HashMap;
use std::rc::Rc;
use types::{Type, Value};

/// The files `mesh(path)` reads, through the caller's loader, and the meshes read so far.
#[derive(Default)]
pub struct Files<'l> {
    /// The caller's loader (none: no file can be read).
    pub loader: Option<&'l mut dyn Loader>,
    /// The name of each source file, by `FileId` (a path is relative to its file's).
    pub names: Vec<String>,
    /// The meshes built, by file name and scale's bits: a file used twice is read once.
    pub meshes: HashMap<(String, u64), std::sync::Arc<crate::program::mesh::TriMesh>>,
    /// The next mesh's id, and where its data starts in `scene_data` (16-byte vectors).
    pub next_id: u32,
    pub next_base: u64,
    /// Triangles of every mesh so far (the `triangles` limit bounds their sum).
    pub triangles: u64,
}

impl std::fmt::Debug for Files<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.debug_struct("Files")
            .field("names", &self.names)
            .field("meshes", &self.meshes.len())
            .finish()
    }
}

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
                ty: eval::type_name(v),
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

/// The files of one compilation being read: parsed in place of their imports, depth
/// first, with their items appended in order.
struct Load<'a> {
    sources: &'a mut SourceMap,
    loader: &'a mut dyn Loader,
    limits: &'a Limits,
    /// The files being imported, outermost first (a file found here again is a cycle).
    stack: Vec<FileId>,
    items: &'a mut Vec<ast::Item>,
    diags: &'a mut Vec<Diagnostic>,
    /// The deepest nesting of the files read ([`syntax::nesting`]).
    depth: usize,
    /// Which file imports which (importer, imported).
    imports: Vec<(FileId, FileId)>,
}

impl Load<'_> {
    /// Parses `file`, then its imports in place (depth first), appending items in order.
    fn file(&mut self, file: FileId) {
        self.stack.push(file);
        let text = self.sources.text(file).to_string();
        let ((ast, parse_diags), depth) = syntax::parse_within(file, &text, Some(self.limits));
        self.depth = self.depth.max(depth);
        self.diags.extend(parse_diags);
        for item in ast.items {
            if let ast::Item::Import { path, span } = &item {
                self.import(file, path, *span);
            } else {
                self.items.push(item);
            }
        }
        self.stack.pop();
    }

    fn import(&mut self, from: FileId, path: &str, span: Span) {
        let from_name = self.sources.name(from).to_string();
        let (name, text) = match self.loader.load(&from_name, path) {
            Ok(x) => x,
            Err(e) => {
                // The diagnostic's label: where the error's message is shown to the user.
                self.diags.push(
                    Diagnostic::error("E0501", format!("cannot import `{path}`"), span)
                        .with_label(e.to_string()),
                );
                return;
            }
        };
        if let Some(existing) = self.sources.find(&name) {
            self.imports.push((from, existing));
            if self.stack.contains(&existing) {
                let chain: Vec<&str> = self
                    .stack
                    .iter()
                    .map(|f| self.sources.name(*f))
                    .chain([name.as_str()])
                    .collect();
                self.diags.push(
                    Diagnostic::error("E0500", "import cycle", span)
                        .with_label(format!("`{path}` is already being imported"))
                        .with_note(format!("the cycle is {}", chain.join(" → "))),
                );
            }
            // A file imported twice (not in a cycle) is read once.
            return;
        }
        let max = self.limits.count(Limit::Files);
        if self.sources.len() >= max {
            self.diags.push(
                Diagnostic::error("E0507", format!("more than {max} files are imported"), span)
                    .with_note(format!(
                        "this limit keeps compilation bounded; {}",
                        self.limits.raise(Limit::Files)
                    )),
            );
            return;
        }
        let id = self.sources.add(name, text);
        self.imports.push((from, id));
        self.file(id);
    }
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

/// Checks the items of the entry file, pass by pass: declarations (functions, recursion,
/// constants, materials), the items in order (constants, materials, blocks), the functions
/// never called, then the scene's objects.
fn check_items(cx: &mut Ctx, items: &[ast::Item], entry: FileId) -> Scene {
    declare(cx, items);
    let mut scene = Scene {
        materials: vec![Material::default_material()],
        ..Scene::default()
    };
    materials::declare_materials(cx, &mut scene, items);
    let scene_item = evaluate_items(cx, &mut scene, items);
    materials::check_pairs(cx, &scene, items);
    // Where `tonemap` is not given, a scene of the newer look is graded by the filmic curve.
    if !cx.settings_given.iter().any(|(name, _)| name == "tonemap") {
        use crate::scene::look::{newer_look, OLDER_LOOK};
        let newer = newer_look(&scene);
        if newer.is_some() {
            scene.settings.tonemap = Tonemap::Filmic;
        }
        scene.settings.tonemap_why = Some(newer.unwrap_or(OLDER_LOOK));
    }
    params::unknown(cx, items, entry);
    check_uncalled_functions(cx);
    scene.root = scene_objects(cx, scene_item, entry);
    scene.graph = std::mem::take(&mut cx.graph);
    let max = cx.limits.count(Limit::Nodes);
    if let (Err(max), Some(root)) = (crate::scene::paint::place(&mut scene, max), scene.root) {
        cx.limit(
            Limit::Nodes,
            scene.graph.span(root),
            format!("painting each shape in its own coordinates meets more than {max} shapes under their placements"),
        );
    }
    crate::scene::recentre::recentre(&mut scene);
    scene
}

/// Declares the functions and the constants, so that any item may use any of them. A
/// function may call itself, directly or through others: a call is evaluated when it is met,
/// within the `call_depth` limit.
fn declare(cx: &mut Ctx, items: &[ast::Item]) {
    collect_functions(cx, items);
    for item in items {
        if let ast::Item::Let(l) = item {
            if let Some(first) = cx.declared.get(&l.name.name).copied() {
                dup(cx, "the constant", &l.name, first);
            } else {
                cx.declared.insert(l.name.name.clone(), l.name.span);
            }
        }
    }
}

/// Evaluates the constants, materials and blocks in order (refusing a second `camera`,
/// `render` or `scene` block); returns the `scene` item with the span of its keyword.
fn evaluate_items<'a>(
    cx: &mut Ctx,
    scene: &mut Scene,
    items: &'a [ast::Item],
) -> Option<(&'a ast::Item, Span)> {
    let mut seen_blocks: HashMap<&str, Span> = HashMap::new();
    let mut scene_item = None;
    for item in items {
        match item {
            ast::Item::Let(l) => {
                if cx.globals.contains_key(&l.name.name) {
                    continue;
                }
                if l.name.name == builtins::TIME {
                    cx.error(
                        Diagnostic::warning("W0013", "this constant hides the time `t`", l.name.span)
                            .with_label("a global constant named `t`")
                            .with_note(
                                "`t` is the time in seconds of an animation's frame; below this constant, every `t` reads the constant instead",
                            )
                            .with_help("give the constant another name"),
                    );
                }
                let reads = cx.time_reads;
                let mut v = cx.let_value(l);
                if let Some(spec) = &l.param {
                    v = params::declare(cx, scene, l, spec, v);
                }
                if let (true, Some(at)) = (cx.time_reads > reads, cx.last_time_read()) {
                    cx.timed_globals.insert(l.name.name.clone(), at);
                }
                cx.globals.insert(l.name.name.clone(), (v, l.name.span));
            }
            ast::Item::Material {
                name, kind, fields, ..
            } => materials::material(cx, scene, name, kind, fields),
            ast::Item::Block(b) => {
                if first_block(cx, &mut seen_blocks, b) {
                    block(cx, scene, b);
                }
            }
            ast::Item::Scene { span, .. } => {
                let keyword = Span {
                    end: span.start + 5,
                    ..*span
                };
                if let Some((_, first)) = scene_item {
                    cx.error(
                        Diagnostic::error("E0504", "more than one `scene` block", keyword)
                            .with_label("second scene")
                            .with_secondary(first, "first scene"),
                    );
                } else {
                    scene_item = Some((item, keyword));
                }
            }
            ast::Item::Fn(_) | ast::Item::Import { .. } | ast::Item::Error(_) => {}
        }
    }
    scene_item
}

/// Whether block `b` is the first of its kind (`light` blocks may repeat); a second
/// `camera` or `render` block is an error.
fn first_block(cx: &mut Ctx, seen: &mut HashMap<&str, Span>, b: &ast::Block) -> bool {
    if b.keyword.name == "light" {
        return true;
    }
    if let Some(first) = seen.get(b.keyword.name.as_str()) {
        cx.error(
            Diagnostic::error(
                "E0504",
                format!("more than one `{}` block", b.keyword.name),
                b.keyword.span,
            )
            .with_label("second block")
            .with_secondary(*first, "first block"),
        );
        return false;
    }
    let kind = if b.keyword.name == "camera" {
        "camera"
    } else {
        "render"
    };
    seen.insert(kind, b.keyword.span);
    true
}

/// Checks the functions no item called: a mistake in one is still reported.
fn check_uncalled_functions(cx: &mut Ctx) {
    let mut unchecked: Vec<(u32, String)> = cx
        .fns
        .iter()
        .filter(|(_, f)| !f.checked)
        .map(|(n, f)| (f.decl.span.start, n.clone()))
        .collect();
    unchecked.sort();
    for (_, name) in unchecked {
        cx.check_function(&name);
    }
}

/// The objects of the `scene` item (E0503 when there is none).
fn scene_objects(
    cx: &mut Ctx,
    scene_item: Option<(&ast::Item, Span)>,
    entry: FileId,
) -> Option<crate::scene::NodeId> {
    match scene_item {
        Some((ast::Item::Scene { stmts, span }, keyword)) => {
            cx.places.scene = Some(keyword);
            objects(cx, stmts, *span)
        }
        _ => {
            cx.error(
                Diagnostic::error(
                    "E0503",
                    "no `scene` block",
                    Span {
                        file: entry,
                        start: 0,
                        end: 0,
                    },
                )
                .with_help("add the objects to render: `scene { sphere(1) @ red; }`"),
            );
            None
        }
    }
}

fn collect_functions(cx: &mut Ctx, items: &[ast::Item]) {
    for item in items {
        let ast::Item::Fn(f) = item else { continue };
        if let Some(prev) = cx.fns.get(&f.name.name) {
            let first = prev.decl.name.span;
            dup(cx, "the function", &f.name, first);
            continue;
        }
        if let Some(b) = builtins::builtin(&f.name.name) {
            let name = &f.name.name;
            let sig = b.sigs.first().map(|s| builtins::signature(name, s));
            let mut d = Diagnostic::warning(
                "W0016",
                format!("this function `{name}` hides the built-in `{name}`"),
                f.name.span,
            )
            .with_label(format!(
                "calls to `{name}` in this file, and in files that import it, call this function"
            ))
            .with_note("files that do not see this one (a library it imports) keep the built-in");
            if let Some(sig) = sig {
                d = d.with_note(format!("the built-in is `{sig}`"));
            }
            cx.diags
                .push(d.with_help("rename the function to keep both in reach"));
        }
        let mut names: HashMap<&str, Span> = HashMap::new();
        let mut ok = true;
        for p in &f.params {
            if let Some(first) = names.insert(&p.name.name, p.name.span) {
                dup(cx, "the parameter", &p.name, first);
                ok = false;
            }
        }
        let params: Vec<Option<Type>> = f.params.iter().map(|p| cx.type_name(&p.ty)).collect();
        let ret = cx.type_name(&f.ret);
        ok &= params.iter().all(Option::is_some) && ret.is_some();
        cx.fns.insert(
            f.name.name.clone(),
            FnInfo {
                decl: Rc::new(f.clone()),
                params,
                ret,
                ok,
                checked: false,
            },
        );
    }
}

fn block(cx: &mut Ctx, scene: &mut Scene, b: &ast::Block) {
    match (b.keyword.name.as_str(), &b.kind) {
        ("camera", _) => {
            let f = eval::record(cx, &builtins::CAMERA, &b.fields, &b.keyword);
            cx.places.camera = Some(field_span(&b.fields, "position").unwrap_or(b.keyword.span));
            scene.camera = Camera {
                position: f["position"].v3(),
                look_at: f["look_at"].v3(),
                up: f["up"].v3(),
                fov: f["fov"].num(),
            };
            if scene.camera.position == scene.camera.look_at && !f["position"].is_abstract() {
                cx.error(
                    Diagnostic::error(
                        "E0400",
                        "the camera looks at its own position",
                        b.keyword.span,
                    )
                    .with_label("`position` and `look_at` are equal"),
                );
            }
        }
        ("render", _) => {
            let f = eval::record(cx, &builtins::RENDER, &b.fields, &b.keyword);
            cx.settings_given = b
                .fields
                .iter()
                .map(|f| (f.name.name.clone(), f.value.span))
                .collect();
            let int = |k: &str| f[k].num() as u32;
            scene.settings = Settings {
                width: int("width"),
                height: int("height"),
                aa: int("aa"),
                max_steps: int("max_steps"),
                epsilon: f["epsilon"].num(),
                footprint: false,
                max_depth: int("max_depth"),
                max_dist: f["max_dist"].num(),
                relaxation: f["relaxation"].num(),
                background: f["background"].v3(),
                method: Method::Auto,
                occlusion: f["occlusion"].num(),
                fog: f["fog"].num(),
                // Left out, the fog takes the background's colour.
                fog_color: field_span(&b.fields, "fog_color").map(|_| f["fog_color"].v3()),
                glow: f["glow"].num(),
                glow_color: f["glow_color"].v3(),
                exposure: f["exposure"].num(),
                tonemap: match &f["tonemap"] {
                    Value::Str(s) => Tonemap::from_name(s).unwrap_or_default(),
                    _ => Tonemap::None,
                },
                tonemap_why: None,
                path: false,
                samples: int("samples"),
                bounces: int("bounces"),
                first_sample: 0,
            };
            if let Value::Str(name) = &f["method"] {
                scene.settings.set_method(name);
            }
            if let (true, Some(at)) = (
                scene.settings.path && scene.settings.glow > 0.0,
                field_span(&b.fields, "glow"),
            ) {
                cx.error(
                    Diagnostic::error("E0400", "the path tracer has no glow of marching steps", at)
                        .with_label("a glow is asked for here")
                        .with_note("`glow` adds light along a camera ray's march, which `method: \"path\"` does not take")
                        .with_help("leave `glow` out, or use `method: \"auto\"`"),
                );
            }
            if let (Value::Float(fps), Value::Float(duration)) = (&f["fps"], &f["duration"]) {
                scene.animation.fps = *fps;
                scene.animation.duration = *duration;
                let max = cx.limits.get(Limit::Frames);
                let frames = scene.animation.frames();
                if frames > max {
                    let at = field_span(&b.fields, "duration").unwrap_or(b.keyword.span);
                    cx.limit_to(
                        Limit::Frames,
                        at,
                        format!("the animation has {frames} frames, more than {max}"),
                        frames,
                    );
                }
            }
        }
        (_, Some(kind)) => lights::light(cx, scene, b, kind),
        _ => {}
    }
}

/// The span of the value of the field `name` of a block, when it is given.
pub(super) fn field_span(fields: &[ast::Field], name: &str) -> Option<Span> {
    fields
        .iter()
        .find(|f| f.name.name == name)
        .map(|f| f.value.span)
}

/// Evaluates the scene statements; returns the union of all objects.
fn objects(cx: &mut Ctx, stmts: &[ast::Stmt], span: Span) -> Option<crate::scene::NodeId> {
    let mut out = Vec::new();
    let mark = cx.locals_mark();
    stmts_into(cx, stmts, &mut out);
    cx.truncate_locals(mark);
    match out.len() {
        0 if crate::diagnostics::has_errors(&cx.diags) => None,
        0 => {
            cx.error(
                Diagnostic::warning(
                    "W0001",
                    "the scene has no objects",
                    Span {
                        end: span.start + 5,
                        ..span
                    },
                )
                .with_label("renders only the background"),
            );
            None
        }
        1 => Some(out[0]),
        _ => match cx.add_node(
            Node::Combine {
                op: Combine::Union,
                children: out,
            },
            span,
        ) {
            Value::Shape(id) => Some(id),
            _ => None,
        },
    }
}

fn stmts_into(cx: &mut Ctx, stmts: &[ast::Stmt], out: &mut Vec<crate::scene::NodeId>) {
    for s in stmts {
        match s {
            ast::Stmt::Let(l) => {
                let v = cx.let_value(l);
                cx.push_local(&l.name.name, v);
            }
            ast::Stmt::Object(e) => match cx.expr(e) {
                // Already reported, or unknown only because of an earlier error.
                Value::Unknown(Type::Shape) => {}
                Value::Shape(id) => {
                    let max = cx.limits.count(Limit::Objects);
                    if out.len() >= max {
                        cx.limit(
                            Limit::Objects,
                            e.span,
                            format!("the scene has more than {max} objects"),
                        );
                        return;
                    }
                    out.push(id)
                }
                Value::Error => {}
                other => {
                    let mut d =
                        Diagnostic::error("E0300", "a scene statement must be a shape", e.span)
                            .with_label(format!(
                                "this is `{}`",
                                other.ty().map_or("?".into(), |t| t.to_string())
                            ));
                    if other.ty().and_then(Type::elem) == Some(Type::Shape) {
                        d = d.with_help("combine the list's shapes into one: `union(...)`");
                    }
                    if other.ty() == Some(Type::Profile) {
                        d = d.with_help(
                            "a profile is flat: make it a shape with `extrude(profile, height)` or `revolve(profile)`",
                        );
                    }
                    cx.error(d)
                }
            },
            ast::Stmt::For {
                var,
                from,
                to,
                body,
                ..
            } => for_loop(cx, var, from, to, body, out),
            ast::Stmt::Error(_) => {}
        }
    }
}

fn for_loop(
    cx: &mut Ctx,
    var: &ast::Ident,
    from: &ast::Expr,
    to: &ast::Expr,
    body: &[ast::Stmt],
    out: &mut Vec<crate::scene::NodeId>,
) {
    let bound = |e: &ast::Expr, cx: &mut Ctx| match cx.expr(e) {
        Value::Int(i) => Some(i),
        Value::Error => None,
        other => {
            let mut d = Diagnostic::error("E0300", "loop bounds must be `int`", e.span).with_label(
                format!(
                    "this is `{}`",
                    other.ty().map_or("?".into(), |t| t.to_string())
                ),
            );
            if other.ty() == Some(Type::Float) {
                d = d.with_help(eval::WHOLE_NUMBER_HELP);
            }
            cx.error(d);
            None
        }
    };
    let (Some(a), Some(b)) = (bound(from, cx), bound(to, cx)) else {
        return;
    };
    let max = cx.limits.get(Limit::Objects);
    if b > a && b.saturating_sub(a) as u64 > max {
        let runs = b.saturating_sub(a) as u64;
        cx.limit_to(
            Limit::Objects,
            to.span,
            format!("the loop runs {runs} times, more than {max}"),
            runs,
        );
        return;
    }
    for i in a..b {
        if !cx.burn(var.span) {
            return;
        }
        let mark = cx.locals_mark();
        cx.push_local(&var.name, Value::Int(i));
        let errors_before = cx.diags.len();
        stmts_into(cx, body, out);
        cx.truncate_locals(mark);
        // One report per mistake, not one per iteration.
        if cx.diags.len() > errors_before {
            break;
        }
    }
}

#[cfg(test)]
mod tests;
