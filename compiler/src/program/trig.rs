//! The sine, cosine and four-quadrant arc tangent of distance programs, in f32 and f64, as
//! polynomials of plain additions, multiplications, divisions and selects: no branch and no
//! library call, so that a loop over a batch of points vectorises, with results identical
//! whether it does or not (and with or without AVX2). Checked against the library over
//! millions of arguments (`program/trig_tests.rs`).
//!
//! f32 ([`sinf`], [`cosf`], [`atan2f`]), computed in f64 and rounded once: within 0.501 ulp
//! of the exact value (the correctly rounded f32 but where the exact value lies within about
//! 2⁻³⁵ ulp of a halfway point).
//!
//! - Sine and cosine: reduced by the nearest multiple k of π/2 (Cody and Waite, π/2 in three
//!   parts, the first two of 33 bits, exact for |k| < 2²⁰), then Taylor polynomials of degree
//!   13 and 14 on [-π/4, π/4].
//! - Arc tangent: the quotient of the smaller by the larger magnitude, z in [0, 1], then
//!   atan z = z·P(z²) with P of degree 14 fitted to within 3·10⁻¹³; the octant and the sign
//!   restored by selects.
//!
//! f64 ([`sin`], [`cos`], [`atan2`]): within 1 ulp of the library's (glibc's, nearly always
//! correctly rounded) for sine and cosine, 2 ulps for the arc tangent.
//!
//! - Sine and cosine: the same reduction, π/2 in four parts (three of 33 bits) summed with
//!   the rounding errors kept, giving the remainder as an unevaluated sum of two f64, then
//!   the kernels of fdlibm (Sun, 1993), which take such a sum.
//! - Arc tangent: the same quotient, then fdlibm's: z < 7/16 directly, else from atan ½ or
//!   atan 1 by the difference formula, with its polynomial of degree 22.
//!
//! Sine and cosine reduce |x| ≤ [`REDUCED`]; beyond it, and for NaN and ±∞, they are the
//! library's (NaN for ±∞ and NaN). The arc tangents have IEEE's special cases (zeros,
//! infinities, NaN) as the library's `atan2` has them.
//!
//! The Rust writer copies this file into `--emit rust` output, so that the emitted functions
//! give the interpreter's values bit for bit: it uses nothing but the core language.

/// Arguments up to this magnitude are reduced here; sine and cosine beyond it are the
/// library's.
pub(crate) const REDUCED: f32 = 1_048_576.0;

/// sin x.
#[inline(always)]
pub(crate) fn sinf(x: f32) -> f32 {
    if reducedf(x) {
        sinf_reduced(x)
    } else {
        x.sin()
    }
}

/// cos x.
#[inline(always)]
pub(crate) fn cosf(x: f32) -> f32 {
    if reducedf(x) {
        cosf_reduced(x)
    } else {
        x.cos()
    }
}

/// Whether [`sinf_reduced`] and [`cosf_reduced`] are [`sinf`] and [`cosf`] at `x` (false for NaN).
#[inline(always)]
pub(crate) fn reducedf(x: f32) -> bool {
    x.abs() <= REDUCED
}

/// sin x where [`reducedf`] (any value elsewhere).
#[inline(always)]
pub(crate) fn sinf_reduced(x: f32) -> f32 {
    quadrantf(x, 0)
}

/// cos x where [`reducedf`] (any value elsewhere).
#[inline(always)]
pub(crate) fn cosf_reduced(x: f32) -> f32 {
    quadrantf(x, 1)
}

/// sin(x + shift·π/2): x = kπ/2 + r with |r| ≤ π/4, then ±sin r or ±cos r by the quadrant
/// k + shift.
#[inline(always)]
fn quadrantf(x: f32, shift: u64) -> f32 {
    // 1.5·2⁵²: adding it rounds to an integer, held in the low bits of the sum.
    const ROUND: f64 = 6_755_399_441_055_744.0;
    // π/2 = P1 + P2 + P3, P1 and P2 of 33 bits so that k·P1 and k·P2 are exact.
    const P1: f64 = 1.570_796_326_734_125_6;
    const P2: f64 = 6.077_100_506_303_966e-11;
    const P3: f64 = 2.022_266_248_795_950_6e-21;
    let x = x as f64;
    let s = x * core::f64::consts::FRAC_2_PI + ROUND;
    let q = s.to_bits().wrapping_add(shift);
    let k = s - ROUND;
    let r = ((x - k * P1) - k * P2) - k * P3;
    let r2 = r * r;
    // Taylor: sin r to r¹³, cos r to r¹⁴ (errors below 3·10⁻¹⁴ of the value on [-π/4, π/4]).
    // sin r as r·(1 + r²·…), so that sin(-0) is -0.
    let sin_r = r
        * (1.0
            + r2 * (-1.0 / 6.0
                + r2 * (1.0 / 120.0
                    + r2 * (-1.0 / 5_040.0
                        + r2 * (1.0 / 362_880.0
                            + r2 * (-1.0 / 39_916_800.0 + r2 * (1.0 / 6_227_020_800.0)))))));
    let cos_r = 1.0
        + r2 * (-0.5
            + r2 * (1.0 / 24.0
                + r2 * (-1.0 / 720.0
                    + r2 * (1.0 / 40_320.0
                        + r2 * (-1.0 / 3_628_800.0
                            + r2 * (1.0 / 479_001_600.0 + r2 * (-1.0 / 87_178_291_200.0)))))));
    let v = if q & 1 == 0 { sin_r } else { cos_r };
    let v = if q & 2 == 0 { v } else { -v };
    v as f32
}

/// The angle of (x, y) from the positive x axis, in [-π, π] (`atan2f`'s meaning, signed zeros
/// and infinities included).
#[inline(always)]
pub(crate) fn atan2f(y: f32, x: f32) -> f32 {
    // atan z / z = P(z²) on [0, 1] (Chebyshev fit, highest power first).
    const P: [f64; 15] = [
        0.000_170_460_404_661_882_4,
        -0.001_466_668_633_411_658_8,
        0.005_936_376_596_452_122,
        -0.015_232_491_909_076_56,
        0.028_410_612_112_699_588,
        -0.042_324_616_793_255_394,
        0.054_582_394_542_429_476,
        -0.065_362_288_118_493_73,
        0.076_631_773_577_540_78,
        -0.090_863_606_607_273_31,
        0.111_106_407_906_493_81,
        -0.142_856_846_612_540_53,
        0.199_999_990_134_210_3,
        -0.333_333_333_202_547_1,
        0.999_999_999_999_71,
    ];
    let (y, x) = (y as f64, x as f64);
    let (ay, ax) = (y.abs(), x.abs());
    // Past the diagonal: atan(y/x) = π/2 - atan(x/y).
    let steep = ay > ax;
    let (num, den) = if steep { (ax, ay) } else { (ay, ax) };
    // Equal magnitudes (two zeros, two infinities) make the diagonal or the axis.
    let equal = if ax == 0.0 { 0.0 } else { 1.0 };
    let z = if ax == ay { equal } else { num / den };
    let w = z * z;
    let mut p = 0.0;
    for c in P {
        p = p * w + c;
    }
    let a = z * p;
    let a = if steep {
        core::f64::consts::FRAC_PI_2 - a
    } else {
        a
    };
    let a = if x.is_sign_negative() {
        core::f64::consts::PI - a
    } else {
        a
    };
    a.copysign(y) as f32
}

/// Whether [`sin_reduced`] and [`cos_reduced`] are [`sin`] and [`cos`] at `x` (false for NaN).
#[inline(always)]
pub(crate) fn reduced(x: f64) -> bool {
    x.abs() <= REDUCED as f64
}

/// sin x.
#[inline(always)]
pub(crate) fn sin(x: f64) -> f64 {
    if reduced(x) {
        sin_reduced(x)
    } else {
        x.sin()
    }
}

/// cos x.
#[inline(always)]
pub(crate) fn cos(x: f64) -> f64 {
    if reduced(x) {
        cos_reduced(x)
    } else {
        x.cos()
    }
}

/// sin x where [`reduced`] (any value elsewhere).
#[inline(always)]
pub(crate) fn sin_reduced(x: f64) -> f64 {
    quadrant(x, 0)
}

/// cos x where [`reduced`] (any value elsewhere).
#[inline(always)]
pub(crate) fn cos_reduced(x: f64) -> f64 {
    quadrant(x, 1)
}

/// `a + b` as the rounded sum and its rounding error (Knuth's two-sum: exact, any order).
#[inline(always)]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// sin(x + shift·π/2): x = kπ/2 + (y0 + y1), then ±sin or ±cos of y0 + y1 by the quadrant
/// k + shift.
#[inline(always)]
fn quadrant(x: f64, shift: u64) -> f64 {
    const ROUND: f64 = 6_755_399_441_055_744.0;
    // π/2 = P1 + P2 + P3 + P4, the first three of 33 bits (fdlibm's).
    const P1: f64 = 1.570_796_326_734_125_6;
    const P2: f64 = 6.077_100_506_303_966e-11;
    const P3: f64 = 2.022_266_248_711_166_5e-21;
    const P4: f64 = 8.478_427_660_368_9e-32;
    let s = x * core::f64::consts::FRAC_2_PI + ROUND;
    let q = s.to_bits().wrapping_add(shift);
    let k = s - ROUND;
    let a = x - k * P1;
    let (hi, e1) = two_sum(a, -(k * P2));
    let (hi, e2) = two_sum(hi, -(k * P3));
    let lo = (e1 + e2) - k * P4;
    // hi where lo is 0, so that sin(-0) is -0.
    let y0 = if lo == 0.0 { hi } else { hi + lo };
    let y1 = (hi - y0) + lo;
    let v = if q & 1 == 0 {
        kernel_sin(y0, y1)
    } else {
        kernel_cos(y0, y1)
    };
    if q & 2 == 0 {
        v
    } else {
        -v
    }
}

/// sin(x + y) for |x| ≤ π/4, |y| below half an ulp of x (fdlibm's `__kernel_sin`).
#[inline(always)]
fn kernel_sin(x: f64, y: f64) -> f64 {
    const S1: f64 = -1.666_666_666_666_663_2e-1;
    const S2: f64 = 8.333_333_333_322_49e-3;
    const S3: f64 = -1.984_126_982_985_795e-4;
    const S4: f64 = 2.755_731_370_707_006_8e-6;
    const S5: f64 = -2.505_076_025_340_686_3e-8;
    const S6: f64 = 1.589_690_995_211_55e-10;
    let z = x * x;
    let w = z * z;
    let r = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6);
    let v = z * x;
    x - ((z * (0.5 * y - v * r) - y) - v * S1)
}

/// cos(x + y) for |x| ≤ π/4, |y| below half an ulp of x (fdlibm's `__kernel_cos`).
#[inline(always)]
fn kernel_cos(x: f64, y: f64) -> f64 {
    const C1: f64 = 0.0416666666666666;
    const C2: f64 = -1.388_888_888_887_411e-3;
    const C3: f64 = 2.480_158_728_947_673e-5;
    const C4: f64 = -2.755_731_435_139_066_3e-7;
    const C5: f64 = 2.087572321298175e-09;
    const C6: f64 = -1.135_964_755_778_819_5e-11;
    let z = x * x;
    let w = z * z;
    let r = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    w + (((1.0 - w) - hz) + (z * r - x * y))
}

/// The angle of (x, y) from the positive x axis, in [-π, π] (`atan2`'s meaning, signed zeros
/// and infinities included).
#[inline(always)]
pub(crate) fn atan2(y: f64, x: f64) -> f64 {
    // atan ½ and atan 1, and π/2 and π, as sums of two f64 (fdlibm's).
    const HALF_HI: f64 = 4.636_476_090_008_061e-1;
    const HALF_LO: f64 = 2.269_877_745_296_168_7e-17;
    const ONE_HI: f64 = core::f64::consts::FRAC_PI_4;
    const ONE_LO: f64 = 3.061_616_997_868_383e-17;
    const PIO2_HI: f64 = core::f64::consts::FRAC_PI_2;
    const PIO2_LO: f64 = 6.123_233_995_736_766e-17;
    const PI_HI: f64 = core::f64::consts::PI;
    const PI_LO: f64 = 1.224_646_799_147_353_2e-16;
    const AT: [f64; 11] = [
        3.333_333_333_333_293e-1,
        -1.999_999_999_987_648_3e-1,
        1.428_571_427_250_346_6e-1,
        -1.111_111_040_546_235_6e-1,
        9.090_887_133_436_507e-2,
        -7.691_876_205_044_83e-2,
        6.661_073_137_387_531e-2,
        -5.833_570_133_790_573_5e-2,
        4.976_877_994_615_932_4e-2,
        -3.653_157_274_421_691_6e-2,
        1.628_582_011_536_578_2e-2,
    ];
    let (ay, ax) = (y.abs(), x.abs());
    let steep = ay > ax;
    let (num, den) = if steep { (ax, ay) } else { (ay, ax) };
    let equal = if ax == 0.0 { 0.0 } else { 1.0 };
    let z = if ax == ay { equal } else { num / den };
    // t = (a·z - b)/(c + d·z): z itself, (2z - 1)/(2 + z) or (z - 1)/(z + 1); atan z is
    // atan t plus hi + lo.
    let (a, b, c, d, hi, lo) = if z < 0.4375 {
        (1.0, 0.0, 1.0, 0.0, 0.0, 0.0)
    } else if z < 0.6875 {
        (2.0, 1.0, 2.0, 1.0, HALF_HI, HALF_LO)
    } else {
        (1.0, 1.0, 1.0, 1.0, ONE_HI, ONE_LO)
    };
    let t = (a * z - b) / (c + d * z);
    let t2 = t * t;
    let w = t2 * t2;
    let s1 = t2 * (AT[0] + w * (AT[2] + w * (AT[4] + w * (AT[6] + w * (AT[8] + w * AT[10])))));
    let s2 = w * (AT[1] + w * (AT[3] + w * (AT[5] + w * (AT[7] + w * AT[9]))));
    let r = hi - ((t * (s1 + s2) - lo) - t);
    // Past the diagonal, π/2 ∓ r (exactly π/2 where r is 0, whatever the sign of x); else r
    // or π - r.
    let negative = x.is_sign_negative();
    let r = if steep {
        PIO2_HI + ((if negative { r } else { -r }) + PIO2_LO)
    } else if negative {
        PI_HI - (r - PI_LO)
    } else {
        r
    };
    r.copysign(y)
}
