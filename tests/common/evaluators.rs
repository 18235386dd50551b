//! The evaluators of a distance program, each run over one set of points: the f64 reference
//! (`Program::run` through `eval_point`), the f32 batch interpreter, the emitted Rust
//! (`back::rust`, compiled by `rustc`), and the WGSL part (`back::wgsl::part`) joined to
//! [`ENTRY`], a compute entry point that evaluates `map` over a storage buffer of points, run
//! through wgpu and, translated to PTX by `back::ptx`, through CUDA. Each returns
//! (distance, material id) per point; the comparison of `distance_conformance.rs` reads
//! them. An evaluator whose tool or device is missing says why in its `Err`.
#![allow(dead_code)]

use sdfc_compiler::back::{ptx, rust, wgsl};
use sdfc_compiler::eval::{eval_point, Evaluator, Outputs, Tape};
use sdfc_compiler::lower::Lowered;
use sdfc_compiler::program::Program;
use sdfc_compiler::scene::Scene;
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use wgpu::naga;

/// One evaluation: the distance and the material id at a point.
pub type Value<T> = (T, u32);

/// The workgroup size of [`ENTRY`].
pub const WORKGROUP: u32 = 64;

/// The entry point joined to a scene's `--part map` (named `map`): thread `i` evaluates
/// `map` at point `i` (x, y, z; w unused) and writes (distance, material id). The buffers
/// hold a whole number of workgroups (the points padded, [`point_words`]), so that no
/// thread needs `arrayLength`, which PTX cannot know.
pub const ENTRY: &str = "
@group(0) @binding(0) var<storage, read> points: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> results: array<vec2<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    results[id.x] = map(points[id.x].xyz);
}
";

/// The WGSL module of the evaluator over points: the part of `scene` (as lowered) with
/// [`ENTRY`], validated by naga.
pub fn points_module(
    scene: &Scene,
    lowered: &Lowered,
) -> (String, naga::Module, naga::valid::ModuleInfo) {
    let part = wgsl::part::write(scene, lowered, "map").expect("the part validates");
    let source = format!("{}\n{ENTRY}", part.source);
    let module = naga::front::wgsl::parse_str(&source)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
    (source, module, info)
}

/// The PTX of [`points_module`] for `sm`.
pub fn points_ptx(module: &naga::Module, info: &naga::valid::ModuleInfo, sm: u32) -> String {
    let options = ptx::Options {
        sm,
        entry_point: "main".into(),
    };
    ptx::write(module, info, &options).unwrap_or_else(|e| panic!("PTX: {e}"))
}

/// The f64 reference at every point.
pub fn reference(program: &Program, points: &[[f64; 3]]) -> Vec<Value<f64>> {
    points
        .iter()
        .map(|&p| eval_point::<f64>(program, p))
        .collect()
}

/// The f32 batch interpreter at every point (coordinates rounded to f32).
pub fn interpreter(program: &Program, points: &[[f64; 3]]) -> Vec<Value<f32>> {
    let tape = Tape::new(program, Outputs::DistanceAndMaterial);
    let mut ev = Evaluator::<f32>::new(&tape, 64);
    let coord = |i: usize| points.iter().map(|p| p[i] as f32).collect::<Vec<f32>>();
    let mut d = vec![0.0f32; points.len()];
    let mut m = vec![0u32; points.len()];
    ev.eval(&coord(0), &coord(1), &coord(2), &mut d, Some(&mut m));
    d.into_iter().zip(m).collect()
}

/// The emitted Rust of every program, compiled by `rustc` into one program (each scene a
/// module, glam's vector types stood in for) that reads the points as f32 bits from a file
/// and prints each result's bits: per program, the f32 `map` at every point.
pub fn emitted_rust(
    programs: &[&Program],
    points: &[[f64; 3]],
    dir: &Path,
) -> Result<Vec<Vec<Value<f32>>>, String> {
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
        "fn main() {\n    let path = std::env::args().nth(1).expect(\"points file\");\n    let bytes = std::fs::read(path).expect(\"points\");\n    let f: Vec<f32> = bytes.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();\n    let mut out = String::new();\n",
    );
    for i in 0..programs.len() {
        let _ = writeln!(
            src,
            "    for p in f.chunks_exact(3) {{ let (d, m) = s{i}::map(glam::Vec3 {{ x: p[0], y: p[1], z: p[2] }}); out.push_str(&format!(\"{{}} {{}}\\n\", d.to_bits(), m)); }}"
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
        .flat_map(|p| p.iter().flat_map(|&c| (c as f32).to_le_bytes()))
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
    let run = Command::new(&exe)
        .arg(&input)
        .output()
        .expect("run the emitted Rust");
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let text = String::from_utf8_lossy(&run.stdout);
    let mut values = text.lines().map(|line| {
        let (d, m) = line.split_once(' ').expect("two words");
        (
            f32::from_bits(d.parse().expect("bits")),
            m.parse().expect("material"),
        )
    });
    Ok(programs
        .iter()
        .map(|_| values.by_ref().take(points.len()).collect())
        .collect())
}

/// The points as the entry point reads them: x, y, z, 0 per point, padded with the origin to
/// a whole number of workgroups.
fn point_words(points: &[[f64; 3]]) -> Vec<f32> {
    let padded = groups(points) as usize * WORKGROUP as usize;
    let mut words: Vec<f32> = points
        .iter()
        .flat_map(|p| [p[0] as f32, p[1] as f32, p[2] as f32, 0.0])
        .collect();
    words.resize(4 * padded, 0.0);
    words
}

/// The workgroups that cover `points`.
fn groups(points: &[[f64; 3]]) -> u32 {
    (points.len() as u32).div_ceil(WORKGROUP)
}

/// The results' size in bytes: a vec2<f32> for every thread.
fn result_bytes(points: &[[f64; 3]]) -> u64 {
    groups(points) as u64 * WORKGROUP as u64 * 8
}

/// Results as the entry point writes them, distance and material id (as a float) per
/// thread, for the first `n` points.
fn values(words: &[f32], n: usize) -> Vec<Value<f32>> {
    words
        .chunks_exact(2)
        .take(n)
        .map(|c| (c[0], c[1] as u32))
        .collect()
}

/// [`ENTRY`] of `wgsl` run through wgpu on `gpu` at every point.
pub fn run_wgpu(gpu: &sdfc_runtime::gpu::Gpu, wgsl: &str, points: &[[f64; 3]]) -> Vec<Value<f32>> {
    let (device, queue) = (gpu.device(), gpu.queue());
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("distance over points"),
        source: wgpu::ShaderSource::Wgsl(wgsl.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: None,
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    use wgpu::BufferUsages as U;
    let buffer = |size: u64, usage: U| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size,
            usage,
            mapped_at_creation: false,
        })
    };
    let input: Vec<u8> = point_words(points)
        .iter()
        .flat_map(|w| w.to_le_bytes())
        .collect();
    let size = result_bytes(points);
    let points_buf = buffer(input.len() as u64, U::STORAGE | U::COPY_DST);
    queue.write_buffer(&points_buf, 0, &input);
    let results = buffer(size, U::STORAGE | U::COPY_SRC);
    let readback = buffer(size, U::MAP_READ | U::COPY_DST);
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: points_buf.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: results.as_entire_binding(),
            },
        ],
    });
    let mut enc = device.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups(groups(points), 1, 1);
    }
    enc.copy_buffer_to_buffer(&results, 0, &readback, 0, size);
    queue.submit([enc.finish()]);
    let slice = readback.slice(..);
    slice.map_async(wgpu::MapMode::Read, |r| r.expect("map"));
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("poll");
    let bytes = slice.get_mapped_range().expect("mapped").to_vec();
    let words: Vec<f32> = bytes
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    values(&words, points.len())
}

/// A CUDA device, opened for [`run_cuda`], or why there is none.
pub fn open_cuda() -> Result<(std::sync::Arc<cudarc::driver::CudaContext>, u32), String> {
    use cudarc::driver::{sys, CudaContext};
    // SAFETY: only tries to dlopen libcuda; no driver call is made.
    #[allow(unsafe_code)]
    let present = unsafe { sys::is_culib_present() };
    if !present {
        return Err("no CUDA driver (libcuda.so)".into());
    }
    match CudaContext::device_count() {
        Ok(n) if n > 0 => {}
        Ok(_) => return Err("the CUDA driver found no device".into()),
        Err(e) => return Err(format!("the CUDA driver: {e}")),
    }
    let ctx = CudaContext::new(0).map_err(|e| format!("a CUDA context: {e}"))?;
    let attr = |a| ctx.attribute(a).map_err(|e| format!("{e}"));
    let major = attr(sys::CUdevice_attribute::CU_DEVICE_ATTRIBUTE_COMPUTE_CAPABILITY_MAJOR)?;
    let minor = attr(sys::CUdevice_attribute::CU_DEVICE_ATTRIBUTE_COMPUTE_CAPABILITY_MINOR)?;
    Ok((ctx, (major * 10 + minor) as u32))
}

/// [`ENTRY`] translated to PTX (`ptx`, for the context's device) run through CUDA at every
/// point.
pub fn run_cuda(
    ctx: &std::sync::Arc<cudarc::driver::CudaContext>,
    ptx_text: &str,
    points: &[[f64; 3]],
) -> Vec<Value<f32>> {
    use cudarc::driver::{LaunchConfig, PushKernelArg};
    let module = ctx
        .load_module(cudarc::nvrtc::Ptx::from_src(ptx_text))
        .unwrap_or_else(|e| panic!("the CUDA JIT refused the PTX: {e}"));
    let function = module.load_function("main").expect("the kernel");
    let s = ctx.default_stream();
    let d_points = s.clone_htod(&point_words(points)).expect("upload");
    let mut d_results = s
        .alloc_zeros::<f32>(result_bytes(points) as usize / 4)
        .expect("allocate");
    let cfg = LaunchConfig {
        grid_dim: (groups(points), 1, 1),
        block_dim: (WORKGROUP, 1, 1),
        shared_mem_bytes: 0,
    };
    let mut launch = s.launch_builder(&function);
    launch.arg(&d_points).arg(&mut d_results);
    // SAFETY: the kernel's parameters are its two buffers in binding order, as the PTX back
    // end declares them; each holds one element for every thread of the grid.
    #[allow(unsafe_code)]
    unsafe { launch.launch(cfg) }.expect("launch");
    s.synchronize().expect("run");
    values(&s.clone_dtoh(&d_results).expect("read back"), points.len())
}

/// `ptxas` on the PATH, if any.
pub fn ptxas() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join("ptxas"))
        .find(|p| p.is_file())
}

/// Whether the environment asks for every device: then a missing one fails.
pub fn required(var: &str) -> bool {
    std::env::var(var).is_ok_and(|v| v == "1")
}
