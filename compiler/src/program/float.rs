//! The scalar types a distance program runs in (f32, f64) and the meaning of every operation.
//!
//! The interpreter, the constant folder of `lower` and the Rust writer all follow the
//! definitions here, so that one program means one thing everywhere:
//!
//! - `min(a, b)` is `if a < b { a } else { b }` and `max(a, b)` is `if a > b { a } else { b }`
//!   (one compare and a blend; with a NaN operand the second operand wins);
//! - `round(x)` is `floor(x + 0.5)` (halves go up);
//! - `lt(a, b)` is 1 when `a < b`, else 0; `select(c, a, b)` is `a` when `c != 0`, else `b`;
//! - `sin`, `cos` and `atan2` are `trig.rs`'s polynomials (in f32 within 0.501 ulp, in f64
//!   within 1 ulp of the library's, 2 for `atan2`; the same whether a loop over them
//!   vectorises or not); every other function is the library's.

use super::trig;
use std::fmt::Debug;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A floating-point type the interpreter and the CPU renderer are generic over.
pub trait Float:
    Copy
    + Debug
    + Default
    + PartialOrd
    + Send
    + Sync
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// The machine epsilon of the type.
    const EPSILON: Self;
    /// The name of the type (`f32`, `f64`).
    const NAME: &'static str;
    /// Converts from f64, rounding to nearest.
    fn from_f64(x: f64) -> Self;
    /// Converts to f64 exactly.
    fn to_f64(self) -> f64;
    /// Square root.
    fn sqrt(self) -> Self;
    /// Sine.
    fn sin(self) -> Self;
    /// Cosine.
    fn cos(self) -> Self;
    /// Whether [`Float::sin_reduced`] and [`Float::cos_reduced`] are `sin` and `cos` at
    /// `self`: a batch loop runs those, without branches, over every lane, then `sin` or `cos`
    /// over the lanes where this is false (beyond `trig.rs`'s reduction).
    fn reduced(self) -> bool;
    /// `sin` where [`Float::reduced`] (any value elsewhere).
    fn sin_reduced(self) -> Self;
    /// `cos` where [`Float::reduced`] (any value elsewhere).
    fn cos_reduced(self) -> Self;
    /// Arc cosine.
    fn acos(self) -> Self;
    /// Four-quadrant arc tangent of `self / x`.
    fn atan2(self, x: Self) -> Self;
    /// e^self.
    fn exp(self) -> Self;
    /// Natural logarithm.
    fn ln(self) -> Self;
    /// self^e.
    fn powf(self, e: Self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// The largest integer not above `self`, computed without a library call.
    fn floor(self) -> Self;
    /// True for NaN.
    fn is_nan(self) -> bool;

    /// Zero.
    #[inline(always)]
    fn zero() -> Self {
        Self::from_f64(0.0)
    }
    /// One.
    #[inline(always)]
    fn one() -> Self {
        Self::from_f64(1.0)
    }
    /// The smaller operand (see the module doc for NaN).
    #[inline(always)]
    fn min(self, b: Self) -> Self {
        if self < b {
            self
        } else {
            b
        }
    }
    /// The larger operand (see the module doc for NaN).
    #[inline(always)]
    fn max(self, b: Self) -> Self {
        if self > b {
            self
        } else {
            b
        }
    }
    /// `floor(self + 0.5)`.
    #[inline(always)]
    fn round_half_up(self) -> Self {
        (self + Self::from_f64(0.5)).floor()
    }
    /// `self` limited to `[lo, hi]`.
    #[inline(always)]
    fn clamp(self, lo: Self, hi: Self) -> Self {
        self.max(lo).min(hi)
    }
}

macro_rules! impl_float {
    ($t:ty, $i:ty, $big:expr, [$sin:ident, $cos:ident, $reduced:ident, $sin_r:ident, $cos_r:ident, $atan2:ident]) => {
        impl Float for $t {
            #[inline(always)]
            fn sin(self) -> Self {
                trig::$sin(self)
            }
            #[inline(always)]
            fn cos(self) -> Self {
                trig::$cos(self)
            }
            #[inline(always)]
            fn reduced(self) -> bool {
                trig::$reduced(self)
            }
            #[inline(always)]
            fn sin_reduced(self) -> Self {
                trig::$sin_r(self)
            }
            #[inline(always)]
            fn cos_reduced(self) -> Self {
                trig::$cos_r(self)
            }
            #[inline(always)]
            fn atan2(self, x: Self) -> Self {
                trig::$atan2(self, x)
            }
            const EPSILON: Self = <$t>::EPSILON;
            const NAME: &'static str = stringify!($t);
            #[inline(always)]
            fn from_f64(x: f64) -> Self {
                x as $t
            }
            #[inline(always)]
            fn to_f64(self) -> f64 {
                self as f64
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }
            #[inline(always)]
            fn acos(self) -> Self {
                <$t>::acos(self)
            }
            #[inline(always)]
            fn exp(self) -> Self {
                <$t>::exp(self)
            }
            #[inline(always)]
            fn ln(self) -> Self {
                <$t>::ln(self)
            }
            #[inline(always)]
            fn powf(self, e: Self) -> Self {
                <$t>::powf(self, e)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                <$t>::abs(self)
            }
            /// Truncation through an integer, corrected for negative non-integers. Values at
            /// or beyond `$big` are integers already and pass through (so do NaN, ±inf and ±0).
            #[inline(always)]
            fn floor(self) -> Self {
                let big: $t = $big;
                let t = (self as $i) as $t;
                let f = if t > self { t - 1.0 } else { t };
                // Zeros pass through too, so that floor(-0.0) is -0.0 as in std and WGSL.
                if self.abs() < big && self != 0.0 {
                    f
                } else {
                    self
                }
            }
            #[inline(always)]
            fn is_nan(self) -> bool {
                <$t>::is_nan(self)
            }
        }
    };
}

impl_float!(
    f32,
    i32,
    8_388_608.0,
    [sinf, cosf, reducedf, sinf_reduced, cosf_reduced, atan2f]
);
impl_float!(
    f64,
    i64,
    4_503_599_627_370_496.0,
    [sin, cos, reduced, sin_reduced, cos_reduced, atan2]
);

#[cfg(test)]
mod tests {
    use super::Float;

    #[test]
    fn floor_matches_std() {
        for &x in &[
            -2.5f32, -2.0, -0.5, -0.0, 0.0, 0.3, 1.0, 1.7, 1e7, -1e7, 3e9, -3e9,
        ] {
            assert_eq!(Float::floor(x).to_bits(), x.floor().to_bits(), "{x}");
        }
        for &x in &[
            -2.5f64,
            -1e15,
            1e15 + 0.5,
            7.0,
            -7.25,
            1e300,
            -0.0,
            0.0,
            -0.25,
        ] {
            assert_eq!(Float::floor(x).to_bits(), x.floor().to_bits(), "{x}");
        }
        assert!(Float::floor(f32::NAN).is_nan());
        assert_eq!(Float::floor(f32::INFINITY), f32::INFINITY);
    }
}
