//! Values built and read by expressions: tuples (vectors), fields of values and records, and
//! `@ material` (paint).

use super::Ctx;
use crate::check::field;
use crate::check::suggest::closest;
use crate::check::types::{Type, Value};
use crate::diagnostics::Diagnostic;
use crate::scene::Node;
use crate::span::Span;
use crate::syntax::ast::*;

impl Ctx<'_> {
    pub(super) fn tuple(&mut self, items: &[Expr], span: Span) -> Value {
        let vals: Vec<Value> = items.iter().map(|i| self.expr(i)).collect();
        if !(2..=3).contains(&vals.len()) {
            self.error(
                Diagnostic::error(
                    "E0300",
                    format!("a vector has 2 or 3 components, this has {}", vals.len()),
                    span,
                )
                .with_label("not a vec2 or vec3"),
            );
            return Value::Error;
        }
        let mut nums = Vec::new();
        let mut abstract_ = false;
        for (v, item) in vals.iter().zip(items) {
            match v.clone().coerce(Type::Float) {
                Some(Value::Float(f)) => nums.push(f),
                Some(_) => abstract_ = true,
                None => {
                    self.error(
                        Diagnostic::error("E0300", "vector components must be numbers", item.span)
                            .with_label(format!("this is `{}`", v.type_name())),
                    );
                    return Value::Error;
                }
            }
        }
        let ty = if vals.len() == 2 {
            Type::Vec2
        } else {
            Type::Vec3
        };
        if abstract_ {
            return Value::Unknown(ty);
        }
        if nums.len() == 2 {
            Value::Vec2([nums[0], nums[1]])
        } else {
            Value::Vec3([nums[0], nums[1], nums[2]])
        }
    }

    pub(super) fn field(&mut self, v: Value, name: &Ident) -> Value {
        let dims = match v.ty() {
            Some(Type::Vec2) => 2,
            Some(Type::Vec3) => 3,
            _ => 0,
        };
        // Swizzles (`p.xz`, `v.zyx`), and components of per-point vectors.
        if dims > 0 && (name.name.len() > 1 || field::is_point(&v)) {
            if let Some(idx) = field::swizzle(&name.name, dims) {
                if let Some(c) = field::comps(&v) {
                    let picked: Vec<_> = idx.iter().map(|&i| c[i].clone()).collect();
                    if field::is_point(&v) {
                        return field::point(picked);
                    }
                    let k: Vec<f64> = idx.iter().map(|&i| v.components()[i]).collect();
                    return match k.len() {
                        1 => Value::Float(k[0]),
                        2 => Value::Vec2([k[0], k[1]]),
                        _ => Value::Vec3([k[0], k[1], k[2]]),
                    };
                }
                return Value::Unknown(match idx.len() {
                    1 => Type::Float,
                    2 => Type::Vec2,
                    _ => Type::Vec3,
                });
            }
        }
        let idx = match name.name.as_str() {
            "x" | "r" => 0,
            "y" | "g" => 1,
            "z" | "b" => 2,
            _ => 3,
        };
        let dims = match v.ty() {
            None => return Value::Error,
            Some(Type::Vec2) => 2,
            Some(Type::Vec3) => 3,
            Some(t) => {
                self.error(
                    Diagnostic::error(
                        "E0210",
                        format!("`{t}` has no component `{}`", name.name),
                        name.span,
                    )
                    .with_label("components exist only on vec2 and vec3"),
                );
                return Value::Error;
            }
        };
        if idx >= dims {
            let mut d = Diagnostic::error(
                "E0210",
                format!("unknown vector component `{}`", name.name),
                name.span,
            )
            .with_label(if dims == 2 {
                "a vec2 has `x` and `y`"
            } else {
                "a vec3 has `x`, `y` and `z`"
            });
            if dims == 2 && field::is_point(&v) && self.planes.last() == Some(&true) {
                d = d
                    .with_note(
                        "inside `profile { … }` the point `p` is a vec2: a point of the plane",
                    )
                    .with_help("a field of points in space, with `p.z`, is written `field { … }`");
            }
            self.error(d);
            return Value::Error;
        }
        match v {
            Value::Vec2(a) => Value::Float(a[idx]),
            Value::Vec3(a) => Value::Float(a[idx]),
            _ => Value::Unknown(Type::Float),
        }
    }

    pub(super) fn paint(&mut self, v: Value, vspan: Span, m: &Ident, span: Span) -> Value {
        let mat = match self.material_ids.get(&m.name) {
            Some((id, _)) => Some(*id),
            None => {
                let mut d =
                    Diagnostic::error("E0212", format!("unknown material `{}`", m.name), m.span)
                        .with_label("no material of this name");
                if let Some(s) = closest(&m.name, self.material_ids.keys().map(String::as_str)) {
                    d = d.with_help(format!("did you mean `{s}`?"));
                } else {
                    d = d.with_help(format!(
                        "declare it: `material {} = phong {{ color: (0.8, 0.8, 0.8) }}`",
                        m.name
                    ));
                }
                self.error(d);
                None
            }
        };
        match (v, mat) {
            (Value::Shape(child), Some(material)) => {
                self.add_node(Node::Paint { material, child }, span)
            }
            (Value::Error, _) | (Value::Shape(_), None) => Value::Error,
            (Value::Unknown(Type::Shape), _) => Value::Unknown(Type::Shape),
            (other, _) => {
                self.error(
                    Diagnostic::error("E0300", "only shapes can be given a material", vspan)
                        .with_label(format!("this is `{}`", other.type_name())),
                );
                Value::Error
            }
        }
    }
}
