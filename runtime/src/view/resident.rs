//! Frames that stay on the GPU: on wgpu the viewer dispatches the scene's kernel into buffers
//! of its own on the device that presents the window; a second pass adds each frame's colours
//! (linear light: the scene renders ungraded) to the samples accumulated so far and writes
//! their mean, graded by the scene's exposure and tone curve and sRGB-encoded, into a storage
//! texture that the window's render pass samples. Nothing crosses to the host per frame; the
//! accumulated samples are read back only when asked (a screenshot of the session's image,
//! and the mean steps per pixel that the statistics in the title show, a sum reduced on the
//! GPU to two words).

use super::grade::Grade;
use crate::gpu::wgpu::{Pipeline, TILE_STRIDE};
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

/// The viewer's frames on a wgpu device: the accumulating pass and the buffers of the frames
/// at the current size.
pub struct Resident {
    gpu: Arc<Gpu>,
    accumulate: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    target: Option<Target>,
    /// What the scene-data buffer holds: the key its writer gave ([`Resident::render`]).
    data_key: Option<(u64, bool)>,
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

/// The buffers of frames of one size (the pixel buffers may be larger, from a larger size).
struct Target {
    width: u32,
    height: u32,
    /// Pixels the image, statistics and sums buffers hold.
    capacity: u64,
    uniforms: wgpu::Buffer,
    data: Option<wgpu::Buffer>,
    /// The tiles (one dispatch each) and their table, an entry every [`TILE_STRIDE`] bytes.
    tiles: Vec<crate::gpu::launch::Tile>,
    tile_table: wgpu::Buffer,
    image: wgpu::Buffer,
    stats: wgpu::Buffer,
    /// The kernel's finished pixels (binding 5), which the viewer does not read: it
    /// accumulates the linear image.
    pixels: wgpu::Buffer,
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
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty,
            count: None,
        };
        let storage = |read_only| wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sdfc view accumulate"),
            entries: &[
                entry(0, storage(true)),
                entry(1, storage(true)),
                entry(2, storage(false)),
                entry(
                    3,
                    wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: wgpu::TextureFormat::Rgba8Unorm,
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                ),
                entry(4, storage(true)),
                entry(5, storage(false)),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("sdfc view accumulate"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
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
            target: None,
            data_key: None,
            textures: 0,
        })
    }

    /// Renders one frame of `scene` (its settings' size, one sample a pixel, ungraded: linear
    /// light) with `kernel` (compiled on this device: [`Gpu::compute_pipeline`]) and adds it
    /// to the samples accumulated: the first of them when `first` (or the size changed), else
    /// the next; the texture on show is their mean graded by `grade`.
    /// `data_key` names the kernel's scene data: it is uploaded only when the key changes.
    /// With `steps`, the frame's mean steps per pixel are read back (two words). Returns when
    /// the device has finished the frame.
    pub fn render(
        &mut self,
        (kernel, lipschitz): (&wgsl::Kernel, f64),
        (scene, grade): (&Scene, Grade),
        data_key: (u64, bool),
        first: bool,
        steps: bool,
    ) -> Result<Rendered, Error> {
        let (width, height) = (scene.settings.width.max(1), scene.settings.height.max(1));
        let uniforms = wgsl::uniforms(&kernel.contract.uniform, scene, lipschitz)?;
        let data = kernel.data.as_deref();
        let pipeline =
            self.gpu
                .compute_pipeline(&kernel.source, wgsl::ENTRY_POINT, data.is_some())?;
        let device = self.gpu.device().clone();
        let queue = self.gpu.queue().clone();
        let scope = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
        self.fit(
            width,
            height,
            uniforms.len() as u64,
            data.map(|d| d.len() as u64),
        );
        let Some(t) = self.target.as_mut() else {
            return Err(Error::NoBuffers);
        };
        if first {
            t.count = 0;
        }
        t.count += 1;
        queue.write_buffer(&t.uniforms, 0, &uniforms);
        if let (Some(buffer), Some(bytes)) = (&t.data, data) {
            if self.data_key != Some(data_key) {
                queue.write_buffer(buffer, 0, bytes);
                self.data_key = Some(data_key);
            }
        }
        t.grade = grade;
        queue.write_buffer(&t.frame, 0, &t.frame_words(steps as u32));
        let kernel_bind = kernel_bindings(
            &device,
            &pipeline,
            [&t.uniforms, &t.tile_table, &t.image, &t.stats, &t.pixels],
            t.data.as_ref(),
        );
        let mut encoder = device.create_command_encoder(&Default::default());
        if steps {
            encoder.clear_buffer(&t.steps, 0, None);
        }
        for (i, tile) in (0..).zip(&t.tiles) {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline.0);
            pass.set_bind_group(0, &kernel_bind, &[i * TILE_STRIDE]);
            pass.dispatch_workgroups(
                tile.2.div_ceil(wgsl::WORKGROUP),
                tile.3.div_ceil(wgsl::WORKGROUP),
                1,
            );
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

    /// Makes the buffers and texture fit frames of `width`×`height` with a uniform of
    /// `uniform` bytes and scene data of `data` bytes; a new size starts the samples again.
    fn fit(&mut self, width: u32, height: u32, uniform: u64, data: Option<u64>) {
        let device = self.gpu.device();
        let pixels = width as u64 * height as u64;
        let tiles = crate::gpu::launch::tiling(width, height, crate::gpu::TILE, 1);
        let buffer = |label, size: u64, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size.max(16),
                usage,
                mapped_at_creation: false,
            })
        };
        use wgpu::BufferUsages as U;
        let same_size = self
            .target
            .as_ref()
            .is_some_and(|t| (t.width, t.height) == (width, height));
        if !same_size {
            let old = self.target.take();
            let capacity = old.as_ref().map_or(0, |t| t.capacity).max(pixels);
            let (image, stats, finished, sum) = match old {
                Some(t) if t.capacity >= pixels => (t.image, t.stats, t.pixels, t.sum),
                _ => (
                    buffer("sdfc view image", capacity * 16, U::STORAGE),
                    buffer(
                        "sdfc view stats",
                        capacity * 4 * wgsl::STATS_WORDS as u64,
                        U::STORAGE,
                    ),
                    buffer("sdfc view pixels", capacity * 4, U::STORAGE),
                    buffer("sdfc view sums", capacity * 16, U::STORAGE | U::COPY_SRC),
                ),
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
            let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("sdfc view accumulate"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: frame.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: image.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: sum.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 3,
                        resource: wgpu::BindingResource::TextureView(&view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 4,
                        resource: stats.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 5,
                        resource: steps.as_entire_binding(),
                    },
                ],
            });
            let table: Vec<u8> = tiles
                .iter()
                .flat_map(|t| {
                    let mut entry = words(&[t.0, t.1, t.2, t.3]);
                    entry.resize(TILE_STRIDE as usize, 0);
                    entry
                })
                .collect();
            let tile_table = buffer(
                "sdfc view tiles",
                table.len() as u64,
                U::UNIFORM | U::COPY_DST,
            );
            self.gpu.queue().write_buffer(&tile_table, 0, &table);
            self.target = Some(Target {
                width,
                height,
                capacity,
                uniforms: buffer("sdfc view scene", uniform, U::UNIFORM | U::COPY_DST),
                data: data.map(|n| buffer("sdfc view scene data", n, U::STORAGE | U::COPY_DST)),
                tiles,
                tile_table,
                image,
                stats,
                pixels: finished,
                sum,
                frame,
                steps,
                texture,
                number: self.textures,
                bind,
                count: 0,
                grade: Grade::default(),
            });
            self.data_key = None;
        }
        let Some(t) = self.target.as_mut() else {
            return;
        };
        if t.uniforms.size() != uniform.max(16) {
            t.uniforms = buffer("sdfc view scene", uniform, U::UNIFORM | U::COPY_DST);
        }
        if t.data.as_ref().map(|b| b.size()) != data.map(|n| n.max(16)) {
            t.data = data.map(|n| buffer("sdfc view scene data", n, U::STORAGE | U::COPY_DST));
            self.data_key = None;
        }
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

/// The bindings of the scene's kernel ([`Gpu::compute_pipeline`]'s layout): the scene
/// uniform, the tile table (16 bytes at a dynamic offset), the image, the statistics and the
/// finished pixels, and the scene data when the kernel reads it.
fn kernel_bindings(
    device: &wgpu::Device,
    pipeline: &Pipeline,
    [uniforms, tiles, image, stats, pixels]: [&wgpu::Buffer; 5],
    data: Option<&wgpu::Buffer>,
) -> wgpu::BindGroup {
    let mut entries = vec![
        wgpu::BindGroupEntry {
            binding: 0,
            resource: uniforms.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 1,
            resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: tiles,
                offset: 0,
                size: std::num::NonZeroU64::new(16),
            }),
        },
        wgpu::BindGroupEntry {
            binding: 2,
            resource: image.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 3,
            resource: stats.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 5,
            resource: pixels.as_entire_binding(),
        },
    ];
    if let Some(data) = data {
        entries.push(wgpu::BindGroupEntry {
            binding: 4,
            resource: data.as_entire_binding(),
        });
    }
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("sdfc view kernel"),
        layout: &pipeline.1,
        entries: &entries,
    })
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

/// Runs a compiled kernel once, on one workgroup of the first tile of the frame `first` (or
/// of no pixels: a tile of size 0, every thread returning at once), so that a driver that
/// compiles a pipeline only at its first dispatch does so here, on the thread that compiles
/// it, and not in the first frame on the window's thread. Lavapipe compiles then, and again
/// for each new value of a uniform that decides a loop or a branch: the first frame's
/// uniforms make its variant the one compiled.
pub fn warm(
    gpu: &Gpu,
    wgsl_text: &str,
    data: bool,
    first: Option<&FirstFrame>,
) -> Result<(), Error> {
    let pipeline = gpu.compute_pipeline(wgsl_text, wgsl::ENTRY_POINT, data)?;
    let device = gpu.device();
    let buffer = |size: u64, usage| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sdfc view warm"),
            size,
            usage,
            mapped_at_creation: false,
        })
    };
    use wgpu::BufferUsages as U;
    // A uniform as large as one may be bound (the kernel's is at most that), zeros: a frame
    // of 0×0 pixels and no samples.
    let limit = device.limits().max_uniform_buffer_binding_size.min(1 << 16);
    let uniforms = buffer(limit, U::UNIFORM | U::COPY_DST);
    let tiles = buffer(TILE_STRIDE as u64, U::UNIFORM | U::COPY_DST);
    // The pixels of one workgroup: the first rows of the frame.
    let width = first.map_or(1, |f| f.tile.2.max(1)) as u64;
    let pixels = width * wgsl::WORKGROUP as u64;
    let (image, stats, finished) = (
        buffer(pixels * 16, U::STORAGE),
        buffer(pixels * 4 * wgsl::STATS_WORDS as u64, U::STORAGE),
        buffer(pixels * 4, U::STORAGE),
    );
    if let Some(f) = first {
        let n = (f.uniforms.len() as u64).min(limit) as usize;
        gpu.queue().write_buffer(&uniforms, 0, &f.uniforms[..n]);
        let t = f.tile;
        gpu.queue()
            .write_buffer(&tiles, 0, &words(&[t.0, t.1, t.2, t.3]));
    }
    let scene_data = data.then(|| buffer(16, U::STORAGE));
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let bind = kernel_bindings(
        device,
        &pipeline,
        [&uniforms, &tiles, &image, &stats, &finished],
        scene_data.as_ref(),
    );
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline.0);
        pass.set_bind_group(0, &bind, &[0]);
        pass.dispatch_workgroups(1, 1, 1);
    }
    gpu.queue().submit([encoder.finish()]);
    if let Some(e) = pollster::block_on(scope.pop()) {
        return Err(Error::Pass("kernel's first dispatch", e));
    }
    Ok(gpu.wait()?)
}

fn words(w: &[u32]) -> Vec<u8> {
    w.iter().flat_map(|x| x.to_le_bytes()).collect()
}
