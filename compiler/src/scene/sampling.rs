//! The path tracer's random stream and the formulas it samples directions with
//! (docs/rendering.md, "Path tracing"), generic over the evaluation type so that the CPU
//! renderer and the f64 reference run these very lines; the kernel writes the same integer
//! arithmetic and formulas in WGSL (`path.wgsl`) with the constants named here.
//!
//! The stream is counter based: the number for a (pixel, sample, bounce, dimension) is a hash
//! of the four, so every backend draws the same numbers for the same path whatever order it
//! traces the paths in.

use crate::program::Float;

/// Bounce index of the camera ray's own numbers (its place in the pixel); the hit of a ray
/// of depth `d` draws with bounce index `d + 1`.
pub const CAMERA: u32 = 0;

/// The dimensions a hit draws from (with its bounce index).
pub mod dim {
    /// The camera's place in the pixel, x and y (bounce index [`super::CAMERA`]).
    pub const JITTER: [u32; 2] = [0, 1];
    /// Which lobe of the material the continued path takes.
    pub const LOBE: u32 = 0;
    /// The continued path's direction within its lobe.
    pub const DIRECTION: [u32; 2] = [1, 2];
    /// The direction towards the sky of the next-event estimate.
    pub const SKY: [u32; 2] = [3, 4];
    /// Russian roulette.
    pub const ROULETTE: u32 = 5;
    /// The first of the directional lights' dimensions: the `j`-th directional light (suns
    /// included, in the scene's order) draws its direction within its disc from
    /// `LAMPS + 2j` and `LAMPS + 2j + 1`; point lights draw none.
    pub const LAMPS: u32 = 6;
}

/// Paths whose next ray would be of this depth or deeper play Russian roulette.
pub const ROULETTE_DEPTH: u32 = 3;
/// The most a path survives Russian roulette with: `q = min(max(throughput), ROULETTE_MAX)`.
pub const ROULETTE_MAX: f64 = 0.95;

/// `2⁻²⁴`: a hash's top 24 bits times it is a number in [0, 1) exact in f32 and f64.
pub const UNIT: f64 = 1.0 / 16_777_216.0;

/// The PCG hash of one word (O'Neill's permuted congruential generator, one step and its
/// output permutation, as Jarzynski and Olano recommend for GPU hashing, 2020).
pub fn pcg(x: u32) -> u32 {
    let state = x.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// The random word of dimension `dim` of bounce `bounce` of sample `sample` of pixel
/// `pixel` (`y·width + x`): `pcg(pcg(pcg(pcg(pixel) + sample) + bounce) + dim)`, wrapping.
pub fn hash(pixel: u32, sample: u32, bounce: u32, dim: u32) -> u32 {
    let h = pcg(pixel).wrapping_add(sample);
    let h = pcg(h).wrapping_add(bounce);
    pcg(pcg(h).wrapping_add(dim))
}

/// [`hash`] as a number in [0, 1): its top 24 bits times [`UNIT`], the same value in every
/// evaluation type.
pub fn uniform<T: Float>(pixel: u32, sample: u32, bounce: u32, dim: u32) -> T {
    T::from_f64((hash(pixel, sample, bounce, dim) >> 8) as f64 * UNIT)
}

/// Two unit vectors that make an orthonormal basis with the unit vector `n` (Duff et al.,
/// "Building an Orthonormal Basis, Revisited", 2017): with `s = ±1` the sign of `n.z`
/// (+1 at 0), `a = −1/(s + n.z)`, `b = n.x·n.y·a`: `(1 + s·n.x²·a, s·b, −s·n.x)` and
/// `(b, s + n.y²·a, −n.y)`.
pub fn basis<T: Float>(n: [T; 3]) -> ([T; 3], [T; 3]) {
    let s = if n[2] >= T::zero() {
        T::one()
    } else {
        -T::one()
    };
    let a = -T::one() / (s + n[2]);
    let b = n[0] * n[1] * a;
    (
        [T::one() + s * n[0] * n[0] * a, s * b, -s * n[0]],
        [b, s + n[1] * n[1] * a, -n[1]],
    )
}

/// The direction `x·t + y·b + z·n` of local coordinates `(x, y, z)` about `n` ([`basis`]).
pub fn to_world<T: Float>(local: [T; 3], n: [T; 3]) -> [T; 3] {
    let (t, b) = basis(n);
    std::array::from_fn(|i| local[0] * t[i] + local[1] * b[i] + local[2] * n[i])
}

/// `(cos φ, sin φ)` of `φ = 2π·u`.
fn turn<T: Float>(u: T) -> (T, T) {
    let phi = T::from_f64(2.0 * std::f64::consts::PI) * u;
    (phi.cos(), phi.sin())
}

/// A direction about the axis (local z) whose cosine to it is `cos`, turned by `2π·u`.
fn about<T: Float>(cos: T, u: T) -> [T; 3] {
    let sin = (T::one() - cos * cos).max(T::zero()).sqrt();
    let (c, s) = turn(u);
    [sin * c, sin * s, cos]
}

/// A cosine-distributed direction about local z (density `cos θ/π`): Malley's method,
/// `r = √u₁`, `φ = 2π·u₂`, `(r·cos φ, r·sin φ, √(1 − u₁))`.
pub fn cosine<T: Float>(u1: T, u2: T) -> [T; 3] {
    let r = u1.sqrt();
    let (c, s) = turn(u2);
    [r * c, r * s, (T::one() - u1).max(T::zero()).sqrt()]
}

/// A half vector about local z distributed as the GGX normals, `D(h)·cos θ_h` (Walter et
/// al. 2007): `cos²θ = (1 − u₁)/(1 + (α² − 1)·u₁)`, `φ = 2π·u₂`.
pub fn ggx_half<T: Float>(u1: T, u2: T, alpha: T) -> [T; 3] {
    let a2 = alpha * alpha;
    let cos2 = (T::one() - u1) / (T::one() + (a2 - T::one()) * u1);
    about(cos2.max(T::zero()).sqrt(), u2)
}

/// A direction uniform over the cone about local z of cosine `cos_max` (a disc light seen
/// from afar): `cos θ = 1 − u₁·(1 − cos_max)`, `φ = 2π·u₂`.
pub fn cone<T: Float>(u1: T, u2: T, cos_max: T) -> [T; 3] {
    about(T::one() - u1 * (T::one() - cos_max), u2)
}

/// The density over directions of reflecting `v` about a GGX half vector drawn by
/// [`ggx_half`]: `D(h)·(N·H)/(4·(V·H))` (0 where `V·H ≤ 0`).
pub fn ggx_pdf<T: Float>(nh: T, vh: T, alpha: T) -> T {
    if vh <= T::zero() {
        return T::zero();
    }
    super::pbr::ggx(nh, alpha) * nh / (T::from_f64(4.0) * vh)
}

/// The power heuristic's weight of a strategy of density `a` against one of density `b`
/// (Veach 1997, β = 2): `a²/(a² + b²)`, 0 where both are 0.
pub fn power<T: Float>(a: T, b: T) -> T {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > T::zero() {
        a2 / (a2 + b2)
    } else {
        T::zero()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The words are spread: over a pixel's first samples every bit is set about half the
    /// time, and the numbers of neighbouring pixels, samples and dimensions differ.
    #[test]
    fn the_stream_is_spread_and_counter_based() {
        let mut ones = [0u32; 32];
        let n = 4096;
        for s in 0..n {
            let h = hash(7, s, 1, 0);
            for (b, count) in ones.iter_mut().enumerate() {
                *count += (h >> b) & 1;
            }
        }
        for (b, &count) in ones.iter().enumerate() {
            let f = count as f64 / n as f64;
            assert!((f - 0.5).abs() < 0.04, "bit {b}: {f}");
        }
        assert_ne!(hash(0, 0, 0, 0), hash(1, 0, 0, 0));
        assert_ne!(hash(0, 0, 0, 0), hash(0, 1, 0, 0));
        assert_ne!(hash(0, 0, 0, 0), hash(0, 0, 1, 0));
        assert_ne!(hash(0, 0, 0, 0), hash(0, 0, 0, 1));
        // The same value in f32 and f64.
        for s in 0..100 {
            let a: f32 = uniform(3, s, 2, 4);
            let b: f64 = uniform(3, s, 2, 4);
            assert_eq!(a as f64, b);
            assert!((0.0..1.0).contains(&b));
        }
        // The mean of many is a half.
        let mean: f64 = (0..n).map(|s| uniform::<f64>(9, s, 0, 0)).sum::<f64>() / n as f64;
        assert!((mean - 0.5).abs() < 0.01, "{mean}");
    }

    /// The basis is orthonormal, for normals on either side of z = 0.
    #[test]
    fn the_basis_is_orthonormal() {
        for n in [
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
            [0.6, 0.0, 0.8],
            [0.48, -0.6, -0.64],
        ] {
            let (t, b) = basis::<f64>(n);
            let dot = |a: [f64; 3], c: [f64; 3]| a[0] * c[0] + a[1] * c[1] + a[2] * c[2];
            for (x, y, want) in [
                (t, t, 1.0),
                (b, b, 1.0),
                (t, b, 0.0),
                (t, n, 0.0),
                (b, n, 0.0),
            ] {
                assert!((dot(x, y) - want).abs() < 1e-12, "{n:?}");
            }
        }
    }

    /// Cosine sampling's mean of `cos θ` is 2/3; the cone's directions stay within it; at
    /// normal incidence the GGX half vectors reflect the view above the surface, with a
    /// positive density.
    #[test]
    fn the_samplers_have_their_densities() {
        let n = 20_000u32;
        let u = |s: u32, d: u32| uniform::<f64>(1, s, 1, d);
        let mean: f64 = (0..n).map(|s| cosine(u(s, 0), u(s, 1))[2]).sum::<f64>() / n as f64;
        assert!((mean - 2.0 / 3.0).abs() < 0.01, "{mean}");
        let cos_max = 0.99f64;
        assert!((0..n).all(|s| cone(u(s, 0), u(s, 1), cos_max)[2] >= cos_max - 1e-12));
        // The GGX half vectors within 25.8° of the axis (cos θ_h > 0.9) are as many as the
        // distribution's share there, ∫ D(h)·cos θ_h dω_h (midpoint rule); and the density of
        // a reflected direction is positive where the half vector faces the view.
        for alpha in [0.1, 0.5, 1.0] {
            let drawn = (0..n)
                .filter(|&s| ggx_half(u(s, 0), u(s, 1), alpha)[2] > 0.9)
                .count() as f64
                / n as f64;
            let (steps, top) = (20_000, 0.9f64.acos());
            let share: f64 = (0..steps)
                .map(|i| {
                    let th = (i as f64 + 0.5) / steps as f64 * top;
                    super::super::pbr::ggx(th.cos(), alpha)
                        * th.cos()
                        * 2.0
                        * std::f64::consts::PI
                        * th.sin()
                        * (top / steps as f64)
                })
                .sum();
            assert!(
                (drawn - share).abs() < 0.01,
                "α {alpha}: {drawn} drawn, {share}"
            );
            assert!(ggx_pdf(0.95, 0.6, alpha) > 0.0 && ggx_pdf(0.95, -0.1, alpha) == 0.0);
        }
        assert_eq!(power(1.0, 1.0), 0.5);
        assert_eq!(power(0.0, 0.0), 0.0);
    }
}
