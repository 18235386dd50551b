//! Writes a distance program as the WGSL function `fn map(p: vec3<f32>) -> vec2<f32>`:
//! one `let` per instruction, with comments naming the scene node each block comes from.

use crate::lower::{Axis, Binary, Op, Program, Unary};
use std::fmt::Write;

/// The WGSL text of `map`, returning (distance, material id).
pub fn write_map(program: &Program) -> String {
    let mut out = String::new();
    out.push_str("// The scene's distance field: (signed distance, material id) at p.\n");
    out.push_str("fn map(p: vec3<f32>) -> vec2<f32> {\n");
    let mut notes = program.notes().iter().peekable();
    for (i, op) in program.ops().iter().enumerate() {
        while let Some(n) = notes.next_if(|n| n.at == i) {
            let _ = writeln!(out, "    // {}", n.text);
        }
        let _ = writeln!(out, "    let r{i} = {};", expr(op));
    }
    let _ = writeln!(
        out,
        "    return vec2<f32>(r{}, r{});",
        program.distance().0,
        program.material().0
    );
    out.push_str("}\n");
    out
}

/// A WGSL float literal for `x` rounded to f32 (finite values only reach here; others are
/// clamped to the largest f32 so that the module stays valid).
pub fn float(x: f64) -> String {
    let f = (x as f32).clamp(-f32::MAX, f32::MAX);
    let s = format!("{f:?}");
    if s.contains('.') || s.contains('e') {
        s
    } else {
        format!("{s}.0")
    }
}

fn expr(op: &Op) -> String {
    match *op {
        Op::Const(c) => float(c),
        Op::Input(Axis::X) => "p.x".into(),
        Op::Input(Axis::Y) => "p.y".into(),
        Op::Input(Axis::Z) => "p.z".into(),
        Op::Unary(u, a) => {
            let a = format!("r{}", a.0);
            match u {
                Unary::Neg => format!("-{a}"),
                Unary::Abs => format!("abs({a})"),
                Unary::Sqrt => format!("sqrt({a})"),
                Unary::Sin => format!("sin({a})"),
                Unary::Cos => format!("cos({a})"),
                Unary::Acos => format!("acos({a})"),
                Unary::Exp => format!("exp({a})"),
                Unary::Log => format!("log({a})"),
                Unary::Floor => format!("floor({a})"),
                // ⌊a + 0.5⌋, as on the CPU (WGSL's round() rounds halves to even).
                Unary::Round => format!("floor({a} + 0.5)"),
            }
        }
        Op::Binary(b, x, y) => {
            let (x, y) = (format!("r{}", x.0), format!("r{}", y.0));
            match b {
                Binary::Add => format!("{x} + {y}"),
                Binary::Sub => format!("{x} - {y}"),
                Binary::Mul => format!("{x} * {y}"),
                Binary::Div => format!("{x} / {y}"),
                Binary::Min => format!("min({x}, {y})"),
                Binary::Max => format!("max({x}, {y})"),
                Binary::Pow => format!("pow({x}, {y})"),
                Binary::Atan2 => format!("atan2({x}, {y})"),
                Binary::Lt => format!("select(0.0, 1.0, {x} < {y})"),
            }
        }
        Op::Select(c, a, b) => format!("select(r{}, r{}, r{} != 0.0)", b.0, a.0, c.0),
    }
}
