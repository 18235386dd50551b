//! Helpers shared by the mesh tests (`mesh.rs`, `mesh_accuracy.rs`): running `sdfc mesh`,
//! reading an STL back as a reader sees it, the closed-manifold check by positions with the
//! Euler characteristic, and the f64 distance program of a scene file.
#![allow(dead_code)]

use sdfc_compiler::{eval_point, lower, Program};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A fresh temporary directory for one test.
pub fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sdfc-mesh-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// The repository's root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Runs `sdfc` with `args`.
pub fn sdfc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .args(args)
        .output()
        .expect("run sdfc")
}

/// Runs `sdfc mesh` and insists that it succeeded.
pub fn mesh(args: &[&str]) -> String {
    let mut all = vec!["mesh"];
    all.extend_from_slice(args);
    let out = sdfc(&all);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "sdfc {all:?}: {err}");
    err
}

/// A triangle mesh as read back: positions and triangles.
#[derive(Debug, Default)]
pub struct Read {
    /// Positions.
    pub positions: Vec<[f32; 3]>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[usize; 3]>,
}

/// A binary STL as `stl_io` reads it.
pub fn read_stl(path: &Path) -> Read {
    let mut f = std::fs::File::open(path).expect("open stl");
    // stl_io merges vertices by their exact f32 bits: the positions an STL reader sees.
    let m = stl_io::read_stl(&mut f).expect("stl_io reads it");
    Read {
        positions: m.vertices.iter().map(|v| v.0).collect(),
        triangles: m.faces.iter().map(|f| f.vertices).collect(),
    }
}

/// Each vertex of `m` as the index of its position among the distinct positions (by their f32
/// bits), and how many distinct positions there are.
fn by_position(m: &Read) -> (Vec<usize>, usize) {
    let mut id: HashMap<[u32; 3], usize> = HashMap::new();
    let same: Vec<usize> = m
        .positions
        .iter()
        .map(|p| {
            let n = id.len();
            *id.entry(p.map(f32::to_bits)).or_insert(n)
        })
        .collect();
    (same, id.len())
}

/// Checks a closed, oriented 2-manifold by positions (vertices with the same f32 coordinates
/// are one vertex): every directed edge once and its reverse once (so each undirected edge
/// in exactly two triangles), no triangle of zero area. Returns the Euler characteristic.
pub fn manifold(m: &Read, what: &str) -> i64 {
    assert!(!m.triangles.is_empty(), "{what}: no triangles");
    let (same, _) = by_position(m);
    let mut directed: HashMap<(usize, usize), u32> = HashMap::new();
    for (k, t) in m.triangles.iter().enumerate() {
        let v = t.map(|i| same[i]);
        let p = t.map(|i| m.positions[i].map(f64::from));
        let u = [0, 1, 2].map(|i| p[1][i] - p[0][i]);
        let w = [0, 1, 2].map(|i| p[2][i] - p[0][i]);
        let c = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        assert!(
            c.iter().any(|x| *x != 0.0),
            "{what}: triangle {k} has zero area: {p:?}"
        );
        for (a, b) in [(v[0], v[1]), (v[1], v[2]), (v[2], v[0])] {
            assert_ne!(a, b, "{what}: triangle {k} repeats a vertex");
            *directed.entry((a, b)).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(n, 1, "{what}: directed edge {a}→{b} in {n} triangles");
        assert_eq!(
            directed.get(&(b, a)),
            Some(&1),
            "{what}: edge {a}–{b} has no opposite (open or inconsistently oriented)"
        );
    }
    let used: std::collections::HashSet<usize> =
        m.triangles.iter().flatten().map(|&i| same[i]).collect();
    let edges = directed.len() / 2;
    used.len() as i64 - edges as i64 + m.triangles.len() as i64
}

/// The f64 distance program of a scene file.
pub fn program(path: &Path) -> Program {
    let loaded = sdfc_runtime::frontend::load(path).expect("load");
    let scene = loaded.scene.expect("checks");
    lower(&scene)
}

/// The f64 distance at a point of a mesh.
pub fn distance(p: &Program, q: [f32; 3]) -> f64 {
    eval_point::<f64>(p, q.map(f64::from)).0
}

/// A Gridfinity-style bin in millimetres, 100 × 40 × 60 outside, walls 0.475 thick and a
/// divider as thin, slanted to the grid: thinner than a cell at the resolutions the tests use.
pub const THIN_WALLED_BIN: &str = "let outer = box((50, 20, 30));
let inner = box((49.525, 20, 29.525)).translate(0, 1.2, 0);
let divider = box((0.2375, 19, 29.6)).rotate_y(3deg).rotate_z(2deg).translate(3.1, 0, 0);
scene { union(outer.subtract(inner), divider); }
";

/// Writes a scene file into `d`.
pub fn write_scene(d: &Path, name: &str, body: &str) -> PathBuf {
    let p = d.join(name);
    std::fs::write(&p, body).expect("write scene");
    p
}

/// A fresh directory `test` holding the scene `file` written with `body`, and the path in it
/// that the mesh goes to, `out`: the directory, the scene's path and the output's.
pub fn scene_in(test: &str, file: &str, body: &str, out: &str) -> (PathBuf, PathBuf, PathBuf) {
    let d = dir(test);
    let scene = write_scene(&d, file, body);
    let out = d.join(out);
    (d, scene, out)
}

/// Runs `sdfc` with `args` and insists that it exited with `code`: its standard error.
#[track_caller]
pub fn exits(args: &[&str], code: i32) -> String {
    let out = sdfc(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(code), "sdfc {args:?}: {err}");
    err
}

/// The positions, the linear `COLOR_0` colours and the material's base colour of the one
/// primitive of a `.glb`.
pub fn glb_colours(path: &Path) -> (Vec<[f32; 3]>, Vec<[f32; 3]>, [f32; 4]) {
    let bytes = std::fs::read(path).expect("read glb");
    let gltf = gltf::Gltf::from_slice(&bytes).expect("gltf reads it");
    let blob = gltf.blob.clone();
    let prim = gltf
        .meshes()
        .next()
        .expect("a mesh")
        .primitives()
        .next()
        .expect("one");
    let reader = prim.reader(|_| blob.as_deref());
    let positions: Vec<[f32; 3]> = reader.read_positions().expect("positions").collect();
    let colours: Vec<[f32; 3]> = reader
        .read_colors(0)
        .expect("COLOR_0")
        .into_rgb_f32()
        .collect();
    let base = prim.material().pbr_metallic_roughness().base_color_factor();
    (positions, colours, base)
}

/// A path as a command-line argument.
pub fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}
/// The connected pieces of a mesh, its vertices joined by position (f32 bits) and edges.
pub fn components(m: &Read) -> usize {
    let (same, count) = by_position(m);
    let mut parent: Vec<usize> = (0..count).collect();
    fn find(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    for t in &m.triangles {
        for (a, b) in [(t[0], t[1]), (t[1], t[2])] {
            let (ra, rb) = (find(&mut parent, same[a]), find(&mut parent, same[b]));
            parent[ra] = rb;
        }
    }
    let used: std::collections::HashSet<usize> =
        m.triangles.iter().flatten().map(|&i| same[i]).collect();
    let roots: std::collections::HashSet<usize> =
        used.into_iter().map(|v| find(&mut parent, v)).collect();
    roots.len()
}
