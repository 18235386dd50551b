//! The meaning of each operation on one value: the single definition that the interpreter's
//! loops, the constant folder and the Rust writer follow.

use super::{Binary, Float, Unary};

/// Applies a one-operand operation.
#[inline(always)]
pub fn unary<T: Float>(u: Unary, a: T) -> T {
    match u {
        Unary::Neg => -a,
        Unary::Abs => a.abs(),
        Unary::Sqrt => a.sqrt(),
        Unary::Sin => a.sin(),
        Unary::Cos => a.cos(),
        Unary::Acos => a.acos(),
        Unary::Exp => a.exp(),
        Unary::Log => a.ln(),
        Unary::Floor => a.floor(),
        Unary::Round => a.round_half_up(),
    }
}

/// Applies a two-operand operation.
#[inline(always)]
pub fn binary<T: Float>(b: Binary, x: T, y: T) -> T {
    match b {
        Binary::Add => x + y,
        Binary::Sub => x - y,
        Binary::Mul => x * y,
        Binary::Div => x / y,
        Binary::Min => x.min(y),
        Binary::Max => x.max(y),
        Binary::Pow => x.powf(y),
        Binary::Atan2 => x.atan2(y),
        Binary::Lt => {
            if x < y {
                T::one()
            } else {
                T::zero()
            }
        }
    }
}

/// Applies `select`.
#[inline(always)]
pub fn select<T: Float>(c: T, a: T, b: T) -> T {
    if c != T::zero() {
        a
    } else {
        b
    }
}
