//! Triangle meshes (`mesh(path)`, program/mesh.rs) in `scene_data`, and `fn mesh_distance`,
//! the walk over a mesh's hierarchy that the distance program's `Op::Mesh` calls: the same
//! walk, nearest triangle and pseudo-normal sign as `TriMesh::distance`, in f32.
//!
//! Layout, from the mesh's `base` (in `vec4<f32>`, integers as their bits): one header
//! vector (x: the hierarchy's vectors, twice its nodes; y: the largest magnitude of a
//! coordinate of its box, which pads the walk's starting bound); the nodes, two vectors each
//! (`lo.xyz`, `first`; `hi.xyz`, `count`: a leaf's `count` triangles from `first`, or, when
//! `count` is 0, the children `first` and `first + 1`); then the triangles, nine vectors each
//! (the corners a, b, c, then the pseudo-normals of a, b, c and of the edges ab, bc, ca).
//! The meshes of a scene lie one after the other in the order they were read, each at the
//! `base` the checker gave it.
//!
//! Each invocation keeps, per mesh (four slots by `base`, each naming its mesh), the triangle
//! nearest to its last query, whose distance bounds the next walk from its start
//! (`TriMesh::distance_from`: the same result, fewer nodes).

use crate::program::mesh::{TriMesh, STACK};
use crate::program::Program;

/// The bytes of `scene_data` holding every mesh `programs` name, each at its base (a mesh of
/// the scene that none names leaves zeros).
pub fn data<'a>(programs: impl IntoIterator<Item = &'a Program>) -> Vec<u8> {
    data_of(programs.into_iter().flat_map(|p| p.meshes()))
}

/// The bytes of `scene_data` holding `meshes`, each at its base (a mesh of the scene not
/// among them leaves zeros).
pub fn data_of<'a>(meshes: impl IntoIterator<Item = &'a TriMesh>) -> Vec<u8> {
    let mut out: Vec<u8> = Vec::new();
    {
        for mesh in meshes {
            let start = mesh.base as usize * 16;
            let end = start + mesh.vectors() as usize * 16;
            if out.len() < end {
                out.resize(end, 0);
            }
            let mut at = start;
            let mut put = |v: [f32; 4]| {
                for x in v {
                    out[at..at + 4].copy_from_slice(&x.to_le_bytes());
                    at += 4;
                }
            };
            let bits = |u: u32| f32::from_bits(u);
            // The reach rounded up, so that the f32 pad is no smaller than the f64 one.
            let reach = mesh.reach() as f32;
            let reach = if f64::from(reach) < mesh.reach() {
                reach * (1.0 + f32::EPSILON)
            } else {
                reach
            };
            put([bits(2 * mesh.nodes().len() as u32), reach, 0.0, 0.0]);
            for n in mesh.nodes() {
                let [x, y, z] = n.lo.map(|v| v as f32);
                put([x, y, z, bits(n.first)]);
                let [x, y, z] = n.hi.map(|v| v as f32);
                put([x, y, z, bits(n.count)]);
            }
            for t in mesh.triangles() {
                for v in t {
                    let [x, y, z] = v.map(|c| c as f32);
                    put([x, y, z, 0.0]);
                }
            }
        }
    }
    out
}

/// The length of [`data_of`]'s bytes for `meshes`, without writing them.
pub fn data_len<'a>(meshes: impl IntoIterator<Item = &'a TriMesh>) -> u64 {
    meshes
        .into_iter()
        .map(|mesh| (u64::from(mesh.base) + mesh.vectors()) * 16)
        .max()
        .unwrap_or(0)
}

/// Whether `bytes` of meshes in `scene_data` are within the `scene_data` limit, or why not
/// (the marched kernels and a traced scene's read the same bytes).
pub(super) fn fits(scene: &crate::scene::Scene, bytes: u64) -> Result<(), super::Refused> {
    use crate::limits::Limit;
    let limit = scene.limits.get(Limit::SceneData);
    if bytes > limit.saturating_mul(1 << 20) {
        let mib = bytes.div_ceil(1 << 20);
        let raise = scene.limits.raise_to(Limit::SceneData, mib);
        return Err(super::Refused::MeshData { mib, limit, raise });
    }
    Ok(())
}

/// Whether a program names a mesh.
pub fn uses_meshes(program: &Program) -> bool {
    program.meshes().next().is_some()
}

/// `fn mesh_interval`, the ray's nearest crossing of a mesh's triangles, for an analytically
/// traced scene (the kernel's `Interval`, `missed` and `BIG`, analytic.rs): the hierarchy
/// walked nearer box first, each box entered before the best crossing so far (slab test),
/// each triangle by Möller and Trumbore's test ("Fast, minimum storage ray/triangle
/// intersection", Journal of Graphics Tools, 1997). The CPU's runtime/src/cpu/analytic.rs
/// walks it the same way.
pub fn write_hit() -> String {
    format!(
        "// Where o + t·d enters the box of the node at n (t >= 0), or BIG when it misses it.\n\
         fn mesh_enter(o: vec3<f32>, inv: vec3<f32>, n: u32) -> f32 {{\n\
         \x20   let t1 = (scene_data[n].xyz - o) * inv;\n\
         \x20   let t2 = (scene_data[n + 1u].xyz - o) * inv;\n\
         \x20   let lo = min(t1, t2);\n\
         \x20   let hi = max(t1, t2);\n\
         \x20   let near = max(max(lo.x, lo.y), max(lo.z, 0.0));\n\
         \x20   let far = min(min(hi.x, hi.y), hi.z);\n\
         \x20   return select(BIG, near, near <= far);\n\
         }}\n\n\
         // The nearest crossing of o + t·d, 0 < t < limit, with the triangles of the mesh at\n\
         // scene_data[base] (layout in compiler/src/back/wgsl/mesh.rs): one point, with the\n\
         // triangle's outward normal.\n\
         fn mesh_interval(o: vec3<f32>, d: vec3<f32>, base: u32, limit: f32) -> Interval {{\n\
         \x20   let nodes = base + 1u;\n\
         \x20   let tris = nodes + bitcast<u32>(scene_data[base].x);\n\
         \x20   // A zero component of d as a tiny one, so that no slab computes 0 · inf.\n\
         \x20   let inv = 1.0 / select(d, vec3<f32>(1e-30), abs(d) < vec3<f32>(1e-30));\n\
         \x20   var best = limit;\n\
         \x20   var hit = 0u;\n\
         {walk}\
         \x20               let a = scene_data[t].xyz;\n\
         \x20               let e1 = scene_data[t + 1u].xyz - a;\n\
         \x20               let e2 = scene_data[t + 2u].xyz - a;\n\
         \x20               let q = cross(d, e2);\n\
         \x20               let det = dot(e1, q);\n\
         \x20               if det == 0.0 {{ continue; }}\n\
         \x20               let f = 1.0 / det;\n\
         \x20               let s = o - a;\n\
         \x20               let u = f * dot(s, q);\n\
         \x20               let r = cross(s, e1);\n\
         \x20               let v = f * dot(d, r);\n\
         \x20               let h = f * dot(e2, r);\n\
         \x20               if u >= -{edge} && v >= -{edge} && u + v <= 1.0 + {edge} && h > 0.0 && h < best {{\n\
         \x20                   best = h;\n\
         \x20                   hit = t + 1u;\n\
         \x20               }}\n\
         \x20           }}\n\
         \x20           continue;\n\
         \x20       }}\n\
         \x20       let tl = mesh_enter(o, inv, nodes + 2u * first);\n\
         \x20       let tr = mesh_enter(o, inv, nodes + 2u * first + 2u);\n\
         {push}\
         \x20   if hit == 0u {{ return missed(); }}\n\
         \x20   let a = scene_data[hit - 1u].xyz;\n\
         \x20   let n = cross(scene_data[hit].xyz - a, scene_data[hit + 1u].xyz - a);\n\
         \x20   return Interval(best, best, n, n);\n\
         }}\n",
        edge = super::literal::float(TriMesh::EDGE),
        walk = walk_start("mesh_enter(o, inv, n)"),
        push = push_children("tl", "tr"),
    )
}

/// The WGSL functions of the mesh walk.
pub fn write() -> String {
    format!(
        "// Triangle meshes in scene_data (the layout is in compiler/src/back/wgsl/mesh.rs): the\n\
         // signed distance to the nearest triangle, its sign from the angle-weighted\n\
         // pseudo-normal of the feature nearest (program/mesh.rs).\n\
         fn mesh_box(p: vec3<f32>, n: u32) -> f32 {{\n\
         \x20   let d = max(max(scene_data[n].xyz - p, vec3<f32>(0.0)), p - scene_data[n + 1u].xyz);\n\
         \x20   return d.x * d.x + d.y * d.y + d.z * d.z;\n\
         }}\n\n\
         // The feature of the triangle at t nearest to p: corners 0-2, edges ab, bc, ca 3-5, the\n\
         // face 6 (Ericson, Real-Time Collision Detection, 2005, 5.1.5).\n\
         fn mesh_feature(p: vec3<f32>, t: u32) -> u32 {{\n\
         \x20   let a = scene_data[t].xyz;\n\
         \x20   let b = scene_data[t + 1u].xyz;\n\
         \x20   let c = scene_data[t + 2u].xyz;\n\
         \x20   let ab = b - a;\n\
         \x20   let ac = c - a;\n\
         \x20   let ap = p - a;\n\
         \x20   let d1 = dot(ab, ap);\n\
         \x20   let d2 = dot(ac, ap);\n\
         \x20   if d1 <= 0.0 && d2 <= 0.0 {{ return 0u; }}\n\
         \x20   let bp = p - b;\n\
         \x20   let d3 = dot(ab, bp);\n\
         \x20   let d4 = dot(ac, bp);\n\
         \x20   if d3 >= 0.0 && d4 <= d3 {{ return 1u; }}\n\
         \x20   let vc = d1 * d4 - d3 * d2;\n\
         \x20   if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {{ return 3u; }}\n\
         \x20   let cp = p - c;\n\
         \x20   let d5 = dot(ab, cp);\n\
         \x20   let d6 = dot(ac, cp);\n\
         \x20   if d6 >= 0.0 && d5 <= d6 {{ return 2u; }}\n\
         \x20   let vb = d5 * d2 - d1 * d6;\n\
         \x20   if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {{ return 5u; }}\n\
         \x20   let va = d3 * d6 - d5 * d4;\n\
         \x20   if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {{ return 4u; }}\n\
         \x20   return 6u;\n\
         }}\n\n\
         // The nearest point to p on feature f of the triangle at t.\n\
         fn mesh_point(p: vec3<f32>, t: u32, f: u32) -> vec3<f32> {{\n\
         \x20   if f < 3u {{ return scene_data[t + f].xyz; }}\n\
         \x20   if f < 6u {{\n\
         \x20       let s = scene_data[t + f - 3u].xyz;\n\
         \x20       let d = scene_data[t + select(f - 2u, 0u, f == 5u)].xyz - s;\n\
         \x20       return s + d * clamp(dot(p - s, d) / dot(d, d), 0.0, 1.0);\n\
         \x20   }}\n\
         \x20   let a = scene_data[t].xyz;\n\
         \x20   let n = cross(scene_data[t + 1u].xyz - a, scene_data[t + 2u].xyz - a);\n\
         \x20   return p - n * (dot(p - a, n) / dot(n, n));\n\
         }}\n\n\
         // Per slot (base % 4): the base of the mesh it holds and the triangle nearest to its\n\
         // last query (program/mesh.rs, TriMesh::distance_from).\n\
         var<private> mesh_hints: array<vec2<u32>, 4>;\n\n\
         // The signed distance at p to the mesh whose data starts at scene_data[base].\n\
         fn mesh_distance(p: vec3<f32>, base: u32) -> f32 {{\n\
         \x20   let nodes = base + 1u;\n\
         \x20   let tris = nodes + bitcast<u32>(scene_data[base].x);\n\
         \x20   // The walk starts bounded by the hinted triangle's distance, padded (bound_pad).\n\
         \x20   let slot = base & 3u;\n\
         \x20   let hint = tris + 9u * select(0u, mesh_hints[slot].y, mesh_hints[slot].x == base);\n\
         \x20   let hw = p - mesh_point(p, hint, mesh_feature(p, hint));\n\
         \x20   let hd = sqrt(hw.x * hw.x + hw.y * hw.y + hw.z * hw.z);\n\
         \x20   let ap = abs(p);\n\
         \x20   let bd = hd + 1e-5 * (scene_data[base].y + max(max(ap.x, ap.y), ap.z) + hd);\n\
         \x20   var best = select(3.4e38, bd * bd, bd * bd < 3.4e38);\n\
         \x20   var best_t = tris;\n\
         \x20   var best_f = 6u;\n\
         \x20   // Nodes still to visit, the nearer child on top ({STACK} levels hold any mesh).\n\
         {walk}\
         \x20               let f = mesh_feature(p, t);\n\
         \x20               let w = p - mesh_point(p, t, f);\n\
         \x20               let d2 = w.x * w.x + w.y * w.y + w.z * w.z;\n\
         \x20               if d2 < best {{\n\
         \x20                   best = d2;\n\
         \x20                   best_t = t;\n\
         \x20                   best_f = f;\n\
         \x20               }}\n\
         \x20           }}\n\
         \x20           continue;\n\
         \x20       }}\n\
         \x20       let dl = mesh_box(p, nodes + 2u * first);\n\
         \x20       let dr = mesh_box(p, nodes + 2u * first + 2u);\n\
         {push}\
         \x20   let w = p - mesh_point(p, best_t, best_f);\n\
         \x20   var n = scene_data[best_t + 3u + min(best_f, 5u)].xyz;\n\
         \x20   if best_f == 6u {{\n\
         \x20       let a = scene_data[best_t].xyz;\n\
         \x20       n = cross(scene_data[best_t + 1u].xyz - a, scene_data[best_t + 2u].xyz - a);\n\
         \x20   }}\n\
         \x20   mesh_hints[slot] = vec2<u32>(base, (best_t - tris) / 9u);\n\
         \x20   let d = sqrt(best);\n\
         \x20   return select(d, -d, w.x * n.x + w.y * n.y + w.z * n.z < 0.0);\n\
         }}\n",
        walk = walk_start("mesh_box(p, n)"),
        push = push_children("dl", "dr"),
    )
}

/// The start of a walk over the tree: the stack of nodes to visit, a node skipped where `enter`
/// (of its index `n`) is no nearer than `best`, and a leaf's loop over its triangles, `t` the
/// data of each.
fn walk_start(enter: &str) -> String {
    format!(
        "\x20   var stack: array<u32, {STACK}>;\n\
         \x20   var top = 1u;\n\
         \x20   stack[0] = 0u;\n\
         \x20   loop {{\n\
         \x20       if top == 0u {{ break; }}\n\
         \x20       top -= 1u;\n\
         \x20       let n = nodes + 2u * stack[top];\n\
         \x20       if {enter} >= best {{ continue; }}\n\
         \x20       let first = bitcast<u32>(scene_data[n].w);\n\
         \x20       let count = bitcast<u32>(scene_data[n + 1u].w);\n\
         \x20       if count > 0u {{\n\
         \x20           for (var k = 0u; k < count; k += 1u) {{\n\
         \x20               let t = tris + 9u * (first + k);\n"
    )
}

/// The end of a walk's loop over the tree, once the entries `l` and `r` of the node's two
/// children are known: each child that may hold something nearer than `best` is pushed, the
/// nearer on top; a walk that ended with nodes left is counted.
fn push_children(l: &str, r: &str) -> String {
    format!(
        "\x20       let right = {r} < {l};\n\
         \x20       if max({l}, {r}) < best {{\n\
         \x20           stack[top] = select(first + 1u, first, right);\n\
         \x20           top += 1u;\n\
         \x20       }}\n\
         \x20       if min({l}, {r}) < best {{\n\
         \x20           stack[top] = select(first, first + 1u, right);\n\
         \x20           top += 1u;\n\
         \x20       }}\n\
         \x20   }}\n\
         \x20   // Ended with nodes left: a software adapter cut the walk (see `trace`).\n\
         \x20   if top > 0u {{ counters.cut += 1u; }}\n"
    )
}
