//! The language's tables as Python data, read-only, for the modelling API of the package
//! (python/sdfc/model.py builds a function or method per built-in and a keyword class per
//! record from them, and python/sdfc/stubs.py their type stubs): the built-ins with their
//! overloads, parameters, defaults and doc lines (the checker's `BUILTINS`, the docs'
//! lines the language server's hover shows), the material, light, camera and render records,
//! the check of a value against a parameter's valid range (the checker's own message), and
//! `sdfc fmt`.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use sdfc_compiler::builtins::{self as language, Def, Range, P};
use sdfc_compiler::{Limits, Type, Value};

/// The default of a parameter as a Python value: None (required), a number, a bool, a
/// string, a tuple of three floats, or `("deg", x)` for an angle of x degrees.
fn default<'py>(py: Python<'py>, def: Def) -> PyResult<Bound<'py, PyAny>> {
    Ok(match def {
        Def::Req => py.None().into_bound(py),
        Def::Num(x) => x.into_pyobject(py)?.into_any(),
        Def::Int(i) => i.into_pyobject(py)?.into_any(),
        Def::Bool(b) => pyo3::types::PyBool::new(py, b).to_owned().into_any(),
        Def::V3(v) => (v[0], v[1], v[2]).into_pyobject(py)?.into_any(),
        Def::Text(s) => s.into_pyobject(py)?.into_any(),
        Def::Deg(d) => ("deg", d).into_pyobject(py)?.into_any(),
    })
}

/// One parameter: name, type (as the language writes it: `float`, `vec3`, `[shape]`, …),
/// required, default, its text in a signature (`1`, `(0, 1, 0)`, `"poly"`), and the valid
/// values in words ("" for any).
fn param<'py>(py: Python<'py>, p: &P) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("name", p.name)?;
    d.set_item("type", p.ty.to_string())?;
    d.set_item("required", matches!(p.def, Def::Req))?;
    d.set_item("default", default(py, p.def)?)?;
    d.set_item("default_text", p.def.value().map(|v| v.to_string()))?;
    d.set_item("checked", checked(p.range))?;
    Ok(d)
}

/// Whether a value's range is checked where it is given (a range bounded by a resource
/// limit, or a string's characters counted over the scene, is left to the checker, which
/// knows the limits the scene is compiled with).
fn checked(range: Range) -> bool {
    !matches!(range, Range::Any | Range::Limited(..) | Range::Chars(_))
}

/// `builtins()`: every built-in of the checker's table, in its order: `{"name", "doc",
/// "sigs": [{"params", "rest", "ret", "signature", "method"}]}` (`doc` the markdown the
/// language server's hover shows: each signature with its valid values and what it does;
/// `method` "shape" or "profile" where the form is a method of one, else None).
#[pyfunction]
pub fn builtins(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let list = PyList::empty(py);
    for b in language::BUILTINS.iter() {
        let d = PyDict::new(py);
        d.set_item("name", b.name)?;
        d.set_item("doc", sdfc_runtime::lsp::hover::builtin(b.name))?;
        let sigs = PyList::empty(py);
        for sig in b.sigs {
            let s = PyDict::new(py);
            let params = PyList::empty(py);
            for p in sig.params {
                params.append(param(py, p)?)?;
            }
            s.set_item("params", params)?;
            s.set_item("rest", sig.rest)?;
            // A method of the shape or profile its first parameter takes (`a.f(b)` is
            // `f(a, b)` for every function; Python offers it where the first is one).
            let receiver = sig.params.first().map(|p| p.ty);
            let method = match receiver {
                Some(Type::Shape) => Some("shape"),
                Some(Type::Profile) => Some("profile"),
                _ => None,
            };
            s.set_item("method", method)?;
            s.set_item("ret", sig.ret.to_string())?;
            s.set_item("signature", language::signature(b.name, sig))?;
            sigs.append(s)?;
        }
        d.set_item("sigs", sigs)?;
        list.append(d)?;
    }
    Ok(list)
}

/// The records: `{"group": "material" | "light" | "camera" | "render", "name", "fields",
/// "painted"}`, each field as a parameter of [`builtins`].
#[pyfunction]
pub fn records(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let list = PyList::empty(py);
    let groups = language::MATERIALS
        .iter()
        .map(|r| ("material", r))
        .chain(language::LIGHTS.iter().map(|r| ("light", r)))
        .chain([("camera", &language::CAMERA), ("render", &language::RENDER)]);
    for (group, r) in groups {
        let d = PyDict::new(py);
        d.set_item("group", group)?;
        d.set_item("name", r.name)?;
        let fields = PyList::empty(py);
        for p in r.fields {
            fields.append(param(py, p)?)?;
        }
        d.set_item("fields", fields)?;
        d.set_item("painted", r.painted.to_vec())?;
        list.append(d)?;
    }
    Ok(list)
}

/// The parameter `index` of overload `sig` of the built-in `owner`, or the field `index` of
/// the record `owner` (`"material:phong"`, `"light:point"`, `"camera"`, `"render"`).
fn lookup(owner: &str, sig: usize, index: usize) -> Option<&'static P> {
    let record = |r: &'static language::Record| r.fields.get(index);
    match owner.split_once(':') {
        Some(("builtin", name)) => language::builtin(name)?.sigs.get(sig)?.params.get(index),
        Some(("material", name)) => record(language::MATERIALS.iter().find(|r| r.name == name)?),
        Some(("light", name)) => record(language::LIGHTS.iter().find(|r| r.name == name)?),
        None if owner == "camera" => record(&language::CAMERA),
        None if owner == "render" => record(&language::RENDER),
        _ => None,
    }
}

/// `range_error(owner, sig, index, value)`: what the checker says of `value` given to that
/// parameter when it is outside the valid values ("must be greater than 0"), else None.
/// `value` is a number, a sequence of two or three numbers, a string, or `("rad", x)` for an
/// angle of x radians.
#[pyfunction]
pub fn range_error(
    owner: &str,
    sig: usize,
    index: usize,
    value: &Bound<'_, PyAny>,
) -> PyResult<Option<String>> {
    let p = lookup(owner, sig, index)
        .ok_or_else(|| PyValueError::new_err(format!("no parameter {index} of {owner:?}")))?;
    let value = if let Ok(s) = value.extract::<String>() {
        Value::Str(s.into())
    } else if let Some(x) = value
        .extract::<(String, f64)>()
        .ok()
        .and_then(|(unit, x)| (unit == "rad").then_some(x))
    {
        Value::Angle(x)
    } else if let Ok(x) = value.extract::<f64>() {
        match p.ty {
            Type::Int => Value::Int(x as i64),
            _ => Value::Float(x),
        }
    } else {
        let c: Vec<f64> = value.extract()?;
        match c[..] {
            [x, y] => Value::Vec2([x, y]),
            [x, y, z] => Value::Vec3([x, y, z]),
            _ => return Err(PyValueError::new_err("a value of 1, 2 or 3 numbers")),
        }
    };
    Ok(p.range
        .check(&value, &Limits::default())
        .err()
        .map(|e| e.to_string()))
}

/// `fmt(text)`: the text as `sdfc fmt` writes it, or None where it has syntax errors (the
/// checker reports them) or is nested beyond the `nesting` limit.
#[pyfunction]
pub fn fmt(text: &str) -> Option<String> {
    sdfc_compiler::format::format(text).ok()
}
