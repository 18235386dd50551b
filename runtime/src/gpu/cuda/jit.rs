//! A kernel's PTX loaded through the driver's JIT on a [`Cuda`] device, the compiled module
//! cached on disk (keyed by a hash of the PTX and the device), the statistics' reduction, and
//! a [`Kernel`] ready to render.

#![allow(unsafe_code)] // The driver API is C: its calls are wrapped here, each with its reason.

use super::{driver, Cuda, Error, Kernel, Loaded};
use cudarc::driver::sys;
use sdfc_compiler::{
    ptx::{self},
    wgsl::reduce as reduction,
};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

impl Cuda {
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
            let log = String::from_utf8_lossy(&log[..end]).into_owned();
            Err(Error::Jit {
                during,
                result: r,
                log,
            })
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
    pub(super) fn reducer(&self) -> Result<Arc<Loaded>, Error> {
        let mut kept = self.reducer.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(k) = kept.as_ref() {
            return Ok(k.clone());
        }
        let ptx = reduction::ptx(self.sm).map_err(Error::Reduction)?;
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

/// Where the compiled module of `ptx` for a device is cached ([`super::super::cache_file`], in the
/// `cuda` cache directory). `None` when there is no home.
fn cache_path(ptx: &str, device: &str, sm: u32, cap: Option<u32>) -> Option<PathBuf> {
    super::super::cache_file(
        "cuda",
        &(ptx, device, sm, cap, env!("CARGO_PKG_VERSION")),
        "cubin",
    )
}
