//! The look of docs/rendering.md ("The look") in the evaluation type: the checker's colours
//! mixed over a sample's footprint, ambient occlusion from the distance field, fog over a ray
//! segment, and a pixel's exposure and tone curve. The kernel's copy is
//! `compiler/src/back/wgsl/shading.wgsl`; the constants are `sdfc_compiler::look`'s.

use super::context::Context;
use super::vec::V3;
use super::wave::Evaluators;
use sdfc_compiler::{look, Float, Tonemap};

/// The mean over `[u − w/2, u + w/2]` of the checker's sign along one axis (+1 in even cells,
/// −1 in odd ones), `u` and `w` in cells: `2·(T(f − w/2) − T(f + w/2))/w` with
/// `T(x) = |fract(x/2) − ½|`, `f` the offset of `u` in its cell, times the cell's sign. An
/// axis narrower than [`look::FOOTPRINT_MIN`] is point sampled.
fn checker_sign<T: Float>(u: T, w: T) -> T {
    let (half, two) = (T::from_f64(0.5), T::from_f64(2.0));
    let c = u.floor();
    let cell = T::one() - two * (c - two * (c * half).floor());
    if w < T::from_f64(look::FOOTPRINT_MIN) {
        return cell;
    }
    let f = u - c;
    let x = (f - half * w) * half;
    let y = (f + half * w) * half;
    let a = (x - x.floor() - half).abs();
    let b = (y - y.floor() - half).abs();
    cell * two * (a - b) / w
}

/// The weight of the checker's second colour at `q` (in cells) for a sample whose footprint
/// at the hit is `s` cells wide, seen along `d` on a surface of normal `n`: the footprint's
/// width along axis k is `s·√max(1 − n_k² + ((d_k − (N·D)·n_k)/c)², 0)` with
/// `c = max(|N·D|, FOOTPRINT_COS)`, and the weight is `½ − ½·Π sign_k`.
pub(super) fn checker_weight<T: Float>(q: V3<T>, n: V3<T>, d: V3<T>, s: T) -> T {
    let nd = n.dot(d);
    let c = nd.abs().max(T::from_f64(look::FOOTPRINT_COS));
    let e = (d - n * nd) * (T::one() / c);
    let width = |nk: T, ek: T| s * (T::one() - nk * nk + ek * ek).max(T::zero()).sqrt();
    let sign = checker_sign(q.x, width(n.x, e.x))
        * checker_sign(q.y, width(n.y, e.y))
        * checker_sign(q.z, width(n.z, e.z));
    let half = T::from_f64(0.5);
    half - half * sign
}

/// Ambient occlusion at each `(p, N)` of `at`: with `R` the `occlusion` setting and `n` =
/// [`look::OCCLUSION_SAMPLES`], `hᵢ = R·i/n`, `dᵢ = f(p + hᵢ·N)/L`,
/// `ao = clamp(1 − (k/n)·Σ max(hᵢ − dᵢ, 0)/hᵢ, 0, 1)`, evaluated as one batch.
pub(super) fn occlusion<T: Float>(
    ctx: &Context<T>,
    ev: &mut Evaluators<'_, T>,
    buffers: [&mut Vec<T>; 4],
    at: &[(V3<T>, V3<T>)],
) -> Vec<T> {
    let n = look::OCCLUSION_SAMPLES as usize;
    let [x, y, z, d] = buffers;
    for v in [&mut *x, &mut *y, &mut *z, &mut *d] {
        v.clear();
        v.resize(at.len() * n, T::zero());
    }
    let step = |i: usize| ctx.occlusion * T::from_f64((i + 1) as f64) / T::from_f64(n as f64);
    for (j, &(p, normal)) in at.iter().enumerate() {
        for i in 0..n {
            let q = p + normal * step(i);
            (x[j * n + i], y[j * n + i], z[j * n + i]) = (q.x, q.y, q.z);
        }
    }
    ev.dist.eval(x, y, z, d, None);
    let k = T::from_f64(look::OCCLUSION_STRENGTH) / T::from_f64(n as f64);
    (0..at.len())
        .map(|j| {
            let sum = (0..n).fold(T::zero(), |sum, i| {
                let h = step(i);
                sum + (h - d[j * n + i] * ctx.inv_lipschitz).max(T::zero()) / h
            });
            (T::one() - k * sum).clamp(T::zero(), T::one())
        })
        .collect()
}

/// What fog leaves of a ray segment of length `t`: `e^(−t/D)` (1 without fog).
pub(super) fn fade<T: Float>(ctx: &Context<T>, t: T) -> T {
    if ctx.inv_fog > T::zero() {
        (-t * ctx.inv_fog).exp()
    } else {
        T::one()
    }
}

/// A pixel's linear colour after the exposure and the tone curve (docs/rendering.md,
/// "The look"); unchanged without either.
pub(super) fn grade<T: Float>(ctx: &Context<T>, c: V3<T>) -> V3<T> {
    if !ctx.graded {
        return c;
    }
    let x = c * ctx.exposure;
    let curve = |x: T| match ctx.tonemap {
        Tonemap::None => x,
        Tonemap::Filmic => {
            let [a, b, cc, d, e] = look::FILMIC.map(T::from_f64);
            (x * (a * x + b) / (x * (cc * x + d) + e)).clamp(T::zero(), T::one())
        }
        Tonemap::Reinhard => x / (T::one() + x),
    };
    V3::new(curve(x.x), curve(x.y), curve(x.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The filtered sign is the mean of the point sign over the footprint (checked against
    /// a fine sum), and the point sign where the footprint is narrow.
    #[test]
    fn the_filtered_sign_is_the_mean_over_the_footprint() {
        let point = |u: f64| {
            if u.floor().rem_euclid(2.0) == 0.0 {
                1.0
            } else {
                -1.0
            }
        };
        for &(u, w) in &[
            (0.3, 0.5),
            (1.7, 0.9),
            (-2.2, 3.3),
            (5.5, 0.0001),
            (-0.01, 0.2),
        ] {
            let n = 200_000;
            let mean = (0..n)
                .map(|i| point(u - w / 2.0 + w * (i as f64 + 0.5) / n as f64))
                .sum::<f64>()
                / n as f64;
            let got = checker_sign(u, w);
            assert!(
                (got - mean).abs() < 1e-3,
                "u {u} w {w}: {got} against {mean}"
            );
        }
        assert_eq!(checker_sign(3.2f64, 1e-4), -1.0);
        assert_eq!(checker_sign(-0.5f64, 0.0), -1.0);
        // Straight on, a footprint of whole cells along both axes of a floor averages out.
        let n = V3::new(0.0, 1.0, 0.0);
        let d = V3::new(0.0, -1.0, 0.0);
        let w = checker_weight(V3::new(0.25, -0.01, 0.5), n, d, 2.0f64);
        assert!((w - 0.5).abs() < 1e-12, "{w}");
    }
}
