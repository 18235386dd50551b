//! Liveness over a distance program: which instructions and guarded blocks a set of
//! registers depends on, and which results of a block are needed (for the writers that give
//! each block's results names of their own).

use super::{Op, Program, Reg};

impl Program {
    /// Which instructions the registers `roots` depend on, and which blocks (a block is
    /// needed when one of its `Phi`s is; then so are its `bound` and `best`).
    pub fn live(&self, roots: &[Reg]) -> (Vec<bool>, Vec<bool>) {
        self.live_reading(roots, |i| self.ops[i].operands())
    }

    /// [`Program::live`] where instruction `i` reads `reads(i)` instead of its operands (a
    /// back end that computes some values its own way).
    pub fn live_reading(
        &self,
        roots: &[Reg],
        reads: impl Fn(usize) -> Vec<Reg>,
    ) -> (Vec<bool>, Vec<bool>) {
        let mut live = vec![false; self.ops.len()];
        let mut blocks = vec![false; self.blocks.len()];
        for r in roots {
            if let Some(l) = live.get_mut(r.0 as usize) {
                *l = true;
            }
        }
        let phi_block = self.phi_blocks();
        for i in (0..self.ops.len()).rev() {
            if !live[i] {
                continue;
            }
            for r in reads(i) {
                live[r.0 as usize] = true;
            }
            if let Some(b) = phi_block[i] {
                if !blocks[b] {
                    blocks[b] = true;
                    live[self.blocks[b].bound.0 as usize] = true;
                    live[self.blocks[b].best.0 as usize] = true;
                }
            }
        }
        (live, blocks)
    }

    /// For each instruction, the block it is a `Phi` of.
    pub fn phi_blocks(&self) -> Vec<Option<usize>> {
        let mut out = vec![None; self.ops.len()];
        for (b, block) in self.blocks.iter().enumerate() {
            for slot in &mut out[block.end..block.end + block.results] {
                *slot = Some(b);
            }
        }
        out
    }
}

/// The needed results of block `b`: (register, value inside, value from before).
pub fn results(program: &Program, b: usize, live: &[bool]) -> Vec<(usize, Reg, Reg)> {
    let block = &program.blocks()[b];
    (block.end..block.end + block.results)
        .filter(|&j| live[j])
        .filter_map(|j| match program.ops()[j] {
            Op::Phi(then, other) => Some((j, then, other)),
            _ => None,
        })
        .collect()
}
