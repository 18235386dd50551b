//! The wgpu launcher: finds an adapter, builds the kernel's compute pipeline, and renders an
//! image in tiles (one dispatch each, so that no dispatch runs long enough to trip a driver
//! watchdog), reading back the finished pixels or the linear colours, and the per-pixel
//! statistics reduced on the device (`super::reduce`).

mod buffers;
mod device;
mod pipeline;
mod resident;

pub(crate) use buffers::{compute_entry, storage};
pub use resident::ResidentFrame;

use std::collections::HashMap;
use std::ops::Range;
use std::sync::{Arc, Mutex};
use std::time::Duration;

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
    #[error("the adapter `{adapter}` refused to open a device: {source}")]
    Device {
        adapter: String,
        source: wgpu::RequestDeviceError,
    },
    /// wgpu rejected the shader or pipeline (a compiler bug: the kernel was validated by naga).
    #[error("wgpu rejected the kernel: {0}")]
    Pipeline(#[source] wgpu::Error),
    /// The device reported an error while rendering (out of memory, device lost, …).
    #[error("GPU error while rendering: {0}")]
    Render(#[source] wgpu::Error),
    /// Waiting for the device failed (a lost device, a timeout).
    #[error("GPU error while rendering: {0}")]
    Poll(#[from] wgpu::PollError),
    /// A buffer could not be mapped to be read back.
    #[error("GPU error while rendering: {0}")]
    Map(#[from] wgpu::BufferAsyncError),
    /// A mapped buffer's range could not be viewed.
    #[error("GPU error while rendering: {0}")]
    MapRange(#[from] wgpu::MapRangeError),
    /// The mapping's callback was dropped before it reported.
    #[error("GPU error while rendering: {0}")]
    Mapped(#[from] std::sync::mpsc::RecvError),
    /// The scene's data (`bytes`) is larger than a storage buffer of the adapter may bind.
    #[error("GPU error while rendering: the scene's primitives take {bytes} bytes, more than the {limit} bytes a storage buffer of this adapter may bind")]
    StorageBuffer { bytes: usize, limit: u64 },
    /// A frame whose largest buffer (`largest` bytes) is above what the adapter allows
    /// (`most`).
    #[error("GPU error while rendering: a {width}x{height} frame needs buffers of {largest} bytes, more than the {most} bytes this adapter allows; render it smaller or with --backend cuda")]
    FrameTooLarge {
        width: u32,
        height: u32,
        largest: u64,
        most: u64,
    },
    /// A launch into a [`ResidentFrame`] not fitted to its work (a bug of sdfc's).
    #[error("internal error: the frame kept on the device does not fit the launch")]
    NotFitted,
    /// A fault injected by `SDFC_FAULT_AFTER_TILES` (tests of the scheduler): its message.
    #[error("GPU error while rendering: {0}")]
    Injected(String),
    /// The scene uniform does not fit the kernel's layout (`wgsl::uniforms`; a bug of
    /// sdfc's, or a kernel written for another scene): refused before anything is uploaded.
    #[error("internal error: the scene uniform does not fit the kernel: {0}")]
    Uniform(#[source] sdfc_compiler::wgsl::Mismatch),
}

/// Bytes between tile entries in the tile table (the largest uniform offset alignment).
pub const TILE_STRIDE: u32 = 256;

/// Compiled pipelines kept by a [`Gpu`] (at most this many; the cache is emptied when full).
const PIPELINES_KEPT: usize = 16;

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

/// A kernel on a [`Gpu`], ready to render tiles ([`Gpu::kernel`]), into a frame's buffers of
/// its own or into those of a [`ResidentFrame`] ([`Kernel::into_resident`]).
#[derive(Debug, Clone, Copy)]
pub struct Kernel<'a> {
    gpu: &'a Gpu,
    wgsl: &'a str,
    entry: &'a str,
    workgroup: u32,
    resident: Option<&'a ResidentFrame>,
}

impl<'a> Kernel<'a> {
    /// The kernel rendering into `frame`'s buffers, which stay on the device (a launch of
    /// [`crate::gpu::launch::Target::Resident`] work fitted to it: [`ResidentFrame::fit`]).
    pub fn into_resident(self, frame: &'a ResidentFrame) -> Kernel<'a> {
        Kernel {
            resident: Some(frame),
            ..self
        }
    }
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
    /// Whether the buffers go back to [`Gpu`]'s spare when the frame finishes (not those of
    /// a [`ResidentFrame`], which its owner keeps).
    spare: bool,
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
                source: e,
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
}

#[derive(Debug, Clone)]
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
