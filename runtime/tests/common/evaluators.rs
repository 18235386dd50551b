//! The evaluators of a distance program, each run over one set of points: the f64 reference
//! (`Program::run` through `eval_point`), the f32 batch interpreter, the emitted Rust
//! (`back::rust`, compiled by `rustc`), and two WGSL modules joined to [`entry`], a compute
//! entry point that evaluates `map` over a storage buffer of points: the WGSL part
//! (`back::wgsl::part`) and the marched kernel whose root union's instances are walked in
//! `scene_data` (`back::wgsl::march`, its own formulas of the primitives), each run through
//! wgpu and, translated to PTX by `back::ptx`, through CUDA. Each returns (distance, material
//! id) per point, and the WGSL modules the distance alone too; the comparison of
//! `distance_conformance.rs` reads them. An evaluator whose tool is missing says why in its
//! `Err`.
#![allow(dead_code)]

use sdfc_compiler::back::{ptx, rust, wgsl};
use sdfc_compiler::eval::{eval_point, Evaluator, Float, Outputs, Tape};
use sdfc_compiler::lower::Lowered;
use sdfc_compiler::program::Program;
use sdfc_compiler::scene::{Method, Scene};
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use wgpu::naga;

/// One evaluation: the distance and the material id at a point.
pub type Value<T> = (T, u32);

/// The workgroup size of [`entry`].
pub const WORKGROUP: u32 = 64;

/// The name of [`entry`]'s entry point.
pub const ENTRY_POINT: &str = "eval_points";

/// The entry point joined to a module that declares `map` (distance, material id) and, where
/// given, the distance alone as `alone`, its two buffers in bind group `group`: thread `i`
/// evaluates them at point `i` (x, y, z; w unused) and writes (distance, material id, distance
/// alone or `map`'s distance again, 0).
/// The buffers hold a whole number of workgroups (the points padded, [`point_words`]), so
/// that no thread needs `arrayLength`, which PTX cannot know. With `warm` (a name), an odd
/// thread first calls it at the point before its own, so that the instance walk starts from
/// another point's hint.
pub fn entry(group: u32, alone: Option<&str>, warm: Option<&str>) -> String {
    let alone = alone.map_or("m.x".to_string(), |f| format!("{f}(p)"));
    let warm = warm.map_or(String::new(), |f| {
        format!("if (id.x & 1u) == 1u {{\n        _ = {f}(eval_points_in[id.x - 1u].xyz);\n    }}\n    ")
    });
    format!(
        "
@group({group}) @binding(0) var<storage, read> eval_points_in: array<vec4<f32>>;
@group({group}) @binding(1) var<storage, read_write> eval_points_out: array<vec4<f32>>;

@compute @workgroup_size({WORKGROUP})
fn {ENTRY_POINT}(@builtin(global_invocation_id) id: vec3<u32>) {{
    let p = eval_points_in[id.x].xyz;
    {warm}let m = map(p);
    eval_points_out[id.x] = vec4<f32>(m, {alone}, 0.0);
}}
"
    )
}

/// A WGSL module with [`entry`], validated by naga, and what it binds besides its points.
pub struct PointsModule {
    pub source: String,
    pub module: naga::Module,
    pub info: naga::valid::ModuleInfo,
    /// The bind group of the points and results.
    pub group: u32,
    /// The bytes of `scene_data` (group 0, binding 4), where the module reads it.
    pub data: Option<Vec<u8>>,
}

fn validated(source: String, group: u32, data: Option<Vec<u8>>) -> PointsModule {
    let module = naga::front::wgsl::parse_str(&source)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
    PointsModule {
        source,
        module,
        info,
        group,
        data,
    }
}

/// The part of `scene` (as lowered), `map` and, with `alone`, `map_distance`, with [`entry`].
pub fn points_module(scene: &Scene, lowered: &Lowered, alone: bool) -> PointsModule {
    let part = wgsl::part::write(scene, lowered, "map").expect("the part validates");
    let alone = alone.then_some("map_distance");
    validated(
        format!("{}\n{}", part.source, entry(0, alone, None)),
        0,
        None,
    )
}

/// The marched kernel of `scene` with every instance of its root union walked in
/// `scene_data`, its `map` and `sdf` with [`entry`] (in bind group 1, beside the kernel's
/// group 0), every other point's walks hinted by `sdf` at the point before it; none where
/// the scene has no instances.
pub fn walk_module(scene: &Scene) -> Option<PointsModule> {
    let mut marched = scene.clone();
    marched.settings.method = Method::March;
    let lowered = Lowered::new(&marched);
    lowered.instances(0)?;
    let options = wgsl::Options {
        max_instances: 0,
        ..Default::default()
    };
    let kernel = wgsl::write_with(&marched, &lowered, &options).expect("the kernel validates");
    let walked = kernel.source.contains("fn walk_map(");
    let data = kernel.data.filter(|_| walked)?;
    Some(validated(
        format!("{}\n{}", kernel.source, entry(1, Some("sdf"), Some("sdf"))),
        1,
        Some(data),
    ))
}

/// The PTX of a [`PointsModule`]'s entry point for `sm`.
pub fn points_ptx(m: &PointsModule, sm: u32) -> String {
    let options = ptx::Options {
        sm,
        entry_point: ENTRY_POINT.into(),
    };
    ptx::write(&m.module, &m.info, &options)
        .unwrap_or_else(|e| panic!("PTX: {e}"))
        .text
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

/// The points as the entry point reads them: x, y, z, 0 per point, padded with the origin to
/// a whole number of workgroups, as bytes.
fn point_bytes(points: &[[f64; 3]]) -> Vec<u8> {
    let padded = groups(points) as usize * WORKGROUP as usize;
    let mut words: Vec<f32> = points
        .iter()
        .flat_map(|p| [p[0] as f32, p[1] as f32, p[2] as f32, 0.0])
        .collect();
    words.resize(4 * padded, 0.0);
    words.iter().flat_map(|w| w.to_le_bytes()).collect()
}

/// The workgroups that cover `points`.
fn groups(points: &[[f64; 3]]) -> u32 {
    (points.len() as u32).div_ceil(WORKGROUP)
}

/// The results' size in bytes: a vec4<f32> for every thread.
fn result_bytes(points: &[[f64; 3]]) -> u64 {
    groups(points) as u64 * WORKGROUP as u64 * 16
}

/// What [`entry`] computed at each point: `map` (distance, material id) and the distance
/// alone.
pub type Results = (Vec<Value<f32>>, Vec<f32>);

/// Results as the entry point writes them, for the first `n` points.
fn results(bytes: &[u8], n: usize) -> Results {
    let words: Vec<f32> = bytes
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    let quads = || words.chunks_exact(4).take(n);
    (
        quads().map(|c| (c[0], c[1] as u32)).collect(),
        quads().map(|c| c[2]).collect(),
    )
}

/// [`entry`] of `m` run through wgpu on `gpu` at every point.
pub fn run_wgpu(gpu: &sdfc_runtime::gpu::Gpu, m: &PointsModule, points: &[[f64; 3]]) -> Results {
    let (device, queue) = (gpu.device(), gpu.queue());
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("distance over points"),
        source: wgpu::ShaderSource::Wgsl(m.source.as_str().into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: None,
        layout: None,
        module: &module,
        entry_point: Some(ENTRY_POINT),
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
    let input = point_bytes(points);
    let size = result_bytes(points);
    let points_buf = buffer(input.len() as u64, U::STORAGE | U::COPY_DST);
    queue.write_buffer(&points_buf, 0, &input);
    let out = buffer(size, U::STORAGE | U::COPY_SRC);
    let readback = buffer(size, U::MAP_READ | U::COPY_DST);
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(m.group),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: points_buf.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: out.as_entire_binding(),
            },
        ],
    });
    let data = m.data.as_ref().map(|bytes| {
        let b = buffer(bytes.len() as u64, U::STORAGE | U::COPY_DST);
        queue.write_buffer(&b, 0, bytes);
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[wgpu::BindGroupEntry {
                binding: 4,
                resource: b.as_entire_binding(),
            }],
        })
    });
    let mut enc = device.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(m.group, &bind, &[]);
        if let Some(d) = &data {
            pass.set_bind_group(0, d, &[]);
        }
        pass.dispatch_workgroups(groups(points), 1, 1);
    }
    enc.copy_buffer_to_buffer(&out, 0, &readback, 0, size);
    queue.submit([enc.finish()]);
    let slice = readback.slice(..);
    slice.map_async(wgpu::MapMode::Read, |r| r.expect("map"));
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("poll");
    let bytes = slice.get_mapped_range().expect("mapped").to_vec();
    results(&bytes, points.len())
}

/// A CUDA device, opened for [`run_cuda`], with its compute capability, or why there is
/// none.
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

/// [`entry`] of `m` translated to PTX (`ptx_text`, for the context's device) run through
/// CUDA at every point. The kernel's parameters are the module's buffers in (group,
/// binding) order (docs/ptx.md): the points and results, `scene_data`, and a small zeroed
/// buffer for each binding the entry point does not use (the renderer kernel's others).
pub fn run_cuda(
    ctx: &std::sync::Arc<cudarc::driver::CudaContext>,
    m: &PointsModule,
    ptx_text: &str,
    points: &[[f64; 3]],
) -> Results {
    use cudarc::driver::{LaunchConfig, PushKernelArg};
    let module = ctx
        .load_module(cudarc::nvrtc::Ptx::from_src(ptx_text))
        .unwrap_or_else(|e| panic!("the CUDA JIT refused the PTX: {e}"));
    let function = module.load_function(ENTRY_POINT).expect("the kernel");
    let s = ctx.default_stream();
    let mut bindings: Vec<(u32, u32)> = m
        .module
        .global_variables
        .iter()
        .filter_map(|(_, g)| g.binding.as_ref().map(|b| (b.group, b.binding)))
        .collect();
    bindings.sort();
    let out_at = bindings
        .iter()
        .position(|&b| b == (m.group, 1))
        .expect("the results' binding");
    let buffers: Vec<cudarc::driver::CudaSlice<u8>> = bindings
        .iter()
        .map(|&b| {
            let bytes = match b {
                b if b == (m.group, 0) => point_bytes(points),
                b if b == (m.group, 1) => vec![0; result_bytes(points) as usize],
                (0, 4) => m.data.clone().expect("scene_data"),
                _ => vec![0; 256],
            };
            s.clone_htod(&bytes).expect("upload")
        })
        .collect();
    let cfg = LaunchConfig {
        grid_dim: (groups(points), 1, 1),
        block_dim: (WORKGROUP, 1, 1),
        shared_mem_bytes: 0,
    };
    let mut launch = s.launch_builder(&function);
    for b in &buffers {
        launch.arg(b);
    }
    // SAFETY: the kernel's parameters are the module's buffers in (group, binding) order, as
    // the PTX back end declares them, each passed here; the points and results hold one
    // element for every thread of the grid, scene_data is the kernel's own, and the entry
    // point reads nothing of the other buffers.
    #[allow(unsafe_code)]
    unsafe { launch.launch(cfg) }.expect("launch");
    s.synchronize().expect("run");
    results(
        &s.clone_dtoh(&buffers[out_at]).expect("read back"),
        points.len(),
    )
}

/// `ptxas` on the PATH, if any.
pub fn ptxas() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join("ptxas"))
        .find(|p| p.is_file())
}

/// Whether the environment asks for every device of its kind: then a missing one fails.
pub fn required(var: &str) -> bool {
    std::env::var(var).is_ok_and(|v| v == "1")
}
