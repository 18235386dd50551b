//! Constant evaluation of expressions, with type checking: every expression of a scene is
//! evaluated at compile time. Function bodies are also checked on their own, with their
//! parameters `Unknown` values of the declared types ("dry" evaluation: types only, no nodes).

use super::field;
use super::ops;
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
mod report;
mod scope;
mod values;

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
    /// Evaluates `e`, within the nesting and fuel limits.
    pub fn expr(&mut self, e: &Expr) -> Value {
        let max = self.limits.count(Limit::Nesting);
        if self.nesting >= max {
            return self.too_deep(
                e.span,
                format!("expressions nest more than {max} levels deep"),
            );
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

    /// The error value, the nesting limit reported at `span` as `message`.
    fn too_deep(&mut self, span: Span, message: String) -> Value {
        self.limit(Limit::Nesting, span, message);
        Value::Error
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
            return self.too_deep(e.span, format!("a chain of operators or method calls is longer than {max} links (ten times the nesting limit)"));
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
                    .with_label(format!("this is `{}`", other.type_name())),
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
                        .with_label(format!("this is `{}`", other.type_name())),
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

    /// Adds a node unless the node budget is spent.
    pub fn add_node(&mut self, node: Node, span: Span) -> Value {
        if self.nodes_exhausted(span) {
            return Value::Error;
        }
        Value::Shape(self.graph.add(node, span))
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
