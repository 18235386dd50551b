//! Per-point values inside `field { … }` and `profile { … }`: the point `p` (a vec3, or a vec2
//! of the plane) and everything computed from it are expressions, not constants
//! ([`Value::Point`]); arithmetic, swizzles and the builtins that accept them build expression
//! nodes (constants folded), and the finished body becomes the flat [`FieldFn`] of a field
//! shape or profile. Everything else still needs constants: a per-point
//! value where one is needed is error E0410.

use super::types::{Sx, Value};
use crate::scene::field::{FBin, FOp, FUn, FieldFn, Slot};
use crate::syntax::ast::{BinOp, UnOp};
use std::collections::HashMap;
use std::rc::Rc;

/// The constant `c` as an expression.
fn k(c: f64) -> Rc<Sx> {
    Rc::new(Sx::Const(c))
}

fn konst(s: &Sx) -> Option<f64> {
    match s {
        Sx::Const(c) => Some(*c),
        _ => None,
    }
}

/// `u a`, folded when `a` is constant.
pub fn un(u: FUn, a: Rc<Sx>) -> Rc<Sx> {
    if let Some(x) = konst(&a) {
        let y = match u {
            FUn::Neg => -x,
            FUn::Abs => x.abs(),
            FUn::Sqrt => x.sqrt(),
            FUn::Sin => x.sin(),
            FUn::Cos => x.cos(),
            FUn::Tan => x.tan(),
            FUn::Exp => x.exp(),
            FUn::Log => x.ln(),
            FUn::Floor => x.floor(),
            FUn::Smooth => {
                let t = x.clamp(0.0, 1.0);
                t * t * (3.0 - 2.0 * t)
            }
        };
        if y.is_finite() {
            return k(y);
        }
    }
    Rc::new(Sx::Un(u, a))
}

/// `a op b`, folded when both are constant, and the identities x + 0, x · 1 dropped.
pub fn bin(op: FBin, a: Rc<Sx>, b: Rc<Sx>) -> Rc<Sx> {
    match (op, konst(&a), konst(&b)) {
        (_, Some(x), Some(y)) => {
            let z = match op {
                FBin::Add => x + y,
                FBin::Sub => x - y,
                FBin::Mul => x * y,
                FBin::Div => x / y,
                FBin::Min => x.min(y),
                FBin::Max => x.max(y),
                FBin::Pow => x.powf(y),
                FBin::Atan2 => x.atan2(y),
            };
            if z.is_finite() {
                return k(z);
            }
        }
        (FBin::Add | FBin::Sub, _, Some(0.0)) => return a,
        (FBin::Add, Some(0.0), _) => return b,
        (FBin::Mul | FBin::Div, _, Some(1.0)) => return a,
        (FBin::Mul, Some(1.0), _) => return b,
        _ => {}
    }
    Rc::new(Sx::Bin(op, a, b))
}

/// A per-point value of these components.
pub fn point(c: Vec<Rc<Sx>>) -> Value {
    Value::Point(c.into())
}

/// The components of a number or vector, constant or per-point; `None` for other values.
pub fn comps(v: &Value) -> Option<Vec<Rc<Sx>>> {
    match v {
        Value::Point(c) => Some(c.to_vec()),
        Value::Int(_) | Value::Float(_) | Value::Angle(_) | Value::Vec2(_) | Value::Vec3(_) => {
            Some(v.components().into_iter().map(k).collect())
        }
        _ => None,
    }
}

/// Whether a value is per-point.
pub fn is_point(v: &Value) -> bool {
    matches!(v, Value::Point(_))
}

/// Why an operator cannot take a per-point value.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum PointError {
    /// `!` of a per-point value.
    #[error("`!` needs a bool known at compile time")]
    Not,
    /// Operands that are not numbers or vectors.
    #[error("`{}` cannot be applied to these operands", .op.symbol())]
    Operands { op: BinOp },
    /// Vectors of different sizes.
    #[error("`{}` cannot be applied to vectors of different sizes", .op.symbol())]
    Sizes { op: BinOp },
    /// A comparison or logic, which would branch, in a `word` (`field` or `profile`).
    #[error("`{}` of values that depend on the point `p` is not supported: a {word}'s value cannot branch", .op.symbol())]
    Branch { op: BinOp, word: &'static str },
}

/// `op v` for a per-point `v`.
pub fn unary(op: UnOp, v: &Value) -> Result<Value, PointError> {
    match op {
        UnOp::Neg => Ok(point(
            comps(v)
                .unwrap_or_default()
                .into_iter()
                .map(|c| un(FUn::Neg, c))
                .collect(),
        )),
        UnOp::Not => Err(PointError::Not),
    }
}

/// Componentwise `f` over `a` and `b`, a scalar broadcast over a vector.
fn zip(a: Vec<Rc<Sx>>, b: Vec<Rc<Sx>>, f: impl Fn(Rc<Sx>, Rc<Sx>) -> Rc<Sx>) -> Vec<Rc<Sx>> {
    let n = a.len().max(b.len());
    (0..n)
        .map(|i| {
            let x = a[if a.len() == 1 { 0 } else { i }].clone();
            let y = b[if b.len() == 1 { 0 } else { i }].clone();
            f(x, y)
        })
        .collect()
}

/// `a op b` where either operand is per-point (types already checked by the caller):
/// arithmetic componentwise; `%` is the floored remainder a − b·⌊a/b⌋. Comparisons and logic
/// need constants (the message names the value as `word`'s: `field` or `profile`).
pub fn binary(op: BinOp, a: &Value, b: &Value, word: &'static str) -> Result<Value, PointError> {
    let (Some(x), Some(y)) = (comps(a), comps(b)) else {
        return Err(PointError::Operands { op });
    };
    if x.len() > 1 && y.len() > 1 && x.len() != y.len() {
        return Err(PointError::Sizes { op });
    }
    let f: fn(Rc<Sx>, Rc<Sx>) -> Rc<Sx> = match op {
        BinOp::Add => |a, b| bin(FBin::Add, a, b),
        BinOp::Sub => |a, b| bin(FBin::Sub, a, b),
        BinOp::Mul => |a, b| bin(FBin::Mul, a, b),
        BinOp::Div => |a, b| bin(FBin::Div, a, b),
        BinOp::Rem => modulo,
        _ => return Err(PointError::Branch { op, word }),
    };
    Ok(point(zip(x, y, f)))
}

/// a − b·⌊a/b⌋.
fn modulo(a: Rc<Sx>, b: Rc<Sx>) -> Rc<Sx> {
    let q = bin(FBin::Div, a.clone(), b.clone());
    let f = un(FUn::Floor, q);
    let m = bin(FBin::Mul, b, f);
    bin(FBin::Sub, a, m)
}

/// The components named by a swizzle (`x`, `xz`, `zyx`, `rgb`): indices, when every letter
/// names one of `dims` components.
pub fn swizzle(name: &str, dims: usize) -> Option<Vec<usize>> {
    if name.is_empty() || name.len() > 3 {
        return None;
    }
    name.chars()
        .map(|c| match c {
            'x' | 'r' => Some(0),
            'y' | 'g' => Some(1),
            'z' | 'b' => Some(2),
            _ => None,
        })
        .map(|i| i.filter(|&i| i < dims))
        .collect()
}

fn dot(a: &[Rc<Sx>], b: &[Rc<Sx>]) -> Rc<Sx> {
    let mut acc: Option<Rc<Sx>> = None;
    for (x, y) in a.iter().zip(b) {
        let m = bin(FBin::Mul, x.clone(), y.clone());
        acc = Some(match acc {
            None => m,
            Some(s) => bin(FBin::Add, s, m),
        });
    }
    acc.unwrap_or_else(|| k(0.0))
}

fn length(v: Vec<Rc<Sx>>) -> Rc<Sx> {
    if let Some(c) = v.iter().map(|s| konst(s)).collect::<Option<Vec<f64>>>() {
        return k(c.iter().map(|x| x * x).sum::<f64>().sqrt());
    }
    Rc::new(Sx::Length(v))
}

fn map1(v: &Value, f: impl Fn(Rc<Sx>) -> Rc<Sx>) -> Value {
    point(comps(v).unwrap_or_default().into_iter().map(f).collect())
}

/// The builtins that accept per-point arguments, applied to `a` (bound to the overload's
/// parameters, at least one per-point). `None` for a builtin that needs constants.
pub fn builtin(name: &str, a: &[Value]) -> Option<Value> {
    let c = |i: usize| comps(&a[i]).unwrap_or_default();
    let s = |i: usize| c(i)[0].clone();
    let f1 = |u: FUn| Some(map1(&a[0], |x| un(u, x)));
    Some(match name {
        "sin" => return f1(FUn::Sin),
        "cos" => return f1(FUn::Cos),
        "tan" => return f1(FUn::Tan),
        "sqrt" => return f1(FUn::Sqrt),
        "exp" => return f1(FUn::Exp),
        "log" => return f1(FUn::Log),
        "abs" => return f1(FUn::Abs),
        "floor" => return f1(FUn::Floor),
        "ceil" => map1(&a[0], |x| {
            let n = un(FUn::Neg, x);
            un(FUn::Neg, un(FUn::Floor, n))
        }),
        "fract" => map1(&a[0], |x| {
            let f = un(FUn::Floor, x.clone());
            bin(FBin::Sub, x, f)
        }),
        "mod" => point(zip(c(0), c(1), modulo)),
        "min" => point(zip(c(0), c(1), |x, y| bin(FBin::Min, x, y))),
        "max" => point(zip(c(0), c(1), |x, y| bin(FBin::Max, x, y))),
        "clamp" => point(zip(
            zip(c(0), c(1), |x, y| bin(FBin::Max, x, y)),
            c(2),
            |x, y| bin(FBin::Min, x, y),
        )),
        "pow" => point(vec![bin(FBin::Pow, s(0), s(1))]),
        "atan2" => point(vec![bin(FBin::Atan2, s(0), s(1))]),
        "mix" => {
            let t = s(2);
            point(zip(c(0), c(1), |x, y| Rc::new(Sx::Mix(x, y, t.clone()))))
        }
        "smoothstep" => {
            let (e0, e1) = (s(0), s(1));
            point(vec![un(
                FUn::Smooth,
                bin(
                    FBin::Div,
                    bin(FBin::Sub, s(2), e0.clone()),
                    bin(FBin::Sub, e1, e0),
                ),
            )])
        }
        "length" => point(vec![length(c(0))]),
        "dot" => point(vec![dot(&c(0), &c(1))]),
        "cross" => {
            let (x, y) = (c(0), c(1));
            let m = |i: usize, j: usize| {
                bin(
                    FBin::Sub,
                    bin(FBin::Mul, x[i].clone(), y[j].clone()),
                    bin(FBin::Mul, x[j].clone(), y[i].clone()),
                )
            };
            point(vec![m(1, 2), m(2, 0), m(0, 1)])
        }
        "normalize" => {
            let v = c(0);
            let l = length(v.clone());
            point(
                v.into_iter()
                    .map(|x| bin(FBin::Div, x, l.clone()))
                    .collect(),
            )
        }
        "vec2" => point(vec![s(0), s(1)]),
        "vec3" if a.len() == 1 => point(vec![s(0), s(0), s(0)]),
        "vec3" => point(vec![s(0), s(1), s(2)]),
        "float" => a[0].clone(),
        "distance" => {
            let (Value::Shape(id) | Value::Profile(id)) = a[0] else {
                return Some(Value::Error);
            };
            // A profile's distance reads x and y: it is read in the plane z = 0.
            let q = c(1);
            let z = q.get(2).cloned().unwrap_or_else(|| k(0.0));
            point(vec![Rc::new(Sx::Distance(
                id,
                [q[0].clone(), q[1].clone(), z],
            ))])
        }
        "noise" => point(vec![Rc::new(Sx::Noise(c(0)))]),
        "voronoi" => point(vec![Rc::new(Sx::Voronoi(c(0)))]),
        "hash" => point(vec![Rc::new(Sx::Hash(c(0)))]),
        "fbm" => return Some(fbm(a)),
        _ => return None,
    })
}

/// Fractal sums of noise: `octaves` noises at frequencies multiplied by `lacunarity` and
/// amplitudes by `gain`, each octave's point shifted so that the octaves do not share their
/// lattice's origin.
fn fbm(a: &[Value]) -> Value {
    let q = comps(&a[0]).unwrap_or_default();
    let octaves = a[1].num() as i64;
    let (lac, gain) = (a[2].num(), a[3].num());
    let mut sum: Option<Rc<Sx>> = None;
    let (mut freq, mut amp) = (1.0, 1.0);
    for o in 0..octaves {
        let shift = 17.13 * o as f64;
        let at: Vec<Rc<Sx>> = q
            .iter()
            .map(|x| bin(FBin::Add, bin(FBin::Mul, x.clone(), k(freq)), k(shift)))
            .collect();
        let n = bin(FBin::Mul, Rc::new(Sx::Noise(at)), k(amp));
        sum = Some(match sum {
            None => n,
            Some(s) => bin(FBin::Add, s, n),
        });
        freq *= lac;
        amp *= gain;
    }
    point(vec![sum.unwrap_or_else(|| k(0.0))])
}

/// Whether any of the expressions `out` reads a shape's distance (each shared part visited
/// once).
pub fn reads_distance(out: &[Rc<Sx>]) -> bool {
    reads(out, |s| matches!(s, Sx::Distance(..)))
}

/// Whether the expression `out` reads the surface normal `n` (a colour field's alone).
pub fn reads_normal(out: &[Rc<Sx>]) -> bool {
    reads(out, |s| matches!(s, Sx::Coord(a, _) if *a >= 3))
}

/// Whether the value is the surface normal `n` a field's body is given.
pub fn is_normal(v: &Value) -> bool {
    matches!(v, Value::Point(c) if matches!(c.first().map(|s| &**s), Some(Sx::Coord(3, _))))
}

/// Whether a part of the expression `out` is one that `hit` picks.
fn reads(out: &[Rc<Sx>], hit: impl Fn(&Sx) -> bool) -> bool {
    let mut seen: std::collections::HashSet<*const Sx> = std::collections::HashSet::new();
    let mut stack: Vec<&Rc<Sx>> = out.iter().collect();
    while let Some(s) = stack.pop() {
        if !seen.insert(Rc::as_ptr(s)) {
            continue;
        }
        if hit(s) {
            return true;
        }
        match &**s {
            Sx::Distance(..) | Sx::Coord(..) | Sx::Const(_) => {}
            Sx::Un(_, a) => stack.push(a),
            Sx::Bin(_, a, b) => stack.extend([a, b]),
            Sx::Length(v) | Sx::Noise(v) | Sx::Voronoi(v) | Sx::Hash(v) => stack.extend(v),
            Sx::Mix(a, b, t) => stack.extend([a, b, t]),
        }
    }
    false
}

/// A coordinate of an enclosing field's point, read by an inner field (which cannot).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OuterPoint;

/// The flat form of the expression `out` of field number `owner`.
pub fn flatten(out: &[Rc<Sx>], owner: u32) -> Result<FieldFn, OuterPoint> {
    let mut f = Flat {
        ops: Vec::new(),
        seen: HashMap::new(),
        owner,
    };
    let mut slots = Vec::new();
    for o in out {
        slots.push(f.slot(o)?);
    }
    Ok(FieldFn {
        ops: f.ops,
        out: slots,
    })
}

struct Flat {
    ops: Vec<FOp>,
    /// Each node already flattened, by address (shared parts once).
    seen: HashMap<*const Sx, Slot>,
    owner: u32,
}

impl Flat {
    fn slot(&mut self, s: &Rc<Sx>) -> Result<Slot, OuterPoint> {
        let key = Rc::as_ptr(s);
        if let Some(&slot) = self.seen.get(&key) {
            return Ok(slot);
        }
        let op = stacker::maybe_grow(64 * 1024, 1024 * 1024, || -> Result<FOp, OuterPoint> {
            Ok(match &**s {
                Sx::Coord(a, o) => {
                    if *o != self.owner {
                        return Err(OuterPoint);
                    }
                    FOp::Coord(*a)
                }
                Sx::Const(c) => FOp::Const(*c),
                Sx::Un(u, a) => FOp::Un(*u, self.slot(a)?),
                Sx::Bin(b, x, y) => {
                    let x = self.slot(x)?;
                    FOp::Bin(*b, x, self.slot(y)?)
                }
                Sx::Length(v) => FOp::Length(self.list(v)?),
                Sx::Noise(v) => FOp::Noise(self.list(v)?),
                Sx::Voronoi(v) => FOp::Voronoi(self.list(v)?),
                Sx::Hash(v) => FOp::Hash(self.list(v)?),
                Sx::Mix(a, b, t) => {
                    let (a, b) = (self.slot(a)?, self.slot(b)?);
                    FOp::Mix(a, b, self.slot(t)?)
                }
                Sx::Distance(id, q) => {
                    let l = self.list(q)?;
                    FOp::Distance(*id, [l[0], l[1], l[2]])
                }
            })
        })?;
        let slot = self.ops.len() as Slot;
        self.ops.push(op);
        self.seen.insert(key, slot);
        Ok(slot)
    }

    fn list(&mut self, v: &[Rc<Sx>]) -> Result<Vec<Slot>, OuterPoint> {
        v.iter().map(|s| self.slot(s)).collect()
    }
}
