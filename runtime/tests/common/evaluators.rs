//! The evaluators of a distance program, each run over one set of points: the f64 reference
//! (`Program::run` through `eval_point`), the f32 batch interpreter, the emitted Rust
//! (`back::rust`, compiled by `rustc`), and two WGSL modules joined to a compute entry point
//! that evaluates `map` over a storage buffer of points (the runtime's `gpu::points`): the
//! WGSL part (`back::wgsl::part`) and the marched kernel whose root union's instances are
//! walked in `scene_data` (`back::wgsl::march`, its own formulas of the primitives), each run
//! through wgpu and, translated to PTX by `back::ptx`, through CUDA. Each returns (distance, material
//! id) per point, and the WGSL modules the distance alone too; the comparison of
//! `distance_conformance.rs` reads them. An evaluator whose tool is missing says why in its
//! `Err`.
#![allow(dead_code)]

use sdfc_compiler::{eval_point, rust, Evaluator, Float, Lowered, Outputs, Program, Scene, Tape};
use sdfc_runtime::gpu::points;
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

#[allow(unused_imports)] // Not every test binary that includes this module uses each.
pub use sdfc_runtime::gpu::points::{open_cuda, PointsModule, Results, Value};

/// [`sdfc_runtime::gpu::points::points_module`], which the tests expect to validate.
pub fn points_module(scene: &Scene, lowered: &Lowered, alone: bool) -> PointsModule {
    points::points_module(scene, lowered, alone).unwrap_or_else(|e| panic!("{e}"))
}

/// [`sdfc_runtime::gpu::points::walk_module`], which the tests expect to validate.
pub fn walk_module(scene: &Scene) -> Option<PointsModule> {
    points::walk_module(scene).map(|m| m.unwrap_or_else(|e| panic!("{e}")))
}

/// [`sdfc_runtime::gpu::points::points_ptx`], which the tests expect to translate.
pub fn points_ptx(m: &PointsModule, sm: u32) -> String {
    points::points_ptx(m, sm).unwrap_or_else(|e| panic!("{e}"))
}

/// [`sdfc_runtime::gpu::points::run_wgpu`], which the tests expect to run.
pub fn run_wgpu(gpu: &sdfc_runtime::gpu::Gpu, m: &PointsModule, points: &[[f64; 3]]) -> Results {
    points::run_wgpu(gpu, m, points).unwrap_or_else(|e| panic!("{e}"))
}

/// [`sdfc_runtime::gpu::points::run_cuda`], which the tests expect to run.
pub fn run_cuda(
    ctx: &std::sync::Arc<cudarc::driver::CudaContext>,
    m: &PointsModule,
    ptx_text: &str,
    points: &[[f64; 3]],
) -> Results {
    points::run_cuda(ctx, m, ptx_text, points).unwrap_or_else(|e| panic!("{e}"))
}

/// The f64 reference at every point.
pub fn reference(program: &Program, points: &[[f64; 3]]) -> Vec<Value<f64>> {
    points
        .iter()
        .map(|&p| eval_point::<f64>(program, p))
        .collect()
}

/// The batch interpreter in `T` at every point (coordinates rounded to `T`).
pub fn interpreter<T: Float>(program: &Program, points: &[[f64; 3]]) -> Vec<Value<T>> {
    let tape = Tape::new(program, Outputs::DistanceAndMaterial);
    let mut ev = Evaluator::<T>::new(&tape, 64);
    let coord = |i: usize| points.iter().map(|p| T::from_f64(p[i])).collect::<Vec<T>>();
    let mut d = vec![T::zero(); points.len()];
    let mut m = vec![0u32; points.len()];
    ev.eval(&coord(0), &coord(1), &coord(2), &mut d, Some(&mut m));
    d.into_iter().zip(m).collect()
}

/// What the emitted Rust computed: per program, its f32 `map` and its f64 `map_f64` at
/// every point.
pub struct RustResults {
    pub f32: Vec<Vec<Value<f32>>>,
    pub f64: Vec<Vec<Value<f64>>>,
}

/// The emitted Rust of every program, compiled by `rustc` into one program (each scene a
/// module, glam's vector types stood in for) that reads the points as f64 bits from a file
/// and prints the bits of `map` (at the point rounded to f32) and `map_f64` at each.
pub fn emitted_rust(
    programs: &[&Program],
    points: &[[f64; 3]],
    dir: &Path,
) -> Result<RustResults, String> {
    let mut src = String::from(
        "#![allow(dead_code)]\nmod glam {\n    #[derive(Clone, Copy)]\n    pub struct Vec3 { pub x: f32, pub y: f32, pub z: f32 }\n    #[derive(Clone, Copy)]\n    pub struct DVec3 { pub x: f64, pub y: f64, pub z: f64 }\n}\n",
    );
    for (i, program) in programs.iter().enumerate() {
        let _ = writeln!(
            src,
            "mod s{i} {{\nuse super::glam;\n{}\n}}",
            rust::write(program)
        );
    }
    src.push_str(
        "fn main() {\n    let path = std::env::args().nth(1).expect(\"points file\");\n    let bytes = std::fs::read(path).expect(\"points\");\n    let c: Vec<f64> = bytes.chunks_exact(8).map(|b| f64::from_le_bytes(b.try_into().unwrap())).collect();\n    let mut out = String::new();\n",
    );
    for i in 0..programs.len() {
        let _ = writeln!(
            src,
            "    for p in c.chunks_exact(3) {{\n        let (a, m) = s{i}::map(glam::Vec3 {{ x: p[0] as f32, y: p[1] as f32, z: p[2] as f32 }});\n        let (b, n) = s{i}::map_f64(glam::DVec3 {{ x: p[0], y: p[1], z: p[2] }});\n        out.push_str(&format!(\"{{}} {{}} {{}} {{}}\\n\", a.to_bits(), m, b.to_bits(), n));\n    }}"
        );
    }
    src.push_str("    print!(\"{out}\");\n}\n");
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let (source, exe, input) = (
        dir.join("eval.rs"),
        dir.join("eval"),
        dir.join("points.bin"),
    );
    std::fs::write(&source, src).map_err(|e| e.to_string())?;
    let bits: Vec<u8> = points
        .iter()
        .flat_map(|p| p.iter().flat_map(|c| c.to_le_bytes()))
        .collect();
    std::fs::write(&input, bits).map_err(|e| e.to_string())?;
    let compiled = Command::new("rustc")
        .args(["--edition", "2021", "-C", "opt-level=1", "-o"])
        .arg(&exe)
        .arg(&source)
        .output()
        .map_err(|e| format!("no rustc on the PATH ({e})"))?;
    assert!(
        compiled.status.success(),
        "the emitted Rust does not compile:\n{}",
        String::from_utf8_lossy(&compiled.stderr)
    );
    let run = crate::common::run_ok(Command::new(&exe).arg(&input), "the emitted Rust");
    let text = String::from_utf8_lossy(&run.stdout);
    let mut rows = text.lines().map(|line| {
        let w: Vec<&str> = line.split(' ').collect();
        assert_eq!(w.len(), 4, "{line}");
        let n = |i: usize| -> u64 { w[i].parse().expect("a number") };
        (
            (f32::from_bits(n(0) as u32), n(1) as u32),
            (f64::from_bits(n(2)), n(3) as u32),
        )
    });
    let mut results = RustResults {
        f32: Vec::new(),
        f64: Vec::new(),
    };
    for _ in programs {
        let (a, b): (Vec<_>, Vec<_>) = rows.by_ref().take(points.len()).unzip();
        assert_eq!(
            a.len(),
            points.len(),
            "the emitted Rust printed too few results"
        );
        results.f32.push(a);
        results.f64.push(b);
    }
    Ok(results)
}

/// `ptxas` on the PATH, if any.
pub fn ptxas() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join("ptxas"))
        .find(|p| p.is_file())
}

/// The PTX file `ptx` assembled by `ptxas` for sm_80 into `cubin`, which must succeed
/// (`what` names the PTX in the failure).
pub fn assemble(ptxas: &Path, ptx: &Path, cubin: &Path, what: &str) {
    let mut command = Command::new(ptxas);
    command.args(["-arch=sm_80", "-o"]).arg(cubin).arg(ptx);
    crate::common::run_ok(&mut command, &format!("ptxas on {what}"));
}

/// Whether the environment asks for every device of its kind: then a missing one fails.
pub fn required(var: &str) -> bool {
    std::env::var(var).is_ok_and(|v| v == "1")
}
