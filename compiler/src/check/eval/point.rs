//! Values that depend on the point `p` in constant evaluation: the operations and
//! built-ins per-point values allow, and `field { … }` blocks lowered to field shapes.

use super::bind::type_mismatch;
use super::{arg_span, Ctx};
use crate::check::builtins::{self, NORMAL};
use crate::check::field;
use crate::check::ops;
use crate::check::types::{Type, Value};
use crate::diagnostics::Diagnostic;
use crate::scene::Node;
use crate::span::Span;
use crate::syntax::ast::*;

impl Ctx<'_> {
    /// E0410: a per-point value where a constant is needed, or an operation per-point values
    /// do not support.
    pub(super) fn per_point(&mut self, msg: String, at: Span) -> Value {
        let word = self.word();
        self.error(
            Diagnostic::error("E0410", msg, at)
                .with_label("this depends on the point `p`")
                .with_note(format!(
                    "inside `{word} {{ … }}` what depends on `p` is computed per point; everything else is a constant computed once"
                )),
        );
        Value::Error
    }

    /// `profile` inside the body of a profile, else `field` (for messages).
    pub(super) fn word(&self) -> &'static str {
        if self.planes.last() == Some(&true) {
            "profile"
        } else {
            "field"
        }
    }

    /// `a op b` where an operand is per-point.
    pub(super) fn point_binary(
        &mut self,
        op: BinOp,
        a: (&Value, Span),
        b: (&Value, Span),
        span: Span,
    ) -> Value {
        let (Some(ta), Some(tb)) = (a.0.ty(), b.0.ty()) else {
            return Value::Error;
        };
        let Some(ty) = ops::binary_type(op, ta, tb) else {
            let err = ops::OpError::Types(format!(
                "`{}` cannot be applied to `{ta}` and `{tb}`",
                op.symbol()
            ));
            return self.op_error(err, op, a, b, span);
        };
        // A function body checked on its own: types only.
        if a.0.is_abstract() || b.0.is_abstract() {
            return if a.0 == &Value::Error || b.0 == &Value::Error {
                Value::Error
            } else {
                Value::Unknown(if ty == Type::Angle { Type::Float } else { ty })
            };
        }
        match field::binary(op, a.0, b.0, self.word()) {
            Ok(v) => v,
            Err(e) => {
                let at = if field::is_point(a.0) { a.1 } else { b.1 };
                let v = self.per_point(e.to_string(), at);
                let word = self.word();
                if let Some(d) = self.diags.last_mut() {
                    d.help = Some(format!(
                        "a {word} is continuous: combine values with `min`, `max`, `clamp`, `mix` or `smoothstep`"
                    ));
                }
                v
            }
        }
    }

    /// A builtin called with per-point arguments.
    pub(super) fn point_builtin(
        &mut self,
        b: &builtins::Builtin,
        sig: &builtins::Sig,
        vals: &[Value],
        at: Span,
    ) -> Value {
        if vals.iter().any(Value::is_abstract) {
            return if vals.contains(&Value::Error) {
                Value::Error
            } else {
                Value::Unknown(sig.ret)
            };
        }
        match field::builtin(b.name, vals) {
            Some(v) => v,
            None => self.per_point(
                format!("`{}` needs values known at compile time", b.name),
                at,
            ),
        }
    }

    /// `field [(lipschitz: L)] { body }`: the body evaluated with `p` the point, its value
    /// (a float of the point) the distance of a new field shape. With `plane` (`profile {
    /// … }`), `p` is a point of the plane (a vec2) and the value a profile's distance.
    pub(super) fn field_block(
        &mut self,
        args: &[Arg],
        body: &Body,
        plane: bool,
        span: Span,
    ) -> Value {
        let word = if plane { "profile" } else { "field" };
        let lipschitz = match self.field_lipschitz(args, word) {
            Ok(l) => l,
            Err(v) => return v,
        };
        self.fields += 1;
        let owner = self.fields;
        let (v, normal_read) = self.field_body(body, plane, owner);
        let distance = if plane { Type::Profile } else { Type::Shape };
        // A float body is a distance (a shape, or a profile), a vec3 body a colour (a colour
        // field; not of the plane).
        if plane && v.ty().is_some_and(|t| !t.fits(Type::Float)) {
            let ty = v.type_name();
            let mut d = Diagnostic::error(
                "E0300",
                format!("the body of `profile` is a `{ty}`, not a float"),
                body.value.span,
            )
            .with_label(format!("this is `{ty}`"))
            .with_note("a profile's body is its distance at the point `p` of the plane (a vec2)");
            if v.ty() == Some(Type::Vec3) {
                d = d.with_help(
                    "a colour field is a formula of a point in space: write it `field { … }`",
                );
            }
            self.error(d);
            return Value::Error;
        }
        let (comps, colour) = match &v {
            Value::Error => return Value::Error,
            Value::Unknown(Type::Float | Type::Int) => return Value::Unknown(distance),
            Value::Unknown(Type::Vec3) => return Value::Unknown(Type::ColourField),
            Value::Int(_) | Value::Float(_) | Value::Point(_)
                if v.ty().is_some_and(|t| t.fits(Type::Float)) =>
            {
                (field::comps(&v).unwrap_or_default(), false)
            }
            Value::Vec3(_) | Value::Point(_) if v.ty() == Some(Type::Vec3) => {
                (field::comps(&v).unwrap_or_default(), true)
            }
            other => {
                self.error(
                    Diagnostic::error(
                        "E0300",
                        format!(
                            "the body of `field` is a `{}`, not a float or a vec3",
                            other.type_name()
                        ),
                        body.value.span,
                    )
                    .with_label(format!("this is `{}`", other.type_name()))
                    .with_note(
                        "a field's body is its distance at the point `p` (a float), or, for a \
                         material's colour, its colour there (a vec3)",
                    ),
                );
                return Value::Error;
            }
        };
        if let Some(at) = normal_read.filter(|_| !colour && field::reads_normal(&comps)) {
            self.error(
                Diagnostic::error(
                    "E0410",
                    "`n`, the surface normal, exists only in a colour field",
                    at,
                )
                .with_label("read in a field whose body is a distance")
                .with_note(
                    "a distance field defines the surface; its normal is known only where a \
                     ray hits it, where a material's colour field (a vec3 body) is evaluated",
                ),
            );
            return Value::Error;
        }
        if colour && lipschitz.is_some() {
            self.error(
                Diagnostic::error(
                    "E0202",
                    "a colour field takes no `lipschitz`",
                    args.first().map_or(span, arg_span),
                )
                .with_label("a bound of a distance's gradient")
                .with_note("this field's body is a vec3: a colour, not a distance"),
            );
            return Value::Error;
        }
        if colour && field::reads_distance(&comps) {
            self.error(
                Diagnostic::error(
                    "E0410",
                    "a colour field cannot read a shape's distance",
                    body.value.span,
                )
                .with_label("this colour reads `distance(…)`")
                .with_note(
                    "a colour field is a formula of the point `p`: arithmetic, the maths \
                     builtins, noise, fbm and voronoi",
                ),
            );
            return Value::Error;
        }
        if self.dry > 0 {
            return Value::Unknown(if colour { Type::ColourField } else { distance });
        }
        match field::flatten(&comps, owner) {
            Ok(f) if colour => Value::Colour(std::rc::Rc::new(f)),
            Ok(f) => match self.add_node(
                Node::Field {
                    f,
                    lipschitz,
                    plane,
                },
                span,
            ) {
                Value::Shape(id) if plane => Value::Profile(id),
                other => other,
            },
            Err(field::OuterPoint) => self.per_point(
                format!("this {word} reads the point `p` of an enclosing field or profile"),
                body.value.span,
            ),
        }
    }

    /// The `lipschitz` argument of a `field` or `profile` (`word`), if given: a constant
    /// greater than 0; the value to return where it is refused.
    fn field_lipschitz(&mut self, args: &[Arg], word: &str) -> Result<Option<f64>, Value> {
        let mut lipschitz = None;
        for (i, a) in args.iter().enumerate() {
            let named = a.name.as_ref().map(|n| n.name.as_str());
            // The label is on the argument at fault: a name other than `lipschitz`, or any
            // argument after the first (whose own name, if any, was checked first).
            let fault = match named {
                Some(name) if name != "lipschitz" => Some((
                    "E0202",
                    format!("`{word}` has no parameter `{name}`"),
                    "not `lipschitz`",
                )),
                Some(_) if i > 0 => Some((
                    "E0203",
                    "argument `lipschitz` is given twice".to_string(),
                    "a second `lipschitz`",
                )),
                None if i > 0 => Some((
                    "E0205",
                    format!("too many arguments to `{word}`"),
                    "a second argument",
                )),
                _ => None,
            };
            if let Some((code, msg, label)) = fault {
                self.error(
                    Diagnostic::error(code, msg, arg_span(a))
                        .with_label(label)
                        .with_note(format!("`{word}` takes one argument, `lipschitz`"))
                        .with_help(format!(
                            "declare a bound of the gradient: `{word}(lipschitz: 2) {{ … }}`"
                        )),
                );
                return Err(Value::Error);
            }
            match self.expr(&a.value).coerce(Type::Float) {
                Some(Value::Float(l)) if l > 0.0 && l.is_finite() => lipschitz = Some(l),
                Some(Value::Error) => return Err(Value::Error),
                Some(Value::Unknown(_)) => {}
                Some(v @ Value::Float(_)) => {
                    self.error(
                        Diagnostic::error(
                            "E0400",
                            format!("`lipschitz` of `{word}` must be greater than 0"),
                            a.value.span,
                        )
                        .with_label(format!("this is {v}")),
                    );
                    return Err(Value::Error);
                }
                other => {
                    let v = other.unwrap_or(Value::Error);
                    if field::is_point(&v) {
                        return Err(self.per_point(
                            format!("`lipschitz` of `{word}` must be a constant"),
                            a.value.span,
                        ));
                    }
                    self.error(type_mismatch("lipschitz", Type::Float, &v, a.value.span));
                    return Err(Value::Error);
                }
            }
        }
        Ok(lipschitz)
    }

    /// A field's body evaluated with `p` its point (of the plane where `plane`) and, in space,
    /// `n` the surface normal: its value, and where it first read `n`.
    fn field_body(&mut self, body: &Body, plane: bool, owner: u32) -> (Value, Option<Span>) {
        let coord = |i: u8| std::rc::Rc::new(crate::check::types::Sx::Coord(i, owner));
        let mark = self.locals.len();
        let point = if plane {
            vec![coord(0), coord(1)]
        } else {
            vec![coord(0), coord(1), coord(2)]
        };
        // The surface normal `n`, unless a name of the program hides it (as it hides `t`):
        // read by a colour field, refused in a distance's (`field_block`). Bound before `p`,
        // so that `p` is the nearer binding a misspelt name is told of.
        let reads = self.normal_reads.len();
        if !plane && !self.names(NORMAL) {
            let normal = vec![coord(3), coord(4), coord(5)];
            self.locals.push((NORMAL.into(), field::point(normal)));
        }
        self.locals.push(("p".into(), field::point(point)));
        self.planes.push(plane);
        let v = self.body(body);
        self.planes.pop();
        self.locals.truncate(mark);
        let normal_read = self.normal_reads.get(reads).copied();
        self.normal_reads.truncate(reads);
        (v, normal_read)
    }
}
