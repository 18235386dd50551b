//! Binding arguments to parameters and record fields to their names: positional and named
//! arguments, defaults, receivers, type coercion with its helpful mismatch messages.

use super::{ArgVal, Ctx, PView};
use crate::check::builtins::{self, Def};
use crate::check::field;
use crate::check::suggest::closest;
use crate::check::types::{Type, Value};
use crate::diagnostics::Diagnostic;
use crate::scene::Node;
use crate::span::Span;
use crate::syntax::ast::*;
use std::collections::HashMap;
use std::rc::Rc;

/// What names are given to: a call's parameters or a record's fields (the words of the
/// diagnostics).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Given {
    /// Arguments to a function's parameters.
    Arguments,
    /// A record's fields.
    Fields,
}

/// Names given to a list of parameters or fields, the one binder of calls ([`bind`]) and
/// records ([`record`]): which each fills, E0203 for a name given twice, and at the end E0202
/// for an unknown name (suggesting one not given) and E0204 for a required one not given.
pub(super) struct Binder<'a> {
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
pub(super) struct Bound {
    /// Each parameter's value and where it came from, if given.
    pub(super) slots: Vec<Option<(Value, Span)>>,
    /// The values after the last parameter (a variadic built-in's).
    pub(super) rest: Vec<(Value, Span)>,
    /// Elements of lists copied to convert them (ints to floats), spent as fuel.
    pub(super) copied: u64,
}

/// Matches arguments to parameters and checks their types. A method receiver goes to the first
/// parameter of its type. Returns every problem found.
#[allow(clippy::too_many_arguments)]
pub(super) fn bind(
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
pub(super) fn receiver_slot(params: &[PView], v: &Value) -> Option<usize> {
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
pub(super) fn coerce(
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

pub(super) fn type_mismatch(param: &str, want: Type, v: &Value, span: Span) -> Diagnostic {
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
pub(crate) const WHOLE_NUMBER_HELP: &str = "use a whole number: `div(a, b)` divides whole numbers \
     (`/` gives a float: `5 / 2` is 2.5), and `int(x)` rounds a float down";

/// Adds the hint for a common type mix-up (a number for an angle, a float for an int...).
pub(super) fn with_type_help(mut d: Diagnostic, want: Type, found: Option<Type>) -> Diagnostic {
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
        if let Some(d) = crate::check::colour::warning(rec.name, p.name, &v, f.value.span) {
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
