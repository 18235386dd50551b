//! The CUDA launcher: loads the PTX of the kernel through the driver's JIT (the compiled
//! module is cached on disk, keyed by a hash of the PTX and the device), renders in tiles
//! (one launch each) and reads back the image, and the statistics reduced on the device
//! (`super::reduce`).
//!
//! The driver is loaded at run time (cudarc's dynamic loading), so sdfc builds and runs on
//! machines without CUDA and says so when asked to use it.

#![allow(unsafe_code)] // The driver API is C: its calls are wrapped here, each with its reason.

mod device;
mod jit;

use cudarc::driver::{
    sys, CudaContext, CudaEvent, CudaFunction, CudaSlice, CudaStream, PinnedHostSlice,
};
use sdfc_compiler::ptx::{self, Param};
use std::ops::Range;
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// What can go wrong on the CUDA path.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// libcuda could not be loaded.
    #[error(
        "no CUDA driver found (libcuda.so): install the NVIDIA driver, or choose another backend"
    )]
    NoDriver,
    /// The driver has no device.
    #[error("the CUDA driver found no device")]
    NoDevice,
    /// A driver call failed.
    #[error("CUDA driver error during {during}: {source}")]
    Driver {
        during: &'static str,
        source: cudarc::driver::DriverError,
    },
    /// Device `index` is not among those the driver was restricted to ([`only_devices`]).
    #[error(
        "CUDA driver error during opening the device: CUDA device {index} was not among those \
         named before the driver started"
    )]
    NotVisible { index: usize },
    /// There is no device `index`: the driver found `count` (of those named, when
    /// `restricted`).
    #[error(
        "CUDA driver error during opening the device: there is no CUDA device {index} (the \
         driver found {count}{}; `sdfc devices` lists them)",
        if *.restricted { " of those named" } else { "" }
    )]
    NoSuchDevice {
        index: usize,
        count: i32,
        restricted: bool,
    },
    /// A fault injected by `SDFC_FAULT_AFTER_TILES` (tests of the scheduler): its message.
    #[error("CUDA driver error during running the kernel: {0}")]
    Injected(String),
    /// The JIT refused the PTX (a compiler bug: the PTX is checked by ptxas in CI): the
    /// step, the driver's result and the JIT's log.
    #[error("the CUDA JIT rejected the PTX: {during}: {result:?} {log}")]
    Jit {
        during: &'static str,
        result: sys::CUresult,
        log: String,
    },
    /// The statistics' reduction could not be written as PTX (a compiler bug).
    #[error("the CUDA JIT rejected the PTX: the statistics' reduction: {0}")]
    Reduction(#[source] ptx::Error),
    /// What a launch would pass differs from the kernel's parameters (a bug of sdfc's):
    /// refused before launching.
    #[error("internal error: the CUDA kernel's parameters do not match the launch: {0}")]
    Arguments(#[from] ptx::Mismatch),
    /// The scene's uniforms do not fit the kernel's layout (a bug of sdfc's).
    #[error("internal error: the CUDA kernel's parameters do not match the launch: {0}")]
    Uniforms(#[from] sdfc_compiler::wgsl::Mismatch),
}

fn driver(during: &'static str) -> impl Fn(cudarc::driver::DriverError) -> Error {
    move |source| Error::Driver { during, source }
}

/// An opened CUDA device.
#[derive(Debug)]
pub struct Cuda {
    ctx: Arc<CudaContext>,
    stream: Arc<CudaStream>,
    /// Compute capability as major·10 + minor (90 for compute capability 9.0).
    pub sm: u32,
    name: String,
    memory: u64,
    /// The buffers of the last frame finished, kept for the next frame of the same sizes
    /// (a sequence's or a benchmark's frames): a 1920×1080 frame otherwise allocates and
    /// clears 100 MB of image, statistics and pixels.
    spare: Mutex<Option<FrameBuffers>>,
    /// Page-locked host memory the finished pixels are read back into, kept across frames:
    /// the driver copies into pageable memory through a staging buffer of its own, at a
    /// fraction of the bus's speed.
    pinned: Mutex<Option<PinnedHostSlice<u8>>>,
    /// The statistics' reduction (`sdfc_compiler::wgsl::reduce` as PTX), loaded when
    /// first used.
    reducer: Mutex<Option<Arc<Loaded>>>,
}

/// A kernel loaded into the device, with how it was loaded.
#[derive(Debug)]
pub struct Loaded {
    function: CudaFunction,
    /// The kernel's parameters, as the PTX writer declared them.
    params: Vec<Param>,
    /// Time to compile (or read from the cache) and load the module.
    pub load_time: Duration,
    /// Whether the compiled module came from the disk cache.
    pub cached: bool,
}

/// A kernel loaded on a [`Cuda`] device, ready to render tiles ([`Cuda::kernel`]).
#[derive(Debug, Clone, Copy)]
pub struct Kernel<'a> {
    cuda: &'a Cuda,
    loaded: &'a Loaded,
    workgroup: u32,
}

/// A frame's buffers on the device, and the events timing its launches.
pub struct FrameBuffers {
    uniforms: CudaSlice<u8>,
    tiles: CudaSlice<u32>,
    image: CudaSlice<f32>,
    stats: CudaSlice<u32>,
    data: Option<CudaSlice<u8>>,
    /// The finished pixels, RGBA8 (binding 5).
    pixels: CudaSlice<u8>,
    events: Vec<(CudaEvent, CudaEvent)>,
    /// The reduction's partial records and totals, made when a frame's statistics are first
    /// reduced.
    reduction: Option<(CudaSlice<u32>, CudaSlice<u32>)>,
    /// Page-locked buffers the finished pixels of a band are copied into while the next band
    /// renders ([`launch::Device::start_read`]), with the pixels each holds.
    readback: [Readback; 2],
}

/// A page-locked readback buffer, and the pixels copied into it with the event recorded
/// behind the copy, if a copy was started.
type Readback = (
    Option<PinnedHostSlice<u8>>,
    Option<(Range<usize>, CudaEvent)>,
);

impl std::fmt::Debug for FrameBuffers {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FrameBuffers").finish_non_exhaustive()
    }
}

/// The GPUs this process's driver was restricted to by [`only_devices`], by the indices
/// `--devices` and `sdfc devices` give them, in the driver's order: the ordinal of each is its
/// place here.
static VISIBLE: std::sync::OnceLock<Vec<usize>> = std::sync::OnceLock::new();

/// Makes the CUDA devices `indices` (the indices `sdfc devices` lists) the only ones this
/// process's driver sees, through `CUDA_VISIBLE_DEVICES`: the driver's initialisation
/// otherwise prepares every GPU of the host, most of a short render's time on a host of
/// several GPUs. A user's own `CUDA_VISIBLE_DEVICES` is kept as the list the indices count
/// in (`--devices 1` with `CUDA_VISIBLE_DEVICES=2,3` is still GPU 3); an index past it, or a
/// variable that is not text, leaves it alone for the driver to judge. The variable's
/// indices follow the driver's order (`CUDA_DEVICE_ORDER`), as the ordinals do, and
/// [`Cuda::open_device`] maps an index to its ordinal among those left. Call it once, before
/// any thread starts and before the driver is loaded: the environment is the process's.
pub fn only_devices(indices: &[usize]) {
    let own = match std::env::var("CUDA_VISIBLE_DEVICES") {
        Ok(v) => Some(v),
        Err(std::env::VarError::NotPresent) => None,
        Err(std::env::VarError::NotUnicode(_)) => return,
    };
    if let Some((visible, kept)) = visible_entries(own.as_deref(), indices) {
        std::env::set_var("CUDA_VISIBLE_DEVICES", visible);
        let _ = VISIBLE.set(kept);
    }
}

/// What `CUDA_VISIBLE_DEVICES` becomes for a render on `indices` when it was `own`, and the
/// indices kept (sorted, each once); `None` to leave it as it is (no GPU named, or an index
/// past the user's own list).
fn visible_entries(own: Option<&str>, indices: &[usize]) -> Option<(String, Vec<usize>)> {
    let mut kept = indices.to_vec();
    kept.sort_unstable();
    kept.dedup();
    let entries: Vec<String> = match own {
        Some(own) => {
            let listed: Vec<&str> = own.split(',').collect();
            kept.iter()
                .map(|&i| listed.get(i).map(|e| e.to_string()))
                .collect::<Option<_>>()?
        }
        None => kept.iter().map(usize::to_string).collect(),
    };
    (!entries.is_empty()).then(|| (entries.join(","), kept))
}

/// The driver's ordinal of the device `sdfc devices` lists as `index`: the same unless
/// [`only_devices`] restricted the driver; `None` for a device it left out.
fn ordinal_of(visible: Option<&[usize]>, index: usize) -> Option<usize> {
    match visible {
        Some(v) => v.iter().position(|&i| i == index),
        None => Some(index),
    }
}

impl Cuda {
    /// Opens the first device the driver sees.
    pub fn open() -> Result<Cuda, Error> {
        Self::open_ordinal((0, 0), false)
    }

    /// Whether the CUDA driver's library (libcuda) can be loaded; no driver call is made.
    pub fn driver_present() -> bool {
        // SAFETY: only tries to dlopen libcuda; no driver call is made.
        unsafe { sys::is_culib_present() }
    }

    /// The number of CUDA devices (0 without a driver).
    pub fn count() -> usize {
        if !Self::driver_present() {
            return 0;
        }
        CudaContext::device_count().map_or(0, |n| n.max(0) as usize)
    }

    /// Opens device `index` (as `sdfc devices` lists it; [`only_devices`] may have left the
    /// driver fewer, whose ordinals differ). With `own_stream`, its launches go to a stream
    /// of their own (two `Cuda` opened on one device then run side by side, as two logical
    /// devices); otherwise to the context's default stream.
    pub fn open_device(index: usize, own_stream: bool) -> Result<Cuda, Error> {
        match ordinal_of(VISIBLE.get().map(Vec::as_slice), index) {
            Some(ordinal) => Self::open_ordinal((ordinal, index), own_stream),
            None => Err(Error::NotVisible { index }),
        }
    }

    /// Opens the device of the driver's ordinal `ordinal`, `index` in the messages (as
    /// [`Cuda::open_device`]).
    fn open_ordinal((ordinal, index): (usize, usize), own_stream: bool) -> Result<Cuda, Error> {
        if !Self::driver_present() {
            return Err(Error::NoDriver);
        }
        let count = CudaContext::device_count().map_err(driver("counting devices"))?;
        let restricted = VISIBLE.get().is_some();
        if count < 1 && !restricted {
            return Err(Error::NoDevice);
        }
        if ordinal >= count as usize {
            // Restricted to the devices named, the driver finds only those that exist.
            return Err(Error::NoSuchDevice {
                index,
                count,
                restricted,
            });
        }
        let ctx = CudaContext::new(ordinal).map_err(driver("creating a context"))?;
        let major = ctx
            .attribute(sys::CUdevice_attribute::CU_DEVICE_ATTRIBUTE_COMPUTE_CAPABILITY_MAJOR)
            .map_err(driver("reading the compute capability"))?;
        let minor = ctx
            .attribute(sys::CUdevice_attribute::CU_DEVICE_ATTRIBUTE_COMPUTE_CAPABILITY_MINOR)
            .map_err(driver("reading the compute capability"))?;
        let name = ctx.name().map_err(driver("reading the device name"))?;
        let memory = ctx.total_mem().map_err(driver("reading the memory size"))? as u64;
        let stream = if own_stream {
            ctx.new_stream().map_err(driver("creating a stream"))?
        } else {
            ctx.default_stream()
        };
        Ok(Cuda {
            ctx,
            stream,
            sm: (major * 10 + minor) as u32,
            name,
            memory,
            spare: Mutex::new(None),
            pinned: Mutex::new(None),
            reducer: Mutex::new(None),
        })
    }

    /// The device's memory in bytes.
    pub fn memory(&self) -> u64 {
        self.memory
    }

    /// The device's name and compute capability.
    pub fn describe(&self) -> String {
        format!("{} (sm_{})", self.name, self.sm)
    }
}

/// The register cap of a kernel that sphere traces. Its march loops over memory (the
/// instances' walk) and long arithmetic, and more warps resident on a multiprocessor hide
/// their latency better than the JIT's own choice of registers, which spends them on fewer
/// warps. Of the caps tried, 72 made the large marched kernels fastest; small ones lose a
/// little, and analytically traced kernels more, so they keep the JIT's choice. The JIT's
/// own count does not say which kernels gain, so the cap is one constant.
pub const MARCHED_REGISTERS: u32 = 72;

/// The register cap of a path-traced kernel that sphere traces: its bounces' loop keeps
/// little alive across the march, and of the caps tried on it (48 to 80) 64 was the fastest.
pub const PATH_REGISTERS: u32 = 64;

/// How a kernel finds its surfaces, as far as its register cap goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tracing {
    /// Sphere traced, Whitted shading.
    Marched,
    /// Sphere traced, path traced.
    MarchedPaths,
    /// Traced analytically.
    Analytic,
}

/// The register cap for the JIT of a kernel traced as `tracing`:
/// `$SDFC_CUDA_MAX_REGISTERS` when set (0: the JIT's choice), else [`MARCHED_REGISTERS`] or
/// [`PATH_REGISTERS`] for a marched kernel and the JIT's choice for the other.
pub fn register_cap(tracing: Tracing) -> Option<u32> {
    match std::env::var("SDFC_CUDA_MAX_REGISTERS") {
        Ok(v) => v.trim().parse().ok().filter(|&n| n > 0),
        Err(_) => match tracing {
            Tracing::Marched => Some(MARCHED_REGISTERS),
            Tracing::MarchedPaths => Some(PATH_REGISTERS),
            Tracing::Analytic => None,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::{ordinal_of, visible_entries};

    #[test]
    fn the_driver_sees_the_devices_named_and_their_indices_map_to_its_ordinals() {
        let visible = |own, indices: &[usize]| visible_entries(own, indices);
        assert_eq!(visible(None, &[0]), Some(("0".into(), vec![0])));
        // Sorted, each once: `--devices 3,1,1` is GPUs 1 and 3, the driver's ordinals 0 and 1.
        assert_eq!(visible(None, &[3, 1, 1]), Some(("1,3".into(), vec![1, 3])));
        assert_eq!(ordinal_of(Some(&[1, 3]), 3), Some(1));
        assert_eq!(ordinal_of(Some(&[1, 3]), 1), Some(0));
        assert_eq!(ordinal_of(Some(&[1, 3]), 0), None);
        assert_eq!(ordinal_of(None, 2), Some(2));
        // A user's own list is what the indices count in.
        let own = Some("GPU-a,GPU-b,GPU-c");
        assert_eq!(
            visible(own, &[2, 0]),
            Some(("GPU-a,GPU-c".into(), vec![0, 2]))
        );
        // Past it, or no GPU named: left to the driver.
        assert_eq!(visible(Some("2,3"), &[2]), None);
        assert_eq!(visible(None, &[]), None);
    }
}
