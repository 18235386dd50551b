//! Names during evaluation: variables and their suggestions, `let` bindings and the stack of
//! locals, type names.

use super::{with_type_help, Ctx};
use crate::check::builtins::{self, NORMAL};
use crate::check::field;
use crate::check::suggest::{closest, closest_in_order};
use crate::check::types::{Type, Value};
use crate::diagnostics::Diagnostic;
use crate::syntax::ast::*;

impl Ctx<'_> {
    /// Whether the program names `name` where evaluation is: a local, a global constant, or
    /// one declared further down.
    pub(super) fn names(&self, name: &str) -> bool {
        self.locals.iter().any(|(n, _)| n == name)
            || self.globals.contains_key(name)
            || self.declared.contains_key(name)
    }

    pub(super) fn var(&mut self, id: &Ident) -> Value {
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
                    format!("expected `{want}`, found `{}`", v.type_name()),
                    l.value.span,
                )
                .with_label(format!("this is `{}`", v.type_name()))
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
}
