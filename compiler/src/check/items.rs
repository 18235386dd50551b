//! The items of a program: declared (constants, functions and their parameters, once
//! each), then evaluated in order, the top-level blocks once each, the scene's objects last;
//! functions never called are reported.

use super::blocks::{block, objects};
use super::eval::{Ctx, FnInfo};
use super::types::Type;
use super::{builtins, dup, materials, params};
use crate::diagnostics::Diagnostic;
use crate::limits::Limit;
use crate::scene::{Material, Scene, Tonemap};
use crate::span::{FileId, Span};
use crate::syntax::ast;
use std::collections::HashMap;
use std::rc::Rc;

/// Checks the items of the entry file, pass by pass: declarations (functions, recursion,
/// constants, materials), the items in order (constants, materials, blocks), the functions
/// never called, then the scene's objects.
pub(super) fn check_items(cx: &mut Ctx, items: &[ast::Item], entry: FileId) -> Scene {
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
