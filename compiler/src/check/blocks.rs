//! The top-level blocks (`camera`, `render`, `animate`, …) and the scene's objects: its
//! statements and `for` loops, each object a node of the scene.

use super::eval::{self, Ctx};
use super::types::{Type, Value};
use super::{builtins, field_span, lights};
use crate::diagnostics::Diagnostic;
use crate::limits::Limit;
use crate::scene::{Camera, Combine, Method, Node, Scene, Settings, Tonemap};
use crate::span::Span;
use crate::syntax::ast;

pub(super) fn block(cx: &mut Ctx, scene: &mut Scene, b: &ast::Block) {
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

/// Evaluates the scene statements; returns the union of all objects.
pub(super) fn objects(
    cx: &mut Ctx,
    stmts: &[ast::Stmt],
    span: Span,
) -> Option<crate::scene::NodeId> {
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
                            .with_label(format!("this is `{}`", other.type_name()));
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
            let mut d = Diagnostic::error("E0300", "loop bounds must be `int`", e.span)
                .with_label(format!("this is `{}`", other.type_name()));
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
