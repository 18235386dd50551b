//! The CUDA launcher: loads the PTX of the kernel through the driver's JIT (the compiled
//! module is cached on disk, keyed by a hash of the PTX and the device), renders in tiles
//! (one launch each) and reads back the image, and the statistics reduced on the device
//! (`super::reduce`).
//!
//! The driver is loaded at run time (cudarc's dynamic loading), so sdfc builds and runs on
//! machines without CUDA and says so when asked to use it.
#![allow(unsafe_code)] // The driver API is C: its calls are wrapped here, each with its reason.

use super::launch::{self, Job, Pixels};
use super::reduce::{self, Answer, Ask};
use cudarc::driver::{
    sys, CudaContext, CudaEvent, CudaFunction, CudaSlice, CudaStream, LaunchConfig,
    PinnedHostSlice, PushKernelArg,
};
use sdfc_compiler::{
    ptx::{self, Argument, Param, Space},
    wgsl::{reduce as reduction, STATS_WORDS},
};
use std::ops::Range;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

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
    #[error("CUDA driver error during {during}: {message}")]
    Driver {
        during: &'static str,
        message: String,
    },
    /// The JIT refused the PTX (a compiler bug: the PTX is checked by ptxas in CI).
    #[error("the CUDA JIT rejected the PTX: {0}")]
    Jit(String),
    /// What a launch would pass differs from the kernel's parameters (a bug of sdfc's):
    /// refused before launching.
    #[error("internal error: the CUDA kernel's parameters do not match the launch: {0}")]
    Arguments(#[from] ptx::Mismatch),
    /// The scene's uniforms do not fit the kernel's layout (a bug of sdfc's).
    #[error("internal error: the CUDA kernel's parameters do not match the launch: {0}")]
    Uniforms(#[from] sdfc_compiler::wgsl::Mismatch),
}

fn driver(during: &'static str) -> impl Fn(cudarc::driver::DriverError) -> Error {
    move |e| Error::Driver {
        during,
        message: e.to_string(),
    }
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
            None => Err(Error::Driver {
                during: "opening the device",
                message: format!(
                    "CUDA device {index} was not among those named before the driver started"
                ),
            }),
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
            let found = match restricted {
                true => format!("the driver found {count} of those named"),
                false => format!("the driver found {count}"),
            };
            return Err(Error::Driver {
                during: "opening the device",
                message: format!(
                    "there is no CUDA device {index} ({found}; `sdfc devices` lists them)"
                ),
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

    /// Compiles `ptx` for this device (or takes it from the cache) and loads `entry`; `cap`
    /// limits the registers of each thread (`None`: the JIT's choice; [`register_cap`]).
    pub fn load(&self, kernel: &ptx::Ptx, entry: &str, cap: Option<u32>) -> Result<Loaded, Error> {
        let start = Instant::now();
        let ptx = &kernel.text;
        let path = cache_path(ptx, &self.name, self.sm, cap);
        let (cubin, cached) = match path.as_ref().and_then(|p| std::fs::read(p).ok()) {
            Some(bytes) => (bytes, true),
            None => {
                let cubin = self.jit(ptx, cap)?;
                if let Some(p) = &path {
                    // The cache is an optimisation: failing to write it is not an error.
                    if let Some(dir) = p.parent() {
                        let _ = std::fs::create_dir_all(dir);
                    }
                    let _ = crate::image::write_atomic(p, &cubin);
                }
                (cubin, false)
            }
        };
        let module = self
            .ctx
            .load_module(cudarc::nvrtc::Ptx::from_binary(cubin))
            .map_err(driver("loading the module"))?;
        let function = module
            .load_function(entry)
            .map_err(driver("finding the kernel"))?;
        Ok(Loaded {
            function,
            params: kernel.params.clone(),
            load_time: start.elapsed(),
            cached,
        })
    }

    /// PTX to a cubin through the driver's linker (the JIT).
    fn jit(&self, ptx: &str, cap: Option<u32>) -> Result<Vec<u8>, Error> {
        self.ctx
            .bind_to_thread()
            .map_err(driver("binding the context"))?;
        let mut text = ptx.as_bytes().to_vec();
        text.push(0);
        let mut log = vec![0u8; 8192];
        let mut state: sys::CUlinkState = std::ptr::null_mut();
        let mut options = vec![
            sys::CUjit_option::CU_JIT_ERROR_LOG_BUFFER,
            sys::CUjit_option::CU_JIT_ERROR_LOG_BUFFER_SIZE_BYTES,
        ];
        let mut values = vec![
            log.as_mut_ptr() as *mut std::ffi::c_void,
            log.len() as *mut std::ffi::c_void,
        ];
        // A register cap trades spills for occupancy; the value is passed through to the JIT.
        if let Some(n) = cap {
            options.push(sys::CUjit_option::CU_JIT_MAX_REGISTERS);
            values.push(n as usize as *mut std::ffi::c_void);
        }
        let check = |r: sys::CUresult, during: &'static str, log: &[u8]| -> Result<(), Error> {
            if r == sys::CUresult::CUDA_SUCCESS {
                return Ok(());
            }
            let end = log.iter().position(|&b| b == 0).unwrap_or(log.len());
            let msg = String::from_utf8_lossy(&log[..end]).into_owned();
            Err(Error::Jit(format!("{during}: {r:?} {msg}")))
        };
        // SAFETY: the option arrays outlive the link state, which is destroyed below; the
        // PTX buffer is NUL-terminated and outlives cuLinkAddData; the cubin returned by
        // cuLinkComplete is copied before cuLinkDestroy frees it.
        unsafe {
            check(
                sys::cuLinkCreate_v2(
                    options.len() as u32,
                    options.as_mut_ptr(),
                    values.as_mut_ptr(),
                    &mut state,
                ),
                "cuLinkCreate",
                &log,
            )?;
            let added = sys::cuLinkAddData_v2(
                state,
                sys::CUjitInputType::CU_JIT_INPUT_PTX,
                text.as_mut_ptr() as *mut std::ffi::c_void,
                text.len(),
                c"sdfc.ptx".as_ptr(),
                0,
                std::ptr::null_mut(),
                std::ptr::null_mut(),
            );
            if let Err(e) = check(added, "cuLinkAddData", &log) {
                sys::cuLinkDestroy(state);
                return Err(e);
            }
            let mut cubin: *mut std::ffi::c_void = std::ptr::null_mut();
            let mut size = 0usize;
            let done = sys::cuLinkComplete(state, &mut cubin, &mut size);
            let out = check(done, "cuLinkComplete", &log)
                .map(|_| std::slice::from_raw_parts(cubin as *const u8, size).to_vec());
            sys::cuLinkDestroy(state);
            out
        }
    }

    /// The statistics' reduction, loaded (from the JIT cache, or compiled) when first asked.
    fn reducer(&self) -> Result<Arc<Loaded>, Error> {
        let mut kept = self.reducer.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(k) = kept.as_ref() {
            return Ok(k.clone());
        }
        let ptx = reduction::ptx(self.sm)
            .map_err(|e| Error::Jit(format!("the statistics' reduction: {e}")))?;
        let loaded = Arc::new(self.load(&ptx, reduction::ENTRY_POINT, None)?);
        *kept = Some(loaded.clone());
        Ok(loaded)
    }

    /// The kernel `loaded` on this device (workgroups of `workgroup`² threads), as a
    /// [`launch::Device`] the scheduler renders tiles on.
    pub fn kernel<'a>(&'a self, loaded: &'a Loaded, workgroup: u32) -> Kernel<'a> {
        Kernel {
            cuda: self,
            loaded,
            workgroup,
        }
    }
}

impl Kernel<'_> {
    /// The bytes of `src` read back through the device's kept page-locked buffer (allocated,
    /// or reallocated for another size, here).
    fn read_pinned(&self, src: &cudarc::driver::CudaView<'_, u8>) -> Result<Vec<u8>, Error> {
        let s = &self.cuda.stream;
        let kept = self.cuda.pinned.lock().ok().and_then(|mut p| p.take());
        let mut pinned = match kept.filter(|p| p.len() == src.len()) {
            Some(p) => p,
            // SAFETY: page-locked host memory, cached (no write-combining flag: the host reads
            // it); its bytes are not read before the copy below has written every one of them.
            None => unsafe { self.cuda.ctx.alloc_pinned_with_flags::<u8>(src.len(), 0) }
                .map_err(driver("allocating page-locked memory"))?,
        };
        s.memcpy_dtoh(src, &mut pinned)
            .map_err(driver("reading the pixels"))?;
        let bytes =
            super::to_vec_parallel(pinned.as_slice().map_err(driver("reading the pixels"))?);
        if let Ok(mut p) = self.cuda.pinned.lock() {
            *p = Some(pinned);
        }
        Ok(bytes)
    }
}

impl launch::Device for Kernel<'_> {
    type Frame = FrameBuffers;
    type Error = Error;

    fn describe(&self) -> String {
        self.cuda.describe()
    }

    fn prepare(&self, job: &Job) -> Result<FrameBuffers, Error> {
        let s = &self.cuda.stream;
        let pixels = job.width as usize * job.height as usize;
        check_launch(self.loaded, job.uniforms, pixels, STATS_WORDS, job.data)?;
        let table: Vec<u32> = job
            .tiles
            .iter()
            .flat_map(|t| [t.0, t.1, t.2, t.3])
            .collect();
        let kept = self.cuda.spare.lock().ok().and_then(|mut k| k.take());
        let fits = |f: &FrameBuffers| {
            f.image.len() == pixels * 4
                && f.uniforms.len() == job.uniforms.len()
                && f.tiles.len() == table.len()
                && f.data.as_ref().map(|d| d.len()) == job.data.map(|d| d.len())
        };
        if let Some(mut f) = kept.filter(fits) {
            // Every pixel of the tiles is written by the kernel: the buffers need no clearing.
            s.memcpy_htod(job.uniforms, &mut f.uniforms)
                .map_err(driver("uploading the scene"))?;
            s.memcpy_htod(&table, &mut f.tiles)
                .map_err(driver("uploading the tiles"))?;
            if let (Some(d), Some(bytes)) = (&mut f.data, job.data) {
                s.memcpy_htod(bytes, d)
                    .map_err(driver("uploading the scene data"))?;
            }
            f.events.clear();
            s.synchronize().map_err(driver("uploading the scene"))?;
            return Ok(f);
        }
        let uniforms = s
            .clone_htod(job.uniforms)
            .map_err(driver("uploading the scene"))?;
        let tiles = s
            .clone_htod(&table)
            .map_err(driver("uploading the tiles"))?;
        let image = s
            .alloc_zeros::<f32>(pixels * 4)
            .map_err(driver("allocating the image"))?;
        let stats = s
            .alloc_zeros::<u32>(pixels * STATS_WORDS as usize)
            .map_err(driver("allocating the statistics"))?;
        let finished = s
            .alloc_zeros::<u8>(pixels * 4)
            .map_err(driver("allocating the pixels"))?;
        let data = match job.data {
            Some(bytes) => Some(
                s.clone_htod(bytes)
                    .map_err(driver("uploading the scene data"))?,
            ),
            None => None,
        };
        s.synchronize().map_err(driver("uploading the scene"))?;
        Ok(FrameBuffers {
            uniforms,
            tiles,
            image,
            stats,
            data,
            pixels: finished,
            events: Vec::with_capacity(job.tiles.len()),
            reduction: None,
            readback: [(None, None), (None, None)],
        })
    }

    fn run(&self, f: &mut FrameBuffers, job: &Job, tiles: &[usize]) -> Result<(), Error> {
        self.submit(f, job, tiles)?;
        self.cuda
            .stream
            .synchronize()
            .map_err(driver("running the kernel"))
    }

    fn submit(&self, f: &mut FrameBuffers, job: &Job, tiles: &[usize]) -> Result<(), Error> {
        let s = &self.cuda.stream;
        let workgroup = self.workgroup;
        // Each launch is timed by its own pair of events, and the times are summed: the
        // same measure as the wgpu path's per-pass timestamps (gaps between launches excluded).
        let flags = Some(sys::CUevent_flags::CU_EVENT_DEFAULT);
        for &i in tiles {
            let t = job.tiles[i];
            let timed = if job.timed {
                let start = self
                    .cuda
                    .ctx
                    .new_event(flags)
                    .map_err(driver("creating an event"))?;
                let end = self
                    .cuda
                    .ctx
                    .new_event(flags)
                    .map_err(driver("creating an event"))?;
                Some((start, end))
            } else {
                None
            };
            let tile_view = f.tiles.slice(4 * i..4 * i + 4);
            let cfg = LaunchConfig {
                grid_dim: (t.2.div_ceil(workgroup), t.3.div_ceil(workgroup), 1),
                block_dim: (workgroup, workgroup, 1),
                shared_mem_bytes: 0,
            };
            let mut launch = s.launch_builder(&self.loaded.function);
            launch
                .arg(&f.uniforms)
                .arg(&tile_view)
                .arg(&mut f.image)
                .arg(&mut f.stats);
            if let Some(d) = &f.data {
                launch.arg(d);
            }
            launch.arg(&mut f.pixels);
            if let Some((start, _)) = &timed {
                start.record(s).map_err(driver("recording an event"))?;
            }
            // SAFETY: the kernel's parameters are its buffers in binding order, as the PTX back
            // end declares them: four, the scene data when the kernel has it, and the finished
            // pixels, each at least as large as its type (`check_launch` compared them with the
            // kernel's parameters in `prepare`); the image, statistics and pixels hold every
            // pixel the tiles cover.
            unsafe { launch.launch(cfg) }.map_err(driver("launching the kernel"))?;
            if let Some((start, end)) = timed {
                end.record(s).map_err(driver("recording an event"))?;
                f.events.push((start, end));
            }
        }
        Ok(())
    }

    /// The finished pixels of `range`, copied (on the stream, behind the launches) into
    /// page-locked buffer `slot`; the linear colours are read at [`launch::Device::collect`].
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
        let bytes = 4 * range.len();
        let (kept, at) = &mut f.readback[slot];
        let mut pinned = match kept.take().filter(|p| p.len() >= bytes) {
            Some(p) => p,
            // SAFETY: page-locked host memory, cached (the host reads it); its bytes are read
            // only after the copy below has written them (`collect` reads the copied prefix).
            None => unsafe { self.cuda.ctx.alloc_pinned_with_flags::<u8>(bytes, 0) }
                .map_err(driver("allocating page-locked memory"))?,
        };
        let s = &self.cuda.stream;
        // The band's bytes alone, into the buffer's start: a buffer kept from a longer band
        // (the last band is shorter) is longer, and the driver copies as many bytes as the
        // destination holds, past the end of the pixels. The copy into a plain slice records
        // no event of the buffer's: its own is recorded behind it.
        let host = pinned
            .as_mut_slice()
            .map_err(driver("reading the pixels"))?;
        s.memcpy_dtoh(
            &f.pixels.slice(4 * range.start..4 * range.end),
            &mut host[..bytes],
        )
        .map_err(driver("reading the pixels"))?;
        let copied = s
            .record_event(Some(sys::CUevent_flags::CU_EVENT_DISABLE_TIMING))
            .map_err(driver("reading the pixels"))?;
        *kept = Some(pinned);
        *at = Some((range, copied));
        Ok(())
    }

    fn collect(
        &self,
        f: &mut FrameBuffers,
        job: &Job,
        range: Range<usize>,
        slot: usize,
    ) -> Result<Pixels, Error> {
        let (kept, at) = &mut f.readback[slot];
        let copied = at.take().filter(|(r, _)| *r == range);
        let (Some(pinned), Some((_, copied))) = (kept.as_ref(), copied) else {
            return self.read(f, job, std::slice::from_ref(&range));
        };
        // Waits for the copy alone: the launches queued after it may still run.
        copied.synchronize().map_err(driver("reading the pixels"))?;
        let bytes = pinned.as_slice().map_err(driver("reading the pixels"))?;
        let rgba = super::to_vec_parallel(&bytes[..4 * range.len()]);
        Ok(Pixels {
            linear: Vec::new(),
            rgba,
            convert: Duration::ZERO,
        })
    }

    /// A band's finished pixels copied from the page-locked buffer straight into their
    /// place, the wait for the copy timed apart.
    fn collect_into(
        &self,
        f: &mut FrameBuffers,
        job: &Job,
        range: Range<usize>,
        slot: usize,
        place: launch::Place<'_>,
    ) -> Result<launch::Collected, Error> {
        let (kept, at) = &mut f.readback[slot];
        let started = at.as_ref().is_some_and(|(r, _)| *r == range);
        match (kept.as_ref(), at.take().filter(|_| started), place) {
            (Some(pinned), Some((_, copied)), launch::Place::Rgba(out)) => {
                let waiting = Instant::now();
                // Waits for the copy alone: the launches queued after it may still run.
                copied.synchronize().map_err(driver("reading the pixels"))?;
                let wait = waiting.elapsed();
                let bytes = pinned.as_slice().map_err(driver("reading the pixels"))?;
                super::copy_parallel(out, &bytes[..4 * range.len()]);
                Ok(launch::Collected {
                    wait,
                    convert: Duration::ZERO,
                })
            }
            (_, copied, place) => {
                // A read started for this band, collected through `collect`.
                f.readback[slot].1 = copied;
                launch::collect_copied(self, f, job, (range, slot), place)
            }
        }
    }

    fn read(
        &self,
        f: &mut FrameBuffers,
        job: &Job,
        ranges: &[Range<usize>],
    ) -> Result<Pixels, Error> {
        let s = &self.cuda.stream;
        let n: usize = ranges.iter().map(|r| r.end - r.start).sum();
        // The finished pixels (4 bytes each) or the linear colours (4 floats).
        let paged = job.finished && ranges.len() != 1;
        let mut rgba = vec![0u8; if paged { 4 * n } else { 0 }];
        let mut image = vec![0f32; if job.finished { 0 } else { 4 * n }];
        if job.finished && ranges.len() == 1 {
            // Through the kept page-locked buffer, then copied out.
            let r = &ranges[0];
            rgba = self.read_pinned(&f.pixels.slice(4 * r.start..4 * r.end))?;
        }
        let mut at = 0;
        for r in ranges {
            let len = r.end - r.start;
            if job.finished && ranges.len() == 1 {
                // Read above.
            } else if job.finished {
                s.memcpy_dtoh(
                    &f.pixels.slice(4 * r.start..4 * r.end),
                    &mut rgba[4 * at..4 * (at + len)],
                )
                .map_err(driver("reading the pixels"))?;
            } else {
                s.memcpy_dtoh(
                    &f.image.slice(4 * r.start..4 * r.end),
                    &mut image[4 * at..4 * (at + len)],
                )
                .map_err(driver("reading the image"))?;
            }
            at += len;
        }
        s.synchronize().map_err(driver("reading the image"))?;
        let convert = Instant::now();
        let linear = {
            use rayon::prelude::*;
            image
                .par_chunks_exact(4)
                .map(|c| [c[0], c[1], c[2]])
                .collect()
        };
        drop(image);
        Ok(Pixels {
            linear,
            rgba,
            convert: convert.elapsed(),
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
        let reducer = self.cuda.reducer()?;
        let s = &self.cuda.stream;
        let (first, second) = reduce::threads(job.pixels());
        let record = reduction::RECORD as usize;
        if f.reduction.is_none() {
            let partial = s
                .alloc_zeros::<u32>(first as usize * record)
                .map_err(driver("allocating the statistics' reduction"))?;
            let total = s
                .alloc_zeros::<u32>(second as usize * record)
                .map_err(driver("allocating the statistics' reduction"))?;
            f.reduction = Some((partial, total));
        }
        let Some((partial, total)) = f.reduction.as_mut() else {
            unreachable!("made above")
        };
        let words: Vec<u32> = queries.iter().flat_map(|q| q.words()).collect();
        let slots = s
            .clone_htod(&words)
            .map_err(driver("uploading the reduction's queries"))?;
        let n = reduction::QUERY_WORDS as usize;
        for (i, q) in queries.iter().enumerate() {
            let query = slots.slice(n * i..n * (i + 1));
            let cfg = LaunchConfig {
                grid_dim: (q.threads.div_ceil(reduction::WORKGROUP), 1, 1),
                block_dim: (reduction::WORKGROUP, 1, 1),
                shared_mem_bytes: 0,
            };
            let mut launch = s.launch_builder(&reducer.function);
            launch
                .arg(&query)
                .arg(&f.stats)
                .arg(&mut *partial)
                .arg(&mut *total);
            // SAFETY: the reduction's parameters are its four buffers in binding order (the
            // PTX back end's interface): a query of `QUERY_WORDS` words, the frame's
            // statistics (`STATS_WORDS` a pixel, every pixel a query names within the frame),
            // and the partial records and totals, a record of `RECORD` words for each thread
            // of the first and second stage (`reduce::threads`, which sized them).
            unsafe { launch.launch(cfg) }.map_err(driver("reducing the statistics"))?;
        }
        let totals = s
            .clone_dtoh(&*total)
            .map_err(driver("reading the statistics"))?;
        s.synchronize().map_err(driver("reducing the statistics"))?;
        Ok(Answer::of_totals(&totals, ask))
    }

    fn finish(&self, f: FrameBuffers, job: &Job) -> Result<Option<Duration>, Error> {
        let mut time = None;
        if job.timed {
            let mut ms = 0.0f64;
            for (start, end) in &f.events {
                ms += start.elapsed_ms(end).map_err(driver("reading the timer"))? as f64;
            }
            time = Some(Duration::from_secs_f64(ms / 1e3));
        }
        if let Ok(mut spare) = self.cuda.spare.lock() {
            *spare = Some(f);
        }
        Ok(time)
    }

    fn fault(&self, message: String) -> Error {
        Error::Driver {
            during: "running the kernel",
            message,
        }
    }
}

/// `Err` unless the buffers a launch passes are those `k`'s parameters declare: the uniform
/// (binding 0), a tile (1), the image (2) and statistics (3) of `pixels` pixels, `data` (4)
/// exactly when the kernel reads `scene_data`, and the finished pixels (5); each a device
/// address, each as large as its type.
fn check_launch(
    k: &Loaded,
    uniforms: &[u8],
    pixels: usize,
    stats_words: u32,
    data: Option<&[u8]>,
) -> Result<(), Error> {
    let address = std::mem::size_of::<sys::CUdeviceptr>() as u32;
    let arg = |binding, space, bytes: usize| Argument {
        group: 0,
        binding,
        space,
        bytes: bytes as u64,
        size: address,
    };
    let writable = Space::Storage { writable: true };
    let mut args = vec![
        arg(0, Space::Uniform, uniforms.len()),
        arg(1, Space::Uniform, 4 * std::mem::size_of::<u32>()),
        arg(2, writable, pixels * 4 * std::mem::size_of::<f32>()),
        arg(3, writable, pixels * stats_words as usize * 4),
    ];
    if let Some(d) = data {
        args.push(arg(4, Space::Storage { writable: false }, d.len()));
    }
    args.push(arg(5, writable, pixels * 4));
    ptx::check_arguments(&k.params, &args).map_err(Error::Arguments)
}

/// The register cap of a kernel that sphere traces. Its march loops over memory (the
/// instances' walk) and long arithmetic, and more warps resident on a multiprocessor hide
/// their latency better than the JIT's own choice of registers, which spends them on fewer
/// warps. Of the caps tried, 72 made the large marched kernels fastest; small ones lose a
/// little, and analytically traced kernels more, so they keep the JIT's choice. The JIT's
/// own count does not say which kernels gain, so the cap is one constant.
pub const MARCHED_REGISTERS: u32 = 72;

/// The register cap for the JIT of a kernel that sphere traces (`marched`) or traces
/// analytically: `$SDFC_CUDA_MAX_REGISTERS` when set (0: the JIT's choice), else
/// [`MARCHED_REGISTERS`] for a marched kernel and the JIT's choice for the other.
pub fn register_cap(marched: bool) -> Option<u32> {
    match std::env::var("SDFC_CUDA_MAX_REGISTERS") {
        Ok(v) => v.trim().parse().ok().filter(|&n| n > 0),
        Err(_) => marched.then_some(MARCHED_REGISTERS),
    }
}

/// Where the compiled module of `ptx` for a device is cached ([`super::cache_file`], in the
/// `cuda` cache directory). `None` when there is no home.
fn cache_path(ptx: &str, device: &str, sm: u32, cap: Option<u32>) -> Option<PathBuf> {
    super::cache_file(
        "cuda",
        &(ptx, device, sm, cap, env!("CARGO_PKG_VERSION")),
        "cubin",
    )
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
