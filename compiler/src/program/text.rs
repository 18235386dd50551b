//! The stable text form of a distance program (`sdfc compile --emit program`) and the
//! mnemonics of its operations.

use super::{Axis, Binary, Item, Op, Program, Unary};
use std::fmt::Write;

impl Program {
    /// The stable text form (`sdfc compile --emit program`): one instruction per line,
    /// `%3 = add %1, %2`, with `;` comments naming the IR node of each block of
    /// instructions. A guarded block reads `if !(%7 >= %5) {` … `}`, its instructions
    /// indented, and is followed by its `phi` instructions.
    pub fn dump(&self) -> String {
        let mut out = String::new();
        let _ = write!(out, "; distance program: {} instructions", self.ops.len());
        if !self.blocks.is_empty() {
            let _ = write!(out, ", {} guarded blocks", self.blocks.len());
        }
        out.push('\n');
        for (k, o) in self.outlines.iter().enumerate() {
            let _ = writeln!(
                out,
                "; outline {k}: {} glyphs, {} segments, {} levels of boxes (data)",
                o.glyphs().len(),
                o.segments(),
                o.depth()
            );
        }
        let mut notes = self.notes.iter().peekable();
        let mut depth = 0;
        for item in self.items() {
            let pad = "  ".repeat(depth);
            match item {
                Item::Op(i) => {
                    while let Some(n) = notes.next_if(|n| n.at == i) {
                        let _ = writeln!(out, "{pad}; {}", n.text);
                    }
                    let _ = writeln!(out, "{pad}%{i} = {}", op_text(&self.ops[i]));
                }
                Item::Open(b) => {
                    let b = &self.blocks[b];
                    let _ = writeln!(out, "{pad}if !(%{} >= %{}) {{", b.bound.0, b.best.0);
                    depth += 1;
                }
                Item::Close(_) => {
                    depth -= 1;
                    let _ = writeln!(out, "{}}}", "  ".repeat(depth));
                }
            }
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
        Op::Phi(a, b) => format!("phi %{}, %{}", a.0, b.0),
        Op::Mesh(m, x, y, z) => format!("mesh {m} %{}, %{}, %{}", x.0, y.0, z.0),
        Op::Outline(k, x, y) => format!("outline {k} %{}, %{}", x.0, y.0),
    }
}

/// The name of an input coordinate.
pub fn axis_name(a: Axis) -> &'static str {
    match a {
        Axis::X => "x",
        Axis::Y => "y",
        Axis::Z => "z",
        Axis::Nx => "nx",
        Axis::Ny => "ny",
        Axis::Nz => "nz",
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
