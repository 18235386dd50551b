//! The WGSL of an analytically traced scene: the interval functions of `intervals.wgsl` its
//! primitives use, `fn trace` (nearest hit, its normal and material) and `fn shadow` (any-hit
//! shadow rays) on top of the kernel template's `ANALYTIC` block. Up to [`MAX_UNROLLED`]
//! primitives, both are unrolled over the primitives and their hierarchy; beyond, they walk
//! the primitives and hierarchy stored in the `scene_data` buffer (buffer.rs). A scene with
//! a triangle mesh is unrolled, its triangles and their hierarchy in `scene_data` (mesh.rs's
//! layout), met by `fn mesh_interval`.

use super::buffer::{self, identity, trace_start};
use super::literal::float;
use crate::scene::analytic::{Item, Primitive, Shape, Traced};
use crate::scene::{MaterialId, V3};
use std::fmt::Write;

/// The interval functions, in sections named by `//= NAME` lines.
const INTERVALS: &str = include_str!("intervals.wgsl");

/// The sections of [`INTERVALS`] that `primitives` and their hierarchy `top` use.
fn sections(primitives: &[Primitive], top: &[Item]) -> String {
    let has = |f: fn(&Shape) -> bool| primitives.iter().any(|p| f(&p.shape));
    let capsule = has(|s| matches!(s, Shape::Capsule { .. }));
    let groups = top.iter().any(|i| matches!(i, Item::Group(_)));
    let boxes = groups || has(|s| matches!(s, Shape::Box { .. }));
    let cylinders = capsule || has(|s| matches!(s, Shape::Cylinder { .. }));
    let framed = primitives.iter().any(|p| !identity(&p.matrix));
    let wanted = |name: &str| match name {
        "sphere" => capsule || has(|s| matches!(s, Shape::Sphere { .. })),
        "slab" | "clip" => boxes || cylinders,
        "box" => boxes,
        "cylinder" => cylinders,
        "capsule" => capsule,
        "plane" => has(|s| matches!(s, Shape::Plane { .. })),
        "enters" => groups,
        "into" | "to_world" => framed,
        _ => false,
    };
    let mut out = String::new();
    for section in INTERVALS.split("//= ").skip(1) {
        let (name, body) = section.split_once('\n').unwrap_or((section, ""));
        if wanted(name.trim()) {
            out.push_str(body.trim_end());
            out.push_str("\n\n");
        }
    }
    out
}

/// The most primitives whose intersections are unrolled into the kernel. Unrolled, every
/// primitive's constants are immediates and nothing is read from memory, which keeps small
/// scenes fast, but the kernel grows by about 180 lines of PTX a primitive and ptxas's time
/// more than in proportion (seconds for a few hundred primitives, minutes for 10 000). Up to
/// 256 the one-time cost stays within seconds (and the driver caches the result), and every
/// example keeps the unrolled code. Beyond, the walk over `scene_data` reads 32 bytes per
/// unrotated primitive or group it visits and its kernel is 2 000 lines of PTX whatever the
/// scene's size (`Options::max_unrolled` chooses either way for one scene).
pub const MAX_UNROLLED: usize = 256;

/// The interval functions the scene uses and `fn trace` and `fn shadow`: unrolled over the
/// primitives (with their frame constants) up to `max_unrolled` of them ([`MAX_UNROLLED`] by
/// default), else walking the buffer `scene_data`, whose bytes are returned too. `clear`
/// says which materials are transparent.
pub fn write(
    traced: &Traced,
    clear: &dyn Fn(MaterialId) -> bool,
    max_unrolled: usize,
) -> (String, Option<Vec<u8>>) {
    let (primitives, top) = (&traced.primitives[..], &traced.hierarchy[..]);
    let mut out = sections(primitives, top);
    let glass = primitives.iter().any(|p| clear(p.material));
    let bases: Vec<u32> = traced.meshes.iter().map(|m| m.0.base).collect();
    let meshes = (!bases.is_empty()).then(|| {
        out.push_str(&super::mesh::write_hit());
        out.push('\n');
        super::mesh::data_of(traced.meshes.iter().map(|m| &*m.0))
    });
    // The buffer's layout holds no mesh (`buffer::fits` keeps a scene with one unrolled), so
    // the meshes' bytes are never dropped here.
    if primitives.len() > max_unrolled && buffer::fits(primitives) {
        out.push_str(&buffer::write(primitives, top, glass));
        return (out, Some(buffer::data(primitives, top)));
    }
    if primitives.iter().any(|p| !identity(&p.matrix)) {
        out.push_str("// The world-to-local rows of the primitives that are rotated or scaled.\n");
    }
    for (i, p) in primitives.iter().enumerate() {
        if !identity(&p.matrix) {
            for (r, row) in p.matrix.iter().enumerate() {
                let _ = writeln!(out, "const P{i}_R{r} = {};", vec3(*row));
            }
        }
    }
    if primitives.iter().any(|p| !identity(&p.matrix)) {
        out.push('\n');
    }
    out.push_str(
        "// The nearest surface along o + t·d, 0 < t < max_dist, with its normal and material.\n",
    );
    out.push_str("fn trace(o: vec3<f32>, d: vec3<f32>, t0: f32, sign: f32) -> Traced {\n");
    out.push_str(&trace_start(glass));
    // Only a transparent surface's distance gets the slack.
    let nearest = |i: usize, p: &Primitive| {
        format!(
            "best = nearest(best, {}, {}u, {});",
            interval(i, p, "best.limit", &bases),
            p.material.0,
            if clear(p.material) { "slack" } else { "0.0" }
        )
    };
    items(&mut out, primitives, top, 1, "best.limit", &nearest);
    out.push_str("    return best;\n}\n\n");
    out.push_str(
        "// The light arriving along o + t·d, 0 < t < tmax: 0 behind an opaque primitive, else the\n\
         // product of the transparencies of the primitives the ray enters.\n",
    );
    out.push_str("fn shadow(o: vec3<f32>, d: vec3<f32>, t0: f32, tmax: f32, k: f32) -> f32 {\n");
    out.push_str("    counters.shadow += 1u;\n    var through = 1.0;\n");
    let occlude = |i: usize, p: &Primitive| {
        format!(
            "through = occlude(through, {}, tmax, params.materials[{}u].optics.y);",
            interval(i, p, "tmax", &bases),
            p.material.0
        )
    };
    items(&mut out, primitives, top, 1, "tmax", &occlude);
    out.push_str("    return through;\n}\n");
    (out, meshes)
}

/// Writes the statements of `items` at `depth`: one `test` per primitive, each group's items
/// inside an `if` that the ray enters the group's box before `limit`.
fn items(
    out: &mut String,
    primitives: &[Primitive],
    items_here: &[Item],
    depth: usize,
    limit: &str,
    test: &dyn Fn(usize, &Primitive) -> String,
) {
    let pad = "    ".repeat(depth);
    for item in items_here {
        match item {
            Item::Primitive(i) => {
                let p = &primitives[*i];
                let _ = writeln!(out, "{pad}// node {} {}", p.node.0, name(&p.shape));
                let _ = writeln!(out, "{pad}{}", test(*i, p));
            }
            Item::Group(g) => {
                let _ = writeln!(
                    out,
                    "{pad}if enters(o - {}, d, {}, {limit}) {{",
                    vec3(g.centre),
                    vec3(g.half)
                );
                self::items(out, primitives, &g.items, depth + 1, limit, test);
                let _ = writeln!(out, "{pad}}}");
            }
        }
    }
}

fn name(s: &Shape) -> &'static str {
    match s {
        Shape::Sphere { .. } => "sphere",
        Shape::Box { .. } => "box",
        Shape::Cylinder { .. } => "cylinder",
        Shape::Capsule { .. } => "capsule",
        Shape::Plane { .. } => "plane",
        Shape::Mesh { .. } => "mesh",
    }
}

fn vec3(v: V3) -> String {
    format!(
        "vec3<f32>({}, {}, {})",
        float(v[0]),
        float(v[1]),
        float(v[2])
    )
}

/// The expression of primitive `i`'s interval along the ray (o, d), normals in world space;
/// a mesh's (whose data starts at its entry of `bases`) is searched before `limit` alone.
fn interval(i: usize, p: &Primitive, limit: &str, bases: &[u32]) -> String {
    let plain = identity(&p.matrix);
    let rows = format!("P{i}_R0, P{i}_R1, P{i}_R2");
    let moved = |v: &str| {
        if plain {
            v.to_string()
        } else {
            format!("into({v}, {rows})")
        }
    };
    let origin = if p.offset == [0.0; 3] {
        moved("o")
    } else {
        format!("{} + {}", moved("o"), vec3(p.offset))
    };
    let dir = moved("d");
    let call = match p.shape {
        Shape::Sphere { radius } => {
            format!(
                "sphere_interval({origin}, {dir}, {})",
                float(radius * radius)
            )
        }
        Shape::Box { half } => format!("box_interval({origin}, {dir}, {})", vec3(half)),
        Shape::Cylinder {
            radius,
            half_height,
        } => format!(
            "cylinder_interval({origin}, {dir}, {}, {})",
            float(radius * radius),
            float(half_height)
        ),
        Shape::Capsule {
            radius,
            half_height,
        } => format!(
            "capsule_interval({origin}, {dir}, {}, {})",
            float(radius * radius),
            float(half_height)
        ),
        Shape::Plane { normal, height } => format!(
            "plane_interval({origin}, {dir}, {}, {})",
            vec3(normal),
            float(height)
        ),
        Shape::Mesh { index, .. } => format!(
            "mesh_interval({origin}, {dir}, {}u, {limit})",
            bases[index as usize]
        ),
    };
    if plain {
        call
    } else {
        format!("to_world({call}, {rows})")
    }
}
