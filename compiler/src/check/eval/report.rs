//! How evaluation reports what goes wrong: errors (up to `MAX_ERRORS`), values that are not
//! finite, the operators' errors with help, overflow, and the limits a scene reaches.

use super::{Ctx, MAX_ERRORS};
use crate::check::ops;
use crate::check::types::{Type, Value};
use crate::diagnostics::Diagnostic;
use crate::limits::Limit;
use crate::span::Span;
use crate::syntax::ast::*;

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

    pub(super) fn finite(&mut self, v: Value, span: Span) -> Value {
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

    pub(super) fn result(&mut self, r: Result<Value, ops::OpError>, span: Span) -> Value {
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

    pub(super) fn op_error(
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
            .with_secondary(a.1, format!("this is `{}`", a.0.type_name()))
            .with_secondary(b.1, format!("this is `{}`", b.0.type_name()));
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

    pub(super) fn overflow(&mut self, span: Span) -> Value {
        self.error(
            Diagnostic::error("E0404", "integer overflow", span)
                .with_label("the result does not fit in a 64-bit integer")
                .with_help("use a float (`1.0 * x`) for large values"),
        );
        Value::Error
    }

    /// Whether the node budget is spent (reported once).
    pub(super) fn nodes_exhausted(&mut self, span: Span) -> bool {
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
