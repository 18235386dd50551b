//! Lowering of the scene IR to the distance program: one flat scalar SSA program that maps a
//! point (x, y, z) to (distance, material id).
//!
//! The program has no control flow. Every instruction defines one register, numbered by its
//! position, over the evaluation's float type (f32 or f64). Material ids are registers too
//! (small integers held as floats); a union picks the nearer child's material with `lt` and
//! `select`. Loops (the Mandelbulb's iterations) are unrolled, with the escape test done by
//! `select` so that the state freezes once a point has escaped.
//!
//! The builder folds constants and shares equal instructions, so a feature a scene does not
//! use costs nothing, and a node reached twice at the same point is computed once.

mod builder;
mod graph;
mod shapes;

use crate::scene::Scene;
use std::fmt::Write;

/// Names a register: the value defined by the instruction at this index.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Reg(pub u32);

/// A coordinate of the input point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Axis {
    /// x
    X,
    /// y
    Y,
    /// z
    Z,
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
}

impl Op {
    /// The registers this instruction reads.
    pub fn operands(&self) -> Vec<Reg> {
        match *self {
            Op::Const(_) | Op::Input(_) => Vec::new(),
            Op::Unary(_, a) => vec![a],
            Op::Binary(_, a, b) => vec![a, b],
            Op::Select(c, a, b) => vec![c, a, b],
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

/// A distance program: p ↦ (distance, material id).
#[derive(Debug, Clone, PartialEq)]
pub struct Program {
    ops: Vec<Op>,
    notes: Vec<Note>,
    distance: Reg,
    material: Reg,
}

impl Program {
    /// The instructions; register `i` is defined by `ops()[i]`.
    pub fn ops(&self) -> &[Op] {
        &self.ops
    }

    /// The comments naming the IR node of each block.
    pub fn notes(&self) -> &[Note] {
        &self.notes
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

    /// True for a program with no instructions (never produced by [`lower`]).
    pub fn is_empty(&self) -> bool {
        self.ops.is_empty()
    }

    /// The stable text form (`sdfc compile --emit program`): one instruction per line,
    /// `%3 = add %1, %2`, with `;` comments naming the IR node of each block.
    pub fn dump(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(out, "; distance program: {} instructions", self.ops.len());
        let mut notes = self.notes.iter().peekable();
        for (i, op) in self.ops.iter().enumerate() {
            while let Some(n) = notes.next_if(|n| n.at == i) {
                let _ = writeln!(out, "; {}", n.text);
            }
            let _ = writeln!(out, "%{i} = {}", op_text(op));
        }
        for n in notes {
            let _ = writeln!(out, "; {}", n.text);
        }
        let _ = writeln!(
            out,
            "return distance %{}, material %{}",
            self.distance.0, self.material.0
        );
        out
    }
}

/// The text of one instruction, as in the dump.
pub fn op_text(op: &Op) -> String {
    match *op {
        Op::Const(c) => format!("const {c:?}"),
        Op::Input(a) => axis_name(a).to_string(),
        Op::Unary(u, a) => format!("{} %{}", unary_name(u), a.0),
        Op::Binary(b, x, y) => format!("{} %{}, %{}", binary_name(b), x.0, y.0),
        Op::Select(c, a, b) => format!("select %{}, %{}, %{}", c.0, a.0, b.0),
    }
}

/// The name of an input coordinate.
pub fn axis_name(a: Axis) -> &'static str {
    match a {
        Axis::X => "x",
        Axis::Y => "y",
        Axis::Z => "z",
    }
}

/// The mnemonic of a one-operand operation.
pub fn unary_name(u: Unary) -> &'static str {
    match u {
        Unary::Neg => "neg",
        Unary::Abs => "abs",
        Unary::Sqrt => "sqrt",
        Unary::Sin => "sin",
        Unary::Cos => "cos",
        Unary::Acos => "acos",
        Unary::Exp => "exp",
        Unary::Log => "log",
        Unary::Floor => "floor",
        Unary::Round => "round",
    }
}

/// The mnemonic of a two-operand operation.
pub fn binary_name(b: Binary) -> &'static str {
    match b {
        Binary::Add => "add",
        Binary::Sub => "sub",
        Binary::Mul => "mul",
        Binary::Div => "div",
        Binary::Min => "min",
        Binary::Max => "max",
        Binary::Pow => "pow",
        Binary::Atan2 => "atan2",
        Binary::Lt => "lt",
    }
}

/// The distance a program reports for a scene with no objects: far beyond any `max_dist`.
pub const EMPTY_DISTANCE: f64 = 1e30;

/// Lowers a checked scene to its distance program.
pub fn lower(scene: &Scene) -> Program {
    let mut b = builder::Builder::new();
    let p = b.input_point();
    let (d, m) = match scene.root {
        Some(root) => {
            let field = graph::Lowerer::new(&scene.graph, &mut b).node(root, p);
            (field.d, field.m)
        }
        None => (b.c(EMPTY_DISTANCE), b.c(graph::UNPAINTED)),
    };
    b.note("result: unpainted shapes get the default material 0".into());
    let m = b.paint(m, 0.0);
    b.finish(d, m)
}
