//! The wgpu launcher: finds an adapter, builds the kernel's compute pipeline, and renders an
//! image in tiles (one dispatch each, so that no dispatch runs long enough to trip a driver
//! watchdog), reading back the finished pixels or the linear colours, and the per-pixel
//! statistics reduced on the device (`super::reduce`).

use super::launch::{self, Job, Pixels};
use super::reduce::{self, Answer, Ask};
use sdfc_compiler::wgsl::{reduce as reduction, STATS_WORDS};
use std::collections::HashMap;
use std::ops::Range;
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
    /// `--devices` named an adapter wgpu did not find.
    #[error("there is no wgpu adapter {index} (wgpu found {count}; `sdfc devices` lists them)")]
    NoSuchAdapter { index: usize, count: usize },
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
pub const TILE_STRIDE: u32 = 256;

/// Compiled pipelines kept by a [`Gpu`] (at most this many; the cache is emptied when full).
const PIPELINES_KEPT: usize = 16;

/// The size of a buffer for `n` bytes: at least 16, so that one for no bytes can be bound.
fn padded(n: u64) -> u64 {
    n.max(16)
}

/// How long [`Gpu::wait`] polls before it blocks.
const SPIN: Duration = Duration::from_millis(20);

/// A compiled kernel: its pipeline and bind group layout.
pub type Pipeline = Arc<(wgpu::ComputePipeline, wgpu::BindGroupLayout)>;

/// An opened device, with the pipelines compiled on it, kept by kernel text (so a scene whose
/// kernel is unchanged, such as one edited only in uniform data, is not compiled again).
#[derive(Debug)]
pub struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    timestamps: bool,
    /// Whether the device keeps the driver's compiled pipelines as data (wgpu's
    /// `PIPELINE_CACHE`, Vulkan only), which [`Gpu::pipeline_for`] stores on disk.
    driver_cache: bool,
    pipelines: Mutex<HashMap<(String, String, bool), Pipeline>>,
    /// The buffers of the last frame finished, kept for the next frame of the same sizes
    /// (a benchmark's or a sequence's frames): wgpu clears a new storage buffer before its
    /// first use, which each frame would otherwise pay for within its launches.
    spare: Mutex<Option<Buffers>>,
    /// Staging buffers for reading back, kept across frames by size: a new one is allocated
    /// and mapped into the process each time otherwise (33 MB for a 1920×1080 frame's
    /// linear colours).
    staging: Mutex<Vec<wgpu::Buffer>>,
    /// The statistics' reduction (`sdfc_compiler::wgsl::reduce`), compiled when first
    /// used.
    reducer: Mutex<Option<Pipeline>>,
}

/// How a kernel's pipeline was obtained ([`Gpu::pipeline_for`]).
#[derive(Debug, Clone, Copy)]
pub struct PipelineTime {
    /// Time to get it (creation and validation, or the cache look-up).
    pub time: Duration,
    /// Whether it came from the cache of compiled pipelines.
    pub cached: bool,
    /// Where the driver's compiled code came from, when it was created now.
    pub driver: DriverCache,
}

/// What the driver was given when a pipeline was created: the data of its pipeline cache for
/// this kernel from an earlier process, or nothing (then the data it produced is stored).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DriverCache {
    /// The pipeline came from this device's own cache: no driver call.
    NotAsked,
    /// The device keeps no pipeline cache (a backend other than Vulkan), or there is no
    /// cache directory.
    Unsupported,
    /// No data was stored for this kernel: the driver compiled it, and its cache data was
    /// written (the number of bytes; 0 when writing failed or the driver gave none).
    Written(u64),
    /// The data stored by an earlier process for this kernel and device was given to the
    /// driver (the number of bytes read).
    Read(u64),
}

/// A kernel on a [`Gpu`], ready to render tiles ([`Gpu::kernel`]).
#[derive(Debug, Clone, Copy)]
pub struct Kernel<'a> {
    gpu: &'a Gpu,
    wgsl: &'a str,
    entry: &'a str,
    workgroup: u32,
}

/// A frame's buffers on the device: the pipeline and its bindings, the timestamp queries and
/// the error scope that catches running out of memory.
pub struct FrameBuffers {
    pipeline: Pipeline,
    buffers: Buffers,
    bind: wgpu::BindGroup,
    queries: Option<wgpu::QuerySet>,
    memory: Option<wgpu::ErrorScopeGuard>,
    /// The reads started into each of [`Buffers::readback`]: the pixels, the copy's
    /// submission, and the mapping's outcome to come.
    reading: [Option<Reading>; 2],
}

/// A read started into a readback buffer ([`launch::Device::start_read`]).
type Reading = (
    Range<usize>,
    wgpu::SubmissionIndex,
    std::sync::mpsc::Receiver<Result<(), wgpu::BufferAsyncError>>,
);

impl FrameBuffers {
    /// The frame's finished pixels on the device (binding 5: RGBA8, sRGB-encoded, red in the
    /// low byte, a row of `width` pixels after another), for a caller that draws them without
    /// reading them back: after [`launch::Device::run`], copy it into an `Rgba8UnormSrgb`
    /// texture (`copy_buffer_to_texture`, rows padded to 256 bytes where the width needs it)
    /// on [`Gpu::queue`]. The buffer has `COPY_SRC` usage.
    pub fn pixels(&self) -> &wgpu::Buffer {
        &self.buffers.pixels
    }
}

impl std::fmt::Debug for FrameBuffers {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FrameBuffers").finish_non_exhaustive()
    }
}

/// The process's one wgpu instance, never destroyed. Destroying the last Vulkan instance
/// makes the loader unload the driver, and the NVIDIA driver keeps a thread of its own that
/// may still run code of the unloaded library, a segmentation fault at exit. An
/// instance that lives until the process exits keeps the driver loaded; the operating system
/// reclaims it.
fn instance() -> &'static wgpu::Instance {
    static INSTANCE: std::sync::OnceLock<wgpu::Instance> = std::sync::OnceLock::new();
    INSTANCE.get_or_init(|| {
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env())
    })
}

/// The adapters wgpu finds, in its order (the indices of `--devices` and `sdfc devices`).
pub fn adapters() -> Vec<wgpu::Adapter> {
    pollster::block_on(instance().enumerate_adapters(wgpu::Backends::all()))
}

/// One line about an adapter: its name, backend and kind, and its largest buffer (wgpu does
/// not report a device's memory).
pub fn describe_adapter(adapter: &wgpu::Adapter) -> String {
    let info = adapter.get_info();
    format!(
        "{} ({:?}, {:?}); largest buffer {} MiB",
        info.name,
        info.backend,
        info.device_type,
        adapter.limits().max_buffer_size >> 20
    )
}

impl Gpu {
    /// Opens adapter `index` of [`adapters`].
    pub fn open_index(index: usize) -> Result<Gpu, Error> {
        let adapters = adapters();
        let count = adapters.len();
        match adapters.into_iter().nth(index) {
            Some(a) => Self::from_adapter(&a),
            None => Err(Error::NoSuchAdapter { index, count }),
        }
    }

    /// Opens the first adapter wgpu finds. With `require_hardware`, a CPU adapter (lavapipe)
    /// does not count.
    pub fn open(require_hardware: bool) -> Result<Gpu, Error> {
        let adapters = adapters();
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
        let driver_cache = adapter.features().contains(wgpu::Features::PIPELINE_CACHE)
            && wgpu::util::pipeline_cache_key(&info).is_some();
        let mut features = wgpu::Features::empty();
        if timestamps {
            features |= wgpu::Features::TIMESTAMP_QUERY;
        }
        if driver_cache {
            features |= wgpu::Features::PIPELINE_CACHE;
        }
        // The adapter's own buffer limits, not wgpu's defaults (256 MiB, which an 8K image of
        // 16 bytes a pixel exceeds).
        let limits = wgpu::Limits {
            max_storage_buffer_binding_size: adapter.limits().max_storage_buffer_binding_size,
            max_buffer_size: adapter.limits().max_buffer_size,
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
            driver_cache,
            pipelines: Mutex::new(HashMap::new()),
            spare: Mutex::new(None),
            staging: Mutex::new(Vec::new()),
            reducer: Mutex::new(None),
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
    /// `data`), or finds it among those already compiled on this device. `module` is the
    /// kernel's naga module when the caller has it (the compiler parsed and validated the
    /// text): wgpu then takes it instead of parsing the text again.
    pub fn pipeline_for(
        &self,
        wgsl: &str,
        module: Option<&wgpu::naga::Module>,
        entry: &str,
        data: bool,
    ) -> Result<PipelineTime, Error> {
        let start = Instant::now();
        let (_, driver) = self.pipeline_from(wgsl, module, entry, data)?;
        Ok(PipelineTime {
            time: start.elapsed(),
            cached: driver == DriverCache::NotAsked,
            driver,
        })
    }

    /// The pipeline of a kernel, from this device's cache or created (and validated) now,
    /// with what the driver was given ([`DriverCache::NotAsked`] when it came from the cache).
    fn cached_pipeline(
        &self,
        wgsl: &str,
        entry: &str,
        data: bool,
    ) -> Result<(Pipeline, DriverCache), Error> {
        self.pipeline_from(wgsl, None, entry, data)
    }

    /// [`Gpu::cached_pipeline`], created from the kernel's naga `module` when given.
    fn pipeline_from(
        &self,
        wgsl: &str,
        module: Option<&wgpu::naga::Module>,
        entry: &str,
        data: bool,
    ) -> Result<(Pipeline, DriverCache), Error> {
        let key = (wgsl.to_string(), entry.to_string(), data);
        if let Some(p) = self.lock_pipelines().get(&key) {
            return Ok((p.clone(), DriverCache::NotAsked));
        }
        // The cache is not held while the driver compiles: the viewer compiles a kernel on
        // another thread while its window's thread renders with another one. Two threads that
        // ask for the same kernel at once may both compile it; the last one's is kept. wgpu's
        // error scopes belong to the thread that pushes them.
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let (pipeline, layout, driver) = self.pipeline(wgsl, module, entry, data);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::Pipeline(e.to_string()));
        }
        let pipeline = Arc::new((pipeline, layout));
        let mut cache = self.lock_pipelines();
        if cache.len() >= PIPELINES_KEPT {
            cache.clear();
        }
        cache.insert(key, pipeline.clone());
        Ok((pipeline, driver))
    }

    /// The pipeline of `wgsl` (entry point `entry`, with the scene-data binding when `data`)
    /// and its bind group layout (the bindings of [`Gpu::kernel`]'s frames), compiled now or
    /// found among those compiled: for a caller that dispatches the kernel into buffers of its
    /// own (the viewer's frames, which stay on the device).
    pub fn compute_pipeline(&self, wgsl: &str, entry: &str, data: bool) -> Result<Pipeline, Error> {
        self.cached_pipeline(wgsl, entry, data).map(|(p, _)| p)
    }

    /// Whether the pipeline of `wgsl` (entry point `entry`, with the scene-data binding when
    /// `data`) is among those compiled on this device: [`Gpu::pipeline_for`] then returns at
    /// once, with no driver call.
    pub fn has_pipeline(&self, wgsl: &str, entry: &str, data: bool) -> bool {
        let key = (wgsl.to_string(), entry.to_string(), data);
        self.lock_pipelines().contains_key(&key)
    }

    fn lock_pipelines(
        &self,
    ) -> std::sync::MutexGuard<'_, HashMap<(String, String, bool), Pipeline>> {
        self.pipelines.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The file of the driver's pipeline cache data for a kernel on this device
    /// ([`super::cache_file`], keyed like the CUDA cache by everything the compiled code
    /// depends on: the kernel's text and entry point, its bindings, the adapter and driver,
    /// sdfc's version), when the device keeps such data.
    fn driver_cache_path(&self, wgsl: &str, entry: &str, data: bool) -> Option<std::path::PathBuf> {
        if !self.driver_cache {
            return None;
        }
        let i = &self.info;
        let adapter = wgpu::util::pipeline_cache_key(i)?;
        let key = (
            (wgsl, entry, data),
            (adapter, &i.name, &i.driver, &i.driver_info),
            env!("CARGO_PKG_VERSION"),
        );
        super::cache_file("wgpu", &key, "pipeline")
    }

    /// The adapter's name and backend, e.g. `<the GPU's name> (Vulkan)`.
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

    /// The kernel `wgsl` (entry point `entry`, workgroups of `workgroup`² threads) on this
    /// device, as a [`launch::Device`] the scheduler renders tiles on.
    pub fn kernel<'a>(&'a self, wgsl: &'a str, entry: &'a str, workgroup: u32) -> Kernel<'a> {
        Kernel {
            gpu: self,
            wgsl,
            entry,
            workgroup,
        }
    }

    /// The pipeline and its bind group layout: binding 0 the scene uniform, 1 the tile table
    /// (a uniform at a dynamic offset), 2 the image, 3 the statistics and 5 the finished
    /// pixels (storage), and 4 the scene data (read-only storage) when the kernel has it. The driver is given the
    /// pipeline cache data an earlier process stored for this kernel on this device, or else
    /// what it produces is stored ([`Gpu::driver_cache_path`]).
    fn pipeline(
        &self,
        wgsl: &str,
        naga: Option<&wgpu::naga::Module>,
        entry_point: &str,
        data: bool,
    ) -> (wgpu::ComputePipeline, wgpu::BindGroupLayout, DriverCache) {
        // wgpu validates a naga module as it would the module it parses from the text.
        let source = match naga {
            Some(m) => wgpu::ShaderSource::Naga(std::borrow::Cow::Owned(m.clone())),
            None => wgpu::ShaderSource::Wgsl(wgsl.into()),
        };
        // wgpu's checks except the bound on loops: naga gives every loop a counter, tested
        // each turn, up to a fifth more time on a marched scene's frame. Index bounds stay
        // checked, at no measurable cost. Storage buffers' bounds are left to the driver's
        // robust buffer access where the adapter has
        // `robustBufferAccess2` (wgpu's choice; no option changes it).
        let mut checks = wgpu::ShaderRuntimeChecks::checked();
        checks.force_loop_bounding = false;
        // SAFETY: wgpu requires that no loop of the shader runs forever. Every loop of a
        // kernel sdfc writes ends on the data sdfc writes (ARCHITECTURE.md, "Invariants"): the
        // march and shadow loops count steps to `max_steps`, the ray stack pops an entry each
        // turn and pushes at most two per hit up to `max_depth`, the walks over `scene_data`
        // move forwards or pop a stack of bounded depth, and the interpreter's jumps go
        // forwards to its RETURN.
        #[allow(unsafe_code)]
        let module = unsafe {
            self.device.create_shader_module_trusted(
                wgpu::ShaderModuleDescriptor {
                    label: Some("sdfc kernel"),
                    source,
                },
                checks,
            )
        };
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
            entry(5, storage(false)),
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
        let (pipeline, driver) = self.cached_compute(
            (wgsl, entry_point, data),
            "sdfc render",
            &pipeline_layout,
            &module,
        );
        (pipeline, layout, driver)
    }

    /// The compute pipeline of `module`'s entry point `entry` (of the text `wgsl`, with the
    /// scene-data binding when `data`: the key of [`Gpu::driver_cache_path`]) laid out as
    /// `layout`, the driver given the pipeline cache data an earlier process stored for it on
    /// this device, or else what it produces stored.
    fn cached_compute(
        &self,
        (wgsl, entry, data): (&str, &str, bool),
        label: &str,
        layout: &wgpu::PipelineLayout,
        module: &wgpu::ShaderModule,
    ) -> (wgpu::ComputePipeline, DriverCache) {
        let path = self.driver_cache_path(wgsl, entry, data);
        let stored = path.as_ref().and_then(|p| std::fs::read(p).ok());
        // wgpu cannot check that cache data came from
        // `PipelineCache::get_data`.
        #[allow(unsafe_code)]
        let cache = path.as_ref().map(|_| {
            // SAFETY: the data was returned by `PipelineCache::get_data` for this kernel on an
            // adapter with the same `pipeline_cache_key` and driver (the file's name hashes
            // them), written atomically; wgpu checks its header (adapter, driver validation
            // key, length) and, with `fallback`, starts an empty cache from data it refuses.
            unsafe {
                self.device
                    .create_pipeline_cache(&wgpu::PipelineCacheDescriptor {
                        label: Some("sdfc pipeline cache"),
                        data: stored.as_deref(),
                        fallback: true,
                    })
            }
        });
        let pipeline = self
            .device
            .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(label),
                layout: Some(layout),
                module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: cache.as_ref(),
            });
        let driver = match (&path, &stored, &cache) {
            (Some(_), Some(bytes), _) => DriverCache::Read(bytes.len() as u64),
            (Some(p), None, Some(cache)) => {
                let written = cache.get_data().filter(|bytes| {
                    let dir = p.parent().map(std::fs::create_dir_all);
                    dir.is_none_or(|r| r.is_ok()) && crate::image::write_atomic(p, bytes).is_ok()
                });
                DriverCache::Written(written.map_or(0, |b| b.len() as u64))
            }
            _ => DriverCache::Unsupported,
        };
        (pipeline, driver)
    }

    /// The buffers of a frame with the job's uniforms and scene data written (queued): the
    /// spare ones when their sizes fit, else new ones.
    fn buffers(&self, l: &Job, pixels: u64, tiles: u64) -> Buffers {
        let fits = |b: &Buffers| {
            b.uniforms.size() == padded(l.uniforms.len() as u64)
                && b.data.as_ref().map(|d| d.size()) == l.data.map(|d| padded(d.len() as u64))
                && b.tile.size() == padded(tiles * TILE_STRIDE as u64)
                && b.image.size() == padded(pixels * 16)
        };
        let b = match self.spare.lock().ok().and_then(|mut s| s.take()) {
            Some(b) if fits(&b) => b,
            _ => self.new_buffers(l, pixels, tiles),
        };
        self.queue.write_buffer(&b.uniforms, 0, l.uniforms);
        if let (Some(buffer), Some(bytes)) = (&b.data, l.data) {
            self.queue.write_buffer(buffer, 0, bytes);
        }
        b
    }

    fn new_buffers(&self, l: &Job, pixels: u64, tiles: u64) -> Buffers {
        use wgpu::BufferUsages as U;
        let make = |label, size: u64, usage| {
            self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: padded(size),
                usage,
                mapped_at_creation: false,
            })
        };
        Buffers {
            uniforms: make(
                "sdfc scene",
                l.uniforms.len() as u64,
                U::UNIFORM | U::COPY_DST,
            ),
            data: l.data.map(|bytes| {
                make(
                    "sdfc scene data",
                    bytes.len() as u64,
                    U::STORAGE | U::COPY_DST,
                )
            }),
            tile: make(
                "sdfc tiles",
                tiles * TILE_STRIDE as u64,
                U::UNIFORM | U::COPY_DST,
            ),
            image: make("sdfc image", pixels * 16, U::STORAGE | U::COPY_SRC),
            pixels: make("sdfc pixels", pixels * 4, U::STORAGE | U::COPY_SRC),
            stats: make(
                "sdfc stats",
                pixels * 4 * STATS_WORDS as u64,
                U::STORAGE | U::COPY_SRC,
            ),
            reduction: None,
            readback: [None, None],
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
            wgpu::BindGroupEntry {
                binding: 5,
                resource: b.pixels.as_entire_binding(),
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

    /// Waits for the work submitted. On a GPU the host first polls, yielding its core
    /// between polls, for up to [`SPIN`]: the driver's blocking wait returns a tenth of a
    /// millisecond or more after the end of a frame, as long as a short frame itself
    /// (measured), and CUDA's default wait polls too. A longer
    /// wait blocks, its latency small beside the frame. A software adapter (lavapipe)
    /// renders on the host's cores, which polling would take from it: it blocks at once.
    pub fn wait(&self) -> Result<(), Error> {
        let error = |e: wgpu::PollError| Error::Render(e.to_string());
        if !self.is_cpu() {
            let start = Instant::now();
            while start.elapsed() < SPIN {
                if self
                    .device
                    .poll(wgpu::PollType::Poll)
                    .map_err(error)?
                    .is_queue_empty()
                {
                    return Ok(());
                }
                std::thread::yield_now();
            }
        }
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(error)
    }

    /// The statistics' reduction pipeline (`sdfc_compiler::wgsl::reduce`): binding 0
    /// its query (read-only storage at a dynamic offset), 1 the kernel's statistics (read
    /// only), 2 and 3 the partial records and totals.
    fn reducer(&self) -> Result<Pipeline, Error> {
        let mut kept = self.reducer.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(p) = kept.as_ref() {
            return Ok(p.clone());
        }
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = self
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("sdfc reduction"),
                source: wgpu::ShaderSource::Wgsl(reduction::SOURCE.into()),
            });
        let entry = |binding, read_only, dynamic| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: dynamic,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = self
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("sdfc reduction"),
                entries: &[
                    entry(0, true, true),
                    entry(1, true, false),
                    entry(2, false, false),
                    entry(3, false, false),
                ],
            });
        let pipeline_layout = self
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("sdfc reduction"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
        // The driver's compiled code kept between processes, as a kernel's is.
        let (pipeline, _) = self.cached_compute(
            (reduction::SOURCE, reduction::ENTRY_POINT, false),
            "sdfc reduction",
            &pipeline_layout,
            &module,
        );
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::Pipeline(e.to_string()));
        }
        let p = Arc::new((pipeline, layout));
        *kept = Some(p.clone());
        Ok(p)
    }

    /// The per-pixel statistics of the last frame of `pixels` pixels rendered on this device,
    /// read back whole ([`STATS_WORDS`] words a pixel), for checking their reduction on the
    /// device against the host's sums ([`super::counters`]); `None` when no frame of that
    /// size has been rendered.
    pub fn last_statistics(&self, pixels: usize) -> Result<Option<Vec<u32>>, Error> {
        let spare = self.spare.lock().unwrap_or_else(|e| e.into_inner());
        let Some(b) = spare
            .as_ref()
            .filter(|b| b.image.size() == padded(16 * pixels as u64))
        else {
            return Ok(None);
        };
        let bytes = self.read(&b.stats, 4 * STATS_WORDS as u64 * pixels as u64)?;
        Ok(Some(
            bytes
                .chunks_exact(4)
                .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect(),
        ))
    }

    /// Waits until submission `index` is done and the mapping it was followed by has
    /// reported to `mapped` (polling first, as [`Gpu::wait`] does), not for the work
    /// submitted after it.
    fn wait_for(
        &self,
        index: wgpu::SubmissionIndex,
        mapped: &std::sync::mpsc::Receiver<Result<(), wgpu::BufferAsyncError>>,
    ) -> Result<(), Error> {
        let error = |e: wgpu::PollError| Error::Render(e.to_string());
        let done =
            |r: Result<(), wgpu::BufferAsyncError>| r.map_err(|e| Error::Render(e.to_string()));
        if !self.is_cpu() {
            let start = Instant::now();
            while start.elapsed() < SPIN {
                self.device.poll(wgpu::PollType::Poll).map_err(error)?;
                if let Ok(r) = mapped.try_recv() {
                    return done(r);
                }
                std::thread::yield_now();
            }
        }
        self.device
            .poll(wgpu::PollType::Wait {
                submission_index: Some(index),
                timeout: None,
            })
            .map_err(error)?;
        done(mapped.recv().map_err(|e| Error::Render(e.to_string()))?)
    }

    fn read(&self, src: &wgpu::Buffer, size: u64) -> Result<Vec<u8>, Error> {
        self.read_ranges(src, std::slice::from_ref(&(0..size)))
    }

    /// The bytes of `ranges` of `src`, one after the other, through one staging buffer.
    fn read_ranges(&self, src: &wgpu::Buffer, ranges: &[Range<u64>]) -> Result<Vec<u8>, Error> {
        self.read_with(src, ranges, |bytes| bytes.to_vec())
    }

    /// What `f` makes of the bytes of `ranges` of `src`, one after the other, read in the
    /// staging buffer while it is mapped (a frame's colours are converted there, not copied
    /// out first: 33 MB at 1920×1080).
    fn read_with<T>(
        &self,
        src: &wgpu::Buffer,
        ranges: &[Range<u64>],
        f: impl FnOnce(&[u8]) -> T,
    ) -> Result<T, Error> {
        let size: u64 = ranges.iter().map(|r| r.end - r.start).sum();
        let kept = self.staging.lock().ok().and_then(|mut kept| {
            let at = kept.iter().position(|b| b.size() == size)?;
            Some(kept.swap_remove(at))
        });
        let staging = kept.unwrap_or_else(|| {
            self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("sdfc readback"),
                size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        });
        let mut enc = self.device.create_command_encoder(&Default::default());
        let mut at = 0;
        for r in ranges {
            enc.copy_buffer_to_buffer(src, r.start, &staging, at, r.end - r.start);
            at += r.end - r.start;
        }
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
        let out = f(&slice
            .get_mapped_range()
            .map_err(|e| Error::Render(e.to_string()))?);
        staging.unmap();
        if let Ok(mut kept) = self.staging.lock() {
            // The few sizes a frame reads back (image or pixels, statistics, timestamps).
            if kept.len() >= 4 {
                kept.remove(0);
            }
            kept.push(staging);
        }
        Ok(out)
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

#[derive(Debug)]
struct Buffers {
    uniforms: wgpu::Buffer,
    data: Option<wgpu::Buffer>,
    tile: wgpu::Buffer,
    image: wgpu::Buffer,
    pixels: wgpu::Buffer,
    stats: wgpu::Buffer,
    /// The reduction's partial records and totals, made when a frame's statistics are first
    /// reduced.
    reduction: Option<(wgpu::Buffer, wgpu::Buffer)>,
    /// Two mappable buffers the finished pixels of a band are copied into while the next band
    /// renders, made when first used.
    readback: [Option<wgpu::Buffer>; 2],
}

fn words(w: &[u32]) -> Vec<u8> {
    w.iter().flat_map(|x| x.to_le_bytes()).collect()
}

impl launch::Device for Kernel<'_> {
    type Frame = FrameBuffers;
    type Error = Error;

    fn describe(&self) -> String {
        self.gpu.describe()
    }

    fn prepare(&self, job: &Job) -> Result<FrameBuffers, Error> {
        let gpu = self.gpu;
        let limits = gpu.device.limits();
        let limit = limits.max_storage_buffer_binding_size;
        if let Some(data) = job.data.filter(|d| d.len() as u64 > limit) {
            return Err(Error::Render(format!(
                "the scene's primitives take {} bytes, more than the {limit} bytes a storage buffer of this adapter may bind",
                data.len()
            )));
        }
        // The image (16 bytes a pixel) and the statistics are storage buffers bound whole.
        let largest = job.width as u64 * job.height as u64 * 4 * STATS_WORDS.max(4) as u64;
        let most = limit.min(limits.max_buffer_size);
        if largest > most {
            return Err(Error::Render(format!(
                "a {}x{} frame needs buffers of {largest} bytes, more than the {most} bytes this adapter allows; render it smaller or with --backend cuda",
                job.width, job.height
            )));
        }
        let (pipeline, _) = gpu.cached_pipeline(self.wgsl, self.entry, job.data.is_some())?;
        let pixels = job.width as u64 * job.height as u64;
        let tiles = job.tiles.len() as u64;
        let buffers = gpu.buffers(job, pixels, tiles);
        let bind = gpu.bind_group(&pipeline.1, &buffers);
        let queries = (gpu.timestamps && job.timed).then(|| {
            gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("sdfc timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * tiles as u32,
            })
        });
        let memory = Some(gpu.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory));
        let table: Vec<u8> = job
            .tiles
            .iter()
            .flat_map(|t| {
                let mut entry = words(&[t.0, t.1, t.2, t.3]);
                entry.resize(TILE_STRIDE as usize, 0);
                entry
            })
            .collect();
        gpu.queue.write_buffer(&buffers.tile, 0, &table);
        // wgpu queues its writes until the next submission: submitted now, the uploads are
        // part of the frame's setup, as CUDA's are, not of its first launch.
        gpu.queue.submit([]);
        gpu.wait()?;
        Ok(FrameBuffers {
            pipeline,
            buffers,
            bind,
            queries,
            memory,
            reading: [None, None],
        })
    }

    fn run(&self, f: &mut FrameBuffers, job: &Job, tiles: &[usize]) -> Result<(), Error> {
        self.submit(f, job, tiles)?;
        self.gpu.wait()
    }

    fn submit(&self, f: &mut FrameBuffers, job: &Job, tiles: &[usize]) -> Result<(), Error> {
        let gpu = self.gpu;
        // Each tile is its own dispatch, in one submission.
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        for &i in tiles {
            let t = job.tiles[i];
            let i = i as u32;
            let writes = f
                .queries
                .as_ref()
                .map(|q| wgpu::ComputePassTimestampWrites {
                    query_set: q,
                    beginning_of_pass_write_index: Some(2 * i),
                    end_of_pass_write_index: Some(2 * i + 1),
                });
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: None,
                timestamp_writes: writes,
            });
            pass.set_pipeline(&f.pipeline.0);
            pass.set_bind_group(0, &f.bind, &[i * TILE_STRIDE]);
            pass.dispatch_workgroups(
                t.2.div_ceil(self.workgroup),
                t.3.div_ceil(self.workgroup),
                1,
            );
        }
        gpu.queue.submit([enc.finish()]);
        Ok(())
    }

    /// The finished pixels of `range`, copied (in a submission after the launches) into
    /// readback buffer `slot` and mapped when the copy is done; the linear colours are read at
    /// [`launch::Device::collect`].
    fn start_read(
        &self,
        f: &mut FrameBuffers,
        job: &Job,
        range: Range<usize>,
        slot: usize,
    ) -> Result<(), Error> {
        if !job.finished {
            return Ok(());
        }
        let gpu = self.gpu;
        let size = 4 * range.len() as u64;
        let kept = f.buffers.readback[slot].take();
        let buffer = kept.filter(|b| b.size() >= size).unwrap_or_else(|| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("sdfc band readback"),
                size: padded(size),
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        });
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(&f.buffers.pixels, 4 * range.start as u64, &buffer, 0, size);
        let index = gpu.queue.submit([enc.finish()]);
        let (tx, rx) = std::sync::mpsc::channel();
        buffer
            .slice(..size)
            .map_async(wgpu::MapMode::Read, move |r| {
                let _ = tx.send(r);
            });
        f.buffers.readback[slot] = Some(buffer);
        f.reading[slot] = Some((range, index, rx));
        Ok(())
    }

    fn collect(
        &self,
        f: &mut FrameBuffers,
        job: &Job,
        range: Range<usize>,
        slot: usize,
    ) -> Result<Pixels, Error> {
        let reading = f.reading[slot].take();
        let (Some((at, index, mapped)), Some(buffer)) = (reading, &f.buffers.readback[slot]) else {
            return self.read(f, job, std::slice::from_ref(&range));
        };
        debug_assert_eq!(at, range, "the band read into this slot");
        // Waits for the copy alone: the launches submitted after it may still run.
        self.gpu.wait_for(index, &mapped)?;
        let size = 4 * range.len() as u64;
        let rgba = {
            let view = buffer
                .slice(..size)
                .get_mapped_range()
                .map_err(|e| Error::Render(e.to_string()))?;
            super::to_vec_parallel(&view)
        };
        buffer.unmap();
        Ok(Pixels {
            linear: Vec::new(),
            rgba,
            convert: Duration::ZERO,
        })
    }

    /// A band's finished pixels copied from the mapped buffer straight into their place,
    /// the wait for the copy timed apart.
    fn collect_into(
        &self,
        f: &mut FrameBuffers,
        job: &Job,
        range: Range<usize>,
        slot: usize,
        place: launch::Place<'_>,
    ) -> Result<launch::Collected, Error> {
        let started = matches!(&f.reading[slot], Some((at, ..)) if *at == range);
        let buffer = f.buffers.readback[slot].as_ref().filter(|_| started);
        match (buffer, place) {
            (Some(buffer), launch::Place::Rgba(out)) => {
                let Some((_, index, mapped)) = f.reading[slot].take() else {
                    return Err(Error::Render("no band was read into this slot".into()));
                };
                let waiting = Instant::now();
                // Waits for the copy alone: the launches submitted after it may still run.
                self.gpu.wait_for(index, &mapped)?;
                let wait = waiting.elapsed();
                let size = 4 * range.len() as u64;
                {
                    let view = buffer
                        .slice(..size)
                        .get_mapped_range()
                        .map_err(|e| Error::Render(e.to_string()))?;
                    super::copy_parallel(out, &view);
                }
                buffer.unmap();
                Ok(launch::Collected {
                    wait,
                    convert: Duration::ZERO,
                })
            }
            (_, place) => launch::collect_copied(self, f, job, (range, slot), place),
        }
    }

    fn read(
        &self,
        f: &mut FrameBuffers,
        job: &Job,
        ranges: &[Range<usize>],
    ) -> Result<Pixels, Error> {
        let bytes = |per: u64| -> Vec<Range<u64>> {
            ranges
                .iter()
                .map(|r| r.start as u64 * per..r.end as u64 * per)
                .collect()
        };
        // Converted in the mapped staging buffers, each conversion timed.
        use rayon::prelude::*;
        let mut convert = Duration::ZERO;
        let f32_at = |b: &[u8]| f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        let (linear, rgba) = if job.finished {
            // The finished pixels are the bytes to write: copied out as they are.
            let rgba = self.gpu.read_with(&f.buffers.pixels, &bytes(4), |b| {
                // Copied out by every core, as the linear colours are converted.
                super::to_vec_parallel(b)
            })?;
            (Vec::new(), rgba)
        } else {
            let linear = self.gpu.read_with(&f.buffers.image, &bytes(16), |b| {
                let start = Instant::now();
                let linear = b
                    .par_chunks_exact(16)
                    .map(|c| [f32_at(&c[0..4]), f32_at(&c[4..8]), f32_at(&c[8..12])])
                    .collect();
                convert += start.elapsed();
                linear
            })?;
            (linear, Vec::new())
        };
        Ok(Pixels {
            linear,
            rgba,
            convert,
        })
    }

    fn reduce(
        &self,
        f: &mut FrameBuffers,
        job: &Job,
        ranges: &[Range<usize>],
        ask: Ask,
    ) -> Result<Answer, Error> {
        let queries = reduce::queries(job.pixels(), ranges, ask);
        if queries.is_empty() {
            return Ok(Answer::empty(ask));
        }
        let gpu = self.gpu;
        let pipeline = gpu.reducer()?;
        let (first, second) = reduce::threads(job.pixels());
        let record = 4 * reduction::RECORD as u64;
        let (partial, total) = f.buffers.reduction.get_or_insert_with(|| {
            use wgpu::BufferUsages as U;
            let make = |label, size| {
                gpu.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size,
                    usage: U::STORAGE | U::COPY_SRC,
                    mapped_at_creation: false,
                })
            };
            (
                make("sdfc partial statistics", first as u64 * record),
                make("sdfc statistics", second as u64 * record),
            )
        });
        // One query a dispatch, each at its own offset of one buffer.
        let slots: Vec<u8> = queries
            .iter()
            .flat_map(|q| {
                let mut slot = words(&q.words());
                slot.resize(TILE_STRIDE as usize, 0);
                slot
            })
            .collect();
        let query = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sdfc reduction queries"),
            size: slots.len() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        gpu.queue.write_buffer(&query, 0, &slots);
        let entry = |binding, resource| wgpu::BindGroupEntry { binding, resource };
        let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sdfc reduction"),
            layout: &pipeline.1,
            entries: &[
                entry(
                    0,
                    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &query,
                        offset: 0,
                        size: std::num::NonZeroU64::new(4 * reduction::QUERY_WORDS as u64),
                    }),
                ),
                entry(1, f.buffers.stats.as_entire_binding()),
                entry(2, partial.as_entire_binding()),
                entry(3, total.as_entire_binding()),
            ],
        });
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        for (i, q) in queries.iter().enumerate() {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline.0);
            pass.set_bind_group(0, &bind, &[i as u32 * TILE_STRIDE]);
            pass.dispatch_workgroups(q.threads.div_ceil(reduction::WORKGROUP), 1, 1);
        }
        gpu.queue.submit([enc.finish()]);
        let totals = gpu.read_with(
            total,
            std::slice::from_ref(&(0..second as u64 * record)),
            |b| {
                b.chunks_exact(4)
                    .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                    .collect::<Vec<u32>>()
            },
        )?;
        Ok(Answer::of_totals(&totals, ask))
    }

    fn check(&self, f: &mut FrameBuffers) -> Result<(), Error> {
        if let Some(scope) = f.memory.take() {
            let error = pollster::block_on(scope.pop());
            f.memory = Some(
                self.gpu
                    .device
                    .push_error_scope(wgpu::ErrorFilter::OutOfMemory),
            );
            if let Some(e) = error {
                return Err(Error::Render(e.to_string()));
            }
        }
        Ok(())
    }

    fn finish(&self, mut f: FrameBuffers, job: &Job) -> Result<Option<Duration>, Error> {
        if let Some(scope) = f.memory.take() {
            if let Some(e) = pollster::block_on(scope.pop()) {
                return Err(Error::Render(e.to_string()));
            }
        }
        let time = match &f.queries {
            Some(q) => Some(self.gpu.gpu_time(q, job.tiles.len() as u32)?),
            None => None,
        };
        if let Ok(mut spare) = self.gpu.spare.lock() {
            *spare = Some(f.buffers);
        }
        Ok(time)
    }

    fn fault(&self, message: String) -> Error {
        Error::Render(message)
    }
}
