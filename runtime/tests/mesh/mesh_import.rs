//! `mesh(path)`: every format `sdfc mesh` writes reads back to the same field; a meshed
//! sphere (compiler/tests/in/mesh/sphere.ply) is within its own error of `sphere` as a field and as
//! a CPU render; the shape composes with transforms, `round`, `shell`, smooth blends,
//! `repeat` and materials, and `sdfc mesh` remeshes it; bad files are errors at the call
//! that read them, naming where in the file, and never a crash.

use crate::common;
use crate::common::assert_has;
use crate::common::words;
use crate::glb::glb;
use common::run_ok;

use sdfc_compiler::{Lowered, Rng, Scene};
use sdfc_runtime::cpu::{self, Options};
use std::path::{Path, PathBuf};
use std::process::Command;

/// A scratch folder of this test.
fn scratch(what: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sdfc-mesh-import-{}-{what}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

/// A scratch folder holding a copy of compiler/tests/in/mesh/sphere.ply.
fn with_sphere(what: &str) -> PathBuf {
    let dir = scratch(what);
    let from = Path::new(env!("CARGO_MANIFEST_DIR")).join("../compiler/tests/in/mesh/sphere.ply");
    std::fs::copy(from, dir.join("sphere.ply")).expect("copy the sphere");
    dir
}

/// The scene of `text` written as `name` in `dir`, checked: the scene or the diagnostics.
fn check(dir: &Path, name: &str, text: &str) -> Result<Scene, Vec<sdfc_compiler::Diagnostic>> {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write the scene");
    let loaded = sdfc_runtime::frontend::load(&path).expect("readable");
    loaded.scene.ok_or(loaded.diagnostics)
}

/// The f64 distances of a scene's program at `points`.
fn distances(scene: &Scene, points: &[[f64; 3]]) -> Vec<f64> {
    let program = Lowered::new(scene).program;
    points
        .iter()
        .map(|&p| program.run(p, |_| {})[program.distance().0 as usize])
        .collect()
}

fn points(n: usize, s: f64) -> Vec<[f64; 3]> {
    let mut rng = Rng::new(40);
    (0..n).map(|_| rng.point(s)).collect()
}

const LIGHTS: &str = "light point { position: (-3, 4, -4), intensity: 1 }\n\
                      camera { position: (0, 0.5, -3.5), look_at: (0, 0, 0), fov: 45deg }\n\
                      render { width: 64, height: 48 }\n";

#[test]
fn every_format_sdfc_mesh_writes_reads_back_the_same() {
    let dir = scratch("formats");
    std::fs::write(
        dir.join("part.sdf"),
        format!(
            "{LIGHTS}scene {{ smooth_union(0.2, box(0.4), sphere(0.35).translate(0.4, 0.3, 0)); }}"
        ),
    )
    .expect("write");
    let pts = points(200, 1.5);
    let mut first: Option<Vec<f64>> = None;
    for ext in ["stl", "obj", "ply", "glb"] {
        run_ok(
            Command::new(env!("CARGO_BIN_EXE_sdfc"))
                .args(["mesh", "part.sdf", "--resolution", "12", "-o"])
                .arg(format!("part.{ext}"))
                .current_dir(&dir),
            "run sdfc mesh",
        );
        let scene = check(
            &dir,
            "read.sdf",
            &format!("{LIGHTS}scene {{ mesh(\"part.{ext}\"); }}"),
        )
        .unwrap_or_else(|d| panic!("{ext}: {d:?}"));
        let d = distances(&scene, &pts);
        match &first {
            None => first = Some(d),
            Some(f) => assert_eq!(f, &d, "{ext} reads back another field than stl"),
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The sphere `sdfc mesh` wrote (compiler/tests/in/mesh/sphere.ply, radius 1 at resolution 10) is
/// within its own error of the unit sphere: at every point the two distances differ by at
/// most the Hausdorff distance between the mesh and the sphere, bounded by the vertices'
/// distance from the sphere and the triangles' depth below it.
#[test]
fn a_meshed_sphere_is_a_sphere_within_its_own_error() {
    let dir = with_sphere("sphere");
    let mesh_scene = check(
        &dir,
        "mesh.sdf",
        &format!("{LIGHTS}scene {{ mesh(\"sphere.ply\"); }}"),
    )
    .expect("the mesh scene checks");
    let sphere = check(
        &dir,
        "sphere.sdf",
        &format!("{LIGHTS}scene {{ sphere(1); }}"),
    )
    .expect("checks");
    // The mesh's error: its vertices off the sphere, and its faces inside it.
    let program = Lowered::new(&mesh_scene).program;
    let mesh = program.meshes().next().expect("a mesh");
    let mut error = 0.0f64;
    for t in mesh.triangles() {
        for v in &t[..3] {
            error = error.max(((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt() - 1.0).abs());
        }
    }
    // No point of the mesh is nearer the centre than the nearest triangle.
    error = error.max(1.0 + mesh.distance([0.0, 0.0, 0.0]));
    assert!(error > 0.0 && error < 0.05, "the mesh's error is {error}");
    let pts = points(400, 2.0);
    for ((p, a), b) in pts
        .iter()
        .zip(distances(&mesh_scene, &pts))
        .zip(distances(&sphere, &pts))
    {
        assert!(
            (a - b).abs() <= error + 1e-9,
            "at {p:?}: mesh {a}, sphere {b}, error {error}"
        );
    }
    // As pictures: only pixels on the silhouette and the shading of the facets differ.
    let render = |s: &Scene| cpu::render(s, &Lowered::new(s), &Options::default(), &|| {});
    let (a, b) = (render(&mesh_scene), render(&sphere));
    let diff = sdfc_runtime::metrics::compare(&a.image, &b.image, 0.1).expect("same size");
    assert!(diff.differing < 0.03 && diff.psnr > 28.0, "{diff:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A mesh under every operation the issue names renders, and `sdfc mesh` remeshes it.
#[test]
fn a_mesh_composes_and_remeshes() {
    let dir = with_sphere("compose");
    let text = format!(
        "{LIGHTS}material red = phong {{ color: (0.9, 0.2, 0.2) }};\n\
         let m = mesh(\"sphere.ply\", 0.5);\n\
         scene {{\n\
           smooth_union(0.1, m.round(0.05).shell(0.02), box(0.3).translate(0.5, 0, 0)) @ red;\n\
           m.rotate_y(30deg).translate(0, 1, 0);\n\
           m.repeat((3, 0, 0), (3, 1, 1)).translate(0, -1.5, 0);\n\
         }}"
    );
    let scene = check(&dir, "compose.sdf", &text).unwrap_or_else(|d| panic!("{d:?}"));
    // The mesh at half scale: 0.5 from the centre, within the mesh's own error.
    let d = distances(&scene, &[[0.0, 1.6, 0.0]]);
    assert!((d[0] - 0.1).abs() < 0.01, "{d:?}");
    std::fs::write(
        dir.join("round.sdf"),
        format!("{LIGHTS}scene {{ mesh(\"sphere.ply\").round(0.1); }}"),
    )
    .expect("write");
    run_ok(
        Command::new(env!("CARGO_BIN_EXE_sdfc"))
            .args(["mesh", "round.sdf", "--resolution", "16", "-o", "round.stl"])
            .current_dir(&dir),
        "run sdfc mesh",
    );
    // The remeshed, rounded sphere has radius 1.1: its vertices lie near that.
    let remeshed = check(
        &dir,
        "back.sdf",
        &format!("{LIGHTS}scene {{ mesh(\"round.stl\"); }}"),
    )
    .expect("checks");
    let d = distances(&remeshed, &[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]]);
    assert!(
        (d[0] + 1.1).abs() < 0.03 && (d[1] - 0.9).abs() < 0.03,
        "{d:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Bad files: an error E0400 at the `mesh` call whose message says what and where.
#[test]
fn bad_mesh_files_are_located_errors() {
    let dir = scratch("bad");
    let stl = |count: u32, tris: &[[f32; 9]]| {
        let mut b = vec![b' '; 80];
        b.extend_from_slice(&count.to_le_bytes());
        for t in tris {
            b.extend_from_slice(&[0u8; 12]);
            for x in t {
                b.extend_from_slice(&x.to_le_bytes());
            }
            b.extend_from_slice(&[0, 0]);
        }
        b
    };
    let tri = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let nan = [f32::NAN, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    // A binary STL whose 80-byte header begins with `solid`, cut short.
    let mut solid = stl(2, &[tri, tri]);
    solid[..5].copy_from_slice(b"solid");
    solid.truncate(120);
    // An ASCII STL cut in the middle of `endfacet`.
    let cut = b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfa".to_vec();
    // A glTF file whose index buffer view starts 2^64 - 1 bytes in.
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],"bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":{},"byteLength":12}}],"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}},{{"bufferView":1,"componentType":5125,"count":3,"type":"SCALAR"}}]}}"#,
        u64::MAX
    );
    let mut bin: Vec<u8> = tri.iter().flat_map(|x: &f32| x.to_le_bytes()).collect();
    bin.extend([0u32, 1, 2].iter().flat_map(|i| i.to_le_bytes()));
    let offset = glb(&json, &bin);
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("truncated.stl", stl(2, &[tri])[..120].to_vec(), "truncated binary STL"),
        ("nan.stl", stl(1, &[nan]), "not a finite number"),
        ("empty.stl", stl(0, &[]), "no triangles"),
        ("huge.stl", stl(100_000_000, &[tri]), "at byte 80"),
        ("flat.stl", stl(1, &[[0.0; 9]]), "no area"),
        ("bad.obj", b"v 0 0 0\nv 1 0 0\nf 1 2 7\n".to_vec(), "line 3"),
        ("short.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 100000000\nproperty float x\nend_header\n".to_vec(), "truncated PLY"),
        ("bad.glb", b"glTF\x02\0\0\0\xff\xff\0\0".to_vec(), "glTF"),
        ("solid.stl", solid, "truncated binary STL"),
        ("cut.stl", cut, "line 8: ASCII STL: expected `endfacet`, found `endfa`"),
        ("offset.glb", offset, "at `bufferViews[1]` of the JSON chunk"),
        ("sparse.glb", glb(&json.replace(r#""type":"SCALAR""#, r#""type":"SCALAR","sparse":{}"#), &bin), "accessors[1].sparse"),
        ("v1.glb", { let mut b = glb(&json, &bin); b[4] = 1; b }, "glTF version 1"),
        ("missing.stl", Vec::new(), "cannot read"),
        ("part.txt", Vec::new(), "not a mesh file"),
    ];
    for (name, bytes, says) in &cases {
        if *name != "missing.stl" {
            std::fs::write(dir.join(name), bytes).expect("write");
        }
        let text = format!("{LIGHTS}scene {{\n  mesh(\"{name}\");\n}}");
        let diags = check(&dir, "bad.sdf", &text).map(|_| ()).expect_err(name);
        let e = diags
            .iter()
            .find(|d| d.code == "E0400")
            .unwrap_or_else(|| panic!("{name}: {diags:?}"));
        assert!(e.message.contains(says), "{name}: {}", e.message);
        let at = e.span();
        assert_eq!(
            &text[at.start as usize..at.end as usize],
            format!("mesh(\"{name}\")"),
            "{name}"
        );
    }
    // The limit names the flag that raises it, with the value that would do: the file's
    // triangles and those of the meshes read before it (not twice the limit).
    let other = [0.0, 0.0, 1.0, 1.0, 0.0, 1.0, 0.0, 1.0, 1.0];
    std::fs::write(dir.join("two.stl"), stl(2, &[tri, other])).expect("write");
    std::fs::write(dir.join("three.stl"), stl(3, &[tri, other, tri])).expect("write");
    let mut limits = sdfc_compiler::Limits::default();
    limits
        .set(sdfc_compiler::Limit::Triangles, 4)
        .expect("a valid limit");
    for (scene, says) in [
        ("mesh(\"two.stl\"); mesh(\"three.stl\");", "the file has 3 triangles, and the scene's other meshes 2, more than the `triangles` limit of 4; raise it with `--limit triangles=5`"),
        ("mesh(\"three.stl\", 2); mesh(\"three.stl\");", "the file has 3 triangles, and the scene's other meshes 3, more than the `triangles` limit of 4; raise it with `--limit triangles=6`"),
    ] {
        let path = dir.join("limited.sdf");
        std::fs::write(&path, format!("{LIGHTS}scene {{ {scene} }}")).expect("write");
        let loaded = sdfc_runtime::frontend::load_with(&path, &limits).expect("readable");
        assert!(
            loaded.diagnostics.iter().any(|d| d.message.contains(says)),
            "{scene}: {:?}",
            loaded.diagnostics
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A software adapter (lavapipe) ends every loop of a shader once they have iterated 65 535
/// times together; a shell of a finely meshed ball spends that on its distance walks, and the
/// picture came out streaked (28.9 dB from the CPU) without a word. The kernel counts the
/// loops ended that way and such a frame is refused with the reason; on a GPU it renders as
/// the CPU does.
#[test]
fn a_software_adapter_that_would_cut_loops_refuses_instead_of_a_wrong_picture() {
    use sdfc_runtime::backend::{Backend, Prepared};
    let Some(gpu) = common::open_gpu("a mesh scene on a software adapter") else {
        return;
    };
    let dir = scratch("software_cut");
    std::fs::write(dir.join("ball.sdf"), "scene { sphere(1); }").expect("write");
    run_ok(
        std::process::Command::new(env!("CARGO_BIN_EXE_sdfc"))
            .current_dir(&dir)
            .args(["mesh", "ball.sdf", "-o", "ball.stl", "--resolution", "96"]),
        "sdfc mesh runs",
    );
    let scene = check(
        &dir,
        "shell.sdf",
        "camera { position: (0.5, 1.5, -4), look_at: (0.5, 0, 0), fov: 45deg }\n\
         light point { position: (3, 5, -4) }\n\
         render { width: 32, height: 24 }\n\
         scene { smooth_union(0.2, mesh(\"ball.stl\").shell(0.05), box(0.5).translate(1, 0, 0)).round(0.02); }",
    )
    .expect("a valid scene");
    let frame = Prepared::new(Backend::Wgpu, &scene, sdfc_runtime::cpu::Precision::F32)
        .expect("prepared")
        .render(&scene, &|_| {});
    // The command line asks for the image alone (no `--stats`): a software adapter counts
    // its cut loops all the same (it wrote the streaked picture without a word).
    let cli = std::process::Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .current_dir(&dir)
        .args(words("render shell.sdf --backend wgpu -o shell.png"))
        .output()
        .expect("sdfc render runs");
    let stderr = String::from_utf8_lossy(&cli.stderr);
    if gpu.is_cpu() {
        let Err(e) = frame else {
            panic!("rendered on a software adapter, where it should be refused");
        };
        let e = e.to_string();
        assert_has(&e, &["65 535", "--backend cpu"]);
        assert!(
            !cli.status.success() && stderr.contains("65 535"),
            "{stderr}"
        );
        assert!(
            !dir.join("shell.png").exists(),
            "a refused frame wrote its picture"
        );
    } else {
        let frame = frame.expect("a GPU renders it");
        assert_eq!(frame.render.stats.counters.cut, 0);
        assert!(cli.status.success(), "{stderr}");
    }
}

/// The seeds of the `mesh_file` fuzz target (fuzz/seeds/mesh_file/: a byte picking the
/// format, then the file) are valid files of each format, so that a fuzz run starts from
/// inputs that reach every reader's whole path.
#[test]
fn the_mesh_file_fuzz_seeds_read() {
    use sdfc_compiler::meshfile::{read, Format};
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/seeds/mesh_file");
    let mut formats = Vec::new();
    for entry in std::fs::read_dir(&dir).expect("the seeds") {
        let path = entry.expect("an entry").path();
        let bytes = std::fs::read(&path).expect("a seed");
        let format = [Format::Stl, Format::Obj, Format::Ply, Format::Glb][bytes[0] as usize % 4];
        let r =
            read(format, &bytes[1..], 1000).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(!r.faces.is_empty());
        formats.push(format);
    }
    for f in [Format::Stl, Format::Obj, Format::Ply, Format::Glb] {
        assert!(formats.contains(&f), "no seed of {f:?}");
    }
}
