//! `sdfc mesh --backend wgpu|cuda`: the mesh a GPU's f32 points kernel evaluates against the
//! CPU's f64 one, on the bracket, the knob and a thin-walled bin that is meshed again on finer
//! cells. "The same mesh" (docs/mesh.md, "On a GPU"): as many vertices and triangles, the
//! triangles the same but for at most 0.1 % (edges flipped, or not, beside a sharp edge),
//! and the vertices within 1 % of a cell of the CPU's but for at most 0.5 % of them (inner
//! vertices of patches whose normals lie at a threshold of the placement, which may be put
//! elsewhere in their cell). wgpu runs wherever an adapter opens
//! (lavapipe here; required under `SDFC_REQUIRE_DEVICES=1`), CUDA where a device is
//! (required under `SDFC_REQUIRE_CUDA=1`); the mesher's PTX is assembled by `ptxas` where it
//! is on the PATH.

use super::common::open_gpu;
use super::evaluators;
use super::meshes::{self, dir, exits, root, s, scene_in, sdfc, write_scene};
use crate::common::assert_has;
use sdfc_compiler::{Limits, LowerOptions};
use sdfc_runtime::backend::Backend;
use sdfc_runtime::commands::mesh::{surface, Meshed, Region, Spelling};
use sdfc_runtime::frontend::{self, DiagnosticFormat};
use sdfc_runtime::mesh::Settings;
use std::path::{Path, PathBuf};

/// An example compared: its name, scene file, the bounds it is meshed in, and the resolution.
type Case = (&'static str, PathBuf, Option<[[f64; 3]; 2]>, u32);

/// The examples compared.
fn cases() -> Vec<Case> {
    let d = dir("gpu_bin");
    // The bin of `mesh_accuracy`, smaller: its divider is thinner than a cell at 48.
    let bin = write_scene(&d, "bin.sdf", meshes::THIN_WALLED_BIN);
    vec![
        (
            "bracket",
            root().join("examples/mesh/bracket.sdf"),
            None,
            64,
        ),
        (
            "knob",
            root().join("examples/knob.sdf"),
            Some([[-1.1, 0.01, -1.1], [1.1, 1.25, 1.1]]),
            64,
        ),
        ("thin-walled bin", bin, None, 48),
    ]
}

fn meshed(file: &Path, bounds: Option<[[f64; 3]; 2]>, resolution: u32, backend: Backend) -> Meshed {
    let limits = Limits::default();
    let checked = frontend::load_scene_code(file, DiagnosticFormat::Human, &limits)
        .unwrap_or_else(|code| panic!("{}: exit {code}", file.display()));
    let region = Region {
        resolution: Some(resolution),
        voxel: None,
        bounds,
        spelling: Spelling::Flags,
    };
    let settings = Settings {
        backend,
        ..Settings::default()
    };
    let pool = rayon::ThreadPoolBuilder::new().build().expect("pool");
    surface(
        &checked,
        region,
        &settings,
        &limits,
        &pool,
        &|_, _| {},
        &|_| {},
    )
    .unwrap_or_else(|(_, why)| panic!("{} on {backend:?}: {why}", file.display()))
}

/// The mesh of `backend` is the CPU's within the stated tolerance.
fn agrees(what: &str, cpu: &Meshed, gpu: &Meshed) {
    let (a, b) = (&cpu.mesh, &gpu.mesh);
    assert_eq!(cpu.grid, gpu.grid, "{what}: the grids");
    assert_eq!(a.positions.len(), b.positions.len(), "{what}: vertices");
    assert_eq!(a.triangles.len(), b.triangles.len(), "{what}: triangles");
    let differ = a
        .triangles
        .iter()
        .zip(&b.triangles)
        .filter(|(s, t)| s != t)
        .count();
    assert!(
        differ * 1000 <= a.triangles.len(),
        "{what}: {differ} of {} triangles differ",
        a.triangles.len()
    );
    let voxel = cpu.grid.voxel;
    let apart: Vec<f64> = a
        .positions
        .iter()
        .zip(&b.positions)
        .map(|(p, q)| (0..3).map(|i| (p[i] - q[i]).powi(2)).sum::<f64>().sqrt() / voxel)
        .collect();
    let worst = apart.iter().copied().fold(0.0f64, f64::max);
    let off = apart.iter().filter(|&&d| d > 0.01).count();
    assert!(
        off * 200 <= apart.len(),
        "{what}: {off} of {} vertices more than 1 % of a cell from the CPU's",
        apart.len()
    );
    assert!(
        worst <= 3f64.sqrt(),
        "{what}: a vertex {worst} cells from the CPU's, out of its cell"
    );
    println!(
        "{what} on {}: {} triangles, {differ} differ; {off} of {} vertices more than 1 % of a \
         cell from the CPU's, the farthest {:.3} % of a cell",
        gpu.stats.backend,
        a.triangles.len(),
        apart.len(),
        100.0 * worst
    );
}

#[test]
fn wgpu_meshes_the_examples_as_the_cpu_does() {
    if open_gpu("meshing on wgpu").is_none() {
        return;
    }
    for (what, file, bounds, resolution) in cases() {
        let cpu = meshed(&file, bounds, resolution, Backend::Cpu);
        let gpu = meshed(&file, bounds, resolution, Backend::Wgpu);
        assert_eq!(cpu.stats.backend, "cpu");
        assert_eq!(gpu.stats.backend, "wgpu");
        assert!(gpu.stats.launches > 0, "{what}: no launch counted");
        if what == "thin-walled bin" {
            assert!(
                cpu.stats.refined_from.is_some() && gpu.stats.refined_from.is_some(),
                "{what}: meshed again on finer cells by both"
            );
        }
        agrees(what, &cpu, &gpu);
    }
}

#[test]
fn cuda_meshes_the_examples_as_the_cpu_does() {
    // The mesher's kernel (the part's `map`, without `map_distance`) assembles for sm_80.
    if let Some(ptxas) = evaluators::ptxas() {
        let d = dir("gpu_ptx");
        for (what, file, _, _) in cases() {
            let limits = Limits::default();
            let checked = frontend::load_scene_code(&file, DiagnosticFormat::Human, &limits)
                .unwrap_or_else(|code| panic!("{what}: exit {code}"));
            let lowered = checked
                .lower(&LowerOptions::default(), &limits)
                .unwrap_or_else(|_| panic!("{what}: lowered"));
            let m = evaluators::points_module(&checked.scene, &lowered, false);
            let ptx = d.join("mesh.ptx");
            std::fs::write(&ptx, evaluators::points_ptx(&m, 80)).expect("PTX written");
            let cubin = d.join("mesh.cubin");
            evaluators::assemble(&ptxas, &ptx, &cubin, &format!("{what}: the mesher's PTX"));
        }
    } else {
        println!("SKIPPED: ptxas: not on the PATH");
    }
    if let Err(why) = evaluators::open_cuda() {
        assert!(
            std::env::var("SDFC_REQUIRE_CUDA").as_deref() != Ok("1"),
            "SDFC_REQUIRE_CUDA=1 but CUDA cannot be opened: {why}"
        );
        println!("SKIPPED: meshing on CUDA: {why}");
        return;
    }
    for (what, file, bounds, resolution) in cases() {
        let cpu = meshed(&file, bounds, resolution, Backend::Cpu);
        let gpu = meshed(&file, bounds, resolution, Backend::Cuda);
        assert_eq!(gpu.stats.backend, "cuda");
        agrees(what, &cpu, &gpu);
    }
}

/// A backend that cannot be had is an error that names it and the way out, never a mesh
/// made on the CPU instead; `--stats` names what evaluated the points.
#[test]
fn a_missing_device_is_an_error_and_stats_name_the_backend() {
    let body = "scene { sphere(0.5); }\n";
    let (_, scene, out) = scene_in("gpu_cli", "ball.sdf", body, "ball.stl");
    if evaluators::open_cuda().is_err() {
        let err = exits(&["mesh", s(&scene), "-o", s(&out), "--backend", "cuda"], 1);
        assert_has(
            &err,
            &["error: --backend cuda cannot mesh here: found no CUDA device ("],
        );
        assert_has(&err, &["--backend cpu"]);
        assert!(!out.exists(), "no mesh is written");
    }
    let r = sdfc(&[
        "mesh",
        s(&scene),
        "-o",
        s(&out),
        "--stats",
        "--resolution",
        "16",
    ]);
    let stats = String::from_utf8_lossy(&r.stdout);
    assert!(r.status.success());
    assert_has(&stats, &["points", " on cpu, "]);
    let r = sdfc(&["mesh", s(&scene), "-o", s(&out), "--backend", "metal"]);
    assert_eq!(
        r.status.code(),
        Some(2),
        "an unknown backend is a usage error"
    );
}
