//! Unary and binary operators on constant values, with their typing rules.

use super::types::{Type, Value};
use crate::syntax::ast::{BinOp, UnOp};

/// Why an operator could not be applied.
#[derive(Debug, Clone, PartialEq)]
pub enum OpError {
    /// The operand types do not go with the operator.
    Types(String),
    /// Division by zero, or an integer remainder by zero.
    DivZero,
    /// Integer overflow.
    Overflow,
}

/// Applies a unary operator.
pub fn unary(op: UnOp, v: &Value) -> Result<Value, OpError> {
    Ok(match (op, v) {
        (_, Value::Error) => Value::Error,
        (UnOp::Neg, Value::Int(i)) => Value::Int(i.checked_neg().ok_or(OpError::Overflow)?),
        (UnOp::Neg, Value::Float(f)) => Value::Float(-f),
        (UnOp::Neg, Value::Angle(f)) => Value::Angle(-f),
        (UnOp::Neg, Value::Vec2(a)) => Value::Vec2([-a[0], -a[1]]),
        (UnOp::Neg, Value::Vec3(a)) => Value::Vec3([-a[0], -a[1], -a[2]]),
        (
            UnOp::Neg,
            Value::Unknown(t @ (Type::Int | Type::Float | Type::Angle | Type::Vec2 | Type::Vec3)),
        ) => Value::Unknown(*t),
        (UnOp::Not, Value::Bool(b)) => Value::Bool(!b),
        (UnOp::Not, Value::Unknown(Type::Bool)) => Value::Unknown(Type::Bool),
        (UnOp::Neg, other) => {
            return Err(OpError::Types(format!(
                "cannot negate `{}`",
                other.type_name()
            )))
        }
        (UnOp::Not, other) => {
            return Err(OpError::Types(format!(
                "`!` needs a bool, found `{}`",
                other.type_name()
            )))
        }
    })
}

/// The result type of `a op b`, or `None` when the operator does not apply.
pub fn binary_type(op: BinOp, a: Type, b: Type) -> Option<Type> {
    use BinOp::*;
    use Type::*;
    let num = |t: Type| matches!(t, Int | Float);
    let vec = |t: Type| matches!(t, Vec2 | Vec3);
    // Arithmetic of two numbers: an int where both are.
    let numbers = |a: Type, b: Type| match (a, b) {
        (Int, Int) => Some(Int),
        _ if num(a) && num(b) => Some(Float),
        _ => None,
    };
    // Arithmetic of vectors of one size, componentwise, or of a vector and a number, which
    // broadcasts over its components (either order), as in GLSL: `0.5 + 0.5 * n` is
    // `vec3(0.5) + 0.5 * n`.
    let vectors = |a: Type, b: Type| match (a, b) {
        (v, x) | (x, v) if vec(v) && num(x) => Some(v),
        _ if vec(a) && a == b => Some(a),
        _ => None,
    };
    match op {
        Or | And => (a == Bool && b == Bool).then_some(Bool),
        Eq | Ne => (a == b || (num(a) && num(b)))
            .then_some(Bool)
            .filter(|_| a != Shape && a.elem().is_none()),
        Lt | Le | Gt | Ge => ((num(a) && num(b)) || (a == Angle && b == Angle)).then_some(Bool),
        // Lists concatenate, ints among floats becoming floats as in a list literal.
        Add if a.elem().is_some() && b.elem().is_some() => {
            [b, a].into_iter().find(|w| a.fits(*w) && b.fits(*w))
        }
        Add | Sub => match (a, b) {
            (Angle, Angle) => Some(Angle),
            _ => numbers(a, b).or_else(|| vectors(a, b)),
        },
        Mul => match (a, b) {
            (Angle, x) | (x, Angle) if num(x) => Some(Angle),
            _ => numbers(a, b).or_else(|| vectors(a, b)),
        },
        // `5 / 2` is 2.5: whole numbers divide with `div(a, b)`.
        Div => match (a, b) {
            _ if num(a) && num(b) => Some(Float),
            (Angle, x) if num(x) => Some(Angle),
            (Angle, Angle) => Some(Float),
            _ => vectors(a, b),
        },
        Rem => numbers(a, b),
    }
}

fn comps(v: &Value) -> Vec<f64> {
    v.components()
}

fn rebuild(like: Type, c: Vec<f64>) -> Value {
    match like {
        Type::Vec2 => Value::Vec2([c[0], c[1]]),
        Type::Vec3 => Value::Vec3([c[0], c[1], c[2]]),
        Type::Angle => Value::Angle(c[0]),
        Type::Int => Value::Int(c[0] as i64),
        _ => Value::Float(c[0]),
    }
}

/// Applies a binary operator.
pub fn binary(op: BinOp, a: &Value, b: &Value) -> Result<Value, OpError> {
    let (Some(ta), Some(tb)) = (a.ty(), b.ty()) else {
        return Ok(Value::Error);
    };
    let Some(ty) = binary_type(op, ta, tb) else {
        return Err(OpError::Types(format!(
            "`{}` cannot be applied to `{ta}` and `{tb}`",
            op.symbol()
        )));
    };
    if a.is_abstract() || b.is_abstract() {
        return Ok(Value::Unknown(ty));
    }
    if let (Value::List(..), Value::List(..)) = (a, b) {
        let (Some(Value::List(_, x)), Some(Value::List(elem, y))) =
            (a.clone().coerce(ty), b.clone().coerce(ty))
        else {
            return Ok(Value::Error);
        };
        return Ok(Value::List(
            elem,
            x.iter().chain(y.iter()).cloned().collect(),
        ));
    }
    if op == BinOp::Div && comps(b).contains(&0.0) {
        return Err(OpError::DivZero);
    }
    if let (Value::Int(x), Value::Int(y)) = (a, b) {
        if ty == Type::Int {
            return int_op(op, *x, *y).map(Value::Int);
        }
    }
    use BinOp::*;
    Ok(match op {
        Or | And => {
            let (x, y) = (*a == Value::Bool(true), *b == Value::Bool(true));
            Value::Bool(if op == Or { x || y } else { x && y })
        }
        Eq | Ne => {
            let eq = if ta == Type::Str || ta == Type::Bool {
                a == b
            } else {
                comps(a) == comps(b)
            };
            Value::Bool(eq == (op == Eq))
        }
        Lt | Le | Gt | Ge => {
            let (x, y) = (a.num(), b.num());
            Value::Bool(match op {
                Lt => x < y,
                Le => x <= y,
                Gt => x > y,
                _ => x >= y,
            })
        }
        _ => {
            let (ca, cb) = (comps(a), comps(b));
            let n = ca.len().max(cb.len());
            let at = |c: &Vec<f64>, i: usize| if c.len() == 1 { c[0] } else { c[i] };
            let f = |x: f64, y: f64| match op {
                Add => x + y,
                Sub => x - y,
                Mul => x * y,
                Div => x / y,
                _ => x % y,
            };
            rebuild(ty, (0..n).map(|i| f(at(&ca, i), at(&cb, i))).collect())
        }
    })
}

fn int_op(op: BinOp, x: i64, y: i64) -> Result<i64, OpError> {
    let overflow = || OpError::Overflow;
    match op {
        BinOp::Add => x.checked_add(y).ok_or_else(overflow),
        BinOp::Sub => x.checked_sub(y).ok_or_else(overflow),
        BinOp::Mul => x.checked_mul(y).ok_or_else(overflow),
        BinOp::Rem if y == 0 => Err(OpError::DivZero),
        _ => x.checked_rem(y).ok_or_else(overflow),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arithmetic_promotes_and_checks() {
        assert_eq!(
            binary(BinOp::Add, &Value::Int(2), &Value::Int(3)),
            Ok(Value::Int(5))
        );
        assert_eq!(
            binary(BinOp::Add, &Value::Int(2), &Value::Float(0.5)),
            Ok(Value::Float(2.5))
        );
        assert_eq!(
            binary(BinOp::Div, &Value::Int(7), &Value::Int(2)),
            Ok(Value::Float(3.5))
        );
        assert_eq!(
            binary(BinOp::Div, &Value::Float(1.0), &Value::Int(0)),
            Err(OpError::DivZero)
        );
        assert_eq!(
            binary(BinOp::Div, &Value::Int(7), &Value::Int(0)),
            Err(OpError::DivZero)
        );
        assert_eq!(
            binary(
                BinOp::Mul,
                &Value::Vec3([1.0, 2.0, 3.0]),
                &Value::Float(2.0)
            ),
            Ok(Value::Vec3([2.0, 4.0, 6.0]))
        );
        assert_eq!(
            binary(
                BinOp::Add,
                &Value::Float(0.5),
                &Value::Vec3([1.0, 2.0, 3.0])
            ),
            Ok(Value::Vec3([1.5, 2.5, 3.5]))
        );
        assert_eq!(
            binary(BinOp::Sub, &Value::Vec2([1.0, 2.0]), &Value::Int(1)),
            Ok(Value::Vec2([0.0, 1.0]))
        );
        assert_eq!(
            binary(BinOp::Sub, &Value::Int(1), &Value::Vec2([1.0, 2.0])),
            Ok(Value::Vec2([0.0, -1.0]))
        );
        assert_eq!(
            binary(BinOp::Div, &Value::Int(1), &Value::Vec3([1.0, 2.0, 4.0])),
            Ok(Value::Vec3([1.0, 0.5, 0.25]))
        );
        assert_eq!(
            binary(BinOp::Div, &Value::Int(1), &Value::Vec3([1.0, 0.0, 4.0])),
            Err(OpError::DivZero)
        );
        assert!(matches!(
            binary(BinOp::Add, &Value::Angle(1.0), &Value::Vec2([1.0, 2.0])),
            Err(OpError::Types(_))
        ));
        assert_eq!(
            binary(BinOp::Mul, &Value::Angle(1.0), &Value::Int(2)),
            Ok(Value::Angle(2.0))
        );
        assert_eq!(
            binary(BinOp::Div, &Value::Angle(1.0), &Value::Angle(0.5)),
            Ok(Value::Float(2.0))
        );
        assert!(matches!(
            binary(BinOp::Add, &Value::Angle(1.0), &Value::Float(1.0)),
            Err(OpError::Types(_))
        ));
        assert_eq!(
            binary(BinOp::Lt, &Value::Int(1), &Value::Float(1.5)),
            Ok(Value::Bool(true))
        );
        assert_eq!(
            binary(BinOp::Mul, &Value::Int(i64::MAX), &Value::Int(2)),
            Err(OpError::Overflow)
        );
        assert_eq!(
            binary(BinOp::Add, &Value::Unknown(Type::Float), &Value::Int(1)),
            Ok(Value::Unknown(Type::Float))
        );
    }

    #[test]
    fn unary_ops() {
        assert_eq!(
            unary(UnOp::Neg, &Value::Vec2([1.0, -2.0])),
            Ok(Value::Vec2([-1.0, 2.0]))
        );
        assert_eq!(unary(UnOp::Not, &Value::Bool(true)), Ok(Value::Bool(false)));
        assert!(unary(UnOp::Not, &Value::Int(1)).is_err());
    }
}
