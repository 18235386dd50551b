//! Tapes: distance programs prepared for batch evaluation (dead instructions dropped,
//! constant operands of two-operand instructions made immediate, fused steps where
//! [`fuse`] finds them, registers packed into reusable slots; the inputs are slots 0 to 2,
//! read in place), and the loop that runs each step.
//!
//! A guarded block becomes an `Enter` step, the block's steps and a `Leave` step. `Enter`
//! finds the points of the batch where the block runs; where none does, it sets the block's
//! results to their values from before and jumps past `Leave`. Otherwise it gathers the
//! values the block reads from outside into slots of its own, packed for the running points
//! only, so that the block's steps run over those points alone; `Leave` scatters the
//! results back. Blocks nest, each packing relative to the one around it.

use super::fuse::{self, Finish, Fusions, Kind};
use super::Float;
use crate::program::mesh::TriMesh;
use crate::program::outline::{self, Outline};
use crate::program::{scalar, Axis, Binary, Item, Op, Program, Reg, Unary};
use std::collections::HashMap;
use std::sync::Arc;

/// Which results a tape computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outputs {
    /// The distance only (sphere tracing, shadows, normals).
    Distance,
    /// The distance and the material id (shading).
    DistanceAndMaterial,
}

/// The operation of one instruction step.
#[derive(Debug, Clone, Copy)]
enum Code {
    /// `op(a)`
    Unary(Unary),
    /// `op(a, b)`
    Binary(Binary),
    /// `op(a, k)`
    BinaryK(Binary),
    /// `op(k, a)`
    KBinary(Binary),
    /// `select(a, b, c)`
    Select,
    /// A fused sum of 1 to 3 terms over `a`, `b`, `c` (see [`fuse`]).
    Fused(Kind, u8, Finish),
    /// The distance to the tape's mesh of this id at the point (`a`, `b`, `c`).
    Mesh(u32),
    /// The signed distance at (`a`, `b`) to the tape's outline number `k`.
    Outline,
}

/// One instruction over slots: `dst = code(a, b, c)` with the immediate `k` (and, for a
/// fused step, its terms' constants `ks`). `dst` never equals an operand.
#[derive(Debug, Clone, Copy)]
pub(super) struct Inst {
    code: Code,
    pub(super) dst: u32,
    a: u32,
    b: u32,
    c: u32,
    k: f64,
    ks: [f64; 3],
}

/// A step of a tape.
#[derive(Debug, Clone, Copy)]
pub(super) enum Step {
    /// An instruction.
    Inst(Inst),
    /// The start of a guarded block (index into the guards).
    Enter(u32),
    /// The end of a guarded block.
    Leave(u32),
}

/// The slots of a guarded block.
#[derive(Debug, Clone)]
pub(super) struct Guard {
    /// The block runs where `!(bound >= best)`.
    pub bound: u32,
    pub best: u32,
    /// (outside slot, inside slot) of each value the block reads from outside.
    pub gathers: Vec<(u32, u32)>,
    /// (result slot outside, value inside, value from before) of each result.
    pub phis: Vec<(u32, u32, u32)>,
    /// The index of the step after the block's `Leave`.
    pub after: usize,
}

/// Slot numbers below this one are the inputs x, y and z, read in place from the caller's
/// slices; scratch slot `s` (from `INPUTS` up) is the evaluator's `s - INPUTS`th chunk.
pub(super) const INPUTS: u32 = 3;

/// A program prepared for an [`super::Evaluator`].
#[derive(Debug, Clone)]
pub struct Tape {
    steps: Vec<Step>,
    guards: Vec<Guard>,
    constants: Vec<(u32, f64)>,
    slots: usize,
    depth: usize,
    instructions: usize,
    distance: u32,
    material: Option<u32>,
    /// Whether the last step computes the distance at the top level, and so can write it
    /// straight into the caller's output.
    direct: bool,
    /// The program's meshes, by id.
    meshes: Vec<Option<std::sync::Arc<TriMesh>>>,
    /// The program's outlines ([`Op::Outline`]).
    outlines: Vec<Arc<Outline>>,
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

    /// The meshes its steps read, by id.
    pub(super) fn meshes(&self) -> &[Option<std::sync::Arc<TriMesh>>] {
        &self.meshes
    }

    /// Number of instructions run per point (when every guarded block runs).
    pub fn len(&self) -> usize {
        self.instructions
    }

    /// True when the tape runs no instruction (the result is a constant or an input).
    pub fn is_empty(&self) -> bool {
        self.instructions == 0
    }

    /// Number of scratch slots (of one chunk each) an evaluator needs (inputs not counted).
    pub fn slot_count(&self) -> usize {
        self.slots
    }

    /// The deepest nesting of guarded blocks.
    pub fn depth(&self) -> usize {
        self.depth
    }

    pub(super) fn outlines(&self) -> &[Arc<Outline>] {
        &self.outlines
    }

    pub(super) fn steps(&self) -> &[Step] {
        &self.steps
    }

    pub(super) fn guard(&self, g: u32) -> &Guard {
        &self.guards[g as usize]
    }

    pub(super) fn constants(&self) -> &[(u32, f64)] {
        &self.constants
    }

    pub(super) fn distance_slot(&self) -> u32 {
        self.distance
    }

    pub(super) fn material_slot(&self) -> Option<u32> {
        self.material
    }

    /// Whether the last step computes the distance at the top level, and so can write it
    /// straight into the caller's output instead of its slot.
    pub(super) fn direct(&self) -> bool {
        self.direct
    }
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
        for (i, op) in ops.iter().enumerate() {
            match *op {
                Op::Const(c) if need[i] && self.live[i] => {
                    let s = self.alloc.fresh();
                    self.slot_of[i] = Some(s);
                    self.tape.constants.push((s, c));
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

impl Inst {
    /// Runs this step on the first `n` points: into `out` where given, else into its own
    /// slot of `slots` (scratch slots of `chunk` values, back to back), which is split off
    /// the buffer; operands are read from the rest of it, or from the inputs.
    #[inline(always)]
    pub(super) fn apply<T: Float>(
        &self,
        (meshes, outlines): (&[Option<std::sync::Arc<TriMesh>>], &[Arc<Outline>]),
        slots: &mut [T],
        out: Option<&mut [T]>,
        inputs: [&[T]; 3],
        chunk: usize,
        n: usize,
    ) {
        let (d, sources) = match out {
            Some(out) => (out, Sources::whole(inputs, slots, chunk, n)),
            None => {
                let dst = (self.dst - INPUTS) as usize;
                let (lo, rest) = slots.split_at_mut(dst * chunk);
                let (d, hi) = rest.split_at_mut(chunk);
                let sources = Sources {
                    inputs,
                    lo,
                    hi,
                    dst,
                    chunk,
                    n,
                };
                (d, sources)
            }
        };
        let d = &mut d[..n];
        let k = T::from_f64(self.k);
        match self.code {
            Code::Unary(u) => unary_loop(u, d, sources.get(self.a)),
            Code::Binary(b) => binary_loop(b, d, sources.get(self.a), sources.get(self.b)),
            Code::BinaryK(b) => binary_k_loop(b, d, sources.get(self.a), k),
            Code::KBinary(b) => k_binary_loop(b, d, k, sources.get(self.a)),
            Code::Select => {
                let (c, x, y) = (
                    sources.get(self.a),
                    sources.get(self.b),
                    sources.get(self.c),
                );
                for (((o, &c), &p), &q) in d.iter_mut().zip(c).zip(x).zip(y) {
                    *o = scalar::select(c, p, q);
                }
            }
            Code::Fused(kind, terms, finish) => {
                let [k0, k1, k2] = self.ks;
                let ks = [T::from_f64(k0), T::from_f64(k1), T::from_f64(k2)];
                let x = [
                    sources.get(self.a),
                    sources.get(self.b),
                    sources.get(self.c),
                ];
                fused_loop(kind, terms, finish, d, x, ks, k);
            }
            Code::Mesh(m) => {
                let mesh = meshes[m as usize]
                    .as_deref()
                    .expect("a tape holds every mesh its program names");
                let (x, y, z) = (
                    sources.get(self.a),
                    sources.get(self.b),
                    sources.get(self.c),
                );
                // Each lane's walk starts bounded by the triangle nearest to the lane before
                // (neighbouring lanes are near points: the same results, fewer nodes).
                let mut hint = 0;
                map3(d, x, y, z, |x, y, z| {
                    mesh.distance_from([x, y, z], &mut hint)
                });
            }
            Code::Outline => {
                let o = &outlines[self.k as usize];
                let (x, y) = (sources.get(self.a), sources.get(self.b));
                for ((r, &x), &y) in d.iter_mut().zip(x).zip(y) {
                    *r = outline::distance(o, x, y);
                }
            }
        }
    }
}

/// Where an instruction's operands are read: the inputs, and the scratch slots below (`lo`)
/// and above (`hi`) its destination slot `dst` (all in `lo` when it writes elsewhere).
pub(super) struct Sources<'a, T> {
    inputs: [&'a [T]; 3],
    lo: &'a [T],
    hi: &'a [T],
    dst: usize,
    chunk: usize,
    n: usize,
}

impl<'a, T> Sources<'a, T> {
    /// Every slot readable: the inputs and all of `slots`.
    #[inline(always)]
    pub(super) fn whole(inputs: [&'a [T]; 3], slots: &'a [T], chunk: usize, n: usize) -> Self {
        Sources {
            inputs,
            lo: slots,
            hi: &[],
            dst: usize::MAX,
            chunk,
            n,
        }
    }

    /// The first `n` values of slot `s` (never the destination).
    #[inline(always)]
    pub(super) fn get(&self, s: u32) -> &'a [T] {
        let Some(s) = s.checked_sub(INPUTS) else {
            return &self.inputs[s as usize][..self.n];
        };
        let s = s as usize;
        if s < self.dst {
            &self.lo[s * self.chunk..][..self.n]
        } else {
            &self.hi[(s - self.dst - 1) * self.chunk..][..self.n]
        }
    }
}

#[inline(always)]
fn map1<T: Float>(d: &mut [T], a: &[T], f: impl Fn(T) -> T) {
    for (o, &x) in d.iter_mut().zip(a) {
        *o = f(x);
    }
}

#[inline(always)]
fn map3<T: Float>(d: &mut [T], a: &[T], b: &[T], c: &[T], mut f: impl FnMut(T, T, T) -> T) {
    for (((o, &x), &y), &z) in d.iter_mut().zip(a).zip(b).zip(c) {
        *o = f(x, y, z);
    }
}

#[inline(always)]
fn map2<T: Float>(d: &mut [T], a: &[T], b: &[T], f: impl Fn(T, T) -> T) {
    for ((o, &x), &y) in d.iter_mut().zip(a).zip(b) {
        *o = f(x, y);
    }
}

/// One loop per operation, each specialised by `scalar::unary` with a constant operation.
#[inline(always)]
fn unary_loop<T: Float>(u: Unary, d: &mut [T], a: &[T]) {
    macro_rules! arms {
        ($($v:ident),*) => {
            match u {
                $(Unary::$v => map1(d, a, |x| scalar::unary(Unary::$v, x)),)*
            }
        };
    }
    arms!(Neg, Abs, Sqrt, Sin, Cos, Acos, Exp, Log, Floor, Round)
}

/// One loop per operation, each specialised by `scalar::binary` with a constant operation.
#[inline(always)]
fn binary_loop<T: Float>(b: Binary, d: &mut [T], x: &[T], y: &[T]) {
    macro_rules! arms {
        ($($v:ident),*) => {
            match b {
                $(Binary::$v => map2(d, x, y, |p, q| scalar::binary(Binary::$v, p, q)),)*
            }
        };
    }
    arms!(Add, Sub, Mul, Div, Min, Max, Pow, Atan2, Lt)
}

/// `op(x, k)` for an immediate `k`.
#[inline(always)]
fn binary_k_loop<T: Float>(b: Binary, d: &mut [T], x: &[T], k: T) {
    macro_rules! arms {
        ($($v:ident),*) => {
            match b {
                $(Binary::$v => map1(d, x, |p| scalar::binary(Binary::$v, p, k)),)*
            }
        };
    }
    arms!(Add, Sub, Mul, Div, Min, Max, Pow, Atan2, Lt)
}

/// `op(k, y)` for an immediate `k`.
#[inline(always)]
fn k_binary_loop<T: Float>(b: Binary, d: &mut [T], k: T, y: &[T]) {
    macro_rules! arms {
        ($($v:ident),*) => {
            match b {
                $(Binary::$v => map1(d, y, |q| scalar::binary(Binary::$v, k, q)),)*
            }
        };
    }
    arms!(Add, Sub, Mul, Div, Min, Max, Pow, Atan2, Lt)
}

/// A fused step: `finish(Σ term(xᵢ, kᵢ))` over `terms` operands, summed left to right, the
/// operations those of the instructions it replaces (one loop per combination).
#[inline(always)]
fn fused_loop<T: Float>(
    kind: Kind,
    terms: u8,
    finish: Finish,
    d: &mut [T],
    x: [&[T]; 3],
    ks: [T; 3],
    k: T,
) {
    macro_rules! sum {
        ($term:expr, $fin:expr) => {{
            let (term, fin) = ($term, $fin);
            match terms {
                1 => map1(d, x[0], |a| fin(term(a, ks[0]))),
                2 => map2(d, x[0], x[1], |a, b| fin(term(a, ks[0]) + term(b, ks[1]))),
                _ => map3(d, x[0], x[1], x[2], |a, b, c| {
                    fin(term(a, ks[0]) + term(b, ks[1]) + term(c, ks[2]))
                }),
            }
        }};
    }
    macro_rules! finishes {
        ($term:expr) => {
            match finish {
                Finish::None => sum!($term, |s: T| s),
                Finish::Add => sum!($term, |s: T| s + k),
                Finish::Sqrt => sum!($term, |s: T| s.sqrt()),
                Finish::SqrtAdd => sum!($term, |s: T| s.sqrt() + k),
            }
        };
    }
    let square = |t: T| t * t;
    match kind {
        Kind::SquareAdd => finishes!(|v: T, k: T| square(v + k)),
        Kind::SquareMax => finishes!(|v: T, k: T| square(v.max(k))),
        Kind::Scale => finishes!(|v: T, k: T| v * k),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::front::check_str;
    use crate::lower::lower;

    /// The registers block `b` of `c`'s program reads from before it, found the slow way:
    /// every live instruction inside it, every live block inside it, its results.
    fn outside_reads_by_scanning(c: &Compiler, b: usize) -> Vec<Reg> {
        let block = c.program.blocks()[b];
        let mut reads = Vec::new();
        for i in block.start..block.end {
            if c.live[i] {
                reads.extend(c.fusions.reads(c.program, i));
            }
        }
        for (nb, inner) in c.program.blocks().iter().enumerate() {
            let within = inner.start >= block.start && inner.end <= block.end && nb != b;
            if within && c.live_blocks[nb] {
                reads.extend([inner.bound, inner.best]);
            }
        }
        for i in block.end..block.end + block.results {
            if let (true, Op::Phi(then, _)) = (c.live[i], c.ops()[i]) {
                reads.push(then);
            }
        }
        reads.retain(|&r| (r.0 as usize) < block.start && !c.is_const(r));
        reads.sort();
        reads.dedup();
        reads
    }

    /// A scene of `n` objects in a loop, some under smooth blends and transforms, so that
    /// its program holds blocks nested several deep.
    fn many(n: usize) -> Program {
        let text = format!(
            "material a = phong {{ color: (1, 0, 0) }};
             material b = phong {{ color: (0, 0, 1) }};
             scene {{
               plane((0, 1, 0), -2) @ a;
               for i in 0..{n} {{
                 let s = smooth_union(0.1, sphere(0.2), box((0.1, 0.3, 0.1)).rotate_y(30deg * i));
                 if hash(i) < 0.5 {{ s.translate(hash(3 * i) * 20, hash(3 * i + 1), hash(3 * i + 2) * 20) @ a }}
                 else {{ torus(0.3, 0.1).translate(hash(3 * i) * 20, 1, hash(3 * i + 2) * 20) @ b }};
               }}
             }}"
        );
        let (scene, diagnostics, _) = check_str("many.sdf", &text);
        assert!(diagnostics.iter().all(|d| !d.is_error()), "{diagnostics:?}");
        lower(&scene.expect("a scene"))
    }

    #[test]
    fn gathered_reads_equal_the_scan_of_every_block() {
        for n in [1, 7, 64, 300] {
            let program = many(n);
            assert!(program.blocks().len() >= n / 4, "{n}: few blocks");
            for outputs in [Outputs::Distance, Outputs::DistanceAndMaterial] {
                let mut roots = vec![program.distance()];
                if outputs == Outputs::DistanceAndMaterial {
                    roots.push(program.material());
                }
                let c = Compiler::new(&program, &roots);
                let depth = program.blocks().iter().enumerate().any(|(b, block)| {
                    program.blocks()[b + 1..]
                        .iter()
                        .any(|inner| inner.start >= block.start && inner.end <= block.end)
                });
                assert!(n < 64 || depth, "{n}: no nested blocks");
                // What the walk gathers stays within a few registers a block: the sets that
                // blocks hand outwards do not grow with the number of blocks around them.
                let gathered: usize = c.outside.iter().map(Vec::len).sum();
                let blocks = program.blocks().len();
                assert!(
                    gathered <= 8 * blocks,
                    "{n}: {gathered} for {blocks} blocks"
                );
                for b in 0..program.blocks().len() {
                    assert_eq!(
                        c.outside_reads(b),
                        outside_reads_by_scanning(&c, b),
                        "{n} objects, block {b}"
                    );
                }
            }
        }
    }
}
