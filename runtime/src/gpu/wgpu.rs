//! The wgpu launcher: finds an adapter, builds the kernel's compute pipeline, and renders an
//! image in tiles (one dispatch each, so that no dispatch runs long enough to trip a driver
//! watchdog), reading back the linear colours and the per-pixel statistics.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// What can go wrong on the wgpu path.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// No adapter (or, when a GPU is required, no hardware adapter) was found.
    #[error("no {what} adapter found by wgpu: install a Vulkan, Metal or DX12 driver (on Linux without a GPU, Mesa's lavapipe: `apt-get install mesa-vulkan-drivers`)")]
    NoAdapter {
        /// "GPU" or "wgpu".
        what: &'static str,
    },
    /// The adapter refused the device request.
    #[error("the adapter `{adapter}` refused to open a device: {message}")]
    Device { adapter: String, message: String },
    /// wgpu rejected the shader or pipeline (a compiler bug: the kernel was validated by naga).
    #[error("wgpu rejected the kernel: {0}")]
    Pipeline(String),
    /// The device reported an error while rendering (out of memory, device lost, …).
    #[error("GPU error while rendering: {0}")]
    Render(String),
    /// The scene uniform does not fit the kernel's layout (`wgsl::uniforms`; a bug of
    /// sdfc's, or a kernel written for another scene): refused before anything is uploaded.
    #[error("internal error: the scene uniform does not fit the kernel: {0}")]
    Uniform(String),
}

/// Bytes between tile entries in the tile table (the largest uniform offset alignment).
const TILE_STRIDE: u32 = 256;
/// Tiles per queue submission.
const TILES_PER_SUBMIT: usize = 8;

/// Compiled pipelines kept by a [`Gpu`] (at most this many; the cache is emptied when full).
const PIPELINES_KEPT: usize = 16;

/// A compiled kernel: its pipeline and bind group layout.
type Pipeline = Arc<(wgpu::ComputePipeline, wgpu::BindGroupLayout)>;

/// An opened device, with the pipelines compiled on it, kept by kernel text (so a scene whose
/// kernel is unchanged, such as one edited only in uniform data, is not compiled again).
#[derive(Debug)]
pub struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    timestamps: bool,
    pipelines: Mutex<HashMap<(String, String, bool), Pipeline>>,
}

/// How a kernel's pipeline was obtained ([`Gpu::pipeline_for`]).
#[derive(Debug, Clone, Copy)]
pub struct PipelineTime {
    /// Time to get it (creation and validation, or the cache look-up).
    pub time: Duration,
    /// Whether it came from the cache of compiled pipelines.
    pub cached: bool,
}

/// Per-pixel results of a render.
#[derive(Debug, Clone)]
pub struct Frame {
    /// Linear RGB per pixel, row-major.
    pub linear: Vec<[f32; 3]>,
    /// The kernel's statistics words per pixel, `stats_words` of them per pixel.
    pub stats: Vec<u32>,
    /// GPU time of the dispatches measured with timestamps, where the adapter has them.
    pub gpu_time: Option<Duration>,
    /// Wall time from the first submit until the last dispatch finished (readback excluded).
    pub wall_time: Duration,
    /// Where the wall time of the whole frame went.
    pub phases: super::Phases,
}

/// A compiled kernel ready to launch: its WGSL, entry point and uniform bytes.
#[derive(Debug, Clone, Copy)]
pub struct Launch<'a> {
    /// WGSL source (validated by the compiler).
    pub wgsl: &'a str,
    /// Entry point name.
    pub entry: &'a str,
    /// Bytes of the scene uniform (binding 0).
    pub uniforms: &'a [u8],
    /// Bytes of the read-only `scene_data` (binding 4), when the kernel declares it.
    pub data: Option<&'a [u8]>,
    /// Image size.
    pub width: u32,
    pub height: u32,
    /// Statistics words written per pixel (binding 3).
    pub stats_words: u32,
    /// Workgroup edge of the kernel (it is square).
    pub workgroup: u32,
    /// Tile edge in pixels.
    pub tile: u32,
}

/// The process's one wgpu instance, never destroyed. Destroying the last Vulkan instance
/// makes the loader unload the driver, and the NVIDIA driver keeps a thread of its own that
/// may still run code of the unloaded library: on an H100, 2 of 6 renders of
/// `examples/temple.sdf` under a debugger died so at exit, in that thread, at an unmapped
/// address (BENCHMARKS.md, "Crash at exit"). An instance that lives until the process exits
/// keeps the driver loaded; the operating system reclaims it.
fn instance() -> &'static wgpu::Instance {
    static INSTANCE: std::sync::OnceLock<wgpu::Instance> = std::sync::OnceLock::new();
    INSTANCE.get_or_init(|| {
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env())
    })
}

impl Gpu {
    /// Opens the first adapter wgpu finds. With `require_hardware`, a CPU adapter (lavapipe)
    /// does not count.
    pub fn open(require_hardware: bool) -> Result<Gpu, Error> {
        let adapters = pollster::block_on(instance().enumerate_adapters(wgpu::Backends::all()));
        let rank = |a: &wgpu::Adapter| match a.get_info().device_type {
            wgpu::DeviceType::DiscreteGpu => 0,
            wgpu::DeviceType::IntegratedGpu => 1,
            wgpu::DeviceType::VirtualGpu => 2,
            wgpu::DeviceType::Other => 3,
            wgpu::DeviceType::Cpu => 4,
        };
        let adapter = adapters
            .into_iter()
            .filter(|a| !require_hardware || a.get_info().device_type != wgpu::DeviceType::Cpu)
            .min_by_key(rank)
            .ok_or(Error::NoAdapter {
                what: if require_hardware { "GPU" } else { "wgpu" },
            })?;
        Self::from_adapter(&adapter)
    }

    /// Opens a device on `adapter` (for example one chosen to present to a window's surface,
    /// so that the kernel renders on the device that shows its frames).
    pub fn from_adapter(adapter: &wgpu::Adapter) -> Result<Gpu, Error> {
        let info = adapter.get_info();
        let timestamps = adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let features = if timestamps {
            wgpu::Features::TIMESTAMP_QUERY
        } else {
            wgpu::Features::empty()
        };
        let limits = wgpu::Limits {
            max_storage_buffer_binding_size: adapter.limits().max_storage_buffer_binding_size,
            ..wgpu::Limits::default()
        }
        .using_resolution(adapter.limits());
        let desc = wgpu::DeviceDescriptor {
            label: Some("sdfc"),
            required_features: features,
            required_limits: limits,
            ..Default::default()
        };
        let (device, queue) =
            pollster::block_on(adapter.request_device(&desc)).map_err(|e| Error::Device {
                adapter: info.name.clone(),
                message: e.to_string(),
            })?;
        Ok(Gpu {
            device,
            queue,
            info,
            timestamps,
            pipelines: Mutex::new(HashMap::new()),
        })
    }

    /// The device.
    pub fn device(&self) -> &wgpu::Device {
        &self.device
    }

    /// The device's queue.
    pub fn queue(&self) -> &wgpu::Queue {
        &self.queue
    }

    /// Compiles the pipeline of `wgsl` (entry point `entry`, with the scene-data binding when
    /// `data`), or finds it among those already compiled on this device.
    pub fn pipeline_for(&self, wgsl: &str, entry: &str, data: bool) -> Result<PipelineTime, Error> {
        let start = Instant::now();
        let (_, cached) = self.cached_pipeline(wgsl, entry, data)?;
        Ok(PipelineTime {
            time: start.elapsed(),
            cached,
        })
    }

    /// The pipeline of a kernel, from the cache or compiled (and validated) now; `true` when
    /// it came from the cache.
    fn cached_pipeline(
        &self,
        wgsl: &str,
        entry: &str,
        data: bool,
    ) -> Result<(Pipeline, bool), Error> {
        let key = (wgsl.to_string(), entry.to_string(), data);
        let mut cache = self.pipelines.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(p) = cache.get(&key) {
            return Ok((p.clone(), true));
        }
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let pipeline = Arc::new(self.pipeline(wgsl, entry, data));
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::Pipeline(e.to_string()));
        }
        if cache.len() >= PIPELINES_KEPT {
            cache.clear();
        }
        cache.insert(key, pipeline.clone());
        Ok((pipeline, false))
    }

    /// The adapter's name and backend, e.g. `NVIDIA H100 (Vulkan)`.
    pub fn describe(&self) -> String {
        format!(
            "{} ({:?}, {:?})",
            self.info.name, self.info.backend, self.info.device_type
        )
    }

    /// True for a software adapter such as lavapipe.
    pub fn is_cpu(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// Renders one frame. `progress` is called with the fraction done after each tile.
    pub fn render(&self, l: &Launch, progress: &mut dyn FnMut(f64)) -> Result<Frame, Error> {
        let setup = Instant::now();
        let limit = self.device.limits().max_storage_buffer_binding_size;
        if let Some(data) = l.data.filter(|d| d.len() as u64 > limit) {
            return Err(Error::Render(format!(
                "the scene's primitives take {} bytes, more than the {limit} bytes a storage buffer of this adapter may bind",
                data.len()
            )));
        }
        let (pipeline, _) = self.cached_pipeline(l.wgsl, l.entry, l.data.is_some())?;
        let pixels = l.width as u64 * l.height as u64;
        let tiles = tiles(l.width, l.height, l.tile);
        let buffers = self.buffers(l, pixels, tiles.len() as u64);
        let bind = self.bind_group(&pipeline.1, &buffers);
        let pipeline = &pipeline.0;
        let queries = self.timestamps.then(|| {
            self.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("sdfc timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * tiles.len() as u32,
            })
        });
        let mem_scope = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let table: Vec<u8> = tiles
            .iter()
            .flat_map(|t| {
                let mut entry = words(&[t.0, t.1, t.2, t.3]);
                entry.resize(TILE_STRIDE as usize, 0);
                entry
            })
            .collect();
        self.queue.write_buffer(&buffers.tile, 0, &table);
        // (wgpu's writes are queued: the uploads are paid for in the first submission.)
        let setup = setup.elapsed();
        let start = Instant::now();
        let fault = super::fault_after_tiles();
        // Tiles are submitted in batches: each tile is its own dispatch, and the host waits
        // after each batch (progress, and a bound on how much work is queued at once).
        for (b, batch) in tiles.chunks(TILES_PER_SUBMIT).enumerate() {
            let mut enc = self.device.create_command_encoder(&Default::default());
            for (j, t) in batch.iter().enumerate() {
                let i = (b * TILES_PER_SUBMIT + j) as u32;
                let writes = queries.as_ref().map(|q| wgpu::ComputePassTimestampWrites {
                    query_set: q,
                    beginning_of_pass_write_index: Some(2 * i),
                    end_of_pass_write_index: Some(2 * i + 1),
                });
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: None,
                    timestamp_writes: writes,
                });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &bind, &[i * TILE_STRIDE]);
                pass.dispatch_workgroups(t.2.div_ceil(l.workgroup), t.3.div_ceil(l.workgroup), 1);
            }
            self.queue.submit([enc.finish()]);
            self.wait()?;
            let first = b * TILES_PER_SUBMIT;
            if let Some(msg) =
                (first..first + batch.len()).find_map(|i| super::injected_fault(fault, i))
            {
                return Err(Error::Render(msg));
            }
            progress(((b * TILES_PER_SUBMIT + batch.len()) as f64 / tiles.len() as f64).min(1.0));
        }
        let wall_time = start.elapsed();
        let readback = Instant::now();
        let linear = self.read(&buffers.image, pixels * 16)?;
        let stats = self.read(&buffers.stats, pixels * 4 * l.stats_words as u64)?;
        let readback = readback.elapsed();
        if let Some(e) = pollster::block_on(mem_scope.pop()) {
            return Err(Error::Render(e.to_string()));
        }
        let gpu_time = match &queries {
            Some(q) => Some(self.gpu_time(q, tiles.len() as u32)?),
            None => None,
        };
        let convert = Instant::now();
        let (linear, stats) = {
            use rayon::prelude::*;
            let f = |b: &[u8]| f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
            let linear = linear
                .par_chunks_exact(16)
                .map(|c| [f(&c[0..4]), f(&c[4..8]), f(&c[8..12])])
                .collect();
            let stats = stats
                .par_chunks_exact(4)
                .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect();
            (linear, stats)
        };
        let phases = super::Phases {
            setup,
            launches: wall_time,
            readback,
            convert: convert.elapsed(),
        };
        Ok(Frame {
            linear,
            stats,
            gpu_time,
            wall_time,
            phases,
        })
    }

    /// The pipeline and its bind group layout: binding 0 the scene uniform, 1 the tile table
    /// (a uniform at a dynamic offset), 2 the image and 3 the statistics (storage), and 4 the
    /// scene data (read-only storage) when the kernel has it.
    fn pipeline(
        &self,
        wgsl: &str,
        entry_point: &str,
        data: bool,
    ) -> (wgpu::ComputePipeline, wgpu::BindGroupLayout) {
        let module = self
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("sdfc kernel"),
                source: wgpu::ShaderSource::Wgsl(wgsl.into()),
            });
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty,
            count: None,
        };
        let uniform = |dynamic| wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: dynamic,
            min_binding_size: None,
        };
        let storage = |read_only| wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let mut entries = vec![
            entry(0, uniform(false)),
            entry(1, uniform(true)),
            entry(2, storage(false)),
            entry(3, storage(false)),
        ];
        if data {
            entries.push(entry(4, storage(true)));
        }
        let layout = self
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("sdfc bindings"),
                entries: &entries,
            });
        let pipeline_layout = self
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("sdfc layout"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
        let pipeline = self
            .device
            .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("sdfc render"),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry_point),
                compilation_options: Default::default(),
                cache: None,
            });
        (pipeline, layout)
    }

    fn buffers(&self, l: &Launch, pixels: u64, tiles: u64) -> Buffers {
        use wgpu::BufferUsages as U;
        let make = |label, size: u64, usage| {
            self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size.max(16),
                usage,
                mapped_at_creation: false,
            })
        };
        let uniforms = make(
            "sdfc scene",
            l.uniforms.len() as u64,
            U::UNIFORM | U::COPY_DST,
        );
        self.queue.write_buffer(&uniforms, 0, l.uniforms);
        let data = l.data.map(|bytes| {
            let buffer = make(
                "sdfc scene data",
                bytes.len() as u64,
                U::STORAGE | U::COPY_DST,
            );
            self.queue.write_buffer(&buffer, 0, bytes);
            buffer
        });
        Buffers {
            uniforms,
            data,
            tile: make(
                "sdfc tiles",
                tiles * TILE_STRIDE as u64,
                U::UNIFORM | U::COPY_DST,
            ),
            image: make("sdfc image", pixels * 16, U::STORAGE | U::COPY_SRC),
            stats: make(
                "sdfc stats",
                pixels * 4 * l.stats_words as u64,
                U::STORAGE | U::COPY_SRC,
            ),
        }
    }

    fn bind_group(&self, layout: &wgpu::BindGroupLayout, b: &Buffers) -> wgpu::BindGroup {
        let tile = wgpu::BufferBinding {
            buffer: &b.tile,
            offset: 0,
            size: std::num::NonZeroU64::new(16),
        };
        let mut entries = vec![
            wgpu::BindGroupEntry {
                binding: 0,
                resource: b.uniforms.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::Buffer(tile),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: b.image.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: b.stats.as_entire_binding(),
            },
        ];
        if let Some(data) = &b.data {
            entries.push(wgpu::BindGroupEntry {
                binding: 4,
                resource: data.as_entire_binding(),
            });
        }
        self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sdfc bindings"),
            layout,
            entries: &entries,
        })
    }

    fn wait(&self) -> Result<(), Error> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| Error::Render(e.to_string()))
    }

    fn read(&self, src: &wgpu::Buffer, size: u64) -> Result<Vec<u8>, Error> {
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sdfc readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(src, 0, &staging, 0, size);
        self.queue.submit([enc.finish()]);
        let slice = staging.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.wait()?;
        rx.recv()
            .map_err(|e| Error::Render(e.to_string()))?
            .map_err(|e| Error::Render(e.to_string()))?;
        let bytes = slice
            .get_mapped_range()
            .map_err(|e| Error::Render(e.to_string()))?
            .to_vec();
        staging.unmap();
        Ok(bytes)
    }

    fn gpu_time(&self, q: &wgpu::QuerySet, tiles: u32) -> Result<Duration, Error> {
        let n = 2 * tiles as u64;
        let resolve = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sdfc timestamps"),
            size: n * 8,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.resolve_query_set(q, 0..n as u32, &resolve, 0);
        self.queue.submit([enc.finish()]);
        let bytes = self.read(&resolve, n * 8)?;
        let ticks: Vec<u64> = bytes
            .chunks_exact(8)
            .map(|c| u64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
            .collect();
        let period = self.queue.get_timestamp_period() as f64;
        let total: u64 = ticks
            .chunks_exact(2)
            .map(|p| p[1].saturating_sub(p[0]))
            .sum();
        Ok(Duration::from_nanos((total as f64 * period) as u64))
    }
}

struct Buffers {
    uniforms: wgpu::Buffer,
    data: Option<wgpu::Buffer>,
    tile: wgpu::Buffer,
    image: wgpu::Buffer,
    stats: wgpu::Buffer,
}

/// Splits the image into tiles (x, y, width, height) of at most `edge` pixels a side.
pub fn tiles(width: u32, height: u32, edge: u32) -> Vec<(u32, u32, u32, u32)> {
    let edge = edge.max(8);
    let mut out = Vec::new();
    for y in (0..height).step_by(edge as usize) {
        for x in (0..width).step_by(edge as usize) {
            out.push((x, y, edge.min(width - x), edge.min(height - y)));
        }
    }
    out
}

fn words(w: &[u32]) -> Vec<u8> {
    w.iter().flat_map(|x| x.to_le_bytes()).collect()
}

#[cfg(test)]
mod tests {
    use super::tiles;

    #[test]
    fn tiles_cover_the_image_once() {
        let t = tiles(100, 70, 32);
        assert_eq!(t.len(), 4 * 3);
        let area: u32 = t.iter().map(|t| t.2 * t.3).sum();
        assert_eq!(area, 100 * 70);
    }
}
