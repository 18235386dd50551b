//! The kernels' compute pipelines on a [`Gpu`]: compiled once per kernel text and kept, the
//! driver's pipeline cache stored on disk between processes, and a [`Kernel`] ready to render.

use super::buffers::{compute_entry, storage, words};
use super::{
    Buffers, DriverCache, Error, Gpu, Kernel, Pipeline, PipelineTime, PIPELINES_KEPT, TILE_STRIDE,
};
use crate::gpu::launch;
use sdfc_compiler::wgsl::STATS_WORDS;
use std::collections::HashMap;
use std::sync::Arc;
use std::time::Instant;

impl Gpu {
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
    pub(super) fn cached_pipeline(
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
            return Err(Error::Pipeline(e));
        }
        let pipeline = Arc::new((pipeline, layout));
        let mut cache = self.lock_pipelines();
        if cache.len() >= PIPELINES_KEPT {
            cache.clear();
        }
        cache.insert(key, pipeline.clone());
        Ok((pipeline, driver))
    }

    /// Runs the pipeline of `wgsl` (entry point `entry`, with the scene-data binding when
    /// `data`; compiled now or found among those compiled) once, on one workgroup of a tile
    /// (of no pixels: a tile of size 0, every thread returning at once, unless `first` gives
    /// the uniforms and first tile of the frame to come), so that a driver that compiles a
    /// pipeline only at its first dispatch does so here, on the thread that compiles it, and
    /// not in the first frame. Lavapipe compiles then, and again for each new value of a
    /// uniform that decides a loop or a branch: the first frame's uniforms make its variant
    /// the one compiled. No frame is rendered: the buffers hold one workgroup's pixels.
    pub fn warm(
        &self,
        (wgsl, entry, data): (&str, &str, bool),
        first: Option<(&[u8], launch::Tile)>,
    ) -> Result<(), Error> {
        let (pipeline, _) = self.cached_pipeline(wgsl, entry, data)?;
        let buffer = |size, usage| self.buffer("sdfc warm", size, usage);
        use wgpu::BufferUsages as U;
        // A uniform as large as one may be bound (the kernel's is at most that), zeros: a
        // frame of 0×0 pixels and no samples.
        let limit = self
            .device
            .limits()
            .max_uniform_buffer_binding_size
            .min(1 << 16);
        // The pixels of one workgroup: the first rows of the frame.
        let width = first.map_or(1, |(_, t)| t.2.max(1)) as u64;
        let pixels = width * sdfc_compiler::wgsl::WORKGROUP as u64;
        let b = Buffers {
            uniforms: buffer(limit, U::UNIFORM | U::COPY_DST),
            data: data.then(|| buffer(16, U::STORAGE)),
            tile: buffer(TILE_STRIDE as u64, U::UNIFORM | U::COPY_DST),
            image: buffer(pixels * 16, U::STORAGE),
            pixels: buffer(pixels * 4, U::STORAGE),
            stats: buffer(pixels * 4 * STATS_WORDS as u64, U::STORAGE),
            reduction: None,
            readback: [None, None],
        };
        if let Some((uniforms, t)) = first {
            let n = (uniforms.len() as u64).min(limit) as usize;
            self.queue.write_buffer(&b.uniforms, 0, &uniforms[..n]);
            self.queue
                .write_buffer(&b.tile, 0, &words(&[t.0, t.1, t.2, t.3]));
        }
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let bind = self.bind_group(&pipeline.1, &b);
        let mut encoder = self.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline.0);
            pass.set_bind_group(0, &bind, &[0]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        self.queue.submit([encoder.finish()]);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::Pipeline(e));
        }
        self.wait()
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
    /// ([`crate::gpu::cache_file`], keyed like the CUDA cache by everything the compiled code
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
        crate::gpu::cache_file("wgpu", &key, "pipeline")
    }

    /// The kernel `wgsl` (entry point `entry`, workgroups of `workgroup`² threads) on this
    /// device, as a [`launch::Device`] the scheduler renders tiles on.
    pub fn kernel<'a>(&'a self, wgsl: &'a str, entry: &'a str, workgroup: u32) -> Kernel<'a> {
        Kernel {
            gpu: self,
            wgsl,
            entry,
            workgroup,
            resident: None,
        }
    }

    /// The pipeline and its bind group layout: binding 0 the scene uniform, 1 the tile table
    /// (a uniform at a dynamic offset), 2 the image, 3 the statistics and 5 the finished
    /// pixels (storage), and 4 the scene data (read-only storage) when the kernel has it. The driver is given the
    /// pipeline cache data an earlier process stored for this kernel on this device, or else
    /// what it produces is stored ([`Gpu::driver_cache_path`]).
    pub(super) fn pipeline(
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
        let uniform = |dynamic| wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: dynamic,
            min_binding_size: None,
        };
        let mut entries = vec![
            compute_entry(0, uniform(false)),
            compute_entry(1, uniform(true)),
            compute_entry(2, storage(false, false)),
            compute_entry(3, storage(false, false)),
            compute_entry(5, storage(false, false)),
        ];
        if data {
            entries.push(compute_entry(4, storage(true, false)));
        }
        let (layout, pipeline_layout) = self.layouts(("sdfc bindings", "sdfc layout"), &entries);
        let (pipeline, driver) = self.cached_compute(
            (wgsl, entry_point, data),
            "sdfc render",
            &pipeline_layout,
            &module,
        );
        (pipeline, layout, driver)
    }

    /// A bind group layout of `entries` and the layout of a pipeline of that one group, with
    /// the labels `labels`.
    pub(crate) fn layouts(
        &self,
        (group, pipeline): (&str, &str),
        entries: &[wgpu::BindGroupLayoutEntry],
    ) -> (wgpu::BindGroupLayout, wgpu::PipelineLayout) {
        let layout = self
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(group),
                entries,
            });
        let pipeline_layout = self
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(pipeline),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
        (layout, pipeline_layout)
    }

    /// The compute pipeline of `module`'s entry point `entry` (of the text `wgsl`, with the
    /// scene-data binding when `data`: the key of [`Gpu::driver_cache_path`]) laid out as
    /// `layout`, the driver given the pipeline cache data an earlier process stored for it on
    /// this device, or else what it produces stored.
    pub(super) fn cached_compute(
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
}
