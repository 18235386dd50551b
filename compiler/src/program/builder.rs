//! The program builder: emits instructions with constant folding, algebraic identities and
//! sharing of equal instructions (when optimising), opens and closes guarded blocks, and
//! offers the small vector helpers the lowering rules are written with.

use super::mesh::TriMesh;
use super::outline::Outline;
use super::{scalar, Axis, Binary, Block, Note, Op, Program, Reg, Unary};
use std::collections::HashMap;
use std::sync::Arc;

/// A point or vector: three registers.
pub(crate) type P = [Reg; 3];

/// The constants of an exact primitive (`shapes::slots`): up to eight, unused ones 0.
pub type Slots = [f64; 8];

/// A constant that is a primitive's constant `slot` times `scale` ([`Builder::param`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Param {
    /// The constant's register.
    pub reg: Reg,
    pub slot: usize,
    /// An exact factor: ±1 or ±2.
    pub scale: f64,
}

/// The identity of an instruction for sharing (constants compared by bits).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Key {
    Const(u64),
    Input(Axis),
    Unary(Unary, Reg),
    Binary(Binary, Reg, Reg),
    Select(Reg, Reg, Reg),
    Mesh(u32, Reg, Reg, Reg),
    Outline(u32, Reg, Reg),
}

/// The scope of registers defined outside every block.
const TOP: u32 = u32::MAX;

/// Builds one program.
#[derive(Debug, Default)]
pub(crate) struct Builder {
    /// Fold, share and drop dead instructions (optimisation level ≥ 1).
    optimise: bool,
    ops: Vec<Op>,
    /// Per register: known to be ≥ 0 (a constant ≥ 0, or a select between such registers).
    nonneg: Vec<bool>,
    /// Per register: the innermost block it was defined in, or [`TOP`].
    scope: Vec<u32>,
    notes: Vec<Note>,
    /// Per note: whether it only resumes a node after its children (dropped when no
    /// instruction follows it).
    resumes: Vec<bool>,
    shared: HashMap<Key, Reg>,
    blocks: Vec<Block>,
    /// The blocks open now, innermost last.
    open: Vec<u32>,
    /// The most instructions to emit (the `program` limit): past it, [`Builder::over`]
    /// turns true and the lowering stops descending.
    cap: usize,
    /// No folding that depends on a constant's value ([`super::LowerOptions::parametric`]):
    /// constants are not shared, identities and sign rewrites are kept as written, a
    /// `Select` keeps both sides. Constant operations still fold (into a constant, whatever
    /// the values).
    pub parametric: bool,
    /// When recording, the constants [`Builder::param`] made, in order.
    pub params: Option<Vec<Param>>,
    /// The meshes `Op::Mesh` names, by id ([`Program::meshes`]).
    meshes: Vec<Option<Arc<TriMesh>>>,
    /// The outlines [`Op::Outline`] reads, by index.
    outlines: Vec<Arc<Outline>>,
}

impl Builder {
    /// An empty builder; `optimise` turns on folding, sharing and dead-code removal.
    pub fn new(optimise: bool) -> Self {
        Builder {
            optimise,
            cap: usize::MAX,
            ..Self::default()
        }
    }

    /// An empty builder that stops at `cap` instructions ([`Builder::over`]).
    pub fn capped(optimise: bool, cap: usize) -> Self {
        Builder {
            cap,
            ..Self::new(optimise)
        }
    }

    /// Whether more instructions than the cap were emitted: the program is incomplete.
    pub fn over(&self) -> bool {
        self.ops.len() > self.cap
    }

    /// Starts a commented block at the next instruction.
    pub fn note(&mut self, text: String) {
        self.notes.push(Note {
            at: self.ops.len(),
            text,
        });
        self.resumes.push(false);
    }

    /// Notes that the next instructions belong to a node again, after its children.
    pub fn note_resume(&mut self, text: String) {
        self.note(text);
        if let Some(last) = self.resumes.last_mut() {
            *last = true;
        }
    }

    /// The input point.
    pub fn input_point(&mut self) -> P {
        [
            self.emit(Op::Input(Axis::X)),
            self.emit(Op::Input(Axis::Y)),
            self.emit(Op::Input(Axis::Z)),
        ]
    }

    /// The unit surface normal at the input point (a colour field's program reads it).
    pub fn input_normal(&mut self) -> P {
        [
            self.emit(Op::Input(Axis::Nx)),
            self.emit(Op::Input(Axis::Ny)),
            self.emit(Op::Input(Axis::Nz)),
        ]
    }

    /// The constant `x`.
    pub fn c(&mut self, x: f64) -> Reg {
        self.emit(Op::Const(x))
    }

    /// The constant `scale · s[slot]`, a primitive's constant `slot` times an exact factor
    /// (±1, ±2, so that a shader computing it from the slot gets the same f32); recorded in
    /// [`Builder::params`] when that is on.
    pub fn param(&mut self, s: &Slots, slot: usize, scale: f64) -> Reg {
        let reg = self.c(scale * s[slot]);
        if let Some(params) = &mut self.params {
            params.push(Param { reg, slot, scale });
        }
        reg
    }

    /// The value of a register when it is a constant.
    pub fn value(&self, r: Reg) -> Option<f64> {
        match self.ops[r.0 as usize] {
            Op::Const(c) => Some(c),
            _ => None,
        }
    }

    fn is(&self, r: Reg, x: f64) -> bool {
        self.value(r) == Some(x)
    }

    /// Whether register `r` may be read here: defined outside every block, or inside one
    /// that is still open.
    pub fn visible(&self, r: Reg) -> bool {
        let s = self.scope[r.0 as usize];
        s == TOP || self.open.contains(&s)
    }

    /// Emits an instruction, or (when optimising) returns an equal or simpler one emitted
    /// before and visible here.
    pub fn emit(&mut self, op: Op) -> Reg {
        if !self.optimise {
            return self.push(op);
        }
        if let Some(r) = self.fold(op) {
            return r;
        }
        let key = match op {
            Op::Const(_) if self.parametric => return self.push(op),
            Op::Const(c) => Key::Const(c.to_bits()),
            Op::Input(a) => Key::Input(a),
            Op::Unary(u, a) => Key::Unary(u, a),
            Op::Binary(b, x, y) if commutes(b) && y < x => Key::Binary(b, y, x),
            Op::Binary(b, x, y) => Key::Binary(b, x, y),
            Op::Select(c, a, b) => Key::Select(c, a, b),
            Op::Mesh(m, x, y, z) => Key::Mesh(m, x, y, z),
            Op::Outline(k, x, y) => Key::Outline(k, x, y),
            Op::Phi(..) => return self.push(op),
        };
        if let Some(&r) = self.shared.get(&key) {
            if self.visible(r) {
                return r;
            }
        }
        let r = self.push(op);
        self.shared.insert(key, r);
        r
    }

    /// Appends an instruction in the current scope.
    fn push(&mut self, op: Op) -> Reg {
        let r = Reg(self.ops.len() as u32);
        let nonneg = match op {
            Op::Const(c) => c >= 0.0,
            Op::Select(_, a, b) | Op::Phi(a, b) => {
                self.nonneg[a.0 as usize] && self.nonneg[b.0 as usize]
            }
            _ => false,
        };
        self.ops.push(op);
        self.nonneg.push(nonneg);
        self.scope.push(self.open.last().copied().unwrap_or(TOP));
        r
    }

    /// Opens a guarded block that runs where `!(bound >= best)`.
    pub fn open_block(&mut self, bound: Reg, best: Reg) -> u32 {
        let id = self.blocks.len() as u32;
        self.blocks.push(Block {
            bound,
            best,
            start: self.ops.len(),
            end: self.ops.len(),
            results: 0,
        });
        self.open.push(id);
        id
    }

    /// Closes the innermost block, which must be `id`, and returns its results: for each
    /// pair, the first register where the block ran, else the second.
    pub fn close_block(&mut self, id: u32, results: &[(Reg, Reg)]) -> Vec<Reg> {
        debug_assert_eq!(self.open.last(), Some(&id));
        self.open.pop();
        self.blocks[id as usize].end = self.ops.len();
        self.blocks[id as usize].results = results.len();
        results
            .iter()
            .map(|&(inner, other)| self.push(Op::Phi(inner, other)))
            .collect()
    }

    /// Constant folding and algebraic identities; `None` when the instruction stays.
    fn fold(&mut self, op: Op) -> Option<Reg> {
        match op {
            Op::Const(_) | Op::Input(_) | Op::Phi(..) | Op::Mesh(..) | Op::Outline(..) => None,
            Op::Unary(u, a) => self.fold_unary(u, a),
            Op::Binary(b, x, y) => self.fold_binary(b, x, y),
            Op::Select(c, a, b) => match self.value(c) {
                Some(_) if self.parametric => None,
                Some(v) => Some(if v != 0.0 { a } else { b }),
                None if a == b => Some(a),
                None => None,
            },
        }
    }

    fn fold_unary(&mut self, u: Unary, a: Reg) -> Option<Reg> {
        if let Some(v) = self.value(a) {
            return Some(self.c(scalar::unary(u, v)));
        }
        match (u, self.ops[a.0 as usize]) {
            (Unary::Neg, Op::Unary(Unary::Neg, inner)) => Some(inner),
            (Unary::Neg, Op::Binary(Binary::Sub, x, y)) => Some(self.sub(y, x)),
            (Unary::Abs, Op::Unary(Unary::Abs | Unary::Neg, inner)) => Some(self.abs(inner)),
            _ => None,
        }
    }

    fn fold_binary(&mut self, b: Binary, x: Reg, y: Reg) -> Option<Reg> {
        if let (Some(u), Some(v)) = (self.value(x), self.value(y)) {
            return Some(self.c(scalar::binary(b, u, v)));
        }
        if let Some(r) = self.fold_chain(b, x, y) {
            return Some(r);
        }
        if self.parametric {
            return match b {
                Binary::Min | Binary::Max if x == y => Some(x),
                Binary::Lt if x == y => Some(self.c(0.0)),
                _ => None,
            };
        }
        match b {
            Binary::Add if self.is(y, 0.0) => Some(x),
            Binary::Add if self.is(x, 0.0) => Some(y),
            Binary::Sub if self.is(y, 0.0) => Some(x),
            Binary::Sub if self.is(x, 0.0) => Some(self.neg(y)),
            Binary::Sub if self.value(y).is_some_and(|v| v < 0.0) => {
                let k = self.c(-self.value(y).unwrap_or(0.0));
                Some(self.add(x, k))
            }
            Binary::Mul if self.is(y, 1.0) => Some(x),
            Binary::Mul if self.is(x, 1.0) => Some(y),
            Binary::Mul if self.is(x, 0.0) || self.is(y, 0.0) => Some(self.c(0.0)),
            Binary::Mul if self.is(y, -1.0) => Some(self.neg(x)),
            Binary::Mul if self.is(x, -1.0) => Some(self.neg(y)),
            Binary::Div if self.is(y, 1.0) => Some(x),
            Binary::Pow if self.is(y, 1.0) => Some(x),
            Binary::Pow if self.is(y, 2.0) => Some(self.mul(x, x)),
            Binary::Min | Binary::Max if x == y => Some(x),
            Binary::Lt if x == y => Some(self.c(0.0)),
            Binary::Lt if self.is(y, 0.0) && self.nonneg[x.0 as usize] => Some(self.c(0.0)),
            _ => None,
        }
    }

    /// Chains of constant offsets and factors: (a ± k1) ± k2 becomes a ± (k1 ± k2), and
    /// (a·k1)·k2 becomes a·(k1·k2) (one rounding instead of two).
    fn fold_chain(&mut self, b: Binary, x: Reg, y: Reg) -> Option<Reg> {
        let k2 = self.value(y)?;
        let (inner, k1) = match self.ops[x.0 as usize] {
            Op::Binary(ib, a, k) => (ib, (a, self.value(k)?)),
            _ => return None,
        };
        let (a, k1) = k1;
        match (b, inner) {
            (Binary::Add | Binary::Sub, Binary::Add | Binary::Sub) => {
                let sign = |op: Binary| if op == Binary::Add { 1.0 } else { -1.0 };
                let k = sign(inner) * k1 + sign(b) * k2;
                Some(self.addc(a, k))
            }
            (Binary::Mul, Binary::Mul) => Some(self.mulc(a, k1 * k2)),
            _ => None,
        }
    }

    /// Ends the program: drops instructions the outputs do not need (when optimising) and
    /// renumbers the rest.
    pub fn finish(self, d: Reg, m: Reg) -> Program {
        self.finish_roots(&[d, m]).0
    }

    /// [`Builder::finish`] keeping every register of `roots` (at least one) and giving their
    /// new numbers; the program's distance is the first root, its material the second (or
    /// the first again).
    pub fn finish_roots(self, roots: &[Reg]) -> (Program, Vec<Reg>) {
        let (d, m) = (roots[0], *roots.get(1).unwrap_or(&roots[0]));
        let raw = Program {
            ops: self.ops,
            notes: Vec::new(),
            blocks: self.blocks,
            distance: d,
            material: m,
            lipschitz: 1.0,
            meshes: Vec::new(),
            outlines: Vec::new(),
        };
        let (live, live_blocks) = if self.optimise {
            raw.live(roots)
        } else {
            (vec![true; raw.ops.len()], vec![true; raw.blocks.len()])
        };
        let n = raw.ops.len();
        let mut new_index = vec![Reg(0); n];
        let mut ops = Vec::new();
        let mut first_at_or_after = vec![0usize; n + 1];
        for (i, op) in raw.ops.iter().enumerate() {
            first_at_or_after[i] = ops.len();
            if live[i] {
                new_index[i] = Reg(ops.len() as u32);
                ops.push(renumber(op, &new_index));
            }
        }
        first_at_or_after[n] = ops.len();
        let blocks = raw
            .blocks
            .iter()
            .zip(&live_blocks)
            .filter(|(_, &l)| l)
            .map(|(b, _)| Block {
                bound: new_index[b.bound.0 as usize],
                best: new_index[b.best.0 as usize],
                start: first_at_or_after[b.start],
                end: first_at_or_after[b.end],
                results: (b.end..b.end + b.results).filter(|&i| live[i]).count(),
            })
            .collect();
        let moved: Vec<Note> = self
            .notes
            .into_iter()
            .map(|n| Note {
                at: first_at_or_after[n.at],
                text: n.text,
            })
            .collect();
        let notes = useful_notes(moved, &self.resumes, ops.len());
        // The outlines the kept instructions read, renumbered in order of first use.
        let mut outlines: Vec<Arc<Outline>> = Vec::new();
        let mut index: HashMap<u32, u32> = HashMap::new();
        for op in &mut ops {
            if let Op::Outline(k, _, _) = op {
                let next = outlines.len() as u32;
                let new = *index.entry(*k).or_insert_with(|| {
                    outlines.push(self.outlines[*k as usize].clone());
                    next
                });
                *k = new;
            }
        }
        let program = Program {
            ops,
            notes,
            blocks,
            distance: new_index[d.0 as usize],
            material: new_index[m.0 as usize],
            lipschitz: 1.0,
            meshes: self.meshes,
            outlines,
        };
        (
            program,
            roots.iter().map(|r| new_index[r.0 as usize]).collect(),
        )
    }
}

/// Drops the resuming notes that no instruction follows before the next note or the end.
fn useful_notes(notes: Vec<Note>, resumes: &[bool], end: usize) -> Vec<Note> {
    let next_at: Vec<usize> = (0..notes.len())
        .map(|i| notes.get(i + 1).map_or(end, |n| n.at))
        .collect();
    notes
        .into_iter()
        .enumerate()
        .filter(|(i, n)| !resumes[*i] || n.at < next_at[*i])
        .map(|(_, n)| n)
        .collect()
}

/// Whether `b(x, y)` and `b(y, x)` are the same value for every operand: not `min` and `max`,
/// whose NaN rule makes the order matter.
fn commutes(b: Binary) -> bool {
    matches!(b, Binary::Add | Binary::Mul)
}

fn renumber(op: &Op, new_index: &[Reg]) -> Op {
    let n = |r: Reg| new_index[r.0 as usize];
    match *op {
        Op::Const(_) | Op::Input(_) => *op,
        Op::Unary(u, a) => Op::Unary(u, n(a)),
        Op::Binary(b, x, y) => Op::Binary(b, n(x), n(y)),
        Op::Select(c, a, b) => Op::Select(n(c), n(a), n(b)),
        Op::Phi(a, b) => Op::Phi(n(a), n(b)),
        Op::Mesh(m, x, y, z) => Op::Mesh(m, n(x), n(y), n(z)),
        Op::Outline(k, x, y) => Op::Outline(k, n(x), n(y)),
    }
}

/// Methods `name(x, y)`: the operation `Binary::$op` of two registers.
macro_rules! binary {
    ($($name:ident => $op:ident,)*) => {
        $(
            pub fn $name(&mut self, x: Reg, y: Reg) -> Reg {
                self.bin(Binary::$op, x, y)
            }
        )*
    };
}

/// Methods `name(x, k)`: the operation `op` of `x` and the constant `k`.
macro_rules! with_constant {
    ($($(#[$doc:meta])* $name:ident => $op:ident;)*) => {
        $(
            $(#[$doc])*
            pub fn $name(&mut self, x: Reg, k: f64) -> Reg {
                let k = self.c(k);
                self.$op(x, k)
            }
        )*
    };
}

/// Scalar helpers, one per instruction.
impl Builder {
    /// The signed distance to a triangle mesh at `p`.
    pub fn mesh(&mut self, mesh: &Arc<TriMesh>, p: P) -> Reg {
        let id = mesh.id as usize;
        if self.meshes.len() <= id {
            self.meshes.resize(id + 1, None);
        }
        self.meshes[id] = Some(Arc::clone(mesh));
        self.emit(Op::Mesh(mesh.id, p[0], p[1], p[2]))
    }

    pub fn un(&mut self, u: Unary, a: Reg) -> Reg {
        self.emit(Op::Unary(u, a))
    }
    pub fn bin(&mut self, b: Binary, x: Reg, y: Reg) -> Reg {
        self.emit(Op::Binary(b, x, y))
    }
    binary! {
        add => Add,
        sub => Sub,
        mul => Mul,
        div => Div,
        min => Min,
        max => Max,
        lt => Lt,
    }
    /// The signed distance at (x, y) to `outline` ([`Op::Outline`]), the outline shared by
    /// every instruction that reads it.
    pub fn outline(&mut self, outline: &Arc<Outline>, x: Reg, y: Reg) -> Reg {
        let k = match self.outlines.iter().position(|o| Arc::ptr_eq(o, outline)) {
            Some(k) => k,
            None => {
                self.outlines.push(outline.clone());
                self.outlines.len() - 1
            }
        };
        self.emit(Op::Outline(k as u32, x, y))
    }
    pub fn select(&mut self, c: Reg, a: Reg, b: Reg) -> Reg {
        self.emit(Op::Select(c, a, b))
    }
    pub fn neg(&mut self, a: Reg) -> Reg {
        self.un(Unary::Neg, a)
    }
    pub fn abs(&mut self, a: Reg) -> Reg {
        self.un(Unary::Abs, a)
    }
    pub fn sqrt(&mut self, a: Reg) -> Reg {
        self.un(Unary::Sqrt, a)
    }
    with_constant! {
        /// x + k for a constant k.
        addc => add;
        /// x - k for a constant k.
        subc => sub;
        /// x * k for a constant k.
        mulc => mul;
        /// max(x, k) for a constant k.
        maxc => max;
        /// min(x, k) for a constant k.
        minc => min;
    }
    /// x limited to the constant range [lo, hi].
    pub fn clampc(&mut self, x: Reg, lo: f64, hi: f64) -> Reg {
        let m = self.maxc(x, lo);
        self.minc(m, hi)
    }
    /// √(a² + b²).
    pub fn len2(&mut self, a: Reg, b: Reg) -> Reg {
        let d = self.dot2(a, b, a, b);
        self.sqrt(d)
    }
    /// a·c + b·d.
    pub fn dot2(&mut self, a: Reg, b: Reg, c: Reg, d: Reg) -> Reg {
        let x = self.mul(a, c);
        let y = self.mul(b, d);
        self.add(x, y)
    }
    /// The material `m`, or the constant `id` where `m` is unpainted (negative).
    pub fn paint(&mut self, m: Reg, id: f64) -> Reg {
        let zero = self.c(0.0);
        let unpainted = self.lt(m, zero);
        let id = self.c(id);
        self.select(unpainted, id, m)
    }
}

/// Vector helpers over [`P`].
impl Builder {
    /// Componentwise `f`.
    pub fn map3(&mut self, p: P, mut f: impl FnMut(&mut Self, Reg, usize) -> Reg) -> P {
        [f(self, p[0], 0), f(self, p[1], 1), f(self, p[2], 2)]
    }
    /// The constant vector `v`.
    pub fn c3(&mut self, v: [f64; 3]) -> P {
        [self.c(v[0]), self.c(v[1]), self.c(v[2])]
    }
    /// p - v for a constant v.
    pub fn sub3c(&mut self, p: P, v: [f64; 3]) -> P {
        self.map3(p, |b, x, i| b.subc(x, v[i]))
    }
    /// |p| componentwise.
    pub fn abs3(&mut self, p: P) -> P {
        self.map3(p, |b, x, _| b.abs(x))
    }
    /// max(p, k) componentwise.
    pub fn max3c(&mut self, p: P, k: f64) -> P {
        self.map3(p, |b, x, _| b.maxc(x, k))
    }
    /// a · b.
    pub fn dot3(&mut self, a: P, c: P) -> Reg {
        let xy = self.dot2(a[0], a[1], c[0], c[1]);
        let z = self.mul(a[2], c[2]);
        self.add(xy, z)
    }
    /// |p|.
    pub fn len3(&mut self, p: P) -> Reg {
        let d = self.dot3(p, p);
        self.sqrt(d)
    }
    /// The largest component.
    pub fn max_comp(&mut self, p: P) -> Reg {
        let yz = self.max(p[1], p[2]);
        self.max(p[0], yz)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_exactly_commuting_operations_are_shared_in_either_order() {
        let mut b = Builder::new(true);
        let [x, y, _] = b.input_point();
        // IEEE addition and multiplication commute, NaN included (up to which NaN).
        assert_eq!(b.add(x, y), b.add(y, x));
        assert_eq!(b.mul(x, y), b.mul(y, x));
        // min and max do not: with a NaN operand the second one wins (program::float).
        assert_ne!(b.min(x, y), b.min(y, x));
        assert_ne!(b.max(x, y), b.max(y, x));
        assert_eq!(b.max(x, y), b.max(x, y));
    }
}
