//! The render settings that shape a picture's look beyond Phong (docs/rendering.md, "The
//! look"): ambient occlusion, distance fog, exposure and tone mapping, and the constants of
//! the filtered checker, each formula's constants named once for every backend.

/// The tone curve a pixel's linear colour goes through after its exposure (the `tonemap`
/// render setting).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Tonemap {
    /// The colour as it is (clamped to [0, 1] when encoded): the look of every scene before
    /// the setting existed.
    #[default]
    None,
    /// Narkowicz's fit of the ACES filmic curve (2015): a toe, a shoulder that rolls bright
    /// values off towards 1, and more contrast in the middle.
    Filmic,
    /// Reinhard's `x / (1 + x)` (2002): every value below 1, no toe.
    Reinhard,
}

impl Tonemap {
    /// The curves' names, as the `tonemap` setting spells them.
    pub const NAMES: &'static [&'static str] = &["none", "filmic", "reinhard"];

    /// The curve of a name in [`Tonemap::NAMES`].
    pub fn from_name(name: &str) -> Option<Tonemap> {
        match name {
            "none" => Some(Tonemap::None),
            "filmic" => Some(Tonemap::Filmic),
            "reinhard" => Some(Tonemap::Reinhard),
            _ => None,
        }
    }

    /// The curve's name.
    pub const fn name(self) -> &'static str {
        match self {
            Tonemap::None => "none",
            Tonemap::Filmic => "filmic",
            Tonemap::Reinhard => "reinhard",
        }
    }

    /// The number the kernel's uniform holds for the curve (`look.w`).
    pub const fn index(self) -> u32 {
        match self {
            Tonemap::None => 0,
            Tonemap::Filmic => 1,
            Tonemap::Reinhard => 2,
        }
    }
}

/// The coefficients `(a, b, c, d, e)` of the filmic curve
/// `clamp(x·(a·x + b) / (x·(c·x + d) + e), 0, 1)` (Narkowicz's ACES fit).
pub const FILMIC: [f64; 5] = [2.51, 0.03, 2.43, 0.59, 0.14];

/// The samples of ambient occlusion along the normal, at `R·i/n` for `i = 1..=n`.
pub const OCCLUSION_SAMPLES: u32 = 5;

/// The strength `k` of ambient occlusion: `ao = clamp(1 − (k/n)·Σ max(hᵢ − dᵢ, 0)/hᵢ, 0, 1)`.
pub const OCCLUSION_STRENGTH: f64 = 2.0;

/// The least `|N·D|` the checker's footprint takes: a grazing ray's footprint stretches by
/// `1/|N·D|` along the surface, up to this.
pub const FOOTPRINT_COS: f64 = 0.01;

/// A checker axis whose footprint is narrower than this fraction of a cell is point sampled
/// (the filtered value differs from the point's only within half of it of a cell's edge, and
/// the difference of two close values would lose its precision).
pub const FOOTPRINT_MIN: f64 = 1e-3;

/// The default sky of `light sky`: a clear day's blue overhead, paler at the horizon, a
/// brown ground (linear RGB).
pub const SKY_ZENITH: [f64; 3] = [0.08, 0.22, 0.64];
/// See [`SKY_ZENITH`].
pub const SKY_HORIZON: [f64; 3] = [0.51, 0.64, 0.79];
/// See [`SKY_ZENITH`].
pub const SKY_GROUND: [f64; 3] = [0.16, 0.13, 0.10];

/// The radiance of a sky in the direction whose height (y component) is `y`: `ground` below
/// the horizon, else `horizon + (zenith − horizon)·y`.
pub fn sky_radiance(zenith: [f64; 3], horizon: [f64; 3], ground: [f64; 3], y: f64) -> [f64; 3] {
    if y < 0.0 {
        ground
    } else {
        std::array::from_fn(|k| horizon[k] + (zenith[k] - horizon[k]) * y)
    }
}

/// The coefficients `(c₀, c₁, c₂)` of a sky's irradiance over π at a surface of normal `N`,
/// `E(N)/π = c₀ + c₁·N_y + c₂·(3N_y² − 1)`: its radiance (a function of the height μ of the
/// direction alone) expanded in Legendre polynomials up to P₂, each term convolved with the
/// cosine lobe (Funk–Hecke: factors π, 2π/3, π/4). With `D = zenith − horizon`:
/// `c₀ = (horizon + D/2 + ground)/2`, `c₁ = horizon/2 + D/3 − ground/2`, `c₂ = 5·D/128`.
/// Exact for a sky of one colour and for one of two (above and below the horizon); for a
/// gradient the terms left out (P₄ on) are below 1 % of `D`.
pub fn sky_irradiance(zenith: [f64; 3], horizon: [f64; 3], ground: [f64; 3]) -> [[f64; 3]; 3] {
    let d: [f64; 3] = std::array::from_fn(|k| zenith[k] - horizon[k]);
    [
        std::array::from_fn(|k| (horizon[k] + d[k] / 2.0 + ground[k]) / 2.0),
        std::array::from_fn(|k| horizon[k] / 2.0 + d[k] / 3.0 - ground[k] / 2.0),
        std::array::from_fn(|k| 5.0 * d[k] / 128.0),
    ]
}

/// Why a scene's default tone curve is `"none"`: it has nothing of [`newer_look`].
pub const OLDER_LOOK: &str = "it has no `pbr` material, `light sky` or `method: \"path\"`";

/// What makes a scene's default tone curve `"filmic"` (docs/rendering.md, "The look"): a
/// `pbr` material, a `light sky` or `method: "path"`, the look written since the curve came,
/// whose light runs above 1 (skies, emission, Fresnel's rims); a scene of none of them keeps
/// `"none"`, the look it was written for. `None` for such a scene.
pub fn newer_look(scene: &super::Scene) -> Option<&'static str> {
    if scene.settings.path {
        Some("it is path traced (`method: \"path\"`)")
    } else if scene.materials.iter().any(|m| m.pbr.is_some()) {
        Some("it has a `pbr` material")
    } else if scene
        .lights
        .iter()
        .any(|l| matches!(l, super::Light::Sky { .. }))
    {
        Some("it is lit by a `light sky`")
    } else {
        None
    }
}

/// `tonemap(2^exposure · c)` for one channel, in f64 (the CPU renderer's own copy, in its
/// evaluation type, is `runtime/src/cpu/look.rs`; this one states the formula for tests).
pub fn grade(tonemap: Tonemap, exposure: f64, c: f64) -> f64 {
    let x = c * exposure.exp2();
    match tonemap {
        Tonemap::None => x,
        Tonemap::Filmic => {
            let [a, b, cc, d, e] = FILMIC;
            (x * (a * x + b) / (x * (cc * x + d) + e)).clamp(0.0, 1.0)
        }
        Tonemap::Reinhard => x / (1.0 + x),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The irradiance of the formula against a sum over the hemisphere of directions.
    #[test]
    fn the_skys_irradiance_is_its_integral_over_the_hemisphere() {
        let (z, h, g) = ([0.2, 0.4, 1.0], [0.7, 0.8, 0.9], [0.3, 0.2, 0.1]);
        let c = sky_irradiance(z, h, g);
        for ny in [-1.0, -0.6, -0.1, 0.0, 0.3, 0.8, 1.0f64] {
            let n = [(1.0 - ny * ny).sqrt(), ny, 0.0];
            // Midpoint sums over the sphere in (cos θ, φ): equal areas.
            let (m, k) = (400, 400);
            let mut e = [0.0; 3];
            for i in 0..m {
                let y = -1.0 + 2.0 * (i as f64 + 0.5) / m as f64;
                let r = (1.0 - y * y).sqrt();
                for j in 0..k {
                    let phi = std::f64::consts::TAU * (j as f64 + 0.5) / k as f64;
                    let w = [r * phi.cos(), y, r * phi.sin()];
                    let cos = (n[0] * w[0] + n[1] * w[1] + n[2] * w[2]).max(0.0);
                    let l = sky_radiance(z, h, g, y);
                    for ch in 0..3 {
                        e[ch] += l[ch] * cos * 4.0 / (m * k) as f64;
                    }
                }
            }
            for ch in 0..3 {
                let formula = c[0][ch] + c[1][ch] * ny + c[2][ch] * (3.0 * ny * ny - 1.0);
                assert!(
                    (formula - e[ch]).abs() < 0.01 * (z[ch] - h[ch]).abs() + 2e-4,
                    "N_y {ny}, channel {ch}: {formula} against {}",
                    e[ch]
                );
            }
        }
        let one = sky_irradiance([1.0; 3], [1.0; 3], [1.0; 3]);
        assert_eq!(one, [[1.0; 3], [0.0; 3], [0.0; 3]]);
    }

    #[test]
    fn the_curves_keep_black_and_order() {
        for t in [Tonemap::None, Tonemap::Filmic, Tonemap::Reinhard] {
            assert_eq!(Tonemap::from_name(t.name()), Some(t));
            assert_eq!(grade(t, 0.0, 0.0), 0.0);
            let mut last = 0.0;
            for i in 1..70 {
                let v = grade(t, 0.0, i as f64 * 0.1);
                assert!(v > last, "{t:?} at {}", i as f64 * 0.1);
                last = v;
            }
        }
        assert_eq!(grade(Tonemap::None, 1.0, 0.25), 0.5);
        assert!(grade(Tonemap::Filmic, 0.0, 100.0) > 0.99);
        assert!((grade(Tonemap::Reinhard, 0.0, 1.0) - 0.5).abs() < 1e-15);
    }
}
