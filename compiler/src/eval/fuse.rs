//! Fused steps: the Euclidean-length idiom of distance programs run as one interpreter step.
//!
//! Lowering spells `length(p - c) - r` (spheres, tori, capsules, rounded boxes) as a chain
//! of single-operation instructions: an offset per axis, a square per axis, the sums, a
//! square root and the radius. Each becomes one pass over the batch, storing a value that
//! the next pass loads again. A [`Norm`] replaces the whole chain with one step computing
//! `finish(Σ pre(aᵢ, kᵢ)²)` point by point in registers: the same IEEE operations in the same
//! order, so results are bit for bit those of the unfused chain.
//!
//! The chain's inner instructions are recomputed by the step, not read; those that nothing
//! else reads run no step of their own. The rest of the program is untouched.

use crate::lower::{Binary, Op, Program, Reg, Unary};

/// What each term's operand goes through before it is squared.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Pre {
    /// `aᵢ + kᵢ` (a subtraction of a constant is the addition of its negation, exactly; an
    /// absent offset is `+ 0`, which changes only the sign of a zero, and squaring drops it).
    Add,
    /// `max(aᵢ, kᵢ)`, the positive part of a box's corner vector.
    Max,
}

/// What is done with the sum of squares.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Finish {
    /// Nothing: the squared length.
    None,
    /// `√s`.
    Sqrt,
    /// `√s + k`.
    SqrtAdd,
}

/// A fused norm rooted at one instruction.
#[derive(Debug, Clone)]
pub(super) struct Norm {
    pub pre: Pre,
    /// The operand and offset of each term (1 to 3), in the order the sum adds them.
    pub terms: Vec<(Reg, f64)>,
    pub finish: Finish,
    /// The offset of [`Finish::SqrtAdd`].
    pub k: f64,
}

/// The fusions of a program: which instructions root a [`Norm`], and which instructions
/// and blocks still run as steps once the norms read their terms' operands directly.
#[derive(Debug)]
pub(super) struct Fusions {
    pub norms: Vec<Option<Norm>>,
    /// The instructions whose values some step, block or result reads.
    pub live: Vec<bool>,
    /// The blocks whose results are read.
    pub live_blocks: Vec<bool>,
}

impl Fusions {
    /// The registers an instruction's step reads: a norm's term operands, else its operands.
    pub fn reads(&self, program: &Program, i: usize) -> Vec<Reg> {
        reads(&self.norms, program, i)
    }
}

fn reads(norms: &[Option<Norm>], program: &Program, i: usize) -> Vec<Reg> {
    match &norms[i] {
        Some(norm) => norm.terms.iter().map(|t| t.0).collect(),
        None => program.ops()[i].operands(),
    }
}

/// A term found while matching: `pre(reg, k)²`.
#[derive(Debug, Clone, Copy)]
struct Term {
    reg: Reg,
    k: f64,
    /// Whether the pre-operation is a `max` (else an offset, or nothing).
    max: bool,
    /// Whether the term covers a pre-operation instruction besides the square.
    pre: bool,
    /// The operand of the square.
    squared: Reg,
}

struct Matcher<'p> {
    ops: &'p [Op],
}

/// Finds the fused norms of `program`, given which instructions the results `roots` need
/// (`live`), and what then still runs.
///
/// Every live instruction that heads a chain becomes a norm. A chain's inner instructions
/// are pure arithmetic, so a norm recomputes them from the chain's operands instead of
/// reading them; they keep a step of their own only where something else still reads them
/// (a value shared by several chains is recomputed by each, which costs a few operations
/// per point and saves a pass over memory).
pub(super) fn fuse(program: &Program, live: &[bool], roots: &[Reg]) -> Fusions {
    let ops = program.ops();
    let m = Matcher { ops };
    let norms: Vec<Option<Norm>> = (0..ops.len())
        .map(|i| if live[i] { m.norm(i) } else { None })
        .collect();
    let (live, live_blocks) = program.live_reading(roots, |i| reads(&norms, program, i));
    Fusions {
        norms,
        live,
        live_blocks,
    }
}

impl Matcher<'_> {
    /// The instruction computing `r` where it is pure arithmetic a chain may recompute.
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

    /// `r` as a term `pre(a, k)²`: a square, of an offset or `max` with a constant where
    /// there is one.
    fn term(&self, r: Reg) -> Option<Term> {
        let square = self.inner(r)?;
        let Op::Binary(Binary::Mul, a, b) = self.ops[square] else {
            return None;
        };
        if a != b {
            return None;
        }
        let plain = Term {
            reg: a,
            k: 0.0,
            max: false,
            pre: false,
            squared: a,
        };
        let Some(p) = self.inner(a) else {
            return Some(plain);
        };
        let (k, max, x) = match self.ops[p] {
            Op::Binary(Binary::Add, x, y) | Op::Binary(Binary::Add, y, x)
                if self.constant(y).is_some() && self.constant(x).is_none() =>
            {
                (self.constant(y)?, false, x)
            }
            Op::Binary(Binary::Sub, x, y)
                if self.constant(y).is_some() && self.constant(x).is_none() =>
            {
                (-self.constant(y)?, false, x)
            }
            // max(x, k), not max(k, x): the two differ where x is NaN.
            Op::Binary(Binary::Max, x, y)
                if self.constant(y).is_some() && self.constant(x).is_none() =>
            {
                (self.constant(y)?, true, x)
            }
            _ => return Some(plain),
        };
        Some(Term {
            reg: x,
            k,
            max,
            pre: true,
            squared: a,
        })
    }

    /// `r` as a sum of one to three terms, in the order they are added: a term, or an `add`
    /// of a term and a term or a two-term sum.
    fn sum(&self, r: Reg) -> Option<Vec<Term>> {
        if let Some(t) = self.term(r) {
            return Some(vec![t]);
        }
        let add = self.inner(r)?;
        let Op::Binary(Binary::Add, x, y) = self.ops[add] else {
            return None;
        };
        if x == y {
            return None;
        }
        // Addition commutes exactly, so `t + (u + v)` is `(u + v) + t`.
        for (first, last) in [(x, y), (y, x)] {
            if let Some(t) = self.term(last) {
                if let Some(u) = self.term(first) {
                    return Some(vec![u, t]);
                }
                if let Some(inner) = self.inner(first) {
                    if let Op::Binary(Binary::Add, p, q) = self.ops[inner] {
                        if let (Some(u), Some(v), true) = (self.term(p), self.term(q), p != q) {
                            return Some(vec![u, v, t]);
                        }
                    }
                }
            }
        }
        None
    }

    /// The norm rooted at instruction `i`, if it covers more than that instruction.
    fn norm(&self, i: usize) -> Option<Norm> {
        // The finish: `√s + k` (or `- k`), `√s`, or none (the root is the sum itself).
        let (finish, k, sum) = match self.ops[i] {
            Op::Binary(Binary::Add, x, y) | Op::Binary(Binary::Add, y, x)
                if self.constant(y).is_some() && self.sqrt_operand(x).is_some() =>
            {
                (Finish::SqrtAdd, self.constant(y)?, self.sqrt_operand(x)?)
            }
            Op::Binary(Binary::Sub, x, y)
                if self.constant(y).is_some() && self.sqrt_operand(x).is_some() =>
            {
                (Finish::SqrtAdd, -self.constant(y)?, self.sqrt_operand(x)?)
            }
            Op::Unary(Unary::Sqrt, a) => (Finish::Sqrt, 0.0, a),
            _ => (Finish::None, 0.0, Reg(i as u32)),
        };
        let mut terms = self.sum(sum)?;
        // One kind of pre-operation per step: where `max` terms and others mix, the `max`
        // instructions stay steps of their own, read as plain terms.
        let pre = if terms.iter().all(|t| t.max) {
            Pre::Max
        } else {
            Pre::Add
        };
        for t in &mut terms {
            if pre == Pre::Add && t.max {
                *t = Term {
                    reg: t.squared,
                    k: 0.0,
                    max: false,
                    pre: false,
                    squared: t.squared,
                };
            }
        }
        // The instructions covered: squares, pre-operations, additions, root and offset.
        let finishing = match finish {
            Finish::None => 0,
            Finish::Sqrt => 1,
            Finish::SqrtAdd => 2,
        };
        let covered = terms.iter().map(|t| 1 + usize::from(t.pre)).sum::<usize>()
            + (terms.len() - 1)
            + finishing;
        (covered > 1).then(|| Norm {
            pre,
            terms: terms.iter().map(|t| (t.reg, t.k)).collect(),
            finish,
            k,
        })
    }

    /// The operand of `r` where `r` is a square root.
    fn sqrt_operand(&self, r: Reg) -> Option<Reg> {
        match self.ops[r.0 as usize] {
            Op::Unary(Unary::Sqrt, a) => Some(a),
            _ => None,
        }
    }
}
