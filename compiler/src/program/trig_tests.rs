//! The error bounds of `trig.rs`, against the library over millions of arguments (random bits
//! over the whole range, uniform angles, the values nearest multiples of π/2): its f32
//! functions against f64 libm, its f64 functions against libm's; and its special cases against
//! the library's.

use super::trig::{self, atan2f, cosf, reducedf, sinf, REDUCED};
use super::Float;
use crate::rng::Rng;

/// The bound of the module doc, in ulps of the exact value.
const BOUND: f64 = 0.501;

/// The distance in ulps where a value is NaN: none between two NaN, infinite between NaN and a
/// number; `None` between two numbers.
fn nan_ulps(a: f64, b: f64) -> Option<f64> {
    match (a.is_nan(), b.is_nan()) {
        (false, false) => None,
        (true, true) => Some(0.0),
        _ => Some(f64::INFINITY),
    }
}

/// How far `got` is from `exact`, in ulps of f32 at `exact` (subnormal spacing below the
/// normal range).
fn ulps(got: f32, exact: f64) -> f64 {
    if let Some(e) = nan_ulps(got as f64, exact) {
        return e;
    }
    let e = if exact == 0.0 {
        -126
    } else {
        (((exact.to_bits() >> 52) & 0x7ff) as i32 - 1023).max(-126)
    };
    (got as f64 - exact).abs() / 2f64.powi(e - 23)
}

/// The values nearest kπ/2 (where reduction is hardest) for k up to just beyond [`REDUCED`],
/// each as `near` gives it with its neighbours, and their negatives.
fn near_quarters<T: Float>(near: impl Fn(f64) -> [T; 3]) -> Vec<T> {
    let quarter = std::f64::consts::FRAC_PI_2;
    let mut xs = Vec::new();
    let mut k = 1.0;
    while k * quarter <= REDUCED as f64 * 1.01 {
        for x in near(k * quarter) {
            xs.extend([x, -x]);
        }
        k = (k * 1.0007f64).ceil();
    }
    xs
}

/// Pairs (y, x) for the arc tangent of every kind: random bits with random bits, angles with
/// angles, and each argument against a nearby magnitude (ratios near 1, the octants' seam),
/// each in the four orders and signs that reach every octant: `f` is called with each.
fn atan2_pairs<T: Float>(xs: &[T], rng: &mut Rng, mut f: impl FnMut(T, T)) {
    for (i, &y) in xs.iter().enumerate() {
        let x = match i % 3 {
            0 => xs[rng.below(xs.len())],
            1 => T::from_f64(rng.range(-10.0, 10.0)),
            _ => y * T::from_f64(rng.range(0.5, 2.0)),
        };
        for (y, x) in [(y, x), (x, y), (-y, x), (y, -x)] {
            f(y, x);
        }
    }
}

/// Arguments over the whole f32 range and where reduction is hardest: random bits, uniform
/// angles, and the f32 values on both sides of kπ/2 up to [`REDUCED`].
fn arguments() -> Vec<f32> {
    let mut rng = Rng::new(53);
    let mut xs = Vec::new();
    for _ in 0..1 << 21 {
        xs.push(f32::from_bits(rng.next_u64() as u32));
        xs.push(rng.range(-10.0, 10.0) as f32);
        xs.push(rng.range(-2e4, 2e4) as f32);
    }
    xs.extend(near_quarters(|v| {
        let v = v as f32;
        [
            v,
            f32::from_bits(v.to_bits() + 1),
            f32::from_bits(v.to_bits() - 1),
        ]
    }));
    xs.extend([
        0.0,
        -0.0,
        f32::MIN_POSITIVE,
        1e-45,
        -1e-45,
        1e-20,
        REDUCED,
        -REDUCED,
    ]);
    xs.extend([
        f32::from_bits(REDUCED.to_bits() + 1),
        1e30,
        f32::MAX,
        f32::MIN,
    ]);
    xs
}

#[test]
fn sine_and_cosine_are_within_the_bound_and_the_library_beyond_the_reduction() {
    let (mut worst_sin, mut worst_cos) = (0.0f64, 0.0f64);
    for x in arguments() {
        let (s, c) = (sinf(x), cosf(x));
        if reducedf(x) {
            let e = ulps(s, (x as f64).sin());
            assert!(
                e <= BOUND,
                "sin {x:e} ({:#x}): {s:e}, {e} ulps",
                x.to_bits()
            );
            let e2 = ulps(c, (x as f64).cos());
            assert!(
                e2 <= BOUND,
                "cos {x:e} ({:#x}): {c:e}, {e2} ulps",
                x.to_bits()
            );
            (worst_sin, worst_cos) = (worst_sin.max(e), worst_cos.max(e2));
        } else {
            assert_eq!(s.to_bits(), x.sin().to_bits(), "sin {x:e}");
            assert_eq!(c.to_bits(), x.cos().to_bits(), "cos {x:e}");
        }
    }
    // The bound is tight enough to mean something: the worst cases are above half an ulp.
    assert!(
        worst_sin > 0.49 && worst_cos > 0.49,
        "{worst_sin} {worst_cos}"
    );
    assert_eq!(sinf(-0.0).to_bits(), (-0.0f32).to_bits());
    assert_eq!(cosf(-0.0), 1.0);
    for x in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        assert!(sinf(x).is_nan() && cosf(x).is_nan(), "{x}");
    }
}

#[test]
fn the_arc_tangent_is_within_the_bound() {
    let xs = arguments();
    let mut rng = Rng::new(7);
    let mut worst = 0.0f64;
    atan2_pairs(&xs, &mut rng, |y, x| {
        let a = atan2f(y, x);
        let e = ulps(a, (y as f64).atan2(x as f64));
        assert!(e <= BOUND, "atan2({y:e}, {x:e}): {a:e}, {e} ulps");
        worst = worst.max(e);
    });
    assert!(worst > 0.49, "{worst}");
}

#[test]
fn the_arc_tangent_has_the_library_special_cases() {
    // Zeros, infinities and NaN give the library's values bit for bit; finite values (the
    // tiniest and the largest among them) are within the bound, where the library may not be:
    // its atan2f(-3e38, -1) is -1.5707963, not the correctly rounded -1.5707964.
    let special = [0.0, -0.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN];
    let values = [1.0, -1.0, 1e-45, -1e-45, 3e38, -3e38, 2.5];
    for y in special.into_iter().chain(values) {
        for x in special.into_iter().chain(values) {
            let a = atan2f(y, x);
            if special
                .iter()
                .any(|s| s.to_bits() == y.to_bits() || s.to_bits() == x.to_bits())
            {
                let b = y.atan2(x);
                assert!(
                    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                    "atan2({y}, {x}): {a:e}, the library {b:e}"
                );
            } else {
                let e = ulps(a, (y as f64).atan2(x as f64));
                assert!(e <= BOUND, "atan2({y:e}, {x:e}): {a:e}, {e} ulps");
            }
        }
    }
}

/// How far apart two f64 are, in ulps of `b` (the spacing above |b|).
fn ulps64(a: f64, b: f64) -> f64 {
    if let Some(e) = nan_ulps(a, b) {
        return e;
    }
    let m = b.abs();
    (a - b).abs() / (f64::from_bits(m.to_bits() + 1) - m)
}

/// f64 arguments: random bits, uniform angles, and the values on both sides of kπ/2.
fn arguments64() -> Vec<f64> {
    let mut rng = Rng::new(54);
    let mut xs = Vec::new();
    for _ in 0..1 << 21 {
        xs.push(f64::from_bits(rng.next_u64()));
        xs.push(rng.range(-10.0, 10.0));
        xs.push(rng.range(-2e4, 2e4));
        // Exponents from 2⁻⁶⁰ to 2²¹, the mantissa random.
        let e = 2f64.powi(rng.below(82) as i32 - 60);
        xs.push(rng.range(-1.0, 1.0) * e);
    }
    xs.extend(near_quarters(|v| {
        [
            v,
            f64::from_bits(v.to_bits() + 1),
            f64::from_bits(v.to_bits() - 1),
        ]
    }));
    let limit = REDUCED as f64;
    xs.extend([
        0.0,
        -0.0,
        f64::MIN_POSITIVE,
        5e-324,
        -5e-324,
        1e-200,
        limit,
        -limit,
    ]);
    xs.extend([
        f64::from_bits(limit.to_bits() + 1),
        1e300,
        f64::MAX,
        f64::MIN,
    ]);
    xs
}

#[test]
fn f64_sine_and_cosine_are_within_an_ulp_of_the_library() {
    let (mut worst, mut same, mut count) = (0.0f64, 0usize, 0usize);
    for x in arguments64() {
        let (s, c) = (trig::sin(x), trig::cos(x));
        let (ls, lc) = (x.sin(), x.cos());
        if trig::reduced(x) {
            for (got, lib, what) in [(s, ls, "sin"), (c, lc, "cos")] {
                let e = ulps64(got, lib);
                assert!(
                    e <= 1.0,
                    "{what} {x:e} ({:#x}): {got:e}, the library {lib:e}",
                    x.to_bits()
                );
                worst = worst.max(e);
                same += usize::from(got.to_bits() == lib.to_bits());
                count += 1;
            }
        } else {
            assert!(
                s.to_bits() == ls.to_bits() || s.is_nan() && ls.is_nan(),
                "sin {x:e}"
            );
            assert!(
                c.to_bits() == lc.to_bits() || c.is_nan() && lc.is_nan(),
                "cos {x:e}"
            );
        }
    }
    // Nearly all (98 %) are the library's bit for bit.
    assert!(
        same as f64 > 0.97 * count as f64,
        "{same} of {count}, worst {worst}"
    );
    assert_eq!(trig::sin(-0.0).to_bits(), (-0.0f64).to_bits());
    assert_eq!(trig::cos(-0.0), 1.0);
    for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert!(trig::sin(x).is_nan() && trig::cos(x).is_nan(), "{x}");
    }
}

#[test]
fn the_f64_arc_tangent_is_within_two_ulps_of_the_library() {
    let xs = arguments64();
    let mut rng = Rng::new(8);
    let (mut same, mut count) = (0usize, 0usize);
    atan2_pairs(&xs, &mut rng, |y, x| {
        let (a, b) = (trig::atan2(y, x), y.atan2(x));
        let e = ulps64(a, b);
        assert!(e <= 2.0, "atan2({y:e}, {x:e}): {a:e}, the library {b:e}");
        same += usize::from(a.to_bits() == b.to_bits());
        count += 1;
    });
    // Most (79 %) are the library's bit for bit.
    assert!(same as f64 > 0.75 * count as f64, "{same} of {count}");
    let special = [0.0, -0.0, f64::INFINITY, f64::NEG_INFINITY, f64::NAN];
    let values = [1.0, -1.0, 5e-324, -1e300, 2.5];
    for y in special.into_iter().chain(values) {
        for x in special.into_iter().chain(values) {
            let (a, b) = (trig::atan2(y, x), y.atan2(x));
            if special
                .iter()
                .any(|s| s.to_bits() == y.to_bits() || s.to_bits() == x.to_bits())
            {
                assert!(
                    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                    "atan2({y}, {x}): {a:e}, the library {b:e}"
                );
            } else {
                assert!(
                    ulps64(a, b) <= 2.0,
                    "atan2({y:e}, {x:e}): {a:e}, the library {b:e}"
                );
            }
        }
    }
}
