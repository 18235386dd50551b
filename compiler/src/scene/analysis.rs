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

use super::bounds::singular_range;
use super::ir::{Combine, Exactness, Facts, Feature, Node, Scene, Smooth, V3};
use super::NodeId;
use crate::diagnostics::Diagnostic;
use crate::prim::Field as PrimField;
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

/// The top-down facts: what each node's field is read for.
#[derive(Debug)]
struct Usage {
    /// Highest level set of the node's field that an ancestor reads (offsets, shells, blends).
    margin: Vec<f64>,
    /// Where (in the node's coordinates) rays can evaluate the field.
    region: Vec<Aabb>,
    /// Whether the root reaches the node.
    reachable: Vec<bool>,
}

impl Usage {
    fn of(scene: &Scene) -> Usage {
        let n = scene.graph.len();
        let mut u = Usage {
            margin: vec![0.0; n],
            region: vec![Aabb::EMPTY; n],
            reachable: vec![false; n],
        };
        let Some(root) = scene.root else { return u };
        u.reachable[root.0 as usize] = true;
        u.region[root.0 as usize] = view_region(scene);
        for i in (0..n).rev() {
            if !u.reachable[i] {
                continue;
            }
            let node = scene.graph.node(NodeId(i as u32));
            for (child, margin, region) in down(node, u.margin[i], u.region[i]) {
                let c = child.0 as usize;
                u.reachable[c] = true;
                u.margin[c] = u.margin[c].max(margin);
                u.region[c] = u.region[c].union(region);
            }
        }
        u
    }
}

/// The region of each node, in its own coordinates, that the box `start` (in the root's
/// coordinates) reaches through the maps above the node (the union over the paths that reach
/// it; empty where none does), as the analysis carries the region rays reach. With `clip`,
/// each node's region is also cut to its own box (`scene/bounds.rs`) along the axes where
/// that is finite: the part of `start` around the node's shape.
pub(crate) fn regions(
    scene: &Scene,
    start: Aabb,
    clip: Option<&super::bounds::Bounds>,
) -> Vec<Aabb> {
    let n = scene.graph.len();
    let mut region = vec![Aabb::EMPTY; n];
    let Some(root) = scene.root else {
        return region;
    };
    let cut = |id: NodeId, r: Aabb| match clip.and_then(|b| b.get(id)) {
        Some(b) => r.intersect(Aabb {
            min: [0, 1, 2].map(|i| b.aabb.c[i] - b.aabb.h[i]),
            max: [0, 1, 2].map(|i| b.aabb.c[i] + b.aabb.h[i]),
        }),
        None => r,
    };
    region[root.0 as usize] = cut(root, start);
    for i in (0..n).rev() {
        if region[i].is_empty() {
            continue;
        }
        let node = scene.graph.node(NodeId(i as u32));
        for (child, _, r) in down(node, 0.0, region[i])
            .into_iter()
            .chain(profiles(node, region[i]))
        {
            let c = child.0 as usize;
            region[c] = region[c].union(cut(child, r));
        }
    }
    region
}

/// The region the profiles of a solid made of profiles are read in (their plane z = 0): an
/// extrusion's and a loft's at (x, y); a revolution's and a screw's at the distance from the
/// y axis (less the revolution's offset) and y.
fn profiles(node: &Node, r: Aabb) -> Vec<(NodeId, f64, Aabb)> {
    let flat = |r: Aabb| Aabb {
        min: [r.min[0], r.min[1], 0.0],
        max: [r.max[0], r.max[1], 0.0],
    };
    let around = |r: Aabb, offset: f64| Aabb {
        min: [-offset, r.min[1], 0.0],
        max: [r.radius(0, 2) - offset, r.max[1], 0.0],
    };
    if r.is_empty() {
        return Vec::new();
    }
    match node {
        Node::Extrude { child, .. } => vec![(*child, 0.0, flat(r))],
        Node::Loft { bottom, top, .. } => vec![(*bottom, 0.0, flat(r)), (*top, 0.0, flat(r))],
        Node::Revolve { offset, child } => vec![(*child, 0.0, around(r, *offset))],
        Node::Screw { child, .. } => vec![(*child, 0.0, around(r, 0.0))],
        // Within the farthest the region reaches from the path's box, either way.
        Node::Sweep { path, child, .. } => {
            let (lo, hi) = path.0.aabb();
            let m = [0, 1, 2]
                .map(|i| (r.max[i] - lo[i]).abs().max((hi[i] - r.min[i]).abs()))
                .iter()
                .map(|x| x * x)
                .sum::<f64>()
                .sqrt();
            vec![(
                *child,
                0.0,
                Aabb {
                    min: [-m, -m, 0.0],
                    max: [m, m, 0.0],
                },
            )]
        }
        _ => Vec::new(),
    }
}

/// Where rays can go: within `max_dist` of the camera for camera rays, of a hit for each
/// bounce and each shadow ray towards a directional light, and up to every point light.
fn view_region(scene: &Scene) -> Aabb {
    let s = &scene.settings;
    let secondary = scene
        .materials
        .iter()
        .any(|m| m.reflects() || m.transparency > 0.0);
    let legs = if secondary {
        s.max_depth as f64 + 2.0
    } else {
        2.0
    };
    let reach = s.max_dist.max(0.0) * legs;
    let mut region = Aabb::centred([reach; 3]).translate(scene.camera.position);
    for l in &scene.lights {
        if let super::ir::Light::Point { position, .. } = l {
            region = region.union(Aabb {
                min: *position,
                max: *position,
            });
        }
    }
    region
}

/// The children of a node with the margin and region they are read with.
fn down(node: &Node, m: f64, r: Aabb) -> Vec<(NodeId, f64, Aabb)> {
    match node {
        Node::Combine { children, .. } => children.iter().map(|&c| (c, m, r)).collect(),
        Node::SmoothCombine {
            k, variant, a, b, ..
        } => {
            // The blend reads each operand wherever it is within k of the other, and the
            // surface lies where the smaller one is below the reach.
            let m = m + k.max(0.0) + blend_reach(*k, *variant);
            vec![(*a, m, r), (*b, m, r)]
        }
        Node::Feature { op, a, b } => {
            // The feature is shaped by both fields up to its size from either surface.
            let m = m + op.reach();
            vec![(*a, m, r), (*b, m, r)]
        }
        Node::Translate { offset, child } => vec![(*child, m, r.translate(offset.map(|x| -x)))],
        Node::Rotate { matrix, child } => vec![(*child, m, r.transform(matrix, true))],
        Node::Scale { factor, child } => vec![(*child, m / factor, r.scale([1.0 / factor; 3]))],
        Node::ScaleXyz { factors, child } => {
            let smin = factors.iter().fold(f64::INFINITY, |a, f| a.min(f.abs()));
            vec![(*child, m / smin, r.scale(factors.map(|f| 1.0 / f)))]
        }
        Node::Repeat {
            period,
            count,
            child,
        } => vec![(*child, m, repeat_region(r, *period, *count))],
        Node::Mirror { axes, child } => vec![(*child, m, fold(r, *axes))],
        Node::Twist { child, .. } | Node::RepeatPolar { child, .. } => {
            vec![(*child, m, around(r, 1))]
        }
        Node::Wrap { radius, child } => vec![(*child, m, unwrap_region(r, *radius))],
        Node::Shear { matrix, child } => {
            let (smin, _) = singular_range(matrix);
            let inverse = invert(matrix).unwrap_or(IDENTITY);
            vec![(*child, m / smin.max(1e-12), r.transform(&inverse, false))]
        }
        Node::Taper { rate, child } => vec![(*child, m, untaper_region(r, *rate))],
        Node::Morph { a, b, .. } => vec![(*a, m, r), (*b, m, r)],
        Node::Bend { child, .. } => vec![(*child, m, around(r, 2))],
        Node::Round { radius, child } => vec![(*child, m + radius, r)],
        Node::Shell { half, child } => vec![(*child, m + half, r)],
        Node::Elongate { half, child } => vec![(
            *child,
            m,
            r.map(|i, lo, hi| (unstretch(lo, half[i]), unstretch(hi, half[i]))),
        )],
        Node::Paint { child, .. } => vec![(*child, m, r)],
        _ => Vec::new(),
    }
}

/// The identity matrix.
const IDENTITY: [V3; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// The inverse of a 3×3 matrix (rows), or `None` when it is singular.
pub(crate) fn invert(m: &[V3; 3]) -> Option<[V3; 3]> {
    let c = |i: usize, j: usize| {
        let (a, b) = ((i + 1) % 3, (i + 2) % 3);
        let (x, y) = ((j + 1) % 3, (j + 2) % 3);
        m[a][x] * m[b][y] - m[a][y] * m[b][x]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    if det.abs() < 1e-12 || !det.is_finite() {
        return None;
    }
    // The inverse is the transposed cofactor matrix over the determinant.
    Some([0, 1, 2].map(|i| [0, 1, 2].map(|j| c(j, i) / det)))
}

/// The region a wrap's child is read in: u = R·angle within ±π·R, y kept, w = R − ρ for ρ
/// from 0 to the region's farthest distance from the y axis.
fn unwrap_region(r: Aabb, radius: f64) -> Aabb {
    let rho = r.radius(0, 2);
    Aabb {
        min: [-std::f64::consts::PI * radius, r.min[1], radius - rho],
        max: [std::f64::consts::PI * radius, r.max[1], radius],
    }
}

/// The region a taper's child is read in: (x, z) divided by 1 + rate·y, which is at least
/// the smallest positive factor over the region's heights (clamped as the lowering clamps).
fn untaper_region(r: Aabb, rate: f64) -> Aabb {
    let s = taper_floor(rate, r.min[1], r.max[1]);
    r.map(|i, lo, hi| if i == 1 { (lo, hi) } else { (lo / s, hi / s) })
        .union(r)
}

/// The smallest factor 1 + rate·y a taper divides by over heights y0 … y1: the factor there,
/// but never below [`TAPER_FLOOR`] (where the factor falls below it the lowering clamps it).
pub(crate) fn taper_floor(rate: f64, y0: f64, y1: f64) -> f64 {
    let s = (1.0 + rate * y0).min(1.0 + rate * y1);
    if s.is_finite() {
        s.max(TAPER_FLOOR)
    } else {
        TAPER_FLOOR
    }
}

/// The smallest scale factor of a taper: below it (the cross-section shrunk to a point and
/// beyond, where the taper folds) the factor is clamped.
pub(crate) const TAPER_FLOOR: f64 = 1e-3;

/// The angle ±α about y, in the sense of `rotate_y`, within which a box lies; π when it
/// reaches the y axis or beyond (on the side x ≤ 0).
pub(crate) fn angular_half_extent(b: &Aabb) -> f64 {
    if b.is_empty() || !(b.min[0] > 0.0) || !b.is_bounded() {
        return std::f64::consts::PI;
    }
    let mut alpha = 0.0f64;
    for x in [b.min[0], b.max[0]] {
        for z in [b.min[2], b.max[2]] {
            alpha = alpha.max(z.atan2(x).abs());
        }
    }
    alpha
}

/// The copies a polar repetition of `count` copies evaluates around the point's own sector,
/// for a child within ±`alpha` of angle 0: `reach[0]` sectors on each side, and `beyond` the
/// factor sin γ with γ = (2r + 1)·π/count − α, so that ρ·sin γ (ρ the distance from the
/// axis) is a lower bound of the distance to every copy outside the window (infinite when
/// the window holds every copy). `docs/analysis.md`, "Polar repetition", derives it.
pub(crate) fn polar_window(count: u32, alpha: f64) -> Window {
    let n = f64::from(count);
    let sector = std::f64::consts::PI / n;
    // The least r ≥ 1 with (2r + 1)·π/n > α, plus a sliver, so that γ is not 0.
    let mut r = ((alpha / sector - 1.0) * 0.5).floor() + 1.0;
    r = r.max(1.0);
    if (2.0 * r + 1.0) * sector - alpha < 1e-6 {
        r += 1.0;
    }
    if 2.0 * r + 1.0 >= n {
        return Window {
            reach: [(count / 2).max(1), 0, 0],
            beyond: f64::INFINITY,
        };
    }
    let gamma = ((2.0 * r + 1.0) * sector - alpha).min(std::f64::consts::FRAC_PI_2);
    Window {
        reach: [r as u32, 0, 0],
        beyond: gamma.sin(),
    }
}

/// x − clamp(x, −h, h): the coordinate an elongation reads its child at.
fn unstretch(x: f64, h: f64) -> f64 {
    x - x.clamp(-h, h)
}

/// The region a repetition's child is read in.
fn repeat_region(r: Aabb, period: V3, count: Option<V3>) -> Aabb {
    r.map(|i, lo, hi| {
        let s = period[i];
        if s == 0.0 {
            return (lo, hi);
        }
        let cell = (-s * 0.5, s * 0.5);
        match count {
            None => cell,
            Some(n) => {
                let reach = s * (n[i] - 1.0) * 0.5;
                (cell.0.min(lo + reach), cell.1.max(hi - reach))
            }
        }
    })
}

/// The region folded by a mirror.
fn fold(r: Aabb, axes: [bool; 3]) -> Aabb {
    r.map(|i, lo, hi| {
        if !axes[i] || lo >= 0.0 {
            (lo, hi)
        } else if hi <= 0.0 {
            (-hi, -lo)
        } else {
            (0.0, hi.max(-lo))
        }
    })
}

/// The region a rotation about axis `keep` can move `r` to: a square around that axis.
fn around(r: Aabb, keep: usize) -> Aabb {
    let (a, b) = match keep {
        1 => (0, 2),
        _ => (0, 1),
    };
    let rho = r.radius(a, b);
    r.map(|i, lo, hi| if i == keep { (lo, hi) } else { (-rho, rho) })
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

impl Pass<'_> {
    fn get(&self, id: NodeId) -> Derived {
        self.nodes[id.0 as usize]
    }

    fn derive(&mut self, id: NodeId) -> Derived {
        let node = self.scene.graph.node(id);
        match node {
            Node::Sphere { radius } => exact(Aabb::centred([*radius; 3]), [true; 3]),
            Node::Box { half } | Node::RoundBox { half, .. } => {
                exact(Aabb::centred(*half), [true; 3])
            }
            Node::Plane { normal, height } => {
                exact(plane_bounds(*normal, *height), normal.map(|n| n == 0.0))
            }
            Node::Torus { major, minor } => exact(
                Aabb::centred([major + minor, *minor, major + minor]),
                [true; 3],
            ),
            Node::Cylinder {
                radius,
                half_height,
            } => exact(Aabb::centred([*radius, *half_height, *radius]), [true; 3]),
            Node::Capsule {
                radius,
                half_height,
            } => exact(
                Aabb::centred([*radius, half_height + radius, *radius]),
                [true; 3],
            ),
            Node::Cone {
                radius,
                half_height,
            } => exact(
                Aabb::centred([*radius, *half_height, *radius]),
                [true, false, true],
            ),
            Node::Ellipsoid { radii } => ellipsoid(*radii),
            Node::Rect { half } => exact(profile_bounds(*half), [true; 3]),
            Node::Prim { prim, args } => {
                let e = (prim.extent)(args);
                let mut bounds = Aabb {
                    min: e.min,
                    max: e.max,
                };
                if prim.profile {
                    (bounds.min[2], bounds.max[2]) = (f64::NEG_INFINITY, f64::INFINITY);
                }
                let d = exact(bounds, e.symmetric);
                match prim.field {
                    PrimField::Exact => d,
                    PrimField::Unproven => unproven(d, id),
                }
            }
            Node::Mesh { mesh } => {
                let (min, max) = mesh.0.aabb();
                exact(Aabb { min, max }, [false; 3])
            }
            Node::Bezier {
                a,
                control,
                b,
                radius,
            } => {
                let lo = [0, 1].map(|i| a[i].min(control[i]).min(b[i]) - radius);
                let hi = [0, 1].map(|i| a[i].max(control[i]).max(b[i]) + radius);
                let bounds = Aabb {
                    min: [lo[0], lo[1], f64::NEG_INFINITY],
                    max: [hi[0], hi[1], f64::INFINITY],
                };
                exact(bounds, [false, false, true])
            }
            Node::Polygon { points } => {
                let mut b = Aabb::EMPTY;
                for q in points {
                    b = b.union(Aabb {
                        min: [q[0], q[1], f64::NEG_INFINITY],
                        max: [q[0], q[1], f64::INFINITY],
                    });
                }
                exact(b, [false, false, true])
            }
            Node::Text { outline, .. } => {
                let (lo, hi) = outline.bounds();
                let b = Aabb {
                    min: [lo[0], lo[1], f64::NEG_INFINITY],
                    max: [hi[0], hi[1], f64::INFINITY],
                };
                exact(b, [false, false, true])
            }
            Node::Extrude {
                half_height,
                round,
                child,
            } => {
                let mut d = self.get(*child);
                if *round > 0.0 {
                    // The profile shrunk by `round` is a bound outside its solid.
                    d = at_most_bound(d);
                }
                // |(a, b)| of a field a of the plane and b = |z| - h: as steep as the steeper.
                d.facts.lipschitz = d.facts.lipschitz.max(1.0);
                d.gradient = d.gradient.max(1.0);
                d.bounds.min[2] = -half_height;
                d.bounds.max[2] = *half_height;
                d.symmetric[2] = true;
                d
            }
            Node::Revolve { offset, child } => {
                let mut d = self.get(*child);
                let c = d.bounds;
                // The profile is read at x = r - offset for r ≥ 0; a part of it at smaller x
                // is never read, but may be nearer than the part that is: then a bound.
                let read_only = c.min[0] >= -offset || (d.symmetric[0] && *offset == 0.0);
                if !read_only {
                    d = at_most_bound(d);
                }
                let r = (c.max[0] + offset).max(0.0);
                d.bounds = if c.max[0] + offset < 0.0 || c.is_empty() {
                    Aabb::EMPTY
                } else {
                    Aabb {
                        min: [-r, c.min[1], -r],
                        max: [r, c.max[1], r],
                    }
                };
                d.symmetric = [true, d.symmetric[1], true];
                d
            }
            Node::Loft {
                half_height,
                spread,
                bottom,
                top,
            } => self.loft(id, *half_height, *spread, *bottom, *top),
            Node::Screw {
                pitch,
                half_height,
                inner,
                floor,
                child,
            } => self.screw(id, *pitch, *half_height, *inner, *floor, *child),
            Node::Sweep {
                path,
                inner,
                extent,
                folds,
                child,
            } => self.sweep(id, &path.0, *folds || inner < extent, *extent, *child),
            Node::Feature { op, a, b } => self.feature(id, *op, *a, *b),
            Node::Combine { op, children } => self.combine(*op, children),
            Node::SmoothCombine {
                op,
                k,
                variant,
                a,
                b,
            } => self.smooth(id, *op, *k, *variant, *a, *b),
            Node::Translate { offset, child } => {
                let mut d = self.get(*child);
                d.bounds = d.bounds.translate(*offset);
                d.symmetric = [0, 1, 2].map(|i| d.symmetric[i] && offset[i] == 0.0);
                d
            }
            Node::Rotate { matrix, child } => self.rotate(matrix, *child),
            Node::Scale { factor, child } => {
                let mut d = self.get(*child);
                d.bounds = d.bounds.scale([*factor; 3]);
                d
            }
            Node::ScaleXyz { factors, child } => self.scale_xyz(id, *factors, *child),
            Node::Repeat {
                period,
                count,
                child,
            } => self.repeat(id, *period, *count, *child),
            Node::Mirror { axes, child } => self.mirror(*axes, *child),
            Node::RepeatPolar { count, child, .. } => self.polar(id, *count, *child),
            Node::Wrap { radius, child } => self.wrap(id, *radius, *child),
            Node::Shear { matrix, child } => self.shear(id, matrix, *child),
            Node::Taper { rate, child } => self.taper(id, *rate, *child),
            Node::Morph { a, b, .. } => {
                // A convex combination of L-Lipschitz fields is L-Lipschitz, so f / L is a
                // bound of its own zero set; the solid lies where either operand's does.
                let (da, db) = (self.get(*a), self.get(*b));
                let mut d = merge(&[da, db]);
                d.facts.exactness = Exactness::Approximate;
                if d.gradient.is_finite() {
                    d.facts.lipschitz = d.facts.lipschitz.max(d.gradient);
                    d.facts.exactness = classify(d.facts.lipschitz, d.proven);
                } else if d.proven {
                    d = unproven(d, id);
                }
                d.bounds = da.bounds.union(db.bounds);
                d
            }
            Node::Twist { rate, child } => self.distort(id, *rate, *child, 1),
            Node::Bend { rate, child } => self.distort(id, *rate, *child, 2),
            Node::Round { radius, child } => self.offset(id, *child, *radius),
            Node::Shell { half, child } => self.offset(id, *child, *half),
            Node::Elongate { half, child } => {
                let mut d = at_most_bound(self.get(*child));
                d.bounds = d.bounds.map(|i, lo, hi| (lo - half[i], hi + half[i]));
                d
            }
            Node::Paint { child, .. } => self.get(*child),
            Node::Field { f, lipschitz, .. } => self.field(id, f, *lipschitz),
        }
    }

    /// A user field: its declared L, or the one derived from its expression (the shapes it
    /// reads contributing their own proven constants), or nothing proven. Its solid lies in
    /// the box its expression proves by interval arithmetic ([`field::solid_box`]), with the
    /// shapes it reads bounded by their boxes: outside a shape's box its field is above 0,
    /// and an exact one's at least the distance to the box.
    fn field(&self, id: NodeId, f: &super::field::FieldFn, declared: Option<f64>) -> Derived {
        let (min, max) = field::solid_box(f, |s, q| {
            let c = self.get(s);
            let b = c.bounds;
            if b.is_empty() {
                return f64::MIN_POSITIVE;
            }
            let gap = (0..3)
                .map(|i| {
                    (b.min[i] - q[i][1])
                        .max(q[i][0] - b.max[i])
                        .max(0.0)
                        .powi(2)
                })
                .sum::<f64>()
                .sqrt();
            match gap > 0.0 {
                true if c.proven && c.facts.exactness == Exactness::Exact => gap,
                true => f64::MIN_POSITIVE,
                false => f64::NEG_INFINITY,
            }
        });
        let mut d = exact(Aabb { min, max }, [false; 3]);
        let l = declared.unwrap_or_else(|| {
            field::lipschitz(f, |s| {
                let c = self.get(s);
                if c.proven {
                    c.gradient
                } else {
                    f64::INFINITY
                }
            })
        });
        if !l.is_finite() {
            return unproven(d, id);
        }
        d.facts.lipschitz = l;
        d.gradient = l;
        d.facts.exactness = classify(l, true);
        if d.facts.exactness != Exactness::Exact {
            d.cause = Some(id);
        }
        d
    }

    /// Union, intersection, subtraction: L is the largest of the children's (a min or max of
    /// L-Lipschitz fields is L-Lipschitz); exact only outside (union) or inside
    /// (intersection), so a bound.
    fn combine(&mut self, op: Combine, children: &[NodeId]) -> Derived {
        let ds: Vec<Derived> = children.iter().map(|&c| self.get(c)).collect();
        let Some(first) = ds.first() else {
            return exact(Aabb::EMPTY, [true; 3]);
        };
        if ds.len() == 1 {
            return *first;
        }
        let mut d = merge(&ds);
        d.bounds = match op {
            Combine::Union => ds.iter().fold(Aabb::EMPTY, |b, c| b.union(c.bounds)),
            Combine::Intersect => ds
                .iter()
                .skip(1)
                .fold(first.bounds, |b, c| b.intersect(c.bounds)),
            Combine::Subtract => first.bounds,
        };
        d
    }

    /// Smooth combinations: the gradient is a convex combination of the children's, so the
    /// Lipschitz constant is the larger one, and a Lipschitz field divided by its constant is
    /// a bound (Hart 1996). The surface moves by at most `blend_reach`.
    fn smooth(
        &mut self,
        id: NodeId,
        op: Combine,
        k: f64,
        v: Smooth,
        a: NodeId,
        b: NodeId,
    ) -> Derived {
        // A radius of 0 is the plain combination (an animated radius passing through 0).
        if k <= 0.0 {
            return self.combine(op, &[a, b]);
        }
        let (da, db) = (self.get(a), self.get(b));
        let mut d = merge(&[da, db]);
        d.facts.exactness = Exactness::Approximate;
        let reach = blend_reach(k, v);
        if d.gradient.is_finite() {
            let steep = blend_steepness(v);
            d.gradient *= steep;
            d.facts.lipschitz = (d.facts.lipschitz * steep).max(d.gradient);
            d.facts.exactness = classify(d.facts.lipschitz, d.proven);
        } else if d.proven {
            d = unproven(d, id);
        }
        d.bounds = match op {
            Combine::Union => da
                .bounds
                .grow(da.growth * reach)
                .union(db.bounds.grow(db.growth * reach)),
            Combine::Intersect => da.bounds.intersect(db.bounds),
            Combine::Subtract => da.bounds,
        };
        let size = da.bounds.half_min().min(db.bounds.half_min());
        if v == Smooth::Exp && reach > size {
            self.warn_exp(id, op, k, reach, size);
        }
        d
    }

    /// A feature of `a` along `b`'s surface: like a blend, L is the operands' times the
    /// feature's steepness; the solid lies within `a`'s, grown by what stands out of it.
    fn feature(&mut self, id: NodeId, f: Feature, a: NodeId, b: NodeId) -> Derived {
        let (da, db) = (self.get(a), self.get(b));
        let mut d = merge(&[da, db]);
        d.facts.exactness = Exactness::Approximate;
        if d.gradient.is_finite() {
            let steep = feature_steepness(f);
            d.gradient *= steep;
            d.facts.lipschitz = (d.facts.lipschitz * steep).max(d.gradient);
            d.facts.exactness = classify(d.facts.lipschitz, d.proven);
        } else if d.proven {
            d = unproven(d, id);
        }
        d.bounds = da.bounds.grow(da.growth * f.outset());
        d
    }

    fn rotate(&self, matrix: &[V3; 3], child: NodeId) -> Derived {
        let mut d = self.get(child);
        let c = d.symmetric;
        d.bounds = d.bounds.transform(matrix, false);
        // A mirror plane of the child with normal e_j becomes one with normal M·e_j.
        d.symmetric =
            [0, 1, 2].map(|i| (0..3).any(|j| c[j] && (matrix[i][j].abs() - 1.0).abs() < 1e-12));
        d
    }

    /// `f(p / s)·min|s|`: a bound (the point map stretches by at most 1 / min|s|), no steeper
    /// than the child; it underestimates by up to max|s| / min|s|.
    fn scale_xyz(&mut self, id: NodeId, s: V3, child: NodeId) -> Derived {
        let mut d = at_most_bound(self.get(child));
        let smin = s.iter().fold(f64::INFINITY, |a, f| a.min(f.abs()));
        let smax = s.iter().fold(0.0f64, |a, f| a.max(f.abs()));
        let ratio = smax / smin;
        d.bounds = d.bounds.scale(s);
        d.growth *= ratio;
        if ratio >= WARN_SCALE_RATIO {
            self.warn_scale(id, s, ratio);
        }
        d
    }

    /// Domain repetition evaluates only the copy in the point's own cell. That is the nearest
    /// copy, and the field keeps its facts (at every level, so offsets above need no margin),
    /// when the child fits in its cell and is symmetric about the cell's centre on every
    /// repeated axis.
    fn repeat(&mut self, id: NodeId, period: V3, count: Option<V3>, child: NodeId) -> Derived {
        let c = self.get(child);
        let extent = c.bounds;
        let mut d = c;
        let mut strict = true;
        let (mut overlap, mut off_centre) = (None, None);
        for (i, s, n) in repeated_axes(&extent, period, count) {
            let (lo, hi, half) = (extent.min[i], extent.max[i], s * 0.5);
            strict &= lo > -half && hi < half;
            if lo < -half - TOLERANCE || hi > half + TOLERANCE {
                overlap = overlap.or(Some(i));
            } else if !c.symmetric[i] {
                off_centre = off_centre.or(Some(i));
            }
            let reach = s * (n - 1.0) * 0.5;
            (d.bounds.min[i], d.bounds.max[i]) = (c.bounds.min[i] - reach, c.bounds.max[i] + reach);
        }
        if overlap.is_some() || off_centre.is_some() {
            // The neighbouring cells, far enough that the levels ancestors read stay right.
            // Windows nested in windows multiply: their product is bounded too.
            let margin = self.usage.margin[id.0 as usize];
            let below = self.copies[child.0 as usize];
            if let Some(w) = window(&extent, c.symmetric, period, count, margin) {
                if w.cells() * below <= MAX_WINDOW_CELLS {
                    self.windows[id.0 as usize] = Some(w);
                    return at_most_bound(d);
                }
            }
        }
        if let Some(axis) = overlap {
            self.warn_overlap(id, axis, extent.min[axis], extent.max[axis], period[axis]);
            unproven(d, id)
        } else if let Some(axis) = off_centre {
            self.warn_off_centre(id, axis);
            unproven(d, id)
        } else if strict {
            d
        } else {
            at_most_bound(d)
        }
    }

    /// `f(|x|, y, z)`: the child where x ≥ 0, mirrored. A bound whatever the child (the
    /// mirrored copy is never nearer than the child's own part); exact when the child lies on
    /// the kept side or is symmetric already.
    fn mirror(&self, axes: [bool; 3], child: NodeId) -> Derived {
        let c = self.get(child);
        let mut d = c;
        for i in (0..3).filter(|&i| axes[i]) {
            if !(c.bounds.min[i] >= 0.0 || c.symmetric[i] || c.bounds.is_empty()) {
                d = at_most_bound(d);
            }
            d.symmetric[i] = true;
            if c.bounds.max[i] < 0.0 {
                d.bounds = Aabb::EMPTY;
            } else if !d.bounds.is_empty() {
                (d.bounds.min[i], d.bounds.max[i]) = (-c.bounds.max[i], c.bounds.max[i]);
            }
        }
        d
    }

    /// Twist (about y, `keep` = 1) and bend (about z, `keep` = 2): the point map stretches by
    /// at most σ(|rate|·ρ), ρ the largest distance from the axis of the child's surface (the
    /// levels its ancestors read, within the region rays reach); so `f/(σ·L)` is a bound.
    fn distort(&mut self, id: NodeId, rate: f64, child: NodeId, keep: usize) -> Derived {
        let c = self.get(child);
        let (a, b) = if keep == 1 { (0, 2) } else { (0, 1) };
        let i = id.0 as usize;
        let extent = c.bounds.grow(c.growth * self.usage.margin[i]);
        let region = down(self.scene.graph.node(id), 0.0, self.usage.region[i])
            .first()
            .map_or(Aabb::ALL, |x| x.2);
        let seen = if self.usage.reachable[i] {
            extent.intersect(region)
        } else {
            extent
        };
        let rho = seen.radius(a, b);
        if rate == 0.0 || c.bounds.is_empty() {
            return c;
        }
        let x = rate.abs() * rho;
        let sigma = if keep == 1 {
            twist_stretch(x)
        } else {
            bend_stretch(x)
        };
        let mut d = c;
        let rb = c.bounds.radius(a, b);
        d.bounds = c
            .bounds
            .map(|j, lo, hi| if j == keep { (lo, hi) } else { (-rb, rb) });
        d.symmetric = [false, false, keep == 2 && c.symmetric[2]];
        d.growth *= sigma;
        d.facts.lipschitz *= sigma;
        d.gradient *= sigma;
        d.facts.exactness = classify(d.facts.lipschitz, d.proven);
        if sigma > 1.0 && d.proven {
            d.cause = Some(id);
        }
        let what = if keep == 1 { "twist" } else { "bend" };
        if !extent.radius(a, b).is_finite() {
            self.warn_unbounded(id, what, sigma, rho);
        } else if sigma >= WARN_STRETCH {
            self.warn_stretch(id, what, rate, rho, sigma);
        }
        d
    }

    /// Polar repetition: the copies in the point's sector and its neighbours, enough of them
    /// that every copy left out is farther than ρ·sin γ ([`polar_window`]); the minimum with
    /// that is a bound, exact wherever the nearest copy is in the window and nearer than it.
    /// The window counts towards [`MAX_WINDOW_CELLS`] like a repetition's.
    fn polar(&mut self, id: NodeId, count: u32, child: NodeId) -> Derived {
        let c = self.get(child);
        if count <= 1 || c.bounds.is_empty() {
            return c;
        }
        let margin = self.usage.margin[id.0 as usize];
        let extent = c.bounds.grow(c.growth * margin);
        let w = polar_window(count, angular_half_extent(&extent));
        let mut d = at_most_bound(c);
        let rb = c.bounds.radius(0, 2);
        d.bounds = c
            .bounds
            .map(|j, lo, hi| if j == 1 { (lo, hi) } else { (-rb, rb) });
        d.symmetric = [false, c.symmetric[1], false];
        let cells = w.cells().min(count);
        if cells * self.copies[child.0 as usize] > MAX_WINDOW_CELLS {
            self.warn_polar(id, count, cells);
            return unproven(d, id);
        }
        self.windows[id.0 as usize] = Some(w);
        d
    }

    /// Wrap: the map from space to the child stretches arcs at distance ρ from the axis by
    /// R/ρ; over the child's surface (w ≤ w_max, so ρ ≥ R − w_max) that is at most
    /// σ = R/(R − w_max), and `f/(σ·L)` is a bound. A child reaching the axis (w_max ≥ R)
    /// or longer than the circle (|u| > π·R) folds (W0014).
    fn wrap(&mut self, id: NodeId, radius: f64, child: NodeId) -> Derived {
        let c = self.get(child);
        if c.bounds.is_empty() {
            return c;
        }
        let extent = c.bounds.grow(c.growth * self.usage.margin[id.0 as usize]);
        let mut d = c;
        let rho = (radius - c.bounds.min[2])
            .abs()
            .max((radius - c.bounds.max[2]).abs());
        d.bounds = Aabb {
            min: [-rho, c.bounds.min[1], -rho],
            max: [rho, c.bounds.max[1], rho],
        };
        d.symmetric = [true, c.symmetric[1], false];
        let inner = radius - extent.max[2];
        // The shape itself, not its levels that ancestors read: a bar of exactly the circle's
        // length closes, and its offsets (a `round` above) meet at the seam as its faces do.
        let half = std::f64::consts::PI * radius * (1.0 + 1e-12) + TOLERANCE;
        let long = c.bounds.min[0] < -half || c.bounds.max[0] > half;
        if !(inner > 0.0) || long {
            let how = if long {
                format!(
                    "the shape spans {} … {} on x, more than the circle's length 2π·{} = {}",
                    fmt(c.bounds.min[0]),
                    fmt(c.bounds.max[0]),
                    fmt(radius),
                    fmt(2.0 * std::f64::consts::PI * radius)
                )
            } else {
                format!(
                    "the shape reaches z = {}, across the wrap's axis at z = {}",
                    fmt(extent.max[2]),
                    fmt(radius)
                )
            };
            self.warn_fold(
                id,
                "wrap",
                how,
                "wrap a shape that lies within −π·radius … π·radius on x and below z = radius",
            );
            return unproven(d, id);
        }
        let sigma = (radius / inner).max(1.0);
        d.growth *= sigma;
        d.facts.lipschitz *= sigma;
        d.gradient *= sigma;
        d.facts.exactness = classify(d.facts.lipschitz, d.proven);
        if sigma > 1.0 && d.proven {
            d.cause = Some(id);
        }
        d
    }

    /// Shear S: the lowering multiplies f(S⁻¹p) by σmin(S), which makes it a bound with the
    /// child's L (the map S⁻¹ stretches by at most 1/σmin); it underestimates by up to
    /// σmax/σmin, reported like a scale's ratio (W0007).
    fn shear(&mut self, id: NodeId, matrix: &[V3; 3], child: NodeId) -> Derived {
        let c = self.get(child);
        let mut d = at_most_bound(c);
        let (smin, smax) = singular_range(matrix);
        d.bounds = c.bounds.transform(matrix, false);
        d.symmetric = [false; 3];
        let ratio = smax / smin;
        d.growth *= ratio;
        if ratio >= WARN_SCALE_RATIO {
            self.warn_scale(id, [smin, smax, smax], ratio);
        }
        d
    }

    /// Taper: f(q)·s with q = (x/s, y, z/s), s = 1 + rate·y. Near the surface the gradient is
    /// s·Jᵀ∇f, and s·J is diag(1, s, 1) plus a column of norm |rate|·ρ_q (ρ_q the child's
    /// distance from the y axis), so σ = max(1, s_max) + |rate|·ρ_q; `f/(σ·L)` is a bound
    /// there. Where s ≤ 0 over the child's heights the taper folds (W0014).
    fn taper(&mut self, id: NodeId, rate: f64, child: NodeId) -> Derived {
        let c = self.get(child);
        if rate == 0.0 || c.bounds.is_empty() {
            return c;
        }
        let extent = c.bounds.grow(c.growth * self.usage.margin[id.0 as usize]);
        let (y0, y1) = (extent.min[1], extent.max[1]);
        let s_lo = (1.0 + rate * y0).min(1.0 + rate * y1);
        let s_hi = (1.0 + rate * y0).max(1.0 + rate * y1);
        let mut d = c;
        d.bounds = c.bounds.map(|j, lo, hi| {
            if j == 1 {
                (lo, hi)
            } else {
                (lo * s_hi.max(0.0), hi * s_hi.max(0.0))
            }
        });
        d.symmetric = [c.symmetric[0], false, c.symmetric[2]];
        if !(s_lo > TAPER_FLOOR) {
            self.warn_fold(
                id,
                "taper",
                format!(
                    "its scale 1 + rate·y falls to {} over the shape's heights {} … {}",
                    fmt(s_lo),
                    fmt(y0),
                    fmt(y1)
                ),
                "lower the rate so that 1 + rate·y stays above 0 over the shape",
            );
            return unproven(d, id);
        }
        let rho = extent.radius(0, 2);
        let sigma = s_hi.max(1.0) + rate.abs() * rho;
        if !sigma.is_finite() {
            return unproven(d, id);
        }
        d.growth *= sigma;
        d.facts.lipschitz *= sigma;
        d.gradient *= sigma;
        d.facts.exactness = classify(d.facts.lipschitz, d.proven);
        if d.proven {
            d.cause = Some(id);
        }
        if sigma >= WARN_STRETCH {
            self.warn_stretch(id, "taper", rate, rho, sigma);
        }
        d
    }

    /// Round (`f − r`) and shell (`|f| − t`): the surface is a level set of the child, so only
    /// the child's Lipschitz constant makes the result a bound.
    /// A loft: at height z the profile a + t·clamp(b - a, ±s), extruded. Across the
    /// profiles' plane the gradient is a convex combination of theirs (or a's alone where
    /// the clamp holds); along z it is the clamped difference over the height, at most
    /// s / (2h). Outside |z| ≤ h the extrusion's two terms are orthogonal. So L is
    /// max(1, √(G² + (s / 2h)²)), G the profiles' larger constant; the same profile at both
    /// ends is its extrusion (docs/analysis.md, "Loft").
    fn loft(&mut self, id: NodeId, h: f64, spread: f64, bottom: NodeId, top: NodeId) -> Derived {
        let (da, db) = (self.get(bottom), self.get(top));
        let mut d = merge(&[da, db]);
        if bottom == top {
            d = da;
        }
        d.bounds = da.bounds.union(db.bounds);
        d.bounds.min[2] = -h;
        d.bounds.max[2] = h;
        d.symmetric = [d.symmetric[0], d.symmetric[1], bottom == top];
        if !d.gradient.is_finite() {
            return if d.proven { unproven(d, id) } else { d };
        }
        let slope = if bottom == top {
            0.0
        } else {
            spread / (2.0 * h)
        };
        let g = d.gradient.hypot(slope).max(1.0);
        d.gradient = g;
        d.facts.lipschitz = d.facts.lipschitz.max(g);
        if bottom != top {
            d.facts.exactness = classify(d.facts.lipschitz, d.proven);
            if d.proven && d.cause.is_none() {
                d.cause = Some(id);
            }
        }
        d
    }

    /// A screw: the profile read at (r, w), r the distance from the y axis and w the height
    /// less pitch·φ/2π folded into one pitch, the nearer of its two nearest turns. Moving
    /// by s round the axis at radius r moves w by pitch·s / (2π·r), so the map stretches by
    /// √(1 + (pitch / 2πr)²); the field below r = inner / 2 is floor·max(inner - r, r),
    /// never above the profile's there, so the profile's is read only at r ≥ inner / 2.
    /// The nearer turn's minimum is continuous, and the distance to the profile's turns, only
    /// for an exact profile (docs/analysis.md, "Screw").
    fn screw(
        &mut self,
        id: NodeId,
        pitch: f64,
        half_height: f64,
        inner: f64,
        floor: f64,
        child: NodeId,
    ) -> Derived {
        let c = self.get(child);
        let mut d = c;
        let r = c.bounds.max[0].max(0.0);
        d.bounds = Aabb {
            min: [-r, -half_height, -r],
            max: [r, half_height, r],
        };
        d.symmetric = [false; 3];
        d.growth = c.growth.max(1.0 / floor);
        if c.facts.exactness != Exactness::Exact {
            return unproven(d, id);
        }
        let k = pitch / std::f64::consts::TAU;
        let stretch = (k / (0.5 * inner)).hypot(1.0);
        let g = (c.gradient * stretch).max(1.0);
        d.gradient = g;
        d.facts.lipschitz = g;
        d.facts.exactness = classify(g, d.proven);
        d.cause = Some(id);
        d
    }

    /// A sweep (docs/analysis.md, "Sweep"): a disc about the origin swept is the distance to
    /// the path less its radius, exact; another profile's field is read at coordinates that
    /// change as the point moves across the path and not along it (the frame does not turn
    /// about the path), but for the twist that closes a closed path: L is the profile's times
    /// √(1 + (twist·extent)²), a bound within `inner` of the path and the tube's distance
    /// beyond. Where the profile reaches past half the path's reach (`inner` below `extent`;
    /// past the whole of it, the sweep `folds`) nothing is proven.
    fn sweep(
        &mut self,
        id: NodeId,
        path: &super::Path,
        folds: bool,
        extent: f64,
        child: NodeId,
    ) -> Derived {
        let c = self.get(child);
        let mut d = c;
        let (lo, hi) = path.aabb();
        d.bounds = Aabb {
            min: lo.map(|x| x - extent),
            max: hi.map(|x| x + extent),
        };
        d.symmetric = [false; 3];
        d.growth = c.growth.max(1.0);
        if super::path::round_profile(&self.scene.graph, child) {
            d.gradient = 1.0;
            d.facts.lipschitz = 1.0;
            return d;
        }
        if !c.proven || folds || c.facts.exactness == Exactness::Approximate {
            return unproven(d, id);
        }
        let g = (c.gradient * (path.twist * extent).hypot(1.0)).max(1.0);
        d.gradient = g;
        d.facts.lipschitz = g;
        d.facts.exactness = classify(g, d.proven);
        d.cause = Some(id);
        d
    }

    fn offset(&self, id: NodeId, child: NodeId, by: f64) -> Derived {
        let c = self.get(child);
        let mut d = at_most_bound(c);
        // An inset (a 2D `offset` below 0) lies within the child's box.
        d.bounds = c.bounds.grow(c.growth * by.max(0.0));
        if c.gradient.is_finite() {
            d.facts.lipschitz = c.facts.lipschitz.max(c.gradient);
            d.facts.exactness = classify(d.facts.lipschitz, d.proven);
            d
        } else if c.proven {
            unproven(d, id)
        } else {
            d
        }
    }
}

/// The window of neighbouring cells that makes a repetition of a child with box `extent` a
/// bound read up to level `margin`, or `None` when it would exceed [`MAX_WINDOW_CELLS`].
///
/// Along an axis of period s where the child fits and is symmetric, the own cell suffices
/// (reach 0). Elsewhere, with h the child's farthest extent from its cell's centre, a copy r + 1
/// or more cells away lies at least (r + ½)·s − h from the point along that axis (the point is
/// within ½·s of its own cell's centre, or outside the array beyond it): the reach r is the
/// least ≥ 1 that makes this exceed the margin, and `beyond` is its minimum over such axes.
/// A finite repetition whose window holds every copy on an axis needs no bound there.
pub(crate) fn window(
    extent: &Aabb,
    symmetric: [bool; 3],
    period: V3,
    count: Option<V3>,
    margin: f64,
) -> Option<Window> {
    let mut w = Window {
        reach: [0; 3],
        beyond: f64::INFINITY,
    };
    let mut cells = 1.0;
    for (i, s, n) in repeated_axes(extent, period, count) {
        let (lo, hi, half) = (extent.min[i], extent.max[i], s * 0.5);
        let fits = lo >= -half - TOLERANCE && hi <= half + TOLERANCE;
        if fits && symmetric[i] {
            continue;
        }
        let h = lo.abs().max(hi.abs());
        let mut r = ((h + margin) / s - 0.5).floor() + 1.0;
        r = r.max(1.0);
        if r >= n - 1.0 {
            r = n - 1.0;
        } else {
            w.beyond = w.beyond.min((r + 0.5) * s - h);
        }
        cells *= 2.0 * r + 1.0;
        if !(cells <= MAX_WINDOW_CELLS as f64) {
            return None;
        }
        w.reach[i] = r as u32;
    }
    Some(w)
}

/// The axes along which a repetition of a non-empty shape makes copies: (axis, period,
/// number of copies, infinite for an infinite repetition).
fn repeated_axes(
    extent: &Aabb,
    period: V3,
    count: Option<V3>,
) -> impl Iterator<Item = (usize, f64, f64)> {
    let empty = extent.is_empty();
    (0..3).filter_map(move |i| {
        let n = count.map_or(f64::INFINITY, |n| n[i]);
        (period[i] != 0.0 && n > 1.0 && !empty).then_some((i, period[i], n))
    })
}

/// The facts of a combination of several fields (before its own rule): the largest L and
/// gradient, proven when all are, exactness at most a bound, the cause of the worst child.
fn merge(ds: &[Derived]) -> Derived {
    let mut d = exact(Aabb::EMPTY, [true; 3]);
    d.facts.exactness = Exactness::Bound;
    d.gradient = 0.0;
    d.facts.lipschitz = 0.0;
    d.growth = 0.0;
    // The worst child with a cause: unproven first, then the largest L.
    let key = |c: &Derived| (!c.proven, c.facts.lipschitz);
    let mut worst: Option<&Derived> = None;
    for c in ds {
        d.facts.lipschitz = d.facts.lipschitz.max(c.facts.lipschitz);
        d.gradient = d.gradient.max(c.gradient);
        d.proven &= c.proven;
        d.growth = d.growth.max(c.growth);
        d.symmetric = [0, 1, 2].map(|i| d.symmetric[i] && c.symmetric[i]);
        if c.facts.exactness == Exactness::Approximate {
            d.facts.exactness = Exactness::Approximate;
        }
        if c.cause.is_some() && worst.is_none_or(|w| key(c) > key(w)) {
            worst = Some(c);
        }
    }
    d.cause = worst.and_then(|w| w.cause);
    d
}

/// The half-space `dot(p, n) ≤ h`: bounded on one side when `n` is an axis.
fn plane_bounds(n: V3, h: f64) -> Aabb {
    let mut b = Aabb::ALL;
    for i in 0..3 {
        let others = (0..3).filter(|&j| j != i).all(|j| n[j] == 0.0);
        if others && n[i] != 0.0 {
            if n[i] > 0.0 {
                b.max[i] = h / n[i];
            } else {
                b.min[i] = h / n[i];
            }
        }
    }
    b
}

/// Quilez's ellipsoid bound `k0·(k0 − 1)/k1`: never above the distance, but not Lipschitz
/// (it jumps at the centre and steepens along the long axes), and its level sets reach up to
/// max r / min r times further than the distance's.
fn ellipsoid(radii: V3) -> Derived {
    let mut d = exact(Aabb::centred(radii), [true; 3]);
    d.facts.exactness = Exactness::Bound;
    d.gradient = f64::INFINITY;
    let rmin = radii.iter().fold(f64::INFINITY, |a, r| a.min(*r));
    let rmax = radii.iter().fold(0.0f64, |a, r| a.max(*r));
    d.growth = rmax / rmin;
    d
}

/// A number for a message: up to three decimals, no trailing zeros.
fn fmt(x: f64) -> String {
    crate::diagnostics::number(x, 3)
}

mod aabb;
mod field;
#[cfg(test)]
mod tests;
mod warnings;

pub(crate) use aabb::Aabb;
