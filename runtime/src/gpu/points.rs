//! Distances at points on a GPU: the compiler's module of them (`sdfc_compiler::points`, a
//! compute entry point joined to a WGSL module that declares `map`) run over a buffer of
//! points through wgpu or, translated to PTX, through CUDA. The distance conformance tests
//! compare every evaluator with it, and the Python package's `Scene.distance(points,
//! backend=…)` answers with it.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, PoisonError};

pub use sdfc_compiler::points::{
    entry, points_module, points_ptx, walk_module, PointsModule, Value, ENTRY_POINT, WORKGROUP,
};

/// Why distances at points cannot be computed on a device.
#[derive(Debug, Clone, thiserror::Error)]
pub enum RunError {
    /// There is no CUDA driver library to load.
    #[error("no CUDA driver (libcuda.so)")]
    NoCudaDriver,
    /// The CUDA driver found no device.
    #[error("the CUDA driver found no device")]
    NoCudaDevice,
    /// A call of the CUDA driver failed: `what` it was doing.
    #[error("{what}: {error}")]
    Cuda {
        what: &'static str,
        error: cudarc::driver::DriverError,
    },
    /// The PTX holds no entry point [`ENTRY_POINT`] that the driver can load.
    #[error("the kernel {ENTRY_POINT}: {error}")]
    Function { error: cudarc::driver::DriverError },
    /// The module binds no results buffer in its group.
    #[error("the module binds no results")]
    NoResults,
    /// The module reads `scene_data`, which it was not given.
    #[error("the module reads scene_data it lacks")]
    NoSceneData,
    /// Waiting for the wgpu device failed.
    #[error("waiting for the GPU: {0}")]
    Wait(std::sync::Arc<wgpu::PollError>),
    /// The mapping of the results ended without a word.
    #[error("reading the distances back: {0}")]
    Unanswered(#[from] std::sync::mpsc::RecvError),
    /// The results could not be mapped back to the host.
    #[error("reading the distances back: {0}")]
    Map(#[from] wgpu::BufferAsyncError),
    /// The mapped results could not be viewed.
    #[error("reading the distances back: {0}")]
    MapRange(#[from] wgpu::MapRangeError),
}

/// The points as the entry point reads them: x, y, z, 0 per point, padded with the origin to
/// a whole number of workgroups, as bytes (written on rayon's threads: a batch of the mesher
/// may hold millions).
fn point_bytes(points: &[[f64; 3]]) -> Vec<u8> {
    use rayon::prelude::*;
    let padded = groups(points) as usize * WORKGROUP as usize;
    let mut bytes = vec![0u8; 16 * padded];
    bytes
        .par_chunks_mut(16 * 4096)
        .zip(points.par_chunks(4096))
        .for_each(|(out, ps)| {
            for (o, p) in out.chunks_exact_mut(16).zip(ps) {
                for (k, w) in [p[0] as f32, p[1] as f32, p[2] as f32].iter().enumerate() {
                    o[4 * k..4 * k + 4].copy_from_slice(&w.to_le_bytes());
                }
            }
        });
    bytes
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

/// Room for the results of `n` points.
fn results_for(n: usize) -> Results {
    (Vec::with_capacity(n), Vec::with_capacity(n))
}

/// Results as the entry point writes them, for the first `n` points (read on rayon's
/// threads).
fn results(bytes: &[u8], n: usize) -> Results {
    use rayon::prelude::*;
    let word = |c: &[u8], k: usize| {
        f32::from_le_bytes([c[4 * k], c[4 * k + 1], c[4 * k + 2], c[4 * k + 3]])
    };
    let quads = || bytes.par_chunks_exact(16).take(n);
    (
        quads().map(|c| (word(c, 0), word(c, 1) as u32)).collect(),
        quads().map(|c| word(c, 2)).collect(),
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
) -> Result<Results, RunError> {
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
    /// The points', results' and read-back buffers of the last run, reused by the next
    /// while they are large enough.
    kept: Mutex<Option<WgpuBuffers>>,
    /// Dispatches run so far.
    launches: AtomicU64,
}

/// The buffers of one dispatch of [`WgpuPoints`]: `bytes` of points, of results and of
/// their copy read back (a vec4 each per thread), and the bind group of the first two.
#[derive(Debug)]
struct WgpuBuffers {
    bytes: u64,
    points: wgpu::Buffer,
    results: wgpu::Buffer,
    readback: wgpu::Buffer,
    bind: wgpu::BindGroup,
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
            kept: Mutex::new(None),
            launches: AtomicU64::new(0),
        }
    }

    /// Dispatches run so far (one per [`POINTS_PER_DISPATCH`] points or fewer of a run).
    pub fn launches(&self) -> u64 {
        self.launches.load(Ordering::Relaxed)
    }

    /// Buffers for `bytes` of points and of results on `device`.
    fn buffers(&self, device: &wgpu::Device, bytes: u64) -> WgpuBuffers {
        use wgpu::BufferUsages as U;
        let buffer = |usage: U| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: None,
                size: bytes,
                usage,
                mapped_at_creation: false,
            })
        };
        let points = buffer(U::STORAGE | U::COPY_DST);
        let results = buffer(U::STORAGE | U::COPY_SRC);
        let readback = buffer(U::MAP_READ | U::COPY_DST);
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &self.pipeline.get_bind_group_layout(self.group),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: points.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: results.as_entire_binding(),
                },
            ],
        });
        WgpuBuffers {
            bytes,
            points,
            results,
            readback,
            bind,
        }
    }

    /// The pipeline run at every point, [`POINTS_PER_DISPATCH`] at a time, on the `gpu` it
    /// was compiled on, in the buffers of the run before where they are large enough
    /// (otherwise in new ones, twice as large or as this run needs, kept for the next).
    pub fn run(&self, gpu: &crate::gpu::Gpu, points: &[[f64; 3]]) -> Result<Results, RunError> {
        let (device, queue) = (gpu.device(), gpu.queue());
        let mut out = results_for(points.len());
        let mut kept = self.kept.lock().unwrap_or_else(PoisonError::into_inner);
        for chunk in points.chunks(POINTS_PER_DISPATCH) {
            let input = point_bytes(chunk);
            let size = result_bytes(chunk);
            let b = match kept.take() {
                Some(b) if b.bytes >= size => b,
                old => {
                    let most = result_bytes(&points[..POINTS_PER_DISPATCH.min(points.len())]);
                    let grown = old.map_or(size, |b| (2 * b.bytes).clamp(size, most.max(size)));
                    self.buffers(device, grown)
                }
            };
            queue.write_buffer(&b.points, 0, &input);
            let mut enc = device.create_command_encoder(&Default::default());
            {
                let mut pass = enc.begin_compute_pass(&Default::default());
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(self.group, &b.bind, &[]);
                if let Some(d) = &self.data {
                    pass.set_bind_group(0, d, &[]);
                }
                pass.dispatch_workgroups(groups(chunk), 1, 1);
            }
            enc.copy_buffer_to_buffer(&b.results, 0, &b.readback, 0, size);
            queue.submit([enc.finish()]);
            self.launches.fetch_add(1, Ordering::Relaxed);
            let slice = b.readback.slice(..size);
            let (tx, rx) = std::sync::mpsc::channel();
            slice.map_async(wgpu::MapMode::Read, move |r| {
                let _ = tx.send(r);
            });
            device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(|e| RunError::Wait(e.into()))?;
            rx.recv()??;
            let (v, d) = results(&slice.get_mapped_range()?, chunk.len());
            b.readback.unmap();
            out.0.extend(v);
            out.1.extend(d);
            *kept = Some(b);
        }
        Ok(out)
    }
}

/// A CUDA context and its device's compute capability (`major * 10 + minor`).
pub type CudaDevice = (std::sync::Arc<cudarc::driver::CudaContext>, u32);

/// A CUDA device, opened for [`run_cuda`], with its compute capability, or why there is
/// none.
pub fn open_cuda() -> Result<CudaDevice, RunError> {
    use cudarc::driver::{sys, CudaContext};
    // SAFETY: only tries to dlopen libcuda; no driver call is made.
    #[allow(unsafe_code)]
    let present = unsafe { sys::is_culib_present() };
    if !present {
        return Err(RunError::NoCudaDriver);
    }
    match CudaContext::device_count() {
        Ok(n) if n > 0 => {}
        Ok(_) => return Err(RunError::NoCudaDevice),
        Err(error) => {
            let what = "the CUDA driver";
            return Err(RunError::Cuda { what, error });
        }
    }
    let cuda = |what| move |error| RunError::Cuda { what, error };
    let ctx = CudaContext::new(0).map_err(cuda("a CUDA context"))?;
    let attr = |a| {
        ctx.attribute(a)
            .map_err(cuda("the device's compute capability"))
    };
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
) -> Result<Results, RunError> {
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
    /// Where the results are among them.
    out_at: usize,
    /// The bind group of the points and results.
    group: u32,
    /// The bytes of `scene_data`, where the module reads it.
    data: Option<Vec<u8>>,
    /// The buffers of the last run, reused by the next while they are large enough.
    kept: Mutex<Option<CudaBuffers>>,
    /// Launches run so far.
    launches: AtomicU64,
}

/// The kernel's buffers of one launch of [`CudaPoints`], in its parameters' order, for
/// `bytes` of points and of results.
#[derive(Debug)]
struct CudaBuffers {
    bytes: usize,
    buffers: Vec<cudarc::driver::CudaSlice<u8>>,
}

impl CudaPoints {
    /// `m`'s entry point, as `ptx_text` for the context's device, loaded by the CUDA JIT.
    pub fn new(
        ctx: &std::sync::Arc<cudarc::driver::CudaContext>,
        m: &PointsModule,
        ptx_text: &str,
    ) -> Result<CudaPoints, RunError> {
        let cuda = |what| move |error| RunError::Cuda { what, error };
        let module = ctx
            .load_module(cudarc::nvrtc::Ptx::from_src(ptx_text))
            .map_err(cuda("the CUDA JIT refused the PTX"))?;
        let function = module
            .load_function(ENTRY_POINT)
            .map_err(|error| RunError::Function { error })?;
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
            .ok_or(RunError::NoResults)?;
        Ok(CudaPoints {
            ctx: ctx.clone(),
            function,
            bindings,
            out_at,
            group: m.group,
            data: m.data.clone(),
            kept: Mutex::new(None),
            launches: AtomicU64::new(0),
        })
    }

    /// Launches run so far (one per [`POINTS_PER_DISPATCH`] points or fewer of a run).
    pub fn launches(&self) -> u64 {
        self.launches.load(Ordering::Relaxed)
    }

    /// The kernel's buffers for `bytes` of points and of results, `scene_data` written.
    fn buffers(
        &self,
        s: &std::sync::Arc<cudarc::driver::CudaStream>,
        bytes: usize,
    ) -> Result<CudaBuffers, RunError> {
        let cuda = |what| move |error| RunError::Cuda { what, error };
        let group = self.group;
        let buffers = self
            .bindings
            .iter()
            .map(|&b| match b {
                b if b == (group, 0) || b == (group, 1) => {
                    s.alloc_zeros::<u8>(bytes).map_err(cuda("CUDA"))
                }
                (0, 4) => {
                    let data = self.data.as_ref().ok_or(RunError::NoSceneData)?;
                    s.clone_htod(data).map_err(cuda("CUDA"))
                }
                _ => s.alloc_zeros::<u8>(256).map_err(cuda("CUDA")),
            })
            .collect::<Result<Vec<_>, RunError>>()?;
        Ok(CudaBuffers { bytes, buffers })
    }

    /// The kernel run at every point, [`POINTS_PER_DISPATCH`] at a time, in the buffers of
    /// the run before where they are large enough (otherwise in new ones, twice as large or as
    /// this run needs, kept for the next).
    pub fn run(&self, points: &[[f64; 3]]) -> Result<Results, RunError> {
        use cudarc::driver::{LaunchConfig, PushKernelArg};
        let cuda = |what| move |error| RunError::Cuda { what, error };
        let s = self.ctx.default_stream();
        let at_points = self
            .bindings
            .iter()
            .position(|&b| b == (self.group, 0))
            .ok_or(RunError::NoResults)?;
        let mut out = results_for(points.len());
        let mut kept = self.kept.lock().unwrap_or_else(PoisonError::into_inner);
        for chunk in points.chunks(POINTS_PER_DISPATCH) {
            let input = point_bytes(chunk);
            let size = result_bytes(chunk) as usize;
            let mut b = match kept.take() {
                Some(b) if b.bytes >= size => b,
                old => {
                    let most =
                        result_bytes(&points[..POINTS_PER_DISPATCH.min(points.len())]) as usize;
                    let grown = old.map_or(size, |b| (2 * b.bytes).clamp(size, most.max(size)));
                    self.buffers(&s, grown)?
                }
            };
            s.memcpy_htod(&input, &mut b.buffers[at_points].slice_mut(..input.len()))
                .map_err(cuda("uploading the points"))?;
            let cfg = LaunchConfig {
                grid_dim: (groups(chunk), 1, 1),
                block_dim: (WORKGROUP, 1, 1),
                shared_mem_bytes: 0,
            };
            let mut launch = s.launch_builder(&self.function);
            for buffer in &b.buffers {
                launch.arg(buffer);
            }
            // SAFETY: the kernel's parameters are the module's buffers in (group, binding)
            // order, as the PTX back end declares them, each passed here; the points and
            // results hold one element for every thread of the grid (or more), scene_data is
            // the kernel's own, and the entry point reads nothing of the other buffers.
            #[allow(unsafe_code)]
            unsafe { launch.launch(cfg) }.map_err(cuda("CUDA"))?;
            self.launches.fetch_add(1, Ordering::Relaxed);
            let mut bytes = vec![0u8; size];
            s.memcpy_dtoh(&b.buffers[self.out_at].slice(..size), &mut bytes)
                .map_err(cuda("reading the distances back"))?;
            s.synchronize().map_err(cuda("CUDA"))?;
            let (v, d) = results(&bytes, chunk.len());
            out.0.extend(v);
            out.1.extend(d);
            *kept = Some(b);
        }
        Ok(out)
    }
}
