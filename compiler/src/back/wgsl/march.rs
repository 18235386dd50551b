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
mod tests;
