//! The instances of a large sphere-traced scene as data: the contents of the read-only storage
//! buffer `scene_data` (binding 4) for a marched kernel, and the loop that walks it, so that
//! the kernel's size does not grow with the number of instances (`lower::Lowered::instances` says which
//! children of the root union are instances). `map(p)` is `min(rest(p), walk(p))` with the
//! nearer one's material (the rest's on a tie, else the earlier instance's): the field of the
//! whole program, evaluated in another order.
//!
//! Layout: an array of `vec4<f32>`; integers are stored as their bits (`bitcast<u32>`).
//!
//! ```text
//! [0]          (end, 0, 0, 0): the index one past the last entry
//! [1 .. end)   the entries, in the order of a depth-first walk of the hierarchy:
//!   group      [i]     (centre.xyz, GROUP)
//!              [i + 1] (half-extents.xyz, next): next is the index past the group's entries,
//!                      where a point whose signed distance to the group's box is not below
//!                      the best distance so far goes on
//!   instance   [i]     (offset.xyz, kind | ROTATED | material << 4): the point in the
//!                      shape's frame is q = rotate(p) − offset
//!              [i + 1] the shape: sphere (r, 0, 0, 0), box (half.xyz, 0), round box
//!                      (half.xyz − r, r), torus (R, r, 0, 0), cylinder and capsule
//!                      (r, half height, 0, 0), cone (r, h, 2h², 1 / (r² + 4h²))
//!              [+ 3]   only when ROTATED: the columns of the rotation's matrix M, as rows
//!                      (q_j = Σ_i p_i·M_ij)
//! ```
//!
//! The constants are `lower::slots`, computed in f64 and rounded to f32 as the program's are,
//! and each kind's shape function is lowered by the rules of `lower/shapes.rs` that lower the
//! program (`lower::shape_program`, written by `map::write_shape`), so the walk computes the
//! program's operations in the program's order and the GPU's field equals the CPU's up to f32
//! rounding. Every instance is an exact distance, so its value
//! is at least the signed distance to its box, and a group whose box is not nearer than the
//! best distance so far cannot change the minimum: skipping it is exact. The walk needs no
//! stack and ends after at most `end` steps, as in buffer.rs. An unrotated instance takes
//! 32 bytes, a rotated one 80, a group 32.

use super::buffer::{
    self, bits, entries, tag, tag_holds, vec, GROUP, KIND_BITS, MATERIAL_SHIFT, TRANSFORMED,
};
use super::map;
use crate::lower::Instance;
use crate::scene::analytic::{boxed, Item};
use crate::scene::{Node, V3};
use std::fmt::Write;

/// The kinds of instance (the tags are buffer.rs's).
const SPHERE: u32 = 0;
const BOX: u32 = 1;
const ROUND_BOX: u32 = 2;
const TORUS: u32 = 3;
const CYLINDER: u32 = 4;
const CAPSULE: u32 = 5;
const CONE: u32 = 6;
/// The kernel's name of [`TRANSFORMED`] here: an instance with a rotation.
const ROTATED: u32 = TRANSFORMED;

/// Whether every material of `instances` fits in a tag.
pub fn fits(instances: &[Instance]) -> bool {
    instances
        .iter()
        .all(|i| tag_holds(i.material.map_or(0, |m| m.0)))
}

fn kind(shape: &Node) -> u32 {
    match shape {
        Node::Sphere { .. } => SPHERE,
        Node::Box { .. } => BOX,
        Node::RoundBox { .. } => ROUND_BOX,
        Node::Torus { .. } => TORUS,
        Node::Cylinder { .. } => CYLINDER,
        Node::Capsule { .. } => CAPSULE,
        _ => CONE,
    }
}

/// The contents of `scene_data` for `instances`, as little-endian bytes, their hierarchy
/// built over their boxes, the items of every group ordered by the distance of their boxes
/// from `eye` (the camera): camera rays, most of the evaluations, then meet the nearer
/// instances first, and the best distance shrinks early enough to skip more groups.
pub fn data(instances: &[Instance], eye: V3) -> Vec<u8> {
    let mut top = boxed(instances.iter().map(|i| i.aabb).enumerate().collect());
    nearer_first(&mut top, instances, eye);
    entries(&top, &mut |out, i| instance(out, &instances[i]))
}

/// Orders `items`, and the items of every group among them, by the distance from `eye` to
/// their boxes (stable: ties keep the hierarchy's order).
fn nearer_first(items: &mut [Item], instances: &[Instance], eye: V3) {
    let distance = |item: &Item| {
        let (c, h) = match item {
            Item::Primitive(i) => {
                let (lo, hi) = instances[*i].aabb;
                let c = [0, 1, 2].map(|k| (lo[k] + hi[k]) * 0.5);
                (c, [0, 1, 2].map(|k| (hi[k] - lo[k]) * 0.5))
            }
            Item::Group(g) => (g.centre, g.half),
        };
        let outside = [0, 1, 2].map(|k| ((eye[k] - c[k]).abs() - h[k]).max(0.0));
        outside.iter().map(|x| x * x).sum::<f64>()
    };
    items.sort_by(|a, b| distance(a).total_cmp(&distance(b)));
    for item in items.iter_mut() {
        if let Item::Group(g) = item {
            nearer_first(&mut g.items, instances, eye);
        }
    }
}

fn instance(out: &mut Vec<[u32; 4]>, i: &Instance) {
    let material = i.material.map_or(0, |m| m.0);
    let tag = tag(kind(&i.shape), i.rotation.is_some(), material);
    out.push(vec(i.offset, tag));
    out.push(crate::lower::slots(&i.shape).map_or([0; 4], |s| s.map(bits)));
    if let Some(m) = i.rotation {
        out.extend((0..3).map(|j| vec([m[0][j], m[1][j], m[2][j]], 0)));
    }
}

/// `fn map` and `fn sdf` of the scene: the rest's, `rest_map` and `rest_sdf`, then the walk
/// over `scene_data`; only the kinds of `instances` are tested for.
pub fn write(instances: &[Instance]) -> String {
    let rotated = instances.iter().any(|i| i.rotation.is_some());
    let mut out = String::from(
        "// The instances in scene_data (the layout is in compiler/src/back/wgsl/march.rs): the\n\
         // kind of entry in a tag's low three bits, ROTATED, the material above.\n",
    );
    let _ = writeln!(out, "const GROUP: u32 = {GROUP}u;");
    if rotated {
        let _ = writeln!(out, "const ROTATED: u32 = {ROTATED}u;");
    }
    out.push('\n');
    helpers(&mut out);
    shape_distance(&mut out, instances);
    instance_distance(&mut out, rotated);
    walk(&mut out, true);
    walk(&mut out, false);
    out.push_str(
        "// The scene's distance field: (signed distance, material id) at p, the nearer of the\n\
         // rest of the scene and its instances.\n\
         fn map(p: vec3<f32>) -> vec2<f32> {\n    return walk_map(p, rest_map(p));\n}\n\n\
         // The distance alone, for marching and normals.\n\
         fn sdf(p: vec3<f32>) -> f32 {\n    return walk_sdf(p, rest_sdf(p));\n}\n",
    );
    out
}

/// The length and the box distance of the walk's groups, in the program's order of operations.
fn helpers(out: &mut String) {
    out.push_str(
        "fn len3(q: vec3<f32>) -> f32 {\n    return sqrt((q.x * q.x + q.y * q.y) + q.z * q.z);\n}\n\n\
         // The signed distance of a box of half-extents h about the origin, given |q| - h.\n\
         fn box_of(a: vec3<f32>) -> f32 {\n    \
         return len3(max(a, vec3<f32>(0.0))) + min(max(a.x, max(a.y, a.z)), 0.0);\n}\n\n",
    );
}

/// The shape of each kind among `instances` as a function of its own, `fn shape_KIND(p, s)`,
/// written from the lowering's rules (`lower::shape_program`), then `fn shape_distance`: the
/// distance of a shape of the tag's kind at q in its own frame, with a branch for each kind.
fn shape_distance(out: &mut String, instances: &[Instance]) {
    let mut kinds: Vec<(u32, &Node)> = instances
        .iter()
        .map(|i| (kind(&i.shape), &i.shape))
        .collect();
    kinds.sort_by_key(|k| k.0);
    kinds.dedup_by_key(|k| k.0);
    out.push_str(
        "// The distance of each kind of shape at p in its own frame, its constants s (the\n\
         // rules of lower/shapes.rs, as in the scene's program).\n",
    );
    for (_, shape) in &kinds {
        if let Some(program) = crate::lower::shape_program(shape) {
            out.push_str(&map::write_shape(
                &program,
                &format!("shape_{}", shape.kind()),
            ));
            out.push('\n');
        }
    }
    out.push_str(
        "// The distance at q of an instance's shape of the tag's kind in its own frame, its\n\
         // constants s (lower/shapes.rs).\n\
         fn shape_distance(kind: u32, q: vec3<f32>, s: vec4<f32>) -> f32 {\n",
    );
    let call = |k: u32| {
        let name = kinds.iter().find(|c| c.0 == k).map_or("", |c| c.1.kind());
        format!("return shape_{name}(q, s);")
    };
    buffer::branches(out, kinds.iter().map(|k| k.0), call, "return 1e30;");
    out.push_str("}\n\n");
}

/// `fn instance_distance`: the field of the instance whose entry starts at `i` with `head`,
/// and `fn instance_size`, its number of vectors.
fn instance_distance(out: &mut String, rotated: bool) {
    let _ = write!(
        out,
        "// The distance at p of the instance whose entry starts at scene_data[i] with head.\n\
         fn instance_distance(i: u32, head: vec4<f32>, p: vec3<f32>) -> f32 {{\n\
         \x20   let tag = bitcast<u32>(head.w);\n\
         \x20   {} q = p - head.xyz;\n",
        if rotated { "var" } else { "let" }
    );
    if rotated {
        out.push_str(
            "    if (tag & ROTATED) != 0u {\n\
             \x20       let c0 = scene_data[i + 2u].xyz;\n\
             \x20       let c1 = scene_data[i + 3u].xyz;\n\
             \x20       let c2 = scene_data[i + 4u].xyz;\n\
             \x20       let r = vec3<f32>(\n\
             \x20           (p.x * c0.x + p.y * c0.y) + p.z * c0.z,\n\
             \x20           (p.x * c1.x + p.y * c1.y) + p.z * c1.z,\n\
             \x20           (p.x * c2.x + p.y * c2.y) + p.z * c2.z,\n\
             \x20       );\n\
             \x20       q = r - head.xyz;\n\
             \x20   }\n",
        );
    }
    let shape = format!("shape_distance(tag & {KIND_BITS}u, q, scene_data[i + 1u])");
    let _ = writeln!(out, "    return {shape};\n}}\n");
    out.push_str("// The number of vectors of the instance whose tag this is.\n");
    out.push_str("fn instance_size(tag: u32) -> u32 {\n    return 2u");
    if rotated {
        out.push_str(" + select(0u, 3u, (tag & ROTATED) != 0u)");
    }
    out.push_str(";\n}\n\n");
}

/// `fn walk_map` (`material`) or `fn walk_sdf`: the minimum of `start` and the instances,
/// past each group whose box is not nearer than the best distance so far.
fn walk(out: &mut String, material: bool) {
    let (name, ty, d) = if material {
        ("walk_map", "vec2<f32>", "best.x")
    } else {
        ("walk_sdf", "f32", "best")
    };
    let _ = writeln!(
        out,
        "// The nearer of start and the instances at p{}.\n\
         fn {name}(p: vec3<f32>, start: {ty}) -> {ty} {{",
        if material {
            ", with its material (start's on a tie,\n// else the earlier instance's)"
        } else {
            ""
        }
    );
    out.push_str("    var best = start;\n");
    let enter = format!("box_of(abs(p - head.xyz) - size.xyz) < {d}");
    let update = format!("    best = vec2<f32>(d, f32(tag >> {MATERIAL_SHIFT}u));");
    let keep: &[&str] = if material {
        &["if d < best.x {", &update, "}"]
    } else {
        &["best = min(best, d);"]
    };
    let mut visit = vec!["let d = instance_distance(i, head, p);"];
    visit.extend(keep);
    visit.push("i += instance_size(tag);");
    buffer::walk(out, Some(&enter), &visit);
    out.push_str("    return best;\n}\n\n");
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::MaterialId;

    fn sphere(x: f64, k: usize) -> Instance {
        let quarter = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        Instance {
            shape: Node::Sphere { radius: 0.5 },
            offset: [x, 0.0, 0.0],
            rotation: (k % 3 == 1).then_some(quarter),
            material: (k % 2 == 0).then_some(MaterialId(k as u32)),
            aabb: ([x - 0.5, -0.5, -0.5], [x + 0.5, 0.5, 0.5]),
        }
    }

    /// Every instance is written once with its flags and material, every group's `next` lies
    /// past its own entries and within the data, and stepping by each entry's size (as
    /// `instance_size` does) ends exactly at `end`.
    #[test]
    fn entries_cover_every_instance_and_groups_skip_forward() {
        let instances: Vec<Instance> = (0..41).map(|k| sphere(k as f64 * 1.5, k)).collect();
        let bytes = data(&instances, [0.0; 3]);
        let w: Vec<u32> = bytes
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        let e: Vec<&[u32]> = w.chunks_exact(4).collect();
        let end = e[0][0] as usize;
        assert_eq!(end, e.len());
        let (mut i, mut seen, mut groups) = (1, Vec::new(), 0);
        while i < end {
            let tag = e[i][3];
            if tag == GROUP {
                let next = e[i + 1][3] as usize;
                assert!(next > i + 2 && next <= end, "group at {i}: next {next}");
                groups += 1;
                i += 2;
                continue;
            }
            let x = f32::from_bits(e[i][0]);
            let k = (x / 1.5).round() as usize;
            assert_eq!(tag & KIND_BITS, SPHERE);
            assert_eq!(tag & ROTATED != 0, k % 3 == 1, "instance {k}");
            let material = if k % 2 == 0 { k as u32 } else { 0 };
            assert_eq!(tag >> MATERIAL_SHIFT, material);
            seen.push(k);
            i += 2 + 3 * usize::from(tag & ROTATED != 0);
        }
        assert_eq!(i, end);
        assert!(groups >= 9, "{groups} groups");
        seen.sort_unstable();
        assert_eq!(seen, (0..41).collect::<Vec<_>>());
    }
}
