//! Camera-relative coordinates: a scene whose camera is far from the origin is moved, in f64,
//! so that the camera sits at the origin and the renderers' f32 coordinates stay fine where
//! the rays go.
//!
//! Sphere tracing in f32 needs coordinates whose spacing is well below the hit tolerance ε·t
//! and the normal step: 10⁵ units out, f32 coordinates are 8·10⁻³ apart, so a scene placed
//! there renders with broken normals and shadows (the stability suite's `far` scene). Moving
//! the whole scene by −c, c the camera position, puts the points the rays evaluate near the
//! origin; the constants that place the shapes absorb the shift in f64 (a translation's
//! offset, a plane's height), so no precision is lost on the way. Patterns keep their place
//! in the world through [`Scene::origin`].

use super::ir::{Light, Node, Scene, V3};
use super::NodeId;
use glam::DVec3;
use std::collections::HashMap;

/// A camera farther than this from the origin gets camera-relative coordinates. Nearer, f32
/// coordinates are spaced 7.6·10⁻⁶ or less, below the hit tolerance ε·t of a ray of length 1
/// at the default ε = 10⁻⁵, and the scene keeps the coordinates it was written in (which the
/// IR and program dumps then show).
pub const RECENTRE_DISTANCE: f64 = 100.0;

/// Moves `scene` so that its camera is at the origin, when the camera is farther than
/// [`RECENTRE_DISTANCE`] from it: shapes, lights and the camera by −c, and `origin` by +c.
pub fn recentre(scene: &mut Scene) {
    let c = scene.camera.position;
    if c.iter().map(|x| x * x).sum::<f64>().sqrt() <= RECENTRE_DISTANCE {
        return;
    }
    if let Some(root) = scene.root {
        let mut memo = HashMap::new();
        scene.root = Some(moved(scene, root, c, &mut memo));
    }
    scene.camera.position = [0.0; 3];
    scene.camera.look_at = (DVec3::from(scene.camera.look_at) - DVec3::from(c)).to_array();
    for light in &mut scene.lights {
        if let Light::Point { position, .. } = light {
            *position = (DVec3::from(*position) - DVec3::from(c)).to_array();
        }
    }
    scene.origin = (DVec3::from(scene.origin) + DVec3::from(c)).to_array();
}

/// A node whose field at p is node `id`'s at p + c.
fn moved(scene: &mut Scene, id: NodeId, c: V3, memo: &mut HashMap<NodeId, NodeId>) -> NodeId {
    if let Some(&m) = memo.get(&id) {
        return m;
    }
    let span = scene.graph.span(id);
    let node = match scene.graph.node(id).clone() {
        // The offset absorbs the shift: the shape is placed relative to the camera in f64.
        Node::Translate { offset, child } => {
            let offset = (DVec3::from(offset) - DVec3::from(c)).to_array();
            if offset == [0.0; 3] {
                memo.insert(id, child);
                return child;
            }
            Node::Translate { offset, child }
        }
        // dot(p + c, n) − h = dot(p, n) − (h − dot(c, n)).
        Node::Plane { normal, height } => Node::Plane {
            normal,
            height: height - (0..3).map(|i| normal[i] * c[i]).sum::<f64>(),
        },
        // Combinations and paint commute with a translation of the point.
        Node::Combine { op, children } => Node::Combine {
            op,
            children: children.iter().map(|&k| moved(scene, k, c, memo)).collect(),
        },
        Node::Paint { material, child } => Node::Paint {
            material,
            child: moved(scene, child, c, memo),
        },
        _ => Node::Translate {
            offset: [-c[0], -c[1], -c[2]],
            child: id,
        },
    };
    let m = scene.graph.add(node, span);
    memo.insert(id, m);
    m
}

#[cfg(test)]
mod tests {
    use crate::eval::eval_point;
    use crate::front::check_str;
    use crate::lower::lower;
    use crate::scene::Scene;

    /// A sphere, a rotated box and a floor in front of a camera `offset` units out along x
    /// and z, as in the stability suite's `far` scene.
    fn far(offset: f64) -> Scene {
        let text = format!(
            "let o = {offset};
             material floor = checker {{ a: (1, 1, 1), b: (0, 0, 0), size: 0.7 }};
             camera {{ position: (o, 1.5, o - 5), look_at: (o, 0.3, o) }}
             light point {{ position: (o + 3, 5, o - 4) }}
             scene {{
               plane((0, 1, 0), -0.5) @ floor;
               sphere(0.8).translate(o - 0.9, 0.3, o);
               box((0.5, 0.8, 0.5)).rotate_y(30deg).translate(o + 0.9, 0.3, o + 0.3);
             }}"
        );
        let (scene, diags, _) = check_str("far.sdf", &text);
        scene.unwrap_or_else(|| panic!("{diags:?}"))
    }

    #[test]
    fn a_far_scene_is_moved_to_its_camera_in_f64() {
        let near = far(0.0);
        assert_eq!(near.origin, [0.0; 3]);
        let moved = far(1e5);
        assert_eq!(moved.origin, [1e5, 1.5, 1e5 - 5.0]);
        assert_eq!(moved.camera.position, [0.0; 3]);
        assert_eq!(moved.camera.look_at, [0.0, -1.2, 5.0]);
        // The same field around the camera, in f32, as the scene at the origin: the shift
        // lives in f64 constants, not in the coordinates.
        let (a, b) = (lower(&near), lower(&moved));
        for i in 0..200 {
            let u = i as f64 * 0.37;
            let p = [
                u.sin() * 2.0,
                (u * 1.3).cos() - 0.5,
                5.0 + (u * 0.7).sin() * 2.0,
            ];
            let q = [p[0] - near.camera.position[0], p[1] - 1.5, p[2] + 5.0];
            let (da, ma) = eval_point::<f32>(&a, p.map(|x| x as f32));
            let (db, mb) = eval_point::<f32>(&b, q.map(|x| x as f32));
            assert!((da - db).abs() < 1e-5, "at {p:?}: {da} and {db}");
            assert_eq!(ma, mb);
        }
    }

    #[test]
    fn the_checker_keeps_its_place_in_the_world() {
        let moved = far(1e5);
        let shift = moved.checker_shift(0.7);
        // A point of the moved scene and the same point in written coordinates fall in
        // cells of the same parity.
        for i in 0..100 {
            let p = [i as f64 * 0.113 - 5.0, -2.0, i as f64 * 0.071];
            let world: Vec<f64> = (0..3).map(|k| p[k] + moved.origin[k]).collect();
            let cells = |q: &[f64]| q.iter().map(|x| (x / 0.7).floor()).sum::<f64>();
            let here: Vec<f64> = (0..3).map(|k| p[k] / 0.7 + shift[k]).collect();
            let parity = |s: f64| s.rem_euclid(2.0);
            assert_eq!(
                parity(here.iter().map(|x| x.floor()).sum()),
                parity(cells(&world)),
                "at {p:?}"
            );
        }
    }
}
