//! A scene's parameters (`param width = 40 in 10..100 "Box width (mm)";`): their values,
//! defaults, the values they accept and their descriptions, as the checker found them; what
//! `sdfc check` lists, the viewer's panel and Python's `Scene.params` read.

use std::fmt;

/// A parameter's value: a number, an int, a bool or a string.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamValue {
    Float(f64),
    Int(i64),
    Bool(bool),
    Str(String),
}

impl ParamValue {
    /// The name of its type, as the language writes it.
    pub fn type_name(&self) -> &'static str {
        match self {
            ParamValue::Float(_) => "float",
            ParamValue::Int(_) => "int",
            ParamValue::Bool(_) => "bool",
            ParamValue::Str(_) => "string",
        }
    }

    /// `text` (as given on a command line) read as a value of this one's type.
    pub fn parse_like(&self, text: &str) -> Option<ParamValue> {
        let t = text.trim();
        Some(match self {
            ParamValue::Float(_) => {
                ParamValue::Float(t.parse::<f64>().ok().filter(|x| x.is_finite())?)
            }
            ParamValue::Int(_) => ParamValue::Int(t.parse().ok()?),
            ParamValue::Bool(_) => ParamValue::Bool(match t {
                "true" => true,
                "false" => false,
                _ => return None,
            }),
            ParamValue::Str(_) => ParamValue::Str(text.to_string()),
        })
    }

    /// The number it holds (an int as a float); `None` for a bool or a string.
    pub fn number(&self) -> Option<f64> {
        match self {
            ParamValue::Float(x) => Some(*x),
            ParamValue::Int(i) => Some(*i as f64),
            _ => None,
        }
    }
}

impl fmt::Display for ParamValue {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            ParamValue::Float(x) => f.write_str(&crate::diagnostics::number(*x, 6)),
            ParamValue::Int(i) => write!(f, "{i}"),
            ParamValue::Bool(b) => write!(f, "{b}"),
            ParamValue::Str(s) => write!(f, "{s:?}"),
        }
    }
}

/// The values a parameter accepts.
#[derive(Debug, Clone, PartialEq)]
pub enum Accepts {
    /// Any value of its type.
    Any,
    /// A number or int from `lo` to `hi`, a slider's `step` apart where given.
    Range { lo: f64, hi: f64, step: Option<f64> },
    /// One of these strings.
    Choices(Vec<String>),
}

impl fmt::Display for Accepts {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let n = |x: f64| crate::diagnostics::number(x, 6);
        match self {
            Accepts::Any => f.write_str("any value"),
            Accepts::Range { lo, hi, step } => {
                write!(f, "{}..{}", n(*lo), n(*hi))?;
                match step {
                    Some(s) => write!(f, " step {}", n(*s)),
                    None => Ok(()),
                }
            }
            Accepts::Choices(c) => {
                let quoted: Vec<String> = c.iter().map(|s| format!("{s:?}")).collect();
                write!(f, "[{}]", quoted.join(", "))
            }
        }
    }
}

/// One parameter of a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    pub name: String,
    /// The value the scene was checked with: the default, or the one given from outside.
    pub value: ParamValue,
    pub default: ParamValue,
    pub accepts: Accepts,
    /// The description ("" where none is given).
    pub doc: String,
    /// Where it is declared (its name).
    pub span: crate::span::Span,
}

impl Parameter {
    /// Whether `v` is among the values it accepts (its type is the default's).
    pub fn accepts(&self, v: &ParamValue) -> bool {
        match (&self.accepts, v) {
            (Accepts::Any, _) => true,
            (Accepts::Range { lo, hi, .. }, v) => v.number().is_some_and(|x| *lo <= x && x <= *hi),
            (Accepts::Choices(c), ParamValue::Str(s)) => c.contains(s),
            (Accepts::Choices(_), _) => false,
        }
    }
}
