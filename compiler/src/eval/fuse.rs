//! Fused steps: the sums that distance programs are made of, run as one interpreter step.
//!
//! Lowering spells `length(p - c) - r` (spheres, tori, capsules, rounded boxes), a rotated
//! coordinate `m·p` or a plane `n·p - h` as chains of single-operation instructions: offsets,
//! squares or products with constants, the sums, a square root and a final offset. Each
//! instruction is one pass over the batch, storing a value that the next pass loads again.
//! A [`Fused`] step replaces such a chain with one loop computing `finish(Σ term(aᵢ, kᵢ))`
//! point by point in registers: the same IEEE operations in the same order, so results are
//! bit for bit those of the chain (of a NaN, only which NaN may differ: its sign or payload,
//! which nothing reads).
//!
//! The chain's inner instructions are recomputed by the step, not read; those that nothing
//! else reads run no step of their own. The rest of the program is untouched.

use crate::program::{Binary, Op, Program, Reg, Unary};

/// The terms of a fused sum.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    /// `(aᵢ + kᵢ)²` (a subtraction of a constant is the addition of its negation, exactly; an
    /// absent offset is `+ 0`, which changes only the sign of a zero, and squaring drops it).
    SquareAdd,
    /// `max(aᵢ, kᵢ)²`, the positive part of a box's corner vector.
    SquareMax,
    /// `aᵢ · kᵢ`, a row of a rotation or a plane's normal.
    Scale,
}

/// What is done with the sum `s`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Finish {
    /// Nothing.
    None,
    /// `s + k`.
    Add,
    /// `√s`.
    Sqrt,
    /// `√s + k`.
    SqrtAdd,
}

impl Finish {
    /// The instructions it stands for.
    fn ops(self) -> usize {
        match self {
            Finish::None => 0,
            Finish::Add | Finish::Sqrt => 1,
            Finish::SqrtAdd => 2,
        }
    }
}

/// A fused step rooted at one instruction.
#[derive(Debug, Clone)]
pub(super) struct Fused {
    pub kind: Kind,
    /// The operand and constant of each term (1 to 3), in the order the sum adds them.
    pub terms: Vec<(Reg, f64)>,
    pub finish: Finish,
    /// The offset of [`Finish::Add`] and [`Finish::SqrtAdd`].
    pub k: f64,
}

/// The fused steps of a program: the one each instruction roots, if any.
#[derive(Debug)]
pub(super) struct Fusions {
    pub fused: Vec<Option<Fused>>,
}

impl Fusions {
    /// The registers an instruction's step reads: a fused step's term operands, else its
    /// operands.
    pub fn reads(&self, program: &Program, i: usize) -> Vec<Reg> {
        match &self.fused[i] {
            Some(f) => f.terms.iter().map(|t| t.0).collect(),
            None => program.ops()[i].operands(),
        }
    }
}

/// Finds the fused steps of the instructions of `program` that are `live`.
///
/// Every live instruction that ends a chain roots a fused step. A chain's inner
/// instructions are pure arithmetic, so the step recomputes them from the chain's operands
/// instead of reading them; they keep a step of their own only where something else still
/// reads them (what runs is found again from [`Fusions::reads`]; a value shared by several
/// chains is recomputed by each, which costs a few operations per point and saves a pass
/// over memory).
pub(super) fn fuse(program: &Program, live: &[bool]) -> Fusions {
    let m = Matcher { ops: program.ops() };
    let fused = (0..program.len())
        .map(|i| if live[i] { m.fused(i) } else { None })
        .collect();
    Fusions { fused }
}

/// A term found while matching: `term(reg, k)` of a kind.
#[derive(Debug, Clone, Copy)]
struct Term {
    reg: Reg,
    k: f64,
    kind: Kind,
    /// The instructions it stands for.
    ops: usize,
    /// For a square, its operand (the term without its pre-operation); unused for products.
    squared: Reg,
}

struct Matcher<'p> {
    ops: &'p [Op],
}

impl Matcher<'_> {
    /// The instruction computing `r` where it is arithmetic a chain may recompute.
    fn inner(&self, r: Reg) -> Option<usize> {
        let j = r.0 as usize;
        matches!(self.ops[j], Op::Unary(..) | Op::Binary(..)).then_some(j)
    }

    fn constant(&self, r: Reg) -> Option<f64> {
        match self.ops[r.0 as usize] {
            Op::Const(c) => Some(c),
            _ => None,
        }
    }

    /// `op(x, k)` with a variable `x` and a constant `k` (either order where `op` commutes,
    /// exactly as IEEE addition and multiplication do).
    fn with_constant(&self, r: Reg, op: Binary) -> Option<(Reg, f64)> {
        let Op::Binary(o, x, y) = self.ops[self.inner(r)?] else {
            return None;
        };
        if o != op {
            return None;
        }
        let commutes = matches!(op, Binary::Add | Binary::Mul);
        match (self.constant(x), self.constant(y)) {
            (None, Some(k)) => Some((x, k)),
            (Some(k), None) if commutes => Some((y, k)),
            _ => None,
        }
    }

    /// `r` as a term: a square (of an offset or a `max` with a constant where there is one),
    /// or a product with a constant.
    fn term(&self, r: Reg) -> Option<Term> {
        let Op::Binary(Binary::Mul, a, b) = self.ops[self.inner(r)?] else {
            return None;
        };
        if a != b {
            let (x, k) = self.with_constant(r, Binary::Mul)?;
            return Some(Term {
                reg: x,
                k,
                kind: Kind::Scale,
                ops: 1,
                squared: r,
            });
        }
        let pre = |reg, k, kind| Term {
            reg,
            k,
            kind,
            ops: 2,
            squared: a,
        };
        // max(x, k), not max(k, x): the two differ where x is NaN.
        Some(if let Some((x, k)) = self.with_constant(a, Binary::Add) {
            pre(x, k, Kind::SquareAdd)
        } else if let Some((x, k)) = self.with_constant(a, Binary::Sub) {
            pre(x, -k, Kind::SquareAdd)
        } else if let Some((x, k)) = self.with_constant(a, Binary::Max) {
            pre(x, k, Kind::SquareMax)
        } else {
            Term {
                reg: a,
                k: 0.0,
                kind: Kind::SquareAdd,
                ops: 1,
                squared: a,
            }
        })
    }

    /// `r` as a sum of one to three terms, in the order they are added: a term, or an `add`
    /// of a term and a term or a two-term sum.
    fn sum(&self, r: Reg) -> Option<Vec<Term>> {
        if let Some(t) = self.term(r) {
            return Some(vec![t]);
        }
        let Op::Binary(Binary::Add, x, y) = self.ops[self.inner(r)?] else {
            return None;
        };
        // Addition commutes exactly, so `t + (u + v)` is `(u + v) + t`.
        for (first, last) in [(x, y), (y, x)] {
            let Some(t) = self.term(last) else {
                continue;
            };
            if let Some(u) = self.term(first) {
                return Some(vec![u, t]);
            }
            if let Some(Op::Binary(Binary::Add, p, q)) = self.inner(first).map(|j| self.ops[j]) {
                if let (Some(u), Some(v)) = (self.term(p), self.term(q)) {
                    return Some(vec![u, v, t]);
                }
            }
        }
        None
    }

    /// The fused step rooted at instruction `i`, if it stands for more than that instruction.
    fn fused(&self, i: usize) -> Option<Fused> {
        let root = Reg(i as u32);
        let sqrt_of = |r: Reg| match self.ops[r.0 as usize] {
            Op::Unary(Unary::Sqrt, a) => Some(a),
            _ => None,
        };
        // The finish, its offset, and the register holding the sum.
        let offset = self
            .with_constant(root, Binary::Add)
            .or_else(|| self.with_constant(root, Binary::Sub).map(|(x, k)| (x, -k)));
        let (finish, k, sum) = match (offset, sqrt_of(root)) {
            (Some((x, k)), _) => match sqrt_of(x) {
                Some(s) => (Finish::SqrtAdd, k, s),
                None => (Finish::Add, k, x),
            },
            (None, Some(s)) => (Finish::Sqrt, 0.0, s),
            (None, None) => (Finish::None, 0.0, root),
        };
        let mut terms = self.sum(sum)?;
        // One kind of term per step. Where squares of `max` and other squares mix, the `max`
        // instructions stay steps of their own, read as plain squares; products and squares
        // do not mix.
        let kind = match terms[0].kind {
            Kind::Scale => Kind::Scale,
            _ if terms.iter().all(|t| t.kind == Kind::SquareMax) => Kind::SquareMax,
            _ => Kind::SquareAdd,
        };
        for t in &mut terms {
            if (t.kind == Kind::Scale) != (kind == Kind::Scale) {
                return None;
            }
            if t.kind != kind {
                *t = Term {
                    reg: t.squared,
                    k: 0.0,
                    kind,
                    ops: 1,
                    squared: t.squared,
                };
            }
        }
        let ops = terms.iter().map(|t| t.ops).sum::<usize>() + terms.len() - 1 + finish.ops();
        (ops > 1).then(|| Fused {
            kind,
            terms: terms.iter().map(|t| (t.reg, t.k)).collect(),
            finish,
            k,
        })
    }
}
