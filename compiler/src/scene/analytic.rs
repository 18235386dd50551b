//! Which scenes can be ray traced analytically, and their primitives in world space.
//!
//! A scene qualifies when its objects are only spheres, planes, boxes, capped cylinders,
//! capsules and triangle meshes used as they are read (`mesh(path)`, met through their
//! hierarchy, triangle by triangle) under affine transforms (translate, rotate, uniform and
//! per-axis scale), painted
//! and combined by plain union, no light asks for soft shadows (a penumbra estimate needs a
//! distance field) and no glass overlaps other glass. Every ray then has closed-form roots: exact hits, exact normals, no step
//! budget and no ε. The CPU renderer and the WGSL kernel (so also PTX) both trace the list of
//! [`Primitive`]s this module produces (docs/rendering.md, "Analytic ray tracing").

pub use super::ir::MeshRef;
use super::ir::{Combine, MaterialId, Method, Node, Scene, V3};
use super::NodeId;
use crate::limits::{Limit, Limits};
use crate::span::Span;

/// A primitive with a closed-form ray intersection, in its local frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// Sphere of a radius about the origin.
    Sphere { radius: f64 },
    /// Box of half-extents about the origin.
    Box { half: V3 },
    /// Capped cylinder along y.
    Cylinder { radius: f64, half_height: f64 },
    /// Capsule along y: the segment |y| <= half_height swept by a radius.
    Capsule { radius: f64, half_height: f64 },
    /// Half-space `dot(p, normal) <= height` (unit normal).
    Plane { normal: V3, height: f64 },
    /// The triangle mesh `Traced::meshes[index]`, whose triangles lie in the box from `lo`
    /// to `hi`. Not convex: a ray's hit is the nearest triangle it crosses, found through the
    /// mesh's hierarchy; its normal is the triangle's.
    Mesh { index: u32, lo: V3, hi: V3 },
}

/// One primitive of an analytic scene: its shape, the affine map from world to its local
/// frame (`local = matrix · world + offset`, rows of `matrix`), and its material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Primitive {
    pub shape: Shape,
    pub matrix: [V3; 3],
    pub offset: V3,
    pub material: MaterialId,
    /// The primitive's node (for comments in generated code).
    pub node: NodeId,
}

/// What a scene is rendered with, and why.
#[derive(Debug, Clone, PartialEq)]
pub enum Choice {
    /// Analytic ray tracing of these primitives.
    Trace(Vec<Primitive>),
    /// Sphere tracing, for the reason given.
    March(Reason),
}

/// Why a scene is sphere traced.
#[derive(Debug, Clone, PartialEq)]
pub enum Reason {
    /// The render asks for it (`method: "march"`).
    Asked,
    /// A node has no closed-form ray intersection.
    Node { what: &'static str, span: Span },
    /// A light casts soft shadows.
    SoftLight { index: usize },
    /// The render asks for ambient occlusion, which samples the distance field.
    Occlusion,
    /// The render asks for a glow of the marching steps, which it needs.
    Glow,
    /// Too many primitives for `auto` to trace them from one GPU buffer: more than `limit`,
    /// the `traced` limit.
    Many { count: usize, limit: usize },
    /// A transparent primitive overlaps or touches another transparent one: a ray inside both
    /// must leave through the boundary of their union, which tracing primitive by primitive
    /// does not find. (Glass may overlap opaque primitives: a ray inside it stops at the
    /// nearer of the glass's far side and an opaque primitive's entry.)
    Overlap { span: Span },
}

impl Reason {
    /// The reason in words, naming no front end's options (the language server shows it as
    /// it is).
    pub fn describe(&self) -> String {
        match self {
            Reason::Asked => "the render sets `method: \"march\"`".into(),
            Reason::Node { what, .. } => format!("`{what}` has no closed-form ray intersection"),
            Reason::SoftLight { index } => {
                format!(
                    "light {} casts soft shadows, which need a distance field",
                    index + 1
                )
            }
            Reason::Occlusion => {
                "the render asks for ambient `occlusion`, which samples a distance field".into()
            }
            Reason::Glow => {
                "the render asks for a `glow` of the marching steps, which a march takes".into()
            }
            Reason::Overlap { .. } => {
                "a transparent primitive overlaps or touches another transparent one, so rays inside them would need the boundary of their union".into()
            }
            Reason::Many { count, limit } => format!(
                "{count} primitives, more than the `traced` limit of {limit}: their data would outgrow a GPU storage buffer"
            ),
        }
    }

    /// [`Reason::describe`], and for a limit how to raise it as `limits` spells its options
    /// (`--limit traced=N` on the command line, `limits={"traced": N}` in Python).
    pub fn describe_in(&self, limits: &Limits) -> String {
        match self {
            Reason::Many { count, .. } => format!(
                "{}; {}",
                self.describe(),
                limits.raise_to(Limit::Traced, *count as u64)
            ),
            other => other.describe(),
        }
    }
}

impl Choice {
    /// The primitives, when the scene is traced analytically.
    pub fn primitives(&self) -> Option<&[Primitive]> {
        match self {
            Choice::Trace(p) => Some(p),
            Choice::March(_) => None,
        }
    }

    /// One line for `sdfc check`: the method and why.
    pub fn describe(&self) -> String {
        match self {
            Choice::Trace(p) => format!(
                "method: trace ({} primitive{} with closed-form intersections, in a plain union)",
                p.len(),
                if p.len() == 1 { "" } else { "s" }
            ),
            Choice::March(r) => format!("method: march ({})", r.describe()),
        }
    }

    /// [`Choice::describe`] with a limit's option spelled as `limits` spell it
    /// ([`Reason::describe_in`]).
    pub fn describe_in(&self, limits: &Limits) -> String {
        match self {
            Choice::March(r) => format!("method: march ({})", r.describe_in(limits)),
            trace => trace.describe(),
        }
    }
}

/// Decides how `scene` is rendered: [`traceable`] and then [`Traceable::choose`] with the
/// scene's own settings.
pub fn choose(scene: &Scene) -> Choice {
    traceable(scene).choose(scene.settings.method)
}

/// What decides a scene's method apart from its render settings: its primitives, or why it
/// has none, and a transparent primitive that overlaps another transparent one. Computed once per scene (by
/// the lowering, [`crate::lower::Lowered`]); the `method` setting, which a command may set
/// after checking, then picks with [`Traceable::choose`].
#[derive(Debug, Clone, PartialEq)]
pub struct Traceable {
    /// The primitives in world space and their hierarchy, or why some node or light rules
    /// tracing out.
    primitives: Result<Traced, Reason>,
    /// A transparent primitive that overlaps or touches another transparent one (its node's
    /// span).
    overlap: Option<Span>,
    /// The `traced` limit of the scene's limits.
    limit: usize,
}

/// The primitives of a traceable scene and their bounding-volume hierarchy ([`hierarchy`]),
/// built once for every back end.
#[derive(Debug, Clone, PartialEq)]
pub struct Traced {
    /// The primitives in world space.
    pub primitives: Vec<Primitive>,
    /// Their hierarchy (indices into `primitives`).
    pub hierarchy: Vec<Item>,
    /// The triangle meshes [`Shape::Mesh`] primitives name, by index.
    pub meshes: Vec<MeshRef>,
}

/// The primitives of `scene` and what rules tracing out, whatever its `method`.
pub fn traceable(scene: &Scene) -> Traceable {
    let limit = scene.limits.count(Limit::Traced);
    if let Some(index) = scene
        .lights
        .iter()
        .position(|l| l.penumbra() > 0.0 && l.shadows())
    {
        return Traceable {
            primitives: Err(Reason::SoftLight { index }),
            overlap: None,
            limit,
        };
    }
    if scene.settings.occlusion > 0.0 {
        return Traceable {
            primitives: Err(Reason::Occlusion),
            overlap: None,
            limit,
        };
    }
    if scene.settings.glow > 0.0 {
        return Traceable {
            primitives: Err(Reason::Glow),
            overlap: None,
            limit,
        };
    }
    let mut out = Vec::new();
    let mut meshes = Vec::new();
    if let Some(root) = scene.root {
        let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let frame = Frame {
            matrix: identity,
            offset: [0.0; 3],
            material: MaterialId(0),
        };
        if let Err(reason) = collect(scene, root, frame, &mut out, &mut meshes) {
            return Traceable {
                primitives: Err(reason),
                overlap: None,
                limit,
            };
        }
    }
    let overlap = transparent_overlap(scene, &out).map(|p| scene.graph.span(p.node));
    let hierarchy = hierarchy(&out);
    Traceable {
        primitives: Ok(Traced {
            primitives: out,
            hierarchy,
            meshes,
        }),
        overlap,
        limit,
    }
}

impl Traceable {
    /// How a scene with this `method` setting is rendered: `march` marches; `auto` and
    /// `trace` trace when every node and light allows it. For `method: "trace"` on a scene
    /// that does not allow it, the answer is `March` with the reason, and the checker
    /// reports it as an error.
    pub fn choose(&self, method: Method) -> Choice {
        match self.decide(method) {
            Ok(traced) => Choice::Trace(traced.primitives.clone()),
            Err(reason) => Choice::March(reason),
        }
    }

    /// The primitives to trace, with their hierarchy, when a scene with this `method`
    /// setting is traced ([`Traceable::choose`] without copying them).
    pub fn traced(&self, method: Method) -> Option<&Traced> {
        self.decide(method).ok()
    }

    /// [`Traceable::choose`]: the primitives, or why the scene is marched.
    fn decide(&self, method: Method) -> Result<&Traced, Reason> {
        if method == Method::March {
            return Err(Reason::Asked);
        }
        let traced = self.primitives.as_ref().map_err(Clone::clone)?;
        let primitives = &traced.primitives;
        // The `traced` limit (limits.rs): rays visit the primitives through a bounding-volume
        // hierarchy ([`hierarchy`]), in O(log n) per ray on the CPU and on the GPU, whose
        // kernel reads a large scene's primitives and hierarchy from a buffer
        // (`back::wgsl::MAX_UNROLLED`), so tracing beats sphere tracing at any size; the
        // limit keeps that buffer within what a GPU binds. `method: "trace"` has no limit.
        if method == Method::Auto && primitives.len() > self.limit {
            return Err(Reason::Many {
                count: primitives.len(),
                limit: self.limit,
            });
        }
        if let Some(span) = self.overlap {
            return Err(Reason::Overlap { span });
        }
        Ok(traced)
    }
}

/// A transparent primitive whose box meets another transparent primitive's box or a
/// transparent plane's solid side (touching counts; boxes are conservative, so some disjoint
/// pairs are reported too). Rays are traced primitive by primitive: a ray inside glass stops
/// at the nearest of the glass's far side and the entries of the opaque primitives ahead of
/// it, which is the surface it meets whatever opaque primitives overlap the glass (it then
/// shades the opaque surface, within the glass). Inside two overlapping glass primitives,
/// the far side of one may lie inside the other, and the ray would stop at a surface that is
/// not there; only refracted rays travel inside solids, so only transparent pairs need the
/// check.
fn transparent_overlap<'a>(scene: &Scene, prims: &'a [Primitive]) -> Option<&'a Primitive> {
    let clear = |j: usize| scene.material(prims[j].material).transparency > 0.0;
    let boxes: Vec<Option<Aabb>> = prims.iter().map(world_box).collect();
    let touches = |a: &Aabb, j: usize| match (&boxes[j], &prims[j].shape) {
        (Some(b), _) => (0..3).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k]),
        (None, Shape::Plane { normal, height }) => {
            // local = M·p + c: the solid side n·local <= h is (Mᵀn)·p <= h − n·c in the world.
            let m = &prims[j].matrix;
            let n: V3 = [0, 1, 2].map(|k| (0..3).map(|i| m[i][k] * normal[i]).sum());
            let h = height - (0..3).map(|i| normal[i] * prims[j].offset[i]).sum::<f64>();
            let lowest: f64 = (0..3)
                .map(|k| n[k] * if n[k] > 0.0 { a.0[k] } else { a.1[k] })
                .sum();
            lowest <= h
        }
        (None, _) => true,
    };
    // Only transparent primitives are tested, each against the hierarchy of the bounded
    // transparent primitives' boxes (O(log n) groups per test when the scene is spread out)
    // and against the unbounded ones, so the test is not quadratic in the primitives.
    let bounded: Vec<(usize, Aabb)> = boxes
        .iter()
        .enumerate()
        .filter(|&(j, _)| clear(j))
        .filter_map(|(j, b)| b.map(|b| (j, b)))
        .collect();
    let unbounded: Vec<usize> = (0..prims.len())
        .filter(|&j| boxes[j].is_none() && clear(j))
        .collect();
    let mut tree: Option<Vec<Item>> = None;
    prims.iter().enumerate().find_map(|(i, p)| {
        if !clear(i) {
            return None;
        }
        // A transparent primitive without a finite box (a plane) overlaps every other
        // transparent one.
        let Some(a) = &boxes[i] else {
            return ((0..prims.len()).any(|j| j != i && clear(j))).then_some(p);
        };
        if unbounded.iter().any(|&j| j != i && touches(a, j)) {
            return Some(p);
        }
        let tree = tree.get_or_insert_with(|| boxed(bounded.clone()));
        any_box_meets(tree, a, &|j| j != i && touches(a, j)).then_some(p)
    })
}

/// Whether a primitive of `items` whose box meets `a` (the groups' boxes prune the search)
/// passes `test`.
fn any_box_meets(items: &[Item], a: &Aabb, test: &dyn Fn(usize) -> bool) -> bool {
    items.iter().any(|item| match item {
        Item::Primitive(j) => test(*j),
        Item::Group(g) => {
            (0..3).all(|k| a.0[k] <= g.centre[k] + g.half[k] && g.centre[k] - g.half[k] <= a.1[k])
                && any_box_meets(&g.items, a, test)
        }
    })
}

/// The world-to-local map and the material in force at a node.
#[derive(Debug, Clone, Copy)]
struct Frame {
    matrix: [V3; 3],
    offset: V3,
    material: MaterialId,
}

impl Frame {
    /// The frame of a child whose local point is `m · (this frame's local point) + c`.
    fn then(&self, m: [V3; 3], c: V3) -> Frame {
        let mut matrix = [[0.0; 3]; 3];
        let mut offset = c;
        for i in 0..3 {
            for j in 0..3 {
                matrix[i][j] = (0..3).map(|k| m[i][k] * self.matrix[k][j]).sum();
                offset[i] += m[i][j] * self.offset[j];
            }
        }
        Frame {
            matrix,
            offset,
            material: self.material,
        }
    }
}

fn diagonal(v: V3) -> [V3; 3] {
    [[v[0], 0.0, 0.0], [0.0, v[1], 0.0], [0.0, 0.0, v[2]]]
}

fn collect(
    scene: &Scene,
    id: NodeId,
    f: Frame,
    out: &mut Vec<Primitive>,
    meshes: &mut Vec<MeshRef>,
) -> Result<(), Reason> {
    let g = &scene.graph;
    let mut leaf = |shape| {
        out.push(Primitive {
            shape,
            matrix: f.matrix,
            offset: f.offset,
            material: f.material,
            node: id,
        });
        Ok(())
    };
    match g.node(id) {
        Node::Sphere { radius } => leaf(Shape::Sphere { radius: *radius }),
        Node::Box { half } => leaf(Shape::Box { half: *half }),
        Node::Cylinder {
            radius,
            half_height,
        } => leaf(Shape::Cylinder {
            radius: *radius,
            half_height: *half_height,
        }),
        Node::Capsule {
            radius,
            half_height,
        } => leaf(Shape::Capsule {
            radius: *radius,
            half_height: *half_height,
        }),
        Node::Plane { normal, height } => leaf(Shape::Plane {
            normal: *normal,
            height: *height,
        }),
        Node::Mesh { mesh } => {
            let index = match meshes.iter().position(|m| m == mesh) {
                Some(i) => i,
                None => {
                    meshes.push(mesh.clone());
                    meshes.len() - 1
                }
            };
            let (lo, hi) = mesh.0.aabb();
            leaf(Shape::Mesh {
                index: index as u32,
                lo,
                hi,
            })
        }
        Node::Combine {
            op: Combine::Union,
            children,
        } => children
            .iter()
            .try_for_each(|&c| collect(scene, c, f, out, meshes)),
        Node::Translate { offset, child } => {
            let back = offset.map(|x| -x);
            collect(scene, *child, f.then(diagonal([1.0; 3]), back), out, meshes)
        }
        // The lowering evaluates a rotated child at Mᵀp.
        Node::Rotate { matrix, child } => {
            let t = [0, 1, 2].map(|i| [0, 1, 2].map(|j| matrix[j][i]));
            collect(scene, *child, f.then(t, [0.0; 3]), out, meshes)
        }
        Node::Scale { factor, child } => {
            let s = 1.0 / factor;
            collect(
                scene,
                *child,
                f.then(diagonal([s; 3]), [0.0; 3]),
                out,
                meshes,
            )
        }
        Node::ScaleXyz { factors, child } => {
            let s = factors.map(|x| 1.0 / x);
            collect(scene, *child, f.then(diagonal(s), [0.0; 3]), out, meshes)
        }
        // Inner materials take precedence: the nearest paint above a primitive wins.
        Node::Paint { material, child } => {
            let inner = Frame {
                material: *material,
                ..f
            };
            collect(scene, *child, inner, out, meshes)
        }
        other => Err(Reason::Node {
            what: super::analysis::kind(other),
            span: g.span(id),
        }),
    }
}

/// Primitives per leaf of the hierarchy: below this, testing a group's box costs more than
/// testing its primitives.
const LEAF: usize = 4;

/// A node of the bounding-volume hierarchy over a traced scene's primitives: a world-space
/// box (centre and half-extents) around everything in it.
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    pub centre: V3,
    pub half: V3,
    pub items: Vec<Item>,
}

/// What a group holds.
#[derive(Debug, Clone, PartialEq)]
pub enum Item {
    /// A primitive, by index.
    Primitive(usize),
    /// A nested group.
    Group(Group),
}

/// The hierarchy of a traced scene: what every ray tests (unbounded primitives, such as
/// planes, and the top groups), each group only when the ray meets its box before the
/// nearest hit so far.
pub(crate) fn hierarchy(primitives: &[Primitive]) -> Vec<Item> {
    let mut top = Vec::new();
    let mut bounded = Vec::new();
    for (i, p) in primitives.iter().enumerate() {
        match world_box(p) {
            Some(b) => bounded.push((i, b)),
            None => top.push(Item::Primitive(i)),
        }
    }
    top.extend(boxed(bounded));
    top
}

/// The hierarchy over items with boxes, by index: the items themselves when there are a few,
/// else one group around them all, split at medians (the hierarchy of [`hierarchy`], and of
/// any other list of bounded things).
pub(crate) fn boxed(bounded: Vec<(usize, Aabb)>) -> Vec<Item> {
    if bounded.len() <= LEAF {
        bounded
            .into_iter()
            .map(|(i, _)| Item::Primitive(i))
            .collect()
    } else {
        vec![Item::Group(build(bounded))]
    }
}

/// An axis-aligned box as (low, high) corners.
pub(crate) type Aabb = (V3, V3);

/// Splits at the median of the box centres along the axis where they spread most (a median
/// split keeps the tree balanced: depth log₂(n / LEAF)).
fn build(mut items: Vec<(usize, Aabb)>) -> Group {
    let (lo, hi) = items.iter().fold(
        ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
        |(lo, hi), (_, (a, b))| {
            (
                [0, 1, 2].map(|k| lo[k].min(a[k])),
                [0, 1, 2].map(|k| hi[k].max(b[k])),
            )
        },
    );
    let centre = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    // Padded by a few f32 ulps of the box's size and place, so that the box written as f32
    // still contains every primitive in it.
    let pad = 1e-5
        * (0..3)
            .map(|k| centre[k].abs() + hi[k] - lo[k])
            .fold(0.0, f64::max);
    let half = [0, 1, 2].map(|k| 0.5 * (hi[k] - lo[k]) + pad);
    if items.len() <= LEAF {
        let items = items.into_iter().map(|(i, _)| Item::Primitive(i)).collect();
        return Group {
            centre,
            half,
            items,
        };
    }
    let mid = |(a, b): &Aabb, k: usize| a[k] + b[k];
    let spread = |k: usize| {
        let (mut a, mut b) = (f64::INFINITY, f64::NEG_INFINITY);
        for (_, bx) in &items {
            a = a.min(mid(bx, k));
            b = b.max(mid(bx, k));
        }
        b - a
    };
    let axis = (0..3)
        .max_by(|&a, &b| spread(a).total_cmp(&spread(b)))
        .unwrap_or(0);
    // Ties broken by index, so that the tree (and the generated code) is deterministic.
    items.sort_by(|x, y| {
        mid(&x.1, axis)
            .total_cmp(&mid(&y.1, axis))
            .then(x.0.cmp(&y.0))
    });
    let rest = items.split_off(items.len() / 2);
    let halves = [items, rest].map(|h| {
        if h.len() == 1 {
            Item::Primitive(h[0].0)
        } else {
            Item::Group(build(h))
        }
    });
    Group {
        centre,
        half,
        items: halves.into(),
    }
}

/// The world-space box around a primitive (`None` for a plane): the corners of its local box
/// mapped back to the world.
pub(crate) fn world_box(p: &Primitive) -> Option<Aabb> {
    // The local box's centre and half-extents.
    let mut c = [0.0; 3];
    let h = match p.shape {
        Shape::Mesh { lo, hi, .. } => {
            c = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
            [0, 1, 2].map(|k| 0.5 * (hi[k] - lo[k]))
        }
        Shape::Sphere { radius } => [radius; 3],
        Shape::Box { half } => half,
        Shape::Cylinder {
            radius,
            half_height,
        } => [radius, half_height, radius],
        Shape::Capsule {
            radius,
            half_height,
        } => [radius, half_height + radius, radius],
        Shape::Plane { .. } => return None,
    };
    let inv = inverse(&p.matrix)?;
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for corner in 0..8 {
        // local = M·world + c, so world = M⁻¹·(local − c).
        let local = [0, 1, 2].map(|k| {
            let s = if corner >> k & 1 == 1 { 1.0 } else { -1.0 };
            c[k] + s * h[k] - p.offset[k]
        });
        for k in 0..3 {
            let w: f64 = (0..3).map(|j| inv[k][j] * local[j]).sum();
            lo[k] = lo[k].min(w);
            hi[k] = hi[k].max(w);
        }
    }
    lo.iter()
        .chain(&hi)
        .all(|x| x.is_finite())
        .then_some((lo, hi))
}

/// The inverse of a 3×3 matrix (rows), or `None` when it is singular.
fn inverse(m: &[V3; 3]) -> Option<[V3; 3]> {
    let c = |i: usize, j: usize| {
        let (a, b) = ((i + 1) % 3, (i + 2) % 3);
        let (x, y) = ((j + 1) % 3, (j + 2) % 3);
        m[a][x] * m[b][y] - m[a][y] * m[b][x]
    };
    let det: f64 = (0..3).map(|j| m[0][j] * c(0, j)).sum();
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    // The inverse is the transposed cofactor matrix over the determinant.
    Some([0, 1, 2].map(|i| [0, 1, 2].map(|j| c(j, i) / det)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::limits::Spelling;

    /// The reason for marching many primitives names the `traced` limit without a front
    /// end's spelling (the language server shows it so); spelled for a front end, it says
    /// how to raise it there.
    #[test]
    fn the_many_primitives_reason_is_spelled_per_front_end() {
        let many = Reason::Many {
            count: 40_000,
            limit: 1_000,
        };
        let plain = many.describe();
        assert!(plain.contains("`traced` limit of 1000"), "{plain}");
        assert!(
            !plain.contains("--") && !plain.contains("limits="),
            "{plain}"
        );
        let flags = Choice::March(many.clone()).describe_in(&Limits::default());
        assert!(
            flags.starts_with("method: march (40000 primitives"),
            "{flags}"
        );
        assert!(flags.contains("`--limit traced=40000`"), "{flags}");
        let python = many.describe_in(&Limits::default().spelled(Spelling::Parameters));
        assert!(python.contains("`limits={\"traced\": 40000}`"), "{python}");
        assert!(!python.contains("--"), "{python}");
        // Other reasons have no option to name.
        assert_eq!(
            Reason::Asked.describe_in(&Limits::default()),
            Reason::Asked.describe()
        );
    }
}
