//! A scene split by material into solids that do not overlap, for mesh files with an object
//! per material (3MF, `threemf.rs`): a multi-material printer prints each object in its
//! material.
//!
//! The scene's top-level objects (the leaves of its top-level unions, through the paints
//! over them) are grouped by the material painted over them (the innermost paint wins, as
//! everywhere; unpainted: the default material), in the order each material first appears.
//! Group k's solid is the union of its objects less the solids of the groups before it, so
//! that the parts do not overlap and together are the scene's solid: where objects of two
//! materials overlap, the inside belongs to the one that came first. On the surface nothing
//! changes: a point of the scene's surface lies on one object and outside the others, and
//! its part is that object's. An object that mixes materials inside itself (a union under a
//! transform, a smooth union of painted shapes) is one object of its outer material, its
//! triangles of other materials coloured by theirs.

use sdfc_compiler::{Combine, MaterialId, Node, NodeId, Scene};

/// One part: a material and the scene whose root is that material's solid.
#[derive(Debug, Clone)]
pub struct Part {
    /// The material id.
    pub material: u32,
    /// The scene with the part's solid as its root (the same graph, with the part's nodes
    /// added).
    pub scene: Scene,
}

/// The scene's parts, one per material of its top-level objects, in the order each material
/// first appears. One part is the scene itself, unchanged.
pub fn by_material(scene: &Scene) -> Vec<Part> {
    let Some(root) = scene.root else {
        return Vec::new();
    };
    let mut graph = scene.graph.clone();
    // (material, the objects painted with it), in the order of first appearance.
    let mut groups: Vec<(u32, Vec<NodeId>)> = Vec::new();
    // Depth first, children in their order: (node, the material painted over it).
    let mut stack: Vec<(NodeId, Option<MaterialId>)> = vec![(root, None)];
    while let Some((id, paint)) = stack.pop() {
        match graph.node(id) {
            Node::Combine {
                op: Combine::Union,
                children,
            } => stack.extend(children.iter().rev().map(|&c| (c, paint))),
            // The inner paint wins: it replaces the one over it.
            &Node::Paint { material, child } => stack.push((child, Some(material))),
            _ => {
                let (material, object) = match paint {
                    Some(m) => {
                        let span = graph.span(id);
                        (
                            m.0,
                            graph.add(
                                Node::Paint {
                                    material: m,
                                    child: id,
                                },
                                span,
                            ),
                        )
                    }
                    None => (0, id),
                };
                match groups.iter_mut().find(|(m, _)| *m == material) {
                    Some((_, objects)) => objects.push(object),
                    None => groups.push((material, vec![object])),
                }
            }
        }
    }
    if groups.len() <= 1 {
        return groups
            .into_iter()
            .map(|(material, _)| Part {
                material,
                scene: scene.clone(),
            })
            .collect();
    }
    let unions: Vec<NodeId> = groups
        .iter()
        .map(|(_, objects)| match objects[..] {
            [one] => one,
            _ => {
                let span = graph.span(objects[0]);
                graph.add(
                    Node::Combine {
                        op: Combine::Union,
                        children: objects.clone(),
                    },
                    span,
                )
            }
        })
        .collect();
    let roots: Vec<NodeId> = (0..unions.len())
        .map(|k| match k {
            0 => unions[0],
            _ => {
                let span = graph.span(unions[k]);
                let children = std::iter::once(unions[k])
                    .chain(unions[..k].iter().copied())
                    .collect();
                graph.add(
                    Node::Combine {
                        op: Combine::Subtract,
                        children,
                    },
                    span,
                )
            }
        })
        .collect();
    groups
        .iter()
        .zip(roots)
        .map(|((material, _), root)| {
            let mut part = scene.clone();
            part.graph = graph.clone();
            part.root = Some(root);
            Part {
                material: *material,
                scene: part,
            }
        })
        .collect()
}
