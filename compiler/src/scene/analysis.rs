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

use super::ir::{Combine, Exactness, Facts, Node, NodeId, Scene, Smooth, V3};
use crate::diagnostics::Diagnostic;
use std::collections::HashSet;

/// The largest L the renderer steps with: a larger bound is clamped (with the warning that
/// caused it), so that a scene still renders, with artefacts, within its step budget.
pub const MAX_STEP_LIPSCHITZ: f64 = 16.0;

/// A twist or bend that stretches distances by this factor or more is reported (W0003).
pub const WARN_STRETCH: f64 = 1.5;

/// A per-axis scale whose largest factor is this many times its smallest is reported (W0007).
pub const WARN_SCALE_RATIO: f64 = 10.0;

/// A repetition whose copies reach out of their cells evaluates the neighbouring cells too,
/// up to this many cells per point (counting the windows of repetitions nested in it, which
/// multiply); beyond, it evaluates only the own cell and is reported (W0005, W0006).
pub const MAX_WINDOW_CELLS: u32 = 27;

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
pub fn blend_reach(k: f64, variant: Smooth) -> f64 {
    match variant {
        Smooth::Poly => k.max(0.0) * 0.25,
        Smooth::Exp => k.max(0.0) * std::f64::consts::LN_2,
    }
}

/// How much a twist at `a = |rate|·r` (r: distance from the axis) stretches distances: the
/// largest singular value of [[1, a], [0, 1]], a/2 + √(1 + a²/4).
pub fn twist_stretch(a: f64) -> f64 {
    a * 0.5 + (1.0 + a * a * 0.25).sqrt()
}

/// How much a bend at `a = |rate|·r` stretches distances: 1 + a.
pub fn bend_stretch(a: f64) -> f64 {
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

/// Where rays can go: within `max_dist` of the camera for camera rays, of a hit for each
/// bounce and each shadow ray towards a directional light, and up to every point light.
fn view_region(scene: &Scene) -> Aabb {
    let s = &scene.settings;
    let secondary = scene
        .materials
        .iter()
        .any(|m| m.reflect > 0.0 || m.transparency > 0.0);
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
        Node::Twist { child, .. } => vec![(*child, m, around(r, 1))],
        Node::Bend { child, .. } => vec![(*child, m, around(r, 2))],
        Node::Round { radius, child } => vec![(*child, m + radius, r)],
        Node::Shell { thickness, child } => vec![(*child, m + thickness, r)],
        Node::Elongate { half, child } => vec![(
            *child,
            m,
            r.map(|i, lo, hi| (unstretch(lo, half[i]), unstretch(hi, half[i]))),
        )],
        Node::Paint { child, .. } => vec![(*child, m, r)],
        _ => Vec::new(),
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
            Node::Mandelbulb { .. } => {
                let d = exact(Aabb::centred([2.0; 3]), [false; 3]);
                unproven(d, id)
            }
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
            Node::Twist { rate, child } => self.distort(id, *rate, *child, 1),
            Node::Bend { rate, child } => self.distort(id, *rate, *child, 2),
            Node::Round { radius, child } => self.offset(id, *child, *radius),
            Node::Shell { thickness, child } => self.offset(id, *child, *thickness),
            Node::Elongate { half, child } => {
                let mut d = at_most_bound(self.get(*child));
                d.bounds = d.bounds.map(|i, lo, hi| (lo - half[i], hi + half[i]));
                d
            }
            Node::Paint { child, .. } => self.get(*child),
        }
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
        let (da, db) = (self.get(a), self.get(b));
        let mut d = merge(&[da, db]);
        d.facts.exactness = Exactness::Approximate;
        let reach = blend_reach(k, v);
        if d.gradient.is_finite() {
            d.facts.lipschitz = d.facts.lipschitz.max(d.gradient);
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

    /// Round (`f − r`) and shell (`|f| − t`): the surface is a level set of the child, so only
    /// the child's Lipschitz constant makes the result a bound.
    fn offset(&self, id: NodeId, child: NodeId, by: f64) -> Derived {
        let c = self.get(child);
        let mut d = at_most_bound(c);
        d.bounds = c.bounds.grow(c.growth * by);
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
pub fn window(
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
#[cfg(test)]
mod tests;
mod warnings;

pub use aabb::Aabb;
