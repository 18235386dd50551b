//! The distance program, the IR between the lowering and every back end: one flat scalar SSA
//! program that maps a point (x, y, z) to (distance, material id), with the meaning of each
//! operation (`scalar.rs`, over the evaluation types of `float.rs`; their f32 sine, cosine and arc tangent in `trig.rs`), the reference run of a
//! whole program at one point (`run.rs`), liveness (`live.rs`) and its text form (`text.rs`). The lowering builds programs; the interpreter, the placement
//! warnings and the Rust and WGSL writers read them.
//!
//! Every instruction defines one register, numbered by its position, over the evaluation's
//! float type (f32 or f64). Material ids are registers too (small integers held as floats); a
//! union picks the nearer child's material with `lt` and `select`. Loops (the Mandelbulb's
//! iterations) are unrolled, with the escape test done by `select` so that the state freezes
//! once a point has escaped.
//!
//! The only control flow is the guarded [`Block`]: a range of instructions that runs only
//! where a bounding volume is nearer than the best distance found so far, followed by `phi`
//! instructions that carry its results out (the block's value where it ran, the value from
//! before it elsewhere). Blocks nest; a register defined inside a block is read only inside it.

pub(crate) mod builder;
pub mod float;
mod live;
pub mod mesh;
pub mod outline;
mod run;
pub mod scalar;
mod text;
mod trig;
#[cfg(test)]
mod trig_tests;

pub use float::Float;
pub use live::results;
pub use run::Step;

/// Names a register: the value defined by the instruction at this index.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Reg(pub u32);

/// A coordinate of the input point, or of the unit surface normal there: a colour field's
/// program reads the normal (`n` in its body, docs/language.md "Colour fields"); a distance
/// program never does (the checker refuses `n` outside a colour field).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Axis {
    /// x
    X,
    /// y
    Y,
    /// z
    Z,
    /// The normal's x
    Nx,
    /// The normal's y
    Ny,
    /// The normal's z
    Nz,
}

impl Axis {
    /// The component of the point (0 to 2) or of the normal (3 to 5) it names.
    pub fn index(self) -> usize {
        self as usize
    }
}

/// One-operand operations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Unary {
    /// -a
    Neg,
    /// |a|
    Abs,
    /// √a
    Sqrt,
    /// sin a
    Sin,
    /// cos a
    Cos,
    /// acos a
    Acos,
    /// e^a
    Exp,
    /// ln a
    Log,
    /// ⌊a⌋
    Floor,
    /// ⌊a + 0.5⌋
    Round,
}

/// Two-operand operations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Binary {
    /// a + b
    Add,
    /// a - b
    Sub,
    /// a * b
    Mul,
    /// a / b
    Div,
    /// min(a, b)
    Min,
    /// max(a, b)
    Max,
    /// a^b
    Pow,
    /// atan2(a, b): the angle of the vector (b, a)
    Atan2,
    /// 1 when a < b, else 0
    Lt,
}

/// An instruction. Operands always name earlier registers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Op {
    /// A constant (stored as f64, rounded to the evaluation type).
    Const(f64),
    /// A coordinate of the input point.
    Input(Axis),
    /// A one-operand operation.
    Unary(Unary, Reg),
    /// A two-operand operation.
    Binary(Binary, Reg, Reg),
    /// `a` where `c != 0`, else `b`.
    Select(Reg, Reg, Reg),
    /// A result of the guarded block that ends just before this instruction (after the
    /// block's other `Phi`s): `a` (defined inside the block) where the block ran, else `b`
    /// (defined before it).
    Phi(Reg, Reg),
    /// The signed distance at the point (x, y, z) to the triangle mesh of this index in
    /// [`Program::meshes`] (`mesh.rs`).
    Mesh(u32, Reg, Reg, Reg),
    /// The signed distance at (x, y) = (a, b) to the outline at this index of
    /// [`Program::outlines`] (the glyphs of a text, read as data: [`outline::distance`]).
    Outline(u32, Reg, Reg),
}

impl Op {
    /// The registers this instruction reads.
    pub fn operands(&self) -> Vec<Reg> {
        match *self {
            Op::Const(_) | Op::Input(_) => Vec::new(),
            Op::Unary(_, a) => vec![a],
            Op::Binary(_, a, b) => vec![a, b],
            Op::Select(c, a, b) => vec![c, a, b],
            Op::Phi(a, b) | Op::Outline(_, a, b) => vec![a, b],
            Op::Mesh(_, x, y, z) => vec![x, y, z],
        }
    }
}

/// A comment attached to the instruction that follows it: which IR node the next block of
/// instructions comes from.
#[derive(Debug, Clone, PartialEq)]
pub struct Note {
    /// Index of the first instruction of the block.
    pub at: usize,
    /// The text, without comment marker.
    pub text: String,
}

/// A guarded block: the instructions `start..end` run only where `!(bound >= best)` (where
/// the bounding volume is nearer than the best distance so far, or either is NaN). The
/// `results` instructions from `end` on are [`Op::Phi`]s that carry the block's results out.
///
/// Blocks nest properly: a block inside another lies, with its `Phi`s, within the other's
/// range. `bound` and `best` are defined before `start`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Block {
    /// The distance to the bounding volume of what the block computes (a lower bound of it).
    pub bound: Reg,
    /// The best distance before the block.
    pub best: Reg,
    /// Index of the first instruction inside.
    pub start: usize,
    /// One past the last instruction inside: the index of the first `Phi`.
    pub end: usize,
    /// Number of `Phi` instructions after `end`.
    pub results: usize,
}

/// One step of a walk over a program's structure ([`Program::items`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Item {
    /// The instruction at this index.
    Op(usize),
    /// A guarded block opens (by index into [`Program::blocks`]).
    Open(usize),
    /// A guarded block closes (its `Phi`s follow).
    Close(usize),
}

/// A distance program: p ↦ (distance, material id).
#[derive(Debug, Clone, PartialEq)]
pub struct Program {
    pub(crate) ops: Vec<Op>,
    pub(crate) notes: Vec<Note>,
    pub(crate) blocks: Vec<Block>,
    pub(crate) distance: Reg,
    pub(crate) material: Reg,
    pub(crate) lipschitz: f64,
    /// The triangle meshes `Op::Mesh` names, by their index in the scene ([`mesh::TriMesh::id`],
    /// the same in every program of a scene); `None` for those this program does not use.
    pub(crate) meshes: Vec<Option<std::sync::Arc<mesh::TriMesh>>>,
    /// The outlines the [`Op::Outline`] instructions read, by index.
    pub(crate) outlines: Vec<std::sync::Arc<outline::Outline>>,
}

impl Program {
    /// The L a renderer steps with (`f / L` is a distance bound): 1 for a program with local
    /// bounds, else the scene's L ([`Analysis::step_lipschitz`]).
    ///
    /// [`Analysis::step_lipschitz`]: crate::scene::analysis::Analysis::step_lipschitz
    pub fn lipschitz(&self) -> f64 {
        self.lipschitz
    }

    /// The triangle meshes its `Op::Mesh` instructions name, by index.
    pub fn meshes(&self) -> impl Iterator<Item = &mesh::TriMesh> {
        self.meshes.iter().flatten().map(|m| &**m)
    }

    /// The mesh `Op::Mesh` names by `id`.
    pub fn mesh(&self, id: u32) -> &mesh::TriMesh {
        self.meshes[id as usize]
            .as_deref()
            .expect("the builder records every mesh a program names")
    }

    /// The instructions; register `i` is defined by `ops()[i]`.
    pub fn ops(&self) -> &[Op] {
        &self.ops
    }

    /// The comments naming the IR node of each block.
    pub fn notes(&self) -> &[Note] {
        &self.notes
    }

    /// The guarded blocks, by increasing `start` (an enclosing block before the ones inside).
    pub fn blocks(&self) -> &[Block] {
        &self.blocks
    }

    /// The outlines [`Op::Outline`] reads, by index.
    pub fn outlines(&self) -> &[std::sync::Arc<outline::Outline>] {
        &self.outlines
    }

    /// The register holding the signed distance.
    pub fn distance(&self) -> Reg {
        self.distance
    }

    /// The register holding the material id (an integer ≥ 0 held as a float).
    pub fn material(&self) -> Reg {
        self.material
    }

    /// Number of instructions.
    pub fn len(&self) -> usize {
        self.ops.len()
    }

    /// True for a program with no instructions (never produced by [`lower`](crate::lower::lower)).
    pub fn is_empty(&self) -> bool {
        self.ops.is_empty()
    }

    /// The program's structure in order: every instruction, with the opening and closing of
    /// each guarded block around its instructions (the `Phi`s come after the close).
    pub fn items(&self) -> Vec<Item> {
        let mut out = Vec::with_capacity(self.ops.len() + 2 * self.blocks.len());
        let mut open: Vec<usize> = Vec::new();
        let mut next = 0;
        for i in 0..=self.ops.len() {
            loop {
                if let Some(&b) = open.last() {
                    if self.blocks[b].end == i {
                        open.pop();
                        out.push(Item::Close(b));
                        continue;
                    }
                }
                if next < self.blocks.len() && self.blocks[next].start == i {
                    open.push(next);
                    out.push(Item::Open(next));
                    next += 1;
                    continue;
                }
                break;
            }
            if i < self.ops.len() {
                out.push(Item::Op(i));
            }
        }
        out
    }
}
