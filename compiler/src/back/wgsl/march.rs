//! The instances of a large sphere-traced scene as data: the contents of the read-only storage
//! buffer `scene_data` (binding 4) for a marched kernel, and the loop that walks it, so that
//! the kernel's size does not grow with the number of instances (`lower::Lowered::instances` says which
//! children of the root union are instances). `map(p)` is `min(rest(p), walk(p))` with the
//! nearer one's material (the rest's on a tie, else the material of the instance earlier in
//! `scene_data`): the field of the whole program, evaluated in another order.
//!
//! Layout: an array of `vec4<f32>`; integers are stored as their bits (`bitcast<u32>`).
//!
//! ```text
//! [0]          (end, 0, 0, 0): the index one past the last entry
//! [1 .. end)   the entries, in the order of a depth-first walk of the hierarchy: either
//!              one group, the root, or (a scene of a few instances) the instances alone
//!   group      [i]     (centre.xyz, GROUP)
//!              [i + 1] (half-extents.xyz, next): next is the index past the group's entries
//!              [i + 2 .. next) either two groups (the second at the first's next) or from
//!                      two to four instances (a leaf)
//!   instance   [i]     (offset.xyz, kind | ROTATED | material << 5): the point in the
//!                      shape's frame is q = rotate(p) − offset
//!              [i + 1] the shape: sphere (r, 0, 0, 0), box (half.xyz, 0), round box
//!                      (half.xyz − r, r), torus (R, r, 0, 0), cylinder and capsule
//!                      (r, half height, 0, 0), cone (r, h, 2h², 1 / (r² + 4h²)); for the
//!                      kinds from WIDE on, the first four of their eight slots: capped cone
//!                      (h, r1, r2, r2 − r1), round cone (r1, r2, h, s)
//!              [i + 2] only for the kinds from WIDE on, the other four: capped cone
//!                      (dot(k1, k2), 1 / dot(k2, k2), 0, 0), round cone (c, 2h·c, 0, 0)
//!                      (prim/solids.rs)
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
//! best distance so far cannot change the minimum: skipping it is exact.
//!
//! The walk visits the hierarchy nearest first. The hierarchy is the median-split tree of
//! `scene::analytic::boxed`, binary down to leaves of at most four instances, and balanced:
//! its depth D (the root's groups at level 0) is ⌈log₂(n / 4)⌉ or less. At a group the walk
//! measures the boxes of both children, goes on into the nearer and pushes the farther, with
//! its box's distance, on a stack; at a leaf it evaluates the instances; then it pops the
//! stack, passing over every group whose box is no longer nearer than the best distance. The
//! stack holds at most one group per level below the root (when a group of level k is
//! popped, the others are of levels below k, and the descent from it pushes at most one of
//! each level below it), so an array of max(D, 1) entries, which the kernel is written with,
//! never overflows. A point near the surface thus meets its nearest instances first and the
//! boxes prune all but a few paths down the tree: a step costs about log n box tests and a
//! few instances, where a walk in a fixed order costs what lies before the point's nearest
//! instance. (A uniform grid of cells would search ever larger rings for a point far from
//! every instance, as most of a ray's steps are, and suits scenes whose instances are evenly
//! spread, which few are.) The boxes' distances keep their square roots: compared squared,
//! the walk was slower through the Vulkan driver.
//!
//! Before the hierarchy each walk evaluates one instance, its hint: the private variable
//! `hint` holds the entry of the nearest instance the invocation's last walk of `sdf`
//! evaluated (0 before the first). Successive steps of a march, a normal's taps, the
//! material's lookup and the shadow rays from a hit stay near the same instance, so the best
//! distance is about the final one before the first box is measured, and the farther children
//! the descent would push are passed over at once (fewer pushes to local memory). Any hint
//! gives the same result: the minimum does not depend on the order of the visit, nor, with
//! the tie rule below, the material.
//!
//! Most of `sdf`'s calls need no walk at all. `walk_sdf` also returns a lower bound B on the
//! distance at its point p₀ of every instance but the nearest it evaluated (its key): the
//! least of the other instances it evaluated and of the boxes it passed over, each a lower
//! bound since every instance lies in its boxes. `sdf` keeps p₀ and B beside the hint. Each
//! instance is an exact distance, so it changes no faster than the point moves: at p every
//! other instance is at least B − |p − p₀| away, and when the rest of the scene or the hint's
//! instance is no farther than that, their minimum is the field's (another instance can at
//! most tie). A march's steps towards the hint's instance keep to that ball, as do a
//! normal's taps and a shadow ray's first steps; the walks left are steps between instances
//! whose nearest neighbours change as the ray passes (the test `the_cache_of_the_last_walk…`
//! counts them). The hint and the cache each shorten the large scaling scenes' frames.
//!
//! `walk_map`, which gives the material, keeps the tie rule independent of the order of the
//! visit (the hint included): among instances at the same distance the one earlier in
//! `scene_data` wins (the rest of the scene before any), and it
//! passes over a group only when its box is farther than the best distance (a group at
//! exactly that distance may hold an earlier instance that ties). `walk_sdf`, the distance
//! alone, passes over a group whose box is not nearer. An unrotated instance takes 32 bytes,
//! a rotated one 80, a group 32.

use super::buffer::{
    self, bits, entries, tag, tag_holds, vec, GROUP, KIND_BITS, MATERIAL_SHIFT, TRANSFORMED,
};
use super::map;
use crate::lower::Instance;
use crate::scene::analytic::{boxed, Group, Item};
use crate::scene::Node;
use std::fmt::Write;

/// The kinds of instance (the tags are buffer.rs's).
const SPHERE: u32 = 0;
const BOX: u32 = 1;
const ROUND_BOX: u32 = 2;
const TORUS: u32 = 3;
const CYLINDER: u32 = 4;
const CAPSULE: u32 = 5;
const CONE: u32 = 6;
const CAPPED_CONE: u32 = 7;
const ROUND_CONE: u32 = 8;
/// The kinds from this one on have eight slots, in two vectors.
const WIDE: u32 = 7;
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
        Node::Prim { prim, .. } if prim.name == "capped_cone" => CAPPED_CONE,
        Node::Prim { .. } => ROUND_CONE,
        _ => CONE,
    }
}

/// The contents of `scene_data` for `instances`, their hierarchy built over their boxes.
pub struct Data {
    /// The bytes of `scene_data`, little-endian.
    pub bytes: Vec<u8>,
    /// The entries of the walk's stack: the hierarchy's depth, at least 1.
    pub stack: usize,
}

/// The contents of `scene_data` for `instances` and the stack their walk needs.
pub fn data(instances: &[Instance]) -> Data {
    let top = boxed(instances.iter().map(|i| i.aabb).enumerate().collect());
    let stack = match top.as_slice() {
        [Item::Group(root)] => depth(root).max(1),
        items => {
            assert!(
                items.iter().all(|i| matches!(i, Item::Primitive(_))),
                "the top of the hierarchy is one group or instances alone"
            );
            1
        }
    };
    let bytes = entries(&top, &mut |out, i| instance(out, &instances[i]));
    Data { bytes, stack }
}

/// The levels of groups below `group`, checking the shape the walk relies on: every group
/// holds two groups or instances alone.
fn depth(group: &Group) -> usize {
    match group.items.as_slice() {
        [Item::Group(a), Item::Group(b)] => 1 + depth(a).max(depth(b)),
        items => {
            assert!(
                items.iter().all(|i| matches!(i, Item::Primitive(_))),
                "a group of the hierarchy holds two groups or instances alone"
            );
            0
        }
    }
}

fn instance(out: &mut Vec<[u32; 4]>, i: &Instance) {
    let material = i.material.map_or(0, |m| m.0);
    let kind = kind(&i.shape);
    let tag = tag(kind, i.rotation.is_some(), material);
    out.push(vec(i.offset, tag));
    let s = crate::lower::slots(&i.shape).map_or([0; 8], |s| s.map(bits));
    out.push([s[0], s[1], s[2], s[3]]);
    if kind >= WIDE {
        out.push([s[4], s[5], s[6], s[7]]);
    }
    if let Some(m) = i.rotation {
        out.extend((0..3).map(|j| vec([m[0][j], m[1][j], m[2][j]], 0)));
    }
}

/// `fn map` and `fn sdf` of the scene: the rest's, `rest_map` and `rest_sdf`, then the walk
/// over `scene_data`, with a stack of `stack` entries ([`Data::stack`]); only the kinds of
/// `instances` are tested for.
pub fn write(instances: &[Instance], stack: usize) -> String {
    let rotated = instances.iter().any(|i| i.rotation.is_some());
    let wide = instances.iter().any(|i| kind(&i.shape) >= WIDE);
    let mut out = String::from(
        "// The instances in scene_data (the layout is in compiler/src/back/wgsl/march.rs): the\n\
         // kind of entry in a tag's low four bits, ROTATED, the material above.\n",
    );
    let _ = writeln!(out, "const GROUP: u32 = {GROUP}u;");
    out.push_str(
        "// What the last walk of sdf found, the cache of the next calls (see march.rs): the\n\
         // entry of the nearest instance it evaluated (0: none yet), the point of that walk, and\n\
         // a lower bound there on the distance of every other instance. Successive steps of a\n\
         // march, a normal's taps and a shadow ray stay near the same instance.\n\
         var<private> hint: u32;\n\
         var<private> hint_at: vec3<f32>;\n\
         var<private> hint_bound: f32;\n\n\
         // The minimum of walk_sdf; the entry of the nearest instance it evaluated (0: none)\n\
         // and a lower bound at p on the distance of every other instance.\n\
         struct Nearest {\n    d: f32,\n    key: u32,\n    bound: f32,\n}\n\n\
         // Farther than any distance of a scene.\n\
         const FAR: f32 = 1e30;\n",
    );
    if rotated {
        let _ = writeln!(out, "const ROTATED: u32 = {ROTATED}u;");
    }
    if wide {
        let _ = writeln!(out, "const WIDE: u32 = {WIDE}u;");
    }
    out.push('\n');
    helpers(&mut out);
    shape_distance(&mut out, instances, wide);
    instance_distance(&mut out, rotated, wide);
    walk(&mut out, true, stack);
    walk(&mut out, false, stack);
    out.push_str(
        "// The distance at p of the instance at hint; FAR when there is none.\n\
         fn hint_distance(p: vec3<f32>) -> f32 {\n    \
         if hint == 0u {\n        return FAR;\n    }\n    \
         return instance_distance(hint, scene_data[hint], p);\n}\n\n\
         // The scene's distance field: (signed distance, material id) at p, the nearer of the\n\
         // rest of the scene and its instances.\n\
         fn map(p: vec3<f32>) -> vec2<f32> {\n    \
         return walk_map(p, rest_map(p), hint, hint_distance(p));\n}\n\n\
         // The distance alone, for marching and normals. While the rest or the hint's instance\n\
         // is no farther than the bound of the last walk less the way from its point, every\n\
         // other instance is at least as far (each is a distance, 1-Lipschitz): the walk is\n\
         // not needed. Otherwise the walk, whose findings are the next calls' cache.\n\
         fn sdf(p: vec3<f32>) -> f32 {\n    \
         let start = rest_sdf(p);\n    \
         let hd = hint_distance(p);\n    \
         let d = min(start, hd);\n    \
         if hint != 0u && d <= hint_bound - len3(p - hint_at) {\n        return d;\n    }\n    \
         let n = walk_sdf(p, start, hint, hd);\n    \
         if n.key != 0u {\n        \
         hint = n.key;\n        hint_at = p;\n        hint_bound = n.bound;\n    }\n    \
         return n.d;\n}\n",
    );
    out
}

/// The length and the box distance of the walk's groups, in the program's order of operations.
fn helpers(out: &mut String) {
    out.push_str(
        "fn len3(q: vec3<f32>) -> f32 {\n    return sqrt((q.x * q.x + q.y * q.y) + q.z * q.z);\n}\n\n\
         // The signed distance of a box of half-extents h about the origin, given |q| - h.\n\
         fn box_of(a: vec3<f32>) -> f32 {\n    \
         return len3(max(a, vec3<f32>(0.0))) + min(max(a.x, max(a.y, a.z)), 0.0);\n}\n\n\
         // The signed distance at p to the box of the group whose entry starts at scene_data[g].\n\
         fn group_distance(g: u32, p: vec3<f32>) -> f32 {\n    \
         return box_of(abs(p - scene_data[g].xyz) - scene_data[g + 1u].xyz);\n}\n\n",
    );
}

/// The shape of each kind among `instances` as a function of its own, `fn shape_KIND(p, s)`
/// (`(p, s, t)` for the kinds from [`WIDE`] on, their slots in two vectors), written from the
/// lowering's rules (`lower::shape_program`), then `fn shape_distance`: the distance of a
/// shape of the tag's kind at q in its own frame, with a branch for each kind (and `t`, the
/// second vector of slots, where some kind has one).
fn shape_distance(out: &mut String, instances: &[Instance], wide: bool) {
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
         // constants s (lower/shapes.rs).\n",
    );
    let t = if wide { ", t: vec4<f32>" } else { "" };
    let _ = writeln!(
        out,
        "fn shape_distance(kind: u32, q: vec3<f32>, s: vec4<f32>{t}) -> f32 {{"
    );
    let call = |k: u32| {
        let name = kinds.iter().find(|c| c.0 == k).map_or("", |c| c.1.kind());
        let t = if k >= WIDE { ", t" } else { "" };
        format!("return shape_{name}(q, s{t});")
    };
    buffer::branches(out, kinds.iter().map(|k| k.0), call, "return 1e30;");
    out.push_str("}\n\n");
}

/// `fn instance_distance`: the field of the instance whose entry starts at `i` with `head`,
/// and `fn instance_size`, its number of vectors.
fn instance_distance(out: &mut String, rotated: bool, wide: bool) {
    let _ = write!(
        out,
        "// The distance at p of the instance whose entry starts at scene_data[i] with head.\n\
         fn instance_distance(i: u32, head: vec4<f32>, p: vec3<f32>) -> f32 {{\n\
         \x20   let tag = bitcast<u32>(head.w);\n\
         \x20   {} q = p - head.xyz;\n",
        if rotated { "var" } else { "let" }
    );
    // The vectors of slots: one, or two for the kinds from WIDE on.
    let slots = if wide {
        let _ = write!(
            out,
            "    let kind = tag & {KIND_BITS}u;\n\
             \x20   let wide = select(0u, 1u, kind >= WIDE);\n",
        );
        ["i + 2u + wide", "i + 3u + wide", "i + 4u + wide"]
    } else {
        ["i + 2u", "i + 3u", "i + 4u"]
    };
    if rotated {
        let _ = write!(
            out,
            "    if (tag & ROTATED) != 0u {{\n\
             \x20       let c0 = scene_data[{}].xyz;\n\
             \x20       let c1 = scene_data[{}].xyz;\n\
             \x20       let c2 = scene_data[{}].xyz;\n\
             \x20       let r = vec3<f32>(\n\
             \x20           (p.x * c0.x + p.y * c0.y) + p.z * c0.z,\n\
             \x20           (p.x * c1.x + p.y * c1.y) + p.z * c1.z,\n\
             \x20           (p.x * c2.x + p.y * c2.y) + p.z * c2.z,\n\
             \x20       );\n\
             \x20       q = r - head.xyz;\n\
             \x20   }}\n",
            slots[0], slots[1], slots[2]
        );
    }
    let shape = if wide {
        out.push_str(
            "    var t = vec4<f32>(0.0);\n\
             \x20   if wide != 0u {\n\
             \x20       t = scene_data[i + 2u];\n\
             \x20   }\n",
        );
        "shape_distance(kind, q, scene_data[i + 1u], t)".to_string()
    } else {
        format!("shape_distance(tag & {KIND_BITS}u, q, scene_data[i + 1u])")
    };
    let _ = writeln!(out, "    return {shape};\n}}\n");
    out.push_str("// The number of vectors of the instance whose tag this is.\n");
    out.push_str("fn instance_size(tag: u32) -> u32 {\n    return 2u");
    if wide {
        let _ = write!(out, " + select(0u, 1u, (tag & {KIND_BITS}u) >= WIDE)");
    }
    if rotated {
        out.push_str(" + select(0u, 3u, (tag & ROTATED) != 0u)");
    }
    out.push_str(";\n}\n\n");
}

/// `fn walk_map` (`material`) or `fn walk_sdf`: the minimum of `start` and the instances,
/// the instance at `hint` first, then the hierarchy nearest first, past each group whose box
/// is not nearer than the best distance so far (the walk of the module's header, with a
/// stack of `stack` entries).
fn walk(out: &mut String, material: bool, stack: usize) {
    let d = if material { "best.x" } else { "best" };
    // Where a group may be passed over: the material's walk enters a group at exactly the
    // best distance, which may hold an earlier instance that ties.
    let (farther, not_farther) = if material { (">", "<=") } else { (">=", "<") };
    // The distance walk also keeps the nearest instance it evaluated (its key) and a lower
    // bound on every other instance: each instance it evaluates and each box it passes over
    // lowers the bound, or the key's old distance when it finds a nearer one.
    let fold = |x: &str, indent: usize| {
        if material {
            String::new()
        } else {
            format!("{:indent$}bound = min(bound, {x});\n", "")
        }
    };
    if material {
        out.push_str(
            "// The nearer of start and the instances at p, with its material (start's on a tie,\n\
             // else the instance's earlier in scene_data), visiting the instance at hint first\n\
             // (hd: its distance; FAR when hint is 0), then the hierarchy nearest first.\n\
             fn walk_map(p: vec3<f32>, start: vec2<f32>, hint: u32, hd: f32) -> vec2<f32> {\n",
        );
    } else {
        out.push_str(
            "// The nearer of start and the instances at p, visiting the instance at hint first\n\
             // (hd: its distance; FAR when hint is 0), then the hierarchy nearest first; with the\n\
             // nearest instance evaluated and a lower bound on the distance of every other one.\n\
             fn walk_sdf(p: vec3<f32>, start: f32, hint: u32, hd: f32) -> Nearest {\n",
        );
    }
    if material {
        let _ = writeln!(
            out,
            "    var best = start;\n\
             \x20   // The entry of best's instance; 0: start.\n\
             \x20   var owner = 0u;\n\
             \x20   if hd < best.x {{\n\
             \x20       best = vec2<f32>(hd, f32(bitcast<u32>(scene_data[hint].w) >> {MATERIAL_SHIFT}u));\n\
             \x20       owner = hint;\n\
             \x20   }}"
        );
    } else {
        out.push_str(
            "    var best = min(start, hd);\n\
             \x20   // The nearest instance evaluated, its distance, and a bound on the others.\n\
             \x20   var key = hint;\n\
             \x20   var kd = hd;\n\
             \x20   var bound = FAR;\n",
        );
    }
    let _ = write!(
        out,
        "    // Groups still to enter and the distances of their boxes, one per level at most.\n\
         \x20   var stack: array<u32, {stack}>;\n\
         \x20   var near: array<f32, {stack}>;\n\
         \x20   var sp = 0u;\n\
         \x20   // The instances of a leaf still to visit: [i, stop).\n\
         \x20   var i = 1u;\n\
         \x20   var stop = bitcast<u32>(scene_data[0u].x);\n\
         \x20   if bitcast<u32>(scene_data[1u].w) == GROUP {{\n\
         \x20       stack[0] = 1u;\n\
         \x20       near[0] = group_distance(1u, p);\n\
         \x20       sp = 1u;\n\
         \x20       i = stop;\n\
         \x20   }}\n\
         \x20   loop {{\n\
         \x20       if i < stop {{\n\
         \x20           let head = scene_data[i];\n\
         \x20           let tag = bitcast<u32>(head.w);\n\
         \x20           let d = instance_distance(i, head, p);\n"
    );
    if material {
        let _ = write!(
            out,
            "            if d < best.x || (d == best.x && i < owner) {{\n\
             \x20               best = vec2<f32>(d, f32(tag >> {MATERIAL_SHIFT}u));\n\
             \x20               owner = i;\n\
             \x20           }}\n"
        );
    } else {
        out.push_str(
            "            best = min(best, d);\n\
             \x20           if d < kd {\n\
             \x20               bound = min(bound, kd);\n\
             \x20               kd = d;\n\
             \x20               key = i;\n\
             \x20           } else if i != key {\n\
             \x20               bound = min(bound, d);\n\
             \x20           }\n",
        );
    }
    let _ = write!(
        out,
        "            i += instance_size(tag);\n\
         \x20           continue;\n\
         \x20       }}\n\
         \x20       if sp == 0u {{\n\
         \x20           break;\n\
         \x20       }}\n\
         \x20       sp -= 1u;\n\
         \x20       if near[sp] {farther} {d} {{\n\
         {}\
         \x20           continue;\n\
         \x20       }}\n\
         \x20       // Down from the group g, whose box is near enough, into the nearer child.\n\
         \x20       var g = stack[sp];\n\
         \x20       loop {{\n\
         \x20           let a = g + 2u;\n\
         \x20           let first = scene_data[a];\n\
         \x20           if bitcast<u32>(first.w) != GROUP {{\n\
         \x20               i = a;\n\
         \x20               stop = bitcast<u32>(scene_data[g + 1u].w);\n\
         \x20               break;\n\
         \x20           }}\n\
         \x20           let size = scene_data[a + 1u];\n\
         \x20           let b = bitcast<u32>(size.w);\n\
         \x20           let da = box_of(abs(p - first.xyz) - size.xyz);\n\
         \x20           let db = group_distance(b, p);\n\
         \x20           let a_first = da <= db;\n\
         \x20           let far = max(da, db);\n\
         \x20           if far {not_farther} {d} {{\n\
         \x20               stack[sp] = select(a, b, a_first);\n\
         \x20               near[sp] = far;\n\
         \x20               sp += 1u;\n\
         \x20           }}{}\n\
         \x20           if min(da, db) {farther} {d} {{\n\
         {}\
         \x20               break;\n\
         \x20           }}\n\
         \x20           g = select(b, a, a_first);\n\
         \x20       }}\n\
         \x20   }}\n\
         \x20   return {};\n}}\n\n",
        fold("near[sp]", 12),
        if material {
            String::new()
        } else {
            format!(" else {{\n{}\x20           }}", fold("far", 16))
        },
        fold("min(da, db)", 16),
        if material {
            "best"
        } else {
            "Nearest(best, key, bound)"
        }
    );
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
        let bytes = data(&instances).bytes;
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

    fn box_of(a: [f32; 3]) -> f32 {
        let m = a.map(|x| x.max(0.0));
        ((m[0] * m[0] + m[1] * m[1]) + m[2] * m[2]).sqrt() + a[0].max(a[1].max(a[2])).min(0.0)
    }

    /// What [`model`] found: the minimum and its instance (0: start), for `walk_sdf` the
    /// nearest instance evaluated (its key) and the bound on every other instance, and the
    /// work done: instances evaluated, boxes measured, the deepest stack.
    struct Visit {
        best: f32,
        owner: usize,
        key: usize,
        bound: f32,
        evaluated: usize,
        boxes: usize,
        deepest: usize,
    }

    /// The distance at `p` of the unrotated sphere whose entry starts at `e[i]`.
    fn sphere_at(e: &[[f32; 4]], i: usize, p: [f32; 3]) -> f32 {
        let q = [0, 1, 2].map(|k| p[k] - e[i][k]);
        ((q[0] * q[0] + q[1] * q[1]) + q[2] * q[2]).sqrt() - e[i + 1][0]
    }

    /// The walk of `walk_map` (with `material`) or `walk_sdf` as the kernel does it, over the
    /// entries `e` of unrotated spheres, the instance at `hint` first.
    fn model(
        e: &[[f32; 4]],
        p: [f32; 3],
        start: f32,
        hint: usize,
        stack: usize,
        material: bool,
    ) -> Visit {
        let bits = |x: f32| x.to_bits() as usize;
        let group = |g: usize| {
            let (c, h) = (e[g], e[g + 1]);
            box_of([0, 1, 2].map(|k| (p[k] - c[k]).abs() - h[k]))
        };
        let farther = |x: f32, best: f32| if material { x > best } else { x >= best };
        let mut v = Visit {
            best: start,
            owner: 0,
            key: hint,
            bound: f32::INFINITY,
            evaluated: 0,
            boxes: 0,
            deepest: 0,
        };
        let mut kd = f32::INFINITY;
        if hint != 0 {
            v.evaluated += 1;
            kd = sphere_at(e, hint, p);
            if kd < v.best {
                (v.best, v.owner) = (kd, hint);
            }
        }
        let mut st: Vec<(usize, f32)> = Vec::new();
        let (mut i, mut stop) = (1, bits(e[0][0]));
        if bits(e[1][3]) == GROUP as usize {
            st.push((1, group(1)));
            v.boxes += 1;
            i = stop;
        }
        loop {
            if i < stop {
                let d = sphere_at(e, i, p);
                v.evaluated += 1;
                if d < v.best || (material && d == v.best && i < v.owner) {
                    (v.best, v.owner) = (d, i);
                }
                if d < kd {
                    v.bound = v.bound.min(kd);
                    (kd, v.key) = (d, i);
                } else if i != v.key {
                    v.bound = v.bound.min(d);
                }
                i += 2;
                continue;
            }
            let Some((mut g, near)) = st.pop() else { break };
            if farther(near, v.best) {
                v.bound = v.bound.min(near);
                continue;
            }
            loop {
                let a = g + 2;
                if bits(e[a][3]) != GROUP as usize {
                    (i, stop) = (a, bits(e[g + 1][3]));
                    break;
                }
                let b = bits(e[a + 1][3]);
                let (da, db) = (group(a), group(b));
                v.boxes += 2;
                let (n, f) = if da <= db { (a, b) } else { (b, a) };
                if !farther(da.max(db), v.best) {
                    st.push((f, da.max(db)));
                    v.deepest = v.deepest.max(st.len());
                    assert!(st.len() <= stack, "stack of {stack} overflows");
                } else {
                    v.bound = v.bound.min(da.max(db));
                }
                if farther(da.min(db), v.best) {
                    v.bound = v.bound.min(da.min(db));
                    break;
                }
                g = n;
            }
        }
        v
    }

    /// The cache of `sdf`'s last walk: its key, its point, its bound.
    type Cache = (usize, [f32; 3], f32);

    /// `sdf` as the kernel has it: the cache of the last walk (hint, its point, its bound)
    /// when it suffices, else the walk, which renews the cache. Adds to `walks` and `boxes`.
    fn model_sdf(
        e: &[[f32; 4]],
        p: [f32; 3],
        start: f32,
        cache: &mut Cache,
        stack: usize,
        walks: &mut usize,
        boxes: &mut usize,
    ) -> f32 {
        let (hint, at, bound) = *cache;
        if hint != 0 {
            let d = start.min(sphere_at(e, hint, p));
            let q = [0, 1, 2].map(|k| p[k] - at[k]);
            if d <= bound - ((q[0] * q[0] + q[1] * q[1]) + q[2] * q[2]).sqrt() {
                return d;
            }
        }
        let v = model(e, p, start, hint, stack, false);
        *walks += 1;
        *boxes += v.boxes;
        if v.key != 0 {
            *cache = (v.key, p, v.bound);
        }
        v.best
    }

    /// The vectors of `scene_data` as floats.
    fn vectors(d: &Data) -> Vec<[f32; 4]> {
        let w: Vec<f32> = d
            .bytes
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        w.chunks_exact(4)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect()
    }

    /// The minimum of `start` and every sphere of `e` in `scene_data`'s order, and its entry
    /// (0: start).
    fn brute(e: &[[f32; 4]], p: [f32; 3], start: f32) -> (f32, usize) {
        let end = e[0][0].to_bits() as usize;
        let (mut best, mut owner, mut i) = (start, 0, 1);
        while i < end {
            if e[i][3].to_bits() != GROUP {
                let d = sphere_at(e, i, p);
                if d < best {
                    (best, owner) = (d, i);
                }
            }
            i += 2;
        }
        (best, owner)
    }

    /// The nearest-first walk finds the same minimum as every instance in `scene_data`'s
    /// order (the same value, and with the material, the same instance on a tie, the rest
    /// first) whatever its hint, its stack never holds more than the hierarchy's depth, and
    /// near the surface of 4 096 spheres it evaluates a few of them, and no more boxes with
    /// the nearest instance as its hint.
    #[test]
    fn the_nearest_first_walk_finds_the_minimum_in_few_steps() {
        let mut rng = crate::rng::Rng::new(7);
        let mut instances = Vec::new();
        for k in 0..4096 {
            let c = [(k % 16) as f64, ((k / 16) % 16) as f64, (k / 256) as f64]
                .map(|x| x * 1.5 + rng.range(-0.2, 0.2));
            let r = rng.range(0.2, 0.6);
            instances.push(Instance {
                shape: Node::Sphere { radius: r },
                offset: c,
                rotation: None,
                material: Some(MaterialId(k)),
                aabb: (c.map(|x| x - r), c.map(|x| x + r)),
            });
        }
        // Two copies in one place: their distances tie everywhere.
        instances.push(Instance {
            material: Some(MaterialId(9999)),
            ..instances[700].clone()
        });
        let d = data(&instances);
        let e = vectors(&d);
        assert!((10..=12).contains(&d.stack), "depth {}", d.stack);
        let brute = |p: [f32; 3], start: f32| brute(&e, p, start);
        let end = e[0][0].to_bits() as usize;
        // Every vector is a group's two or an unrotated sphere's two.
        let entries: Vec<usize> = (1..end)
            .step_by(2)
            .filter(|&i| e[i][3].to_bits() != GROUP)
            .collect();
        let (mut near_surface, mut deepest, mut ties) = (0, 0, 0);
        let (mut evaluated, mut boxes, mut hinted_boxes) = (0, 0, 0);
        for n in 0..3000 {
            let p = if n % 3 == 0 {
                // On the surface of a sphere, at some copies' exact distance.
                let c = instances[if n % 2 == 0 { 700 } else { rng.below(4096) }].offset;
                c.map(|x| (x + rng.range(-0.7, 0.7)) as f32)
            } else {
                [0, 1, 2].map(|_| rng.range(-4.0, 26.0) as f32)
            };
            for start in [f32::INFINITY, 0.3, 2.0] {
                let (want, owner) = brute(p, start);
                let nearest = brute(p, f32::INFINITY).1;
                let stray = entries[rng.below(entries.len())];
                for hint in [0, nearest, stray] {
                    let v = model(&e, p, start, hint, d.stack, false);
                    assert_eq!(v.best.to_bits(), want.to_bits(), "{p:?} hint {hint}");
                    // Every instance but the key is at least as far as the bound.
                    for &j in entries.iter().filter(|&&j| j != v.key) {
                        assert!(
                            sphere_at(&e, j, p) >= v.bound,
                            "{p:?} {hint}: {j} {}",
                            v.bound
                        );
                    }
                    let Visit {
                        best: map,
                        owner: who,
                        evaluated: k,
                        boxes: b,
                        deepest: s,
                        ..
                    } = model(&e, p, start, hint, d.stack, true);
                    assert_eq!(
                        (map.to_bits(), who),
                        (want.to_bits(), owner),
                        "{p:?} {hint}"
                    );
                    deepest = deepest.max(s);
                    let twin = instances[700].offset.map(|x| x as f32);
                    ties += usize::from(who != 0 && e[who][0..3] == twin);
                    if start.is_infinite() && want.abs() < 0.1 {
                        if hint == 0 {
                            near_surface += 1;
                            evaluated += k;
                            boxes += b;
                        } else if hint == nearest {
                            hinted_boxes += b;
                        }
                    }
                }
            }
        }
        assert!(
            deepest <= d.stack && deepest >= d.stack - 2,
            "deepest {deepest}"
        );
        assert!(near_surface > 100, "{near_surface} points near a surface");
        assert!(ties > 100, "{ties} ties");
        let per = |x: usize| x as f64 / near_surface as f64;
        println!(
            "{near_surface} points near a surface: {:.1} instances and {:.1} boxes each, {:.1} \
             boxes with the nearest as the hint; stack {deepest} of {}",
            per(evaluated),
            per(boxes),
            per(hinted_boxes),
            d.stack
        );
        assert!(
            per(evaluated) < 16.0,
            "{} instances evaluated per point near a surface",
            per(evaluated)
        );
        assert!(
            hinted_boxes <= boxes,
            "{hinted_boxes} boxes hinted, {boxes} not"
        );
    }

    /// Camera rays, their normals' taps and shadow rays marched through 1 024 jittered
    /// spheres over a plane (examples/scaling/jittered_1024.sdf) with `sdf`'s cache: every
    /// step's distance is the minimum over every instance, bit for bit, and most steps need
    /// no walk.
    #[test]
    fn the_cache_of_the_last_walk_gives_the_minimum_and_spares_most_walks() {
        let mut rng = crate::rng::Rng::new(11);
        let instances: Vec<Instance> = (0..1024)
            .map(|k| {
                let cell = [k % 16, k / 64, k / 16 % 4];
                let c = [0, 1, 2].map(|a| {
                    let centre = if a == 1 { 0.5 } else { -7.5 };
                    (cell[a] as f64 + centre) * 0.5 + rng.range(-0.1, 0.1)
                });
                let r = 0.15;
                Instance {
                    shape: Node::Sphere { radius: r },
                    offset: c,
                    rotation: None,
                    material: None,
                    aabb: (c.map(|x| x - r), c.map(|x| x + r)),
                }
            })
            .collect();
        let d = data(&instances);
        let e = vectors(&d);
        let norm = |v: [f32; 3]| {
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            v.map(|x| x / l)
        };
        let (mut steps, mut walks, mut boxes, mut uncached_boxes) = (0, 0, 0, 0);
        let mut cache = (0, [0.0; 3], 0.0);
        let mut field = |p: [f32; 3], cache: &mut Cache| {
            let start = p[1];
            let got = model_sdf(&e, p, start, cache, d.stack, &mut walks, &mut boxes);
            assert_eq!(got.to_bits(), brute(&e, p, start).0.to_bits(), "{p:?}");
            uncached_boxes += model(&e, p, start, cache.0, d.stack, false).boxes;
            steps += 1;
            got
        };
        let (eye, light) = ([0.0f32, 3.2, -7.5], norm([0.5, 1.0, -0.6]));
        let mut hits = 0;
        for y in 0..24 {
            for x in 0..32 {
                let target = [(x as f32 - 15.5) * 0.25, 3.0 - y as f32 * 0.2, 0.0];
                let dir = norm([0, 1, 2].map(|k| target[k] - eye[k]));
                let Some(p) = march(&mut field, eye, dir, &mut cache) else {
                    continue;
                };
                hits += 1;
                // The normal's taps, then a shadow ray from just above the surface.
                let h = 1e-3;
                let g = [0, 1, 2].map(|k| {
                    let (mut a, mut b) = (p, p);
                    a[k] += h;
                    b[k] -= h;
                    field(a, &mut cache) - field(b, &mut cache)
                });
                let n = norm(g);
                let o = [0, 1, 2].map(|k| p[k] + n[k] * 2e-3);
                march(&mut field, o, light, &mut cache);
            }
        }
        assert!(hits > 500, "{hits} hits");
        let per = |x: usize| x as f64 / steps as f64;
        println!(
            "{steps} steps: {:.2} walks and {:.2} boxes each ({:.2} boxes walking every step)",
            per(walks),
            per(boxes),
            per(uncached_boxes)
        );
        assert!(per(walks) < 0.5, "{:.2} walks a step", per(walks));
    }

    /// The point where a ray from `o` along `dir` first comes within 1e-4·t of the surface,
    /// marched through `field` with `cache`, if it does within 512 steps and 30 units.
    fn march(
        field: &mut impl FnMut([f32; 3], &mut Cache) -> f32,
        o: [f32; 3],
        dir: [f32; 3],
        cache: &mut Cache,
    ) -> Option<[f32; 3]> {
        let mut t = 0.0f32;
        for _ in 0..512 {
            let p = [0, 1, 2].map(|k| o[k] + t * dir[k]);
            let d = field(p, cache);
            if d < 1e-4 * t.max(1.0) {
                return Some(p);
            }
            t += d;
            if t > 30.0 {
                break;
            }
        }
        None
    }
}
