//! Paint that moves with its shape (docs/language.md, "Colour fields"): a material's colour
//! fields are evaluated in the coordinates of the shape the `@` paints. [`place`] walks the
//! scene from its root, gathers the maps from the world to each `@` (a [`Frame`] each:
//! translations, rotations, scales and shears as one affine map, mirrors, repetitions), and
//! gives each painted shape whose colour is a field under such maps a material of its own that
//! carries them ([`Material::frame`]). The lowering applies them to the hit point, and to the
//! normal, before the field's body.

use super::frame::Frame;
use super::ir::{Colour, Material, MaterialId, Node, Scene, V3};
use super::NodeId;
use std::collections::HashMap;

/// The map of a node to its child, where the colour's point follows it; `None` for a node
/// that leaves the coordinates as they are, or that a colour field does not follow (the
/// deformations: `twist`, `bend`, `wrap`, `taper`, `elongate`, `repeat_polar`, and the
/// solids made of profiles), whose painted shapes keep the coordinates outside it.
fn frame_of(node: &Node) -> Option<Frame> {
    const I: [V3; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let diagonal = |d: V3| [[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]];
    let linear = |matrix: [V3; 3]| {
        Some(Frame::Affine {
            matrix,
            offset: [0.0; 3],
        })
    };
    match node {
        Node::Translate { offset, .. } => Some(Frame::Affine {
            matrix: I,
            offset: offset.map(|x| -x),
        }),
        // The child's point is Mᵀp (`rotate` in lower/shapes.rs).
        Node::Rotate { matrix, .. } => linear([0, 1, 2].map(|i| [0, 1, 2].map(|j| matrix[j][i]))),
        Node::Scale { factor, .. } => linear(diagonal([1.0 / factor; 3])),
        Node::ScaleXyz { factors, .. } => linear(diagonal(factors.map(|f| 1.0 / f))),
        Node::Shear { matrix, .. } => super::analysis::invert(matrix).and_then(linear),
        Node::Mirror { axes, .. } => Some(Frame::Mirror(*axes)),
        Node::Repeat { period, count, .. } => Some(Frame::Repeat {
            period: *period,
            count: *count,
        }),
        _ => None,
    }
}

/// Gives every painted shape whose material has a colour field, under maps from the world
/// ([`Frame`]), a copy of its material that carries them: the root down, each node rebuilt
/// where a material below it changed. Materials applied in the world's coordinates (at the
/// top of the scene, or under nothing but combinations) keep theirs: such a scene is unchanged.
///
/// Only the subtrees that paint with a colour field are walked (a shape shared under many
/// placements is met once per distinct chain of maps above it, and a scene of 2³⁰ leaves as a
/// tree of shared shapes is 60 nodes). `Err(max)` where that walk would meet more than `max`
/// nodes under their maps (the scene is then left as it was).
pub fn place(scene: &mut Scene, max: usize) -> Result<(), usize> {
    let Some(root) = scene.root else {
        return Ok(());
    };
    let mut walk = Walk {
        copies: Vec::new(),
        memo: HashMap::new(),
        fields: HashMap::new(),
        max,
    };
    let materials = scene.materials.len();
    match walk.node(scene, root, &[]) {
        Some(new) => {
            scene.root = Some(new);
            Ok(())
        }
        None => {
            // Nothing the walk made is reachable from the root; its materials are dropped.
            scene.materials.truncate(materials);
            Err(max)
        }
    }
}

/// The state of [`place`]: the copies of materials made so far, each node rebuilt under
/// the frames it was met under, and which subtrees paint with a colour field.
struct Walk {
    /// (material, frames, the copy's id).
    copies: Vec<(MaterialId, Vec<Frame>, MaterialId)>,
    memo: HashMap<(NodeId, String), NodeId>,
    fields: HashMap<NodeId, bool>,
    /// The most (node, frames) pairs the walk may meet.
    max: usize,
}

impl Walk {
    /// Whether the subtree of `id` paints a shape with a colour field (once per node).
    fn paints_field(&mut self, scene: &Scene, id: NodeId) -> bool {
        if let Some(&f) = self.fields.get(&id) {
            return f;
        }
        let node = scene.graph.node(id);
        let here =
            matches!(node, Node::Paint { material, .. } if has_field(scene.material(*material)));
        let f = here
            || (!matches!(node, Node::Field { .. })
                && stacker::maybe_grow(64 * 1024, 1024 * 1024, || {
                    node.children()
                        .into_iter()
                        .any(|c| self.paints_field(scene, c))
                }));
        self.fields.insert(id, f);
        f
    }

    /// Node `id` met under `frames` (outermost first), rebuilt where a material below it
    /// is copied; `None` once more than [`Walk::max`] nodes were met.
    fn node(&mut self, scene: &mut Scene, id: NodeId, frames: &[Frame]) -> Option<NodeId> {
        if !self.paints_field(scene, id) {
            return Some(id);
        }
        let key = (id, format!("{frames:?}"));
        if let Some(&m) = self.memo.get(&key) {
            return Some(m);
        }
        if self.memo.len() >= self.max {
            return None;
        }
        let mut node = scene.graph.node(id).clone();
        let inner = match frame_of(&node) {
            Some(f) => push(frames, f),
            None => frames.to_vec(),
        };
        if let Node::Paint { material, .. } = &mut node {
            if !frames.is_empty() && has_field(scene.material(*material)) {
                *material = self.copy(scene, *material, frames);
            }
        }
        let mut changed =
            matches!(&node, Node::Paint { material, .. } if Some(*material) != painted(scene, id));
        // The children: a field's shapes (read through `distance`) keep their own points and
        // are left as they are.
        if !matches!(node, Node::Field { .. }) {
            let children = node.children();
            let mut new = Vec::with_capacity(children.len());
            for c in &children {
                let n =
                    stacker::maybe_grow(64 * 1024, 1024 * 1024, || self.node(scene, *c, &inner))?;
                new.push(n);
            }
            if new != children {
                changed = true;
                replace_children(&mut node, &new);
            }
        }
        let out = if changed {
            let span = scene.graph.span(id);
            scene.graph.add(node, span)
        } else {
            id
        };
        self.memo.insert(key, out);
        Some(out)
    }

    /// The copy of `material` under `frames`, made once.
    fn copy(&mut self, scene: &mut Scene, material: MaterialId, frames: &[Frame]) -> MaterialId {
        if let Some((_, _, id)) = self
            .copies
            .iter()
            .find(|(m, f, _)| *m == material && f == frames)
        {
            return *id;
        }
        let mut m = scene.material(material).clone();
        m.frame = frames.to_vec();
        let id = MaterialId(scene.materials.len() as u32);
        scene.materials.push(m);
        self.copies.push((material, frames.to_vec(), id));
        id
    }
}

/// `frames` followed by `f`, an affine map joined to an affine last one.
fn push(frames: &[Frame], f: Frame) -> Vec<Frame> {
    let mut out = frames.to_vec();
    match out.last().and_then(|last| last.then(f)) {
        Some(joined) => *out.last_mut().expect("a last frame") = joined,
        None => out.push(f),
    }
    out
}

/// Whether a material's colour is, or has, a colour field.
fn has_field(m: &Material) -> bool {
    m.pattern
        .colours()
        .iter()
        .any(|c| matches!(c, Colour::Field(_)))
}

/// The material node `id` paints with, where it is paint.
fn painted(scene: &Scene, id: NodeId) -> Option<MaterialId> {
    match scene.graph.node(id) {
        Node::Paint { material, .. } => Some(*material),
        _ => None,
    }
}

/// Puts `new` in place of the children of `node`, in the order [`Node::children`] gives them.
fn replace_children(node: &mut Node, new: &[NodeId]) {
    match node {
        Node::Combine { children, .. } => children.copy_from_slice(new),
        Node::SmoothCombine { a, b, .. }
        | Node::Morph { a, b, .. }
        | Node::Feature { a, b, .. } => (*a, *b) = (new[0], new[1]),
        Node::Loft { bottom, top, .. } => (*bottom, *top) = (new[0], new[1]),
        _ => {
            if let Some(child) = node.child_mut() {
                *child = new[0];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::front::check_str;
    use crate::lower::Lowered;
    use crate::scene::Scene;

    /// The scene of the one object `object`, which may paint with the material `m` of
    /// [`STRIPES`].
    fn striped(object: &str) -> Scene {
        let (scene, diags, _) = check_str("t.sdf", &format!("{STRIPES}scene {{ {object}; }}"));
        scene.unwrap_or_else(|| panic!("{diags:?}"))
    }

    /// The colour of the colour field of material `id` at `p` where the normal is `n`.
    fn colour(lowered: &Lowered, id: usize, p: [f64; 3], n: [f64; 3]) -> [f64; 3] {
        let k = lowered.colours.fields[id][0].expect("a colour field");
        lowered.colours.programs[k].eval(p, n)
    }

    const STRIPES: &str = "material m = phong { color: field { vec3(fract(p.x), fract(2 * p.y), 0.5 + 0.5 * n.z) } };\n";

    /// A chain of shapes each placed twice (2^k placements of the first at level k): without
    /// paint the walk is skipped (30 levels took minutes and gigabytes: the scene is refused
    /// by the `expansion` limit, quickly), and with a colour field at the leaves it stops at
    /// the `nodes` limit with the limit's error.
    #[test]
    fn a_shape_placed_exponentially_often_is_bounded() {
        let chain = |levels: usize, leaf: &str| {
            let mut text = format!("{STRIPES}fn g0() -> shape {{ {leaf} }}\n");
            for k in 1..=levels {
                text += &format!(
                    "fn g{k}() -> shape {{ smooth_union(0.1, g{}().translate(0.01, 0, 0), g{}().rotate_y(1deg)) }}\n",
                    k - 1,
                    k - 1
                );
            }
            text + &format!("scene {{ g{levels}(); }}\n")
        };
        let check = |text: String, nodes: u64| {
            let mut limits = crate::limits::Limits::default();
            limits
                .set(crate::limits::Limit::Nodes, nodes)
                .expect("a valid limit");
            let mut sources = crate::span::SourceMap::new();
            let entry = sources.add("t.sdf", text);
            crate::front::check_with(&mut sources, entry, &mut crate::check::NoImports, &limits)
        };
        let started = std::time::Instant::now();
        let (_, diags) = check(chain(30, "sphere(0.3)"), 1_000_000);
        assert!(
            diags
                .iter()
                .any(|d| d.message.contains("expand to more than")),
            "{diags:?}"
        );
        assert!(started.elapsed().as_secs() < 10, "{:?}", started.elapsed());
        let (painted, diags) = check(chain(12, "sphere(0.3) @ m"), 1_000);
        assert!(painted.is_none(), "{diags:?}");
        assert!(
            diags.iter().any(|d| d
                .message
                .contains("painting each shape in its own coordinates")),
            "{diags:?}"
        );
        let (painted, diags) = check(chain(6, "sphere(0.3) @ m"), 1_000);
        assert!(painted.is_some(), "{diags:?}");
    }

    #[test]
    fn a_painted_shape_moved_afterwards_takes_its_pattern_along() {
        let s = striped("(sphere(1) @ m).rotate_y(90deg).translate(3, 0.25, 0)");
        // The copy of m, carrying the rotation and the translation.
        assert_eq!(s.materials.len(), 3);
        let lowered = Lowered::new(&s);
        // rotate_y(90deg) turns +x into −z: the shape's (x, y, z) is at (3 + z, 0.25 + y, −x).
        for (q, nq) in [
            ([0.3, 0.1, -0.2], [0.0, 0.0, 1.0]),
            ([0.7, -0.4, 0.5], [0.6, 0.0, 0.8]),
        ] {
            let p = [3.0 + q[2], 0.25 + q[1], -q[0]];
            let n = [nq[2], nq[1], -nq[0]];
            let want = colour(&lowered, 1, q, nq);
            let got = colour(&lowered, 2, p, n);
            for i in 0..3 {
                assert!((got[i] - want[i]).abs() < 1e-12, "{got:?} {want:?}");
            }
        }
    }

    #[test]
    fn a_material_applied_in_the_world_keeps_the_world_coordinates() {
        // Painted outside its transforms, at the top of the scene: the scene is as it was.
        let s = striped("sphere(1).rotate_y(90deg).translate(3, 0.25, 0) @ m");
        assert_eq!(s.materials.len(), 2);
        assert!(s.materials[1].frame.is_empty());
    }

    #[test]
    fn the_normal_turns_with_the_shape_under_a_scale_per_axis_and_a_mirror() {
        let s = striped("(sphere(1) @ m).scale((2, 1, 1)).mirror(x: true)");
        let lowered = Lowered::new(&s);
        // At world x < 0 the mirror folds x; the scale halves it. A world normal (a, b, c)
        // becomes (−2a, b, c)/|…| in the sphere's coordinates, its z read as 0.5 + 0.5 n.z.
        let n = [0.6, 0.0, 0.8];
        let got = colour(&lowered, 2, [-1.2, 0.3, 0.1], n);
        let nz = 0.8 / (4.0f64 * 0.36 + 0.64).sqrt();
        assert!((got[0] - 0.6).abs() < 1e-12, "{got:?}");
        assert!((got[2] - (0.5 + 0.5 * nz)).abs() < 1e-12, "{got:?}");
    }

    #[test]
    fn copies_of_a_repeated_painted_shape_each_show_the_pattern_of_their_own() {
        let s = striped("(sphere(0.4) @ m).repeat((2, 0, 0))");
        let lowered = Lowered::new(&s);
        let n = [0.0, 1.0, 0.0];
        let a = colour(&lowered, 2, [0.25, 0.2, 0.0], n);
        let b = colour(&lowered, 2, [4.25, 0.2, 0.0], n);
        assert_eq!(a, b);
    }
}
