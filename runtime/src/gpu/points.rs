//! Distances at points on a GPU: a compute entry point joined to a WGSL module that declares
//! `map` (the scene's part, or the marched kernel with its instances walked in `scene_data`),
//! run over a buffer of points through wgpu or, translated to PTX, through CUDA. The
//! distance conformance tests compare every evaluator with it, and the Python package's
//! `Scene.distance(points, backend=…)` answers with it.

use sdfc_compiler::{ptx, wgsl, Lowered, Method, Scene};
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
#[derive(Debug)]
pub struct PointsModule {
    pub source: String,
    pub module: naga::Module,
    pub info: naga::valid::ModuleInfo,
    /// The bind group of the points and results.
    pub group: u32,
    /// The bytes of `scene_data` (group 0, binding 4), where the module reads it.
    pub data: Option<Vec<u8>>,
}

fn validated(source: String, group: u32, data: Option<Vec<u8>>) -> Result<PointsModule, String> {
    let module = naga::front::wgsl::parse_str(&source).map_err(|e| e.emit_to_string(&source))?;
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .map_err(|e| e.emit_to_string(&source))?;
    Ok(PointsModule {
        source,
        module,
        info,
        group,
        data,
    })
}

/// The part of `scene` (as lowered), `map` and, with `alone`, `map_distance`, with [`entry`];
/// for a scene with a mesh, which has no part, [`mesh_module`].
pub fn points_module(
    scene: &Scene,
    lowered: &Lowered,
    alone: bool,
) -> Result<PointsModule, String> {
    if lowered.program.meshes().next().is_some() {
        return mesh_module(scene, alone);
    }
    let part = wgsl::part::write(scene, lowered, "map").map_err(|e| e.to_string())?;
    let alone = alone.then_some("map_distance");
    validated(
        format!("{}\n{}", part.source, entry(0, alone, None)),
        0,
        None,
    )
}

/// A scene with a mesh has no part (its triangles are data, not code): its marched kernel,
/// with the meshes in `scene_data`, its `map` and, with `alone`, `sdf` with [`entry`] (in bind
/// group 1, beside the kernel's group 0).
fn mesh_module(scene: &Scene, alone: bool) -> Result<PointsModule, String> {
    let mut marched = scene.clone();
    marched.settings.method = Method::March;
    let lowered = Lowered::new(&marched);
    let kernel = wgsl::write(&marched, &lowered).map_err(|e| e.to_string())?;
    validated(
        format!(
            "{}\n{}",
            kernel.source,
            entry(1, alone.then_some("sdf"), None)
        ),
        1,
        kernel.data,
    )
}

/// The marched kernel of `scene` with every instance of its root union walked in
/// `scene_data`, its `map` and `sdf` with [`entry`] (in bind group 1, beside the kernel's
/// group 0), every other point's walks hinted by `sdf` at the point before it; none where
/// the scene has no instances.
pub fn walk_module(scene: &Scene) -> Option<Result<PointsModule, String>> {
    let mut marched = scene.clone();
    marched.settings.method = Method::March;
    let lowered = Lowered::new(&marched);
    lowered.instances(0)?;
    let options = wgsl::Options {
        max_instances: 0,
        ..Default::default()
    };
    let kernel = match wgsl::write_with(&marched, &lowered, &options) {
        Ok(k) => k,
        Err(e) => return Some(Err(e.to_string())),
    };
    let walked = kernel.source.contains("fn walk_map(");
    let data = kernel.data.filter(|_| walked)?;
    Some(validated(
        format!("{}\n{}", kernel.source, entry(1, Some("sdf"), Some("sdf"))),
        1,
        Some(data),
    ))
}

/// The PTX of a [`PointsModule`]'s entry point for `sm`.
pub fn points_ptx(m: &PointsModule, sm: u32) -> Result<String, String> {
    let options = ptx::Options {
        sm,
        entry_point: ENTRY_POINT.into(),
    };
    ptx::write(&m.module, &m.info, &options)
        .map(|p| p.text)
        .map_err(|e| format!("PTX: {e}"))
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

/// The points one dispatch evaluates: the most workgroups a dispatch dimension may hold
/// (65 535, WebGPU's default limit) times [`WORKGROUP`].
pub const POINTS_PER_DISPATCH: usize = 65_535 * WORKGROUP as usize;

/// [`entry`] of `m` run through wgpu on `gpu` at every point, [`POINTS_PER_DISPATCH`] at a
/// time.
pub fn run_wgpu(
    gpu: &crate::gpu::Gpu,
    m: &PointsModule,
    points: &[[f64; 3]],
) -> Result<Results, String> {
    WgpuPoints::new(gpu, m).run(gpu, points)
}

/// [`entry`] of a module compiled into a wgpu pipeline, with its `scene_data` on the device:
/// kept, it evaluates points again without compiling (the Python package's `Scene.distance`).
#[derive(Debug)]
pub struct WgpuPoints {
    pipeline: wgpu::ComputePipeline,
    /// The bind group of `scene_data`, where the module reads it.
    data: Option<wgpu::BindGroup>,
    /// The bind group of the points and results.
    group: u32,
}

impl WgpuPoints {
    /// `m`'s pipeline on `gpu`, its `scene_data` written.
    pub fn new(gpu: &crate::gpu::Gpu, m: &PointsModule) -> WgpuPoints {
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
        let data = m.data.as_ref().map(|bytes| {
            let b = device.create_buffer(&wgpu::BufferDescriptor {
                label: None,
                size: bytes.len() as u64,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
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
        WgpuPoints {
            pipeline,
            data,
            group: m.group,
        }
    }

    /// The pipeline run at every point, [`POINTS_PER_DISPATCH`] at a time, on the `gpu` it
    /// was compiled on.
    pub fn run(&self, gpu: &crate::gpu::Gpu, points: &[[f64; 3]]) -> Result<Results, String> {
        let (device, queue) = (gpu.device(), gpu.queue());
        use wgpu::BufferUsages as U;
        let buffer = |size: u64, usage: U| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: None,
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        let mut out: Results = (
            Vec::with_capacity(points.len()),
            Vec::with_capacity(points.len()),
        );
        for chunk in points.chunks(POINTS_PER_DISPATCH) {
            let input = point_bytes(chunk);
            let size = result_bytes(chunk);
            let points_buf = buffer(input.len() as u64, U::STORAGE | U::COPY_DST);
            queue.write_buffer(&points_buf, 0, &input);
            let results_buf = buffer(size, U::STORAGE | U::COPY_SRC);
            let readback = buffer(size, U::MAP_READ | U::COPY_DST);
            let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &self.pipeline.get_bind_group_layout(self.group),
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: points_buf.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: results_buf.as_entire_binding(),
                    },
                ],
            });
            let mut enc = device.create_command_encoder(&Default::default());
            {
                let mut pass = enc.begin_compute_pass(&Default::default());
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(self.group, &bind, &[]);
                if let Some(d) = &self.data {
                    pass.set_bind_group(0, d, &[]);
                }
                pass.dispatch_workgroups(groups(chunk), 1, 1);
            }
            enc.copy_buffer_to_buffer(&results_buf, 0, &readback, 0, size);
            queue.submit([enc.finish()]);
            let slice = readback.slice(..);
            let (tx, rx) = std::sync::mpsc::channel();
            slice.map_async(wgpu::MapMode::Read, move |r| {
                let _ = tx.send(r);
            });
            device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(|e| format!("waiting for the GPU: {e}"))?;
            rx.recv()
                .map_err(|e| format!("reading the distances back: {e}"))?
                .map_err(|e| format!("reading the distances back: {e}"))?;
            let bytes = slice
                .get_mapped_range()
                .map_err(|e| format!("reading the distances back: {e}"))?
                .to_vec();
            let (v, d) = results(&bytes, chunk.len());
            out.0.extend(v);
            out.1.extend(d);
        }
        Ok(out)
    }
}

/// A CUDA context and its device's compute capability (`major * 10 + minor`).
pub type CudaDevice = (std::sync::Arc<cudarc::driver::CudaContext>, u32);

/// A CUDA device, opened for [`run_cuda`], with its compute capability, or why there is
/// none.
pub fn open_cuda() -> Result<CudaDevice, String> {
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
/// CUDA at every point, [`POINTS_PER_DISPATCH`] at a time.
pub fn run_cuda(
    ctx: &std::sync::Arc<cudarc::driver::CudaContext>,
    m: &PointsModule,
    ptx_text: &str,
    points: &[[f64; 3]],
) -> Result<Results, String> {
    CudaPoints::new(ctx, m, ptx_text)?.run(points)
}

/// [`entry`] of a module loaded into a CUDA context: kept, it evaluates points again
/// without translating or loading (the Python package's `Scene.distance`). The kernel's
/// parameters are the module's buffers in (group, binding) order (docs/ptx.md): the points
/// and results, `scene_data`, and a small zeroed buffer for each binding the entry point
/// does not use (the renderer kernel's others).
#[derive(Debug)]
pub struct CudaPoints {
    ctx: std::sync::Arc<cudarc::driver::CudaContext>,
    function: cudarc::driver::CudaFunction,
    /// The module's bindings, (group, binding), in order.
    bindings: Vec<(u32, u32)>,
    /// The bind group of the points and results.
    group: u32,
    /// The bytes of `scene_data`, where the module reads it.
    data: Option<Vec<u8>>,
}

impl CudaPoints {
    /// `m`'s entry point, as `ptx_text` for the context's device, loaded by the CUDA JIT.
    pub fn new(
        ctx: &std::sync::Arc<cudarc::driver::CudaContext>,
        m: &PointsModule,
        ptx_text: &str,
    ) -> Result<CudaPoints, String> {
        let module = ctx
            .load_module(cudarc::nvrtc::Ptx::from_src(ptx_text))
            .map_err(|e| format!("the CUDA JIT refused the PTX: {e}"))?;
        let function = module
            .load_function(ENTRY_POINT)
            .map_err(|e| format!("the kernel {ENTRY_POINT}: {e}"))?;
        let mut bindings: Vec<(u32, u32)> = m
            .module
            .global_variables
            .iter()
            .filter_map(|(_, g)| g.binding.as_ref().map(|b| (b.group, b.binding)))
            .collect();
        bindings.sort();
        if !bindings.contains(&(m.group, 1)) {
            return Err("the module binds no results".into());
        }
        Ok(CudaPoints {
            ctx: ctx.clone(),
            function,
            bindings,
            group: m.group,
            data: m.data.clone(),
        })
    }

    /// The kernel run at every point, [`POINTS_PER_DISPATCH`] at a time.
    pub fn run(&self, points: &[[f64; 3]]) -> Result<Results, String> {
        use cudarc::driver::{LaunchConfig, PushKernelArg};
        let s = self.ctx.default_stream();
        let group = self.group;
        let out_at = self
            .bindings
            .iter()
            .position(|&b| b == (group, 1))
            .ok_or("the module binds no results")?;
        let cuda = |e: cudarc::driver::DriverError| format!("CUDA: {e}");
        let mut out: Results = (
            Vec::with_capacity(points.len()),
            Vec::with_capacity(points.len()),
        );
        for chunk in points.chunks(POINTS_PER_DISPATCH) {
            let buffers = self
                .bindings
                .iter()
                .map(|&b| {
                    let bytes = match b {
                        b if b == (group, 0) => point_bytes(chunk),
                        b if b == (group, 1) => vec![0; result_bytes(chunk) as usize],
                        (0, 4) => self
                            .data
                            .clone()
                            .ok_or("the module reads scene_data it lacks")?,
                        _ => vec![0; 256],
                    };
                    s.clone_htod(&bytes).map_err(cuda)
                })
                .collect::<Result<Vec<cudarc::driver::CudaSlice<u8>>, String>>()?;
            let cfg = LaunchConfig {
                grid_dim: (groups(chunk), 1, 1),
                block_dim: (WORKGROUP, 1, 1),
                shared_mem_bytes: 0,
            };
            let mut launch = s.launch_builder(&self.function);
            for b in &buffers {
                launch.arg(b);
            }
            // SAFETY: the kernel's parameters are the module's buffers in (group, binding)
            // order, as the PTX back end declares them, each passed here; the points and
            // results hold one element for every thread of the grid, scene_data is the
            // kernel's own, and the entry point reads nothing of the other buffers.
            #[allow(unsafe_code)]
            unsafe { launch.launch(cfg) }.map_err(cuda)?;
            s.synchronize().map_err(cuda)?;
            let (v, d) = results(&s.clone_dtoh(&buffers[out_at]).map_err(cuda)?, chunk.len());
            out.0.extend(v);
            out.1.extend(d);
        }
        Ok(out)
    }
}
