//! The physically based material (`pbr`, docs/rendering.md "Physically based materials"):
//! its parameters and every formula of its shading, generic over the evaluation type so that
//! the CPU renderer and the f64 reference run these very lines (the kernel writes them in
//! WGSL with the constants named here), and Schlick's Fresnel term that `fresnel: true`
//! gives Phong's reflected and refracted rays.

use crate::program::Float;

/// The parameters of a `pbr` material beyond the ones it shares with Phong (its base colour
/// is the material's pattern, its transmission the material's transparency over `1 −
/// metallic`, its index of refraction the material's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pbr {
    /// Perceptual roughness in [0, 1]: 0 a mirror, 1 fully rough.
    pub roughness: f64,
    /// 0 a dielectric, 1 a metal (its specular tinted by the base colour, no diffuse).
    pub metallic: f64,
    /// Light the surface gives off itself (linear RGB), added to what it reflects.
    pub emission: [f64; 3],
    /// The fraction of the dielectric part that is transmitted (refracted) instead of
    /// diffusely reflected, in [0, 1].
    pub transmission: f64,
}

impl Pbr {
    /// The default roughness.
    pub const ROUGHNESS: f64 = 0.5;
    /// The default metallic.
    pub const METALLIC: f64 = 0.0;
    /// The default transmission.
    pub const TRANSMISSION: f64 = 0.0;

    /// The GGX width `α = max(roughness², ALPHA_MIN)`.
    pub fn alpha(&self) -> f64 {
        alpha(self.roughness)
    }

    /// The weight `g = (1 − roughness)²` of the environment's specular reflection that a
    /// reflected ray carries (the rest comes from the skies in closed form).
    pub fn mirror(&self) -> f64 {
        mirror(self.roughness)
    }

    /// The Phong exponent of the same highlight width, `2/α² − 2` within Phong's range
    /// (Walter et al. 2007): what the material tables of `--part map` and the Shadertoy page
    /// give a `pbr` material.
    pub fn shininess(&self) -> f64 {
        let a = self.alpha();
        (2.0 / (a * a) - 2.0).clamp(1.0, 10000.0)
    }
}

/// The least GGX width α: a roughness of 0 is a very sharp lobe, not a delta (a point
/// light's highlight on it is small and bright, not absent).
pub const ALPHA_MIN: f64 = 0.002;

/// The least `N·V` the view term takes (the normal of a silhouette may face away by
/// rounding).
pub const NV_MIN: f64 = 1e-4;

/// Karis's analytic fit of the split-sum environment BRDF ("Physically Based Shading on
/// Mobile", 2014): `c0`, `c1` of `r = roughness·c0 + c1`.
pub const ENV_C0: [f64; 4] = [-1.0, -0.0275, -0.572, 0.022];
/// See [`ENV_C0`].
pub const ENV_C1: [f64; 4] = [1.0, 0.0425, 1.04, -0.04];
/// See [`ENV_C0`]: `a = min(r.x², 2^(ENV_EXP·N·V))·r.x + r.y`.
pub const ENV_EXP: f64 = -9.28;

/// `α = max(roughness², ALPHA_MIN)`.
pub fn alpha(roughness: f64) -> f64 {
    (roughness * roughness).max(ALPHA_MIN)
}

/// `g = (1 − roughness)²`.
pub fn mirror(roughness: f64) -> f64 {
    (1.0 - roughness) * (1.0 - roughness)
}

/// The reflectance at normal incidence of a dielectric of index `ior` in air:
/// `((ior − 1)/(ior + 1))²` (0.04 at 1.5).
pub fn f0(ior: f64) -> f64 {
    let r = (ior - 1.0) / (ior + 1.0);
    r * r
}

/// Schlick's weight `(1 − c)⁵` of the grazing part, `c` the cosine of the angle of incidence
/// (clamped to [0, 1]): `F = F0 + (1 − F0)·schlick(c)`.
pub fn schlick<T: Float>(c: T) -> T {
    let x = T::one() - c.clamp(T::zero(), T::one());
    let x2 = x * x;
    x2 * x2 * x
}

/// The GGX (Trowbridge–Reitz) distribution of normals: `α²/(π·((N·H)²·(α² − 1) + 1)²)`.
pub fn ggx<T: Float>(nh: T, a: T) -> T {
    let a2 = a * a;
    let d = nh * nh * (a2 - T::one()) + T::one();
    a2 / (T::from_f64(std::f64::consts::PI) * d * d)
}

/// The height-correlated Smith shadowing-masking term of GGX over `4·(N·L)·(N·V)` (Heitz,
/// "Understanding the Masking-Shadowing Function", 2014):
/// `½ / (N·L·√((N·V)²·(1 − α²) + α²) + N·V·√((N·L)²·(1 − α²) + α²))`.
pub fn visibility<T: Float>(nv: T, nl: T, a: T) -> T {
    let a2 = a * a;
    let v = nl * (nv * nv * (T::one() - a2) + a2).sqrt();
    let l = nv * (nl * nl * (T::one() - a2) + a2).sqrt();
    T::from_f64(0.5) / (v + l)
}

/// The split-sum environment BRDF `(A, B)` at `N·V` (Karis's fit, [`ENV_C0`]): the specular
/// lobe's directional albedo is `F0·A + B`.
pub fn environment<T: Float>(nv: T, roughness: T) -> (T, T) {
    let r: [T; 4] =
        std::array::from_fn(|i| roughness * T::from_f64(ENV_C0[i]) + T::from_f64(ENV_C1[i]));
    let e = (T::from_f64(ENV_EXP * std::f64::consts::LN_2) * nv).exp();
    let a = (r[0] * r[0]).min(e) * r[0] + r[1];
    let k = T::from_f64(1.04);
    (-k * a + r[2], k * a + r[3])
}

/// The weight of the local colour, of the reflected ray and of the refracted ray of a
/// Phong material with `fresnel: true` that reflects `r` and transmits `τ` (weights summing
/// to 1 with `w = 1 − r − τ`), at a hit seen at `c = |N·V|`: with `s = (1 − c)⁵` and the
/// glass's `R = F0 + (1 − F0)·s` (`F0` of its `ior`), `w' = w·(1 − s)`, `τ' = τ·(1 − R)` and
/// `r' = r + w·s + τ·R`: at normal incidence nearly the weights as written, at grazing
/// incidence a mirror. The three still sum to 1.
pub fn fresnel_weights<T: Float>(r: T, tau: T, f0: T, c: T) -> (T, T, T) {
    let s = schlick(c);
    let w = T::one() - r - tau;
    let big_r = f0 + (T::one() - f0) * s;
    (
        w * (T::one() - s),
        r + w * s + tau * big_r,
        tau * (T::one() - big_r),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The GGX distribution is normalised: ∫ D(h)·(N·H) dω_h = 1 over the hemisphere.
    #[test]
    fn the_distribution_integrates_to_one() {
        for a in [0.05, 0.2, 0.5, 1.0] {
            let n = 20000;
            let mut sum = 0.0;
            for i in 0..n {
                // θ_h over [0, π/2] in the midpoint rule; the ring's solid angle 2π·sin θ dθ.
                let th = (i as f64 + 0.5) / n as f64 * std::f64::consts::FRAC_PI_2;
                let dth = std::f64::consts::FRAC_PI_2 / n as f64;
                sum += ggx(th.cos(), a) * th.cos() * 2.0 * std::f64::consts::PI * th.sin() * dth;
            }
            assert!((sum - 1.0).abs() < 2e-3, "α {a}: {sum}");
        }
    }

    /// The fit's directional albedo of a white metal never exceeds 1 and is 1 for a mirror;
    /// a dielectric's rises towards grazing incidence.
    #[test]
    fn the_environment_fit_conserves_energy() {
        for r in [0.0, 0.3, 0.7, 1.0] {
            for nv in [1e-4, 0.1, 0.5, 1.0] {
                let (a, b) = environment(nv, r);
                assert!(a + b <= 1.0 + 1e-12, "roughness {r}, N·V {nv}: {}", a + b);
                if r == 0.0 {
                    assert!((a + b - 1.0).abs() < 1e-12);
                }
            }
        }
        let (a1, b1) = environment(1.0, 0.2);
        let (a0, b0) = environment(0.05, 0.2);
        assert!(0.04 * a0 + b0 > 0.04 * a1 + b1);
    }

    #[test]
    fn fresnel_weights_sum_to_one_and_turn_to_a_mirror_at_grazing() {
        let (w, r, t) = fresnel_weights(0.2, 0.5, f0(1.5), 1.0);
        assert!((w + r + t - 1.0).abs() < 1e-12);
        assert!((w - 0.3).abs() < 1e-12 && (r - (0.2 + 0.5 * 0.04)).abs() < 1e-12);
        let (w, r, t) = fresnel_weights(0.2, 0.5, f0(1.5), 0.0);
        assert!(w.abs() < 1e-12 && (r - 1.0).abs() < 1e-12 && t.abs() < 1e-12);
        assert!((f0(1.5) - 0.04).abs() < 1e-12);
    }
}
