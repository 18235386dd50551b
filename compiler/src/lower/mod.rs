//! Lowering of the scene IR to the distance program: one flat scalar SSA program that maps a
//! point (x, y, z) to (distance, material id).
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
//!
//! [`lower_with`] runs the optimisation passes of `docs/optimisation.md` at level 1 (the
//! default, [`lower`]): the scene is simplified (composed transforms, flattened unions,
//! primitives in their cheapest exact form), the builder folds constants, shares equal
//! instructions and drops dead ones, and unions are grouped into a bounding volume hierarchy
//! whose subtrees are skipped where they cannot be the nearest. Level 0 lowers the scene
//! literally.

mod bounds;
mod builder;
mod bvh;
mod graph;
mod instances;
mod media;
mod shapes;
mod simplify;
#[cfg(test)]
mod tests;

pub use instances::{split, Instance, Split};
pub use media::{media, Media};

use crate::diagnostics::Diagnostic;
use crate::limits::{Limit, Limits};
use crate::scene::{analysis, Graph, NodeId, Scene};
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
    /// A result of the guarded block that ends just before this instruction (after the
    /// block's other `Phi`s): `a` (defined inside the block) where the block ran, else `b`
    /// (defined before it).
    Phi(Reg, Reg),
}

impl Op {
    /// The registers this instruction reads.
    pub fn operands(&self) -> Vec<Reg> {
        match *self {
            Op::Const(_) | Op::Input(_) => Vec::new(),
            Op::Unary(_, a) => vec![a],
            Op::Binary(_, a, b) => vec![a, b],
            Op::Select(c, a, b) => vec![c, a, b],
            Op::Phi(a, b) => vec![a, b],
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
    ops: Vec<Op>,
    notes: Vec<Note>,
    blocks: Vec<Block>,
    distance: Reg,
    material: Reg,
    lipschitz: f64,
    options: LowerOptions,
}

impl Program {
    /// The options the program was lowered with (a back end that lowers part of the scene
    /// again, [`split`], uses the same).
    pub fn options(&self) -> LowerOptions {
        self.options
    }

    /// The L a renderer steps with (`f / L` is a distance bound): 1 for a program with local
    /// bounds, else the scene's L ([`Analysis::step_lipschitz`]).
    ///
    /// [`Analysis::step_lipschitz`]: crate::scene::analysis::Analysis::step_lipschitz
    pub fn lipschitz(&self) -> f64 {
        self.lipschitz
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

    /// Which instructions the registers `roots` depend on, and which blocks (a block is
    /// needed when one of its `Phi`s is; then so are its `bound` and `best`).
    pub fn live(&self, roots: &[Reg]) -> (Vec<bool>, Vec<bool>) {
        self.live_reading(roots, |i| self.ops[i].operands())
    }

    /// [`Program::live`] where instruction `i` reads `reads(i)` instead of its operands (a
    /// back end that computes some values its own way).
    pub fn live_reading(
        &self,
        roots: &[Reg],
        reads: impl Fn(usize) -> Vec<Reg>,
    ) -> (Vec<bool>, Vec<bool>) {
        let mut live = vec![false; self.ops.len()];
        let mut blocks = vec![false; self.blocks.len()];
        for r in roots {
            if let Some(l) = live.get_mut(r.0 as usize) {
                *l = true;
            }
        }
        let phi_block = self.phi_blocks();
        for i in (0..self.ops.len()).rev() {
            if !live[i] {
                continue;
            }
            for r in reads(i) {
                live[r.0 as usize] = true;
            }
            if let Some(b) = phi_block[i] {
                if !blocks[b] {
                    blocks[b] = true;
                    live[self.blocks[b].bound.0 as usize] = true;
                    live[self.blocks[b].best.0 as usize] = true;
                }
            }
        }
        (live, blocks)
    }

    /// For each instruction, the block it is a `Phi` of.
    pub fn phi_blocks(&self) -> Vec<Option<usize>> {
        let mut out = vec![None; self.ops.len()];
        for (b, block) in self.blocks.iter().enumerate() {
            for slot in &mut out[block.end..block.end + block.results] {
                *slot = Some(b);
            }
        }
        out
    }

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

/// How a scene is lowered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LowerOptions {
    /// Optimisation level: 0 lowers the scene literally (no folding, sharing, dead-code
    /// removal, scene simplification or culling); 1 runs every pass.
    pub level: u8,
    /// At level 1: whether unions get bounding-volume culling (guarded blocks). Turning it
    /// off keeps every other pass, and the same order of evaluation, so that the two
    /// programs compute bit-identical results.
    pub cull: bool,
    /// At level 1: local bounds. Each operand of the scene's unions, intersections and
    /// subtractions (and the root) whose L exceeds 1 is divided by its own L and raised to
    /// the distance to its bounding volume (`docs/analysis.md`, "Local bounds"), so that the
    /// program is a bound with L = 1 and only rays near such an operand step shorter. Off,
    /// the program is the field as written and renderers step by the scene's L everywhere.
    pub local: bool,
    /// At level 1: no rewrite that depends on the value of a number, only on the scene's
    /// structure: no identity removed (a translation by 0, `x · 1`), no subtraction of a
    /// negative constant written as an addition, no sharing of equal constants, no choice of
    /// a `Select` by its constant condition, no rotation absorbed by a box at a quarter turn
    /// or by a shape of revolution about its axis. The frames of an animation are lowered so
    /// (docs/animation.md), so that a number passing through 0 or 1 does not change the
    /// program's structure, and so the kernel. The program computes the same values.
    pub parametric: bool,
}

impl Default for LowerOptions {
    fn default() -> Self {
        LowerOptions::level(1)
    }
}

impl LowerOptions {
    /// The options of an optimisation level (culling on at level 1).
    pub fn level(level: u8) -> Self {
        LowerOptions {
            level,
            cull: level > 0,
            local: level > 0,
            parametric: false,
        }
    }

    /// The options the frames of an animation are lowered with: every pass, none that
    /// depends on a number's value ([`LowerOptions::parametric`]).
    pub fn parametric() -> Self {
        LowerOptions {
            parametric: true,
            ..LowerOptions::level(1)
        }
    }
}

/// Lowers a checked scene to its distance program, with every optimisation pass.
pub fn lower(scene: &Scene) -> Program {
    lower_with(scene, &LowerOptions::default())
}

/// Lowers a checked scene within its limits: a scene over the `expansion` limit is refused
/// before any pass walks it, and the builder counts the instructions it emits and stops at
/// the `program` limit (an E0507 error at the scene's objects), so no program larger than
/// the limit is ever built. Run before any back end or render starts.
pub fn lower_within(
    scene: &Scene,
    options: &LowerOptions,
    limits: &Limits,
) -> Result<Program, Diagnostic> {
    let Some(root) = scene.root else {
        return Ok(lower_with(scene, options));
    };
    let expansion = scene
        .graph
        .over_expanded(root, limits.get(Limit::Expansion));
    if let Some(e) = expansion {
        return Err(scene.graph.expansion_error(&e, limits));
    }
    let max = limits.get(Limit::Program);
    let cap = usize::try_from(max).unwrap_or(usize::MAX);
    let (program, over) = lower_capped(scene, options, cap);
    if !over && program.len() as u64 <= max {
        return Ok(program);
    }
    Err(Diagnostic::error(
        "E0507",
        format!("the distance program has more than {max} operations"),
        scene.graph.span(root),
    )
    .with_label("the scene's objects lower to it")
    .with_note(format!(
        "lowering stopped at the limit; this limit keeps compilation and rendering bounded; {}",
        limits.raise(Limit::Program)
    )))
}

/// Lowers a checked scene to its distance program with the given options.
pub fn lower_with(scene: &Scene, options: &LowerOptions) -> Program {
    lower_capped(scene, options, usize::MAX).0
}

/// [`lower_with`], stopping once more than `cap` instructions were emitted; the flag says
/// whether it stopped (the program is then incomplete).
fn lower_capped(scene: &Scene, options: &LowerOptions, cap: usize) -> (Program, bool) {
    match scene.root {
        _ if options.level == 0 => lower_literal(scene, options, cap),
        Some(root) => {
            let simple = simplify::simplify(&scene.graph, root, options.parametric);
            lower_simple(
                scene,
                simple.graph,
                Some(simple.root),
                &simple.origin,
                options,
                cap,
            )
        }
        None => lower_simple(scene, Graph::default(), None, &[], options, cap),
    }
}

/// Lowers the simplified graph `graph` below `root` (for the scene's camera and settings),
/// `origin` naming the original node of each simplified one.
fn lower_simple(
    scene: &Scene,
    graph: Graph,
    root: Option<NodeId>,
    origin: &[NodeId],
    options: &LowerOptions,
    cap: usize,
) -> (Program, bool) {
    let mut b = builder::Builder::capped(true, cap);
    b.parametric = options.parametric;
    let p = b.input_point();
    let mut lipschitz = 1.0;
    let (d, m) = match root {
        Some(root) => {
            // The analysis of the simplified graph, whose nodes the lowering walks.
            let simple_scene = Scene {
                graph,
                root: Some(root),
                ..scene_without_graph(scene)
            };
            let analysis = analysis::analyse(&simple_scene);
            if !options.local {
                lipschitz = analysis.step_lipschitz();
            }
            let bounds = bounds::Bounds::new(&simple_scene.graph);
            let config = graph::Config {
                cull: options.cull,
                camera: scene.camera.position,
                origin: Some(origin),
                bounds: Some(&bounds),
                optimise: true,
                analysis: Some(&analysis),
                local: options.local,
            };
            let field = graph::Lowerer::new(&simple_scene.graph, &mut b, config).node(root, p);
            (field.d, field.m)
        }
        None => (b.c(EMPTY_DISTANCE), b.c(graph::UNPAINTED)),
    };
    finish(b, d, m, lipschitz, options)
}

/// Lowers the scene as written (level 0).
fn lower_literal(scene: &Scene, options: &LowerOptions, cap: usize) -> (Program, bool) {
    let mut b = builder::Builder::capped(false, cap);
    let p = b.input_point();
    let mut lipschitz = 1.0;
    let (d, m) = match scene.root {
        Some(root) => {
            let analysis = analysis::analyse(scene);
            lipschitz = analysis.step_lipschitz();
            let config = graph::Config {
                cull: false,
                camera: scene.camera.position,
                origin: None,
                bounds: None,
                optimise: false,
                analysis: Some(&analysis),
                local: false,
            };
            let field = graph::Lowerer::new(&scene.graph, &mut b, config).node(root, p);
            (field.d, field.m)
        }
        None => (b.c(EMPTY_DISTANCE), b.c(graph::UNPAINTED)),
    };
    finish(b, d, m, lipschitz, options)
}

/// Paints what is unpainted with material 0 and ends the program.
fn finish(
    mut b: builder::Builder,
    d: Reg,
    m: Reg,
    lipschitz: f64,
    options: &LowerOptions,
) -> (Program, bool) {
    b.note("result: unpainted shapes get the default material 0".into());
    let m = b.paint(m, 0.0);
    let over = b.over();
    let program = Program {
        lipschitz,
        options: *options,
        ..b.finish(d, m)
    };
    (program, over)
}

/// Everything of a scene but its shapes (for analysing a rewritten graph).
fn scene_without_graph(scene: &Scene) -> Scene {
    Scene {
        graph: Graph::default(),
        root: None,
        materials: scene.materials.clone(),
        lights: scene.lights.clone(),
        camera: scene.camera.clone(),
        settings: scene.settings.clone(),
        origin: scene.origin,
        limits: scene.limits.clone(),
        animation: scene.animation,
    }
}
