//! The glass of a scene apart from its opaque solids, for rays travelling inside glass
//! (docs/rendering.md, "Inside glass").
//!
//! A refracted ray marches `−f` inside a transparent solid until it reaches the surface of the
//! union again. Where an opaque solid overlaps the glass (a glass ball sunk into the floor),
//! the union's surface does not run between the two: the ray would pass into the opaque solid
//! and never find its surface. [`media`] splits the scene's objects into the transparent ones
//! (the glass, `G`) and the others (the solids, `O`) and lowers two more programs:
//! `medium = G − O` (`max(d_G, −d_O)`), whose inside is the glass not filled by a solid, so
//! that a ray inside marching `−medium` stops at the glass's far side or at a solid's surface
//! inside the glass, whichever comes first; and `solid = O` with its materials, which tells
//! which of the two the ray reached, and the solid's normal and material there.

use super::{lower, Program};
use crate::scene::bounds::Bounds;
use crate::scene::{Combine, MaterialId, Node, NodeId, Scene};
use std::collections::HashMap;

/// The two programs of a scene whose glass may overlap an opaque solid.
#[derive(Debug, Clone)]
pub struct Media {
    /// `max(d_G, −d_O)`: negative inside the glass where no solid is.
    pub medium: Program,
    /// The opaque (or partly opaque) objects alone, with their materials.
    pub solid: Program,
}

/// The media of `scene`, or `None` when no transparent object may overlap an opaque one: a
/// scene without glass, with only glass, or whose glass objects' bounding boxes stay clear of
/// every solid's (a solid without a bound, such as a plane, counts as overlapping).
pub fn media(scene: &Scene) -> Option<Media> {
    let root = scene.root?;
    if !scene.materials.iter().any(|m| m.transparency > 0.0) {
        return None;
    }
    let mut tops = Vec::new();
    objects(scene, root, &mut tops);
    let mut memo = HashMap::new();
    let (glass, solid): (Vec<NodeId>, Vec<NodeId>) = tops
        .into_iter()
        .partition(|&id| kinds(scene, id, None, &mut memo) == TRANSPARENT);
    if glass.is_empty() || solid.is_empty() {
        return None;
    }
    let mut split = scene.clone();
    let span = scene.graph.span(root);
    let mut union = |ids: Vec<NodeId>| match ids.as_slice() {
        [one] => *one,
        _ => split.graph.add(
            Node::Combine {
                op: Combine::Union,
                children: ids,
            },
            span,
        ),
    };
    let (g, o) = (union(glass), union(solid));
    if apart(&split, g, o) {
        return None;
    }
    let medium_root = split.graph.add(
        Node::Combine {
            op: Combine::Subtract,
            children: vec![g, o],
        },
        span,
    );
    let mut medium = split.clone();
    medium.root = Some(medium_root);
    split.root = Some(o);
    Some(Media {
        medium: lower(&medium),
        solid: lower(&split),
    })
}

/// Whether the bounding boxes of `a` and `b` are disjoint (false when either has no bound).
fn apart(scene: &Scene, a: NodeId, b: NodeId) -> bool {
    let bounds = Bounds::new(&scene.graph);
    let (Some(x), Some(y)) = (bounds.get(a), bounds.get(b)) else {
        return false;
    };
    (0..3).any(|k| (x.aabb.c[k] - y.aabb.c[k]).abs() > x.aabb.h[k] + y.aabb.h[k])
}

/// The scene's objects: the children of its root union, through nested plain unions.
fn objects(scene: &Scene, id: NodeId, out: &mut Vec<NodeId>) {
    match scene.graph.node(id) {
        Node::Combine {
            op: Combine::Union,
            children,
        } => children.iter().for_each(|&c| objects(scene, c, out)),
        _ => out.push(id),
    }
}

const TRANSPARENT: u8 = 1;
const OPAQUE: u8 = 2;

/// Which kinds of material (bits: [`TRANSPARENT`], [`OPAQUE`]) the surfaces of node `id` can
/// have, painted `paint` from above (an inner paint wins; unpainted means material 0).
fn kinds(
    scene: &Scene,
    id: NodeId,
    paint: Option<MaterialId>,
    memo: &mut HashMap<(NodeId, Option<MaterialId>), u8>,
) -> u8 {
    if let Some(&k) = memo.get(&(id, paint)) {
        return k;
    }
    let node = scene.graph.node(id);
    let k = match node {
        Node::Paint { material, child } => kinds(scene, *child, Some(*material), memo),
        _ => {
            // A field's surface is its own: the shapes it reads are not drawn.
            let children = match node {
                Node::Field { .. } => Vec::new(),
                _ => node.children(),
            };
            if children.is_empty() {
                let m = scene.material(paint.unwrap_or(MaterialId(0)));
                if m.transparency > 0.0 {
                    TRANSPARENT
                } else {
                    OPAQUE
                }
            } else {
                children
                    .into_iter()
                    .fold(0, |k, c| k | kinds(scene, c, paint, memo))
            }
        }
    };
    memo.insert((id, paint), k);
    k
}
