//! Parameters: `param name = default [in lo..hi [step s] | in [choices]] ["description"];`.
//! A parameter is a global constant whose value a user may set from outside the file
//! (`--param name=value`, carried with the run's [`crate::Limits`]); the value is refused,
//! located at the declaration, when it is not of the default's type or not among the values
//! the parameter accepts, before any work is done. A value offered instead
//! ([`crate::Limits::offer_param`], the viewer's panel) is taken where it is accepted and
//! passed over otherwise.

use super::eval::Ctx;
use super::types::Value;
use crate::diagnostics::Diagnostic;
use crate::scene::params::{Accepts, ParamValue, Parameter};
use crate::scene::Scene;
use crate::span::{FileId, Span};
use crate::syntax::ast::{Item, Let, ParamSpec};

/// Checks the parameter `l` whose default evaluated to `default`, records it in `scene`, and
/// returns the value the scene is checked with.
pub fn declare(
    cx: &mut Ctx,
    scene: &mut Scene,
    l: &Let,
    spec: &ParamSpec,
    default: Value,
) -> Value {
    let Some(def) = param_value(&default) else {
        if default != Value::Error {
            cx.error(
                Diagnostic::error(
                    "E0300",
                    "a parameter is a number, an int, a bool or a string",
                    l.value.span,
                )
                .with_label(format!("this is `{}`", default.type_name()))
                .with_help("make it a `let` constant, or give it a number, a bool or a string"),
            );
        }
        return Value::Error;
    };
    let Some(accepts) = accepts(cx, spec, &def, l) else {
        return Value::Error;
    };
    let doc = match &spec.doc {
        None => String::new(),
        Some(e) => match cx.expr(e) {
            Value::Str(s) => s.to_string(),
            Value::Error => return Value::Error,
            other => {
                cx.error(
                    Diagnostic::error("E0300", "a parameter's description is a string", e.span)
                        .with_label(format!("this is `{}`", other.type_name())),
                );
                return Value::Error;
            }
        },
    };
    let mut p = Parameter {
        name: l.name.name.clone(),
        value: def.clone(),
        default: def,
        accepts,
        doc,
        span: l.name.span,
    };
    if !p.accepts(&p.default) {
        cx.error(
            Diagnostic::error(
                "E0400",
                format!(
                    "the default of `{}` is outside the values it accepts",
                    p.name
                ),
                l.value.span,
            )
            .with_label(format!("this is {}", p.default))
            .with_note(format!("`{}` accepts {}", p.name, p.accepts)),
        );
        return Value::Error;
    }
    let offered = cx.limits.offered().iter().rev().find(|(n, _)| *n == p.name);
    let offered = offered
        .and_then(|(_, text)| p.default.parse_like(text))
        .filter(|v| p.accepts(v));
    let given = given(cx).into_iter().rev().find(|(n, _)| *n == p.name);
    if let Some(v) = offered {
        p.value = v;
    } else if let Some((_, text)) = given {
        match p.default.parse_like(&text) {
            None => {
                cx.error(
                    Diagnostic::error(
                        "E0300",
                        format!("`{}` is not {}", spelled(cx, &p.name, &text), a(p.default.type_name())),
                        l.name.span,
                    )
                    .with_label(format!("`{}` is {} parameter: its default says so", p.name, a(p.default.type_name())))
                    .with_note(format!("it accepts {}", p.accepts))
                    .with_help("a default written with a point, such as `40.0`, makes a number that need not be whole"),
                );
                return Value::Error;
            }
            Some(v) if !p.accepts(&v) => {
                cx.error(
                    Diagnostic::error(
                        "E0400",
                        format!(
                            "`{}` is outside the values `{}` accepts",
                            spelled(cx, &p.name, &text),
                            p.name
                        ),
                        l.name.span,
                    )
                    .with_label(format!("`{}` accepts {}", p.name, p.accepts)),
                );
                return Value::Error;
            }
            Some(v) => p.value = v,
        }
    }
    let v = value(&p.value);
    scene.params.push(p);
    v
}

/// Refuses values given for parameters the file does not declare, naming those it does.
pub fn unknown(cx: &mut Ctx, items: &[Item], entry: FileId) {
    let names: Vec<&str> = items
        .iter()
        .filter_map(|i| match i {
            Item::Let(l) if l.param.is_some() => Some(l.name.name.as_str()),
            _ => None,
        })
        .collect();
    for (name, text) in given(cx) {
        if names.contains(&name.as_str()) {
            continue;
        }
        let declared: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
        let note = if declared.is_empty() {
            "the scene declares no parameters (`param name = value;`)".to_string()
        } else {
            format!("its parameters: {}", declared.join(", "))
        };
        cx.error(
            Diagnostic::error(
                "E0200",
                format!(
                    "`{}`: the scene has no parameter `{name}`",
                    spelled(cx, &name, &text)
                ),
                Span {
                    file: entry,
                    start: 0,
                    end: 0,
                },
            )
            .with_note(note),
        );
    }
}

/// A value given for a parameter, as the caller wrote it (`--param name=value`, or Python's
/// `params={"name": value}`).
fn spelled(cx: &Ctx, name: &str, text: &str) -> String {
    match cx.limits.spelling() {
        crate::limits::Spelling::Flags => format!("--param {name}={text}"),
        crate::limits::Spelling::Parameters => format!("params={{\"{name}\": {text}}}"),
    }
}

/// The values given from outside, with the limits of the run.
fn given(cx: &mut Ctx) -> Vec<(String, String)> {
    cx.limits.params().to_vec()
}

/// What a parameter accepts, from its `in` clause; `None` after an error.
fn accepts(cx: &mut Ctx, spec: &ParamSpec, def: &ParamValue, l: &Let) -> Option<Accepts> {
    if let Some((lo, hi)) = &spec.range {
        let num = |cx: &mut Ctx, e: &crate::syntax::ast::Expr, what: &str| match cx.expr(e) {
            Value::Int(i) => Some(i as f64),
            Value::Float(x) => Some(x),
            Value::Error => None,
            other => {
                cx.error(
                    Diagnostic::error("E0300", format!("a parameter's {what} is a number"), e.span)
                        .with_label(format!("this is `{}`", other.type_name())),
                );
                None
            }
        };
        let (a, b) = (num(cx, lo, "lower end")?, num(cx, hi, "upper end")?);
        let step = match &spec.step {
            Some(e) => Some(num(cx, e, "step")?),
            None => None,
        };
        if def.number().is_none() {
            cx.error(
                Diagnostic::error(
                    "E0300",
                    format!(
                        "a range is for a number; `{}` is a {}",
                        l.name.name,
                        def.type_name()
                    ),
                    lo.span,
                )
                .with_secondary(l.value.span, "the default says its type"),
            );
            return None;
        }
        if a > b || step.is_some_and(|s| s <= 0.0) {
            let why = if a > b {
                "its lower end is above its upper end"
            } else {
                "its step is not above 0"
            };
            cx.error(Diagnostic::error(
                "E0400",
                format!("this range is empty: {why}"),
                lo.span.join(hi.span),
            ));
            return None;
        }
        return Some(Accepts::Range { lo: a, hi: b, step });
    }
    if let Some(list) = &spec.choices {
        return match cx.expr(list) {
            Value::List(_, items)
                if matches!(def, ParamValue::Str(_))
                    && items.iter().all(|v| matches!(v, Value::Str(_))) =>
            {
                Some(Accepts::Choices(
                    items
                        .iter()
                        .map(|v| match v {
                            Value::Str(s) => s.to_string(),
                            _ => String::new(),
                        })
                        .collect(),
                ))
            }
            Value::Error => None,
            other => {
                cx.error(
                    Diagnostic::error("E0300", "a parameter's choices are a list of strings, and its default one of them", list.span)
                        .with_label(format!("this is `{}`", other.type_name()))
                        .with_secondary(l.value.span, format!("the default is a {}", def.type_name()))
                        .with_help("write `param style = \"round\" in [\"round\", \"square\"];`, or `in lo..hi` for a number"),
                );
                None
            }
        };
    }
    Some(Accepts::Any)
}

fn param_value(v: &Value) -> Option<ParamValue> {
    Some(match v {
        Value::Float(x) => ParamValue::Float(*x),
        Value::Int(i) => ParamValue::Int(*i),
        Value::Bool(b) => ParamValue::Bool(*b),
        Value::Str(s) => ParamValue::Str(s.to_string()),
        _ => return None,
    })
}

fn value(p: &ParamValue) -> Value {
    match p {
        ParamValue::Float(x) => Value::Float(*x),
        ParamValue::Int(i) => Value::Int(*i),
        ParamValue::Bool(b) => Value::Bool(*b),
        ParamValue::Str(s) => Value::Str(s.as_str().into()),
    }
}

/// A type's name with its article: "a float", "an int".
fn a(ty: &str) -> String {
    let article = if ty.starts_with(['a', 'e', 'i', 'o', 'u']) {
        "an"
    } else {
        "a"
    };
    format!("{article} {ty}")
}
