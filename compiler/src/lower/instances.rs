//! The instances of a scene's root union, split from the rest of its distance program: a back
//! end that evaluates them as data (`back::wgsl::march`) instead of as code computes the same
//! field as `min(rest, instances)`, with the nearer one's material.
//!
//! An instance is a child of the simplified root union that is paint ∘ translate ∘ rotate (any
//! of them, in that order, as `simplify` leaves them) of a sphere, box, round box, torus,
//! capped cylinder, capsule or cone, whose field the analysis proves an exact distance (L = 1).
//! `simplify` absorbs every uniform scale of these primitives into their sizes (the checker
//! allows only positive factors), so a scale node above one never reaches this; a child with
//! one stays in the rest. With L = 1 the lowering neither divides an instance by a local L
//! nor raises it to a bound, so its value is the primitive's formula of `shapes.rs` at the
//! transformed point, and, exact, it is at least the signed distance to any box around it
//! (which exact culling needs). The ellipsoid's field is only a bound, so an ellipsoid stays
//! in the rest.

use super::{lower_simple, shapes, LowerOptions, Program, Simplified};
use crate::program::builder::{Builder, Param};
use crate::scene::analysis::Analysis;
use crate::scene::bounds::Bounds;
use crate::scene::{Combine, Exactness, Graph, MaterialId, Node, NodeId, V3};

/// One instance: `shape` evaluated at `rotate(p) − offset`.
#[derive(Debug, Clone, PartialEq)]
pub struct Instance {
    /// The primitive (one of the kinds listed in the module's header), in its own frame.
    pub shape: Node,
    /// Subtracted from the (rotated) point: the translation, rotated into the local frame
    /// when there is a rotation (`Mᵀt`, as the lowering computes it).
    pub offset: V3,
    /// The rotation's matrix `M` (rows), whose transpose maps the point: `q_j = Σ_i p_i·M_ij`.
    pub rotation: Option<[V3; 3]>,
    /// The paint, if any (unpainted shapes get material 0, as in the program).
    pub material: Option<MaterialId>,
    /// A world-space box around the solid (low and high corners): the field is at least the
    /// distance to it.
    pub aabb: (V3, V3),
}

/// A scene's distance program without its root union's instances, and those instances.
#[derive(Debug, Clone)]
pub struct Split {
    /// The program of everything else (the scene's field where it has no instances).
    pub rest: Program,
    /// The instances, in the order of the root union's children.
    pub instances: Vec<Instance>,
}

/// The distance of an instance's primitive as a program of the point in its frame, with its
/// constants as parameters: lowered by the rules of `shapes.rs` (the lowering's own, unoptimised,
/// so that every constant stays an instruction of its own) with placeholder constants, each
/// read of one of the primitive's [`shapes::slots`] recorded. A back end writes the program
/// with those constants replaced by reads of the slots (the GPU walk's shape functions,
/// back/wgsl/march.rs), and so computes what the scene's program computes for the instance.
#[derive(Debug, Clone)]
pub struct ShapeProgram {
    /// The program: its distance is the primitive's (its material is 0).
    pub program: Program,
    /// The constants that are slots, scaled.
    pub params: Vec<Param>,
}

/// [`ShapeProgram`] of the kind of primitive `shape` is; `None` when it cannot be an instance.
pub fn shape_program(shape: &Node) -> Option<ShapeProgram> {
    shapes::slots(shape)?;
    let mut b = Builder::new(false);
    b.params = Some(Vec::new());
    let p = b.input_point();
    let d = shapes::exact(&mut b, p, shape, &[1.0; 8])?;
    let m = b.c(0.0);
    let params = b.params.take().unwrap_or_default();
    Some(ShapeProgram {
        program: b.finish(d, m),
        params,
    })
}

/// Splits the instances off the root union of a simplified scene when it has more than
/// `more_than` of them; the rest is lowered with `options` ([`super::Lowered::instances`]).
pub(super) fn split(
    simple: &Simplified,
    options: &LowerOptions,
    more_than: usize,
) -> Option<Split> {
    let whole = &simple.scene;
    let root = whole.root?;
    let Node::Combine {
        op: Combine::Union,
        children,
    } = whole.graph.node(root).clone()
    else {
        return None;
    };
    if children.len() <= more_than {
        return None;
    }
    let (mut rest, mut instances) = (Vec::new(), Vec::new());
    for c in children {
        match instance(&whole.graph, &simple.analysis, &simple.bounds, c) {
            Some(i) => instances.push(i),
            None => rest.push(c),
        }
    }
    if instances.len() <= more_than {
        return None;
    }
    let mut graph = whole.graph.clone();
    let root = match rest.len() {
        0 => None,
        1 => Some(rest[0]),
        _ => {
            let span = graph.span(root);
            let union = Node::Combine {
                op: Combine::Union,
                children: rest,
            };
            Some(graph.add(union, span))
        }
    };
    let (rest, _, _) = lower_simple(
        whole,
        graph,
        root,
        &simple.origin,
        options,
        (usize::MAX, &mut super::Phases::default()),
    );
    Some(Split { rest, instances })
}

/// Child `id` of the root union as an instance, when it is one.
fn instance(graph: &Graph, analysis: &Analysis, bounds: &Bounds, id: NodeId) -> Option<Instance> {
    let facts = analysis.facts(id);
    if facts.exactness != Exactness::Exact || analysis.node(id).step() > 1.0 {
        return None;
    }
    let bound = bounds.get(id).filter(|b| b.finite() && b.scale == 1.0)?;
    let (c, h) = (bound.aabb.c, bound.aabb.h);
    let mut out = Instance {
        shape: Node::Sphere { radius: 0.0 },
        offset: [0.0; 3],
        rotation: None,
        material: None,
        aabb: (
            [0, 1, 2].map(|k| c[k] - h[k]),
            [0, 1, 2].map(|k| c[k] + h[k]),
        ),
    };
    let mut n = id;
    if let Node::Paint { material, child } = graph.node(n) {
        out.material = Some(*material);
        n = *child;
    }
    let mut translation = None;
    if let Node::Translate { offset, child } = graph.node(n) {
        translation = Some(*offset);
        n = *child;
    }
    if let Node::Rotate { matrix, child } = graph.node(n) {
        out.rotation = Some(*matrix);
        n = *child;
    }
    out.offset = match (translation, &out.rotation) {
        // The lowering computes Mᵀ(p − t) as Mᵀp − Mᵀt.
        (Some(t), Some(m)) => [0, 1, 2].map(|j| (0..3).map(|i| t[i] * m[i][j]).sum()),
        (Some(t), None) => t,
        (None, _) => [0.0; 3],
    };
    out.shape = match graph.node(n) {
        s @ (Node::Sphere { .. }
        | Node::Box { .. }
        | Node::RoundBox { .. }
        | Node::Torus { .. }
        | Node::Cylinder { .. }
        | Node::Capsule { .. }
        | Node::Cone { .. }) => s.clone(),
        s @ Node::Prim { prim, args } => match crate::prim::placed(*prim, args) {
            Some(placed) => return Some(between(out, placed)),
            None => {
                shapes::slots(s)?;
                s.clone()
            }
        },
        _ => return None,
    };
    Some(out)
}

/// An instance whose shape is a shape between two points (`prim::placed`): its shape along y,
/// the frame of its segment composed with the rotation and offset above it. Above, the point
/// is q' = Aᵀp − o (A the instance's rotation, the identity when it has none); the shape reads
/// R(q' − mid) (R the frame's rows), which is (A·Rᵀ)ᵀp − R(o + mid).
fn between(mut out: Instance, placed: crate::prim::Placed) -> Instance {
    let (r, mid) = (placed.rows, placed.mid);
    let a = out
        .rotation
        .unwrap_or([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    out.rotation =
        Some([0, 1, 2].map(|i| [0, 1, 2].map(|k| (0..3).map(|j| a[i][j] * r[k][j]).sum())));
    let o = [0, 1, 2].map(|j| out.offset[j] + mid[j]);
    out.offset = [0, 1, 2].map(|k| (0..3).map(|j| r[k][j] * o[j]).sum());
    out.shape = match placed.shape {
        crate::prim::AlongY::Cylinder {
            radius,
            half_height,
        } => Node::Cylinder {
            radius,
            half_height,
        },
        crate::prim::AlongY::Capsule {
            radius,
            half_height,
        } => Node::Capsule {
            radius,
            half_height,
        },
        crate::prim::AlongY::Entry(prim, args) => Node::Prim { prim, args },
    };
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lower::lower_scene;
    use crate::scene::Scene;

    fn scene(text: &str) -> Scene {
        let (scene, diags, _) = crate::front::check_str("split.sdf", text);
        scene.unwrap_or_else(|| panic!("{diags:?}"))
    }

    /// Exact primitives under paint, translation and rotation are instances; a plane, a
    /// twisted shape and an ellipsoid (a bound) stay in the rest; too few instances, or a
    /// program lowered as written, give no split.
    #[test]
    fn instances_are_exact_children_of_the_root_union() {
        let s = scene(
            "material red = phong { color: (1, 0, 0) };\n\
             scene {\n  plane();\n  box((1, 1, 1)).twist(0.5);\n  ellipsoid((1, 2, 3));\n\
             for i in 0..6 { sphere(0.5).translate(i * 3, 0, 0) @ red; }\n\
             box((0.2, 0.3, 0.4)).rotate_y(30deg).translate(0, 2, 0);\n\
             torus(1, 0.2).rotate_x(20deg) @ red;\n  cone(0.5, 1).translate(0, 0, 5);\n}\n",
        );
        let lowered = lower_scene(&s, &LowerOptions::default());
        let split = lowered.instances(3).expect("more than 3 instances");
        assert_eq!(split.instances.len(), 9);
        let rotated = split.instances.iter().filter(|i| i.rotation.is_some());
        assert_eq!(rotated.count(), 2);
        let painted = split.instances.iter().filter(|i| i.material.is_some());
        assert_eq!(painted.count(), 7);
        let text = split.rest.dump();
        assert!(text.contains("plane") && text.contains("twist") && text.contains("ellipsoid"));
        assert!(!text.contains("torus") && !text.contains("cone") && !text.contains("sphere"));
        assert!(lowered.instances(9).is_none());
        assert!(lower_scene(&s, &LowerOptions::level(0))
            .instances(3)
            .is_none());
    }

    /// The field of `i` at `p` as a back end that walks instances computes it (in f64): the
    /// point in its frame, then its shape's program with its slots.
    fn instance_distance(i: &Instance, p: [f64; 3]) -> f64 {
        let m = i
            .rotation
            .unwrap_or([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
        let q = [0, 1, 2].map(|j| (0..3).map(|k| p[k] * m[k][j]).sum::<f64>() - i.offset[j]);
        let slots = shapes::slots(&i.shape).expect("an instance kind");
        let mut b = Builder::new(false);
        let at = b.input_point();
        let d = shapes::exact(&mut b, at, &i.shape, &slots).expect("exact");
        let zero = b.c(0.0);
        crate::eval::eval_point(&b.finish(d, zero), q).0
    }

    /// Cones, round cones, cylinders and segments between two points are instances, also under paint,
    /// translation, rotation and a uniform scale (absorbed into their points and radii): the
    /// minimum of the instances' fields, each its shape along y in the frame of its segment,
    /// is the scene's program's (up to rounding) at points all around them.
    #[test]
    fn shapes_between_points_are_instances_with_the_programs_field() {
        let s = scene(
            "material red = phong { color: (1, 0, 0) };\n\
             scene {\n\
             for i in 0..5 {\n\
               cone((i, 0, 0), (i + 0.3, 1, 0.2 * i), 0.3, 0.1 * i);\n\
               round_cone((0, i, 1), (0.5, i + 0.7, 1.5), 0.2, 0.1) @ red;\n\
               cylinder((2, 0, i), (2, 0.01 * i, i + 0.8), 0.15);\n\
               segment((-1, i, 2), (-1.5, i + 0.3, 2.4), 0.1);\n\
               union(cone((0, 0, 0), (0, 1, 0), 0.2, 0.1), round_cone((0, 1, 0), (0.3, 2, 0.1), 0.1, 0.05))\n\
                 .scale(0.7).rotate_z(35deg).rotate_y(i * 70deg).translate(-2, i, -1);\n\
             }\n}\n",
        );
        let lowered = lower_scene(&s, &LowerOptions::default());
        let split = lowered.instances(3).expect("instances");
        assert_eq!(split.instances.len(), 30);
        assert!(
            split.rest.dump().lines().count() < 10,
            "{}",
            split.rest.dump()
        );
        let kinds = |name: &str| {
            split
                .instances
                .iter()
                .filter(|i| i.shape.kind() == name)
                .count()
        };
        assert_eq!((kinds("capped_cone"), kinds("round_cone")), (10, 10));
        assert_eq!((kinds("cylinder"), kinds("capsule")), (5, 5));
        let mut rng = crate::Rng::new(7);
        for _ in 0..2000 {
            let p = [0, 1, 2].map(|_| rng.range(-4.0, 7.0));
            let whole = crate::eval::eval_point(&lowered.program, p).0;
            let walked = split
                .instances
                .iter()
                .map(|i| instance_distance(i, p))
                .fold(f64::INFINITY, f64::min);
            // A segment's formula is not the capsule's: equal up to rounding.
            assert!((whole - walked).abs() < 1e-9, "at {p:?}: {whole} {walked}");
        }
    }

    /// The tree of examples/scaling/tree.sdf grows with its parts as a hierarchy should, by
    /// counting, not timing: at 3 to 6 levels (67 to 1 822 parts) its program (the CPU's, its
    /// unions' guarded blocks) spends about the same number of instructions a part, so it grows
    /// linearly, not quadratically; its marched kernel walks the parts from `scene_data`, so
    /// the kernel's text is the same at 607 parts as at 1 822 but for a few numbers, and only the walk's stack
    /// grows, with log₂ of the parts; and the buffer grows linearly.
    #[test]
    fn the_trees_program_grows_linearly_and_its_kernel_not_at_all() {
        let text = include_str!("../../../examples/scaling/tree.sdf");
        assert!(text.contains("let levels = 6;"));
        let mut per_part = Vec::new();
        let mut kernels = Vec::new();
        for levels in 3..=6 {
            let s = scene(&text.replace("let levels = 6;", &format!("let levels = {levels};")));
            let lowered = lower_scene(&s, &LowerOptions::default());
            // A trunk and `levels` levels of three children, and a leaf on each tip.
            let branches: usize = (0..=levels).map(|l| 3usize.pow(l)).sum();
            let parts = branches + 3usize.pow(levels);
            let split = lowered.instances(0).expect("instances");
            assert_eq!(split.instances.len(), parts, "{levels} levels");
            per_part.push(lowered.program.len() as f64 / parts as f64);
            let kernel = crate::back::wgsl::write(&s, &lowered).expect("a kernel");
            if parts > crate::back::wgsl::MAX_INSTANCES {
                let data = kernel.data.as_ref().expect("the parts in scene_data");
                let stack = kernel
                    .source
                    .split("var stack: array<u32, ")
                    .nth(1)
                    .and_then(|t| t.split('>').next())
                    .and_then(|n| n.parse::<usize>().ok())
                    .expect("the walk's stack");
                assert!(stack <= (parts as f64 / 4.0).log2().ceil() as usize + 1);
                kernels.push((parts, kernel.source.len(), data.len(), stack));
            }
        }
        let (least, most) = per_part
            .iter()
            .fold((f64::INFINITY, 0.0_f64), |(a, b), &x| (a.min(x), b.max(x)));
        assert!(most < 1.3 * least, "instructions a part: {per_part:?}");
        let [(p0, k0, d0, s0), (p1, k1, d1, s1)] = kernels[..] else {
            panic!("two trees walked: {kernels:?}")
        };
        // The same text but its numbers (the walk's stack, the camera's reach).
        assert!(k0.abs_diff(k1) < 64, "the kernel's text: {kernels:?}");
        let (ratio, bytes) = (p1 as f64 / p0 as f64, d1 as f64 / d0 as f64);
        assert!(bytes > 0.9 * ratio && bytes < 1.1 * ratio, "{kernels:?}");
        assert!(s1 > s0 && s1 <= s0 + 2, "{kernels:?}");
    }
}
