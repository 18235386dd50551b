//! Distance semantics of the scene IR: for every node, whether its field is an exact distance,
//! a bound or an approximation, and the L that makes `f / L` a safe sphere-tracing step.
//!
//! [`analyse`] makes two passes over the node arena, whose ids put children before parents.
//! Top down, from the root: what each node's field is read for (the band of level sets that
//! an ancestor's offset, shell or blend reads, and the region that rays can reach). Bottom up:
//! the [`Facts`], with the bounding box, level-set growth and mirror symmetries that the rules
//! need, and a warning wherever a construct makes the field unreliable. Every rule, with its
//! source or derivation, is in `docs/analysis.md`.
//!
//! [`Facts::lipschitz`] is the L of docs/rendering.md: `f / L` is a distance bound (Hart 1996).
//! For a field with a known Lipschitz constant that constant is such an L; a bound has L = 1
//! even where its gradient is steeper (the ellipsoid's). Where nothing is proven (a fractal,
//! a repetition whose copies overlap their cells) L is the best guess, and
//! [`Derived::proven`] is false.

use super::ir::{Exactness, Facts, Feature, Node, Scene, Smooth};
use super::NodeId;
use crate::diagnostics::Diagnostic;
use std::collections::HashSet;

/// The largest L the renderer steps with: a larger bound is clamped (with the warning that
/// caused it), so that a scene still renders, with artefacts, within its step budget.
pub(crate) const MAX_STEP_LIPSCHITZ: f64 = 16.0;

/// A twist or bend that stretches distances by this factor or more is reported (W0003).
pub(crate) const WARN_STRETCH: f64 = 1.5;

/// A per-axis scale whose largest factor is this many times its smallest is reported (W0007).
pub(crate) const WARN_SCALE_RATIO: f64 = 10.0;

/// A repetition whose copies reach out of their cells evaluates the neighbouring cells too,
/// up to this many cells per point (counting the windows of repetitions nested in it, which
/// multiply); beyond, it evaluates only the own cell and is reported (W0005, W0006).
pub(crate) const MAX_WINDOW_CELLS: u32 = 27;

/// Slack of the geometric tests (a shape touching its cell still fits).
const TOLERANCE: f64 = 1e-9;

/// What the analysis derived for one node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Derived {
    /// Exactness, and L: `f / L` is a distance bound when `proven`.
    pub facts: Facts,
    /// A Lipschitz constant of the field where it is read (infinite when none is known).
    pub gradient: f64,
    /// Whether `f / L` is proven to be a distance bound (false: L is a best guess).
    pub proven: bool,
    /// A box around the solid (the set where the field is ≤ 0).
    pub bounds: Aabb,
    /// The solid at level `m > 0` lies within `bounds` grown by `growth·m`.
    pub growth: f64,
    /// Whether the shape is its own mirror image across the planes x = 0, y = 0, z = 0.
    pub symmetric: [bool; 3],
    /// The node that made the field inexact or raised L (for messages).
    pub cause: Option<NodeId>,
}

impl Derived {
    /// The L to divide this field by for sphere tracing: its L, at least 1 and at most
    /// [`MAX_STEP_LIPSCHITZ`] (also for an L that is not a number).
    pub fn step(&self) -> f64 {
        let l = self.facts.lipschitz;
        if l.is_nan() {
            MAX_STEP_LIPSCHITZ
        } else {
            l.clamp(1.0, MAX_STEP_LIPSCHITZ)
        }
    }
}

/// The cells a repetition evaluates around a point's own cell, when its copies reach out of
/// their cells or are off-centre: `reach[i]` cells on each side along axis i (clamped to the
/// copies that exist), and the minimum with `beyond`, a lower bound of the distance to every
/// copy outside that window (infinite when the window holds every copy). `docs/analysis.md`,
/// "Repetition", derives it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    pub reach: [u32; 3],
    pub beyond: f64,
}

impl Window {
    /// The number of cells evaluated per point.
    pub fn cells(&self) -> u32 {
        self.reach.iter().map(|r| 2 * r + 1).product()
    }
}

/// The result of [`analyse`].
#[derive(Debug, Clone)]
pub struct Analysis {
    nodes: Vec<Derived>,
    windows: Vec<Option<Window>>,
    root: Option<NodeId>,
    diagnostics: Vec<Diagnostic>,
}

impl Analysis {
    /// Everything derived for a node.
    pub fn node(&self, id: NodeId) -> &Derived {
        &self.nodes[id.0 as usize]
    }

    /// The facts of a node.
    pub fn facts(&self, id: NodeId) -> Facts {
        self.node(id).facts
    }

    /// The neighbouring cells a repetition node evaluates (`None`: only the own cell).
    pub fn window(&self, id: NodeId) -> Option<Window> {
        self.windows.get(id.0 as usize).copied().flatten()
    }

    /// What was derived for the whole scene (`None` for a scene with no objects).
    pub fn root(&self) -> Option<&Derived> {
        self.root.map(|r| self.node(r))
    }

    /// The L the renderers step with: the scene's L, at least 1 and at most
    /// [`MAX_STEP_LIPSCHITZ`].
    pub fn step_lipschitz(&self) -> f64 {
        self.root().map_or(1.0, Derived::step)
    }

    /// Warnings about constructs that make the field unreliable, in node order, one per code
    /// and source span.
    pub fn diagnostics(&self) -> &[Diagnostic] {
        &self.diagnostics
    }
}

/// The word `sdfc check` uses for an exactness.
pub fn describe(e: Exactness) -> &'static str {
    match e {
        Exactness::Exact => "exact",
        Exactness::Bound => "bound",
        Exactness::Approximate => "approximate",
    }
}

/// A short name of a node's kind, for messages: its name in the IR ([`Node::kind`]), but
/// `scale` for a per-axis scale, which the language writes `scale` too.
pub fn kind(node: &Node) -> &'static str {
    match node {
        Node::ScaleXyz { .. } => "scale",
        other => other.kind(),
    }
}

/// Derives the facts of every node of `scene` and the warnings of the nodes its root reaches.
pub fn analyse(scene: &Scene) -> Analysis {
    let usage = Usage::of(scene);
    let mut pass = Pass {
        scene,
        usage,
        nodes: Vec::with_capacity(scene.graph.len()),
        windows: vec![None; scene.graph.len()],
        copies: Vec::with_capacity(scene.graph.len()),
        diagnostics: Vec::new(),
        reported: HashSet::new(),
    };
    for id in scene.graph.ids() {
        let d = pass.derive(id);
        pass.nodes.push(d);
        let below = scene
            .graph
            .node(id)
            .children()
            .iter()
            .map(|c| pass.copies[c.0 as usize])
            .max()
            .unwrap_or(1);
        let own = pass.windows[id.0 as usize].map_or(1, |w| w.cells());
        pass.copies.push(below * own);
    }
    Analysis {
        nodes: pass.nodes,
        windows: pass.windows,
        root: scene.root,
        diagnostics: pass.diagnostics,
    }
}

/// How much a smooth combination moves the surface at most: k/4 for the quadratic smooth
/// minimum, k·ln 2 for the exponential one.
pub(crate) fn blend_reach(k: f64, variant: Smooth) -> f64 {
    let k = k.max(0.0);
    match variant {
        Smooth::Poly => k * 0.25,
        Smooth::Exp => k * std::f64::consts::LN_2,
        // hg_sdf's chamfer is at least min(a, b) - k/√2, its round min(a, b) - 0.42·k, its
        // stairs min(a, b) - k/2, where a, b ≥ 0; its columns, up to k/√2 plus a column's
        // radius, at most k.
        Smooth::Chamfer | Smooth::Round | Smooth::Stairs(_) => k,
        Smooth::Columns(_) => 2.0 * k,
    }
}

/// The factor by which a blend may steepen its operands' fields: the chamfer, round and
/// columns forms read a + b (or |(a, b)|), whose gradient is up to √2 times the larger
/// operand's when the two surfaces meet at a shallow angle; the smooth minima and the stairs
/// are no steeper than their operands (docs/analysis.md).
pub(crate) fn blend_steepness(variant: Smooth) -> f64 {
    match variant {
        Smooth::Poly | Smooth::Exp | Smooth::Stairs(_) => 1.0,
        Smooth::Chamfer | Smooth::Round | Smooth::Columns(_) => std::f64::consts::SQRT_2,
    }
}

/// The same for a feature: the engraving and the pipe read a ± b, the groove and the tongue
/// only minima and maxima of a, |b| and constants.
pub(crate) fn feature_steepness(f: Feature) -> f64 {
    match f {
        Feature::Engrave { .. } | Feature::Pipe { .. } => std::f64::consts::SQRT_2,
        Feature::Groove { .. } | Feature::Tongue { .. } => 1.0,
    }
}

/// How much a twist at `a = |rate|·r` (r: distance from the axis) stretches distances: the
/// largest singular value of [[1, a], [0, 1]], a/2 + √(1 + a²/4).
pub(crate) fn twist_stretch(a: f64) -> f64 {
    a * 0.5 + (1.0 + a * a * 0.25).sqrt()
}

/// How much a bend at `a = |rate|·r` stretches distances: 1 + a.
pub(crate) fn bend_stretch(a: f64) -> f64 {
    1.0 + a
}

/// The bottom-up pass.
struct Pass<'a> {
    scene: &'a Scene,
    usage: Usage,
    nodes: Vec<Derived>,
    windows: Vec<Option<Window>>,
    /// Per node: how many times the windows of the repetitions below it make the lowering
    /// evaluate a leaf, at most (the largest product along a path).
    copies: Vec<u32>,
    diagnostics: Vec<Diagnostic>,
    reported: HashSet<(&'static str, crate::span::Span)>,
}

/// A field that is an exact distance.
fn exact(bounds: Aabb, symmetric: [bool; 3]) -> Derived {
    Derived {
        facts: Facts {
            exactness: Exactness::Exact,
            lipschitz: 1.0,
        },
        gradient: 1.0,
        proven: true,
        bounds,
        growth: 1.0,
        symmetric,
        cause: None,
    }
}

/// The box around a profile of half-extents `half` in x and y: every z (a profile read as a
/// field of space is a prism along z).
fn profile_bounds(half: [f64; 2]) -> Aabb {
    Aabb {
        min: [-half[0], -half[1], f64::NEG_INFINITY],
        max: [half[0], half[1], f64::INFINITY],
    }
}

/// The exactness of a field that is not exact, from its L and whether that L is proven.
fn classify(lipschitz: f64, proven: bool) -> Exactness {
    if proven && lipschitz <= 1.0 {
        Exactness::Bound
    } else {
        Exactness::Approximate
    }
}

/// `d` with its exactness lowered to at most `Bound`.
fn at_most_bound(mut d: Derived) -> Derived {
    if d.facts.exactness == Exactness::Exact {
        d.facts.exactness = Exactness::Bound;
    }
    d
}

/// `d` made unproven by `cause` (L kept as the best guess).
fn unproven(mut d: Derived, cause: NodeId) -> Derived {
    if d.proven {
        d.cause = Some(cause);
    }
    d.proven = false;
    d.gradient = f64::INFINITY;
    d.facts.exactness = Exactness::Approximate;
    d
}

/// A number for a message: up to three decimals, no trailing zeros.
fn fmt(x: f64) -> String {
    crate::diagnostics::number(x, 3)
}

mod aabb;
mod derive;
mod field;
mod geometry;
mod maps;
mod regions;
#[cfg(test)]
mod tests;
mod warnings;
mod window;

pub(crate) use aabb::Aabb;
pub(crate) use geometry::{invert, TAPER_FLOOR};
pub(crate) use regions::regions;
use regions::Usage;
