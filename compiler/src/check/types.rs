//! Types and constant values of the language, and the per-point values of a `field` (`Sx`
//! expressions, built by `field.rs`).

use crate::scene::field::{FBin, FUn};
use crate::scene::NodeId;
use std::fmt;
use std::rc::Rc;

/// The types a value can have. `int` converts to `float` wherever a float is expected (and
/// a list of ints to a list of floats).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Type {
    Int,
    Float,
    Bool,
    Vec2,
    Vec3,
    Angle,
    Str,
    Shape,
    /// A 2D signed distance in the xy plane (docs/language.md, "2D profiles"): made into a
    /// shape by `extrude`, `revolve`, ….
    Profile,
    /// A colour field (docs/language.md, "Colour fields"): `field { … }` whose body is a vec3
    /// of the point, a material's `color` that varies over the surface. Not a list element.
    ColourField,
    /// A path a profile is swept along (`polyline`, `helix`, `bezier`, `arc3`; docs/language.md,
    /// "Sweeps").
    Path,
    /// A list of values of the element type, which is never a list ([`Type::list`]).
    List(&'static Type),
}

/// The element types of lists, for [`Type::list`]: every type but a list.
static ELEMENTS: [Type; 10] = [
    Type::Int,
    Type::Float,
    Type::Bool,
    Type::Vec2,
    Type::Vec3,
    Type::Angle,
    Type::Str,
    Type::Shape,
    Type::Profile,
    Type::Path,
];

impl Type {
    /// The type of lists of `elem`; `None` where `elem` is itself a list (lists do not nest).
    pub fn list(elem: Type) -> Option<Type> {
        ELEMENTS.iter().find(|t| **t == elem).map(Type::List)
    }

    /// The element type of a list type.
    pub fn elem(self) -> Option<Type> {
        match self {
            Type::List(e) => Some(*e),
            _ => None,
        }
    }

    /// The type named `name` in a declaration: a type's name, or `[name]` for a list.
    pub fn from_name(name: &str) -> Option<Type> {
        if let Some(inner) = name.strip_prefix('[').and_then(|n| n.strip_suffix(']')) {
            return Type::list(Type::from_name(inner)?);
        }
        Some(match name {
            "int" => Type::Int,
            "float" => Type::Float,
            "bool" => Type::Bool,
            "vec2" => Type::Vec2,
            "vec3" => Type::Vec3,
            "angle" => Type::Angle,
            "string" => Type::Str,
            "shape" => Type::Shape,
            "profile" => Type::Profile,
            "color_field" => Type::ColourField,
            "path" => Type::Path,
            _ => return None,
        })
    }

    /// All type names, for suggestions.
    pub const NAMES: [&'static str; 11] = [
        "int",
        "float",
        "bool",
        "vec2",
        "vec3",
        "angle",
        "string",
        "shape",
        "profile",
        "color_field",
        "path",
    ];

    /// True when a value of type `self` may be passed where `want` is expected.
    pub fn fits(self, want: Type) -> bool {
        match (self, want) {
            (Type::List(a), Type::List(b)) => a.fits(*b),
            _ => self == want || (self == Type::Int && want == Type::Float),
        }
    }
}

impl fmt::Display for Type {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(match self {
            Type::Int => "int",
            Type::Float => "float",
            Type::Bool => "bool",
            Type::Vec2 => "vec2",
            Type::Vec3 => "vec3",
            Type::Angle => "angle",
            Type::Str => "string",
            Type::Shape => "shape",
            Type::Profile => "profile",
            Type::ColourField => "color_field",
            Type::Path => "path",
            Type::List(elem) => return write!(f, "[{elem}]"),
        })
    }
}

/// A constant value. `Unknown` is a value of a known type that is not computed (while a
/// function body is checked on its own); `Error` is the result of an expression that was
/// already reported, and is accepted everywhere so that one mistake is reported once.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Int(i64),
    Float(f64),
    Bool(bool),
    Vec2([f64; 2]),
    Vec3([f64; 3]),
    /// In radians.
    Angle(f64),
    Str(Rc<str>),
    Shape(NodeId),
    /// A 2D profile: a node of the scene graph whose distance reads only x and y.
    Profile(NodeId),
    /// A list: its element type and its elements (each of that type, or `Error`).
    List(&'static Type, Rc<[Value]>),
    /// A colour field: red, green and blue of the point as a field's three values.
    Colour(Rc<crate::scene::field::FieldFn>),
    /// A path of `sweep`.
    Path(std::sync::Arc<crate::scene::Path>),
    /// A number or vector that depends on the point `p` of a `field` (1, 2 or 3 components):
    /// an expression evaluated per point, not a constant.
    Point(Comps),
    Unknown(Type),
    Error,
}

impl Value {
    /// The name of the value's type for messages (`?` for an error value).
    pub fn type_name(&self) -> String {
        self.ty().map_or("?".into(), |t| t.to_string())
    }

    /// The value's type; `None` for `Error`.
    pub fn ty(&self) -> Option<Type> {
        Some(match self {
            Value::Int(_) => Type::Int,
            Value::Float(_) => Type::Float,
            Value::Bool(_) => Type::Bool,
            Value::Vec2(_) => Type::Vec2,
            Value::Vec3(_) => Type::Vec3,
            Value::Angle(_) => Type::Angle,
            Value::Str(_) => Type::Str,
            Value::Shape(_) => Type::Shape,
            Value::Profile(_) => Type::Profile,
            Value::Colour(_) => Type::ColourField,
            Value::Path(_) => Type::Path,
            Value::List(elem, _) => Type::List(elem),
            Value::Point(c) => match c.len() {
                1 => Type::Float,
                2 => Type::Vec2,
                _ => Type::Vec3,
            },
            Value::Unknown(t) => *t,
            Value::Error => return None,
        })
    }

    /// True for values that are not computed (unknown or error).
    pub fn is_abstract(&self) -> bool {
        matches!(self, Value::Unknown(_) | Value::Error)
    }

    /// Converts to `want` if the type fits (`int` to `float`); `None` if it does not.
    pub fn coerce(self, want: Type) -> Option<Value> {
        match (self, want) {
            (Value::Error, _) => Some(Value::Error),
            (Value::Int(i), Type::Float) => Some(Value::Float(i as f64)),
            (Value::Unknown(t), w) if t.fits(w) => Some(Value::Unknown(w)),
            (Value::List(elem, items), Type::List(w)) if elem.fits(*w) => {
                if elem == w {
                    return Some(Value::List(elem, items));
                }
                let items: Option<Vec<Value>> =
                    items.iter().map(|v| v.clone().coerce(*w)).collect();
                Some(Value::List(w, items?.into()))
            }
            // A per-point number is a float already.
            (Value::Point(c), Type::Float) if c.len() == 1 => Some(Value::Point(c)),
            (v, w) if v.ty() == Some(w) => Some(v),
            _ => None,
        }
    }

    /// The value written as in the language, for a number, vector, angle, bool, string or
    /// list of them (a long list shortened); `None` for shapes, profiles, colour fields,
    /// per-point values and values not computed. Floats are shown to 10 significant digits, angles in degrees.
    pub fn show(&self) -> Option<String> {
        use crate::scene::dump_num as num;
        let join = |xs: &[f64]| xs.iter().map(|&x| num(x)).collect::<Vec<_>>().join(", ");
        Some(match self {
            Value::Int(i) => i.to_string(),
            Value::Float(f) => num(*f),
            Value::Bool(b) => b.to_string(),
            Value::Vec2(v) => format!("({})", join(v)),
            Value::Vec3(v) => format!("({})", join(v)),
            Value::Angle(a) => format!("{}deg", num(a.to_degrees())),
            Value::Str(s) => format!("{:?}", &**s),
            Value::List(_, items) => {
                const SHOWN: usize = 16;
                let mut parts = items
                    .iter()
                    .take(SHOWN)
                    .map(Value::show)
                    .collect::<Option<Vec<_>>>()?;
                if items.len() > SHOWN {
                    parts.push(format!("… {} in all", items.len()));
                }
                format!("[{}]", parts.join(", "))
            }
            Value::Shape(_)
            | Value::Profile(_)
            | Value::Colour(_)
            | Value::Path(_)
            | Value::Point(_)
            | Value::Unknown(_)
            | Value::Error => return None,
        })
    }

    /// The number in an int or float (0 for others; callers check types first).
    pub fn num(&self) -> f64 {
        match self {
            Value::Int(i) => *i as f64,
            Value::Float(f) | Value::Angle(f) => *f,
            _ => 0.0,
        }
    }

    /// The components of a vec3 (zeros for others).
    pub fn v3(&self) -> [f64; 3] {
        match self {
            Value::Vec3(v) => *v,
            _ => [0.0; 3],
        }
    }

    /// Every float component, for range and finiteness checks.
    pub fn components(&self) -> Vec<f64> {
        match self {
            Value::Int(i) => vec![*i as f64],
            Value::Float(f) | Value::Angle(f) => vec![*f],
            Value::Vec2(v) => v.to_vec(),
            Value::Vec3(v) => v.to_vec(),
            _ => Vec::new(),
        }
    }
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            Value::Int(i) => write!(f, "{i}"),
            Value::Float(x) => write!(f, "{x}"),
            Value::Bool(b) => write!(f, "{b}"),
            Value::Vec2(v) => write!(f, "({}, {})", v[0], v[1]),
            Value::Vec3(v) => write!(f, "({}, {}, {})", v[0], v[1], v[2]),
            Value::Angle(a) => write!(f, "{}deg", a.to_degrees()),
            Value::Str(s) => write!(f, "{s:?}"),
            Value::Shape(_) => write!(f, "<shape>"),
            Value::Profile(_) => write!(f, "<profile>"),
            Value::Colour(_) => write!(f, "<color_field>"),
            Value::Path(_) => write!(f, "<path>"),
            Value::List(_, items) => {
                // A long list is shown by its first elements and its length.
                const SHOWN: usize = 4;
                let head: Vec<String> = items.iter().take(SHOWN).map(|v| v.to_string()).collect();
                if items.len() > SHOWN {
                    write!(f, "[{}, … ({} elements)]", head.join(", "), items.len())
                } else {
                    write!(f, "[{}]", head.join(", "))
                }
            }
            Value::Point(_) => write!(f, "<{} of the point>", self.ty().unwrap_or(Type::Float)),
            Value::Unknown(t) => write!(f, "<{t}>"),
            Value::Error => write!(f, "<error>"),
        }
    }
}

/// A call of a user function on concrete arguments, as the key of the checker's memo of
/// calls: each argument by its bits or, for a string or list, its contents. Only short
/// strings and lists make keys ([`CallKey::new`]), so that a key costs little to build,
/// hash, compare and keep whatever the arguments.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct CallKey {
    name: String,
    args: Vec<KeyArg>,
}

impl CallKey {
    /// The key of a call of `name` on `args`; none where an argument is a string or list
    /// longer than [`SHORT`], a colour field or a per-point value: such a call is evaluated
    /// each time (keyed by its contents, a call on a list of 20 000 elements in a loop cost
    /// time and memory in the square of the length).
    pub fn new<'a>(name: &str, args: impl IntoIterator<Item = &'a Value>) -> Option<CallKey> {
        Some(CallKey {
            name: name.to_string(),
            args: args
                .into_iter()
                .map(KeyArg::of)
                .collect::<Option<Vec<_>>>()?,
        })
    }
}

/// Strings and lists up to this length are keys by their contents.
pub const SHORT: usize = 16;

/// One argument of a [`CallKey`].
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
enum KeyArg {
    /// A number, bool, vector, shape or profile: its kind and bits.
    Bits(u8, [u64; 3]),
    Unknown(Type),
    Error,
    /// A short string, by its text.
    Text(Rc<str>),
    /// A short list: its element type and its elements' keys.
    List(Type, Vec<KeyArg>),
}

impl KeyArg {
    fn of(v: &Value) -> Option<KeyArg> {
        let bits = |kind, b: [u64; 3]| Some(KeyArg::Bits(kind, b));
        match v {
            Value::Int(i) => bits(0, [*i as u64, 0, 0]),
            Value::Float(x) => bits(1, [x.to_bits(), 0, 0]),
            Value::Bool(b) => bits(2, [u64::from(*b), 0, 0]),
            Value::Vec2(p) => bits(3, [p[0].to_bits(), p[1].to_bits(), 0]),
            Value::Vec3(p) => bits(4, p.map(f64::to_bits)),
            Value::Angle(a) => bits(5, [a.to_bits(), 0, 0]),
            Value::Shape(id) => bits(6, [u64::from(id.0), 0, 0]),
            Value::Profile(id) => bits(7, [u64::from(id.0), 0, 0]),
            Value::Unknown(t) => Some(KeyArg::Unknown(*t)),
            Value::Error => Some(KeyArg::Error),
            Value::Str(s) if s.len() <= SHORT => Some(KeyArg::Text(Rc::clone(s))),
            Value::List(elem, items) if items.len() <= SHORT => Some(KeyArg::List(
                **elem,
                items.iter().map(KeyArg::of).collect::<Option<_>>()?,
            )),
            Value::Str(_)
            | Value::List(..)
            | Value::Colour(_)
            | Value::Path(_)
            | Value::Point(_) => None,
        }
    }
}

/// One scalar of a per-point value: an expression tree whose shared parts are shared `Rc`s.
#[derive(Clone, PartialEq)]
pub enum Sx {
    /// A coordinate of the point of field number `.1` (fields nest).
    Coord(u8, u32),
    Const(f64),
    Un(FUn, Rc<Sx>),
    Bin(FBin, Rc<Sx>, Rc<Sx>),
    Length(Vec<Rc<Sx>>),
    Distance(NodeId, [Rc<Sx>; 3]),
    Noise(Vec<Rc<Sx>>),
    Voronoi(Vec<Rc<Sx>>),
    Hash(Vec<Rc<Sx>>),
    /// mix(a, b, t) = a + (b − a)·t, kept whole so that its range is known to lie between
    /// a's and b's where t is within [0, 1].
    Mix(Rc<Sx>, Rc<Sx>, Rc<Sx>),
}

impl fmt::Debug for Sx {
    /// Only the kind: a tree with shared parts printed in full could be exponentially long.
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("<per-point>")
    }
}

/// The components of a per-point value (1: float, 2: vec2, 3: vec3).
pub type Comps = Rc<[Rc<Sx>]>;
