//! A small 3-vector generic over the evaluation float type (positions, directions, colours).

use sdfc_compiler::Float;
use std::ops::{Add, Mul, Neg, Sub};

/// A 3-vector of `T`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct V3<T> {
    /// x (or red)
    pub x: T,
    /// y (or green)
    pub y: T,
    /// z (or blue)
    pub z: T,
}

impl<T: Float> V3<T> {
    /// The vector (x, y, z).
    #[inline]
    pub fn new(x: T, y: T, z: T) -> Self {
        V3 { x, y, z }
    }

    /// A vector from f64 components.
    pub fn from_f64(v: [f64; 3]) -> Self {
        V3::new(T::from_f64(v[0]), T::from_f64(v[1]), T::from_f64(v[2]))
    }

    /// All components equal to `s`.
    #[inline]
    pub fn splat(s: T) -> Self {
        V3::new(s, s, s)
    }

    /// The zero vector.
    #[inline]
    pub fn zero() -> Self {
        V3::splat(T::zero())
    }

    /// Dot product.
    #[inline]
    pub fn dot(self, o: Self) -> T {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Euclidean length.
    #[inline]
    pub fn length(self) -> T {
        self.dot(self).sqrt()
    }

    /// The unit vector along `self` (zero stays zero).
    #[inline]
    pub fn normalize(self) -> Self {
        let l = self.length();
        if l > T::zero() {
            self * (T::one() / l)
        } else {
            self
        }
    }

    /// Componentwise product.
    #[inline]
    pub fn mul_v(self, o: Self) -> Self {
        V3::new(self.x * o.x, self.y * o.y, self.z * o.z)
    }

    /// The largest absolute component.
    #[inline]
    pub fn max_abs(self) -> T {
        self.x.abs().max(self.y.abs()).max(self.z.abs())
    }

    /// The mirror image of `self` (a direction) about the plane of normal `n`:
    /// `self - 2 (self·n) n`.
    #[inline]
    pub fn reflect(self, n: Self) -> Self {
        self - n * (T::from_f64(2.0) * self.dot(n))
    }
}

impl<T: Float> Add for V3<T> {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        V3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl<T: Float> Sub for V3<T> {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        V3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl<T: Float> Mul<T> for V3<T> {
    type Output = Self;
    #[inline]
    fn mul(self, s: T) -> Self {
        V3::new(self.x * s, self.y * s, self.z * s)
    }
}

impl<T: Float> Neg for V3<T> {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        V3::new(-self.x, -self.y, -self.z)
    }
}
