//! The reference semantics of a whole program at one point: instruction by instruction, each
//! with the meaning of `scalar.rs`, a guarded block skipped where its bound is not below the
//! best distance (its results then take their values from before it). The interpreter's
//! batch loops, the placement warnings and the tests all compare with, or use, this one loop.

use super::{outline, scalar, Axis, Float, Op, Program, Reg};

/// What [`Program::run`] does, step by step, for a caller that counts or traces it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// The test of guarded block `b` (by index into [`Program::blocks`]).
    Test(usize),
    /// Instruction `i` runs.
    Op(usize),
}

impl Program {
    /// Runs the program at `p` and returns every register (those of skipped blocks hold
    /// zero); `step` sees each block test and each instruction run, in order.
    pub fn run<T: Float>(&self, p: [T; 3], step: impl FnMut(Step)) -> Vec<T> {
        self.run_with_normal(p, [T::zero(); 3], step)
    }

    /// [`Program::run`] at `p` where the surface normal is `n` (a colour field's program
    /// reads it, [`Axis::Nx`]…).
    pub fn run_with_normal<T: Float>(
        &self,
        p: [T; 3],
        n: [T; 3],
        mut step: impl FnMut(Step),
    ) -> Vec<T> {
        let ops = self.ops();
        let blocks = self.blocks();
        let mut regs: Vec<T> = vec![T::zero(); ops.len()];
        let mut next = 0;
        let mut i = 0;
        'run: while i < ops.len() {
            while let Some(b) = blocks.get(next).filter(|b| b.start == i) {
                step(Step::Test(next));
                next += 1;
                if regs[b.bound.0 as usize] >= regs[b.best.0 as usize] {
                    for j in b.end..b.end + b.results {
                        if let Op::Phi(_, other) = ops[j] {
                            regs[j] = regs[other.0 as usize];
                        }
                    }
                    i = b.end + b.results;
                    while blocks.get(next).is_some_and(|n| n.start < i) {
                        next += 1;
                    }
                    continue 'run;
                }
            }
            step(Step::Op(i));
            let r = |x: Reg| regs[x.0 as usize];
            regs[i] = match ops[i] {
                Op::Const(c) => T::from_f64(c),
                Op::Input(Axis::X) => p[0],
                Op::Input(Axis::Y) => p[1],
                Op::Input(Axis::Z) => p[2],
                Op::Input(Axis::Nx) => n[0],
                Op::Input(Axis::Ny) => n[1],
                Op::Input(Axis::Nz) => n[2],
                Op::Unary(u, a) => scalar::unary(u, r(a)),
                Op::Binary(b, x, y) => scalar::binary(b, r(x), r(y)),
                Op::Select(c, a, b) => scalar::select(r(c), r(a), r(b)),
                Op::Phi(a, _) => r(a),
                Op::Mesh(m, x, y, z) => self.mesh(m).distance([r(x), r(y), r(z)]),
                Op::Outline(k, x, y) => outline::distance(&self.outlines[k as usize], r(x), r(y)),
            };
            i += 1;
        }
        regs
    }
}
