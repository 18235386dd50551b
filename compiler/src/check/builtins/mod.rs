//! The built-in functions and record schemas: signatures (types, defaults, valid ranges) and
//! their constant evaluation. Shape builtins add nodes to the scene graph.

macro_rules! sigs {
    ($([$($p:expr),*] $(rest $rest:tt)? -> $ret:expr => $imp:expr;)*) => {
        &[$(Sig { params: &[$($p),*], rest: sigs!(@rest $($rest)?), ret: $ret, imp: Imp::Fn($imp) }),*]
    };
    (@rest) => { false };
    (@rest $t:tt) => { true };
}

mod maths;
mod mesh;
mod records;
mod refusal;
mod shapes;
mod table;

use super::types::{Type, Value};
use super::LoadError;
use crate::limits::{Limit, Limits};
use crate::lower::hash_of;
use crate::prim::{Args, Kind, Prim, PrimRef};
pub use crate::prim::{Def, Range};
use crate::scene::{
    Camera, Combine, Feature, Graph, Material, Node, NodeId, Path, Pbr, Settings, Smooth, V3,
};
use crate::span::Span;
pub use records::*;
pub use refusal::{Expected, MeshRefusal, OutOfRange, Refusal};

impl Def {
    /// The default as a value; `None` for a required parameter.
    pub fn value(self) -> Option<Value> {
        Some(match self {
            Def::Req => return None,
            Def::Num(f) => Value::Float(f),
            Def::Int(i) => Value::Int(i),
            Def::Bool(b) => Value::Bool(b),
            Def::V3(v) => Value::Vec3(v),
            Def::Text(s) => Value::Str(s.into()),
            Def::Deg(d) => Value::Angle(d.to_radians()),
        })
    }
}

impl Range {
    /// The range with its resource limit, if any, replaced by the limit's value.
    pub fn resolve(self, limits: &Limits) -> Range {
        match self {
            Range::Limited(lo, l) => Range::Within(lo, limits.get(l) as f64),
            other => other,
        }
    }

    /// The resource limit a value beyond the top of this range exceeds.
    pub fn limit(self, v: &Value, limits: &Limits) -> Option<Limit> {
        match self {
            Range::Limited(_, l) => {
                let top = limits.get(l) as f64;
                v.components().iter().any(|&x| x > top).then_some(l)
            }
            _ => None,
        }
    }

    /// Checks a concrete value; says what was expected when it is out of range.
    pub fn check(self, v: &Value, limits: &Limits) -> Result<(), OutOfRange> {
        let range = self.resolve(limits);
        let c = v.components();
        let expected = match range {
            Range::Any | Range::Limited(..) | Range::Chars(_) => return Ok(()),
            Range::Pos if c.iter().all(|&x| x > 0.0) => return Ok(()),
            Range::NonNeg if c.iter().all(|&x| x >= 0.0) => return Ok(()),
            Range::Unit if c.iter().all(|&x| (0.0..=1.0).contains(&x)) => return Ok(()),
            Range::Within(lo, hi) if c.iter().all(|&x| x >= lo && x <= hi) => return Ok(()),
            Range::NonZero if c.iter().any(|&x| x != 0.0) => return Ok(()),
            Range::OneOf(opts) => match v {
                Value::Str(s) if !opts.contains(&&**s) => Expected::OneOf(opts),
                _ => return Ok(()),
            },
            Range::Pos => Expected::Positive,
            Range::NonNeg => Expected::NonNegative,
            Range::Unit => Expected::Unit,
            Range::Within(lo, hi) => Expected::Within {
                lo,
                hi,
                angle: matches!(v, Value::Angle(_)),
            },
            Range::NonZero => Expected::NonZero,
        };
        Err(OutOfRange {
            expected,
            vector: matches!(v, Value::Vec2(_) | Value::Vec3(_)),
        })
    }
}

/// One parameter of a builtin or record.
pub type P = crate::prim::Param<Type>;

const fn p(name: &'static str, ty: Type, def: Def, range: Range) -> P {
    crate::prim::param(name, ty, def, range)
}

const fn shape(name: &'static str) -> P {
    p(name, Type::Shape, Def::Req, Range::Any)
}

/// The evaluation of one overload on bound, in-range, concrete arguments.
#[derive(Clone, Copy)]
pub enum Imp {
    /// A function of the arguments.
    Fn(fn(&mut Build<'_, '_>, &[Value]) -> Result<Value, Refusal>),
    /// A primitive of the table: its node, once its checks pass.
    Prim(&'static Prim),
}

impl std::fmt::Debug for Imp {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            Imp::Fn(_) => f.write_str("Fn"),
            Imp::Prim(p) => write!(f, "Prim({})", p.name),
        }
    }
}

impl Imp {
    /// Evaluates the overload on its arguments.
    pub fn call(self, b: &mut Build<'_, '_>, a: &[Value]) -> Result<Value, Refusal> {
        match self {
            Imp::Fn(f) => f(b, a),
            Imp::Prim(prim) => {
                let three = |v: &Value| {
                    let c = v.components();
                    [0, 1, 2].map(|i| c.get(i).copied().unwrap_or(0.0))
                };
                let mut args = Args(a.iter().map(three).collect());
                for (i, v) in a.iter().enumerate() {
                    if let Value::List(_, items) = v {
                        args.0[i] = [items.len() as f64, 0.0, 0.0];
                        args.0.extend(items.iter().map(three));
                    }
                }
                if let Some(why) = (prim.check)(&args) {
                    return Err(Refusal::Primitive(why));
                }
                let node = Node::Prim {
                    prim: PrimRef(prim),
                    args,
                };
                if prim.profile {
                    b.profile(node)
                } else {
                    b.node(node)
                }
            }
        }
    }
}

/// One overload.
#[derive(Debug, Clone)]
pub struct Sig {
    pub params: &'static [P],
    /// The last parameter may be repeated (variadic).
    pub rest: bool,
    pub ret: Type,
    pub imp: Imp,
}

/// A builtin function with its overloads, tried in order.
#[derive(Debug, Clone, Copy)]
pub struct Builtin {
    pub name: &'static str,
    pub sigs: &'static [Sig],
}

/// What a builtin may touch: the scene graph, the span of the call for the nodes it adds,
/// the files `mesh` reads, the limits, and the warnings it gives.
#[derive(Debug)]
pub struct Build<'a, 'l> {
    pub graph: &'a mut Graph,
    pub span: Span,
    /// The files `mesh(path)` reads (none: no file can be read).
    pub files: Option<&'a mut super::Files<'l>>,
    pub limits: &'a Limits,
    pub warnings: Vec<crate::diagnostics::Diagnostic>,
    /// Evaluation steps the `fuel` limit leaves, and those the call has taken (spent by the
    /// evaluator after it: more than were left reports the limit at the call).
    pub fuel_left: u64,
    pub steps: u64,
}

impl Build<'_, '_> {
    /// The name and the bytes of the file `path` (relative to the calling file), read through
    /// the caller's loader.
    fn read_bytes(&mut self, path: &str) -> Result<(String, Vec<u8>), LoadError> {
        let no_files = || LoadError::NoFiles { path: path.into() };
        let files = self.files.as_deref_mut().ok_or_else(no_files)?;
        let from = files
            .names
            .get(self.span.file.0 as usize)
            .cloned()
            .unwrap_or_default();
        let loader = files.loader.as_deref_mut().ok_or_else(no_files)?;
        loader.load_bytes(&from, path)
    }

    fn node(&mut self, node: Node) -> Result<Value, Refusal> {
        Ok(Value::Shape(self.graph.add(node, self.span)))
    }

    /// Adds a node of a profile (whose distance reads only x and y).
    fn profile(&mut self, node: Node) -> Result<Value, Refusal> {
        Ok(Value::Profile(self.graph.add(node, self.span)))
    }
}

/// The result of a builder of shapes as a profile: the 2D operations add the same nodes as
/// the 3D ones, in the plane z = 0.
fn flat(v: Result<Value, Refusal>) -> Result<Value, Refusal> {
    Ok(match v? {
        Value::Shape(id) => Value::Profile(id),
        other => other,
    })
}

const fn prof(name: &'static str) -> P {
    p(name, Type::Profile, Def::Req, Range::Any)
}

fn sh(v: &Value) -> NodeId {
    match v {
        Value::Shape(id) | Value::Profile(id) => *id,
        _ => NodeId(0),
    }
}

/// Renders a signature for notes: `sphere(radius: float = 1) -> shape`.
pub fn signature(name: &str, sig: &Sig) -> String {
    let params: Vec<String> = sig
        .params
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let rest = if sig.rest && i + 1 == sig.params.len() {
                "..."
            } else {
                ""
            };
            match p.def.value() {
                Some(v) => format!("{}{rest}: {} = {v}", p.name, p.ty),
                None => format!("{}{rest}: {}", p.name, p.ty),
            }
        })
        .collect();
    format!("{name}({}) -> {}", params.join(", "), sig.ret)
}

use Def::*;
use Range::*;
use Type::{Angle as A, Bool as B, Float as F, Int as I, Shape as S, Str, Vec2 as V2, Vec3 as V};

/// A list of shapes, `[shape]`.
const LS: Type = Type::List(&Type::Shape);
/// A list of profiles, `[profile]`.
const LP: Type = Type::List(&Type::Profile);
/// A profile.
const PR: Type = Type::Profile;

/// The name of the time, in seconds, that every expression may read (docs/animation.md): a
/// constant, parameter or loop variable of that name hides it.
pub const TIME: &str = "t";

/// The name of the unit surface normal at the hit that a colour field's body may read beside
/// its point `p` (docs/language.md, "Colour fields"); a name of the program hides it.
pub const NORMAL: &str = "n";

/// The built-in constants, read like `t`: a constant, parameter or loop variable of the
/// same name hides them.
pub const CONSTANTS: &[(&str, f64)] =
    &[("pi", std::f64::consts::PI), ("tau", std::f64::consts::TAU)];

/// The value of the built-in constant `name`, if it is one.
pub fn constant(name: &str) -> Option<f64> {
    CONSTANTS.iter().find(|(n, _)| *n == name).map(|(_, v)| *v)
}

/// Every builtin function: those written here and the primitives of the table (`prim/`).
pub static BUILTINS: std::sync::LazyLock<Vec<Builtin>> = std::sync::LazyLock::new(|| {
    let prims = crate::prim::all().map(|prim| {
        let params: Vec<P> = prim
            .params
            .iter()
            .map(|q| p(q.name, kind_type(q.ty), q.def, q.range))
            .collect();
        let sig = Sig {
            params: Vec::leak(params),
            rest: false,
            ret: if prim.profile {
                Type::Profile
            } else {
                Type::Shape
            },
            imp: Imp::Prim(prim),
        };
        Builtin {
            name: prim.name,
            sigs: Vec::leak(vec![sig]),
        }
    });
    // An entry named like a builtin before it is one more overload of that builtin.
    let mut all: Vec<Builtin> = [table::SHAPES, maths::MATHS].concat();
    for prim in prims {
        match all.iter_mut().find(|b| b.name == prim.name) {
            Some(b) => b.sigs = Vec::leak([b.sigs, prim.sigs].concat()),
            None => all.push(prim),
        }
    }
    all
});

/// The type of a primitive's parameter.
fn kind_type(k: Kind) -> Type {
    match k {
        Kind::Float => Type::Float,
        Kind::Int => Type::Int,
        Kind::Angle => Type::Angle,
        Kind::Vec2 => Type::Vec2,
        Kind::Vec3 => Type::Vec3,
        Kind::Points => Type::List(&Type::Vec3),
    }
}

/// Looks a builtin up by name.
pub fn builtin(name: &str) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name)
}
