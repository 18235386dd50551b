//! The estimated cost of a node per point, without its children: what the bounds' table
//! sums over a subtree, and the unions' hierarchies weigh their splits and guards by.

use super::ir::{Node, Smooth};

/// The instructions a node costs per point, roughly, without its children.
pub(super) fn own_cost(node: &Node) -> f64 {
    match node {
        Node::Sphere { .. } => 8.0,
        Node::Box { .. } | Node::RoundBox { .. } => 18.0,
        Node::Plane { .. } => 6.0,
        Node::Torus { .. } => 12.0,
        Node::Cylinder { .. } => 17.0,
        Node::Capsule { .. } => 11.0,
        Node::Cone { .. } => 35.0,
        Node::Ellipsoid { .. } => 20.0,
        Node::Bezier { .. } => 90.0,
        Node::Rect { .. } => 12.0,
        Node::Prim { prim, args } => (prim.cost)(args),
        Node::Polygon { points } => 20.0 * points.len() as f64,
        // A walk of the hierarchy: a few dozen boxes and triangles of some 40 operations.
        Node::Mesh { mesh } => 400.0 + 40.0 * (mesh.0.triangles().len() as f64).log2(),
        // A walk down the glyphs' hierarchy (two boxes a level) to the glyphs near a point:
        // a few glyphs' curves.
        Node::Text { outline, .. } => {
            let glyphs = outline.glyphs().len().max(1) as f64;
            let per_glyph = outline.segments() as f64 / glyphs;
            20.0 * (glyphs.log2() + 1.0) + 3.0 * 40.0 * per_glyph
        }
        Node::Extrude { .. } => 10.0,
        Node::Revolve { .. } => 5.0,
        Node::Loft { .. } => 18.0,
        Node::Screw { .. } => 30.0,
        Node::Sweep { path, .. } => path.0.cost(),
        Node::Feature { .. } => 8.0,
        Node::Combine { children, .. } => 4.0 * children.len() as f64,
        Node::SmoothCombine { variant, .. } => match variant {
            Smooth::Stairs(_) | Smooth::Columns(_) => 24.0,
            _ => 14.0,
        },
        Node::Translate { .. } => 3.0,
        Node::Rotate { .. } => 12.0,
        Node::Scale { .. } | Node::ScaleXyz { .. } => 5.0,
        Node::Repeat { .. } => 12.0,
        Node::Mirror { .. } => 3.0,
        Node::Twist { .. } | Node::Bend { .. } => 10.0,
        Node::RepeatPolar { .. } => 30.0,
        Node::Wrap { .. } => 16.0,
        Node::Shear { .. } => 12.0,
        Node::Taper { .. } => 12.0,
        Node::Morph { .. } => 4.0,
        Node::Elongate { .. } => 9.0,
        Node::Round { .. } | Node::Shell { .. } => 2.0,
        Node::Paint { .. } => 3.0,
        Node::Field { f, .. } => f.cost(),
    }
}
