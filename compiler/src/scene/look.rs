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
