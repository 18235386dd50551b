//! The interpreted kernel's distance functions: `map` and `sdf` (and, for glass over solids,
//! `sdf_medium`, `map_solid` and `sdf_solid`) as one loop that reads the scene's distance
//! programs from `scene_data` and runs them on a fixed-size register file, so that the
//! kernel's text does not depend on the program: it is compiled once per specialisation
//! (the features and the `registers` limit) and found in the drivers' and sdfc's caches for
//! every scene of that specialisation.
//!
//! Layout of `scene_data` (`array<vec4<f32>>`, integers as their bits):
//!
//! ```text
//! [0]       the first word of map, sdf, sdf_medium, map_solid
//! [1]       the first word of sdf_solid, of the colour fields' table, 0, 0
//! [2 ..]    the programs, one instruction a word:
//!           x: opcode (bits 0-7) | operand k read from a register (bit 8 + k) | destination
//!              register (bits 11-23)
//!           y, z, w: the operands: a register's number, an immediate f32 (a constant of the
//!              program), or a word index (a block's end)
//! [table ..] the first word of each colour field's program, four a word
//! [data ..] the meshes (mesh.rs's layout, each at data + its base), then the outlines of
//!           text (glyphs.rs's layout)
//!
//! Every integer (word indices, the fields of x, registers) is held as the f32 of its value,
//! exact below 2^24, and read with `u32(…)`: held as its bits, a small integer would be a
//! subnormal float, which drivers that flush subnormals may zero.
//! ```
//!
//! Each program is its live instructions in order, constants folded into the operands that
//! read them, and ends with `RETURN` (distance, material; or a colour field's red, green and
//! blue). `MESH` (operands x, y, z) takes two words, the second holding the mesh's first
//! word in its y; `OUTLINE` (operands x, y and the outline's first word) one. Both call the
//! specialised kernel's functions over `scene_data` (`mesh_distance`, `text_outline`), once
//! per call outside the unrolled steps, so that the kernel holds one copy of each. A guarded
//! block is a `COPY` of
//! each needed result's value from before it, `BLOCK` (which jumps past the block where
//! `bound >= best`, as the code's `if !(bound >= best)`), its instructions, and a `COPY` of
//! each result's value inside it. Registers are allocated by a linear scan over that order,
//! with each register's last read from the program's liveness: jumps only go forwards, past
//! a block whose values are read inside it alone, so a register freed at its last read in
//! that order is never read again. Each operation is the expression the code writer
//! (map.rs) writes for it, so the two kernels compute the same values, unless a driver
//! contracts the code's products and sums into fused multiply-adds.

use super::map;
use crate::program::{results, Axis, Binary, Item, Op, Program, Reg, Unary};
use std::collections::HashMap;
use std::fmt::Write;

/// `auto` (`Options::kernel`) chooses the interpreted kernel for a marched scene whose
/// distance program written as code (the whole program, or what remains of it beside
/// instances read from `scene_data`) has at least this many live instructions; the runtime
/// keeps the specialised kernel on CUDA, on CPU adapters and for sequences. From about this
/// size the Vulkan driver's cold compile of the code takes longer than the interpreted
/// kernel's whole first render, whose frames are a few times slower (docs/interpreted.md).
pub const AUTO_INTERPRET: usize = 5_000;

/// Words of the header before the first program.
const HEADER: usize = 2;

// Opcodes. The unary operations are `UNARY + Unary as index`, the binary ones `BINARY + …`.
const RETURN: u32 = 0;
const INPUT: u32 = 1; // 1, 2, 3: x, y, z
const COPY: u32 = 4;
const BLOCK: u32 = 5;
const UNARY: u32 = 6;
const BINARY: u32 = 16;
const SELECT: u32 = 25;
const MESH: u32 = 26;
const OUTLINE: u32 = 27;
/// The second word of a `MESH`, never run.
const OPERAND: u32 = 28;
/// 29, 30, 31: the surface normal's x, y, z (a colour field's program reads it).
const NORMAL: u32 = 29;

const UNARIES: [Unary; 10] = [
    Unary::Neg,
    Unary::Abs,
    Unary::Sqrt,
    Unary::Sin,
    Unary::Cos,
    Unary::Acos,
    Unary::Exp,
    Unary::Log,
    Unary::Floor,
    Unary::Round,
];
const BINARIES: [Binary; 9] = [
    Binary::Add,
    Binary::Sub,
    Binary::Mul,
    Binary::Div,
    Binary::Min,
    Binary::Max,
    Binary::Pow,
    Binary::Atan2,
    Binary::Lt,
];

/// One operand of an instruction before registers are allocated.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Arg {
    /// Unused (zero).
    None,
    /// The value of a program register.
    Reg(Reg),
    /// A constant, rounded to f32 as map.rs's literals are.
    Imm(f32),
    /// A word index (a block's end), relative to the program's first word.
    Jump(u32),
    /// A word index of data (a mesh's or an outline's first word), relative to the data's
    /// first word.
    Data(u32),
}

/// One instruction before registers are allocated: the destination is a program register
/// (for a block's results, the `Phi`'s).
#[derive(Debug, Clone, Copy)]
struct Ins {
    op: u32,
    dest: Option<Reg>,
    args: [Arg; 3],
}

/// A program's instructions for `roots` (distance, and material where given), in order;
/// `outlines` gives each outline's first word in the data by its name (glyphs.rs).
fn linear(program: &Program, roots: &[Reg], outlines: &HashMap<String, u32>) -> Vec<Ins> {
    let ops = program.ops();
    let (live, live_blocks) = program.live(roots);
    let phi_of = program.phi_blocks();
    let arg = |r: Reg| match ops[r.0 as usize] {
        Op::Const(c) => Arg::Imm((c as f32).clamp(-f32::MAX, f32::MAX)),
        _ => Arg::Reg(r),
    };
    let mut out: Vec<Ins> = Vec::new();
    let mut open: Vec<usize> = Vec::new();
    for item in program.items() {
        match item {
            Item::Op(i) if live[i] && phi_of[i].is_none() => {
                let (op, args) = match ops[i] {
                    Op::Const(_) => continue,
                    Op::Input(a @ (Axis::X | Axis::Y | Axis::Z)) => {
                        (INPUT + a as u32, [Arg::None; 3])
                    }
                    Op::Input(a) => (NORMAL + (a.index() - 3) as u32, [Arg::None; 3]),
                    Op::Unary(u, a) => (
                        UNARY + UNARIES.iter().position(|&x| x == u).unwrap_or(0) as u32,
                        [arg(a), Arg::None, Arg::None],
                    ),
                    Op::Binary(b, x, y) => (
                        BINARY + BINARIES.iter().position(|&z| z == b).unwrap_or(0) as u32,
                        [arg(x), arg(y), Arg::None],
                    ),
                    Op::Select(c, a, b) => (SELECT, [arg(c), arg(a), arg(b)]),
                    Op::Mesh(..) => (MESH, [Arg::None; 3]),
                    Op::Outline(k, x, y) => {
                        let name = super::glyphs::name(&program.outlines()[k as usize]);
                        let at = outlines.get(&name).copied().unwrap_or(0);
                        (OUTLINE, [arg(x), arg(y), Arg::Data(at)])
                    }
                    Op::Phi(..) => continue,
                };
                if let Op::Mesh(m, x, y, z) = ops[i] {
                    out.push(Ins {
                        op: MESH,
                        dest: Some(Reg(i as u32)),
                        args: [arg(x), arg(y), arg(z)],
                    });
                    out.push(Ins {
                        op: OPERAND,
                        dest: None,
                        args: [Arg::Data(program.mesh(m).base), Arg::None, Arg::None],
                    });
                    continue;
                }
                out.push(Ins {
                    op,
                    dest: Some(Reg(i as u32)),
                    args,
                });
            }
            Item::Open(b) if live_blocks[b] => {
                for (j, _, other) in results(program, b, &live) {
                    out.push(copy(Reg(j as u32), arg(other)));
                }
                let block = &program.blocks()[b];
                open.push(out.len());
                out.push(Ins {
                    op: BLOCK,
                    dest: None,
                    args: [arg(block.bound), arg(block.best), Arg::Jump(0)],
                });
            }
            Item::Close(b) if live_blocks[b] => {
                for (j, then, _) in results(program, b, &live) {
                    out.push(copy(Reg(j as u32), arg(then)));
                }
                if let Some(at) = open.pop() {
                    out[at].args[2] = Arg::Jump(out.len() as u32);
                }
            }
            Item::Op(_) | Item::Open(_) | Item::Close(_) => {}
        }
    }
    let material = roots.get(1).map_or(Arg::Imm(0.0), |&m| arg(m));
    let third = roots.get(2).map_or(Arg::None, |&m| arg(m));
    out.push(Ins {
        op: RETURN,
        dest: None,
        args: [arg(roots[0]), material, third],
    });
    out
}

fn copy(dest: Reg, value: Arg) -> Ins {
    Ins {
        op: COPY,
        dest: Some(dest),
        args: [value, Arg::None, Arg::None],
    }
}

/// A program's instructions with registers allocated: the words, and how many registers
/// they use.
fn allocate(ins: &[Ins], len: usize) -> (Vec<[u32; 4]>, usize) {
    let mut last = vec![usize::MAX; len];
    for (pos, i) in ins.iter().enumerate() {
        for a in i.args {
            if let Arg::Reg(r) = a {
                last[r.0 as usize] = pos;
            }
        }
    }
    let mut phys: Vec<Option<u32>> = vec![None; len];
    let mut free: std::collections::BinaryHeap<std::cmp::Reverse<u32>> = Default::default();
    let mut used = 0u32;
    let mut words = Vec::with_capacity(ins.len());
    for (pos, i) in ins.iter().enumerate() {
        let mut word = [i.op, 0, 0, 0];
        for (k, a) in i.args.iter().enumerate() {
            word[k + 1] = match *a {
                Arg::None => 0,
                Arg::Imm(x) => x.to_bits(),
                Arg::Jump(j) | Arg::Data(j) => j,
                Arg::Reg(r) => {
                    word[0] |= 0x100 << k;
                    phys[r.0 as usize].unwrap_or(0)
                }
            };
        }
        for a in i.args {
            if let Arg::Reg(r) = a {
                if last[r.0 as usize] == pos {
                    if let Some(p) = phys[r.0 as usize].take() {
                        free.push(std::cmp::Reverse(p));
                    }
                }
            }
        }
        let dest = match i.dest {
            Some(d) => {
                let d = d.0 as usize;
                let p = match phys[d] {
                    Some(p) => p,
                    None => {
                        let p = free.pop().map(|r| r.0).unwrap_or_else(|| {
                            used += 1;
                            used - 1
                        });
                        phys[d] = Some(p);
                        p
                    }
                };
                if last[d] == usize::MAX {
                    // Never read (not reached for live instructions): free at once.
                    phys[d] = None;
                    free.push(std::cmp::Reverse(p));
                }
                Some(p)
            }
            None => None,
        };
        // Instructions without a destination write the scratch register, which the kernel
        // places after the file; it is patched in `encode` once the file's size is known.
        word[0] |= dest.map_or(SCRATCH, |p| p) << DEST_SHIFT;
        words.push(word);
    }
    (words, used as usize)
}

/// The destination of an instruction that has none, before [`encode`] replaces it with the
/// register after the file.
const SCRATCH: u32 = 0x1fff;
/// The destination register's place in an instruction's first field.
const DEST_SHIFT: u32 = 11;

/// What keeps a scene from the interpreted kernel.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Unfit {
    /// Its programs need more registers than the file has: (needed, the file's size).
    Registers(usize, usize),
    /// Its programs' words exceed the `scene_data` limit: (bytes, the limit in MiB).
    Bytes(usize, u64),
    /// Its programs take this many words, more than 2^24 (word indices are held as f32).
    Words(usize),
}

/// The registers that `program`'s `map` (distance and material) needs in the interpreter.
pub fn registers(program: &Program) -> usize {
    let roots = [program.distance(), program.material()];
    allocate(&linear(program, &roots, &HashMap::new()), program.len()).1
}

/// The programs of a kernel, in the order of the header: each with its roots (a `map`
/// returns distance and material, an `sdf` the distance alone).
pub(super) struct Programs<'a> {
    /// The scene's program (`map`, `sdf`).
    pub main: &'a Program,
    /// The media's (`sdf_medium`, and `map_solid`, `sdf_solid`), for glass over solids.
    pub media: Option<(&'a Program, &'a Program)>,
    /// The materials' colour fields (`colour_field`), each returning red, green and blue.
    pub colours: &'a [crate::lower::ColourProgram],
}

/// What of the data the interpreted kernel's programs call: the meshes' walk, the outlines'.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(super) struct Calls {
    /// Some program reads a mesh (`MESH`, `mesh_distance`).
    pub meshes: bool,
    /// Some program reads an outline (`OUTLINE`, `text_outline`).
    pub outlines: bool,
}

impl Programs<'_> {
    /// Every program of the kernel.
    fn all(&self) -> Vec<&Program> {
        let mut all = vec![self.main];
        if let Some((a, b)) = self.media {
            all.extend([a, b]);
        }
        all.extend(self.colours.iter().map(|c| &c.program));
        all
    }

    /// The data the programs call.
    pub(super) fn calls(&self) -> Calls {
        let all = self.all();
        Calls {
            meshes: all.iter().any(|p| super::mesh::uses_meshes(p)),
            outlines: all.iter().any(|p| !p.outlines().is_empty()),
        }
    }
}

/// The bytes of `scene_data` holding `programs` for a file of `file` registers, then the
/// meshes and outlines they read, or why they do not fit it or `max_bytes`.
pub(super) fn encode(programs: &Programs, file: usize, max_mib: u64) -> Result<Vec<u8>, Unfit> {
    // The data after the programs: the meshes, each at its base, then the outlines.
    let all = programs.all();
    let calls = programs.calls();
    let mut data = if calls.meshes {
        super::mesh::data(all.iter().copied())
    } else {
        Vec::new()
    };
    let mut outlines = HashMap::new();
    for (name, o) in super::glyphs::collect(&all) {
        outlines.insert(name, (data.len() / 16) as u32);
        for w in o.words() {
            for v in w {
                data.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    let map = |p: &Program| linear(p, &[p.distance(), p.material()], &outlines);
    let sdf = |p: &Program| linear(p, &[p.distance()], &outlines);
    let mut lists = vec![
        (map(programs.main), programs.main.len()),
        (sdf(programs.main), programs.main.len()),
    ];
    if let Some((medium, solid)) = programs.media {
        lists.push((sdf(medium), medium.len()));
        lists.push((map(solid), solid.len()));
        lists.push((sdf(solid), solid.len()));
    }
    let fixed = lists.len();
    for c in programs.colours {
        lists.push((linear(&c.program, &c.rgb, &outlines), c.program.len()));
    }
    let table_words = programs.colours.len().div_ceil(4);
    let data_start =
        (HEADER + lists.iter().map(|(l, _)| l.len()).sum::<usize>() + table_words) as u32;
    let mut starts = [0u32; 8];
    let mut colour_starts = Vec::with_capacity(programs.colours.len());
    let mut body: Vec<[u32; 4]> = Vec::new();
    let mut needed = 0;
    for (k, (list, len)) in lists.iter().enumerate() {
        let base = (HEADER + body.len()) as u32;
        if k < fixed {
            starts[k] = base;
        } else {
            colour_starts.push(base);
        }
        let (mut words, used) = allocate(list, *len);
        needed = needed.max(used);
        for (w, i) in words.iter_mut().zip(list) {
            if w[0] >> DEST_SHIFT == SCRATCH {
                w[0] = (w[0] & ((1 << DEST_SHIFT) - 1)) | (file as u32) << DEST_SHIFT;
            }
            if let Arg::Jump(_) = i.args[2] {
                w[3] += base;
            }
            // Data indices are absolute, written as the f32 of their value.
            for (k, a) in i.args.iter().enumerate() {
                if let Arg::Data(d) = a {
                    w[k + 1] = ((d + data_start) as f32).to_bits();
                }
            }
        }
        body.extend(words);
    }
    // The colour fields' table: their first words, four a word.
    starts[5] = (HEADER + body.len()) as u32;
    debug_assert_eq!(data_start as usize, HEADER + body.len() + table_words);
    if needed > file {
        return Err(Unfit::Registers(needed, file));
    }
    let words = HEADER + body.len() + table_words + data.len() / 16;
    if words > 1 << 24 {
        // Word indices are written as f32 (exact below 2^24).
        return Err(Unfit::Words(words));
    }
    let bytes = words * 16;
    if bytes as u64 > max_mib.saturating_mul(1 << 20) {
        return Err(Unfit::Bytes(bytes, max_mib));
    }
    // Every integer is written as the f32 of its value (exact below 2^24), never as its bits:
    // small integers' bits are subnormal floats, which a driver that flushes subnormals may
    // turn into zeros when it moves them.
    let int = |x: u32| (x as f32).to_bits();
    let mut out = Vec::with_capacity(bytes);
    for x in starts {
        out.extend_from_slice(&int(x).to_le_bytes());
    }
    for w in &body {
        let mut fields = [int(w[0]), w[1], w[2], w[3]];
        for k in 0..3 {
            let jump = k == 2 && w[0] & 0xff == BLOCK;
            if w[0] & (0x100 << k) != 0 || jump {
                fields[k + 1] = int(w[k + 1]);
            }
        }
        for f in fields {
            out.extend_from_slice(&f.to_le_bytes());
        }
    }
    for k in 0..table_words * 4 {
        let start = colour_starts.get(k).copied().unwrap_or(0);
        out.extend_from_slice(&int(start).to_le_bytes());
    }
    out.extend_from_slice(&data);
    Ok(out)
}

/// Instructions interpreted per iteration of the interpreter's loop on a GPU
/// (`Options::interp_unroll`): a small kernel, quick for the drivers to compile.
pub const UNROLL: usize = 8;

/// Instructions interpreted per iteration on a software adapter. Mesa's llvmpipe (and so
/// lavapipe, on which the tests render) ends every loop of a shader once the loops together
/// have iterated 65 535 times (`LP_MAX_TGSI_LOOP_ITERATIONS`, one count shared by all the
/// loops of an invocation's SIMD group): the program's every evaluation, on the camera ray,
/// for the normal and on every shadow ray, spends its length over the unroll of that
/// budget, and once it is spent each loop stops after one pass, so the distances are wrong
/// from there on. One instruction an iteration, examples/lattice.sdf ran out of it; eight
/// (the GPU's [`UNROLL`], about half a million instructions per pixel) were not enough for
/// a field of three noises (about 1 300 instructions a distance, a pixel's hundreds of
/// evaluations); 32 lift the bound to two million, within which it renders as the
/// specialised kernel does. Each doubling doubles the kernel's compile on lavapipe.
pub const UNROLL_SOFTWARE: usize = 32;

/// The WGSL text of the interpreter and of the distance functions the kernel calls, for a
/// file of `file` registers, running `unroll` instructions an iteration of its loop; with
/// `media`, also those of glass over solids; with `calls`, the functions over the data that
/// `MESH` and `OUTLINE` call.
pub(super) fn write(file: usize, media: bool, unroll: usize, calls: Calls) -> String {
    let called = calls.meshes || calls.outlines;
    let last = file; // the scratch register
    let mut out = String::new();
    write_globals(&mut out, file, called);
    write_step(&mut out, last, called);
    if called {
        write_call(&mut out, last, calls);
    }
    write_interpret(&mut out, unroll, called);
    if calls.meshes {
        out.push_str(&super::mesh::write());
        out.push('\n');
    }
    if calls.outlines {
        out.push_str(&super::glyphs::functions("", "scene_data"));
        out.push('\n');
    }
    write_entries(&mut out, media);
    out
}

/// The interpreter's globals: its register file of `file` registers and one scratch, the
/// normal and result it shares with its callers, and, when the programs `called` the data's
/// functions, the operands of a pending call.
fn write_globals(out: &mut String, file: usize, called: bool) {
    let _ = writeln!(
        out,
        "// The distance programs, interpreted from `scene_data` (compiler/src/back/wgsl/interp.rs):\n\
         // one instruction a word (opcode, operands from registers or immediate, destination).\n\
         var<private> interp_regs: array<f32, {}>;\n\
         // The surface normal a colour field's program reads (set by `colour_field`).\n\
         var<private> interp_normal: vec3<f32>;\n\
         // The values of the last program's RETURN.\n\
         var<private> interp_result: vec3<f32>;\n\
         const INTERP_DONE: u32 = 0xffffffffu;\n",
        file + 1
    );
    if called {
        out.push_str(
            "// A call of the data's functions (MESH, OUTLINE): its operands and its word, run by\n\
             // interp_call outside the unrolled steps.\n\
             var<private> interp_args: vec3<f32>;\n\
             var<private> interp_pc: u32;\n\
             const INTERP_CALL: u32 = 0xfffffffeu;\n\n",
        );
    }
}

/// `interp_step`, which runs one instruction: its operands read, then a `case` per opcode
/// ([`write_cases`]) that writes register `last` at most; with `called`, a call of the data's
/// functions returns to the interpreter's loop.
fn write_step(out: &mut String, last: usize, called: bool) {
    let call = if called {
        format!(
            "if op == {MESH}u || op == {OUTLINE}u {{\n        interp_args = vec3<f32>(a, b, c);\n        \
             interp_pc = pc;\n        return INTERP_CALL;\n    }}\n    "
        )
    } else {
        String::new()
    };
    let _ = writeln!(
        out,
        "// Runs the instruction at pc; returns the next one's index, or INTERP_DONE after RETURN.\n\
         fn interp_step(p: vec3<f32>, pc: u32) -> u32 {{\n    \
         let w = scene_data[pc];\n    let h = u32(w.x);\n    var a = w.y;\n    \
         var b = w.z;\n    var c = w.w;\n    \
         if (h & 0x100u) != 0u {{\n        a = interp_regs[min(u32(w.y), {last}u)];\n    }}\n    \
         if (h & 0x200u) != 0u {{\n        b = interp_regs[min(u32(w.z), {last}u)];\n    }}\n    \
         if (h & 0x400u) != 0u {{\n        c = interp_regs[min(u32(w.w), {last}u)];\n    }}\n    \
         let op = h & 0xffu;\n    \
         if op == {RETURN}u {{\n        interp_result = vec3<f32>(a, b, c);\n        return INTERP_DONE;\n    }}\n    \
         {call}\
         var v = 0.0;\n    var next = pc + 1u;\n    switch op {{"
    );
    write_cases(out);
    let _ = writeln!(
        out,
        "        default: {{}}\n    }}\n    interp_regs[min(h >> {DEST_SHIFT}u, {last}u)] = v;\n    return next;\n}}\n"
    );
}

/// The cases of `interp_step`'s switch: the inputs, the copy and the block's jump, then one
/// per unary and binary operation, and the select.
fn write_cases(out: &mut String) {
    let case = |out: &mut String, op: u32, body: &str| {
        let _ = writeln!(
            out,
            "        case {op}u: {{\n            {body}\n        }}"
        );
    };
    case(out, INPUT + Axis::X as u32, "v = p.x;");
    case(out, INPUT + Axis::Y as u32, "v = p.y;");
    case(out, INPUT + Axis::Z as u32, "v = p.z;");
    case(out, NORMAL, "v = interp_normal.x;");
    case(out, NORMAL + 1, "v = interp_normal.y;");
    case(out, NORMAL + 2, "v = interp_normal.z;");
    case(out, COPY, "v = a;");
    // The block runs where !(bound >= best), as map.rs's `if`.
    case(
        out,
        BLOCK,
        "if a >= b {\n                next = u32(w.w);\n            }",
    );
    // Each operation as map.rs writes it, on the registers `a` and `b`.
    for (k, &u) in UNARIES.iter().enumerate() {
        case(
            out,
            UNARY + k as u32,
            &format!("v = {};", map::unary(u, "a")),
        );
    }
    for (k, &bin) in BINARIES.iter().enumerate() {
        case(
            out,
            BINARY + k as u32,
            &format!("v = {};", map::binary(bin, "a", "b")),
        );
    }
    case(out, SELECT, "v = select(c, b, a != 0.0);");
}

/// `interp_call`, which runs the call of the data's functions (a mesh's distance, a text's
/// outline) that `interp_step` left pending, writing register `last` at most.
fn write_call(out: &mut String, last: usize, calls: Calls) {
    let mut body = String::new();
    if calls.meshes {
        let _ = write!(
            body,
            "if (h & 0xffu) == {MESH}u {{\n        \
             let base = u32(scene_data[interp_pc + 1u].y);\n        \
             interp_regs[min(h >> {DEST_SHIFT}u, {last}u)] = mesh_distance(interp_args, base);\n        \
             return interp_pc + 2u;\n    }}\n    "
        );
    }
    if calls.outlines {
        let _ = write!(
            body,
            "if (h & 0xffu) == {OUTLINE}u {{\n        \
             let q = interp_args.xy;\n        \
             interp_regs[min(h >> {DEST_SHIFT}u, {last}u)] = text_outline(u32(interp_args.z), q);\n    }}\n    "
        );
    }
    let _ = writeln!(
        out,
        "// Runs the call at interp_pc; returns the next instruction's index.\n\
         fn interp_call() -> u32 {{\n    let h = u32(scene_data[interp_pc].x);\n    \
         {body}return interp_pc + 1u;\n}}\n"
    );
}

/// `interpret`, which runs a program from its start to its `RETURN`: `unroll` steps an
/// iteration of its loop, the pending calls between (with `called`).
fn write_interpret(out: &mut String, unroll: usize, called: bool) {
    let _ = writeln!(
        out,
        "// Runs the program that starts at `start` at p: (distance, material id, 0), or a colour.\n\
         fn interpret(p: vec3<f32>, start: u32) -> vec3<f32> {{\n    var pc = start;\n    loop {{"
    );
    // With calls, the steps run in an inner loop that a call or the end leaves.
    let (indent, stop) = if called {
        out.push_str("        loop {\n");
        ("    ", "pc >= INTERP_CALL")
    } else {
        ("", "pc == INTERP_DONE")
    };
    for _ in 0..unroll.max(1) {
        let _ = write!(
            out,
            "{indent}        pc = interp_step(p, pc);\n{indent}        if {stop} {{\n{indent}            break;\n{indent}        }}\n"
        );
    }
    if called {
        out.push_str(
            "        }\n        if pc == INTERP_DONE {\n            break;\n        }\n        pc = interp_call();\n",
        );
    }
    // The loop ends only at `RETURN`: ended elsewhere, a software adapter cut it (the
    // distance is wrong, and the frame is refused as for a cut marching loop).
    out.push_str(
        "    }\n    if pc != INTERP_DONE {\n        counters.cut += 1u;\n    }\n    return interp_result;\n}\n\n",
    );
}

/// The distance functions the kernel calls (`map`, `sdf`, and with `media` those of glass
/// over solids), each the interpreter run from its program's start in `scene_data`.
fn write_entries(out: &mut String, media: bool) {
    let entry = |out: &mut String, name: &str, slot: &str, material: bool| {
        let (ty, tail) = if material {
            ("vec2<f32>", ".xy")
        } else {
            ("f32", ".x")
        };
        let _ = writeln!(
            out,
            "fn {name}(p: vec3<f32>) -> {ty} {{\n    return interpret(p, u32(scene_data{slot})){tail};\n}}\n"
        );
    };
    out.push_str("// The scene's distance field: (signed distance, material id) at p.\n");
    entry(out, "map", "[0].x", true);
    out.push_str("// The distance alone, for marching and normals.\n");
    entry(out, "sdf", "[0].y", false);
    if media {
        entry(out, "sdf_medium", "[0].z", false);
        entry(out, "map_solid", "[0].w", true);
        entry(out, "sdf_solid", "[1].x", false);
    }
}

/// The WGSL text of `colour_field(k, p, n)` in the interpreted kernel: colour field `k`'s
/// program, found in the table of `scene_data`, run at p where the surface normal is n
/// (`interp_normal`, which its `NORMAL` instructions read). The text does not depend on the
/// fields.
pub(super) fn write_colours() -> String {
    "// The colour of colour field k at p, where the normal is n, interpreted from `scene_data`.\n\
     fn colour_field(k: u32, p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {\n    \
     let at = u32(scene_data[1].y) + k / 4u;\n    \
     interp_normal = n;\n    \
     return interpret(p, u32(scene_data[at][k % 4u]));\n}"
        .to_string()
}

#[cfg(test)]
mod tests;
