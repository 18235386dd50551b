//! The structure of a frame of an animated scene (docs/animation.md): its distance program with
//! the values of its constants erased, with the intersection method and the settings a kernel
//! is specialised for. Two frames of equal structure differ only in numbers: the constants of
//! their programs, and what the renderers read as run-time parameters (camera, lights,
//! materials, ε, step budget, L).

use crate::back::wgsl::Specialisation;
use crate::lower::Lowered;
use crate::program::{Block, Op, Reg};
use crate::scene::Scene;

/// An operand that is a constant, in a [`Structure`].
pub(crate) const CONST: Reg = Reg(u32::MAX);

/// What a frame's kernel is built from, numbers aside.
#[derive(Debug, Clone, PartialEq)]
pub struct Structure {
    /// The program's instructions but its constants, numbered among themselves.
    ops: Vec<Op>,
    blocks: Vec<Block>,
    distance: Reg,
    material: Reg,
    /// The outlines the program reads as data, compared whole: a frame whose text changes
    /// has new data, so another structure.
    outlines: Vec<std::sync::Arc<crate::program::outline::Outline>>,
    /// Whether the scene is ray traced analytically, and how many primitives it has.
    traced: Option<usize>,
    specialisation: Specialisation,
}

impl Structure {
    /// The structure of `scene`, lowered as `lowered` (its program, and whether its settings
    /// trace it, as the lowering decided). Constants are
    /// erased as operands: the lowering shares one register between equal constants, so
    /// whether two constants are shared depends on their values, not on the structure; here
    /// every operand that is a constant reads as [`CONST`], and the other registers are
    /// numbered among the instructions that are not constants.
    pub fn of(scene: &Scene, lowered: &Lowered) -> Structure {
        let program = &lowered.program;
        let mut renumber = Vec::with_capacity(program.len());
        let mut next = 0u32;
        for op in program.ops() {
            renumber.push(match op {
                Op::Const(_) => CONST,
                _ => {
                    next += 1;
                    Reg(next - 1)
                }
            });
        }
        let r = |reg: Reg| renumber[reg.0 as usize];
        let ops = program
            .ops()
            .iter()
            .filter_map(|op| match *op {
                Op::Const(_) => None,
                Op::Input(a) => Some(Op::Input(a)),
                Op::Unary(u, a) => Some(Op::Unary(u, r(a))),
                Op::Binary(b, x, y) => Some(Op::Binary(b, r(x), r(y))),
                Op::Select(c, x, y) => Some(Op::Select(r(c), r(x), r(y))),
                Op::Phi(x, y) => Some(Op::Phi(r(x), r(y))),
                Op::Mesh(m, x, y, z) => Some(Op::Mesh(m, r(x), r(y), r(z))),
                Op::Outline(k, x, y) => Some(Op::Outline(k, r(x), r(y))),
            })
            .collect();
        // A block's range, in instructions that are not constants.
        let before = |i: usize| {
            program.ops()[..i]
                .iter()
                .filter(|op| !matches!(op, Op::Const(_)))
                .count()
        };
        let blocks = program
            .blocks()
            .iter()
            .map(|b| Block {
                bound: r(b.bound),
                best: r(b.best),
                start: before(b.start),
                end: before(b.end),
                results: b.results,
            })
            .collect();
        let traced = lowered
            .traceable
            .traced(scene.settings.method)
            .map(|t| t.primitives.len());
        Structure {
            ops,
            blocks,
            distance: r(program.distance()),
            material: r(program.material()),
            outlines: program.outlines().to_vec(),
            traced,
            specialisation: Specialisation::of(&scene.settings),
        }
    }

    /// Whether the frame is ray traced analytically.
    pub fn traced(&self) -> bool {
        self.traced.is_some()
    }

    /// Instructions of the program.
    pub fn len(&self) -> usize {
        self.ops.len()
    }

    /// True for a program with no instructions.
    pub fn is_empty(&self) -> bool {
        self.ops.is_empty()
    }
}

/// How the frames of a sequence relate (what `sdfc check` reports): a still, an animation
/// whose frames differ only in numbers, or one whose structure changes.
#[derive(Debug, Clone, PartialEq)]
pub enum Kind {
    /// Nothing reads `t`: every frame is the same.
    Still,
    /// Every frame has the same structure: one kernel, numbers passed per frame.
    Numbers,
    /// The structure changes: the first frame of each run of frames of one structure (the
    /// first run starts at the sequence's first frame).
    Structure(Vec<u64>),
}

/// The runs of equal structure in a sequence of frames `(frame, structure)`: the first frame
/// of each run.
pub fn runs<'a>(frames: impl IntoIterator<Item = (u64, &'a Structure)>) -> Vec<u64> {
    let mut out = Vec::new();
    let mut last: Option<&Structure> = None;
    for (k, s) in frames {
        if last != Some(s) {
            out.push(k);
        }
        last = Some(s);
    }
    out
}
