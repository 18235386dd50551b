//! Tapes: distance programs prepared for batch evaluation (dead instructions dropped,
//! constant operands of two-operand instructions made immediate, registers packed into
//! reusable slots), and the loop that runs each instruction.

use super::{scalar, Float};
use crate::lower::{Axis, Binary, Op, Program, Reg, Unary};

/// Which results a tape computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outputs {
    /// The distance only (sphere tracing, shadows, normals).
    Distance,
    /// The distance and the material id (shading).
    DistanceAndMaterial,
}

/// The operation of one step.
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
}

/// One instruction over slots: `dst = code(a, b, c)` with the immediate `k`. `dst` never
/// equals an operand.
#[derive(Debug, Clone, Copy)]
pub(super) struct Step {
    code: Code,
    pub(super) dst: u32,
    a: u32,
    b: u32,
    c: u32,
    k: f64,
}

/// A program prepared for an [`super::Evaluator`].
#[derive(Debug, Clone)]
pub struct Tape {
    steps: Vec<Step>,
    constants: Vec<(u32, f64)>,
    inputs: [Option<u32>; 3],
    slots: usize,
    distance: u32,
    material: Option<u32>,
}

/// Where each register lives, decided once per tape.
#[derive(Debug, Default)]
struct Allocator {
    slot_of: Vec<Option<u32>>,
    free: Vec<u32>,
    count: u32,
}

impl Allocator {
    fn fresh(&mut self) -> u32 {
        self.free.pop().unwrap_or_else(|| {
            self.count += 1;
            self.count - 1
        })
    }
}

impl Tape {
    /// Prepares `program` for evaluation of `outputs`.
    pub fn new(program: &Program, outputs: Outputs) -> Tape {
        let ops = program.ops();
        let mut roots = vec![program.distance()];
        if outputs == Outputs::DistanceAndMaterial {
            roots.push(program.material());
        }
        let last_use = last_uses(ops, &roots);
        let in_slot = needs_slot(ops, &roots, &last_use);
        let mut alloc = Allocator {
            slot_of: vec![None; ops.len()],
            ..Default::default()
        };
        let mut tape = Tape {
            steps: Vec::new(),
            constants: Vec::new(),
            inputs: [None; 3],
            slots: 0,
            distance: 0,
            material: None,
        };
        // Constants read from memory and inputs keep their slots for the evaluator's life.
        for (i, op) in ops.iter().enumerate() {
            match *op {
                Op::Const(c) if in_slot[i] => {
                    let s = alloc.fresh();
                    alloc.slot_of[i] = Some(s);
                    tape.constants.push((s, c));
                }
                Op::Input(a) if last_use[i].is_some() => {
                    let s = alloc.fresh();
                    alloc.slot_of[i] = Some(s);
                    tape.inputs[axis_index(a)] = Some(s);
                }
                _ => {}
            }
        }
        for (i, op) in ops.iter().enumerate() {
            if last_use[i].is_some() && !matches!(op, Op::Const(_) | Op::Input(_)) {
                tape.steps.push(step(i, op, &mut alloc, &last_use, ops));
            }
        }
        let slot = |r: Reg| {
            alloc
                .slot_of
                .get(r.0 as usize)
                .copied()
                .flatten()
                .unwrap_or(0)
        };
        tape.distance = slot(program.distance());
        if outputs == Outputs::DistanceAndMaterial {
            tape.material = Some(slot(program.material()));
        }
        tape.slots = alloc.count.max(1) as usize;
        tape
    }

    /// Number of instructions run per point.
    pub fn len(&self) -> usize {
        self.steps.len()
    }

    /// True when the tape runs no instruction (the result is a constant or an input).
    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }

    /// Number of scratch slots (of one chunk each) an evaluator needs.
    pub fn slot_count(&self) -> usize {
        self.slots
    }

    pub(super) fn steps(&self) -> &[Step] {
        &self.steps
    }

    pub(super) fn constants(&self) -> &[(u32, f64)] {
        &self.constants
    }

    pub(super) fn input_slot(&self, a: Axis) -> Option<u32> {
        self.inputs[axis_index(a)]
    }

    pub(super) fn distance_slot(&self) -> u32 {
        self.distance
    }

    pub(super) fn material_slot(&self) -> Option<u32> {
        self.material
    }
}

fn axis_index(a: Axis) -> usize {
    match a {
        Axis::X => 0,
        Axis::Y => 1,
        Axis::Z => 2,
    }
}

/// For each register, the index of the last instruction reading it (`usize::MAX` for
/// outputs), or `None` when no output needs it.
fn last_uses(ops: &[Op], roots: &[Reg]) -> Vec<Option<usize>> {
    let mut last = vec![None; ops.len()];
    for r in roots {
        last[r.0 as usize] = Some(usize::MAX);
    }
    for i in (0..ops.len()).rev() {
        if last[i].is_none() {
            continue;
        }
        for r in ops[i].operands() {
            let l = &mut last[r.0 as usize];
            *l = Some(l.map_or(i, |v: usize| v.max(i)));
        }
    }
    last
}

/// Which constants must live in a slot: outputs and operands of one-operand instructions
/// and selects (two-operand instructions take them as immediates).
fn needs_slot(ops: &[Op], roots: &[Reg], last_use: &[Option<usize>]) -> Vec<bool> {
    let mut need = vec![false; ops.len()];
    for r in roots {
        need[r.0 as usize] = true;
    }
    for (i, op) in ops.iter().enumerate() {
        if last_use[i].is_none() {
            continue;
        }
        match *op {
            Op::Unary(_, a) => need[a.0 as usize] = true,
            Op::Select(c, a, b) => [c, a, b].iter().for_each(|r| need[r.0 as usize] = true),
            _ => {}
        }
    }
    need
}

/// Allocates the destination of instruction `i`, then frees operands read for the last time
/// (after, so that the destination is never an operand).
fn step(i: usize, op: &Op, alloc: &mut Allocator, last_use: &[Option<usize>], ops: &[Op]) -> Step {
    let constant = |r: Reg| match ops[r.0 as usize] {
        Op::Const(c) => Some(c),
        _ => None,
    };
    let slot = |alloc: &Allocator, r: Reg| alloc.slot_of[r.0 as usize].unwrap_or(0);
    let (code, operands, k) = match *op {
        Op::Unary(u, a) => (Code::Unary(u), vec![a], 0.0),
        Op::Binary(b, x, y) => match (constant(x), constant(y)) {
            (_, Some(k)) => (Code::BinaryK(b), vec![x], k),
            (Some(k), None) => (Code::KBinary(b), vec![y], k),
            (None, None) => (Code::Binary(b), vec![x, y], 0.0),
        },
        Op::Select(c, a, b) => (Code::Select, vec![c, a, b], 0.0),
        Op::Const(_) | Op::Input(_) => (Code::Select, Vec::new(), 0.0),
    };
    let s: Vec<u32> = operands.iter().map(|&r| slot(alloc, r)).collect();
    let at = |n: usize| s.get(n).copied().unwrap_or(0);
    let dst = alloc.fresh();
    alloc.slot_of[i] = Some(dst);
    let mut freed: Vec<u32> = Vec::new();
    for (r, &slot) in operands.iter().zip(&s) {
        let permanent = matches!(ops[r.0 as usize], Op::Const(_) | Op::Input(_));
        if !permanent && last_use[r.0 as usize] == Some(i) && !freed.contains(&slot) {
            freed.push(slot);
        }
    }
    alloc.free.extend(freed);
    Step {
        code,
        dst,
        a: at(0),
        b: at(1),
        c: at(2),
        k,
    }
}

impl Step {
    /// Runs this step on the first `n` points of `slots` (slots of `chunk` values, back to
    /// back). The destination is split off the buffer; operands are read from both sides.
    #[inline]
    pub(super) fn apply<T: Float>(&self, slots: &mut [T], chunk: usize, n: usize) {
        let dst = self.dst as usize;
        let (lo, rest) = slots.split_at_mut(dst * chunk);
        let (d, hi) = rest.split_at_mut(chunk);
        let read = |s: u32| -> &[T] {
            let s = s as usize;
            if s < dst {
                &lo[s * chunk..][..n]
            } else {
                &hi[(s - dst - 1) * chunk..][..n]
            }
        };
        let d = &mut d[..n];
        let k = T::from_f64(self.k);
        match self.code {
            Code::Unary(u) => unary_loop(u, d, read(self.a)),
            Code::Binary(b) => binary_loop(b, d, read(self.a), read(self.b)),
            Code::BinaryK(b) => binary_k_loop(b, d, read(self.a), k),
            Code::KBinary(b) => k_binary_loop(b, d, k, read(self.a)),
            Code::Select => {
                let (c, x, y) = (read(self.a), read(self.b), read(self.c));
                for (((o, &c), &p), &q) in d.iter_mut().zip(c).zip(x).zip(y) {
                    *o = scalar::select(c, p, q);
                }
            }
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
fn map2<T: Float>(d: &mut [T], a: &[T], b: &[T], f: impl Fn(T, T) -> T) {
    for ((o, &x), &y) in d.iter_mut().zip(a).zip(b) {
        *o = f(x, y);
    }
}

/// One loop per operation, each specialised by `scalar::unary` with a constant operation.
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
