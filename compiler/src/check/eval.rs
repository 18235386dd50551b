//! Constant evaluation of expressions, with type checking: every expression of a scene is
//! evaluated at compile time. Function bodies are also checked on their own, with their
//! parameters `Unknown` values of the declared types ("dry" evaluation: types only, no nodes).

use super::builtins::{self, NORMAL};
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

mod bind;
mod call;
mod list;
mod point;

use bind::with_type_help;
pub(crate) use bind::WHOLE_NUMBER_HELP;
pub use bind::{record, Converted};

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
                        Err(e) => self.per_point(e.to_string(), x.span),
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
}

/// The errors after which evaluation stops (the command line shows the first hundred).
const MAX_ERRORS: usize = 1_000;

/// The span of an argument: `name: value`, or the value alone.
pub(super) fn arg_span(a: &Arg) -> Span {
    a.name
        .as_ref()
        .map_or(a.value.span, |n| n.span.join(a.value.span))
}

/// The name of a value's type for messages (`?` for an error value).
pub fn type_name(v: &Value) -> String {
    v.ty().map_or("?".into(), |t| t.to_string())
}
