//! Frames that stay on the GPU: on wgpu the viewer launches the scene's kernel through
//! `gpu::launch` into a frame kept on the device that presents the window
//! (`gpu::wgpu::ResidentFrame`, the launch's target); a second pass, the viewer's, adds each frame's colours
//! (linear light: the scene renders ungraded) to the samples accumulated so far and writes
//! their mean, graded by the scene's exposure and tone curve and sRGB-encoded, into a storage
//! texture that the window's render pass samples. Nothing crosses to the host per frame; the
//! accumulated samples are read back only when asked (a screenshot of the session's image,
//! and the mean steps per pixel that the statistics in the title show, a sum reduced on the
//! GPU to two words).

use super::grade::Grade;
use crate::gpu::launch::{self, Work};
use crate::gpu::wgpu::{compute_entry, storage, ResidentFrame};
use crate::gpu::Gpu;
use crate::image::Image;
use sdfc_compiler::{wgsl, Scene};
use std::sync::Arc;

/// The pass that accumulates a frame: binding 0 the frame's size, sample count, whether to
/// sum the steps (1; 2 sums them alone, accumulating nothing: the steps of the frame before,
/// asked for after it was rendered), 2^exposure and the tone curve (`Tonemap::index`) (a
/// storage buffer, not a uniform: lavapipe compiles a variant of a shader for
/// each value of a uniform that decides a branch, which the sample count would make one a
/// frame); 1 the kernel's colours (linear light); 2 the sums of the samples so far; 3 the
/// texture on show (the mean graded, sRGB bytes); 4 the kernel's per-pixel statistics (`STATS_WORDS` a pixel, the
/// first the marching steps); 5 the steps summed over the frame, as a 64-bit count in two
/// words (low, high).
const ACCUMULATE: &str = r#"
struct Frame {
    width: u32,
    height: u32,
    count: u32,
    steps: u32,
    scale: f32,
    curve: u32,
}

@group(0) @binding(0) var<storage, read> frame: Frame;
@group(0) @binding(1) var<storage, read> image: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> sum: array<vec4<f32>>;
@group(0) @binding(3) var shown: texture_storage_2d<rgba8unorm, write>;
@group(0) @binding(4) var<storage, read> stats: array<u32>;
@group(0) @binding(5) var<storage, read_write> steps: array<atomic<u32>, 2>;

var<workgroup> group_steps: atomic<u32>;

// The sRGB transfer function, as runtime/src/image.rs encodes (IEC 61966-2-1), rounded to the
// nearest of the 256 levels, so the texture holds the bytes a PNG of the image would.
fn encode(c: f32) -> f32 {
    var x = clamp(c, 0.0, 1.0);
    if !(x == x) {
        x = 0.0;
    }
    var s = 12.92 * x;
    if x > 0.0031308 {
        s = 1.055 * pow(x, 1.0 / 2.4) - 0.055;
    }
    return floor(s * 255.0 + 0.5) / 255.0;
}

// The mean's exposure and tone curve, as the kernel's `grade` (docs/rendering.md, "The look").
fn grade(c: vec3<f32>) -> vec3<f32> {
    let x = c * frame.scale;
    if frame.curve == 1u {
        let num = x * (FILMIC_A * x + FILMIC_B);
        let den = x * (FILMIC_C * x + FILMIC_D) + FILMIC_E;
        return clamp(num / den, vec3<f32>(0.0), vec3<f32>(1.0));
    }
    if frame.curve == 2u {
        return x / (vec3<f32>(1.0) + x);
    }
    return x;
}

@compute @workgroup_size(8, 8, 1)
fn accumulate(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    if gid.x < frame.width && gid.y < frame.height && frame.steps < 2u {
        let p = gid.y * frame.width + gid.x;
        // The first sample replaces the sums; each next one is added, in the order the host
        // added them when it accumulated (the same f32 sums).
        var s = image[p];
        if frame.count > 1u {
            s = sum[p] + image[p];
        }
        sum[p] = s;
        let mean = grade(s.rgb * (1.0 / f32(frame.count)));
        textureStore(shown, gid.xy, vec4<f32>(encode(mean.r), encode(mean.g), encode(mean.b), 1.0));
    }
    if gid.x < frame.width && gid.y < frame.height && frame.steps >= 1u {
        atomicAdd(&group_steps, stats[(gid.y * frame.width + gid.x) * STATS_WORDSu]);
    }
    workgroupBarrier();
    if frame.steps >= 1u && local == 0u {
        let v = atomicLoad(&group_steps);
        let old = atomicAdd(&steps[0], v);
        if old + v < old {
            atomicAdd(&steps[1], 1u);
        }
    }
}
"#;

/// The side of the accumulating pass's workgroups.
const GROUP: u32 = 8;

/// The viewer's frames on a wgpu device: the frame the kernel renders into, kept on the
/// device, and the accumulating pass with its buffers at the current size.
pub struct Resident {
    gpu: Arc<Gpu>,
    accumulate: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    /// The launches' target: the kernel's buffers, kept on the device.
    frame: ResidentFrame,
    target: Option<Target>,
    /// Textures made so far (a new texture's number tells a presenter to bind it).
    textures: u64,
}

impl std::fmt::Debug for Resident {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Resident")
            .field("size", &self.target.as_ref().map(|t| (t.width, t.height)))
            .finish_non_exhaustive()
    }
}

/// The accumulating pass's buffers for frames of one size (the sums may be larger, from a
/// larger size).
struct Target {
    width: u32,
    height: u32,
    /// Pixels the sums buffer holds.
    capacity: u64,
    sum: wgpu::Buffer,
    frame: wgpu::Buffer,
    steps: wgpu::Buffer,
    texture: wgpu::Texture,
    /// The texture's number ([`Resident::textures`]).
    number: u64,
    /// The accumulating pass's bindings (they change with the texture and buffers).
    bind: wgpu::BindGroup,
    /// Samples accumulated in `sum`.
    count: u32,
    /// The grade of their mean.
    grade: Grade,
}

/// The bytes of the accumulating pass's `Frame`.
const FRAME_BYTES: u64 = 24;

impl Target {
    /// The accumulating pass's `Frame`: `steps` 0 (accumulate), 1 (and sum the steps) or 2
    /// (sum the steps alone).
    fn frame_words(&self, steps: u32) -> Vec<u8> {
        let g = &self.grade;
        let curve = g.tonemap.index();
        let mut w = words(&[self.width, self.height, self.count, steps]);
        w.extend(g.scale().to_le_bytes());
        w.extend(curve.to_le_bytes());
        w
    }
}

/// One frame rendered on the device.
#[derive(Debug, Clone, Copy)]
pub struct Rendered {
    /// Samples accumulated, this frame's included.
    pub count: u32,
    /// Mean marching steps per pixel of this frame, when they were asked for.
    pub steps: Option<f64>,
}

/// Why the viewer's pass on the device failed.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// wgpu refused the viewer's pass (which one) or ran out of memory in it.
    #[error("the viewer's {0}: {1}")]
    Pass(&'static str, wgpu::Error),
    /// The scene's uniforms do not fit the kernel: an internal error.
    #[error("internal error: the scene uniform does not fit the kernel: {0}")]
    Layout(#[from] wgsl::Mismatch),
    /// The device: a pipeline that does not compile, or a wait that failed.
    #[error(transparent)]
    Gpu(#[from] crate::gpu::wgpu::Error),
    /// A frame's buffers were not made.
    #[error("no frame buffers")]
    NoBuffers,
    /// The mapping of a readback never answered.
    #[error("reading the frame back: {0}")]
    Unanswered(#[from] std::sync::mpsc::RecvError),
    /// A readback buffer could not be mapped.
    #[error("reading the frame back: {0}")]
    Readback(Box<dyn std::error::Error + Send + Sync>),
}

impl Resident {
    /// The accumulating pass on `gpu`'s device.
    pub fn new(gpu: Arc<Gpu>) -> Result<Resident, Error> {
        let device = gpu.device();
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let mut source = ACCUMULATE.replace("STATS_WORDS", &wgsl::STATS_WORDS.to_string());
        for (k, c) in ["FILMIC_A", "FILMIC_B", "FILMIC_C", "FILMIC_D", "FILMIC_E"]
            .into_iter()
            .zip(sdfc_compiler::look::FILMIC)
        {
            source = source.replace(k, &format!("{c:?}"));
        }
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("sdfc view accumulate"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let (layout, pipeline_layout) = gpu.layouts(
            ("sdfc view accumulate", "sdfc view accumulate"),
            &[
                compute_entry(0, storage(true, false)),
                compute_entry(1, storage(true, false)),
                compute_entry(2, storage(false, false)),
                compute_entry(
                    3,
                    wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: wgpu::TextureFormat::Rgba8Unorm,
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                ),
                compute_entry(4, storage(true, false)),
                compute_entry(5, storage(false, false)),
            ],
        );
        let accumulate = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("sdfc view accumulate"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("accumulate"),
            compilation_options: Default::default(),
            cache: None,
        });
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::Pass("accumulating pass", e));
        }
        Ok(Resident {
            gpu,
            accumulate,
            layout,
            frame: ResidentFrame::default(),
            target: None,
            textures: 0,
        })
    }

    /// Renders one frame of `scene` (its settings' size, one sample a pixel, ungraded: linear
    /// light) with `kernel` through `gpu::launch`, into the frame kept on the device, and adds
    /// it to the samples accumulated: the first of them when `first` (or the size changed),
    /// else the next; the texture on show is their mean graded by `grade`. `data_key` names
    /// the kernel's scene data: it is uploaded only when the key changes. With `steps`, the
    /// frame's mean steps per pixel are read back (two words). Returns when the device has
    /// finished the frame.
    pub fn render(
        &mut self,
        (kernel, lipschitz): (&wgsl::Kernel, f64),
        (scene, grade): (&Scene, Grade),
        data_key: u64,
        first: bool,
        steps: bool,
    ) -> Result<Rendered, Error> {
        let (width, height) = (scene.settings.width.max(1), scene.settings.height.max(1));
        let uniforms = wgsl::uniforms(&kernel.contract.uniform, scene, lipschitz)?;
        let tiles = launch::tiling(width, height, crate::gpu::TILE, 1);
        let work = Work {
            uniforms: &uniforms,
            data: kernel.data.as_deref(),
            width,
            height,
            tiles: &tiles,
            timed: false,
            statistics: false,
            target: launch::Target::Resident,
        };
        let device = self.gpu.device().clone();
        let queue = self.gpu.queue().clone();
        let scope = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
        if self.frame.fit(&self.gpu, &work, data_key) || self.target.is_none() {
            self.target = Some(self.target_for(width, height)?);
        }
        let kernel = self
            .gpu
            .kernel(&kernel.source, wgsl::ENTRY_POINT, wgsl::WORKGROUP);
        let faults = launch::Faults::default();
        launch::render_one(
            &kernel.into_resident(&self.frame),
            &work,
            &faults,
            &mut |_| {},
        )?;
        let Some(t) = self.target.as_mut() else {
            return Err(Error::NoBuffers);
        };
        if first {
            t.count = 0;
        }
        t.count += 1;
        t.grade = grade;
        queue.write_buffer(&t.frame, 0, &t.frame_words(steps as u32));
        let mut encoder = device.create_command_encoder(&Default::default());
        if steps {
            encoder.clear_buffer(&t.steps, 0, None);
        }
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.accumulate);
            pass.set_bind_group(0, &t.bind, &[]);
            pass.dispatch_workgroups(width.div_ceil(GROUP), height.div_ceil(GROUP), 1);
        }
        let staging = steps.then(|| steps_staging(&device, &mut encoder, &t.steps));
        queue.submit([encoder.finish()]);
        let count = t.count;
        if let Some(e) = pollster::block_on(validation.pop()) {
            return Err(Error::Pass("frame", e));
        }
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::Pass("frame (out of memory)", e));
        }
        let steps = match staging {
            Some(staging) => Some(self.mean_steps(&staging, width, height)?),
            None => {
                self.gpu.wait()?;
                None
            }
        };
        Ok(Rendered { count, steps })
    }

    /// The mean marching steps per pixel of the last frame, summed on the device now (the
    /// statistics asked for after it was rendered); `None` before the first frame.
    pub fn last_steps(&mut self) -> Result<Option<f64>, Error> {
        let Some(t) = self.target.as_ref().filter(|t| t.count > 0) else {
            return Ok(None);
        };
        let (device, queue) = (self.gpu.device(), self.gpu.queue());
        let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
        queue.write_buffer(&t.frame, 0, &t.frame_words(2));
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.clear_buffer(&t.steps, 0, None);
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.accumulate);
            pass.set_bind_group(0, &t.bind, &[]);
            pass.dispatch_workgroups(t.width.div_ceil(GROUP), t.height.div_ceil(GROUP), 1);
        }
        let staging = steps_staging(device, &mut encoder, &t.steps);
        queue.submit([encoder.finish()]);
        if let Some(e) = pollster::block_on(validation.pop()) {
            return Err(Error::Pass("steps", e));
        }
        self.mean_steps(&staging, t.width, t.height).map(Some)
    }

    /// The steps summed into `staging` (two words, low and high), per pixel of a
    /// `width`×`height` frame.
    fn mean_steps(&self, staging: &wgpu::Buffer, width: u32, height: u32) -> Result<f64, Error> {
        let bytes = self.map(staging)?;
        let word =
            |i: usize| u32::from_le_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
        let sum = (word(4) as u64) << 32 | word(0) as u64;
        Ok(sum as f64 / (width as f64 * height as f64))
    }

    /// The accumulating pass's buffers and texture for frames of `width`×`height`, bound to
    /// the kernel's colours and statistics in the frame kept on the device (fitted to that
    /// size); the sums of the target before are kept when they are large enough. Its samples
    /// start again.
    fn target_for(&mut self, width: u32, height: u32) -> Result<Target, Error> {
        let (Some(image), Some(stats)) = (self.frame.image(), self.frame.stats()) else {
            return Err(Error::NoBuffers);
        };
        let device = self.gpu.device();
        let pixels = width as u64 * height as u64;
        let buffer = |label, size: u64, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size.max(16),
                usage,
                mapped_at_creation: false,
            })
        };
        use wgpu::BufferUsages as U;
        let old = self.target.take().map(|t| (t.sum, t.capacity));
        let capacity = old.as_ref().map_or(0, |(_, c)| *c).max(pixels);
        let sum = match old {
            Some((sum, c)) if c >= pixels => sum,
            _ => buffer("sdfc view sums", capacity * 16, U::STORAGE | U::COPY_SRC),
        };
        self.textures += 1;
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("sdfc view shown"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[wgpu::TextureFormat::Rgba8UnormSrgb],
        });
        let frame = buffer("sdfc view frame", FRAME_BYTES, U::STORAGE | U::COPY_DST);
        let steps = buffer("sdfc view steps", 8, U::STORAGE | U::COPY_SRC | U::COPY_DST);
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            format: Some(wgpu::TextureFormat::Rgba8Unorm),
            ..Default::default()
        });
        let entry = |binding, resource| wgpu::BindGroupEntry { binding, resource };
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sdfc view accumulate"),
            layout: &self.layout,
            entries: &[
                entry(0, frame.as_entire_binding()),
                entry(1, image.as_entire_binding()),
                entry(2, sum.as_entire_binding()),
                entry(3, wgpu::BindingResource::TextureView(&view)),
                entry(4, stats.as_entire_binding()),
                entry(5, steps.as_entire_binding()),
            ],
        });
        Ok(Target {
            width,
            height,
            capacity,
            sum,
            frame,
            steps,
            texture,
            number: self.textures,
            bind,
            count: 0,
            grade: Grade::default(),
        })
    }

    /// The texture on show (the mean of the samples, sRGB bytes; an `Rgba8Unorm` texture
    /// that may be viewed as `Rgba8UnormSrgb`) and its number, which changes when the
    /// texture does; `None` before the first frame.
    pub fn texture(&self) -> Option<(&wgpu::Texture, u64)> {
        self.target
            .as_ref()
            .filter(|t| t.count > 0)
            .map(|t| (&t.texture, t.number))
    }

    /// The samples accumulated, read back: their mean graded ([`Grade::apply`]), as a linear
    /// image (the host's own accumulation's, value for value). `None` before the first frame.
    pub fn image(&self) -> Result<Option<Image>, Error> {
        let Some(t) = self.target.as_ref().filter(|t| t.count > 0) else {
            return Ok(None);
        };
        let device = self.gpu.device();
        let size = t.width as u64 * t.height as u64 * 16;
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sdfc view readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&t.sum, 0, &staging, 0, size);
        self.gpu.queue().submit([encoder.finish()]);
        let bytes = self.map(&staging)?;
        let inv = 1.0 / t.count as f32;
        let f = |b: &[u8]| f32::from_le_bytes([b[0], b[1], b[2], b[3]]) * inv;
        Ok(Some(Image {
            width: t.width,
            height: t.height,
            linear: bytes
                .chunks_exact(16)
                .map(|c| t.grade.apply([f(&c[0..4]), f(&c[4..8]), f(&c[8..12])]))
                .collect(),
        }))
    }

    /// The bytes of `staging` (a mappable buffer whose copy was submitted), once the device
    /// has written them.
    fn map(&self, staging: &wgpu::Buffer) -> Result<Vec<u8>, Error> {
        let slice = staging.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.gpu.wait()?;
        rx.recv()?.map_err(|e| Error::Readback(Box::new(e)))?;
        let bytes = slice
            .get_mapped_range()
            .map_err(|e| Error::Readback(Box::new(e)))?
            .to_vec();
        staging.unmap();
        Ok(bytes)
    }
}

/// A mappable copy of the steps' two words, its copy recorded in `encoder`.
fn steps_staging(
    device: &wgpu::Device,
    encoder: &mut wgpu::CommandEncoder,
    steps: &wgpu::Buffer,
) -> wgpu::Buffer {
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("sdfc view steps"),
        size: 8,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    encoder.copy_buffer_to_buffer(steps, 0, &staging, 0, 8);
    staging
}

/// What a kernel's first frame will read: its scene uniform and its first tile.
#[derive(Debug, Clone)]
pub struct FirstFrame {
    pub uniforms: Vec<u8>,
    pub tile: crate::gpu::launch::Tile,
}

impl FirstFrame {
    /// The first frame of `scene` (its camera and size set as that frame's) through `kernel`.
    pub fn of((kernel, lipschitz): (&wgsl::Kernel, f64), scene: &Scene) -> Option<FirstFrame> {
        let (w, h) = (scene.settings.width, scene.settings.height);
        let tile = *crate::gpu::launch::tiling(w, h, crate::gpu::TILE, 1).first()?;
        let uniforms = wgsl::uniforms(&kernel.contract.uniform, scene, lipschitz).ok()?;
        Some(FirstFrame { uniforms, tile })
    }
}

fn words(w: &[u32]) -> Vec<u8> {
    w.iter().flat_map(|x| x.to_le_bytes()).collect()
}
