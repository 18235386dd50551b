//! WGSL's built-in math functions (naga's `Expression::Math`), component by component
//! where WGSL applies them so, on hardware instructions or the sequences in `libm`.

use super::emit::{Class, Leaves, Op};
use super::isa::{DIV, EX2, FMA, LG2, MUL, RSQRT, SQRT, SUB};
use super::libm::Trig;
use super::types::{Sc, Shape};
use super::writer::{Frame, Fw};
use super::Error;
use naga::{Expression, Handle, MathFunction as M};
use smallvec::smallvec;

impl Fw<'_, '_> {
    pub fn math(
        &mut self,
        f: &Frame,
        fun: M,
        args: [Option<Handle<Expression>>; 4],
    ) -> Result<Leaves, Error> {
        let first =
            args[0].ok_or_else(|| Error::Invalid("a math function without arguments".into()))?;
        let ty = self.ty(f, first)?;
        if let Shape::Matrix { cols, rows } = self.cx.types.shape(ty)? {
            return self.matrix_math(f, fun, first, cols, rows);
        }
        let (sc, _) = self.sv(f, first)?;
        let mut ops: Vec<Leaves> = Vec::with_capacity(4);
        for a in args.iter().flatten() {
            ops.push(Leaves::from_slice(self.data(f, *a)?));
        }
        match fun {
            M::Dot
            | M::Cross
            | M::Length
            | M::Distance
            | M::Normalize
            | M::FaceForward
            | M::Reflect
            | M::Refract => self.geometry(fun, sc, &ops),
            _ => self.componentwise(fun, sc, &ops),
        }
    }

    /// A function applied to each component (scalar arguments are broadcast).
    fn componentwise(&mut self, fun: M, sc: Sc, ops: &[Leaves]) -> Result<Leaves, Error> {
        if ops.iter().any(|v| v.is_empty()) {
            return Err(Error::Invalid(format!("{fun:?} of an empty value")));
        }
        let n = ops.iter().map(|v| v.len()).max().unwrap_or(0);
        let mut out = Leaves::with_capacity(n);
        for i in 0..n {
            let a: Leaves = ops
                .iter()
                .map(|v| {
                    if v.len() == 1 {
                        v[0]
                    } else {
                        v.get(i).copied().unwrap_or(v[0])
                    }
                })
                .collect();
            out.push(self.scalar_math(fun, sc, &a)?);
        }
        Ok(out)
    }

    fn scalar_math(&mut self, fun: M, sc: Sc, a: &[Op]) -> Result<Op, Error> {
        let arg = |i: usize| {
            a.get(i)
                .copied()
                .ok_or_else(|| Error::Invalid(format!("{fun:?} lacks an argument")))
        };
        let x = arg(0)?;
        let fl = |s: &mut Self, op: &str| s.un(op, Class::F32, x);
        Ok(match (fun, sc) {
            (M::Abs, Sc::F32) => fl(self, "abs.f32"),
            // Not abs.s32: ptxas takes its result to be non-negative, which abs(i32::MIN)
            // (WGSL: i32::MIN) is not.
            (M::Abs, Sc::I32) => {
                let n = self.un("neg.s32", Class::B32, x);
                let neg = self.setp("lt.s32", x, Op::I32(0));
                self.selp(Sc::I32, n, x, neg)
            }
            (M::Abs, Sc::U32) => x,
            (M::Min | M::Max, _) => {
                let op = if fun == M::Min { "min" } else { "max" };
                self.bin_typed(op, sc.ptx(), sc.class(), x, arg(1)?)
            }
            (M::Clamp, _) => {
                let lo = self.bin_typed("max", sc.ptx(), sc.class(), x, arg(1)?);
                self.bin_typed("min", sc.ptx(), sc.class(), lo, arg(2)?)
            }
            (M::Saturate, Sc::F32) => {
                let lo = self.bin("max.f32", Class::F32, x, Op::f32(0.0));
                self.bin("min.f32", Class::F32, lo, Op::f32(1.0))
            }
            (M::Sin, Sc::F32) => self.trig(x, Trig::Sin),
            (M::Cos, Sc::F32) => self.trig(x, Trig::Cos),
            (M::Tan, Sc::F32) => self.trig(x, Trig::Tan),
            (M::Asin, Sc::F32) => self.asin(x),
            (M::Acos, Sc::F32) => self.acos(x),
            (M::Atan, Sc::F32) => self.atan(x),
            (M::Atan2, Sc::F32) => self.atan2(x, arg(1)?),
            (M::Sinh, Sc::F32) => self.sinh_cosh(x, false),
            (M::Cosh, Sc::F32) => self.sinh_cosh(x, true),
            (M::Tanh, Sc::F32) => self.tanh(x),
            (M::Asinh, Sc::F32) => self.asinh(x),
            (M::Acosh, Sc::F32) => self.acosh(x),
            (M::Atanh, Sc::F32) => self.atanh(x),
            (M::Radians, Sc::F32) => self.bin(MUL, Class::F32, x, Op::F32(0x3C8E_FA35)),
            (M::Degrees, Sc::F32) => self.bin(MUL, Class::F32, x, Op::F32(0x4265_2EE1)),
            (M::Ceil, Sc::F32) => fl(self, "cvt.rpi.f32.f32"),
            (M::Floor, Sc::F32) => fl(self, "cvt.rmi.f32.f32"),
            // Halves round to even, as WGSL's round() does.
            (M::Round, Sc::F32) => fl(self, "cvt.rni.f32.f32"),
            (M::Trunc, Sc::F32) => fl(self, "cvt.rzi.f32.f32"),
            (M::Fract, Sc::F32) => {
                let fl = fl(self, "cvt.rmi.f32.f32");
                self.bin(SUB, Class::F32, x, fl)
            }
            (M::Exp, Sc::F32) => self.exp(x),
            (M::Exp2, Sc::F32) => fl(self, EX2),
            (M::Log, Sc::F32) => self.ln(x),
            (M::Log2, Sc::F32) => fl(self, LG2),
            (M::Pow, Sc::F32) => self.pow(x, arg(1)?),
            (M::Sqrt, Sc::F32) => fl(self, SQRT),
            (M::InverseSqrt, Sc::F32) => fl(self, RSQRT),
            (M::Fma, Sc::F32) => self.tri(FMA, Class::F32, x, arg(1)?, arg(2)?),
            (M::Mix, Sc::F32) => {
                // e1·(1 − e3) + e2·e3
                let t = arg(2)?;
                let s = self.bin(SUB, Class::F32, Op::f32(1.0), t);
                let a = self.bin(MUL, Class::F32, x, s);
                self.tri(FMA, Class::F32, arg(1)?, t, a)
            }
            (M::Step, Sc::F32) => {
                let ge = self.setp("ge.f32", arg(1)?, x);
                self.selp(Sc::F32, Op::f32(1.0), Op::f32(0.0), ge)
            }
            (M::SmoothStep, Sc::F32) => self.smoothstep(x, arg(1)?, arg(2)?),
            (M::Sign, Sc::F32) => self.sign(x),
            (M::Sign, Sc::I32) => {
                let pos = self.setp("gt.s32", x, Op::I32(0));
                let neg = self.setp("lt.s32", x, Op::I32(0));
                let p = self.selp(Sc::I32, Op::I32(1), Op::I32(0), pos);
                self.selp(Sc::I32, Op::I32(-1), p, neg)
            }
            (M::CountOneBits, Sc::I32 | Sc::U32) => self.un("popc.b32", Class::B32, x),
            (M::ReverseBits, Sc::I32 | Sc::U32) => self.un("brev.b32", Class::B32, x),
            (M::CountLeadingZeros, Sc::I32 | Sc::U32) => self.un("clz.b32", Class::B32, x),
            (M::CountTrailingZeros, Sc::I32 | Sc::U32) => {
                let r = self.un("brev.b32", Class::B32, x);
                self.un("clz.b32", Class::B32, r)
            }
            (M::FirstLeadingBit, Sc::I32) => self.un("bfind.s32", Class::B32, x),
            (M::FirstLeadingBit, Sc::U32) => self.un("bfind.u32", Class::B32, x),
            _ => {
                return Err(Error::Unsupported(format!(
                    "the math function {fun:?} on {sc:?}"
                )))
            }
        })
    }

    /// smoothstep(lo, hi, x) = t²(3 − 2t), t = clamp((x − lo)/(hi − lo), 0, 1).
    fn smoothstep(&mut self, lo: Op, hi: Op, x: Op) -> Op {
        let n = self.bin(SUB, Class::F32, x, lo);
        let d = self.bin(SUB, Class::F32, hi, lo);
        let t = self.bin(DIV, Class::F32, n, d);
        let t = self.un("cvt.sat.f32.f32", Class::F32, t);
        let s = self.tri(FMA, Class::F32, Op::f32(-2.0), t, Op::f32(3.0));
        let t2 = self.bin(MUL, Class::F32, t, t);
        self.bin(MUL, Class::F32, t2, s)
    }

    /// sign(x): 1, −1 or 0 (and 0 for NaN).
    fn sign(&mut self, x: Op) -> Op {
        let pos = self.setp("gt.f32", x, Op::f32(0.0));
        let neg = self.setp("lt.f32", x, Op::f32(0.0));
        let p = self.selp(Sc::F32, Op::f32(1.0), Op::f32(0.0), pos);
        self.selp(Sc::F32, Op::f32(-1.0), p, neg)
    }

    /// Functions of whole vectors.
    fn geometry(&mut self, fun: M, sc: Sc, ops: &[Leaves]) -> Result<Leaves, Error> {
        let v = |i: usize| {
            ops.get(i)
                .ok_or_else(|| Error::Invalid(format!("{fun:?} lacks an argument")))
        };
        let a = v(0)?;
        Ok(match fun {
            M::Dot => smallvec![self.dot(sc, a, v(1)?)],
            M::Cross => self.cross(a, v(1)?)?,
            M::Length => smallvec![self.length(a)],
            M::Distance => {
                let d: Leaves = a
                    .iter()
                    .zip(v(1)?)
                    .map(|(&x, &y)| self.bin(SUB, Class::F32, x, y))
                    .collect();
                smallvec![self.length(&d)]
            }
            M::Normalize => {
                let d = self.dot(Sc::F32, a, a);
                let r = self.un(RSQRT, Class::F32, d);
                a.iter().map(|&x| self.bin(MUL, Class::F32, x, r)).collect()
            }
            M::FaceForward => {
                let d = self.dot(Sc::F32, v(1)?, v(2)?);
                let neg = self.setp("lt.f32", d, Op::f32(0.0));
                a.iter()
                    .map(|&x| {
                        let nx = self.un("neg.f32", Class::F32, x);
                        self.selp(Sc::F32, x, nx, neg)
                    })
                    .collect()
            }
            M::Reflect => {
                // e1 − 2·dot(e2, e1)·e2
                let n = v(1)?;
                let d = self.dot(Sc::F32, n, a);
                let k = self.bin(MUL, Class::F32, d, Op::f32(-2.0));
                a.iter()
                    .zip(n)
                    .map(|(&x, &y)| self.tri(FMA, Class::F32, k, y, x))
                    .collect()
            }
            M::Refract => self.refract(a, v(1)?, v(2)?)?,
            _ => return Err(Error::Unsupported(format!("the math function {fun:?}"))),
        })
    }

    fn dot(&mut self, sc: Sc, a: &[Op], b: &[Op]) -> Op {
        if sc == Sc::F32 {
            let terms: Vec<(Op, Op)> = a.iter().copied().zip(b.iter().copied()).collect();
            return self.dot_terms(&terms);
        }
        let t = sc.ptx();
        let mut acc = sc.zero();
        for (&x, &y) in a.iter().zip(b) {
            acc = self.tri(&format!("mad.lo.{t}"), Class::B32, x, y, acc);
        }
        acc
    }

    fn length(&mut self, a: &[Op]) -> Op {
        if let [x] = a {
            return self.un("abs.f32", Class::F32, *x);
        }
        let d = self.dot(Sc::F32, a, a);
        self.un(SQRT, Class::F32, d)
    }

    fn cross(&mut self, a: &[Op], b: &[Op]) -> Result<Leaves, Error> {
        let ([ax, ay, az], [bx, by, bz]) = (three(a)?, three(b)?);
        let mut c = |p: Op, q: Op, r: Op, s: Op| {
            let m = self.bin(MUL, Class::F32, r, s);
            let nm = self.un("neg.f32", Class::F32, m);
            self.tri(FMA, Class::F32, p, q, nm)
        };
        Ok(smallvec![
            c(ay, bz, az, by),
            c(az, bx, ax, bz),
            c(ax, by, ay, bx),
        ])
    }

    /// refract(e1, e2, η): k = 1 − η²(1 − dot(e2, e1)²); 0 if k < 0, else
    /// η·e1 − (η·dot(e2, e1) + sqrt(k))·e2.
    fn refract(&mut self, e1: &[Op], e2: &[Op], eta: &[Op]) -> Result<Leaves, Error> {
        let eta = *eta
            .first()
            .ok_or_else(|| Error::Invalid("refract lacks η".into()))?;
        let d = self.dot(Sc::F32, e2, e1);
        let d2 = self.bin(MUL, Class::F32, d, d);
        let omd = self.bin(SUB, Class::F32, Op::f32(1.0), d2);
        let eta2 = self.bin(MUL, Class::F32, eta, eta);
        let p = self.bin(MUL, Class::F32, eta2, omd);
        let k = self.bin(SUB, Class::F32, Op::f32(1.0), p);
        let neg = self.setp("lt.f32", k, Op::f32(0.0));
        let sk = self.un(SQRT, Class::F32, k);
        let m = self.tri(FMA, Class::F32, eta, d, sk);
        let nm = self.un("neg.f32", Class::F32, m);
        let mut out = Leaves::with_capacity(e1.len());
        for (&x, &n) in e1.iter().zip(e2) {
            let ex = self.bin(MUL, Class::F32, eta, x);
            let r = self.tri(FMA, Class::F32, nm, n, ex);
            out.push(self.selp(Sc::F32, Op::f32(0.0), r, neg));
        }
        Ok(out)
    }

    /// Functions of matrices: transpose (others are unsupported).
    fn matrix_math(
        &mut self,
        f: &Frame,
        fun: M,
        m: Handle<Expression>,
        cols: u32,
        rows: u32,
    ) -> Result<Leaves, Error> {
        let d = self.data(f, m)?;
        match fun {
            M::Transpose => {
                let (c, r) = (cols as usize, rows as usize);
                let at = |i: usize| {
                    d.get(i)
                        .copied()
                        .ok_or_else(|| Error::Invalid("a short matrix".into()))
                };
                (0..r)
                    .flat_map(|i| (0..c).map(move |j| (i, j)))
                    .map(|(i, j)| at(j * r + i))
                    .collect()
            }
            _ => Err(Error::Unsupported(format!(
                "the math function {fun:?} on matrices"
            ))),
        }
    }
}

fn three(v: &[Op]) -> Result<[Op; 3], Error> {
    match *v {
        [x, y, z] => Ok([x, y, z]),
        _ => Err(Error::Invalid(
            "cross() of a vector that is not 3-wide".into(),
        )),
    }
}
