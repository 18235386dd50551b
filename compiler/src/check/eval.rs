//! Constant evaluation of expressions, with type checking: every expression of a scene is
//! evaluated at compile time. Function bodies are also checked on their own, with their
//! parameters `Unknown` values of the declared types ("dry" evaluation: types only, no nodes).

use super::builtins::{self, Build, Def, Range, NORMAL, P};
use super::field;
use super::ops;
use super::suggest::{closest, closest_in_order};
use super::types::{CallKey, Type, Value};
use crate::diagnostics::Diagnostic;
use crate::limits::{Limit, Limits};
use crate::scene::{Graph, MaterialId, Node};
use crate::span::{FileId, Span};
use crate::syntax::ast::*;
use std::collections::HashMap;
use std::rc::Rc;

/// A user function and what checking its body found.
#[derive(Debug)]
pub struct FnInfo {
    pub decl: Rc<FnDecl>,
    /// The declared parameter types (`None` where the type name is unknown).
    pub params: Vec<Option<Type>>,
    /// The declared return type.
    pub ret: Option<Type>,
    /// False when the declaration or body had errors: calls then yield `Error` silently.
    pub ok: bool,
    /// Whether the body has been checked on its own yet (at the first call, or at the end).
    pub checked: bool,
}

/// How many links a chain (`1 + 2 + …`, `s.translate(…).rotate(…)…`) may have, as a
/// multiple of the `nesting` limit: chains are not nesting, but they recurse all the same.
pub const CHAIN_FACTOR: usize = 10;

/// The evaluation state of one compilation.
#[derive(Debug, Default)]
pub struct Ctx<'l> {
    pub diags: Vec<Diagnostic>,
    /// The files `mesh(path)` reads.
    pub files: super::Files<'l>,
    pub graph: Graph,
    pub material_ids: HashMap<String, (MaterialId, Span)>,
    pub globals: HashMap<String, (Value, Span)>,
    /// Every global `let`, declared or not yet evaluated, for "used before its definition".
    pub declared: HashMap<String, Span>,
    pub fns: HashMap<String, FnInfo>,
    /// Which file imports which (importer, imported): where a function that hides a built-in
    /// is seen.
    pub imports: Vec<(FileId, FileId)>,
    /// The settings the render block gives, with where: a field with no proven bound has
    /// defaults of its own for `epsilon` and `relaxation`, `max_dist` follows the scene unless
    /// given, and `method: "trace"` of a scene that does not allow it is an error there.
    pub settings_given: Vec<(String, Span)>,
    /// Where the camera, the lights and the scene are written (for the placement warnings).
    pub places: super::Places,
    locals: Vec<(String, Value)>,
    dry: u32,
    depth: usize,
    /// The user functions whose calls are being evaluated, outermost first.
    calling: Vec<String>,
    nesting: usize,
    /// Links of chains being evaluated (see `chained`).
    chain: usize,
    /// Evaluation steps taken (bounded by the `fuel` limit).
    pub fuel: u64,
    /// Characters of the strings passed to a parameter of range `Chars` so far (`text`'s:
    /// the `text_chars` limit bounds their sum).
    pub chars: u64,
    /// The resource limits of this compilation: evaluation stays within them on any input.
    pub limits: Limits,
    reported_limit: bool,
    /// Errors reported so far (evaluation stops at [`MAX_ERRORS`]).
    errors: usize,
    /// Results of calls of user functions on concrete arguments: functions are pure, so a
    /// call repeated with the same arguments is evaluated once. With each, where its
    /// evaluation read the time `t`, if it did.
    memo: HashMap<CallKey, (Value, Option<Span>)>,
    /// The last list an argument was converted from, and to.
    converted: Converted,
    /// Fields begun so far: each field's point is told apart from an enclosing one's.
    fields: u32,
    /// For each field being evaluated, innermost last: whether it is a profile's (its point
    /// a vec2).
    planes: Vec<bool>,
    /// Where the body of a field read `n`, the surface normal (an error unless the field is a
    /// colour's), innermost field's last.
    normal_reads: Vec<Span>,
    /// The time `t` the scene is checked at, in seconds.
    pub time: f64,
    /// Reads of `t` so far (dry evaluation not counted): a count, to tell whether evaluating
    /// something read it, the first read and the last.
    pub time_reads: u64,
    pub first_time_read: Option<Span>,
    last_time_read: Option<Span>,
    /// Global constants whose evaluation read `t`, with where it was read: reading one reads
    /// the time.
    pub timed_globals: HashMap<String, Span>,
}

/// An argument after evaluation.
struct ArgVal {
    name: Option<Ident>,
    value: Value,
    span: Span,
}

/// A parameter as the binder sees it (builtin or user).
struct PView<'a> {
    name: &'a str,
    ty: Option<Type>,
    has_default: bool,
}

impl Ctx<'_> {
    /// Records a diagnostic. After [`MAX_ERRORS`] errors evaluation stops: the last one kept
    /// says so, and no step is taken after it (an input that fails everywhere, such as a
    /// recursion whose every call overflows, is not evaluated to its end for errors no one
    /// reads).
    pub fn error(&mut self, mut d: Diagnostic) {
        if self.dry > 0 && d.code == "E0401" {
            return;
        }
        if d.is_error() {
            if self.errors >= MAX_ERRORS {
                return;
            }
            self.errors += 1;
            if self.errors == MAX_ERRORS {
                d.notes.push(crate::diagnostics::stopped_note(MAX_ERRORS));
            }
        }
        self.diags.push(d);
    }

    /// Evaluates `e`, within the nesting and fuel limits.
    pub fn expr(&mut self, e: &Expr) -> Value {
        let max = self.limits.count(Limit::Nesting);
        if self.nesting >= max {
            self.limit(
                Limit::Nesting,
                e.span,
                format!("expressions nest more than {max} levels deep"),
            );
            return Value::Error;
        }
        if !self.burn(e.span) {
            return Value::Error;
        }
        self.nesting += 1;
        // Deep but legal nesting must not overflow the thread's stack.
        let v = stacker::maybe_grow(64 * 1024, 1024 * 1024, || self.expr_kind(e));
        self.nesting -= 1;
        v
    }

    /// Evaluates the left operand of a binary operator, the receiver of a method, field or
    /// material: a link of a chain (`1 + 2 + … + 1001`, `s.translate(…).rotate(…)…`) at the
    /// level of the chain, so that a long flat chain is not "nesting" (its stack is grown
    /// as needed all the same).
    /// Links of chains count apart, up to [`CHAIN_FACTOR`] times the `nesting` limit.
    fn chained(&mut self, e: &Expr) -> Value {
        let max = self
            .limits
            .count(Limit::Nesting)
            .saturating_mul(CHAIN_FACTOR);
        if self.chain >= max {
            self.limit(
                Limit::Nesting,
                e.span,
                format!("a chain of operators or method calls is longer than {max} links (ten times the nesting limit)"),
            );
            return Value::Error;
        }
        self.nesting -= 1;
        self.chain += 1;
        let v = self.expr(e);
        self.chain -= 1;
        self.nesting += 1;
        v
    }

    /// Spends one evaluation step; false (and a report) once the budget is spent.
    pub fn burn(&mut self, span: Span) -> bool {
        self.burn_steps(1, span)
    }

    /// Spends `steps` evaluation steps (elements copied count as one each).
    fn burn_steps(&mut self, steps: u64, span: Span) -> bool {
        if self.errors >= MAX_ERRORS {
            return false;
        }
        self.fuel = self.fuel.saturating_add(steps);
        let max = self.limits.get(Limit::Fuel);
        if self.fuel > max {
            self.limit(
                Limit::Fuel,
                span,
                format!("evaluating the scene takes more than {max} steps"),
            );
            return false;
        }
        true
    }

    fn expr_kind(&mut self, e: &Expr) -> Value {
        match &e.kind {
            ExprKind::Int(i) => Value::Int(*i),
            ExprKind::Float(f) => self.finite(Value::Float(*f), e.span),
            ExprKind::Angle(a) => self.finite(Value::Angle(*a), e.span),
            ExprKind::Colour(c) => Value::Vec3(c.map(super::colour::srgb_to_linear)),
            ExprKind::Bool(b) => Value::Bool(*b),
            ExprKind::Str(s) => Value::Str(s.as_str().into()),
            ExprKind::Var(id) => self.var(id),
            ExprKind::Tuple(items) => self.tuple(items, e.span),
            ExprKind::Unary(op, x) => {
                let v = self.expr(x);
                if field::is_point(&v) {
                    return match field::unary(*op, &v) {
                        Ok(v) => v,
                        Err(msg) => self.per_point(msg, x.span),
                    };
                }
                self.result(ops::unary(*op, &v), e.span)
            }
            ExprKind::Binary(op, a, b) => {
                let (va, vb) = (self.chained(a), self.expr(b));
                if field::is_point(&va) || field::is_point(&vb) {
                    return self.point_binary(*op, (&va, a.span), (&vb, b.span), e.span);
                }
                if let (Value::List(_, x), Value::List(_, y)) = (&va, &vb) {
                    let n = x.len() + y.len();
                    if !self.list_length(n, e.span) || !self.burn_steps(n as u64, e.span) {
                        return Value::Error;
                    }
                }
                match ops::binary(*op, &va, &vb) {
                    Ok(v) => self.finite(v, e.span),
                    Err(ops::OpError::Overflow) => self.overflow(e.span),
                    Err(ops::OpError::DivZero) => {
                        self.error(
                            Diagnostic::error("E0401", "division by zero", b.span)
                                .with_label("this is zero"),
                        );
                        Value::Error
                    }
                    Err(err) => self.op_error(err, *op, (&va, a.span), (&vb, b.span), e.span),
                }
            }
            ExprKind::Call { callee, args } => {
                let args = self.args(args);
                self.call(callee, None, args, e.span)
            }
            ExprKind::Method {
                receiver,
                name,
                args,
            } => {
                let recv = self.chained(receiver);
                let args = self.args(args);
                self.call(name, Some((recv, receiver.span)), args, e.span)
            }
            ExprKind::Field(x, name) => {
                let v = self.chained(x);
                self.field(v, name)
            }
            ExprKind::If {
                cond,
                then,
                otherwise,
            } => self.if_expr(cond, then, otherwise),
            ExprKind::Material(x, m) => {
                let v = self.chained(x);
                self.paint(v, x.span, m, e.span)
            }
            ExprKind::List(items) => self.list(items, e.span),
            ExprKind::Comprehension {
                var,
                from,
                to,
                cond,
                body,
            } => self.comprehension(var, from, to, cond.as_deref(), body),
            ExprKind::Index(xs, i) => self.index(xs, i),
            ExprKind::FieldBlock { args, body, plane } => {
                self.field_block(args, body, *plane, e.span)
            }
            ExprKind::Error => Value::Error,
        }
    }

    /// `[a, b, c]`: the elements' one type (ints among floats become floats).
    fn list(&mut self, items: &[Expr], span: Span) -> Value {
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
    fn make_list(&mut self, elem: Type, vals: Vec<Value>, at: Span) -> Value {
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
    fn list_length(&mut self, n: usize, span: Span) -> bool {
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
    fn comprehension(
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
                        .with_label(format!("this is `{}`", type_name(&other)));
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
    fn index(&mut self, xs: &Expr, i: &Expr) -> Value {
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

    fn finite(&mut self, v: Value, span: Span) -> Value {
        if v.is_abstract() || v.components().iter().all(|c| c.is_finite()) {
            return v;
        }
        self.error(
            Diagnostic::error("E0402", "this value is not a finite number", span)
                .with_label(format!("evaluates to {v}"))
                .with_note("NaN and infinite values cannot be rendered"),
        );
        Value::Error
    }

    fn result(&mut self, r: Result<Value, ops::OpError>, span: Span) -> Value {
        match r {
            Ok(v) => self.finite(v, span),
            Err(ops::OpError::Types(msg)) => {
                self.error(Diagnostic::error("E0301", msg, span).with_label("here"));
                Value::Error
            }
            Err(ops::OpError::Overflow) => self.overflow(span),
            Err(ops::OpError::DivZero) => Value::Error,
        }
    }

    fn op_error(
        &mut self,
        err: ops::OpError,
        op: BinOp,
        a: (&Value, Span),
        b: (&Value, Span),
        span: Span,
    ) -> Value {
        let msg = match err {
            ops::OpError::Types(m) => m,
            ops::OpError::Overflow => "integer overflow".into(),
            ops::OpError::DivZero => "division by zero".into(),
        };
        let mut d = Diagnostic::error("E0301", msg, span)
            .with_secondary(
                a.1,
                format!(
                    "this is `{}`",
                    a.0.ty().map_or("?".into(), |t| t.to_string())
                ),
            )
            .with_secondary(
                b.1,
                format!(
                    "this is `{}`",
                    b.0.ty().map_or("?".into(), |t| t.to_string())
                ),
            );
        let tys = (a.0.ty(), b.0.ty());
        if [tys.0, tys.1]
            .iter()
            .any(|t| matches!(t, Some(Type::Shape | Type::Profile)))
        {
            d = d.with_help(
                "shapes are combined with `union(a, b)`, `intersect(a, b)` or `subtract(a, b)`",
            );
        } else if matches!(
            tys,
            (Some(Type::Angle), Some(Type::Float | Type::Int))
                | (Some(Type::Float | Type::Int), Some(Type::Angle))
        ) && matches!(op, BinOp::Add | BinOp::Sub)
        {
            d = d.with_help("give the number a unit: `30deg` or `0.5rad`");
        }
        self.error(d);
        Value::Error
    }

    fn overflow(&mut self, span: Span) -> Value {
        self.error(
            Diagnostic::error("E0404", "integer overflow", span)
                .with_label("the result does not fit in a 64-bit integer")
                .with_help("use a float (`1.0 * x`) for large values"),
        );
        Value::Error
    }

    /// Notes that evaluation read the time `t` at `span` (directly, or through a constant
    /// or a call whose evaluation did). Dry evaluation (a function body checked on its own)
    /// does not count: only what the scene evaluates makes it animated.
    pub fn read_time(&mut self, span: Span) {
        if self.dry == 0 {
            self.time_reads += 1;
            self.first_time_read.get_or_insert(span);
            self.last_time_read = Some(span);
        }
    }

    /// Where the last read of `t` was, if any.
    pub fn last_time_read(&self) -> Option<Span> {
        self.last_time_read
    }

    /// Whether the program names `name` where evaluation is: a local, a global constant, or
    /// one declared further down.
    fn names(&self, name: &str) -> bool {
        self.locals.iter().any(|(n, _)| n == name)
            || self.globals.contains_key(name)
            || self.declared.contains_key(name)
    }

    fn var(&mut self, id: &Ident) -> Value {
        if let Some((_, v)) = self.locals.iter().rev().find(|(n, _)| *n == id.name) {
            if id.name == NORMAL && field::is_normal(v) {
                self.normal_reads.push(id.span);
            }
            return v.clone();
        }
        if let Some((v, _)) = self.globals.get(&id.name) {
            let v = v.clone();
            if let Some(at) = self.timed_globals.get(&id.name).copied() {
                self.read_time(at);
            }
            return v;
        }
        if let Some(def) = self.declared.get(&id.name).copied() {
            self.error(
                Diagnostic::error(
                    "E0208",
                    format!("`{}` is used before its definition", id.name),
                    id.span,
                )
                .with_label("used here")
                .with_secondary(def, "defined here, later")
                .with_help("move the `let` above its first use"),
            );
            return Value::Error;
        }
        // The time, unless a constant, parameter or loop variable of that name hides it.
        if id.name == builtins::TIME {
            self.read_time(id.span);
            return Value::Float(self.time);
        }
        // The built-in constants (pi, tau), unless a name of this file hides them.
        if let Some(v) = builtins::constant(&id.name) {
            return Value::Float(v);
        }
        let mut d = Diagnostic::error("E0200", format!("unknown name `{}`", id.name), id.span)
            .with_label("not defined");
        if id.name == "p" {
            d = d.with_help(
                "`p` is the point inside `field { … }` (or `profile { … }`); elsewhere every value is a constant",
            );
        } else if self.fns.contains_key(&id.name) || builtins::builtin(&id.name).is_some() {
            d = d.with_help(format!(
                "`{}` is a function: call it as `{}(...)`",
                id.name, id.name
            ));
        } else if self.material_ids.contains_key(&id.name) {
            d = d.with_help(format!(
                "`{}` is a material: apply it with `shape @ {}`",
                id.name, id.name
            ));
        } else if let Some(s) = self.suggest_value(&id.name) {
            d = d.with_help(format!("did you mean `{s}`?"));
        }
        self.error(d);
        Value::Error
    }

    /// A name in scope one or two edits from `name`; among equally close ones the nearest
    /// binding: locals innermost first (a field's point `p` before the parameters of the
    /// function around the field), then the file's globals, then the built-in constants.
    fn suggest_value(&self, name: &str) -> Option<String> {
        let mut globals: Vec<&str> = self.globals.keys().map(String::as_str).collect();
        globals.sort_unstable();
        let names = self
            .locals
            .iter()
            .rev()
            .map(|(n, _)| n.as_str())
            .chain(globals)
            .chain(builtins::CONSTANTS.iter().map(|(n, _)| *n));
        closest_in_order(name, names).map(str::to_string)
    }

    fn tuple(&mut self, items: &[Expr], span: Span) -> Value {
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
                            .with_label(format!(
                                "this is `{}`",
                                v.ty().map_or("?".into(), |t| t.to_string())
                            )),
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

    fn field(&mut self, v: Value, name: &Ident) -> Value {
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

    /// The condition of a comprehension's `if` (`[for i in 0..n if c { … }]`): its value, or
    /// `None` where it is not known (types only) or is not a bool (reported).
    fn condition(&mut self, cond: &Expr) -> Option<bool> {
        match self.expr(cond) {
            Value::Bool(b) => Some(b),
            Value::Error | Value::Unknown(Type::Bool) => None,
            v if field::is_point(&v) => {
                self.per_point(
                    "which elements a list keeps must be decided by constants: a list's length cannot vary from point to point".into(),
                    cond.span,
                );
                None
            }
            other => {
                self.error(
                    Diagnostic::error(
                        "E0303",
                        "the condition of a comprehension's `if` must be a bool",
                        cond.span,
                    )
                    .with_label(format!("this is `{}`", type_name(&other))),
                );
                None
            }
        }
    }

    fn if_expr(&mut self, cond: &Expr, then: &Body, otherwise: &Body) -> Value {
        let c = self.expr(cond);
        let mut failed = c == Value::Error;
        let taken = match &c {
            Value::Bool(b) => Some(*b),
            Value::Error | Value::Unknown(Type::Bool) => None,
            other => {
                failed = true;
                self.error(
                    Diagnostic::error("E0303", "the condition of `if` must be a bool", cond.span)
                        .with_label(format!(
                            "this is `{}`",
                            other.ty().map_or("?".into(), |t| t.to_string())
                        )),
                );
                None
            }
        };
        // The branch not taken is still type-checked, without building anything.
        let (a, b) = match taken {
            Some(true) => (self.body(then), self.dry(|cx| cx.body(otherwise))),
            Some(false) => (self.dry(|cx| cx.body(then)), self.body(otherwise)),
            None => (
                self.dry(|cx| cx.body(then)),
                self.dry(|cx| cx.body(otherwise)),
            ),
        };
        let (ta, tb) = (a.ty(), b.ty());
        if let (Some(x), Some(y)) = (ta, tb) {
            if x != y && !(x.fits(y) || y.fits(x)) {
                self.error(
                    Diagnostic::error(
                        "E0302",
                        "the branches of `if` have different types",
                        then.value.span,
                    )
                    .with_label(format!("this is `{x}`"))
                    .with_secondary(otherwise.value.span, format!("this is `{y}`")),
                );
                return Value::Error;
            }
        }
        match taken {
            Some(true) => a,
            Some(false) => b,
            None if failed => Value::Error,
            None => ta.or(tb).map_or(Value::Error, Value::Unknown),
        }
    }

    /// E0410: a per-point value where a constant is needed, or an operation per-point values
    /// do not support.
    fn per_point(&mut self, msg: String, at: Span) -> Value {
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
    fn word(&self) -> &'static str {
        if self.planes.last() == Some(&true) {
            "profile"
        } else {
            "field"
        }
    }

    /// `a op b` where an operand is per-point.
    fn point_binary(
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
            Err(msg) => {
                let at = if field::is_point(a.0) { a.1 } else { b.1 };
                let v = self.per_point(msg, at);
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
    fn point_builtin(
        &mut self,
        b: &builtins::Builtin,
        sig: &builtins::Sig,
        vals: &[Value],
        at: Span,
        span: Span,
    ) -> Value {
        if vals.iter().any(Value::is_abstract) {
            return if vals.contains(&Value::Error) {
                Value::Error
            } else {
                Value::Unknown(sig.ret)
            };
        }
        match field::builtin(b.name, vals) {
            Some(Ok(v)) => v,
            Some(Err(msg)) => {
                self.error(
                    Diagnostic::error("E0400", msg, span)
                        .with_label(format!("in this call of `{}`", b.name)),
                );
                Value::Error
            }
            None => self.per_point(
                format!("`{}` needs values known at compile time", b.name),
                at,
            ),
        }
    }

    /// `field [(lipschitz: L)] { body }`: the body evaluated with `p` the point, its value
    /// (a float of the point) the distance of a new field shape. With `plane` (`profile {
    /// … }`), `p` is a point of the plane (a vec2) and the value a profile's distance.
    fn field_block(&mut self, args: &[Arg], body: &Body, plane: bool, span: Span) -> Value {
        let word = if plane { "profile" } else { "field" };
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
                return Value::Error;
            }
            match self.expr(&a.value).coerce(Type::Float) {
                Some(Value::Float(l)) if l > 0.0 && l.is_finite() => lipschitz = Some(l),
                Some(Value::Error) => return Value::Error,
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
                    return Value::Error;
                }
                other => {
                    let v = other.unwrap_or(Value::Error);
                    if field::is_point(&v) {
                        return self.per_point(
                            format!("`lipschitz` of `{word}` must be a constant"),
                            a.value.span,
                        );
                    }
                    self.error(type_mismatch("lipschitz", Type::Float, &v, a.value.span));
                    return Value::Error;
                }
            }
        }
        self.fields += 1;
        let owner = self.fields;
        let coord = |i: u8| std::rc::Rc::new(super::types::Sx::Coord(i, owner));
        let mark = self.locals.len();
        let point = if plane {
            vec![coord(0), coord(1)]
        } else {
            vec![coord(0), coord(1), coord(2)]
        };
        // The surface normal `n`, unless a name of the program hides it (as it hides `t`):
        // read by a colour field, refused below in a distance's. Bound before `p`, so that
        // `p` is the nearer binding a misspelt name is told of.
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
        let distance = if plane { Type::Profile } else { Type::Shape };
        // A float body is a distance (a shape, or a profile), a vec3 body a colour (a colour
        // field; not of the plane).
        if plane && v.ty().is_some_and(|t| !t.fits(Type::Float)) {
            let ty = type_name(&v);
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
                            type_name(other)
                        ),
                        body.value.span,
                    )
                    .with_label(format!("this is `{}`", type_name(other)))
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

    /// Runs `f` in dry mode: types only, no nodes, no range errors.
    pub fn dry<T>(&mut self, f: impl FnOnce(&mut Self) -> T) -> T {
        self.dry += 1;
        let out = f(self);
        self.dry -= 1;
        out
    }

    /// Evaluates a body's local bindings and value; the bindings end with it.
    pub fn body(&mut self, b: &Body) -> Value {
        let mark = self.locals.len();
        for l in &b.lets {
            let v = self.let_value(l);
            self.locals.push((l.name.name.clone(), v));
        }
        let v = self.expr(&b.value);
        self.locals.truncate(mark);
        v
    }

    /// Evaluates the value of a `let`, checking its declared type.
    pub fn let_value(&mut self, l: &Let) -> Value {
        let v = self.expr(&l.value);
        let Some(ty) = &l.ty else { return v };
        let Some(want) = self.type_name(ty) else {
            return Value::Error;
        };
        match v.clone().coerce(want) {
            Some(c) => c,
            None => {
                let d = Diagnostic::error(
                    "E0300",
                    format!("expected `{want}`, found `{}`", type_name(&v)),
                    l.value.span,
                )
                .with_label(format!("this is `{}`", type_name(&v)))
                .with_secondary(ty.span, "declared type");
                self.error(with_type_help(d, want, v.ty()));
                Value::Error
            }
        }
    }

    /// Binds a scene-level local (a `let` or loop variable of a `scene` block).
    pub fn push_local(&mut self, name: &str, v: Value) {
        self.locals.push((name.to_string(), v));
    }

    /// The number of locals, to truncate back to.
    pub fn locals_mark(&self) -> usize {
        self.locals.len()
    }

    /// Drops locals bound after `mark`.
    pub fn truncate_locals(&mut self, mark: usize) {
        self.locals.truncate(mark);
    }

    /// Resolves a type name, reporting an unknown one.
    pub fn type_name(&mut self, id: &Ident) -> Option<Type> {
        let t = Type::from_name(&id.name);
        if t.is_none() {
            let inner = id.name.trim_start_matches('[').trim_end_matches(']');
            if inner != id.name && Type::from_name(inner).is_some() {
                self.error(
                    Diagnostic::error("E0209", format!("unknown type `{}`", id.name), id.span)
                        .with_label("a list of lists")
                        .with_note("the elements of a list are not lists"),
                );
                return None;
            }
            let mut d = Diagnostic::error("E0209", format!("unknown type `{}`", id.name), id.span)
                .with_label("not a type")
                .with_note(format!("the types are {}", Type::NAMES.join(", ")));
            if inner != id.name {
                d = d.with_note(
                    "a list type is written with its element type in brackets, as in `[shape]`",
                );
            }
            if let Some(s) = closest(inner, Type::NAMES) {
                let s = if inner == id.name {
                    s.to_string()
                } else {
                    format!("[{s}]")
                };
                d = d.with_help(format!("did you mean `{s}`?"));
            }
            self.error(d);
        }
        t
    }

    fn paint(&mut self, v: Value, vspan: Span, m: &Ident, span: Span) -> Value {
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
                        .with_label(format!(
                            "this is `{}`",
                            other.ty().map_or("?".into(), |t| t.to_string())
                        )),
                );
                Value::Error
            }
        }
    }

    /// Adds a node unless the node budget is spent.
    pub fn add_node(&mut self, node: Node, span: Span) -> Value {
        if self.nodes_exhausted(span) {
            return Value::Error;
        }
        Value::Shape(self.graph.add(node, span))
    }

    /// Whether the node budget is spent (reported once).
    fn nodes_exhausted(&mut self, span: Span) -> bool {
        let max = self.limits.count(Limit::Nodes);
        if self.graph.len() < max {
            return false;
        }
        self.limit(
            Limit::Nodes,
            span,
            format!("the scene has more than {max} shape nodes"),
        );
        true
    }

    /// Reports an exceeded resource limit once, naming the flag that raises it.
    pub fn limit(&mut self, limit: Limit, span: Span, msg: String) {
        self.limit_report(limit, span, msg, None);
    }

    /// [`Ctx::limit`] where the value that would do is known, `needed`: the note suggests it.
    pub fn limit_to(&mut self, limit: Limit, span: Span, msg: String, needed: u64) {
        self.limit_report(limit, span, msg, Some(needed));
    }

    fn limit_report(&mut self, limit: Limit, span: Span, msg: String, needed: Option<u64>) {
        if !self.reported_limit {
            self.reported_limit = true;
            let raise = match needed {
                Some(n) => self.limits.raise_to(limit, n),
                None => self.limits.raise(limit),
            };
            let note = format!("this limit keeps compilation bounded; {raise}");
            self.error(Diagnostic::error("E0507", msg, span).with_note(note));
        }
    }

    fn args(&mut self, args: &[Arg]) -> Vec<ArgVal> {
        args.iter()
            .map(|a| ArgVal {
                name: a.name.clone(),
                value: self.expr(&a.value),
                span: a.value.span,
            })
            .collect()
    }

    fn call(
        &mut self,
        callee: &Ident,
        recv: Option<(Value, Span)>,
        args: Vec<ArgVal>,
        span: Span,
    ) -> Value {
        if let Some(info) = self.fns.get(&callee.name) {
            // A function named like a built-in hides it where its file is seen (W0016).
            let defined = info.decl.name.span.file;
            if builtins::builtin(&callee.name).is_none() || self.sees(callee.span.file, defined) {
                return self.call_user(callee, recv, args, span);
            }
        }
        if let Some(b) = builtins::builtin(&callee.name) {
            return self.call_builtin(b, callee, recv, args, span);
        }
        let mut d = Diagnostic::error(
            "E0201",
            format!("unknown function `{}`", callee.name),
            callee.span,
        )
        .with_label("no function of this name");
        let names = self
            .fns
            .keys()
            .map(String::as_str)
            .chain(builtins::BUILTINS.iter().map(|b| b.name));
        let known = |n: &str| builtins::builtin(n).is_some();
        if let Some(help) = super::suggest::ported(&callee.name, &known) {
            d = d.with_help(help);
        } else if let Some(s) = closest(&callee.name, names) {
            d = d.with_help(format!("did you mean `{s}`?"));
        }
        self.error(d);
        Value::Error
    }

    /// Whether the file `from` sees the definitions of `file`: it is that file, or imports it
    /// (directly or through other imports).
    fn sees(&self, from: FileId, file: FileId) -> bool {
        let mut seen = vec![from];
        let mut next = vec![from];
        while let Some(f) = next.pop() {
            if f == file {
                return true;
            }
            for &(a, b) in &self.imports {
                if a == f && !seen.contains(&b) {
                    seen.push(b);
                    next.push(b);
                }
            }
        }
        false
    }

    fn call_builtin(
        &mut self,
        b: &'static builtins::Builtin,
        callee: &Ident,
        recv: Option<(Value, Span)>,
        args: Vec<ArgVal>,
        span: Span,
    ) -> Value {
        // Overloads are tried in order; the first that binds cleanly wins. Otherwise the errors
        // of the closest one are reported.
        let mut best: Option<(usize, Vec<Diagnostic>)> = None;
        for (i, sig) in b.sigs.iter().enumerate() {
            let params: Vec<PView> = sig
                .params
                .iter()
                .map(|p| PView {
                    name: p.name,
                    ty: Some(p.ty),
                    has_default: p.def.value().is_some(),
                })
                .collect();
            match bind(
                &params,
                sig.rest,
                &recv,
                &args,
                callee,
                span,
                &mut self.converted,
            ) {
                Ok(slots) => {
                    if !self.burn_steps(slots.copied, span) {
                        return Value::Error;
                    }
                    return self.run_builtin(b, sig, slots, callee, span);
                }
                Err(errs) => {
                    if best.as_ref().is_none_or(|(_, e)| errs.len() < e.len()) {
                        best = Some((i, errs));
                    }
                }
            }
        }
        if let Some((i, errs)) = best {
            let sig_note = if b.sigs.len() > 1 {
                let all: Vec<String> = b
                    .sigs
                    .iter()
                    .map(|s| builtins::signature(b.name, s))
                    .collect();
                format!("the forms of `{}` are:\n  {}", b.name, all.join("\n  "))
            } else {
                format!("`{}`", builtins::signature(b.name, &b.sigs[i]))
            };
            // `min(a, b)` of two shapes, as a shader writes a union.
            let shapes = matches!(b.name, "min" | "max")
                && args.iter().any(|a| matches!(a.value, Value::Shape(_)));
            for (n, d) in errs.into_iter().enumerate() {
                let d = d.with_note(sig_note.clone());
                let d = if shapes && n == 0 && d.help.is_none() {
                    d.with_help("shapes are combined with `union(a, b)` (the minimum of their fields) or `intersect(a, b)` (the maximum)")
                } else {
                    d
                };
                self.error(d);
            }
        }
        Value::Error
    }

    fn run_builtin(
        &mut self,
        b: &builtins::Builtin,
        sig: &builtins::Sig,
        slots: Bound,
        callee: &Ident,
        span: Span,
    ) -> Value {
        let mut vals = Vec::new();
        let mut ok = true;
        let mut abstract_ = false;
        let mut point_at: Option<Span> = None;
        for (i, slot) in slots.slots.into_iter().enumerate() {
            let p: &P = &sig.params[i];
            let (v, vspan) = match slot {
                Some(s) => s,
                None => (p.def.value().unwrap_or(Value::Error), span),
            };
            ok &= self.in_range(p, &v, vspan, callee);
            abstract_ |= v.is_abstract();
            if field::is_point(&v) {
                point_at.get_or_insert(vspan);
            }
            vals.push(v);
        }
        let last = sig.params.last();
        for (v, vspan) in slots.rest {
            if let Some(p) = last {
                ok &= self.in_range(p, &v, vspan, callee);
            }
            abstract_ |= v.is_abstract();
            if field::is_point(&v) {
                point_at.get_or_insert(vspan);
            }
            vals.push(v);
        }
        if !ok {
            return Value::Error;
        }
        if let Some(at) = point_at {
            return self.point_builtin(b, sig, &vals, at, span);
        }
        if abstract_ || self.dry > 0 {
            return if vals.contains(&Value::Error) {
                Value::Error
            } else {
                Value::Unknown(sig.ret)
            };
        }
        if matches!(sig.ret, Type::Shape | Type::Profile) && self.nodes_exhausted(span) {
            return Value::Error;
        }
        let mut build = Build {
            graph: &mut self.graph,
            span,
            files: Some(&mut self.files),
            limits: &self.limits,
            warnings: Vec::new(),
            fuel_left: self.limits.get(Limit::Fuel).saturating_sub(self.fuel),
            steps: 0,
        };
        let result = sig.imp.call(&mut build, &vals);
        let warnings = std::mem::take(&mut build.warnings);
        let steps = build.steps;
        self.diags.extend(warnings);
        if !self.burn_steps(steps, span) {
            return Value::Error;
        }
        match result {
            Ok(v) => self.finite(v, span),
            Err(msg) => {
                self.error(
                    Diagnostic::error("E0400", msg, span)
                        .with_label(format!("in this call of `{}`", b.name)),
                );
                Value::Error
            }
        }
    }

    fn in_range(&mut self, p: &P, v: &Value, span: Span, callee: &Ident) -> bool {
        if v.is_abstract() || field::is_point(v) || p.range == Range::Any || self.dry > 0 {
            return true;
        }
        if let (Range::Chars(limit), Value::Str(s)) = (p.range, v) {
            return self.count_chars(limit, s, span);
        }
        match p.range.check(v, &self.limits) {
            Ok(()) => true,
            Err(why) => {
                self.error(
                    Diagnostic::error(
                        "E0400",
                        format!("`{}` of `{}` {why}", p.name, callee.name),
                        span,
                    )
                    .with_label(format!("this is {v}")),
                );
                false
            }
        }
    }

    /// Counts the characters of `s`, passed at `span`, against `limit` with those of the
    /// strings counted before; false (and a report naming the sum) past it. Counted before
    /// the call lays anything out, so a string of any length costs only its count.
    fn count_chars(&mut self, limit: Limit, s: &str, span: Span) -> bool {
        let here = s.chars().count() as u64;
        let (before, max) = (self.chars, self.limits.get(limit));
        self.chars = before.saturating_add(here);
        if self.chars <= max {
            return true;
        }
        let others = if before > 0 {
            format!(", and the scene's other text {before}")
        } else {
            String::new()
        };
        self.limit_to(
            limit,
            span,
            format!(
                "this text has {here} characters{others}, more than the `{}` limit of {max}",
                limit.name()
            ),
            self.chars,
        );
        false
    }

    fn call_user(
        &mut self,
        callee: &Ident,
        recv: Option<(Value, Span)>,
        args: Vec<ArgVal>,
        span: Span,
    ) -> Value {
        // A body is checked on its own at its function's first evaluated call. A call met
        // while another body is checked needs only the declared types: its function is
        // checked at its own first call, or with the functions never called, so that
        // checking does not nest as deep as a chain of functions is long.
        if !self.fns[&callee.name].checked && self.dry == 0 {
            self.check_function(&callee.name);
        }
        let info = &self.fns[&callee.name];
        let decl = info.decl.clone();
        let (ptys, ret, ok) = (info.params.clone(), info.ret, info.ok);
        let params: Vec<PView> = decl
            .params
            .iter()
            .zip(&ptys)
            .map(|(p, t)| PView {
                name: &p.name.name,
                ty: *t,
                has_default: p.default.is_some(),
            })
            .collect();
        let slots = match bind(
            &params,
            false,
            &recv,
            &args,
            callee,
            span,
            &mut self.converted,
        ) {
            Ok(s) => s,
            Err(errs) => {
                for d in errs {
                    self.error(d.with_secondary(decl.name.span, "declared here"));
                }
                return Value::Error;
            }
        };
        let Some(ret) = ret else { return Value::Error };
        if !ok || !self.burn_steps(slots.copied, span) {
            return Value::Error;
        }
        // The body was checked on its own: a types-only call needs only the return type.
        if self.dry > 0 {
            return Value::Unknown(ret);
        }
        let max = self.limits.count(Limit::CallDepth);
        if self.depth >= max {
            let before = self.diags.len();
            self.limit(
                Limit::CallDepth,
                span,
                format!("calls nest deeper than {max}"),
            );
            // A function that calls itself without end is the likely cause: say which.
            let name = &callee.name;
            let times = self.calling.iter().filter(|c| *c == name).count();
            if let (Some(d), true) = (self.diags.get_mut(before), times > 0) {
                d.notes.push(format!(
                    "`{name}` calls itself, directly or through other functions, and had done so {times} times here: a case that returns without calling it again may be missing or never reached"
                ));
            }
            return Value::Error;
        }
        // Defaults are evaluated in the global scope; the body sees its parameters and the
        // global constants.
        let saved = std::mem::take(&mut self.locals);
        let mut frame = Vec::new();
        for ((slot, p), ty) in slots.slots.into_iter().zip(&decl.params).zip(&ptys) {
            let v = match slot {
                Some((v, _)) => v,
                None => {
                    let d = p.default.as_ref().map_or(Value::Error, |d| self.expr(d));
                    ty.and_then(|t| d.clone().coerce(t)).unwrap_or(Value::Error)
                }
            };
            frame.push((p.name.name.clone(), v));
        }
        // A call on per-point values builds expressions, and one on a long list or string
        // would make a long key: neither is kept.
        let key = CallKey::new(&callee.name, frame.iter().map(|(_, v)| v));
        if let Some((v, read)) = key.as_ref().and_then(|k| self.memo.get(k)).cloned() {
            self.locals = saved;
            if let Some(at) = read {
                self.read_time(at);
            }
            return v;
        }
        self.locals = frame;
        self.depth += 1;
        self.calling.push(callee.name.clone());
        let before = self.diags.len();
        let reads = self.time_reads;
        let v = self.body(&decl.body);
        let read = (self.time_reads > reads)
            .then_some(self.last_time_read)
            .flatten();
        self.calling.pop();
        self.depth -= 1;
        if self.diags[before..].iter().any(Diagnostic::is_error) {
            let label = call_label(&self.locals);
            for d in &mut self.diags[before..] {
                add_call_site(d, span, &label);
            }
        }
        self.locals = saved;
        let v = v.coerce(ret).unwrap_or(Value::Error);
        if let Some(key) = key.filter(|_| !field::is_point(&v)) {
            self.memo.insert(key, (v.clone(), read));
        }
        v
    }

    /// Checks a function's body once with its parameters unknown, so that its type errors are
    /// reported whether or not it is called, and once only. Globals evaluated so far are
    /// visible (a function is checked at its first call, or after all items).
    pub fn check_function(&mut self, name: &str) {
        let Some(info) = self.fns.get_mut(name) else {
            return;
        };
        info.checked = true;
        let (decl, params, ret) = (info.decl.clone(), info.params.clone(), info.ret);
        let before = self.diags.len();
        let saved = std::mem::take(&mut self.locals);
        self.dry(|cx| {
            for (p, t) in decl.params.iter().zip(&params) {
                if let (Some(d), Some(t)) = (&p.default, t) {
                    let v = cx.expr(d);
                    if v.clone().coerce(*t).is_none() {
                        cx.error(
                            Diagnostic::error(
                                "E0300",
                                format!("the default of `{}` is not a `{t}`", p.name.name),
                                d.span,
                            )
                            .with_label(format!("this is `{}`", type_name(&v))),
                        );
                    }
                }
                cx.push_local(&p.name.name, t.map_or(Value::Error, Value::Unknown));
            }
            let v = cx.body(&decl.body);
            if let (Some(want), Some(got)) = (ret, v.ty()) {
                if !got.fits(want) {
                    cx.error(
                        Diagnostic::error(
                            "E0300",
                            format!("`{name}` returns `{got}`, but is declared to return `{want}`"),
                            decl.body.value.span,
                        )
                        .with_label(format!("this is `{got}`"))
                        .with_secondary(decl.ret.span, "declared here"),
                    );
                }
            }
        });
        self.locals = saved;
        if self.diags[before..].iter().any(Diagnostic::is_error) {
            if let Some(info) = self.fns.get_mut(name) {
                info.ok = false;
            }
        }
    }
}

/// At most this many call sites are added to a diagnostic inside nested function bodies.
const MAX_CALL_SITES: usize = 4;

/// The errors after which evaluation stops (the command line shows the first hundred).
const MAX_ERRORS: usize = 1_000;

/// The span of an argument: `name: value`, or the value alone.
fn arg_span(a: &Arg) -> Span {
    a.name
        .as_ref()
        .map_or(a.value.span, |n| n.span.join(a.value.span))
}

/// `called here with r = -1, h = 2`: the label of a call site, with its arguments.
fn call_label(params: &[(String, Value)]) -> String {
    let args: Vec<String> = params
        .iter()
        .map(|(n, v)| match v {
            Value::Shape(_) => format!("{n} = a shape"),
            Value::Profile(_) => format!("{n} = a profile"),
            _ => format!("{n} = {v}"),
        })
        .collect();
    if args.is_empty() {
        "called here".into()
    } else {
        format!("called here with {}", args.join(", "))
    }
}

/// Adds the call site of the function whose body reported `d` as a secondary label, so that
/// an error inside a body shows the chain of calls that led to it (innermost first), up to
/// [`MAX_CALL_SITES`] calls; a note says when more are left out.
fn add_call_site(d: &mut Diagnostic, span: Span, label: &str) {
    const MORE: &str = "called through further functions, not shown";
    let sites = d
        .labels
        .iter()
        .filter(|l| l.message.starts_with("called here"))
        .count();
    if sites < MAX_CALL_SITES {
        d.labels.push(crate::diagnostics::Label {
            span,
            message: label.to_string(),
        });
    } else if !d.notes.iter().any(|n| n == MORE) {
        d.notes.push(MORE.into());
    }
}

/// The name of a value's type for messages (`?` for an error value).
pub fn type_name(v: &Value) -> String {
    v.ty().map_or("?".into(), |t| t.to_string())
}

/// What names are given to: a call's parameters or a record's fields (the words of the
/// diagnostics).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Given {
    /// Arguments to a function's parameters.
    Arguments,
    /// A record's fields.
    Fields,
}

/// Names given to a list of parameters or fields, the one binder of calls ([`bind`]) and
/// records ([`record`]): which each fills, E0203 for a name given twice, and at the end E0202
/// for an unknown name (suggesting one not given) and E0204 for a required one not given.
struct Binder<'a> {
    given: Given,
    /// The function's or the record's name.
    owner: &'a str,
    /// The parameters' or fields' names, and whether each is required.
    params: Vec<(&'a str, bool)>,
    /// Where each was given, if it was.
    filled: Vec<Option<Span>>,
    /// The names that match none.
    unknown: Vec<&'a Ident>,
}

impl<'a> Binder<'a> {
    fn new(given: Given, owner: &'a str, params: Vec<(&'a str, bool)>) -> Self {
        let filled = vec![None; params.len()];
        Binder {
            given,
            owner,
            params,
            filled,
            unknown: Vec::new(),
        }
    }

    /// Fills parameter `i` (by position, or a method's receiver).
    fn fill(&mut self, i: usize, at: Span) {
        self.filled[i] = Some(at);
    }

    /// Whether parameter `i` is filled.
    fn is_filled(&self, i: usize) -> bool {
        self.filled[i].is_some()
    }

    /// The parameter that `name` fills, if it is one and not given already (E0203); an
    /// unknown name is kept for [`Binder::finish`].
    fn name(&mut self, name: &'a Ident) -> Result<Option<usize>, Diagnostic> {
        let Some(i) = self.params.iter().position(|p| p.0 == name.name) else {
            self.unknown.push(name);
            return Ok(None);
        };
        if let Some(first) = self.filled[i] {
            let what = match self.given {
                Given::Arguments => "argument",
                Given::Fields => "field",
            };
            let d = Diagnostic::error(
                "E0203",
                format!("{what} `{}` is given twice", name.name),
                name.span,
            )
            .with_label("given again here");
            return Err(match self.given {
                Given::Arguments => d,
                Given::Fields => d.with_secondary(first, "first given here"),
            });
        }
        self.fill(i, name.span);
        Ok(Some(i))
    }

    /// E0202 for every unknown name and E0204 (at `at`) for every required parameter not
    /// given, with the indices of the latter.
    fn finish(&self, at: Span) -> (Vec<Diagnostic>, Vec<usize>) {
        let mut errs = Vec::new();
        let free = || {
            self.params
                .iter()
                .zip(&self.filled)
                .filter(|(_, f)| f.is_none())
                .map(|(p, _)| p.0)
        };
        for name in &self.unknown {
            let mut d = match self.given {
                Given::Arguments => Diagnostic::error(
                    "E0202",
                    format!("`{}` has no parameter `{}`", self.owner, name.name),
                    name.span,
                )
                .with_label("unknown parameter"),
                Given::Fields => Diagnostic::error(
                    "E0202",
                    format!("`{}` has no field `{}`", self.owner, name.name),
                    name.span,
                )
                .with_label("unknown field")
                .with_note(format!(
                    "the fields of `{}` are {}",
                    self.owner,
                    self.params
                        .iter()
                        .map(|p| p.0)
                        .collect::<Vec<_>>()
                        .join(", ")
                )),
            };
            if let Some(s) = closest(&name.name, free()) {
                d = d.with_help(format!("did you mean `{s}`?"));
            }
            errs.push(d);
        }
        let mut missing = Vec::new();
        for (i, (name, required)) in self.params.iter().enumerate() {
            if *required && self.filled[i].is_none() {
                let what = match self.given {
                    Given::Arguments => "argument",
                    Given::Fields => "field",
                };
                errs.push(
                    Diagnostic::error(
                        "E0204",
                        format!("missing {what} `{name}` of `{}`", self.owner),
                        at,
                    )
                    .with_label(format!("`{name}` is required")),
                );
                missing.push(i);
            }
        }
        (errs, missing)
    }
}

/// Arguments matched to parameters: one slot per parameter (`None`: use the default), then
/// the extra arguments of a variadic last parameter.
struct Bound {
    slots: Vec<Option<(Value, Span)>>,
    rest: Vec<(Value, Span)>,
    /// Elements of lists copied to convert them (ints to floats), spent as fuel.
    copied: u64,
}

/// Matches arguments to parameters and checks their types. A method receiver goes to the first
/// parameter of its type. Returns every problem found.
#[allow(clippy::too_many_arguments)]
fn bind(
    params: &[PView],
    rest: bool,
    recv: &Option<(Value, Span)>,
    args: &[ArgVal],
    callee: &Ident,
    span: Span,
    converted: &mut Converted,
) -> Result<Bound, Vec<Diagnostic>> {
    let mut errs = Vec::new();
    let mut slots: Vec<Option<(Value, Span)>> = vec![None; params.len()];
    let mut extra = Vec::new();
    let names = params.iter().map(|p| (p.name, !p.has_default)).collect();
    let mut binder = Binder::new(Given::Arguments, &callee.name, names);
    if let Some((v, s)) = recv {
        match receiver_slot(params, v) {
            Some(idx) => {
                slots[idx] = Some((v.clone(), *s));
                binder.fill(idx, *s);
            }
            None => errs.push(Diagnostic::error(
                "E0205",
                format!("`{}` takes no arguments", callee.name),
                *s,
            )),
        }
    }
    let mut next = 0;
    let mut seen_named = false;
    for a in args {
        match &a.name {
            None => {
                if seen_named {
                    errs.push(
                        Diagnostic::error(
                            "E0206",
                            "positional argument after a named argument",
                            a.span,
                        )
                        .with_help("give every argument after a named one by name too"),
                    );
                    continue;
                }
                while next < params.len() && binder.is_filled(next) {
                    next += 1;
                }
                if next < params.len() {
                    slots[next] = Some((a.value.clone(), a.span));
                    binder.fill(next, a.span);
                } else if rest && !params.is_empty() {
                    extra.push((a.value.clone(), a.span));
                } else if !errs.iter().any(|d: &Diagnostic| d.code == "E0205") {
                    errs.push(
                        Diagnostic::error(
                            "E0205",
                            format!("too many arguments to `{}`", callee.name),
                            a.span,
                        )
                        .with_label(format!(
                            "`{}` takes at most {} argument{}",
                            callee.name,
                            params.len(),
                            if params.len() == 1 { "" } else { "s" }
                        )),
                    );
                }
            }
            Some(name) => {
                seen_named = true;
                match binder.name(name) {
                    Ok(Some(i)) => slots[i] = Some((a.value.clone(), a.span)),
                    Ok(None) => {}
                    Err(d) => errs.push(d),
                }
            }
        }
    }
    // Suggestions name only parameters that no argument fills.
    errs.extend(binder.finish(span).0);
    let mut bound = Bound {
        slots,
        rest: extra,
        copied: 0,
    };
    coerce(params, &mut bound, converted, &mut errs);
    if errs.is_empty() {
        Ok(bound)
    } else {
        Err(errs)
    }
}

/// The parameter a method's receiver fills: the first of its type, else the first (`None`
/// when there is none).
fn receiver_slot(params: &[PView], v: &Value) -> Option<usize> {
    if params.is_empty() {
        return None;
    }
    let idx = v
        .ty()
        .and_then(|t| {
            params
                .iter()
                .position(|p| p.ty.is_some_and(|pt| t.fits(pt)))
        })
        .unwrap_or(0);
    Some(idx)
}

/// Converts each bound argument to its parameter's type (an int to a float, …), or reports
/// E0300 where it has another.
fn coerce(
    params: &[PView],
    bound: &mut Bound,
    converted: &mut Converted,
    errs: &mut Vec<Diagnostic>,
) {
    for (i, slot) in bound.slots.iter_mut().enumerate() {
        if let (Some((v, s)), Some(want)) = (slot.as_mut(), params[i].ty) {
            if !converted.convert(v, want, &mut bound.copied) {
                errs.push(type_mismatch(params[i].name, want, v, *s));
            }
        }
    }
    if let Some(want) = params.last().and_then(|p| p.ty) {
        for (v, s) in bound.rest.iter_mut() {
            if !converted.convert(v, want, &mut bound.copied) {
                errs.push(type_mismatch(params[params.len() - 1].name, want, v, *s));
            }
        }
    }
}

/// The last list converted to another element type (ints to floats) for an argument: the
/// list, the element type and the copy. A list passed call after call (in a loop) is
/// copied once; every copy's elements are spent as fuel, so that copying is bounded too.
#[derive(Debug, Default)]
pub struct Converted {
    last: Option<Conversion>,
}

/// A list converted: the list, the element type it was converted to, and its copy.
type Conversion = (Rc<[Value]>, &'static Type, Rc<[Value]>);

impl Converted {
    /// Converts `v` to `want` where it fits (false where it does not), adding the elements
    /// of a list copied to `copied`.
    fn convert(&mut self, v: &mut Value, want: Type, copied: &mut u64) -> bool {
        if let (Value::List(elem, items), Type::List(w)) = (&*v, want) {
            if *elem != w {
                if let Some((from, to, out)) = &self.last {
                    if Rc::ptr_eq(from, items) && *to == w {
                        *v = Value::List(w, Rc::clone(out));
                        return true;
                    }
                }
                let from = Rc::clone(items);
                let Some(c) = v.clone().coerce(want) else {
                    return false;
                };
                if let Value::List(_, out) = &c {
                    *copied += from.len() as u64;
                    self.last = Some((from, w, Rc::clone(out)));
                }
                *v = c;
                return true;
            }
        }
        match v.clone().coerce(want) {
            Some(c) => {
                *v = c;
                true
            }
            None => false,
        }
    }
}

fn type_mismatch(param: &str, want: Type, v: &Value, span: Span) -> Diagnostic {
    let found = v.ty().map_or("?".to_string(), |t| t.to_string());
    let mut d = Diagnostic::error(
        "E0300",
        format!(
            "`{param}` expects {} `{want}`, found `{found}`",
            if matches!(want, Type::Int | Type::Angle) {
                "an"
            } else {
                "a"
            }
        ),
        span,
    )
    .with_label(format!("this is `{found}`"));
    d = with_type_help(d, want, v.ty());
    d
}

/// The help where a float is given for an int: most often a `/`, which divides as real
/// numbers do.
pub(super) const WHOLE_NUMBER_HELP: &str = "use a whole number: `div(a, b)` divides whole numbers \
     (`/` gives a float: `5 / 2` is 2.5), and `int(x)` rounds a float down";

/// Adds the hint for a common type mix-up (a number for an angle, a float for an int...).
fn with_type_help(mut d: Diagnostic, want: Type, found: Option<Type>) -> Diagnostic {
    match (want, found) {
        (Type::Angle, Some(Type::Float | Type::Int)) => {
            d = d.with_help("give the angle a unit: `90deg` or `1.57rad`")
        }
        (Type::Int, Some(Type::Float)) => d = d.with_help(WHOLE_NUMBER_HELP),
        (Type::Vec3, Some(Type::Float | Type::Int)) => {
            d = d.with_help("write a vector as `(x, y, z)`")
        }
        (Type::Profile, Some(Type::Shape)) => {
            d = d.with_help(
                "a profile is flat: `circle`, `rect`, `polygon`, …, or a formula of a point of \
                 the plane, `profile { … }` (`field { … }` is a formula of a point in space)",
            )
        }
        (Type::Shape, Some(Type::Profile)) => {
            d = d.with_help(
                "a profile is flat: make it a shape with `extrude(profile, height)` or `revolve(profile)`",
            )
        }
        _ => {}
    }
    d
}

/// Binds the fields of a record block (`phong { ... }`, `camera { ... }`) as named arguments,
/// applying defaults and range checks. Returns the values by field name.
pub fn record(
    cx: &mut Ctx,
    rec: &builtins::Record,
    fields: &[Field],
    head: &Ident,
) -> HashMap<&'static str, Value> {
    let mut out: HashMap<&'static str, Value> = HashMap::new();
    let names = rec
        .fields
        .iter()
        .map(|p| (p.name, matches!(p.def, Def::Req)))
        .collect();
    let mut binder = Binder::new(Given::Fields, rec.name, names);
    for f in fields {
        let reads = cx.time_reads;
        let v = cx.expr(&f.value);
        let p = match binder.name(&f.name) {
            Ok(Some(i)) => &rec.fields[i],
            Ok(None) => continue,
            Err(d) => {
                cx.error(d);
                continue;
            }
        };
        if let (true, Some(at)) = (cx.time_reads > reads, cx.last_time_read()) {
            if rec.timeless.contains(&p.name) {
                cx.error(
                    Diagnostic::error(
                        "E0406",
                        format!(
                            "`{}` of `{}` cannot depend on the time `t`",
                            p.name, rec.name
                        ),
                        f.value.span,
                    )
                    .with_label("this value changes with `t`")
                    .with_secondary(at, "the time is read here")
                    .with_note(format!(
                        "every frame of a sequence shares {}",
                        rec.timeless.join(", ")
                    )),
                );
                out.insert(p.name, Value::Error);
                continue;
            }
        }
        if field::is_point(&v) {
            cx.per_point(
                format!("`{}` of `{}` must be a constant", p.name, rec.name),
                f.value.span,
            );
            out.insert(p.name, Value::Error);
            continue;
        }
        if rec.painted.contains(&p.name) {
            match &v {
                Value::Colour(_) | Value::Unknown(Type::ColourField) => {
                    out.insert(p.name, v);
                    continue;
                }
                Value::Shape(id) if matches!(cx.graph.node(*id), Node::Field { .. }) => {
                    cx.error(
                        Diagnostic::error(
                            "E0300",
                            format!(
                                "`{}` of `{}` is a field whose body is a float, not a vec3",
                                p.name, rec.name
                            ),
                            f.value.span,
                        )
                        .with_label("this field's body is a distance")
                        .with_note("a colour field's body is its colour at the point `p`, a vec3")
                        .with_help("give the body three components: `field { vec3(r, g, b) }`"),
                    );
                    out.insert(p.name, Value::Error);
                    continue;
                }
                _ => {}
            }
        }
        let v = match v.clone().coerce(p.ty) {
            Some(c) => c,
            None => {
                let mut d = type_mismatch(p.name, p.ty, &v, f.value.span);
                if v.ty() == Some(Type::ColourField) {
                    d = d.with_note(
                        "a colour field goes in a material's colour: `color` of `phong`, \
                         `a` and `b` of `checker`, `base_color` of `pbr`",
                    );
                }
                cx.error(d);
                Value::Error
            }
        };
        if let Some(d) = super::colour::warning(rec.name, p.name, &v, f.value.span) {
            cx.error(d);
        }
        if !v.is_abstract() {
            if let Err(why) = p.range.check(&v, &cx.limits) {
                let mut d = Diagnostic::error("E0400", format!("`{}` {why}", p.name), f.value.span)
                    .with_label(format!("this is {v}"));
                if let Some((_, help)) = rec.help.iter().find(|(n, _)| *n == p.name) {
                    d = d.with_help(*help);
                }
                if let Some(limit) = p.range.limit(&v, &cx.limits) {
                    let needed = v.components().into_iter().fold(0.0, f64::max) as u64;
                    d = d.with_note(format!(
                        "this limit keeps rendering bounded; {}",
                        cx.limits.raise_to(limit, needed)
                    ));
                }
                cx.error(d);
                out.insert(p.name, Value::Error);
                continue;
            }
        }
        out.insert(p.name, v);
    }
    let (errs, missing) = binder.finish(head.span);
    for d in errs {
        cx.error(d);
    }
    for (i, p) in rec.fields.iter().enumerate() {
        if missing.contains(&i) {
            out.insert(p.name, Value::Error);
        } else if !binder.is_filled(i) {
            out.insert(p.name, p.def.value().unwrap_or(Value::Error));
        }
    }
    out
}
