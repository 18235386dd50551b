//! The scene IR: a hash-consed DAG of shape nodes plus materials, lights, camera and settings.
//!
//! Everything in it is constant: the checker has evaluated every expression. Nodes live in an
//! arena ([`Graph`]) and are named by [`NodeId`]; structurally equal nodes are stored once, so
//! a sub-shape used twice is one node. Computed facts (bounds, Lipschitz bound, exactness) are
//! kept in side tables keyed by `NodeId` ([`Facts`]), next to the spans.

use super::NodeId;
use crate::diagnostics::Diagnostic;
use crate::limits::{Limit, Limits};
use crate::span::Span;
use glam::DVec3;
use std::collections::HashMap;

/// A 3-vector of f64.
pub type V3 = [f64; 3];

/// The product of the matrix `m` (rows) and `v`.
pub fn mat_vec(m: &[V3; 3], v: V3) -> V3 {
    [0, 1, 2].map(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
}

/// Names a material of a [`Scene`]; 0 is the default material.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MaterialId(pub u32);

/// The smooth-minimum variant of a smooth combinator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Smooth {
    /// Polynomial (quadratic) smooth minimum: exact outside the blend region, a bound inside.
    Poly,
    /// Exponential smooth minimum: smoother, but not a bound for large k.
    Exp,
    /// A 45° chamfer of size k (Mercury's hg_sdf, `fOpUnionChamfer` and its forms).
    Chamfer,
    /// A quarter circle of radius k (hg_sdf's `fOpUnionRound` and its forms).
    Round,
    /// A staircase of this many steps over k (hg_sdf's `fOpUnionStairs` and its forms).
    Stairs(u32),
    /// Columns, this many, along the edge within k (hg_sdf's `fOpUnionColumns` and its forms).
    Columns(u32),
}

impl Smooth {
    /// The variant's name, as `variant:` spells it.
    pub fn name(self) -> &'static str {
        match self {
            Smooth::Poly => "poly",
            Smooth::Exp => "exp",
            Smooth::Chamfer => "chamfer",
            Smooth::Round => "round",
            Smooth::Stairs(_) => "stairs",
            Smooth::Columns(_) => "columns",
        }
    }

    /// The number of steps or columns of a variant that has them.
    pub fn steps(self) -> Option<u32> {
        match self {
            Smooth::Stairs(n) | Smooth::Columns(n) => Some(n),
            _ => None,
        }
    }
}

/// A feature cut into or added onto a shape `a` where the surface of a shape `b` crosses it
/// (Mercury's hg_sdf: `fOpEngrave`, `fOpGroove`, `fOpTongue`, `fOpPipe`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Feature {
    /// A V-shaped cut `depth` deep along b's surface.
    Engrave { depth: f64 },
    /// A square groove `width` wide and `depth` deep along b's surface.
    Groove { width: f64, depth: f64 },
    /// A square tongue `width` wide standing `height` out of a along b's surface.
    Tongue { width: f64, height: f64 },
    /// A tube of `radius` along the curve where the two surfaces meet (neither shape stays).
    Pipe { radius: f64 },
}

impl Feature {
    /// The builtin's name.
    pub fn name(self) -> &'static str {
        match self {
            Feature::Engrave { .. } => "engrave",
            Feature::Groove { .. } => "groove",
            Feature::Tongue { .. } => "tongue",
            Feature::Pipe { .. } => "pipe",
        }
    }

    /// How far the surface may stand out of `a`'s (for the tongue and the pipe).
    pub fn outset(self) -> f64 {
        match self {
            Feature::Engrave { .. } | Feature::Groove { .. } => 0.0,
            Feature::Tongue { height, .. } => height,
            Feature::Pipe { radius } => radius,
        }
    }

    /// How far from either surface the feature reads its operands' fields: the level sets
    /// up to this value shape it.
    pub fn reach(self) -> f64 {
        match self {
            Feature::Engrave { depth } => depth,
            Feature::Groove { width, depth } => width.max(depth),
            Feature::Tongue { width, height } => width.max(height),
            Feature::Pipe { radius } => radius,
        }
    }
}

/// The three boolean combinations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Combine {
    /// min(a, b)
    Union,
    /// max(a, b)
    Intersect,
    /// max(a, -b)
    Subtract,
}

impl Combine {
    /// The combination's name, with the `smooth_` prefix for the smooth one: `union`,
    /// `smooth_subtract`, ….
    pub fn name(self, smooth: bool) -> &'static str {
        match (self, smooth) {
            (Combine::Union, false) => "union",
            (Combine::Intersect, false) => "intersect",
            (Combine::Subtract, false) => "subtract",
            (Combine::Union, true) => "smooth_union",
            (Combine::Intersect, true) => "smooth_intersect",
            (Combine::Subtract, true) => "smooth_subtract",
        }
    }
}

/// A shape node. Primitives are centred on the origin; transforms wrap a child.
#[derive(Debug, Clone, PartialEq)]
pub enum Node {
    /// Sphere of a radius.
    Sphere { radius: f64 },
    /// Box of half-extents.
    Box { half: V3 },
    /// Box of half-extents with edges rounded by a radius (the radius is inside the extents).
    RoundBox { half: V3, radius: f64 },
    /// Half-space below the plane `dot(p, normal) = height` (normal is unit length).
    Plane { normal: V3, height: f64 },
    /// Torus in the xz plane.
    Torus { major: f64, minor: f64 },
    /// Capped cylinder along y.
    Cylinder { radius: f64, half_height: f64 },
    /// Capsule along y: a segment of half-length `half_height`, swept by a radius.
    Capsule { radius: f64, half_height: f64 },
    /// Capped cone along y with its tip at `height / 2` and its base radius `radius` at
    /// `-height / 2`.
    Cone { radius: f64, half_height: f64 },
    /// Axis-aligned ellipsoid of radii (a bound, not exact).
    Ellipsoid { radii: V3 },
    /// A primitive of the table (`prim/`): its entry and its arguments.
    Prim {
        prim: crate::prim::PrimRef,
        args: crate::prim::Args,
    },
    /// Profile: a rectangle of half-extents `half`.
    Rect { half: [f64; 2] },
    /// Profile: a simple polygon through `points` (three or more, either winding).
    Polygon { points: Vec<[f64; 2]> },
    /// Profile: the quadratic Bézier curve from `a` to `b` pulled towards `control`, stroked
    /// to `radius` on either side (`control` is not the midpoint of `a` and `b`).
    Bezier {
        a: [f64; 2],
        control: [f64; 2],
        b: [f64; 2],
        radius: f64,
    },
    /// Profile: the glyphs of `text` in the font named `font` (empty: the shipped DejaVu Sans),
    /// its em `size` high, laid out as `outline` (read as data by every back end).
    Text {
        text: String,
        size: f64,
        font: String,
        outline: std::sync::Arc<crate::program::outline::Outline>,
    },
    /// A profile extruded along z to half-height `half_height`, its edges rounded by `round`
    /// (inside the extents).
    Extrude {
        half_height: f64,
        round: f64,
        child: NodeId,
    },
    /// A profile revolved about the y axis: the profile's x is the distance from the axis,
    /// less `offset`.
    Revolve { offset: f64, child: NodeId },
    /// A solid between two profiles along z, from `bottom` at z = -half_height to `top` at
    /// z = half_height: at height z the profile a + t·clamp(b - a, -spread, spread), t the
    /// height's fraction, a and b the two fields (docs/analysis.md, "Loft"). `spread` is at
    /// least |b - a| everywhere when both are exact, so the clamp only bounds the slope.
    Loft {
        half_height: f64,
        spread: f64,
        bottom: NodeId,
        top: NodeId,
    },
    /// A profile swept along a helix about the y axis, like a revolved one (the profile's x is
    /// the distance from the axis) rising `pitch` per turn, repeated every pitch and cut to
    /// |y| ≤ half_height. `inner` is the least x of the profile's box (> 0) and `floor` the
    /// scale of its bound (`scene/bounds.rs`): near the axis the field is
    /// floor·max(inner - r, r), below the profile's own (docs/analysis.md, "Screw").
    Screw {
        pitch: f64,
        half_height: f64,
        inner: f64,
        floor: f64,
        child: NodeId,
    },
    /// A profile swept along a path (`scene/path.rs`, `lower/sweep.rs`): read at the point's
    /// coordinates in the path's frame at its nearest point, capped at open ends. Beyond
    /// `inner` from the path (∞: nowhere), and beyond `extent` (the profile's reach from its
    /// origin), the field is the distance to the tube of radius `extent` about the path
    /// (docs/analysis.md, "Sweep"); it is proven a bound where `inner` ≥ `extent`.
    Sweep {
        path: PathRef,
        inner: f64,
        extent: f64,
        /// The profile reaches past the path's reach: the sweep folds over itself (W0018) and
        /// its field is not proven.
        folds: bool,
        child: NodeId,
    },
    /// n-ary union, or a binary intersection or subtraction.
    Combine { op: Combine, children: Vec<NodeId> },
    /// Smooth union, intersection or subtraction with blend radius `k`.
    SmoothCombine {
        op: Combine,
        k: f64,
        variant: Smooth,
        a: NodeId,
        b: NodeId,
    },
    /// A feature of `a` along the surface of `b` (engrave, groove, tongue, pipe).
    Feature { op: Feature, a: NodeId, b: NodeId },
    /// Child moved by an offset.
    Translate { offset: V3, child: NodeId },
    /// Child turned by an orthogonal matrix (rows): a rotation, or a reflection
    /// (`reflect`, a left-handed `screw`) where its determinant is −1. Either keeps distances.
    Rotate { matrix: [V3; 3], child: NodeId },
    /// Child scaled uniformly.
    Scale { factor: f64, child: NodeId },
    /// Child scaled per axis (the field becomes a bound).
    ScaleXyz { factors: V3, child: NodeId },
    /// Domain repetition with a period per axis (0: no repetition on that axis), infinite or
    /// limited to `count` copies per axis.
    Repeat {
        period: V3,
        count: Option<V3>,
        child: NodeId,
    },
    /// Polar repetition about the y axis: `count` copies of the child, the child itself at
    /// angle 0 and the others rotated about y by multiples of 360°/count (as `rotate_y`
    /// rotates); with `mirror`, every other copy mirrored across its own plane z = 0 (the
    /// count is then even). The builtin turns other axes into rotations around this node.
    RepeatPolar {
        count: u32,
        mirror: bool,
        child: NodeId,
    },
    /// Mirror across the planes x = 0, y = 0, z = 0 where set.
    Mirror { axes: [bool; 3], child: NodeId },
    /// Twist about y by `rate` radians per unit of height.
    Twist { rate: f64, child: NodeId },
    /// Bend in the xy plane by `rate` radians per unit of x.
    Bend { rate: f64, child: NodeId },
    /// The child's x axis wrapped around the circle of `radius` about the y axis (in the xz
    /// plane, through (0, 0, −radius)): the child's point (u, y, w) goes to
    /// ((radius − w)·sin(u/radius), y, −(radius − w)·cos(u/radius)), so that a bar of length
    /// 2π·radius along x closes into a ring.
    Wrap { radius: f64, child: NodeId },
    /// A linear shear: the child's point p goes to `matrix`·p (rows; ones on the diagonal).
    Shear { matrix: [V3; 3], child: NodeId },
    /// The child's cross-sections (x, z) scaled by 1 + rate·y at height y.
    Taper { rate: f64, child: NodeId },
    /// The field (1 − t)·a + t·b: a shape between `a` (t = 0) and `b` (t = 1).
    Morph { t: f64, a: NodeId, b: NodeId },
    /// Child's surface offset outwards by a radius.
    Round { radius: f64, child: NodeId },
    /// Hollow shell around the child's surface, `|f| - half`: a wall `2·half` thick centred on
    /// the surface (Quilez's onion; `shell(t)` makes `half = t / 2`).
    Shell { half: f64, child: NodeId },
    /// Child stretched by inserting a box of half-extents `half` at the origin.
    Elongate { half: V3, child: NodeId },
    /// Child painted with a material (inner materials take precedence).
    Paint { material: MaterialId, child: NodeId },
    /// A triangle mesh read from a file (`mesh("part.stl")`), with its hierarchy.
    Mesh { mesh: MeshRef },
    /// A user field (`field { … }`): the distance is an expression of the point, which may
    /// read other shapes' distances; its L is derived from the expression, or declared. With
    /// `plane`, a profile (`profile { … }`): an expression of the point's x and y alone.
    Field {
        f: super::field::FieldFn,
        lipschitz: Option<f64>,
        plane: bool,
    },
}

/// A triangle mesh of a scene: equal to another when it is the same mesh of the same check
/// (its [`TriMesh::id`](crate::program::mesh::TriMesh::id)), shown by its file's name.
#[derive(Clone)]
pub struct MeshRef(pub std::sync::Arc<crate::program::mesh::TriMesh>);

impl PartialEq for MeshRef {
    fn eq(&self, other: &Self) -> bool {
        self.0.id == other.0.id
    }
}

impl std::fmt::Debug for MeshRef {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "mesh {} {:?}", self.0.id, self.0.name)
    }
}

/// A path of a sweep: equal to another of the same points and frames, shown by its kind.
#[derive(Clone)]
pub struct PathRef(pub std::sync::Arc<super::path::Path>);

impl PartialEq for PathRef {
    fn eq(&self, other: &Self) -> bool {
        *self.0 == *other.0
    }
}

impl std::fmt::Debug for PathRef {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        // Every number: the hash-consing key tells paths apart by it.
        write!(f, "{:?}", self.0)
    }
}

/// The pattern of every node with exactly one child (the transforms, the modifiers and
/// paint), binding the child to `$child`: the one list of them.
macro_rules! one_child {
    ($child:ident) => {
        Node::Translate { $child, .. }
            | Node::Rotate { $child, .. }
            | Node::Scale { $child, .. }
            | Node::ScaleXyz { $child, .. }
            | Node::Repeat { $child, .. }
            | Node::RepeatPolar { $child, .. }
            | Node::Mirror { $child, .. }
            | Node::Twist { $child, .. }
            | Node::Bend { $child, .. }
            | Node::Wrap { $child, .. }
            | Node::Shear { $child, .. }
            | Node::Taper { $child, .. }
            | Node::Round { $child, .. }
            | Node::Shell { $child, .. }
            | Node::Elongate { $child, .. }
            | Node::Paint { $child, .. }
            | Node::Extrude { $child, .. }
            | Node::Revolve { $child, .. }
            | Node::Screw { $child, .. }
            | Node::Sweep { $child, .. }
    };
}

impl Node {
    /// The node of the table's primitive `name` (`prim/`) with these arguments, each one
    /// number or the two or three of a vector; `None` where the table has no such entry.
    pub fn prim(name: &str, args: &[&[f64]]) -> Option<Node> {
        let prim = crate::prim::find(name)?;
        let args = args
            .iter()
            .map(|a| [0, 1, 2].map(|i| a.get(i).copied().unwrap_or(0.0)))
            .collect();
        Some(Node::Prim {
            prim: crate::prim::PrimRef(prim),
            args: crate::prim::Args(args),
        })
    }

    /// The node's children in order.
    pub fn children(&self) -> Vec<NodeId> {
        match self {
            Node::Combine { children, .. } => children.clone(),
            Node::SmoothCombine { a, b, .. }
            | Node::Morph { a, b, .. }
            | Node::Feature { a, b, .. } => vec![*a, *b],
            Node::Loft { bottom, top, .. } => vec![*bottom, *top],
            one_child!(child) => vec![*child],
            Node::Field { f, .. } => f.shapes(),
            _ => Vec::new(),
        }
    }

    /// The child of a node with exactly one (a transform, a modifier or paint), to replace.
    pub fn child_mut(&mut self) -> Option<&mut NodeId> {
        match self {
            one_child!(child) => Some(child),
            _ => None,
        }
    }

    /// The node's name in the IR (`--emit ir`, and the program's comments): `sphere`,
    /// `smooth_union`, `scale_xyz`, ….
    pub fn kind(&self) -> &'static str {
        match self {
            Node::Sphere { .. } => "sphere",
            Node::Box { .. } => "box",
            Node::RoundBox { .. } => "round_box",
            Node::Plane { .. } => "plane",
            Node::Torus { .. } => "torus",
            Node::Cylinder { .. } => "cylinder",
            Node::Capsule { .. } => "capsule",
            Node::Cone { .. } => "cone",
            Node::Ellipsoid { .. } => "ellipsoid",
            Node::Rect { .. } => "rect",
            Node::Polygon { .. } => "polygon",
            Node::Bezier { .. } => "bezier",
            Node::Text { .. } => "text",
            Node::Prim { prim, .. } => prim.name,
            Node::Extrude { .. } => "extrude",
            Node::Revolve { .. } => "revolve",
            Node::Loft { .. } => "loft",
            Node::Screw { .. } => "screw",
            Node::Sweep { .. } => "sweep",
            Node::Feature { op, .. } => op.name(),
            Node::Combine { op, .. } => op.name(false),
            Node::SmoothCombine { op, .. } => op.name(true),
            Node::Translate { .. } => "translate",
            Node::Rotate { .. } => "rotate",
            Node::Scale { .. } => "scale",
            Node::ScaleXyz { .. } => "scale_xyz",
            Node::Repeat { .. } => "repeat",
            Node::RepeatPolar { .. } => "repeat_polar",
            Node::Mirror { .. } => "mirror",
            Node::Twist { .. } => "twist",
            Node::Bend { .. } => "bend",
            Node::Wrap { .. } => "wrap",
            Node::Shear { .. } => "shear",
            Node::Taper { .. } => "taper",
            Node::Morph { .. } => "morph",
            Node::Round { .. } => "round",
            Node::Shell { .. } => "shell",
            Node::Elongate { .. } => "elongate",
            Node::Paint { .. } => "paint",
            Node::Field { plane: false, .. } => "field",
            Node::Field { plane: true, .. } => "profile",
            Node::Mesh { .. } => "mesh",
        }
    }

    /// A key that is equal for structurally equal nodes (floats compared by bits).
    fn key(&self) -> String {
        format!("{self:?}")
    }
}

/// Facts an analysis computed for a node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Facts {
    /// Whether the field is an exact distance, a bound, or neither.
    pub exactness: Exactness,
    /// The step divisor L: marching by f / L never crosses the surface. For a field with a
    /// proven gradient bound it is that bound; for a bound such as the ellipsoid it is 1
    /// (a lower bound on the distance is safe to step by, however steep the field).
    pub lipschitz: f64,
}

/// How a field relates to the true distance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exactness {
    /// The exact Euclidean distance (signed).
    Exact,
    /// Never above the true distance (safe for sphere tracing).
    Bound,
    /// May overstate the distance.
    Approximate,
}

/// An arena of hash-consed nodes, with the span each node came from.
#[derive(Debug, Default, Clone)]
pub struct Graph {
    nodes: Vec<Node>,
    spans: Vec<Span>,
    dedup: HashMap<String, NodeId>,
}

impl Graph {
    /// Adds a node, or returns the id of an equal node added before.
    pub fn add(&mut self, node: Node, span: Span) -> NodeId {
        let key = node.key();
        if let Some(&id) = self.dedup.get(&key) {
            return id;
        }
        let id = NodeId(self.nodes.len() as u32);
        self.nodes.push(node);
        self.spans.push(span);
        self.dedup.insert(key, id);
        id
    }

    /// The node behind an id.
    pub fn node(&self, id: NodeId) -> &Node {
        &self.nodes[id.0 as usize]
    }

    /// The span of the expression that first built this node.
    pub fn span(&self, id: NodeId) -> Span {
        self.spans[id.0 as usize]
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// True when there are no nodes.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// All ids in creation order (children before parents).
    pub fn ids(&self) -> impl Iterator<Item = NodeId> {
        (0..self.nodes.len() as u32).map(NodeId)
    }

    /// The size of every node as a tree: the node and, for each child it names, the child's
    /// size (a shared sub-shape counts once per use). One pass in creation order, memoised
    /// per node and saturating, so it takes time linear in the graph, however large the
    /// tree: the bound on the passes that walk the scene as a tree (`Limit::Expansion`).
    pub fn tree_sizes(&self) -> Vec<u64> {
        let mut sizes: Vec<u64> = Vec::with_capacity(self.nodes.len());
        for node in &self.nodes {
            let size = node
                .children()
                .iter()
                .fold(1u64, |acc, c| acc.saturating_add(sizes[c.0 as usize]));
            sizes.push(size);
        }
        sizes
    }

    /// When the tree below `root` has more than `max` nodes: the deepest node of it whose
    /// own tree still has more (where the expansion crosses the limit), with the size of
    /// that node's tree and of the root's.
    pub fn over_expanded(&self, root: NodeId, max: u64) -> Option<Expansion> {
        let sizes = self.tree_sizes();
        let total = sizes[root.0 as usize];
        if total <= max {
            return None;
        }
        let mut at = root;
        while let Some(big) = self
            .node(at)
            .children()
            .into_iter()
            .find(|c| sizes[c.0 as usize] > max)
        {
            at = big;
        }
        Some(Expansion {
            at,
            size: sizes[at.0 as usize],
            total,
        })
    }

    /// The E0507 error of a tree over the `expansion` limit of `limits`, at the shape where
    /// the expansion crosses the limit.
    pub fn expansion_error(&self, e: &Expansion, limits: &Limits) -> Diagnostic {
        let max = limits.get(Limit::Expansion);
        Diagnostic::error(
            "E0507",
            format!("the scene's shapes expand to more than {max} nodes"),
            self.span(e.at),
        )
        .with_label(format!(
            "this shape alone expands to {} nodes when its shared sub-shapes are counted once per use",
            e.size
        ))
        .with_note(format!(
            "passes over the scene visit a shape once per use; this limit keeps them bounded; {}",
            limits.raise_to(Limit::Expansion, e.total)
        ))
    }
}

/// A scene whose tree is over the `expansion` limit ([`Graph::over_expanded`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Expansion {
    /// The deepest node whose tree is over the limit.
    pub at: NodeId,
    /// The size of its tree.
    pub size: u64,
    /// The size of the whole scene's tree (saturated at `u64::MAX`).
    pub total: u64,
}

/// One colour of a material: a constant, or a colour field (`field { … }` whose body is a
/// vec3 of the point `p`, docs/language.md "Colour fields"), evaluated at the hit point in
/// the scene's coordinates (the world's, before [`Scene::origin`] moved them).
#[derive(Debug, Clone, PartialEq)]
pub enum Colour {
    /// The same colour everywhere.
    Const(V3),
    /// Red, green and blue as the three values of a field's expression; components below 0
    /// are taken as 0.
    Field(super::field::FieldFn),
}

impl Colour {
    /// The constant colour, or `None` for a field.
    pub fn constant(&self) -> Option<V3> {
        match self {
            Colour::Const(c) => Some(*c),
            Colour::Field(_) => None,
        }
    }
}

impl From<V3> for Colour {
    fn from(c: V3) -> Colour {
        Colour::Const(c)
    }
}

/// The colour of a material at a point.
#[derive(Debug, Clone, PartialEq)]
pub enum Pattern {
    /// One colour (or colour field).
    Solid(Colour),
    /// A 3D checkerboard of two colours (or colour fields) with cubes of edge `size`.
    Checker { a: Colour, b: Colour, size: f64 },
    /// A 3D checkerboard of two materials (`checker { a: gold, b: rubber }`), in cubes of edge
    /// `size` laid out as [`Pattern::Checker`]'s: each cell shades as its material, blended
    /// over a sample's footprint (docs/rendering.md, "The checker's footprint"). The two are
    /// opaque, of one model (both Phong or both `pbr`), and neither is such a checker itself
    /// (the checker refuses the others); the material holding this pattern has no other use.
    Materials {
        a: MaterialId,
        b: MaterialId,
        size: f64,
    },
}

impl Pattern {
    /// The pattern's colours: one, or the checker's two.
    pub fn colours(&self) -> Vec<&Colour> {
        match self {
            Pattern::Solid(c) => vec![c],
            Pattern::Checker { a, b, .. } => vec![a, b],
            // Its cells' colours are its materials'.
            Pattern::Materials { .. } => Vec::new(),
        }
    }
}

/// A material (docs/rendering.md, "At a hit"): Phong, or physically based where `pbr` is
/// given (its Phong fields then hold the nearest Phong material, for the material tables of
/// `--part map` and the Shadertoy page).
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// The name it was declared with.
    pub name: String,
    /// Colour or pattern.
    pub pattern: Pattern,
    /// k_a
    pub ambient: f64,
    /// k_d
    pub diffuse: f64,
    /// k_s
    pub specular: f64,
    /// α
    pub shininess: f64,
    /// Weight of the reflected ray, in [0, 1].
    pub reflect: f64,
    /// Weight of the transmitted ray, in [0, 1]; reflect + transparency ≤ 1.
    pub transparency: f64,
    /// Index of refraction, ≥ 1.
    pub ior: f64,
    /// Schlick's Fresnel term on the reflected and refracted rays (`fresnel: true`; always
    /// on for `pbr`).
    pub fresnel: bool,
    /// The physically based model's parameters (`pbr { … }`), or `None` for Phong.
    pub pbr: Option<super::Pbr>,
    /// The maps from the world to the coordinates its colour fields are evaluated in, the
    /// outermost first (`scene/frame.rs`): none for a material applied in the world's.
    pub frame: Vec<super::frame::Frame>,
}

impl Material {
    // The default of each field of a material (`phong`'s and `checker`'s, check/builtins.rs
    // reads them here), and the default material's.
    /// The default colour.
    pub const COLOR: V3 = [0.8, 0.8, 0.8];
    /// The default k_a.
    pub const AMBIENT: f64 = 0.1;
    /// The default k_d.
    pub const DIFFUSE: f64 = 0.9;
    /// The default k_s.
    pub const SPECULAR: f64 = 0.3;
    /// The default α.
    pub const SHININESS: f64 = 32.0;
    /// The default weight of the reflected ray.
    pub const REFLECT: f64 = 0.0;
    /// The default weight of the transmitted ray.
    pub const TRANSPARENCY: f64 = 0.0;
    /// The default index of refraction.
    pub const IOR: f64 = 1.5;

    /// Whether a hit on it may spawn a reflected ray: `reflect` > 0, a `pbr` material
    /// that is not fully rough (its mirror weight `(1 − roughness)²` > 0), or a Phong
    /// material with Fresnel (which reflects at grazing incidence).
    pub fn reflects(&self) -> bool {
        match self.pbr {
            Some(p) => p.mirror() > 0.0,
            None => self.reflect > 0.0 || self.fresnel,
        }
    }

    /// The material of shapes that were not painted.
    pub fn default_material() -> Self {
        Material {
            name: "default".into(),
            pattern: Pattern::Solid(Colour::Const(Material::COLOR)),
            ambient: Material::AMBIENT,
            diffuse: Material::DIFFUSE,
            specular: Material::SPECULAR,
            shininess: Material::SHININESS,
            reflect: Material::REFLECT,
            transparency: Material::TRANSPARENCY,
            ior: Material::IOR,
            fresnel: false,
            pbr: None,
            frame: Vec::new(),
        }
    }
}

/// A light source.
#[derive(Debug, Clone, PartialEq)]
pub enum Light {
    /// A point light whose contribution falls to zero at `radius`.
    Point {
        position: V3,
        color: V3,
        intensity: f64,
        radius: f64,
        /// The angle of the penumbra in radians (0 gives hard shadows); see [`Light::sharpness`].
        penumbra: f64,
        /// Whether it casts shadows (`shadows: false`: no shadow rays).
        shadows: bool,
    },
    /// A light from a direction (the direction light travels in), with no attenuation.
    Directional {
        direction: V3,
        color: V3,
        intensity: f64,
        /// The angle of the penumbra in radians (0 gives hard shadows); see [`Light::sharpness`].
        /// A `sun`'s is its angular size, `angle`.
        penumbra: f64,
        /// Whether it casts shadows (`shadows: false`: no shadow rays).
        shadows: bool,
    },
    /// Light from the whole sky (docs/rendering.md, "Sky light"): radiance `zenith` straight
    /// up, `horizon` at the horizon, linear in the height of the direction between them,
    /// `ground` below the horizon, each times `intensity`.
    Sky {
        zenith: V3,
        horizon: V3,
        ground: V3,
        intensity: f64,
        /// Whether the ambient occlusion (the `occlusion` render setting) scales its light.
        shadows: bool,
        /// Whether rays that hit nothing show it instead of the `background` colour.
        background: bool,
    },
}

impl Light {
    /// The penumbra angle in radians; 0 means hard shadows.
    pub fn penumbra(&self) -> f64 {
        match self {
            Light::Point { penumbra, .. } | Light::Directional { penumbra, .. } => *penumbra,
            Light::Sky { .. } => 0.0,
        }
    }

    /// Whether it casts shadows (a sky's are its occlusion).
    pub fn shadows(&self) -> bool {
        match self {
            Light::Point { shadows, .. }
            | Light::Directional { shadows, .. }
            | Light::Sky { shadows, .. } => *shadows,
        }
    }

    /// The sharpness k of the soft-shadow estimate `min(k·d/t)` (docs/rendering.md,
    /// "Shadows"): a point whose ray to the light passes an occluder at angular distance
    /// `atan(d/t)` of at least the penumbra angle θ is fully lit, so k = 1/tan θ; 0 (hard
    /// shadows) for θ = 0.
    pub fn sharpness(&self) -> f64 {
        sharpness(self.penumbra())
    }

    /// A soft shadow ray's search around a least `k·d/t` (docs/rendering.md, "Shadows") ends
    /// once its bracket is narrower than this fraction of the penumbra cone's width there.
    pub const PENUMBRA_BRACKET: f64 = 0.02;
    /// The most evaluations one such search takes.
    pub const PENUMBRA_PROBES: u32 = 16;
}

/// The soft-shadow sharpness k = 1/tan θ of a penumbra angle θ (0 for θ = 0).
pub fn sharpness(penumbra: f64) -> f64 {
    if penumbra > 0.0 {
        1.0 / penumbra.tan()
    } else {
        0.0
    }
}

/// The penumbra angle θ = atan(1/k) of a soft-shadow sharpness k (0 for k = 0): the inverse
/// of [`sharpness`], for files written with the old `softness` field.
pub fn penumbra_of_sharpness(k: f64) -> f64 {
    if k > 0.0 {
        (1.0 / k).atan()
    } else {
        0.0
    }
}

/// A pinhole camera.
#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub position: V3,
    /// The point looked at.
    pub look_at: V3,
    /// The direction that is up in the image (need not be perpendicular to the view).
    pub up: V3,
    /// Vertical field of view in radians.
    pub fov: f64,
}

impl Camera {
    /// The camera's orthonormal basis `(w, u, v)` (docs/rendering.md, "Camera"): `w` the view
    /// direction `normalize(look_at − position)`, `u = normalize(w × up)` (the image's
    /// rightward direction), `v = u × w` (the image's up). Where `up` is parallel to
    /// the view (looking straight down or up with the default up), the coordinate axis least
    /// aligned with the view stands in for it, so every camera has a valid basis. Computed in
    /// f64 once, for every backend.
    pub fn basis(&self) -> (V3, V3, V3) {
        let up = DVec3::from(self.up);
        let w = unit(DVec3::from(self.look_at) - DVec3::from(self.position));
        let mut side = w.cross(up);
        if side.length_squared() < 1e-12 * up.length_squared() {
            // z first: of equally unaligned axes +z wins, so looking straight down the top
            // of the image is +z, as for a camera that approaches the vertical from −z.
            let axis = [2, 0, 1]
                .into_iter()
                .min_by(|&a, &b| w[a].abs().total_cmp(&w[b].abs()))
                .unwrap_or(2);
            side = w.cross(DVec3::AXES[axis]);
        }
        let u = unit(side);
        (w.into(), u.into(), u.cross(w).into())
    }
}

/// `a` scaled to length 1 (zero stays zero).
fn unit(a: DVec3) -> DVec3 {
    let l = a.length();
    if l > 0.0 {
        a / l
    } else {
        a
    }
}

impl Camera {
    /// The field of view of a camera that gives none, in degrees.
    pub const FOV_DEGREES: f64 = 60.0;

    /// The camera of a scene without a `camera` block, and the default of each field of one
    /// (`check/builtins.rs` reads them here).
    pub const DEFAULT: Camera = Camera {
        position: [0.0, 1.0, -5.0],
        look_at: [0.0, 0.0, 0.0],
        up: [0.0, 1.0, 0.0],
        fov: Camera::FOV_DEGREES.to_radians(),
    };
}

impl Default for Camera {
    fn default() -> Self {
        Camera::DEFAULT
    }
}

/// Render settings (docs/rendering.md); `sdfc render --set key=value` overrides them.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Supersampling grid edge (n×n samples per pixel).
    pub aa: u32,
    /// Sphere-tracing step budget per ray.
    pub max_steps: u32,
    /// Pixel-cone hit tolerance: hit when |d| < epsilon · t (unless `footprint`).
    pub epsilon: f64,
    /// Whether ε follows the pixel footprint instead of `epsilon`: ε is then the angular
    /// radius of a pixel, tan(fov/2)/height (see [`Settings::hit_epsilon`]). The checker sets
    /// it where the file gives no `epsilon` and the field has no proven distance bound
    /// (docs/accuracy.md, "Fields without a bound"); `--set epsilon` clears it.
    pub footprint: bool,
    /// Secondary-ray depth limit.
    pub max_depth: u32,
    /// Rays stop beyond this distance.
    pub max_dist: f64,
    /// Over-relaxation factor ω in [1, 2).
    pub relaxation: f64,
    /// Colour of rays that hit nothing.
    pub background: V3,
    /// How rays find surfaces (see [`Method`]).
    pub method: Method,
    /// How far from a surface ambient occlusion looks, R (0: none; docs/rendering.md, "The
    /// look").
    pub occlusion: f64,
    /// The distance D over which fog leaves e^(−t/D) of a surface's light (0: none).
    pub fog: f64,
    /// The fog's colour; `None`: the background.
    pub fog_color: Option<V3>,
    /// The distance G of the glow of a camera ray's marching steps: each evaluation of its
    /// march adds `glow_color·e^(−d/G)` (0: none; docs/rendering.md, "The look").
    pub glow: f64,
    /// The colour each marching step of a camera ray adds at a distance 0 from a surface.
    pub glow_color: V3,
    /// Exposure in stops: the pixel's colour is multiplied by 2^exposure.
    pub exposure: f64,
    /// The tone curve after the exposure.
    pub tonemap: super::Tonemap,
    /// Where `tonemap` was not given, why the tone curve is the default it is: what of the
    /// newer look the scene uses (`filmic`), or [`super::look::OLDER_LOOK`] (`none`;
    /// [`super::look::newer_look`]); `None` where it was given.
    pub tonemap_why: Option<&'static str>,
    /// Whether pictures are path traced (`method: "path"`; docs/rendering.md, "Path
    /// tracing"): `samples` paths a pixel of up to `bounces` bounces, intersected as
    /// `method` says (`auto` for `method: "path"`).
    pub path: bool,
    /// The path tracer's samples (paths) per pixel.
    pub samples: u32,
    /// The path tracer's bounces after the camera ray's hit.
    pub bounces: u32,
    /// The number of the path tracer's first sample in its random stream (not a language
    /// field: `sdfc view` renders sample `k` of a resting camera as frame `k`, with one
    /// sample each, so that its frames add up to the picture of `samples` samples).
    pub first_sample: u32,
}

/// The intersection method of a render (docs/rendering.md, "Marching" and "Analytic ray tracing").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Method {
    /// Analytic ray tracing when the scene allows it, sphere tracing otherwise.
    #[default]
    Auto,
    /// Analytic ray tracing; an error for a scene that does not allow it.
    Trace,
    /// Sphere tracing, whatever the scene.
    March,
}

impl Method {
    /// The names of the methods, as the `method` setting spells them.
    pub const NAMES: &'static [&'static str] = &["auto", "trace", "march"];

    /// The method of a name in [`Method::NAMES`].
    pub fn from_name(name: &str) -> Option<Method> {
        match name {
            "auto" => Some(Method::Auto),
            "trace" => Some(Method::Trace),
            "march" => Some(Method::March),
            _ => None,
        }
    }

    /// The method's name.
    pub const fn name(self) -> &'static str {
        match self {
            Method::Auto => "auto",
            Method::Trace => "trace",
            Method::March => "march",
        }
    }
}

impl Settings {
    /// Whether camera rays glow with their marching steps (`glow` > 0, not path traced:
    /// docs/rendering.md, "The look").
    pub fn glows(&self) -> bool {
        self.glow > 0.0 && !self.path
    }

    /// The ε of the hit test for a camera of field of view `fov` (radians): `epsilon`, or
    /// where `footprint`, the angular radius of one pixel, tan(fov/2)/height: the surface as a
    /// cone one pixel wide sees it.
    pub fn hit_epsilon(&self, fov: f64) -> f64 {
        if self.footprint {
            (fov * 0.5).tan() / self.height.max(1) as f64
        } else {
            self.epsilon
        }
    }

    /// The fog's colour: `fog_color`, or where it is not given, the background.
    pub fn fog_colour(&self) -> V3 {
        self.fog_color.unwrap_or(self.background)
    }

    /// The settings of a scene without a `render` block, and the default of each field of one
    /// (`check/builtins.rs` reads them here).
    pub const DEFAULT: Settings = Settings {
        width: 640,
        height: 480,
        aa: 1,
        max_steps: 512,
        epsilon: 1e-5,
        footprint: false,
        max_depth: 5,
        max_dist: 100.0,
        relaxation: 1.4,
        background: [0.05, 0.06, 0.08],
        method: Method::Auto,
        occlusion: 0.0,
        fog: 0.0,
        fog_color: None,
        glow: 0.0,
        glow_color: [0.02, 0.02, 0.02],
        exposure: 0.0,
        tonemap: super::Tonemap::None,
        tonemap_why: None,
        path: false,
        samples: 16,
        bounces: 4,
        first_sample: 0,
    };

    /// The names the `method` setting accepts: [`Method::NAMES`] and `"path"`.
    pub const METHODS: &'static [&'static str] = &["auto", "trace", "march", "path"];

    /// Sets the `method` setting by its name: a [`Method`] (the Whitted renderer), or
    /// `"path"`, the path tracer intersecting as `auto` does. `false` for an unknown name.
    pub fn set_method(&mut self, name: &str) -> bool {
        if name == "path" {
            self.method = Method::Auto;
            self.path = true;
            return true;
        }
        match Method::from_name(name) {
            Some(m) => {
                self.method = m;
                self.path = false;
                true
            }
            None => false,
        }
    }

    /// The `method` setting's name: `"path"` for the path tracer, else [`Method::name`].
    pub fn method_name(&self) -> &'static str {
        if self.path {
            "path"
        } else {
            self.method.name()
        }
    }
}

impl Default for Settings {
    fn default() -> Self {
        Settings::DEFAULT
    }
}

/// A checked scene: everything a back end needs, nothing from the AST.
#[derive(Debug, Clone, Default)]
pub struct Scene {
    /// The shape arena.
    pub graph: Graph,
    /// The union of all scene objects; `None` for a scene with no objects.
    pub root: Option<NodeId>,
    /// Materials; index 0 is the default material.
    pub materials: Vec<Material>,
    /// Lights in declaration order.
    pub lights: Vec<Light>,
    /// The camera.
    pub camera: Camera,
    /// Render settings.
    pub settings: Settings,
    /// Where the scene's origin lies in the coordinates it was written in: zero, unless the
    /// scene was moved to put a far camera at the origin ([`super::recentre`]). Patterns are
    /// laid out in the written coordinates, at p + origin.
    pub origin: V3,
    /// The limits the scene was checked within: the passes after the checker (the choice of
    /// method, the kernel's data) read theirs from here.
    pub limits: Limits,
    /// The animation the `render` block states, the time the scene was checked at, and
    /// whether anything in it read the time `t`.
    pub animation: Animation,
    /// The parameters (`param`), in the order of the source, with the values checked.
    pub params: Vec<super::params::Parameter>,
}

/// A scene's animation (docs/animation.md): frame `k` is the scene checked at the time
/// `k / fps` seconds. A scene that never reads `t` is a still: every frame is the same.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Animation {
    /// Frames per second (`render { fps }`).
    pub fps: f64,
    /// Length of the sequence in seconds (`render { duration }`); 0 for none.
    pub duration: f64,
    /// The time `t` the scene was checked at, in seconds.
    pub time: f64,
    /// Where the checker first read `t` (outside function bodies checked on their own);
    /// `None` when nothing did: the scene is a still.
    pub reads_time: Option<crate::span::Span>,
}

impl Default for Animation {
    fn default() -> Self {
        Animation {
            fps: 30.0,
            duration: 0.0,
            time: 0.0,
            reads_time: None,
        }
    }
}

impl Animation {
    /// The number of frames the `render` block states: `fps × duration`, rounded.
    pub fn frames(&self) -> u64 {
        (self.fps * self.duration).round() as u64
    }

    /// The time of frame `k`, in seconds.
    pub fn time_of(fps: f64, k: u64) -> f64 {
        k as f64 / fps
    }

    /// Whether the scene reads `t` (otherwise every frame is the same).
    pub fn animated(&self) -> bool {
        self.reads_time.is_some()
    }
}

impl Scene {
    /// The ε rays are marched with ([`Settings::hit_epsilon`] for this scene's camera).
    pub fn epsilon(&self) -> f64 {
        self.settings.hit_epsilon(self.camera.fov)
    }

    /// Where a checker of cells of edge `size` starts at the scene's origin, in cells: the
    /// written pattern at p + origin is the pattern at p / size + shift. The origin is
    /// reduced modulo two cells (which keeps the parity) so that the shift stays small and
    /// exact in f32.
    pub fn checker_shift(&self, size: f64) -> V3 {
        self.origin.map(|o| o.rem_euclid(2.0 * size) / size)
    }

    /// The material behind an id.
    pub fn material(&self, id: MaterialId) -> &Material {
        &self.materials[id.0 as usize]
    }

    /// The scene's objects as a tree, when they have more nodes than its `expansion` limit.
    pub fn over_expanded(&self) -> Option<Expansion> {
        let root = self.root?;
        self.graph
            .over_expanded(root, self.limits.get(Limit::Expansion))
    }

    /// The E0507 error of a scene over its `expansion` limit.
    pub fn expansion_error(&self, e: &Expansion) -> Diagnostic {
        self.graph.expansion_error(e, &self.limits)
    }
}
