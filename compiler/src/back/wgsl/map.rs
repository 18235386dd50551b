//! Writes a distance program as the WGSL functions `fn map(p: vec3<f32>) -> vec2<f32>` and
//! `fn sdf(p: vec3<f32>) -> f32`: one `let` per instruction (constants written where they are
//! read), with comments naming the scene node each block comes from. A guarded block is an `if`; each of its results is a `var`
//! holding the value from before the block, assigned the block's value inside it.

use crate::lower::{Axis, Binary, Item, Op, Program, Reg, Unary};
use std::fmt::Write;

/// The WGSL text of `map`, returning (distance, material id).
pub fn write_map(program: &Program) -> String {
    let mut out = String::new();
    out.push_str("// The scene's distance field: (signed distance, material id) at p.\n");
    out.push_str("fn map(p: vec3<f32>) -> vec2<f32> {\n");
    body(
        &mut out,
        program,
        &[program.distance(), program.material()],
        true,
    );
    let names = Names::new(program);
    let (d, m) = (names.get(program.distance()), names.get(program.material()));
    let _ = writeln!(out, "    return vec2<f32>({d}, {m});");
    out.push_str("}\n");
    out
}

/// The WGSL text of `sdf`: only the instructions the distance depends on (marching and
/// normals do not need the material).
pub fn write_sdf(program: &Program) -> String {
    let mut out = String::from(
        "// The distance alone, for marching and normals.\nfn sdf(p: vec3<f32>) -> f32 {\n",
    );
    body(&mut out, program, &[program.distance()], false);
    let d = Names::new(program).get(program.distance());
    let _ = writeln!(out, "    return {d};\n}}");
    out
}

/// The statements computing `roots`, with the program's comments when `comments`.
fn body(out: &mut String, program: &Program, roots: &[Reg], comments: bool) {
    let (live, live_blocks) = program.live(roots);
    let ops = program.ops();
    let blocks = program.blocks();
    let phi_of = program.phi_blocks();
    let names = Names::new(program);
    let mut notes = program.notes().iter().peekable();
    let mut depth = 1;
    let pad = |d: usize| "    ".repeat(d);
    for item in program.items() {
        match item {
            Item::Op(i) if live[i] && phi_of[i].is_none() && !names.inlined(i) => {
                while let Some(n) = notes.next_if(|n| n.at <= i) {
                    if comments {
                        let _ = writeln!(out, "{}// {}", pad(depth), n.text);
                    }
                }
                let _ = writeln!(out, "{}let r{i} = {};", pad(depth), expr(&ops[i], &names));
            }
            Item::Op(_) => {}
            Item::Open(b) if live_blocks[b] => {
                let block = &blocks[b];
                for (j, _, other) in results(program, b, &live) {
                    let _ = writeln!(out, "{}var r{j}: f32 = {};", pad(depth), names.get(other));
                }
                let (x, y) = (names.get(block.bound), names.get(block.best));
                let _ = writeln!(out, "{}if !({x} >= {y}) {{", pad(depth));
                depth += 1;
            }
            Item::Close(b) if live_blocks[b] => {
                for (j, then, _) in results(program, b, &live) {
                    let _ = writeln!(out, "{}r{j} = {};", pad(depth), names.get(then));
                }
                depth -= 1;
                let _ = writeln!(out, "{}}}", pad(depth));
            }
            Item::Open(_) | Item::Close(_) => {}
        }
    }
}

/// The needed results of block `b`: (register, value inside, value from before).
pub(crate) fn results(program: &Program, b: usize, live: &[bool]) -> Vec<(usize, Reg, Reg)> {
    let block = &program.blocks()[b];
    (block.end..block.end + block.results)
        .filter(|&j| live[j])
        .filter_map(|j| match program.ops()[j] {
            Op::Phi(then, other) => Some((j, then, other)),
            _ => None,
        })
        .collect()
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

/// How each register is read: `r{i}`, or the literal of a constant that is only read by
/// instructions with another operand (so that no expression is all constants, which naga
/// would evaluate when parsing).
struct Names(Vec<Option<String>>);

impl Names {
    fn new(program: &Program) -> Names {
        let ops = program.ops();
        let is_const = |r: Reg| matches!(ops[r.0 as usize], Op::Const(_));
        let mut inline: Vec<bool> = ops.iter().map(|op| matches!(op, Op::Const(_))).collect();
        for op in ops {
            let operands = op.operands();
            if !operands.is_empty() && operands.iter().all(|&r| is_const(r)) {
                operands.iter().for_each(|r| inline[r.0 as usize] = false);
            }
        }
        Names(
            ops.iter()
                .zip(inline)
                .map(|(op, i)| match (op, i) {
                    (Op::Const(c), true) => {
                        let lit = float(*c);
                        Some(if lit.starts_with('-') {
                            format!("({lit})")
                        } else {
                            lit
                        })
                    }
                    _ => None,
                })
                .collect(),
        )
    }

    /// Whether the register is written as a literal (and has no `let`).
    fn inlined(&self, i: usize) -> bool {
        self.0[i].is_some()
    }

    fn get(&self, r: Reg) -> String {
        self.0[r.0 as usize]
            .clone()
            .unwrap_or_else(|| format!("r{}", r.0))
    }
}

fn expr(op: &Op, names: &Names) -> String {
    let n = |r: Reg| names.get(r);
    match *op {
        Op::Const(c) => float(c),
        Op::Input(Axis::X) => "p.x".into(),
        Op::Input(Axis::Y) => "p.y".into(),
        Op::Input(Axis::Z) => "p.z".into(),
        Op::Unary(u, a) => {
            let a = n(a);
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
            let (x, y) = (n(x), n(y));
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
        Op::Select(c, a, b) => format!("select({}, {}, {} != 0.0)", n(b), n(a), n(c)),
        Op::Phi(a, _) => n(a),
    }
}
