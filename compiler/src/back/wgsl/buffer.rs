//! The primitives and hierarchy of a large analytically traced scene as data: the contents of
//! the read-only storage buffer `scene_data` (binding 4), and the `trace` and `shadow` that
//! walk it in a loop, so that the kernel's size does not depend on the number of primitives.
//!
//! Layout: an array of `vec4<f32>`; integers are stored as their bits (`bitcast<u32>`).
//!
//! ```text
//! [0]          (end, 0, 0, 0): the index one past the last entry
//! [1 .. end)   the entries, in the order of a depth-first walk of the hierarchy (the order in
//!              which the unrolled code tests them):
//!   group      [i]     (centre.xyz, GROUP)
//!              [i + 1] (half-extents.xyz, next): next is the index past the group's entries,
//!                      where a ray that does not enter the group's box goes on
//!   primitive  [i]     (offset.xyz, kind | FRAMED if rotated or scaled | material << 5)
//!              [i + 1] the shape: sphere (r², 0, 0, 0), box (half.xyz, 0), cylinder and
//!                      capsule (r², half height, 0, 0), plane (normal.xyz, height)
//!              [i + 2 .. i + 5] only when FRAMED: the rows of the world-to-local matrix
//! ```
//!
//! A group's entries follow its two vectors, so a walk goes to `i + 2` into a group it enters
//! and to `next` past one it does not, and `i` grows at every step: the walk needs no stack and
//! ends after at most `end` steps. An unrotated primitive takes 32 bytes, a rotated one 80,
//! a group 32.

use crate::scene::analytic::{Item, Primitive, Shape};
use crate::scene::V3;
use std::fmt::Write;

// An entry's tag, in both layouts of `scene_data` (this one, of a traced scene's primitives,
// and march.rs's, of a marched scene's instances): the kind of entry in the low bits
// (`KIND_BITS`), GROUP or a kind of leaf; `TRANSFORMED` for a leaf with a frame of its own;
// the material above `MATERIAL_SHIFT`.

/// The tag of a group; the other values of the kind bits are the kinds of leaf of a layout.
pub(super) const GROUP: u32 = 15;
/// The bits of a tag that hold the kind of entry.
pub(super) const KIND_BITS: u32 = 15;
/// The tag bit of a leaf with a frame of its own (a primitive with a world-to-local matrix
/// other than the identity, an instance with a rotation).
pub(super) const TRANSFORMED: u32 = 16;
/// Materials are numbered in the tag's bits above these.
pub(super) const MATERIAL_SHIFT: u32 = 5;

/// The tag of a leaf of kind `kind` (below [`GROUP`]).
pub(super) fn tag(kind: u32, transformed: bool, material: u32) -> u32 {
    kind | if transformed { TRANSFORMED } else { 0 } | material << MATERIAL_SHIFT
}

/// The kinds of primitive.
const SPHERE: u32 = 0;
const BOX: u32 = 1;
const CYLINDER: u32 = 2;
const CAPSULE: u32 = 3;
const PLANE: u32 = 4;
/// A mesh's kind, never written: [`fits`] keeps meshes out of this layout.
const MESH: u32 = 5;
/// The kernel's name of [`TRANSFORMED`] here: a primitive with a world-to-local matrix other
/// than the identity.
const FRAMED: u32 = TRANSFORMED;

/// Whether every material of `primitives` fits in a tag.
pub fn fits(primitives: &[Primitive]) -> bool {
    // A mesh's triangles are data of their own (mesh.rs's layout), which this layout does
    // not hold beside the primitives: a scene with a mesh is unrolled.
    primitives
        .iter()
        .all(|p| tag_holds(p.material.0) && !matches!(p.shape, Shape::Mesh { .. }))
}

/// Whether a material id fits in a tag's bits above [`MATERIAL_SHIFT`] (shared with the
/// marched kernel's entries, `march.rs`).
pub(super) fn tag_holds(material: u32) -> bool {
    material < 1 << (32 - MATERIAL_SHIFT)
}

fn kind(s: &Shape) -> u32 {
    match s {
        Shape::Sphere { .. } => SPHERE,
        Shape::Box { .. } => BOX,
        Shape::Cylinder { .. } => CYLINDER,
        Shape::Capsule { .. } => CAPSULE,
        Shape::Plane { .. } => PLANE,
        Shape::Mesh { .. } => MESH,
    }
}

/// The bits of `x` as the f32 the kernel reads (as the literals of the unrolled code are).
pub(super) fn bits(x: f64) -> u32 {
    (x as f32).clamp(-f32::MAX, f32::MAX).to_bits()
}

pub(super) fn vec(v: V3, w: u32) -> [u32; 4] {
    [bits(v[0]), bits(v[1]), bits(v[2]), w]
}

/// The contents of `scene_data` for `primitives` and their hierarchy `top`, as little-endian
/// bytes.
pub fn data(primitives: &[Primitive], top: &[Item]) -> Vec<u8> {
    entries(top, &mut |out, i| primitive(out, &primitives[i]))
}

/// The bytes of a `scene_data` buffer for a hierarchy `items`: `[0]` holds the index one past
/// the last entry, then the entries of a depth-first walk, a group as `(centre, group)` and
/// `(half-extents, next)`, a leaf as `leaf` writes it (the layout above; the marched kernel's
/// `march.rs` shares it with other leaves).
pub(super) fn entries(items: &[Item], leaf: &mut dyn FnMut(&mut Vec<[u32; 4]>, usize)) -> Vec<u8> {
    fn push(
        out: &mut Vec<[u32; 4]>,
        items: &[Item],
        leaf: &mut dyn FnMut(&mut Vec<[u32; 4]>, usize),
    ) {
        for item in items {
            match item {
                Item::Primitive(i) => leaf(out, *i),
                Item::Group(g) => {
                    let at = out.len();
                    out.push(vec(g.centre, GROUP));
                    out.push(vec(g.half, 0));
                    push(out, &g.items, leaf);
                    out[at + 1][3] = out.len() as u32;
                }
            }
        }
    }
    let mut out = vec![[0u32; 4]];
    push(&mut out, items, leaf);
    out[0][0] = out.len() as u32;
    out.iter().flatten().flat_map(|w| w.to_le_bytes()).collect()
}

fn primitive(out: &mut Vec<[u32; 4]>, p: &Primitive) {
    let framed = !identity(&p.matrix);
    let tag = tag(kind(&p.shape), framed, p.material.0);
    out.push(vec(p.offset, tag));
    out.push(match p.shape {
        Shape::Sphere { radius } => [bits(radius * radius), 0, 0, 0],
        Shape::Box { half } => vec(half, 0),
        Shape::Cylinder {
            radius,
            half_height,
        }
        | Shape::Capsule {
            radius,
            half_height,
        } => [bits(radius * radius), bits(half_height), 0, 0],
        Shape::Plane { normal, height } => vec(normal, bits(height)),
        // Never written ([`fits`]): the box, for completeness.
        Shape::Mesh { lo, hi, .. } => vec([0, 1, 2].map(|k| 0.5 * (hi[k] - lo[k])), 0),
    });
    if framed {
        out.extend(p.matrix.iter().map(|row| vec(*row, 0)));
    }
}

/// `fn trace` and `fn shadow` walking `scene_data`, and the interval of one of its
/// primitives; only the kinds of `primitives` are tested for, and groups only when `top` has
/// any; `glass` when some primitive is transparent.
pub fn write(primitives: &[Primitive], top: &[Item], glass: bool) -> String {
    let framed = primitives.iter().any(|p| !identity(&p.matrix));
    let groups = top.iter().any(|i| matches!(i, Item::Group(_)));
    let mut out = String::from(
        "// The entries of scene_data (the layout is in compiler/src/back/wgsl/buffer.rs): the\n\
         // kind of entry in a tag's low three bits, FRAMED for a rotated or scaled primitive,\n\
         // its material above.\n",
    );
    let _ = writeln!(out, "const GROUP: u32 = {GROUP}u;");
    if framed {
        let _ = writeln!(out, "const FRAMED: u32 = {FRAMED}u;");
    }
    out.push('\n');
    shape_interval(&mut out, primitives);
    primitive_interval(&mut out, framed);
    let step = if framed {
        "select(2u, 5u, (tag & FRAMED) != 0u)"
    } else {
        "2u"
    };
    out.push_str(
        "// The nearest surface along o + t·d, 0 < t < max_dist, with its normal and material: the\n\
         // entries of scene_data in order, past each group whose box the ray does not enter\n\
         // before the nearest hit so far.\n",
    );
    out.push_str("fn trace(o: vec3<f32>, d: vec3<f32>, t0: f32, sign: f32) -> Traced {\n");
    out.push_str(&trace_start(glass));
    // Only a transparent surface's distance gets the slack.
    let slack = if glass {
        format!("select(0.0, slack, params.materials[tag >> {MATERIAL_SHIFT}u].optics.y > 0.0)")
    } else {
        "0.0".into()
    };
    walk(
        &mut out,
        groups.then_some("enters(o - head.xyz, d, size.xyz, best.limit)"),
        &[
            &format!("best = nearest(best, primitive_interval(i, head, o, d), tag >> {MATERIAL_SHIFT}u, {slack});"),
            &format!("i += {step};"),
        ],
    );
    out.push_str("    return best;\n}\n\n");
    out.push_str(
        "// The light arriving along o + t·d, 0 < t < tmax: 0 behind an opaque primitive, else the\n\
         // product of the transparencies of the primitives the ray enters.\n",
    );
    out.push_str("fn shadow(o: vec3<f32>, d: vec3<f32>, t0: f32, tmax: f32, k: f32) -> f32 {\n");
    out.push_str("    counters.shadow += 1u;\n    var through = 1.0;\n");
    walk(
        &mut out,
        groups.then_some("enters(o - head.xyz, d, size.xyz, tmax)"),
        &[
            &format!("let tau = params.materials[tag >> {MATERIAL_SHIFT}u].optics.y;"),
            "through = occlude(through, primitive_interval(i, head, o, d), tmax, tau);",
            "if through == 0.0 {",
            "    return 0.0;",
            "}",
            &format!("i += {step};"),
        ],
    );
    out.push_str("    return through;\n}\n");
    out
}

/// The loop over the entries of `scene_data` (of the traced and the marched walks alike): a
/// group (centre `head.xyz`, half-size `size.xyz`) is entered where the WGSL condition `enter`
/// holds, else skipped to its end (with `enter` absent, the data has no groups); any other
/// entry is met by the statements `visit`, which step `i` past it.
pub(super) fn walk(out: &mut String, enter: Option<&str>, visit: &[&str]) {
    out.push_str("    let end = bitcast<u32>(scene_data[0u].x);\n    var i = 1u;\n");
    out.push_str("    while i < end {\n        let head = scene_data[i];\n");
    out.push_str("        let tag = bitcast<u32>(head.w);\n");
    if let Some(enter) = enter {
        out.push_str("        if tag == GROUP {\n            let size = scene_data[i + 1u];\n");
        let _ = writeln!(out, "            let enter = {enter};");
        out.push_str("            i = select(bitcast<u32>(size.w), i + 2u, enter);\n");
        out.push_str("            continue;\n        }\n");
    }
    for line in visit {
        let _ = writeln!(out, "        {line}");
    }
    out.push_str("    }\n");
}

/// `fn shape_interval`: the interval of a primitive of the tag's kind in its own frame, with
/// a branch for each kind among `primitives`.
fn shape_interval(out: &mut String, primitives: &[Primitive]) {
    out.push_str(
        "// The interval along (o, d) of a primitive of the tag's kind in its own frame, its shape\n\
         // given by s.\n",
    );
    out.push_str(
        "fn shape_interval(tag: u32, o: vec3<f32>, d: vec3<f32>, s: vec4<f32>) -> Interval {\n",
    );
    let kinds: Vec<u32> = primitives.iter().map(|p| kind(&p.shape)).collect();
    if kinds.windows(2).any(|w| w[0] != w[1]) {
        let _ = writeln!(out, "    let kind = tag & {KIND_BITS}u;");
    }
    let call = |k: u32| match k {
        SPHERE => "return sphere_interval(o, d, s.x);",
        BOX => "return box_interval(o, d, s.xyz);",
        CYLINDER => "return cylinder_interval(o, d, s.x, s.y);",
        CAPSULE => "return capsule_interval(o, d, s.x, s.y);",
        _ => "return plane_interval(o, d, s.xyz, s.w);",
    };
    branches(out, kinds.into_iter(), call, "return missed();");
    out.push_str("}\n\n");
}

/// The body of a function that dispatches on `kind` (a WGSL `u32` in scope): for each kind
/// among `kinds`, sorted, the statements `body(kind)` (which end in `return`), each but the
/// last under `if kind == …`; `empty` where there is no kind at all.
pub(super) fn branches<S: AsRef<str>>(
    out: &mut String,
    kinds: impl Iterator<Item = u32>,
    body: impl Fn(u32) -> S,
    empty: &str,
) {
    let mut kinds: Vec<u32> = kinds.collect();
    kinds.sort_unstable();
    kinds.dedup();
    for (n, &k) in kinds.iter().enumerate() {
        let last = n + 1 == kinds.len();
        let indent = if last { "    " } else { "        " };
        if !last {
            let _ = writeln!(out, "    if kind == {k}u {{");
        }
        for line in body(k).as_ref().lines() {
            let _ = writeln!(out, "{indent}{line}");
        }
        if !last {
            out.push_str("    }\n");
        }
    }
    if kinds.is_empty() {
        let _ = writeln!(out, "    {empty}");
    }
}

/// `fn primitive_interval`: the interval of the primitive whose entry starts at `i`, with
/// normals in world space (the frame's rows are read only for a FRAMED one).
fn primitive_interval(out: &mut String, framed: bool) {
    out.push_str(
        "// The interval along (o, d) of the primitive whose entry starts at scene_data[i] with\n\
         // head, with normals in world space.\n",
    );
    out.push_str(
        "fn primitive_interval(i: u32, head: vec4<f32>, o: vec3<f32>, d: vec3<f32>) -> Interval {\n",
    );
    out.push_str("    let tag = bitcast<u32>(head.w);\n    let offset = head.xyz;\n");
    out.push_str("    let s = scene_data[i + 1u];\n");
    if framed {
        out.push_str("    if (tag & FRAMED) != 0u {\n");
        for r in 0..3 {
            let _ = writeln!(out, "        let r{r} = scene_data[i + {}u].xyz;", r + 2);
        }
        out.push_str("        let local = shape_interval(tag, into(o, r0, r1, r2) + offset, into(d, r0, r1, r2), s);\n");
        out.push_str("        return to_world(local, r0, r1, r2);\n    }\n");
    }
    out.push_str("    return shape_interval(tag, o + offset, d, s);\n}\n\n");
}

/// The start of `fn trace`'s body, unrolled or walking `scene_data`: no hit yet, and, when
/// some primitive is transparent (`glass`), the slack a transparent surface's distance gets
/// inside glass (`nearest` in kernel.wgsl; `Tracer::nearest` on the CPU): the offset 4h of
/// secondary rays, with the normal step at the ray's origin.
pub(super) fn trace_start(glass: bool) -> String {
    let mut out = String::from(
        "    var best = Traced(params.march.y, STATUS_MISS, vec3<f32>(0.0), 0u, params.march.y);\n",
    );
    if glass {
        out.push_str("    let slack = select(0.0, 4.0 * normal_step(t0, o), sign < 0.0);\n");
    }
    out
}

/// Whether a world-to-local matrix is the identity (the primitive is neither rotated nor
/// scaled).
pub(super) fn identity(m: &[V3; 3]) -> bool {
    (0..3).all(|i| (0..3).all(|j| m[i][j] == if i == j { 1.0 } else { 0.0 }))
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::scene::analytic::hierarchy;
    use crate::scene::{MaterialId, NodeId};

    fn sphere(x: f64, material: u32) -> Primitive {
        let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        Primitive {
            shape: Shape::Sphere { radius: 0.5 },
            matrix: identity,
            offset: [-x, 0.0, 0.0],
            material: MaterialId(material),
            node: NodeId(0),
        }
    }

    /// The entries of `bytes`, four words each.
    pub(in super::super) fn words(bytes: &[u8]) -> Vec<[u32; 4]> {
        let w: Vec<u32> = bytes
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        w.chunks_exact(4)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect()
    }

    /// Walks the entries `e` of the data (`e[0][0]` its end) as the kernel does: checks that
    /// every group's `next` lies past its own entries and within the data, gives every
    /// other entry's index and tag to `entry`, which checks it and says how many entries it
    /// takes, and checks that the walk ends exactly at the end; returns the number of groups.
    pub(in super::super) fn walk(
        e: &[[u32; 4]],
        mut entry: impl FnMut(usize, u32) -> usize,
    ) -> usize {
        let end = e[0][0] as usize;
        assert_eq!(end, e.len());
        let (mut i, mut groups) = (1, 0);
        while i < end {
            let tag = e[i][3];
            if tag == GROUP {
                let next = e[i + 1][3] as usize;
                assert!(next > i + 2 && next <= end, "group at {i}: next {next}");
                groups += 1;
                i += 2;
            } else {
                i += entry(i, tag);
            }
        }
        assert_eq!(i, end);
        groups
    }

    /// Every primitive is written once, in the order of the hierarchy, and every group's
    /// `next` lies past its own entries and within the data, so the walk ends.
    #[test]
    fn entries_follow_the_hierarchy_and_groups_skip_forward() {
        let mut prims: Vec<Primitive> = (0..37).map(|i| sphere(i as f64 * 1.5, i % 3)).collect();
        prims[5].matrix = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        let top = hierarchy(&prims);
        let e = words(&data(&prims, &top));
        let (mut seen, mut framed) = (Vec::new(), Vec::new());
        let groups = walk(&e, |i, tag| {
            seen.push((f32::from_bits(e[i][0]), tag >> MATERIAL_SHIFT));
            assert_eq!(tag & KIND_BITS, SPHERE);
            if tag & FRAMED == 0 {
                return 2;
            }
            framed.push(seen.len() - 1);
            5
        });
        assert!(groups >= 9, "{groups} groups");
        let mut order = Vec::new();
        fn flatten(items: &[Item], out: &mut Vec<usize>) {
            for it in items {
                match it {
                    Item::Primitive(p) => out.push(*p),
                    Item::Group(g) => flatten(&g.items, out),
                }
            }
        }
        flatten(&top, &mut order);
        let expected: Vec<(f32, u32)> = order
            .iter()
            .map(|&p| (-(p as f64 * 1.5) as f32, p as u32 % 3))
            .collect();
        assert_eq!(seen, expected);
        let rotated: Vec<usize> = framed.iter().map(|&k| order[k]).collect();
        assert_eq!(rotated, [5]);
    }
}
