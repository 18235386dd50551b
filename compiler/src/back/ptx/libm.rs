//! f32 functions as instruction sequences: sin, cos and tan (the hardware approximations
//! after a Cody–Waite reduction to [−π, π], exact Payne–Hanek reduction beyond
//! |x| > 105615; `sin(a)` and `cos(a)` in straight-line code share one reduction), atan,
//! atan2, asin and acos (Cephes' minimax polynomials), exp (ex2 of x·log2(e), as the
//! Vulkan driver computes it), pow and the hyperbolic functions (on an exp with the
//! rounding error of x·log2(e) put back).
//! docs/ptx.md states each one's error.

use super::emit::{ins, Class, Op};
use super::isa::{ADD, COS, DIV, DIV_FULL, EX2, FMA, LG2, MUL, SIN, SQRT, SUB};
use super::writer::Fw;

/// The name of the large-argument reduction `.func`.
pub(super) const TRIG_REDUCE: &str = "__sdfc_trig_reduce";

const PI: f32 = std::f32::consts::PI;
const FRAC_PI_2: f32 = std::f32::consts::FRAC_PI_2;
const FRAC_PI_4: f32 = std::f32::consts::FRAC_PI_4;

/// Which trigonometric function of a reduced argument.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Trig {
    Sin,
    Cos,
    Tan,
}

impl Fw<'_, '_> {
    fn f(&mut self, op: &str, a: Op, b: Op) -> Op {
        self.bin(op, Class::F32, a, b)
    }

    fn fma(&mut self, a: Op, b: Op, c: Op) -> Op {
        self.tri(FMA, Class::F32, a, b, c)
    }

    /// A polynomial in `z` by Horner's rule, highest coefficient first.
    fn horner(&mut self, z: Op, coefficients: &[f32]) -> Op {
        let mut acc = Op::f32(coefficients[0]);
        for &c in &coefficients[1..] {
            acc = self.fma(acc, z, Op::f32(c));
        }
        acc
    }

    /// sin, cos or tan of `x`: the hardware approximations on x reduced to [−π, π].
    pub fn trig(&mut self, x: Op, which: Trig) -> Op {
        let r = match self.reduced.iter().find(|&&(a, _)| a == x) {
            Some(&(_, r)) => r,
            None => {
                let r = self.reduce_2pi(x);
                self.reduced.push((x, r));
                r
            }
        };
        // Near 0 the hardware's error is absolute (about 2^-21): within WGSL's absolute
        // 2^-11 for sin and cos, as in NVIDIA's Vulkan driver; tan (rare, and whose error
        // WGSL inherits from sin/cos) takes the first terms of its series there.
        match which {
            Trig::Sin => self.un(SIN, Class::F32, r),
            Trig::Cos => self.un(COS, Class::F32, r),
            Trig::Tan => {
                let s = self.un(SIN, Class::F32, r);
                let c = self.un(COS, Class::F32, r);
                let t = self.f(DIV, s, c);
                let series = self.odd_series(x, &[1.0 / 3.0, 2.0 / 15.0]);
                self.near_zero(x, 0.03125, series, t)
            }
        }
    }

    /// r = x − k·2π with |r| ≤ π (a little more beyond |x| = 105615): three-part
    /// Cody–Waite (2π = 4·(P1 + P2 + P3), each product exact) up to |x| = 105615, the
    /// exact Payne–Hanek reduction (a `.func`, modulo π/2) beyond; NaN for ±∞.
    fn reduce_2pi(&mut self, x: Op) -> Op {
        self.cx.trig_reduce.set(true);
        let t = self.f(MUL, x, Op::f32(1.0 / std::f32::consts::TAU));
        let k = self.un("cvt.rni.f32.f32", Class::F32, t);
        let r = self.fma(k, Op::F32(0xC0C9_0FDA), x);
        let r = self.fma(k, Op::F32(0xB4A2_2168), r);
        let r = self.fma(k, Op::F32(0xA8C2_34C5), r);
        let ax = self.un("abs.f32", Class::F32, x);
        let big = self.setp("gt.f32", ax, Op::f32(105615.0));
        let done = self.out.label("trig_reduced");
        ins!(self.out, "@!{big} bra {done};");
        let (rq, q) = (self.out.reg(Class::F32), self.out.reg(Class::B32));
        self.out.raw("\t{\n");
        ins!(self.out, ".param .f32 param0;");
        ins!(self.out, "st.param.f32 [param0], {x};");
        ins!(self.out, ".param .align 4 .b8 retval0[8];");
        ins!(self.out, "call (retval0), {TRIG_REDUCE}, (param0);");
        ins!(self.out, "ld.param.f32 {rq}, [retval0];");
        ins!(self.out, "ld.param.b32 {q}, [retval0+4];");
        self.out.raw("\t}\n");
        // x = rq + q·π/2: add back (q mod 4) quarter turns, as −1, 0, 1 or 2.
        let q3 = self.bin("and.b32", Class::B32, Op::Reg(q), Op::U32(3));
        let qf = self.un("cvt.rn.f32.u32", Class::F32, q3);
        let wrap = self.setp("gt.f32", qf, Op::f32(2.5));
        let qm = self.f(SUB, qf, Op::f32(4.0));
        let qf = self.selp(super::types::Sc::F32, qm, qf, wrap);
        let full = self.fma(qf, Op::f32(FRAC_PI_2), Op::Reg(rq));
        let _ = self.mov_to(r, full);
        self.out.place(&done);
        r
    }

    /// atan of `a` ≥ 0 (or NaN), by Cephes' reduction to |u| ≤ tan(π/8).
    fn atan_kernel(&mut self, a: Op) -> Op {
        use super::types::Sc::F32;
        let big = self.setp("gt.f32", a, Op::F32(0x401A_827A));
        let mid = self.setp("gt.f32", a, Op::F32(0x3ED4_13CD));
        let am1 = self.f(SUB, a, Op::f32(1.0));
        let ap1 = self.f(ADD, a, Op::f32(1.0));
        let num = self.selp(F32, am1, a, mid);
        let num = self.selp(F32, Op::f32(-1.0), num, big);
        let den = self.selp(F32, ap1, Op::f32(1.0), mid);
        let den = self.selp(F32, a, den, big);
        let u = self.f(DIV, num, den);
        let y0 = self.selp(F32, Op::f32(FRAC_PI_4), Op::f32(0.0), mid);
        let y0 = self.selp(F32, Op::f32(FRAC_PI_2), y0, big);
        let z = self.f(MUL, u, u);
        let p = self.horner(
            z,
            &[
                8.053_744_5e-2,
                -1.387_768_6e-1,
                1.997_771_1e-1,
                -3.333_295e-1,
            ],
        );
        let p = self.f(MUL, p, z);
        let k = self.fma(p, u, u);
        self.f(ADD, y0, k)
    }

    pub fn atan(&mut self, x: Op) -> Op {
        let a = self.un("abs.f32", Class::F32, x);
        let r = self.atan_kernel(a);
        self.f("copysign.f32", x, r)
    }

    /// atan2(y, x) with IEEE's quadrants and signed zeros; NaN if either is NaN.
    pub fn atan2(&mut self, y: Op, x: Op) -> Op {
        use super::types::Sc::F32;
        let ax = self.un("abs.f32", Class::F32, x);
        let ay = self.un("abs.f32", Class::F32, y);
        let mx = self.f("max.f32", ax, ay);
        let mn = self.f("min.f32", ax, ay);
        let t = self.f(DIV_FULL, mn, mx);
        let zero = self.setp("eq.f32", mx, Op::f32(0.0));
        let t = self.selp(F32, Op::f32(0.0), t, zero);
        let inf = self.setp("eq.f32", mn, Op::f32(f32::INFINITY));
        let t = self.selp(F32, Op::f32(1.0), t, inf);
        let a = self.atan_kernel(t);
        let swap = self.setp("gt.f32", ay, ax);
        let b = self.f(SUB, Op::f32(FRAC_PI_2), a);
        let a = self.selp(F32, b, a, swap);
        let xb = self.un("mov.b32", Class::B32, x);
        let xneg = self.setp("lt.s32", xb, Op::I32(0));
        let b = self.f(SUB, Op::f32(PI), a);
        let a = self.selp(F32, b, a, xneg);
        let r = self.f("copysign.f32", y, a);
        let nan = self.setp("nan.f32", x, y);
        let sum = self.f(ADD, x, y);
        self.selp(F32, sum, r, nan)
    }

    /// (asin |x|, acos |x|) pieces: the Cephes kernel `k` and whether |x| > 1/2, in
    /// which case k = asin(sqrt((1 − |x|)/2)).
    fn asin_kernel(&mut self, a: Op) -> (Op, Op) {
        use super::types::Sc::F32;
        let big = self.setp("gt.f32", a, Op::f32(0.5));
        let zb = self.fma(Op::f32(-0.5), a, Op::f32(0.5));
        let sb = self.un(SQRT, Class::F32, zb);
        let a2 = self.f(MUL, a, a);
        let z = self.selp(F32, zb, a2, big);
        let s = self.selp(F32, sb, a, big);
        let p = self.horner(
            z,
            &[
                4.216_32e-2,
                2.418_131e-2,
                4.547_002_6e-2,
                7.495_300_3e-2,
                1.666_675_2e-1,
            ],
        );
        let p = self.f(MUL, p, z);
        (self.fma(p, s, s), big)
    }

    pub fn asin(&mut self, x: Op) -> Op {
        let a = self.un("abs.f32", Class::F32, x);
        let (k, big) = self.asin_kernel(a);
        let r = self.fma(Op::f32(-2.0), k, Op::f32(FRAC_PI_2));
        let r = self.selp(super::types::Sc::F32, r, k, big);
        self.f("copysign.f32", x, r)
    }

    pub fn acos(&mut self, x: Op) -> Op {
        use super::types::Sc::F32;
        let a = self.un("abs.f32", Class::F32, x);
        let (k, big) = self.asin_kernel(a);
        let two_k = self.f(ADD, k, k);
        let small = self.f(SUB, Op::f32(FRAC_PI_2), k);
        let r = self.selp(F32, two_k, small, big);
        let neg = self.setp("lt.f32", x, Op::f32(0.0));
        let flipped = self.f(SUB, Op::f32(PI), r);
        self.selp(F32, flipped, r, neg)
    }

    /// WGSL's exp: ex2 of x·log2(e), as NVIDIA's Vulkan driver computes it. Rounding
    /// x·log2(e) adds up to |x|·2⁻²⁴ of relative error (|x| ulp at most), within WGSL's
    /// 3 + 2·|x| ulp; the hyperbolic functions use [`Self::exp_precise`].
    pub fn exp(&mut self, x: Op) -> Op {
        let t = self.f(MUL, x, Op::F32(0x3FB8_AA3B));
        self.un(EX2, Class::F32, t)
    }

    /// e^x to 2.6 ulp: ex2 of t = x·log2(e), times 1 + ε·ln 2 where ε is what rounding t
    /// lost.
    pub fn exp_precise(&mut self, x: Op) -> Op {
        let t = self.f(MUL, x, Op::F32(0x3FB8_AA3B));
        let nt = self.un("neg.f32", Class::F32, t);
        let e = self.fma(x, Op::F32(0x3FB8_AA3B), nt);
        let e = self.fma(x, Op::F32(0x32A5_7060), e);
        let c = self.fma(e, Op::f32(std::f32::consts::LN_2), Op::f32(1.0));
        let bad = self.setp("nan.f32", c, c);
        let c = self.selp(super::types::Sc::F32, Op::f32(1.0), c, bad);
        let y = self.un(EX2, Class::F32, t);
        self.f(MUL, y, c)
    }

    /// ln x = log2(x)·ln 2.
    pub fn ln(&mut self, x: Op) -> Op {
        let l = self.un(LG2, Class::F32, x);
        self.f(MUL, l, Op::f32(std::f32::consts::LN_2))
    }

    /// x^y = 2^(y·log2 x), as WGSL defines it: NaN for x < 0; 1 when y = 0 or x = 1.
    pub fn pow(&mut self, x: Op, y: Op) -> Op {
        use super::types::Sc::F32;
        let l = self.un(LG2, Class::F32, x);
        let t = self.f(MUL, y, l);
        let p = self.un(EX2, Class::F32, t);
        let y0 = self.setp("eq.f32", y, Op::f32(0.0));
        let x1 = self.setp("eq.f32", x, Op::f32(1.0));
        let one = self.bin("or.pred", Class::Pred, y0, x1);
        self.selp(F32, Op::f32(1.0), p, one)
    }

    /// x + x³·(c₁ + c₂x² + c₃x⁴ …): the start of an odd series, for small |x|.
    fn odd_series(&mut self, x: Op, c: &[f32]) -> Op {
        let z = self.f(MUL, x, x);
        let mut rev = c.iter().rev();
        let mut p = Op::f32(rev.next().copied().unwrap_or(0.0));
        for &k in rev {
            p = self.fma(p, z, Op::f32(k));
        }
        let p = self.f(MUL, p, z);
        self.fma(p, x, x)
    }

    /// `series` where |x| < `limit`, else `other` (a formula that loses relative
    /// accuracy near 0, where the first terms of the series are exact to f32).
    fn near_zero(&mut self, x: Op, limit: f32, series: Op, other: Op) -> Op {
        let a = self.un("abs.f32", Class::F32, x);
        let small = self.setp("lt.f32", a, Op::f32(limit));
        self.selp(super::types::Sc::F32, series, other, small)
    }

    /// sinh, cosh: E ± 1/(4E) with E = e^|x|/2 = e^(|x|/2)·e^(|x|/2)/2 (no overflow
    /// before the result overflows); sinh by its series near 0.
    pub fn sinh_cosh(&mut self, x: Op, cosh: bool) -> Op {
        let a = self.un("abs.f32", Class::F32, x);
        let h = self.f(MUL, a, Op::f32(0.5));
        let e = self.exp_precise(h);
        let half = self.f(MUL, e, Op::f32(0.5));
        let big = self.f(MUL, e, half);
        let small = self.f(DIV, Op::f32(0.25), big);
        if cosh {
            return self.f(ADD, big, small);
        }
        let d = self.f(SUB, big, small);
        let r = self.f("copysign.f32", x, d);
        let series = self.odd_series(x, &[1.0 / 6.0, 1.0 / 120.0, 1.0 / 5040.0]);
        self.near_zero(x, 0.5, series, r)
    }

    /// tanh x = sign(x)·(1 − 2/(e^{2|x|} + 1)), which tends to ±1 without overflow;
    /// its series near 0.
    pub fn tanh(&mut self, x: Op) -> Op {
        let a = self.un("abs.f32", Class::F32, x);
        let a2 = self.f(ADD, a, a);
        let e = self.exp_precise(a2);
        let d = self.f(ADD, e, Op::f32(1.0));
        let q = self.f(DIV, Op::f32(2.0), d);
        let r = self.f(SUB, Op::f32(1.0), q);
        let r = self.f("copysign.f32", x, r);
        let series = self.odd_series(x, &[-1.0 / 3.0, 2.0 / 15.0, -17.0 / 315.0]);
        self.near_zero(x, 0.25, series, r)
    }

    /// asinh x = sign(x)·ln(|x| + sqrt(x² + 1)); ln|x| + ln 2 for |x| > 4096 (where x²
    /// could overflow), the series near 0.
    pub fn asinh(&mut self, x: Op) -> Op {
        let a = self.un("abs.f32", Class::F32, x);
        let s = self.fma(a, a, Op::f32(1.0));
        let s = self.un(SQRT, Class::F32, s);
        let s = self.f(ADD, a, s);
        let r = self.ln(s);
        let r = self.log_of_double(a, r);
        let r = self.f("copysign.f32", x, r);
        let series = self.odd_series(x, &[-1.0 / 6.0, 3.0 / 40.0, -5.0 / 112.0]);
        self.near_zero(x, 0.25, series, r)
    }

    /// ln(2a) = ln a + ln 2 where a > 4096, else `r`.
    fn log_of_double(&mut self, a: Op, r: Op) -> Op {
        let l = self.ln(a);
        let l = self.f(ADD, l, Op::f32(std::f32::consts::LN_2));
        let big = self.setp("gt.f32", a, Op::f32(4096.0));
        self.selp(super::types::Sc::F32, l, r, big)
    }

    /// acosh x = ln(x + sqrt(x² − 1)); ln x + ln 2 for x > 4096.
    pub fn acosh(&mut self, x: Op) -> Op {
        let s = self.fma(x, x, Op::f32(-1.0));
        let s = self.un(SQRT, Class::F32, s);
        let s = self.f(ADD, x, s);
        let r = self.ln(s);
        self.log_of_double(x, r)
    }

    /// atanh x = ln((1 + x)/(1 − x))/2; its series near 0.
    pub fn atanh(&mut self, x: Op) -> Op {
        let n = self.f(ADD, Op::f32(1.0), x);
        let d = self.f(SUB, Op::f32(1.0), x);
        let q = self.f(DIV, n, d);
        let l = self.ln(q);
        let r = self.f(MUL, l, Op::f32(0.5));
        let series = self.odd_series(x, &[1.0 / 3.0, 1.0 / 5.0, 1.0 / 7.0]);
        self.near_zero(x, 0.15, series, r)
    }
}

/// The `.func` that reduces |x| > 105615 exactly (Payne–Hanek): the 24-bit mantissa
/// times 192 bits of 2/π, the two integer bits and 62 fraction bits around the binary
/// point, the fraction times π/2 in f64. Returns (r: f32 at 0, q: s32 at 4).
pub(super) fn trig_reduce_func() -> String {
    const TWO_OVER_PI: [u32; 6] = [
        0x3C43_9041,
        0xDB62_9599,
        0xF534_DDC0,
        0xFC27_57D1,
        0x4E44_1529,
        0xA2F9_836E,
    ];
    let mut s = String::new();
    s.push_str(&format!(
        "// x = r + q*pi/2 for |x| > 105615 (Payne-Hanek, exact).\n\
         .func (.param .align 4 .b8 {TRIG_REDUCE}_ret[8]) {TRIG_REDUCE}(.param .f32 {TRIG_REDUCE}_x)\n{{\n\
         \t.reg .pred %p<4>;\n\t.reg .b32 %r<40>;\n\t.reg .f32 %f<4>;\n\t.reg .b64 %rd<24>;\n\t.reg .f64 %fd<4>;\n\
         \tld.param.f32 %f1, [{TRIG_REDUCE}_x];\n\
         \tmov.b32 %r1, %f1;\n\
         \tand.b32 %r2, %r1, -2147483648;\n\
         \tbfe.u32 %r3, %r1, 23, 8;\n\
         \tadd.s32 %r4, %r3, -128;\n\
         \tshl.b32 %r5, %r1, 8;\n\
         \tor.b32 %r6, %r5, -2147483648;\n\
         \t// the product of the mantissa and 2/pi, words %r10 (lowest) to %r16\n\
         \tmov.u64 %rd1, 0;\n"
    ));
    for (q, w) in TWO_OVER_PI.iter().enumerate() {
        s.push_str(&format!(
            "\tmad.wide.u32 %rd{a}, %r6, {w}, %rd{c};\n\tcvt.u32.u64 %r{d}, %rd{a};\n\tshr.u64 %rd{b}, %rd{a}, 32;\n",
            a = 2 * q + 2,
            b = 2 * q + 3,
            c = 2 * q + 1,
            d = 10 + q
        ));
    }
    s.push_str(
        "\tcvt.u32.u64 %r16, %rd13;\n\
         \t// k = e / 32 picks the words around the binary point\n\
         \tshr.s32 %r7, %r4, 5;\n\
         \tand.b32 %r8, %r4, 31;\n\
         \tsetp.eq.s32 %p1, %r7, 1;\n\
         \tsetp.eq.s32 %p2, %r7, 2;\n\
         \tsetp.eq.s32 %p3, %r7, 3;\n\
         \tselp.b32 %r20, %r15, %r16, %p1;\n\
         \tselp.b32 %r20, %r14, %r20, %p2;\n\
         \tselp.b32 %r20, %r13, %r20, %p3;\n\
         \tselp.b32 %r21, %r14, %r15, %p1;\n\
         \tselp.b32 %r21, %r13, %r21, %p2;\n\
         \tselp.b32 %r21, %r12, %r21, %p3;\n\
         \tselp.b32 %r22, %r13, %r14, %p1;\n\
         \tselp.b32 %r22, %r12, %r22, %p2;\n\
         \tselp.b32 %r22, %r11, %r22, %p3;\n\
         \t// W: 2 integer bits, then 62 fraction bits\n\
         \tmov.b64 %rd14, {%r21, %r20};\n\
         \tshl.b64 %rd14, %rd14, %r8;\n\
         \tsub.s32 %r23, 32, %r8;\n\
         \tshr.u32 %r24, %r22, %r23;\n\
         \tcvt.u64.u32 %rd15, %r24;\n\
         \tor.b64 %rd14, %rd14, %rd15;\n\
         \tshr.u64 %rd16, %rd14, 62;\n\
         \tcvt.u32.u64 %r25, %rd16;\n\
         \tshl.b64 %rd17, %rd14, 2;\n\
         \t// a fraction of one half or more rounds q up and r becomes negative\n\
         \tshr.u64 %rd18, %rd17, 63;\n\
         \tcvt.u32.u64 %r26, %rd18;\n\
         \tadd.s32 %r25, %r25, %r26;\n\
         \tsetp.ne.u32 %p1, %r26, 0;\n\
         \tneg.s64 %rd19, %rd17;\n\
         \tselp.b64 %rd17, %rd19, %rd17, %p1;\n\
         \tshl.b32 %r27, %r26, 31;\n\
         \txor.b32 %r28, %r2, %r27;\n\
         \tsetp.ne.u32 %p2, %r2, 0;\n\
         \tneg.s32 %r29, %r25;\n\
         \tselp.b32 %r25, %r29, %r25, %p2;\n\
         \t// r = fraction * pi/2\n\
         \tcvt.rn.f64.u64 %fd1, %rd17;\n\
         \tmul.f64 %fd2, %fd1, 0d3BF921FB54442D18;\n\
         \tcvt.rn.f32.f64 %f2, %fd2;\n\
         \tmov.b32 %r30, %f2;\n\
         \tor.b32 %r30, %r30, %r28;\n\
         \tmov.b32 %f3, %r30;\n\
         \t// infinities give NaN\n\
         \tsetp.eq.u32 %p3, %r3, 255;\n\
         \tmul.f32 %f2, %f1, 0f00000000;\n\
         \tselp.f32 %f3, %f2, %f3, %p3;\n",
    );
    s.push_str(&format!(
        "\tst.param.f32 [{TRIG_REDUCE}_ret], %f3;\n\tst.param.b32 [{TRIG_REDUCE}_ret+4], %r25;\n\tret;\n}}\n"
    ));
    s
}
