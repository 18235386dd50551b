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

/// Where frame `after`'s scene as written differs from frame `before`'s in more than numbers,
/// walking both from their roots in step: a node of another kind (`sphere` where there was a
/// `box`, `smooth_union` where there was `union`), another number of children (the children
/// both have are compared on), another text. Each place is the expression that built the node
/// in `after`, with words saying what it became; in written order. Empty when the two have one
/// structure as written: their programs then differ by a setting the kernel is specialised
/// for, or by a choice the lowering made from the numbers ([`why_not_the_same`]).
pub fn structural_changes(before: &Scene, after: &Scene) -> Vec<(crate::Span, String)> {
    use crate::scene::ir::Node;
    let (b, a) = (&before.graph, &after.graph);
    let mut out = Vec::new();
    let mut stack = match (before.root, after.root) {
        (Some(x), Some(y)) => vec![(x, y)],
        _ => return out,
    };
    let mut seen = std::collections::HashSet::new();
    while let Some((x, y)) = stack.pop() {
        if !seen.insert((x, y)) {
            continue;
        }
        let (nx, ny) = (b.node(x), a.node(y));
        if nx.kind() != ny.kind() {
            out.push((
                a.span(y),
                format!("`{}` here was `{}`", ny.kind(), nx.kind()),
            ));
            continue;
        }
        let (cx, cy) = (nx.children(), ny.children());
        if cx.len() != cy.len() {
            let what = format!(
                "this `{}` has {} parts, {} in the frame before",
                ny.kind(),
                cy.len(),
                cx.len()
            );
            out.push((a.span(y), what));
        }
        if let (Node::Text { text: tx, .. }, Node::Text { text: ty, .. }) = (nx, ny) {
            if tx != ty {
                let what = format!("this text is {ty:?}, {tx:?} in the frame before");
                out.push((a.span(y), what));
            }
        }
        // Children in reverse, so that the walk meets them in written order.
        stack.extend(cx.into_iter().zip(cy).rev());
    }
    out
}

/// Why two frames whose scenes have one structure as written ([`structural_changes`] found
/// nothing) still have two: a setting the kernel is specialised for, or the lowering.
pub fn why_not_the_same(before: &Scene, after: &Scene) -> String {
    let (x, y) = (
        Specialisation::of(&before.settings),
        Specialisation::of(&after.settings),
    );
    if x.method != y.method {
        return format!(
            "the `method` setting is \"{}\", \"{}\" in the frame before",
            y.method.name(),
            x.method.name()
        );
    }
    if x.relax != y.relax {
        return "the `relaxation` setting crosses 1 (the kernel over-relaxes or not)".into();
    }
    if x.max_depth != y.max_depth {
        return format!(
            "the `max_depth` setting is {}, {} in the frame before",
            y.max_depth, x.max_depth
        );
    }
    if x != y {
        return "a setting the kernel is specialised for changes".into();
    }
    "the scene as written keeps its structure; the lowering chose differently from the numbers \
     (whether a primitive is traced analytically, or how a part is bounded)"
        .into()
}

/// The note `sdfc check` prints at frame `k` (time `time`), whose structure differs from the
/// frame before's: where in the source the structure changes and how, or which setting or
/// choice of the lowering changed it (at the scene's root, when nothing as written did).
/// `None` for a scene without a root.
pub fn change_note(
    k: u64,
    time: f64,
    before: (&Scene, &Structure),
    after: (&Scene, &Structure),
) -> Option<crate::Diagnostic> {
    let at = format!("the structure changes at frame {k} (t = {time} s)");
    let mut changes = structural_changes(before.0, after.0).into_iter();
    let (span, what) = match changes.next() {
        Some(found) => found,
        None => {
            let why = if before.1.traced() != after.1.traced() {
                let (was, is) = if after.1.traced() {
                    ("marched", "traced analytically")
                } else {
                    ("traced analytically", "marched")
                };
                format!("the scene is {is} here, {was} in the frame before (docs/rendering.md)")
            } else {
                why_not_the_same(before.0, after.0)
            };
            (after.0.graph.span(after.0.root?), why)
        }
    };
    let mut note = crate::Diagnostic::note("N0001", at, span).with_label(what);
    for (span, what) in changes {
        note = note.with_secondary(span, what);
    }
    Some(
        note
            .with_note("the kernel is specialised again at this frame; a sequence whose structure stays the same is one kernel (docs/animation.md)"),
    )
}
