//! Calls in constant evaluation: a built-in's arguments bound and run, a user function's
//! body evaluated (memoised, within the call-depth limit), and the chain of call sites an
//! error inside a body shows.

use super::bind::{bind, Bound};
use super::{ArgVal, Ctx, PView};
use crate::check::builtins::{self, Build, Range, P};
use crate::check::field;
use crate::check::suggest::closest;
use crate::check::types::{CallKey, Type, Value};
use crate::diagnostics::Diagnostic;
use crate::limits::Limit;
use crate::span::{FileId, Span};
use crate::syntax::ast::*;

impl Ctx<'_> {
    pub(super) fn args(&mut self, args: &[Arg]) -> Vec<ArgVal> {
        args.iter()
            .map(|a| ArgVal {
                name: a.name.clone(),
                value: self.expr(&a.value),
                span: a.value.span,
            })
            .collect()
    }

    pub(super) fn call(
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
        if let Some(help) = crate::check::suggest::ported(&callee.name, &known) {
            d = d.with_help(help);
        } else if let Some(s) = closest(&callee.name, names) {
            d = d.with_help(format!("did you mean `{s}`?"));
        }
        self.error(d);
        Value::Error
    }

    /// Whether the file `from` sees the definitions of `file`: it is that file, or imports it
    /// (directly or through other imports).
    pub(super) fn sees(&self, from: FileId, file: FileId) -> bool {
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

    pub(super) fn call_builtin(
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

    pub(super) fn run_builtin(
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
            return self.point_builtin(b, sig, &vals, at);
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
            Err(refusal) => {
                self.error(
                    Diagnostic::error("E0400", refusal.to_string(), span)
                        .with_label(format!("in this call of `{}`", b.name)),
                );
                Value::Error
            }
        }
    }

    pub(super) fn in_range(&mut self, p: &P, v: &Value, span: Span, callee: &Ident) -> bool {
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
    pub(super) fn count_chars(&mut self, limit: Limit, s: &str, span: Span) -> bool {
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

    pub(super) fn call_user(
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
                            .with_label(format!("this is `{}`", v.type_name())),
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
