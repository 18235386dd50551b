//! The nodes of the scene IR: every shape, combination, transform and modifier ([`Node`]),
//! the blends and features they name, and what each node's children are.

use super::{MaterialId, NodeId, V3};

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
        f: crate::scene::field::FieldFn,
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
pub struct PathRef(pub std::sync::Arc<crate::scene::Path>);

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
    pub(super) fn key(&self) -> String {
        format!("{self:?}")
    }
}
