//! The compiler of a tape: a program's instructions nested in their blocks, constants made
//! immediate, fused chains, the values each block gathers, and registers packed into slots
//! freed after their last use.

use super::{Code, Guard, Inst, Outputs, Step, Tape, INPUTS};
use crate::eval::fuse::{self, Fusions};
use crate::program::{Axis, Item, Op, Program, Reg};
use std::collections::HashMap;

impl Tape {
    /// Prepares `program` for evaluation of `outputs`.
    pub fn new(program: &Program, outputs: Outputs) -> Tape {
        let mut roots = vec![program.distance()];
        if outputs == Outputs::DistanceAndMaterial {
            roots.push(program.material());
        }
        let mut c = Compiler::new(program, &roots);
        c.permanent(&roots);
        let entries = nest(program);
        c.scope(&entries, &roots);
        let slot = |r: Reg| c.slot_of.get(r.0 as usize).copied().flatten().unwrap_or(0);
        c.tape.distance = slot(program.distance());
        if outputs == Outputs::DistanceAndMaterial {
            c.tape.material = Some(slot(program.material()));
        }
        c.tape.slots = (c.alloc.count - INPUTS).max(1) as usize;
        // Not where the material is the distance register: it is read from the slot.
        c.tape.direct = matches!(c.tape.steps.last(), Some(Step::Inst(i)) if i.dst == c.tape.distance)
            && c.tape.material != Some(c.tape.distance);
        c.tape.instructions = c
            .tape
            .steps
            .iter()
            .filter(|s| matches!(s, Step::Inst(_)))
            .count();
        c.tape
    }
}

/// Where each register lives, decided once per tape: scratch slots from [`INPUTS`] up.
#[derive(Debug)]
struct Allocator {
    free: Vec<u32>,
    count: u32,
}

impl Default for Allocator {
    fn default() -> Self {
        Allocator {
            free: Vec::new(),
            count: INPUTS,
        }
    }
}

impl Allocator {
    fn fresh(&mut self) -> u32 {
        self.free.pop().unwrap_or_else(|| {
            self.count += 1;
            self.count - 1
        })
    }
}

/// The nesting of a program: instructions and blocks (a block's `Phi`s belong to it).
#[derive(Debug)]
enum Entry {
    Op(usize),
    Block(usize, Vec<Entry>),
}

/// Builds the nesting from [`Program::items`].
fn nest(program: &Program) -> Vec<Entry> {
    let phi_of = program.phi_blocks();
    let mut stack: Vec<(usize, Vec<Entry>)> = vec![(usize::MAX, Vec::new())];
    for item in program.items() {
        match item {
            Item::Op(i) if phi_of[i].is_some() => {}
            Item::Op(i) => {
                if let Some(s) = stack.last_mut() {
                    s.1.push(Entry::Op(i));
                }
            }
            Item::Open(b) => stack.push((b, Vec::new())),
            Item::Close(_) => {
                if let Some((b, inner)) = stack.pop() {
                    if let Some(s) = stack.last_mut() {
                        s.1.push(Entry::Block(b, inner));
                    }
                }
            }
        }
    }
    stack.pop().map(|s| s.1).unwrap_or_default()
}

/// Compiles a program into a tape.
#[derive(Debug)]
struct Compiler<'p> {
    program: &'p Program,
    live: Vec<bool>,
    live_blocks: Vec<bool>,
    slot_of: Vec<Option<u32>>,
    fusions: Fusions,
    alloc: Allocator,
    tape: Tape,
    depth: usize,
    /// Per block, what [`Compiler::gathered`] found it reads from before it.
    outside: Vec<Vec<Reg>>,
}

/// The slot of an input.
fn axis_index(a: Axis) -> u32 {
    match a {
        Axis::X => 0,
        Axis::Y => 1,
        Axis::Z => 2,
        // The tape runs distance programs, which never read the normal (only a colour
        // field's program does, run by `Program::run_with_normal`): as the point's.
        Axis::Nx => 0,
        Axis::Ny => 1,
        Axis::Nz => 2,
    }
}

impl<'p> Compiler<'p> {
    /// A compiler of `program` for the results `roots`: what they need, then what still
    /// runs once fused steps read their chains' operands, and what each block gathers.
    fn new(program: &'p Program, roots: &[Reg]) -> Self {
        let (live, _) = program.live(roots);
        let fusions = fuse::fuse(program, &live);
        let (live, live_blocks) = program.live_reading(roots, |i| fusions.reads(program, i));
        let mut c = Compiler {
            program,
            live,
            live_blocks,
            slot_of: vec![None; program.len()],
            fusions,
            alloc: Allocator::default(),
            tape: Tape {
                steps: Vec::new(),
                guards: Vec::new(),
                constants: Vec::new(),
                slots: 0,
                depth: 0,
                instructions: 0,
                distance: 0,
                material: None,
                direct: false,
                meshes: program.meshes.clone(),
                outlines: program.outlines().to_vec(),
            },
            depth: 0,
            outside: Vec::new(),
        };
        c.outside = c.gathered();
        c
    }
}

impl Compiler<'_> {
    fn ops(&self) -> &[Op] {
        self.program.ops()
    }

    fn constant(&self, r: Reg) -> Option<f64> {
        match self.ops()[r.0 as usize] {
            Op::Const(c) => Some(c),
            _ => None,
        }
    }

    fn is_const(&self, r: Reg) -> bool {
        self.constant(r).is_some()
    }

    fn slot(&self, r: Reg) -> u32 {
        self.slot_of[r.0 as usize].unwrap_or(0)
    }

    /// Slots for the constants read from memory, kept for the evaluator's life (constants
    /// hold their value in every lane, so blocks read them directly), and the inputs' slots.
    fn permanent(&mut self, roots: &[Reg]) {
        let ops = self.program.ops();
        let mut need = vec![false; ops.len()];
        for r in roots {
            need[r.0 as usize] = true;
        }
        for (i, op) in ops.iter().enumerate() {
            if !self.live[i] {
                continue;
            }
            if self.fusions.fused[i].is_some() {
                for r in self.fusions.reads(self.program, i) {
                    need[r.0 as usize] = true;
                }
                continue;
            }
            match *op {
                Op::Binary(_, x, y) if self.is_const(y) => need[x.0 as usize] = true,
                Op::Binary(_, x, y) if self.is_const(x) => need[y.0 as usize] = true,
                Op::Binary(..) | Op::Const(_) | Op::Input(_) => {}
                _ => op.operands().iter().for_each(|r| need[r.0 as usize] = true),
            }
        }
        for (b, block) in self.program.blocks().iter().enumerate() {
            if self.live_blocks[b] {
                need[block.bound.0 as usize] = true;
                need[block.best.0 as usize] = true;
            }
        }
        // One slot per value: a large program repeats its constants (materials, radii,
        // the infinity of an empty union) many times, and each slot is a chunk of memory
        // the evaluator keeps filled.
        let mut by_value: HashMap<u64, u32> = HashMap::new();
        for (i, op) in ops.iter().enumerate() {
            match *op {
                Op::Const(c) if need[i] && self.live[i] => {
                    let s = *by_value.entry(c.to_bits()).or_insert_with(|| {
                        let s = self.alloc.fresh();
                        self.tape.constants.push((s, c));
                        s
                    });
                    self.slot_of[i] = Some(s);
                }
                Op::Input(a) if self.live[i] => self.slot_of[i] = Some(axis_index(a)),
                _ => {}
            }
        }
    }

    /// The registers block `b` reads that are defined outside it (constants aside), the
    /// values it must gather (found once for every block by [`Compiler::gathered`]).
    fn outside_reads(&self, b: usize) -> Vec<Reg> {
        let block = self.program.blocks()[b];
        let mut reads = self.outside[b].clone();
        let results = block.end..block.end + block.results;
        for (&op, &live) in self.ops()[results.clone()].iter().zip(&self.live[results]) {
            if let (true, Op::Phi(then, _)) = (live, op) {
                if (then.0 as usize) < block.start && !self.is_const(then) {
                    reads.push(then);
                }
            }
        }
        reads.sort();
        reads.dedup();
        reads
    }

    /// For every block, the registers defined before it (constants aside) that its live
    /// instructions, nested blocks' tests included, read: one walk over the program's items,
    /// each block handing its own set to the block around it, so that the work is the
    /// program's length plus the sizes of the sets, not the blocks times the program.
    fn gathered(&self) -> Vec<Vec<Reg>> {
        let blocks = self.program.blocks();
        let mut out = vec![Vec::new(); blocks.len()];
        let mut open: Vec<Vec<Reg>> = Vec::new();
        for item in self.program.items() {
            match item {
                Item::Op(i) => {
                    if let (true, Some(top)) = (self.live[i], open.last_mut()) {
                        top.extend(self.fusions.reads(self.program, i));
                    }
                }
                Item::Open(_) => open.push(Vec::new()),
                Item::Close(b) => {
                    let block = blocks[b];
                    let mut reads = open.pop().unwrap_or_default();
                    reads.retain(|&r| (r.0 as usize) < block.start && !self.is_const(r));
                    reads.sort();
                    reads.dedup();
                    if let Some(top) = open.last_mut() {
                        top.extend_from_slice(&reads);
                        if self.live_blocks[b] {
                            top.extend([block.bound, block.best]);
                        }
                    }
                    out[b] = reads;
                }
            }
        }
        out
    }

    /// What the scope around block `b` sees it read: its outside reads, its test and the
    /// values from before of its results.
    fn block_reads(&self, b: usize) -> Vec<Reg> {
        let block = self.program.blocks()[b];
        let mut reads = self.outside_reads(b);
        reads.push(block.bound);
        reads.push(block.best);
        for i in block.end..block.end + block.results {
            if let (true, Op::Phi(_, other)) = (self.live[i], self.ops()[i]) {
                reads.push(other);
            }
        }
        reads
    }

    /// For the registers a scope reads, the position of the last entry reading them
    /// (`entries.len()` for `at_end`: read when the scope ends).
    fn last_uses(&self, entries: &[Entry], at_end: &[Reg]) -> HashMap<u32, usize> {
        let mut last = HashMap::new();
        for (k, e) in entries.iter().enumerate() {
            match e {
                Entry::Op(i) if self.live[*i] => {
                    for r in self.fusions.reads(self.program, *i) {
                        last.insert(r.0, k);
                    }
                }
                Entry::Block(b, _) if self.live_blocks[*b] => {
                    for r in self.block_reads(*b) {
                        last.insert(r.0, k);
                    }
                }
                _ => {}
            }
        }
        for r in at_end {
            last.insert(r.0, entries.len());
        }
        last
    }

    /// Whether a register's slot outlives every scope (constants, and inputs outside
    /// blocks).
    fn permanent_reg(&self, r: Reg) -> bool {
        match self.ops()[r.0 as usize] {
            Op::Const(_) => true,
            Op::Input(_) => self.depth == 0,
            _ => false,
        }
    }

    /// Compiles one scope; `at_end` are the registers read when it ends.
    fn scope(&mut self, entries: &[Entry], at_end: &[Reg]) {
        let last = self.last_uses(entries, at_end);
        for (k, e) in entries.iter().enumerate() {
            let reads = match e {
                Entry::Op(i) if self.live[*i] => {
                    if !matches!(self.ops()[*i], Op::Const(_) | Op::Input(_)) {
                        let inst = self.inst(*i);
                        self.tape.steps.push(Step::Inst(inst));
                    }
                    self.fusions.reads(self.program, *i)
                }
                Entry::Block(b, inner) if self.live_blocks[*b] => {
                    self.block(*b, inner);
                    self.block_reads(*b)
                }
                _ => continue,
            };
            self.free_after(&reads, &last, k);
        }
    }

    /// Frees the slots of the registers whose last read is entry `k`.
    fn free_after(&mut self, reads: &[Reg], last: &HashMap<u32, usize>, k: usize) {
        let mut freed: Vec<u32> = Vec::new();
        for &r in reads {
            if self.permanent_reg(r) || last.get(&r.0) != Some(&k) {
                continue;
            }
            if let Some(s) = self.slot_of[r.0 as usize] {
                if !freed.contains(&s) {
                    freed.push(s);
                }
            }
        }
        self.alloc.free.extend(freed);
    }

    /// The step of instruction `i`: its destination is allocated before its operands are
    /// freed, so that it is never one of them.
    fn inst(&mut self, i: usize) -> Inst {
        let op = self.ops()[i];
        let mut ks = [0.0; 3];
        let (code, operands, k) = match (&self.fusions.fused[i], op) {
            (Some(f), _) => {
                for (slot, t) in ks.iter_mut().zip(&f.terms) {
                    *slot = t.1;
                }
                let regs = f.terms.iter().map(|t| t.0).collect();
                (
                    Code::Fused(f.kind, f.terms.len() as u8, f.finish),
                    regs,
                    f.k,
                )
            }
            (None, op) => match op {
                Op::Unary(u, a) => (Code::Unary(u), vec![a], 0.0),
                Op::Binary(b, x, y) => match (self.constant(x), self.constant(y)) {
                    (_, Some(k)) => (Code::BinaryK(b), vec![x], k),
                    (Some(k), None) => (Code::KBinary(b), vec![y], k),
                    (None, None) => (Code::Binary(b), vec![x, y], 0.0),
                },
                Op::Select(c, a, b) => (Code::Select, vec![c, a, b], 0.0),
                Op::Mesh(m, x, y, z) => (Code::Mesh(m), vec![x, y, z], 0.0),
                Op::Outline(k, x, y) => (Code::Outline, vec![x, y], k as f64),
                Op::Const(_) | Op::Input(_) | Op::Phi(..) => (Code::Select, Vec::new(), 0.0),
            },
        };
        let s: Vec<u32> = operands.iter().map(|&r| self.slot(r)).collect();
        // An operand a step has no use for repeats its first (a fused sum of fewer than
        // three terms still names three slots, which must exist where it runs).
        let at = |n: usize| s.get(n).or(s.first()).copied().unwrap_or(0);
        let dst = self.alloc.fresh();
        self.slot_of[i] = Some(dst);
        Inst {
            code,
            dst,
            a: at(0),
            b: at(1),
            c: at(2),
            k,
            ks,
        }
    }

    /// Compiles guarded block `b`: gathers, its scope, the results.
    fn block(&mut self, b: usize, inner: &[Entry]) {
        let block = self.program.blocks()[b];
        let reads = self.outside_reads(b);
        let (bound, best) = (self.slot(block.bound), self.slot(block.best));
        let mut saved = Vec::new();
        let mut gathers = Vec::new();
        for r in reads {
            let outside = self.slot(r);
            let copy = self.alloc.fresh();
            saved.push((r, self.slot_of[r.0 as usize]));
            self.slot_of[r.0 as usize] = Some(copy);
            gathers.push((outside, copy));
        }
        let g = self.tape.guards.len() as u32;
        self.tape.guards.push(Guard {
            bound,
            best,
            gathers,
            phis: Vec::new(),
            after: 0,
        });
        self.tape.steps.push(Step::Enter(g));
        let phis: Vec<(usize, Reg, Reg)> = (block.end..block.end + block.results)
            .filter(|&i| self.live[i])
            .filter_map(|i| match self.ops()[i] {
                Op::Phi(then, other) => Some((i, then, other)),
                _ => None,
            })
            .collect();
        let thens: Vec<Reg> = phis.iter().map(|p| p.1).collect();
        self.depth += 1;
        self.tape.depth = self.tape.depth.max(self.depth);
        self.scope(inner, &thens);
        self.depth -= 1;
        let then_slots: Vec<u32> = thens.iter().map(|&r| self.slot(r)).collect();
        let held: Vec<u32> = thens
            .iter()
            .filter(|&&r| !self.is_const(r))
            .map(|&r| self.slot(r))
            .collect();
        for (r, s) in saved {
            self.slot_of[r.0 as usize] = s;
        }
        let mut results = Vec::new();
        for (&(i, _, other), &then) in phis.iter().zip(&then_slots) {
            let dst = self.alloc.fresh();
            self.slot_of[i] = Some(dst);
            results.push((dst, then, self.slot(other)));
        }
        let mut held = held;
        held.sort_unstable();
        held.dedup();
        self.alloc.free.extend(held);
        self.tape.steps.push(Step::Leave(g));
        let guard = &mut self.tape.guards[g as usize];
        guard.phis = results;
        guard.after = self.tape.steps.len();
    }
}

#[cfg(test)]
mod tests;
