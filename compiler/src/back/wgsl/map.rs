//! Writes a distance program as the WGSL functions `fn map(p: vec3<f32>) -> vec2<f32>` and
//! `fn sdf(p: vec3<f32>) -> f32`: one `let` per instruction (constants written where they are
//! read), with comments naming the scene node each block comes from. A guarded block is an
//! `if`; each of its results is a `var` holding the value from before the block, assigned the
//! block's value inside it. In a large program, large blocks become functions of their own
//! (`map_blockN`, `sdf_blockN`) that take the point and the values they read from outside.

use super::literal::float;
use crate::program::{results, Axis, Binary, Item, Op, Program, Reg, Unary};
use std::cell::RefCell;
use std::fmt::Write;

/// The constants of programs written as reads of `scene_data` instead of literals
/// ([`super::Options::parameters`]): each read of a constant is a slot of its own, in the
/// order they are written, and registers are numbered among the instructions that are not
/// constants; so the text depends only on the program with its constants erased as operands
/// (`animation::Structure`), and two programs that differ in numbers only share one kernel
/// and differ in the values, `values[k]` at `scene_data[k / 4][k % 4]`.
#[derive(Debug, Default)]
pub(super) struct Params {
    /// The values of the slots so far, rounded to f32 as literals are.
    pub values: RefCell<Vec<f32>>,
}

impl Params {
    /// The expression reading the next slot, which holds `x`.
    fn read(&self, x: f64) -> String {
        let mut v = self.values.borrow_mut();
        let k = v.len();
        v.push((x as f32).clamp(-f32::MAX, f32::MAX));
        format!("scene_data[{}].{}", k / 4, ["x", "y", "z", "w"][k % 4])
    }

    /// The slots as the bytes of `scene_data` (whole `vec4`s, at least one).
    pub fn bytes(&self) -> Vec<u8> {
        let v = self.values.borrow();
        let mut out: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
        out.resize(out.len().div_ceil(16).max(1) * 16, 0);
        out
    }
}

/// Programs with more live instructions than this have their large guarded blocks written as
/// functions of their own. naga's WGSL front end takes time that grows with the square of a
/// function's length (examples/scaling/compound_1000.sdf, about 150 000 instructions, parses
/// about twenty times faster cut into functions); ptxas
/// then inlines them again. Smaller programs are written as one function.
const OUTLINE_PROGRAM: usize = 8_000;
/// In such a program, a guarded block with at least this many live instructions becomes a
/// function (nested blocks inside it may become functions in turn). Smaller pieces parse
/// faster still but made ptxas slower.
const OUTLINE_BLOCK: usize = 2_000;
/// A block that reads more values from outside than this stays inline.
const OUTLINE_PARAMS: usize = 48;

/// The WGSL text of `map`, returning (distance, material id), preceded by the functions
/// of its outlined blocks, if any.
pub fn write_map(program: &Program) -> String {
    write_map_named(program, "map")
}

/// [`write_map`] as the function `name` (its outlined blocks prefixed by it).
pub(super) fn write_map_named(program: &Program, name: &str) -> String {
    write_map_with(program, name, None)
}

/// [`write_map_named`], with the constants read from `params` when given.
pub(super) fn write_map_with(program: &Program, name: &str, params: Option<&Params>) -> String {
    let roots = [program.distance(), program.material()];
    let mut w = Writer::new(program, &roots, true, name, params);
    let mut main = String::new();
    w.emit(0, w.items.len(), 1, &mut main);
    let names = &w.names;
    let (d, m) = (
        names.get(program.distance(), params),
        names.get(program.material(), params),
    );
    let mut out = std::mem::take(&mut w.functions);
    out.push_str("// The scene's distance field: (signed distance, material id) at p.\n");
    let _ = writeln!(out, "fn {name}(p: vec3<f32>) -> vec2<f32> {{");
    out.push_str(&main);
    let _ = writeln!(out, "    return vec2<f32>({d}, {m});");
    out.push_str("}\n");
    out
}

/// The WGSL text of `sdf`: only the instructions the distance depends on (marching and
/// normals do not need the material).
pub fn write_sdf(program: &Program) -> String {
    write_sdf_named(program, "sdf")
}

/// [`write_sdf`] as the function `name`.
pub(super) fn write_sdf_named(program: &Program, name: &str) -> String {
    write_sdf_with(program, name, None)
}

/// [`write_sdf_named`], with the constants read from `params` when given.
pub(super) fn write_sdf_with(program: &Program, name: &str, params: Option<&Params>) -> String {
    let roots = [program.distance()];
    let mut w = Writer::new(program, &roots, false, name, params);
    let mut main = String::new();
    w.emit(0, w.items.len(), 1, &mut main);
    let d = w.names.get(program.distance(), params);
    let mut out = std::mem::take(&mut w.functions);
    let _ = writeln!(
        out,
        "// The distance alone, for marching and normals.\nfn {name}(p: vec3<f32>) -> f32 {{"
    );
    out.push_str(&main);
    let _ = writeln!(out, "    return {d};\n}}");
    out
}

/// The WGSL functions of the materials' colour fields (`lower::Colours`): `colour_fieldK(p, n)`
/// for each, written as `map` is, and `colour_field(k, p, n)`, field `k`'s colour at p where
/// the unit surface normal is n (each name after `prefix`).
pub(super) fn write_colours(colours: &[crate::lower::ColourProgram], prefix: &str) -> String {
    let mut out = String::new();
    for (k, c) in colours.iter().enumerate() {
        let name = format!("{prefix}colour_field{k}");
        let mut w = Writer::new(&c.program, &c.rgb, true, &name, None);
        let mut body = String::new();
        w.emit(0, w.items.len(), 1, &mut body);
        let rgb = c.rgb.map(|r| w.names.get(r, None));
        out.push_str(&std::mem::take(&mut w.functions));
        let _ = writeln!(
            out,
            "// Colour field {k}: (red, green, blue) at p, where the normal is n.\nfn {name}(p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {{"
        );
        out.push_str(&body);
        let _ = writeln!(
            out,
            "    return vec3<f32>({}, {}, {});\n}}",
            rgb[0], rgb[1], rgb[2]
        );
    }
    let _ = writeln!(
        out,
        "// The colour of colour field k at p, where the normal is n.\nfn {prefix}colour_field(k: u32, p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {{\n    switch k {{"
    );
    for k in 0..colours.len() {
        let _ = writeln!(
            out,
            "        case {k}u: {{\n            return {prefix}colour_field{k}(p, n);\n        }}"
        );
    }
    out.push_str("        default: {}\n    }\n    return vec3<f32>(0.0);\n}");
    out
}

/// The WGSL function `fn name(p: vec3<f32>, s: vec4<f32>) -> f32` of a primitive's distance
/// (`lower::ShapeProgram`): the program's distance, each of its constants that is a slot read
/// as `scale · s[slot]` (`s.x`, `(-s.x)`, `(2.0 * s.y)`), the others written as literals.
pub(super) fn write_shape(shape: &crate::lower::ShapeProgram, name: &str) -> String {
    let program = &shape.program;
    let roots = [program.distance()];
    let mut w = Writer::new(program, &roots, false, name, None);
    for p in &shape.params {
        let lane = ["s.x", "s.y", "s.z", "s.w", "t.x", "t.y", "t.z", "t.w"][p.slot];
        w.names.literals[p.reg.0 as usize] = Some(match p.scale {
            1.0 => lane.to_string(),
            -1.0 => format!("(-{lane})"),
            k => format!("({} * {lane})", float(k)),
        });
    }
    let mut body = String::new();
    w.emit(0, w.items.len(), 1, &mut body);
    let d = w.names.get(program.distance(), None);
    // The slots past the fourth are a second vector.
    let t = if shape.params.iter().any(|p| p.slot >= 4) {
        ", t: vec4<f32>"
    } else {
        ""
    };
    format!("fn {name}(p: vec3<f32>, s: vec4<f32>{t}) -> f32 {{\n{body}    return {d};\n}}\n")
}

/// Writes the statements of a program's live instructions, outlining large blocks.
struct Writer<'a> {
    program: &'a Program,
    /// Where constants are read from, when not written as literals.
    params: Option<&'a Params>,
    live: Vec<bool>,
    live_blocks: Vec<bool>,
    phi_of: Vec<Option<usize>>,
    names: Names,
    items: Vec<Item>,
    /// For each `Item::Open` position, the position of its `Item::Close`.
    close: Vec<usize>,
    /// Whether each block is written as a function.
    outline: Vec<bool>,
    comments: bool,
    /// Next program note to write.
    note: usize,
    /// Prefix of the outlined functions' names.
    prefix: &'a str,
    /// The outlined functions written so far.
    functions: String,
}

impl<'a> Writer<'a> {
    fn new(
        program: &'a Program,
        roots: &[Reg],
        comments: bool,
        prefix: &'a str,
        params: Option<&'a Params>,
    ) -> Self {
        let (live, live_blocks) = program.live(roots);
        let items = program.items();
        let mut close = vec![0; items.len()];
        let mut open = Vec::new();
        for (k, item) in items.iter().enumerate() {
            match item {
                Item::Open(_) => open.push(k),
                Item::Close(_) => {
                    if let Some(o) = open.pop() {
                        close[o] = k;
                    }
                }
                Item::Op(_) => {}
            }
        }
        let count = |a: usize, b: usize| live[a..b].iter().filter(|&&l| l).count();
        let big = count(0, live.len()) > OUTLINE_PROGRAM;
        let outline = program
            .blocks()
            .iter()
            .enumerate()
            .map(|(b, block)| {
                big && live_blocks[b] && count(block.start, block.end) >= OUTLINE_BLOCK
            })
            .collect();
        Writer {
            program,
            params,
            names: Names::new(program, params.is_some()),
            phi_of: program.phi_blocks(),
            live,
            live_blocks,
            items,
            close,
            outline,
            comments,
            note: 0,
            prefix,
            functions: String::new(),
        }
    }

    /// Writes the items `lo..hi` (blocks whole) at `depth` into `out`.
    fn emit(&mut self, lo: usize, hi: usize, depth: usize, out: &mut String) {
        let pad = |d: usize| "    ".repeat(d);
        let ops = self.program.ops();
        let mut k = lo;
        while k < hi {
            match self.items[k] {
                Item::Op(i)
                    if self.live[i] && self.phi_of[i].is_none() && !self.names.inlined(i) =>
                {
                    let notes = self.program.notes();
                    while self.note < notes.len() && notes[self.note].at <= i {
                        if self.comments {
                            let _ = writeln!(out, "{}// {}", pad(depth), notes[self.note].text);
                        }
                        self.note += 1;
                    }
                    let _ = writeln!(
                        out,
                        "{}let {} = {};",
                        pad(depth),
                        self.names.reg(i),
                        expr(self.program, &ops[i], &self.names, self.params)
                    );
                }
                Item::Open(b) if self.live_blocks[b] => {
                    let block = &self.program.blocks()[b];
                    let results = results(self.program, b, &self.live);
                    for &(j, _, other) in &results {
                        let _ = writeln!(
                            out,
                            "{}var {}: f32 = {};",
                            pad(depth),
                            self.names.reg(j),
                            self.names.get(other, self.params)
                        );
                    }
                    let (x, y) = (
                        self.names.get(block.bound, self.params),
                        self.names.get(block.best, self.params),
                    );
                    let _ = writeln!(out, "{}if !({x} >= {y}) {{", pad(depth));
                    let end = self.close[k];
                    let arity = results.len();
                    let params = if self.outline[b] && (1..=4).contains(&arity) {
                        Some(self.outside_reads(b, &results)).filter(|p| p.len() <= OUTLINE_PARAMS)
                    } else {
                        None
                    };
                    if let Some(params) = params {
                        let name = format!("{}_block{b}", self.prefix);
                        let args: Vec<String> = params
                            .iter()
                            .map(|r| format!(", {}", self.names.reg(r.0 as usize)))
                            .collect();
                        let _ =
                            writeln!(out, "{}let o = {name}(p{});", pad(depth + 1), args.concat());
                        for (n, &(j, _, _)) in results.iter().enumerate() {
                            let lane = if arity == 1 {
                                ""
                            } else {
                                [".x", ".y", ".z", ".w"][n]
                            };
                            let _ =
                                writeln!(out, "{}{} = o{lane};", pad(depth + 1), self.names.reg(j));
                        }
                        self.function(&name, k + 1, end, &params, &results);
                    } else {
                        self.emit(k + 1, end, depth + 1, out);
                        for &(j, then, _) in &results {
                            let _ = writeln!(
                                out,
                                "{}{} = {};",
                                pad(depth + 1),
                                self.names.reg(j),
                                self.names.get(then, self.params)
                            );
                        }
                    }
                    let _ = writeln!(out, "{}}}", pad(depth));
                    k = end;
                }
                Item::Op(_) | Item::Open(_) | Item::Close(_) => {}
            }
            k += 1;
        }
    }

    /// Writes the function of an outlined block: the point and the values it reads from
    /// outside in, the block's results out.
    fn function(
        &mut self,
        name: &str,
        lo: usize,
        hi: usize,
        params: &[Reg],
        results: &[(usize, Reg, Reg)],
    ) {
        let mut body = String::new();
        self.emit(lo, hi, 1, &mut body);
        let ty = match results.len() {
            1 => "f32".to_string(),
            n => format!("vec{n}<f32>"),
        };
        let list: Vec<String> = params
            .iter()
            .map(|r| format!(", {}: f32", self.names.reg(r.0 as usize)))
            .collect();
        let values: Vec<String> = results
            .iter()
            .map(|&(_, then, _)| self.names.get(then, self.params))
            .collect();
        let value = if results.len() == 1 {
            values[0].clone()
        } else {
            format!("{ty}({})", values.join(", "))
        };
        let f = &mut self.functions;
        let _ = writeln!(f, "// A guarded block of `{}`, outlined.", self.prefix);
        let _ = writeln!(f, "fn {name}(p: vec3<f32>{}) -> {ty} {{", list.concat());
        f.push_str(&body);
        let _ = writeln!(f, "    return {value};\n}}\n");
    }

    /// The registers that block `b` (its live instructions, nested blocks and results) reads
    /// from before it, other than literals, in order.
    fn outside_reads(&self, b: usize, results: &[(usize, Reg, Reg)]) -> Vec<Reg> {
        let program = self.program;
        let block = &program.blocks()[b];
        let inside = |r: Reg| (block.start..block.end).contains(&(r.0 as usize));
        let mut reads: Vec<Reg> = Vec::new();
        for i in block.start..block.end {
            if self.live[i] && !self.names.inlined(i) {
                reads.extend(program.ops()[i].operands());
            }
        }
        for (b2, inner) in program.blocks().iter().enumerate() {
            if b2 != b && self.live_blocks[b2] && inside(Reg(inner.start as u32)) {
                reads.extend([inner.bound, inner.best]);
            }
        }
        reads.extend(results.iter().map(|&(_, then, _)| then));
        reads.retain(|&r| !inside(r) && !self.names.inlined(r.0 as usize));
        reads.sort_by_key(|r| r.0);
        reads.dedup();
        reads
    }
}

/// How each register is read: `r{i}`, or the literal of a constant that is only read by
/// instructions with another operand (so that no expression is all constants, which naga
/// would evaluate when parsing); with parameters, every constant is read from its slot and
/// the other registers are numbered among themselves.
struct Names {
    literals: Vec<Option<String>>,
    /// The value of each constant.
    constants: Vec<Option<f64>>,
    /// With parameters: each register's number among the instructions that are not
    /// constants (constants have none).
    numbers: Option<Vec<u32>>,
    /// The constant naming each outline's place in `scene_data` (glyphs.rs).
    glyphs: Vec<String>,
}

impl Names {
    fn new(program: &Program, params: bool) -> Names {
        let ops = program.ops();
        let glyphs = program
            .outlines()
            .iter()
            .map(|o| super::glyphs::name(o))
            .collect();
        let constants: Vec<Option<f64>> = ops
            .iter()
            .map(|op| match op {
                Op::Const(c) => Some(*c),
                _ => None,
            })
            .collect();
        if params {
            let mut next = 0;
            let numbers = ops
                .iter()
                .map(|op| {
                    next += u32::from(!matches!(op, Op::Const(_)));
                    next.saturating_sub(1)
                })
                .collect();
            return Names {
                literals: ops.iter().map(|_| None).collect(),
                constants,
                numbers: Some(numbers),
                glyphs,
            };
        }
        let is_const = |r: Reg| matches!(ops[r.0 as usize], Op::Const(_));
        let mut inline: Vec<bool> = ops.iter().map(|op| matches!(op, Op::Const(_))).collect();
        for op in ops {
            let operands = op.operands();
            if !operands.is_empty() && operands.iter().all(|&r| is_const(r)) {
                operands.iter().for_each(|r| inline[r.0 as usize] = false);
            }
        }
        Names {
            literals: ops
                .iter()
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
            constants,
            numbers: None,
            glyphs,
        }
    }

    /// Whether the register is written where it is read (and has no `let`).
    fn inlined(&self, i: usize) -> bool {
        match &self.numbers {
            Some(_) => self.constants[i].is_some(),
            None => self.literals[i].is_some(),
        }
    }

    /// The name of the variable of register `i`.
    fn reg(&self, i: usize) -> String {
        match &self.numbers {
            Some(n) => format!("r{}", n[i]),
            None => format!("r{i}"),
        }
    }

    /// How register `r` is read (a constant's next slot, with parameters).
    fn get(&self, r: Reg, params: Option<&Params>) -> String {
        if let (Some(p), Some(c)) = (params, self.constants[r.0 as usize]) {
            return p.read(c);
        }
        self.literals[r.0 as usize]
            .clone()
            .unwrap_or_else(|| self.reg(r.0 as usize))
    }
}

/// The WGSL of a one-operand operation on the expression `a` (also the interpreted kernel's).
pub(super) fn unary(u: Unary, a: &str) -> String {
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

/// The WGSL of a two-operand operation on the expressions `x` and `y` (also the interpreted
/// kernel's).
pub(super) fn binary(b: Binary, x: &str, y: &str) -> String {
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

fn expr(program: &Program, op: &Op, names: &Names, params: Option<&Params>) -> String {
    let n = |r: Reg| names.get(r, params);
    match *op {
        Op::Const(c) => float(c),
        Op::Input(Axis::X) => "p.x".into(),
        Op::Input(Axis::Y) => "p.y".into(),
        Op::Input(Axis::Z) => "p.z".into(),
        Op::Input(Axis::Nx) => "n.x".into(),
        Op::Input(Axis::Ny) => "n.y".into(),
        Op::Input(Axis::Nz) => "n.z".into(),
        Op::Unary(u, a) => unary(u, &n(a)),
        Op::Binary(b, x, y) => binary(b, &n(x), &n(y)),
        Op::Select(c, a, b) => format!("select({}, {}, {} != 0.0)", n(b), n(a), n(c)),
        Op::Phi(a, _) => n(a),
        // The walk over the mesh's hierarchy in `scene_data` (mesh.rs).
        Op::Mesh(m, x, y, z) => format!(
            "mesh_distance(vec3<f32>({}, {}, {}), {}u)",
            n(x),
            n(y),
            n(z),
            program.mesh(m).base
        ),
        Op::Outline(k, x, y) => format!(
            "text_outline({}, vec2<f32>({}, {}))",
            names.glyphs[k as usize],
            n(x),
            n(y)
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::float;

    /// The value WGSL gives a literal without suffix: read as an f64, then rounded to the
    /// nearest f32; `None` where Tint rejects it (an f64 beyond the largest f32).
    fn wgsl_value(text: &str) -> Option<f32> {
        let read: f64 = text.parse().expect("a decimal literal");
        (read.abs() <= f64::from(f32::MAX)).then_some(read as f32)
    }

    #[test]
    fn largest_f32_is_written_exactly() {
        // Its shortest text, 3.4028235e38, reads as an f64 above f32::MAX, which Tint rejects.
        assert_eq!(float(f64::from(f32::MAX)), "3.4028234663852886e38");
        assert_eq!(float(-f64::from(f32::MAX)), "-3.4028234663852886e38");
        assert_eq!(float(f64::INFINITY), "3.4028234663852886e38");
        assert_eq!(float(1e300), "3.4028234663852886e38");
        // Others keep their shortest text.
        assert_eq!(float(0.1), "0.1");
        assert_eq!(float(3.0e38), "3e38");
        assert_eq!(float(2.0), "2.0");
    }

    #[test]
    fn every_literal_reads_back_as_its_f32() {
        let near_max = (0..20_000u32).map(|k| f32::MAX.to_bits() - k);
        let spread = (0..=u32::MAX / 7919).map(|k| k * 7919);
        for bits in near_max.chain(spread) {
            let f = f32::from_bits(bits);
            if !f.is_finite() {
                continue;
            }
            for x in [f, -f] {
                let text = float(f64::from(x));
                assert_eq!(wgsl_value(&text), Some(x), "{x:e} written as {text}");
            }
        }
    }
}
