//! Lists in constant evaluation: literals, comprehensions (with their conditions) and
//! indexing, each list's length held to its limit.

use super::bind::WHOLE_NUMBER_HELP;
use super::Ctx;
use crate::check::field;
use crate::check::types::{Type, Value};
use crate::diagnostics::Diagnostic;
use crate::limits::Limit;
use crate::span::Span;
use crate::syntax::ast::*;
impl Ctx<'_> {
    /// `[a, b, c]`: the elements' one type (ints among floats become floats).
    pub(super) fn list(&mut self, items: &[Expr], span: Span) -> Value {
        if items.is_empty() {
            self.error(
                Diagnostic::error("E0300", "an empty list has no element type", span)
                    .with_label("`[]` is a list of nothing in particular")
                    .with_help("a list that may be empty is built by a comprehension, such as `[for i in 0..n { sphere(1) }]`"),
            );
            return Value::Error;
        }
        if !self.list_length(items.len(), span) {
            return Value::Error;
        }
        let vals: Vec<Value> = items.iter().map(|i| self.expr(i)).collect();
        let mut elem: Option<(Type, Span)> = None;
        for (v, item) in vals.iter().zip(items) {
            let Some(t) = v.ty() else { continue };
            match elem {
                None => elem = Some((t, item.span)),
                Some((e, _)) if t.fits(e) => {}
                Some((e, at)) if e.fits(t) => elem = Some((t, at)),
                Some((e, at)) => {
                    self.error(
                        Diagnostic::error(
                            "E0300",
                            "the elements of a list have different types",
                            item.span,
                        )
                        .with_label(format!("this is `{t}`"))
                        .with_secondary(at, format!("this is `{e}`"))
                        .with_note("every element of a list has one type"),
                    );
                    return Value::Error;
                }
            }
        }
        let Some((elem, at)) = elem else {
            return Value::Error;
        };
        self.make_list(elem, vals, at)
    }

    /// A list of `vals`, each converted to `elem`; `Unknown` when any is not computed.
    pub(super) fn make_list(&mut self, elem: Type, vals: Vec<Value>, at: Span) -> Value {
        let Some(ty) = Type::list(elem) else {
            let d = if elem == Type::ColourField {
                // A `field` of a vec3 is a colour, where a list of shapes was likely meant.
                Diagnostic::error("E0300", "a colour field cannot be a list's element", at)
                    .with_label("this `field` is of a vec3: a `color_field`, a material's `color`")
                    .with_note("a list holds ints, floats, bools, vectors, angles, strings, shapes, profiles or paths")
                    .with_help("a `field` is a shape when its body is a float, the distance: `field { length(p) - 1 }`; a colour field goes in a material's `color`")
            } else {
                Diagnostic::error("E0300", "a list's elements cannot be lists", at)
                    .with_label(format!("this is `{elem}`"))
                    .with_note("lists do not nest")
            };
            self.error(d);
            return Value::Error;
        };
        if vals.contains(&Value::Error) {
            return Value::Error;
        }
        if vals.iter().any(Value::is_abstract) {
            return Value::Unknown(ty);
        }
        let items: Option<Vec<Value>> = vals.into_iter().map(|v| v.coerce(elem)).collect();
        match (items, ty) {
            (Some(items), Type::List(e)) => Value::List(e, items.into()),
            _ => Value::Error,
        }
    }

    /// Whether a list of `n` elements is within the `objects` limit (reported once if not).
    pub(super) fn list_length(&mut self, n: usize, span: Span) -> bool {
        let max = self.limits.count(Limit::Objects);
        if n <= max {
            return true;
        }
        self.limit_to(
            Limit::Objects,
            span,
            format!("a list has {n} elements, more than {max}"),
            n as u64,
        );
        false
    }

    /// `[for var in from..to { body }]`: the body's value for each int from `from` up to
    /// `to`, excluded. The body is checked once on its own (for the element type, also of an
    /// empty list) and then evaluated for each value.
    pub(super) fn comprehension(
        &mut self,
        var: &Ident,
        from: &Expr,
        to: &Expr,
        cond: Option<&Expr>,
        body: &Body,
    ) -> Value {
        let bound = |cx: &mut Self, e: &Expr| match cx.expr(e) {
            Value::Int(i) => Ok(Some(i)),
            Value::Unknown(Type::Int) => Ok(None),
            Value::Error => Err(()),
            v if field::is_point(&v) => {
                cx.per_point(
                    "the bounds of a range must be constants: a list's length cannot vary from point to point".into(),
                    e.span,
                );
                Err(())
            }
            other => {
                let mut d =
                    Diagnostic::error("E0300", "the bounds of a range must be `int`", e.span)
                        .with_label(format!("this is `{}`", other.type_name()));
                if other.ty() == Some(Type::Float) {
                    d = d.with_help(WHOLE_NUMBER_HELP);
                }
                cx.error(d);
                Err(())
            }
        };
        let (a, b) = (bound(self, from), bound(self, to));
        let mark = self.locals.len();
        self.locals
            .push((var.name.clone(), Value::Unknown(Type::Int)));
        let before = self.diags.len();
        let shape = self.dry(|cx| {
            if let Some(c) = cond {
                cx.condition(c);
            }
            cx.body(body)
        });
        self.locals.truncate(mark);
        let (Ok(a), Ok(b)) = (a, b) else {
            return Value::Error;
        };
        let Some(elem) = shape.ty() else {
            return Value::Error;
        };
        if self.diags[before..].iter().any(Diagnostic::is_error) {
            return Value::Error;
        }
        let (Some(a), Some(b)) = (a, b) else {
            return self.make_list(elem, vec![Value::Unknown(elem)], body.value.span);
        };
        if self.dry > 0 {
            return self.make_list(elem, vec![Value::Unknown(elem)], body.value.span);
        }
        let n = b.saturating_sub(a).max(0);
        if !self.list_length(n as usize, to.span) {
            return Value::Error;
        }
        let mut vals = Vec::with_capacity(n as usize);
        for i in a..b {
            if !self.burn(var.span) {
                return Value::Error;
            }
            self.locals.push((var.name.clone(), Value::Int(i)));
            let errors = self.diags.len();
            if let Some(c) = cond {
                match self.condition(c) {
                    Some(true) => {}
                    Some(false) => {
                        self.locals.truncate(mark);
                        continue;
                    }
                    None => {
                        self.locals.truncate(mark);
                        return Value::Error;
                    }
                }
            }
            let v = self.body(body);
            self.locals.truncate(mark);
            // One report per mistake, not one per element.
            if self.diags[errors..].iter().any(Diagnostic::is_error) {
                return Value::Error;
            }
            vals.push(v);
        }
        self.make_list(elem, vals, body.value.span)
    }

    /// `xs[i]`: the element at `i`, counted from 0; an index outside the list is E0407.
    pub(super) fn index(&mut self, xs: &Expr, i: &Expr) -> Value {
        let (list, at) = (self.expr(xs), self.expr(i));
        let elem = match list.ty() {
            None => None,
            Some(Type::List(e)) => Some(*e),
            Some(t) => {
                self.error(
                    Diagnostic::error("E0300", format!("`{t}` cannot be indexed"), xs.span)
                        .with_label(format!("this is `{t}`, not a list"))
                        .with_help(if matches!(t, Type::Vec2 | Type::Vec3) {
                            "a vector's components are `v.x`, `v.y` and `v.z`"
                        } else {
                            "only lists, such as `[a, b, c]`, are indexed with `xs[i]`"
                        }),
                );
                return Value::Error;
            }
        };
        match at.ty() {
            None | Some(Type::Int) => {}
            Some(t) => {
                let mut d = Diagnostic::error(
                    "E0300",
                    format!("a list index must be `int`, found `{t}`"),
                    i.span,
                )
                .with_label(format!("this is `{t}`"));
                if t == Type::Float {
                    d = d.with_help(WHOLE_NUMBER_HELP);
                }
                self.error(d);
                return Value::Error;
            }
        }
        let Some(elem) = elem else {
            return Value::Error;
        };
        match (&list, &at) {
            (Value::List(_, items), Value::Int(k)) => {
                match usize::try_from(*k).ok().and_then(|k| items.get(k)) {
                    Some(v) => v.clone(),
                    None => {
                        let n = items.len();
                        let elements = if n == 1 { "element" } else { "elements" };
                        let note = match n {
                            0 => "the list is empty: it has no index".to_string(),
                            _ => format!("the indices of this list are 0 to {}", n - 1),
                        };
                        self.error(
                            Diagnostic::error(
                                "E0407",
                                format!("index {k} is outside a list of {n} {elements}"),
                                i.span,
                            )
                            .with_label(format!("this is {k}"))
                            .with_secondary(xs.span, format!("this list has {n} {elements}"))
                            .with_note(note),
                        );
                        Value::Error
                    }
                }
            }
            (Value::Error, _) | (_, Value::Error) => Value::Error,
            _ => Value::Unknown(elem),
        }
    }
}
