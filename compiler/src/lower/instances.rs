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
    let d = shapes::exact(&mut b, p, shape, &[1.0; 4])?;
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
        _ => return None,
    };
    Some(out)
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
}
