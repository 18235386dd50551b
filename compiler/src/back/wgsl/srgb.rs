//! The sRGB encoding of a finished pixel, shared by the host and the kernel: `encode` clamps a
//! linear value to [0, 1] and applies the sRGB transfer function (IEC 61966-2-1) rounded to
//! 8 bits; `thresholds` are the least linear values of each code, which the kernel searches
//! (`fn srgb_code` in kernel.wgsl) so that the GPU's 8-bit pixels are the host's, bit for bit.

/// A linear value clamped to [0, 1] and encoded with the sRGB transfer function (NaN is 0).
pub fn encode(c: f32) -> u8 {
    let c = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
    let s = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0 + 0.5) as u8
}

/// `thresholds()[v]` is the least f32 in [0, 1] that [`encode`]s to `v` or more (0 for
/// `v = 0`). `encode` never decreases as its argument grows (checked for every f32 in
/// [0, 1] by the runtime's `image::tests::the_srgb_table_is_srgb_encode_for_every_f32`), so
/// the number of thresholds from 1 to 255 at or below a value is its encoding. Computed
/// once: 255 binary searches over the bits of f32s (for non-negative f32s the order of the
/// bits is the order of the values).
pub fn thresholds() -> &'static [f32; 256] {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let mut at = [0.0f32; 256];
        for (v, t) in at.iter_mut().enumerate().skip(1) {
            let (mut lo, mut hi) = (0u32, 1.0f32.to_bits());
            while lo < hi {
                let mid = lo + (hi - lo) / 2;
                if (encode(f32::from_bits(mid)) as usize) < v {
                    lo = mid + 1;
                } else {
                    hi = mid;
                }
            }
            *t = f32::from_bits(lo);
        }
        at
    })
}

/// The kernel's search ([`thresholds`] at or below `c`, as `fn srgb_code` does it) in Rust.
pub fn search(c: f32) -> u8 {
    let at = thresholds();
    let mut v = 0usize;
    for step in [128, 64, 32, 16, 8, 4, 2, 1] {
        if c >= at[v + step] {
            v += step;
        }
    }
    v as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The kernel's search gives `encode` around every threshold, at the special values and
    /// over a grid of [-0.1, 1.1].
    #[test]
    fn the_search_is_the_encoding() {
        for &t in thresholds() {
            let b = t.to_bits();
            for d in b.saturating_sub(64)..=b.saturating_add(64).min(1.0f32.to_bits()) {
                let c = f32::from_bits(d);
                assert_eq!(search(c), encode(c), "{c:e}");
            }
        }
        for c in [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -0.0,
            0.0,
            1.0,
            -1.0,
            2.0,
        ] {
            assert_eq!(search(c), encode(c), "{c:e}");
        }
        for i in 0..=120_000 {
            let c = -0.1 + 1.2 * i as f32 / 120_000.0;
            assert_eq!(search(c), encode(c), "{c:e}");
        }
        assert_eq!(encode(0.5), 188);
    }
}
