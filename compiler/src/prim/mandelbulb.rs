//! The Mandelbulb fractal: its entry and its distance estimator, the iteration unrolled
//! over the program's operations.

use super::Kind::{Float as F, Int as I};
use super::Range::Within;
use super::{any, param, Def, Extent, Field, Prim};
use crate::program::builder::{Builder, P};
use crate::program::{Binary, Reg, Unary};

pub(super) static PRIMS: &[Prim] = &[Prim {
    name: "mandelbulb",
    profile: false,
    params: &[
        param("power", F, Def::Num(8.0), Within(2.0, 16.0)),
        param("iterations", I, Def::Int(8), Within(1.0, 64.0)),
    ],
    accepts: "`power` 2 … 16; `iterations` 1 … 64",
    doc: "The Mandelbulb fractal (a distance estimate).",
    check: any,
    field: Field::Unproven,
    // f ≥ |p| - 2 beyond radius 2, and f ≥ -0.5/e everywhere (docs/analysis.md).
    extent: |_| Extent::centred([2.2; 3], 2.2, [false; 3]),
    cost: |a| 20.0 + 45.0 * a.f(1),
    distance: |b, p, a| mandelbulb(b, p, a.f(0), a.f(1) as u32),
}];

/// Escape radius of the Mandelbulb iteration.
const BAILOUT: f64 = 2.0;

/// The Mandelbulb distance estimator 0.5·ln(r)·r/dr, with `iterations` unrolled steps of
/// z ← zⁿ + p in spherical coordinates (y up). A point escapes when r > 2; from then on
/// `select` keeps its state. Beyond |p| > 4 the field is |p| - 2 (the set lies inside the
/// ball of radius 2), which keeps the far field a bound where the estimator would overstate.
fn mandelbulb(b: &mut Builder, p: P, power: f64, iterations: u32) -> Reg {
    let mut z = p;
    let mut dr = b.c(1.0);
    for _ in 0..iterations {
        let r = b.len3(z);
        let bailout = b.c(BAILOUT);
        let escaped = b.lt(bailout, r);
        let (nz, ndr) = bulb_step(b, p, z, r, dr, power);
        z = [0, 1, 2].map(|i| b.select(escaped, z[i], nz[i]));
        dr = b.select(escaped, dr, ndr);
    }
    let r = b.len3(z);
    let r = b.maxc(r, 1e-30);
    let lr = b.un(Unary::Log, r);
    let d = b.mul(lr, r);
    let d = b.mulc(d, 0.5);
    let de = b.div(d, dr);
    let r0 = b.len3(p);
    let four = b.c(4.0);
    let far = b.lt(four, r0);
    let sphere = b.subc(r0, BAILOUT);
    b.select(far, sphere, de)
}

/// One iteration: dr ← n·rⁿ⁻¹·dr + 1, z ← rⁿ·(sin nθ cos nφ, cos nθ, sin nθ sin nφ) + p with
/// θ = acos(z.y / r), φ = atan2(z.z, z.x).
fn bulb_step(b: &mut Builder, p: P, z: P, r: Reg, dr: Reg, n: f64) -> (P, Reg) {
    let ((cos_nt, sin_nt), (cos_np, sin_np), rn1) = match integer_power(n) {
        Some(k) => bulb_angles_algebraic(b, z, r, k),
        None => bulb_angles_trig(b, z, r, n),
    };
    let ndr = b.mul(rn1, dr);
    let ndr = b.mulc(ndr, n);
    let ndr = b.addc(ndr, 1.0);
    let rn = b.mul(rn1, r);
    let x = b.mul(sin_nt, cos_np);
    let z2 = b.mul(sin_nt, sin_np);
    let dir = [x, cos_nt, z2];
    let nz = [0, 1, 2].map(|i| {
        let s = b.mul(rn, dir[i]);
        b.add(s, p[i])
    });
    (nz, ndr)
}

/// Powers the algebraic iteration handles: whole numbers from 2 to 64.
fn integer_power(n: f64) -> Option<u32> {
    (n.fract() == 0.0 && (2.0..=64.0).contains(&n)).then_some(n as u32)
}

/// A pair of registers: (cos, sin) of an angle.
type Angle = (Reg, Reg);

/// (cos nθ, sin nθ), (cos nφ, sin nφ) and rⁿ⁻¹ by acos, atan2 and pow.
fn bulb_angles_trig(b: &mut Builder, z: P, r: Reg, n: f64) -> (Angle, Angle, Reg) {
    let safe_r = b.maxc(r, 1e-30);
    let cos_t = b.div(z[1], safe_r);
    let cos_t = b.clampc(cos_t, -1.0, 1.0);
    let theta = b.un(Unary::Acos, cos_t);
    let theta = b.mulc(theta, n);
    let phi = b.bin(Binary::Atan2, z[2], z[0]);
    let phi = b.mulc(phi, n);
    let e = b.c(n - 1.0);
    let rn1 = b.bin(Binary::Pow, r, e);
    let t = (b.un(Unary::Cos, theta), b.un(Unary::Sin, theta));
    let f = (b.un(Unary::Cos, phi), b.un(Unary::Sin, phi));
    (t, f, rn1)
}

/// The same without trigonometry, for a whole power k (de Moivre): cos θ = z.y / r,
/// sin θ = √(1 - cos²θ) (θ ∈ [0, π]), cos φ = z.x / ρ, sin φ = z.z / ρ with ρ = |z.xz|, then
/// (cos + i·sin)^k and r^(k-1) by repeated squaring.
fn bulb_angles_algebraic(b: &mut Builder, z: P, r: Reg, k: u32) -> (Angle, Angle, Reg) {
    let safe_r = b.maxc(r, 1e-30);
    let cos_t = b.div(z[1], safe_r);
    let cos_t = b.clampc(cos_t, -1.0, 1.0);
    let c2 = b.mul(cos_t, cos_t);
    let one = b.c(1.0);
    let s2 = b.sub(one, c2);
    let s2 = b.maxc(s2, 0.0);
    let sin_t = b.sqrt(s2);
    let rho = b.len2(z[0], z[2]);
    let rho = b.maxc(rho, 1e-30);
    let cos_p = b.div(z[0], rho);
    let sin_p = b.div(z[2], rho);
    let t = complex_pow(b, (cos_t, sin_t), k);
    let f = complex_pow(b, (cos_p, sin_p), k);
    let rn1 = real_pow(b, r, k - 1);
    (t, f, rn1)
}

/// (a + ib)^k by squaring.
fn complex_pow(b: &mut Builder, base: Angle, k: u32) -> Angle {
    let mut acc = (b.c(1.0), b.c(0.0));
    let mut base = base;
    let mut k = k;
    while k > 0 {
        if k & 1 == 1 {
            acc = complex_mul(b, acc, base);
        }
        k >>= 1;
        if k > 0 {
            base = complex_square(b, base);
        }
    }
    acc
}

/// (a + ib)² = (a - b)(a + b) + i·2ab, in five operations.
fn complex_square(b: &mut Builder, (a, c): Angle) -> Angle {
    let (d, s) = (b.sub(a, c), b.add(a, c));
    let re = b.mul(d, s);
    let ac = b.mul(a, c);
    (re, b.add(ac, ac))
}

fn complex_mul(b: &mut Builder, (a, c): Angle, (d, e): Angle) -> Angle {
    let (ad, ce, ae, cd) = (b.mul(a, d), b.mul(c, e), b.mul(a, e), b.mul(c, d));
    (b.sub(ad, ce), b.add(ae, cd))
}

/// x^k by squaring.
fn real_pow(b: &mut Builder, x: Reg, k: u32) -> Reg {
    let mut acc = b.c(1.0);
    let mut base = x;
    let mut k = k;
    while k > 0 {
        if k & 1 == 1 {
            acc = b.mul(acc, base);
        }
        k >>= 1;
        if k > 0 {
            base = b.mul(base, base);
        }
    }
    acc
}
