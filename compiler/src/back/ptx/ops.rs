//! Operators: unary, binary (with WGSL's integer division, remainder and shift rules),
//! `select`, relational functions, conversions (saturating float-to-integer, as naga's
//! other back ends do) and matrix products.

use super::emit::Leaves;
use super::emit::{Class, Op};
use super::isa::{ADD, DIV, FMA, MUL, SUB};
use super::types::{Sc, Shape, Ty};
use super::writer::{Frame, Fw};
use super::Error;
use naga::{
    BinaryOperator as B, Expression, Handle, RelationalFunction, ScalarKind, UnaryOperator,
};
use smallvec::smallvec;

/// The largest f32 below 2^31 and below 2^32: the saturation bounds of WGSL's
/// float-to-integer conversions.
const I32_MAX_F: f32 = 2147483520.0;
const U32_MAX_F: f32 = 4294967040.0;

impl Fw<'_, '_> {
    pub fn unary(
        &mut self,
        f: &Frame,
        op: UnaryOperator,
        e: Handle<Expression>,
    ) -> Result<Leaves, Error> {
        let sc = self.leaf_sc(self.ty(f, e)?)?;
        let (ins, class) = match (op, sc) {
            (UnaryOperator::Negate, Sc::F32) => ("neg.f32", Class::F32),
            (UnaryOperator::Negate, Sc::I32 | Sc::U32) => ("neg.s32", Class::B32),
            (UnaryOperator::LogicalNot, Sc::Bool) | (UnaryOperator::BitwiseNot, Sc::Bool) => {
                ("not.pred", Class::Pred)
            }
            (UnaryOperator::BitwiseNot, Sc::I32 | Sc::U32) => ("not.b32", Class::B32),
            _ => return Err(Error::Invalid(format!("{op:?} of {sc:?}"))),
        };
        let d = self.data(f, e)?;
        Ok(d.iter().map(|&a| self.un(ins, class, a)).collect())
    }

    /// The scalar of each leaf of a scalar, vector or matrix type.
    pub fn leaf_sc(&self, ty: Ty) -> Result<Sc, Error> {
        match self.cx.types.shape(ty)? {
            Shape::Scalar(s) | Shape::Vector(_, s) => Ok(s),
            Shape::Matrix { .. } => Ok(Sc::F32),
            _ => Err(Error::Invalid(format!(
                "an operator on `{}`",
                self.cx.types.name(ty)
            ))),
        }
    }

    pub fn binary(
        &mut self,
        f: &Frame,
        op: B,
        l: Handle<Expression>,
        r: Handle<Expression>,
    ) -> Result<Leaves, Error> {
        let (lt, rt) = (self.ty(f, l)?, self.ty(f, r)?);
        let (ls, rs) = (self.cx.types.shape(lt)?, self.cx.types.shape(rt)?);
        let (a, b) = (self.data(f, l)?, self.data(f, r)?);
        match (op, ls, rs) {
            (B::Multiply, Shape::Matrix { cols, rows }, Shape::Vector(..)) => {
                return Ok(self.mat_vec(a, b, cols, rows))
            }
            (B::Multiply, Shape::Vector(..), Shape::Matrix { cols, rows }) => {
                return Ok(self.vec_mat(a, b, cols, rows))
            }
            (B::Multiply, Shape::Matrix { cols: k, rows }, Shape::Matrix { cols, .. }) => {
                return Ok(self.mat_mat(a, b, k, rows, cols))
            }
            _ => {}
        }
        let sc = self.leaf_sc(lt)?;
        let n = a.len().max(b.len());
        let pick = |v: &[Op], i: usize| {
            if v.len() == 1 {
                v[0]
            } else {
                v.get(i).copied().unwrap_or(v[0])
            }
        };
        if a.is_empty() || b.is_empty() {
            return Err(Error::Invalid("an operator on an empty value".into()));
        }
        (0..n)
            .map(|i| self.bin_leaf(op, sc, pick(a, i), pick(b, i)))
            .collect()
    }

    /// One leaf of a binary operator on operands of scalar `sc`.
    pub fn bin_leaf(&mut self, op: B, sc: Sc, a: Op, b: Op) -> Result<Op, Error> {
        let t = sc.ptx();
        let class = sc.class();
        let cmp = |s: &mut Self, c: &str| s.setp_typed(c, t, a, b);
        Ok(match (op, sc) {
            (B::Add, Sc::F32) => self.bin(ADD, class, a, b),
            (B::Subtract, Sc::F32) => self.bin(SUB, class, a, b),
            (B::Add, Sc::I32 | Sc::U32) => self.bin_typed("add", t, class, a, b),
            (B::Subtract, Sc::I32 | Sc::U32) => self.bin_typed("sub", t, class, a, b),
            (B::Multiply, Sc::F32) => self.bin(MUL, class, a, b),
            (B::Multiply, Sc::I32 | Sc::U32) => self.bin_typed("mul.lo", t, class, a, b),
            (B::Divide, Sc::F32) => self.bin(DIV, class, a, b),
            (B::Divide, Sc::I32 | Sc::U32) => self.int_div("div", sc, a, b),
            (B::Modulo, Sc::F32) => self.fmod(a, b),
            (B::Modulo, Sc::I32 | Sc::U32) => self.int_div("rem", sc, a, b),
            (B::Equal, Sc::Bool) => {
                let x = self.bin("xor.pred", Class::Pred, a, b);
                self.un("not.pred", Class::Pred, x)
            }
            (B::NotEqual, Sc::Bool) => self.bin("xor.pred", Class::Pred, a, b),
            (B::Equal, _) => cmp(self, "eq"),
            // Unordered: NaN != x is true.
            (B::NotEqual, Sc::F32) => cmp(self, "neu"),
            (B::NotEqual, _) => cmp(self, "ne"),
            (B::Less, _) => cmp(self, "lt"),
            (B::LessEqual, _) => cmp(self, "le"),
            (B::Greater, _) => cmp(self, "gt"),
            (B::GreaterEqual, _) => cmp(self, "ge"),
            (B::And | B::LogicalAnd, Sc::Bool) => self.bin("and.pred", class, a, b),
            (B::InclusiveOr | B::LogicalOr, Sc::Bool) => self.bin("or.pred", class, a, b),
            (B::ExclusiveOr, Sc::Bool) => self.bin("xor.pred", class, a, b),
            (B::And, Sc::I32 | Sc::U32) => self.bin("and.b32", class, a, b),
            (B::InclusiveOr, Sc::I32 | Sc::U32) => self.bin("or.b32", class, a, b),
            (B::ExclusiveOr, Sc::I32 | Sc::U32) => self.bin("xor.b32", class, a, b),
            (B::ShiftLeft | B::ShiftRight, Sc::I32 | Sc::U32) => {
                // WGSL uses the low 5 bits of the shift; PTX clamps larger shifts.
                let s = self.bin("and.b32", Class::B32, b, Op::U32(31));
                let ins = match (op, sc) {
                    (B::ShiftLeft, _) => "shl.b32",
                    (_, Sc::I32) => "shr.s32",
                    _ => "shr.u32",
                };
                self.bin(ins, class, a, s)
            }
            _ => return Err(Error::Invalid(format!("{op:?} on {sc:?}"))),
        })
    }

    /// WGSL's integer `/` and `%`: a zero divisor (and `i32::MIN / -1`) divides by 1
    /// instead, so `x / 0 = x` and `x % 0 = 0`.
    fn int_div(&mut self, what: &str, sc: Sc, a: Op, b: Op) -> Op {
        let t = sc.ptx();
        let safe = match b {
            Op::I32(v) if v != 0 && v != -1 => b,
            Op::U32(v) if v != 0 => b,
            _ => {
                let mut bad = self.setp(&format!("eq.{t}"), b, sc.zero());
                if sc == Sc::I32 {
                    let m1 = self.setp("eq.s32", b, Op::I32(-1));
                    let mn = self.setp("eq.s32", a, Op::I32(i32::MIN));
                    let ov = self.bin("and.pred", Class::Pred, m1, mn);
                    bad = self.bin("or.pred", Class::Pred, bad, ov);
                }
                self.selp(Sc::U32, Op::U32(1), b, bad)
            }
        };
        self.bin(&format!("{what}.{t}"), Class::B32, a, safe)
    }

    /// WGSL's float `%`: `a - b * trunc(a / b)` (the product and difference fused).
    fn fmod(&mut self, a: Op, b: Op) -> Op {
        let q = self.bin(DIV, Class::F32, a, b);
        let t = self.un("cvt.rzi.f32.f32", Class::F32, q);
        let nt = self.un("neg.f32", Class::F32, t);
        self.tri(FMA, Class::F32, nt, b, a)
    }

    pub fn select(
        &mut self,
        f: &Frame,
        cond: Handle<Expression>,
        accept: Handle<Expression>,
        reject: Handle<Expression>,
    ) -> Result<Leaves, Error> {
        let sc = self.leaf_sc(self.ty(f, accept)?)?;
        let (c, t, e) = (
            self.data(f, cond)?,
            self.data(f, accept)?,
            self.data(f, reject)?,
        );
        if c.is_empty() || t.len() != e.len() {
            return Err(Error::Invalid("a select of mismatched values".into()));
        }
        let mut out = Leaves::with_capacity(t.len());
        for i in 0..t.len() {
            let p = if c.len() == 1 {
                c[0]
            } else {
                c.get(i).copied().unwrap_or(c[0])
            };
            out.push(self.selp(sc, t[i], e[i], p));
        }
        Ok(out)
    }

    pub fn relational(
        &mut self,
        f: &Frame,
        fun: RelationalFunction,
        e: Handle<Expression>,
    ) -> Result<Leaves, Error> {
        let d = self.data(f, e)?;
        let fold = |s: &mut Self, ins: &str| {
            let mut acc = d.first().copied().unwrap_or(Op::Bool(false));
            for &x in d.iter().skip(1) {
                acc = s.bin(ins, Class::Pred, acc, x);
            }
            acc
        };
        Ok(match fun {
            RelationalFunction::All => smallvec![fold(self, "and.pred")],
            RelationalFunction::Any => smallvec![fold(self, "or.pred")],
            RelationalFunction::IsNan => d.iter().map(|&x| self.setp("nan.f32", x, x)).collect(),
            RelationalFunction::IsInf => d
                .iter()
                .map(|&x| {
                    let a = self.un("abs.f32", Class::F32, x);
                    self.setp("eq.f32", a, Op::f32(f32::INFINITY))
                })
                .collect(),
        })
    }

    /// `As`: a bit cast (`convert` is `None`) or a value conversion.
    pub fn convert(
        &mut self,
        f: &Frame,
        e: Handle<Expression>,
        kind: ScalarKind,
        convert: Option<u8>,
    ) -> Result<Leaves, Error> {
        let from = self.leaf_sc(self.ty(f, e)?)?;
        let to = Sc::of(naga::Scalar {
            kind,
            width: convert.unwrap_or(4),
        })?;
        let d = self.data(f, e)?;
        d.iter()
            .map(|&a| match convert {
                None => Ok(self.bitcast(to, a)),
                Some(_) => self.conv(from, to, a),
            })
            .collect()
    }

    fn bitcast(&mut self, to: Sc, a: Op) -> Op {
        match (a, to) {
            (Op::F32(b) | Op::U32(b), Sc::I32) => Op::I32(b as i32),
            (Op::F32(b), Sc::U32) => Op::U32(b),
            (Op::I32(i), Sc::U32) => Op::U32(i as u32),
            (Op::I32(i), Sc::F32) => Op::F32(i as u32),
            (Op::U32(u), Sc::F32) => Op::F32(u),
            (Op::Reg(r), _) if r.class == to.class() => a,
            (Op::Reg(_), _) => {
                let d = self.fresh(to);
                super::emit::ins!(self.out, "mov.b32 {d}, {a};");
                Op::Reg(d)
            }
            _ => a,
        }
    }

    /// A value conversion between scalars (WGSL's `f32(x)`, `i32(x)`, `bool(x)` ...).
    pub fn conv(&mut self, from: Sc, to: Sc, a: Op) -> Result<Op, Error> {
        Ok(match (from, to) {
            _ if from == to => a,
            (Sc::I32, Sc::U32) | (Sc::U32, Sc::I32) => self.bitcast(to, a),
            (Sc::F32, Sc::I32) => {
                let lo = self.bin("max.f32", Class::F32, a, Op::f32(-2147483648.0));
                let c = self.bin("min.f32", Class::F32, lo, Op::f32(I32_MAX_F));
                self.un("cvt.rzi.s32.f32", Class::B32, c)
            }
            (Sc::F32, Sc::U32) => {
                let lo = self.bin("max.f32", Class::F32, a, Op::f32(0.0));
                let c = self.bin("min.f32", Class::F32, lo, Op::f32(U32_MAX_F));
                self.un("cvt.rzi.u32.f32", Class::B32, c)
            }
            (Sc::I32, Sc::F32) => self.un("cvt.rn.f32.s32", Class::F32, a),
            (Sc::U32, Sc::F32) => self.un("cvt.rn.f32.u32", Class::F32, a),
            (Sc::Bool, Sc::F32) => self.selp(Sc::F32, Op::f32(1.0), Op::f32(0.0), a),
            (Sc::Bool, _) => self.selp(to, one(to), to.zero(), a),
            // bool(x) is x != 0; NaN is true.
            (Sc::F32, Sc::Bool) => self.setp("neu.f32", a, Op::f32(0.0)),
            (_, Sc::Bool) => self.setp("ne.b32", a, Op::U32(0)),
            _ => {
                return Err(Error::Invalid(format!(
                    "a conversion from {from:?} to {to:?}"
                )))
            }
        })
    }

    /// `m * v`: column-major `m` of `cols` columns of `rows`.
    fn mat_vec(&mut self, m: &[Op], v: &[Op], cols: u32, rows: u32) -> Leaves {
        (0..rows as usize)
            .map(|r| {
                let terms: Vec<(Op, Op)> = (0..cols as usize)
                    .map(|c| (at(m, c * rows as usize + r), at(v, c)))
                    .collect();
                self.dot_terms(&terms)
            })
            .collect()
    }

    /// `v * m`: each result component is the dot product of `v` with a column.
    fn vec_mat(&mut self, v: &[Op], m: &[Op], cols: u32, rows: u32) -> Leaves {
        (0..cols as usize)
            .map(|c| {
                let terms: Vec<(Op, Op)> = (0..rows as usize)
                    .map(|r| (at(v, r), at(m, c * rows as usize + r)))
                    .collect();
                self.dot_terms(&terms)
            })
            .collect()
    }

    /// `a * b` with `a` of `k` columns of `rows` and `b` of `cols` columns of `k`.
    fn mat_mat(&mut self, a: &[Op], b: &[Op], k: u32, rows: u32, cols: u32) -> Leaves {
        let (k, rows) = (k as usize, rows as usize);
        let mut out = Leaves::with_capacity(cols as usize * rows);
        for c in 0..cols as usize {
            for r in 0..rows {
                let terms: Vec<(Op, Op)> = (0..k)
                    .map(|i| (at(a, i * rows + r), at(b, c * k + i)))
                    .collect();
                out.push(self.dot_terms(&terms));
            }
        }
        out
    }

    /// Σ xᵢ·yᵢ as a multiply followed by fused multiply-adds.
    pub fn dot_terms(&mut self, terms: &[(Op, Op)]) -> Op {
        let Some((&(x, y), rest)) = terms.split_first() else {
            return Op::f32(0.0);
        };
        let mut acc = self.bin(MUL, Class::F32, x, y);
        for &(x, y) in rest {
            acc = self.tri(FMA, Class::F32, x, y, acc);
        }
        acc
    }
}

/// Leaf `i` of a matrix or vector (zero past the end, which validation rules out).
fn at(v: &[Op], i: usize) -> Op {
    v.get(i).copied().unwrap_or(Op::F32(0))
}

fn one(sc: Sc) -> Op {
    match sc {
        Sc::F32 => Op::f32(1.0),
        Sc::I32 => Op::I32(1),
        Sc::U32 => Op::U32(1),
        Sc::Bool => Op::Bool(true),
    }
}
