//! How the viewer's window shows images: through wgpu, a render pass over the window's
//! surface that samples the texture of the session's image (the one the GPU's frames are
//! accumulated into, or one the CPU renderer's image is uploaded to) into the view's part of
//! the surface, with what is drawn over it (the parameter panel: [`Overlay`]); or, where no
//! adapter can present to the window, softbuffer (pixels copied to the window by the CPU, no
//! panel). Each reads back what it presents for the screenshots.

use super::write_rgba_png;
use crate::gpu::Gpu;
use crate::image::Image;
use std::num::NonZeroU32;
use std::path::PathBuf;
use std::sync::Arc;
use winit::event_loop::{ActiveEventLoop, OwnedDisplayHandle};
use winit::window::Window;

/// What is drawn over the image before a frame is presented (and so in its screenshot): the
/// parameter panel.
pub trait Overlay {
    /// Records the drawing into `view`, a texture of the surface's format and `size`, whose
    /// image is drawn already.
    fn draw(
        &mut self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        view: &wgpu::TextureView,
        size: (u32, u32),
    );
}

/// How the window shows images: through wgpu, or, where no adapter can present to it, with
/// softbuffer (pixels copied to the window by the CPU).
pub(crate) enum Presenter {
    Gpu(Box<GpuPresenter>),
    Soft(SoftPresenter),
}

impl Presenter {
    pub fn resize(&mut self, width: u32, height: u32) {
        match self {
            Presenter::Gpu(p) => p.resize(width, height),
            Presenter::Soft(p) => p.size = (width.max(1), height.max(1)),
        }
    }

    pub fn upload(&mut self, image: &Image) {
        match self {
            Presenter::Gpu(p) => p.upload(image),
            Presenter::Soft(p) => p.image = Some((image.width, image.height, image.to_rgba8())),
        }
    }

    /// Shows `texture` (sRGB bytes, on the presenting device; `number` changes with the
    /// texture): only a wgpu presenter has a device.
    pub fn show(&mut self, texture: &wgpu::Texture, number: u64) {
        if let Presenter::Gpu(p) = self {
            p.show(texture, number);
        }
    }

    /// The width of the surface the image is drawn into, from its left edge (the panel takes
    /// the rest); the whole surface when `None`. Softbuffer has no panel.
    pub fn set_view_width(&mut self, width: Option<u32>) {
        if let Presenter::Gpu(p) = self {
            p.view_width = width;
        }
    }

    /// Draws the image, then `overlay` (wgpu only), presents, and first writes what is drawn
    /// to each of `shots` (PNG). `Ok(false)` when the surface had no texture to give.
    pub fn present(
        &mut self,
        shots: &[PathBuf],
        overlay: Option<&mut dyn Overlay>,
    ) -> Result<bool, Error> {
        match self {
            Presenter::Gpu(p) => p.present(shots, overlay),
            Presenter::Soft(p) => p.present(shots),
        }
    }
}

/// Why the window could not be drawn into.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// wgpu made no surface for the window.
    #[error("cannot make a wgpu surface for the window: {0}")]
    Surface(#[from] wgpu::CreateSurfaceError),
    /// No adapter presents to the window's surface.
    #[error("no wgpu adapter can present to the window ({0})")]
    Adapter(#[from] wgpu::RequestAdapterError),
    /// The adapter's device could not be opened.
    #[error(transparent)]
    Gpu(#[from] crate::gpu::wgpu::Error),
    /// The surface offers none of the formats the viewer draws.
    #[error("the window's surface offers no 8-bit RGBA format (it offers {0:?})")]
    Format(Vec<wgpu::TextureFormat>),
    /// The surface reported a validation error.
    #[error("the window's surface reported a validation error")]
    Validation,
    /// softbuffer (the window without wgpu) failed to do what is said.
    #[error("cannot {0}: {1}")]
    Soft(&'static str, softbuffer::SoftBufferError),
    /// A screenshot could not be written.
    #[error(transparent)]
    Shot(#[from] super::PngError),
    /// The window's pixels could not be read back for a screenshot.
    #[error("reading the window back: {0}")]
    Readback(Box<dyn std::error::Error + Send + Sync>),
}

/// Opens the wgpu presenter: an instance with the window's display, a surface, and an adapter
/// that can present to it.
pub(crate) fn wgpu_presenter(
    event_loop: &ActiveEventLoop,
    window: &Arc<Window>,
) -> Result<(Arc<Gpu>, GpuPresenter), Error> {
    // One instance for the process, never destroyed (as `runtime/src/gpu/wgpu/mod.rs` keeps its
    // own): the Vulkan driver then stays loaded until the process ends.
    static INSTANCE: std::sync::OnceLock<wgpu::Instance> = std::sync::OnceLock::new();
    let instance = INSTANCE.get_or_init(|| {
        let display = Box::new(event_loop.owned_display_handle());
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
            display,
        ))
    });
    let surface = instance.create_surface(window.clone())?;
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        force_fallback_adapter: false,
        compatible_surface: Some(&surface),
        apply_limit_buckets: false,
    }))?;
    let gpu = Arc::new(Gpu::from_adapter(&adapter)?);
    let size = window.inner_size();
    let presenter = GpuPresenter::new(gpu.clone(), surface, &adapter, size.width, size.height)?;
    Ok((gpu, presenter))
}

/// Shows images with softbuffer: each is scaled to the window (nearest pixel) by the CPU and
/// copied to it.
pub(crate) struct SoftPresenter {
    surface: softbuffer::Surface<OwnedDisplayHandle, Arc<Window>>,
    size: (u32, u32),
    /// The image's size and sRGB RGBA bytes.
    image: Option<(u32, u32, Vec<u8>)>,
}

impl SoftPresenter {
    pub fn new(event_loop: &ActiveEventLoop, window: &Arc<Window>) -> Result<SoftPresenter, Error> {
        let soft = |e| Error::Soft("draw in the window without wgpu either", e);
        let context = softbuffer::Context::new(event_loop.owned_display_handle()).map_err(soft)?;
        let surface = softbuffer::Surface::new(&context, window.clone()).map_err(soft)?;
        let size = window.inner_size();
        Ok(SoftPresenter {
            surface,
            size: (size.width.max(1), size.height.max(1)),
            image: None,
        })
    }

    fn present(&mut self, shots: &[PathBuf]) -> Result<bool, Error> {
        let (w, h) = self.size;
        let (Some(nw), Some(nh)) = (NonZeroU32::new(w), NonZeroU32::new(h)) else {
            return Ok(false);
        };
        self.surface
            .resize(nw, nh)
            .map_err(|e| Error::Soft("resize the window's buffer", e))?;
        let mut buffer = self
            .surface
            .buffer_mut()
            .map_err(|e| Error::Soft("draw in the window", e))?;
        for y in 0..h {
            for x in 0..w {
                let px = match &self.image {
                    Some((iw, ih, rgba)) => {
                        let (sx, sy) = (x * iw / w, y * ih / h);
                        let i = 4 * (sy as usize * *iw as usize + sx as usize);
                        (rgba[i] as u32) << 16 | (rgba[i + 1] as u32) << 8 | rgba[i + 2] as u32
                    }
                    None => 0x050505,
                };
                buffer[y as usize * w as usize + x as usize] = px;
            }
        }
        if !shots.is_empty() {
            let rgba: Vec<u8> = buffer
                .iter()
                .flat_map(|&p| [(p >> 16) as u8, (p >> 8) as u8, p as u8, 255])
                .collect();
            for path in shots {
                write_rgba_png(path, w, h, &rgba)?;
            }
        }
        buffer
            .present()
            .map_err(|e| Error::Soft("show the frame", e))?;
        Ok(true)
    }
}

/// Draws the session's image into the window's surface: a texture of sRGB bytes, the one the
/// GPU's frames are accumulated into or one the CPU renderer's image is uploaded to, drawn
/// over the whole surface with a linear filter (so the smaller frames rendered while moving
/// fill the window).
pub(crate) struct GpuPresenter {
    gpu: Arc<Gpu>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    /// Whether the surface texture can be copied from (else screenshots are drawn into a
    /// texture of the surface's format).
    copyable: bool,
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    texture_format: wgpu::TextureFormat,
    /// The texture uploaded to, and its bindings.
    image: Option<(wgpu::Texture, wgpu::BindGroup)>,
    /// The bindings of a texture shown in place, with its number ([`GpuPresenter::show`]):
    /// drawn instead of `image` while it is set.
    shown: Option<(u64, wgpu::BindGroup)>,
    /// The width the image is drawn at from the left edge ([`Presenter::set_view_width`]).
    view_width: Option<u32>,
}

/// The blit: a triangle over the whole target sampling the image.
const BLIT: &str = r#"
@group(0) @binding(0) var image: texture_2d<f32>;
@group(0) @binding(1) var smp: sampler;

struct Out {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
};

@vertex
fn vs(@builtin(vertex_index) i: u32) -> Out {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    var o: Out;
    o.position = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0);
    o.uv = uv;
    return o;
}

@fragment
fn fs(o: Out) -> @location(0) vec4<f32> {
    return vec4<f32>(textureSample(image, smp, o.uv).rgb, 1.0);
}
"#;

/// The colour of the window before the first image (dark grey).
const EMPTY: wgpu::Color = wgpu::Color {
    r: 0.02,
    g: 0.02,
    b: 0.02,
    a: 1.0,
};

impl GpuPresenter {
    fn new(
        gpu: Arc<Gpu>,
        surface: wgpu::Surface<'static>,
        adapter: &wgpu::Adapter,
        width: u32,
        height: u32,
    ) -> Result<GpuPresenter, Error> {
        let caps = surface.get_capabilities(adapter);
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| {
                matches!(
                    f,
                    wgpu::TextureFormat::Bgra8UnormSrgb | wgpu::TextureFormat::Rgba8UnormSrgb
                )
            })
            .or_else(|| {
                caps.formats.iter().copied().find(|f| {
                    matches!(
                        f,
                        wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Rgba8Unorm
                    )
                })
            })
            .ok_or_else(|| Error::Format(caps.formats.clone()))?;
        let copyable = caps.usages.contains(wgpu::TextureUsages::COPY_SRC);
        let mut usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        if copyable {
            usage |= wgpu::TextureUsages::COPY_SRC;
        }
        let config = wgpu::SurfaceConfiguration {
            usage,
            format,
            width: width.max(1),
            height: height.max(1),
            present_mode: wgpu::PresentMode::Fifo,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes[0],
            view_formats: vec![],
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        let device = gpu.device();
        surface.configure(device, &config);
        // The image holds sRGB bytes: an sRGB texture decodes them for an sRGB surface, which
        // encodes them again; a plain one passes them through to a plain surface.
        let texture_format = if format.is_srgb() {
            wgpu::TextureFormat::Rgba8UnormSrgb
        } else {
            wgpu::TextureFormat::Rgba8Unorm
        };
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("sdfc view blit"),
            source: wgpu::ShaderSource::Wgsl(BLIT.into()),
        });
        let (layout, pipeline_layout) = gpu.layouts(
            ("sdfc view blit", "sdfc view blit"),
            &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        );
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("sdfc view blit"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs"),
                compilation_options: Default::default(),
                targets: &[Some(format.into())],
            }),
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            multiview_mask: None,
            cache: None,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("sdfc view blit"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        Ok(GpuPresenter {
            gpu,
            surface,
            config,
            copyable,
            pipeline,
            layout,
            sampler,
            texture_format,
            image: None,
            shown: None,
            view_width: None,
        })
    }

    /// The device it presents with.
    pub fn gpu(&self) -> &Gpu {
        &self.gpu
    }

    /// The surface's format.
    pub fn format(&self) -> wgpu::TextureFormat {
        self.config.format
    }

    fn resize(&mut self, width: u32, height: u32) {
        if width == 0 || height == 0 {
            return;
        }
        self.config.width = width;
        self.config.height = height;
        self.surface.configure(self.gpu.device(), &self.config);
    }

    /// Draws `texture` (sRGB bytes in an `Rgba8Unorm` texture that may be viewed as
    /// `Rgba8UnormSrgb`, on this device) from now on; `number` names it, so that its bindings
    /// are made once.
    pub fn show(&mut self, texture: &wgpu::Texture, number: u64) {
        if self.shown.as_ref().is_some_and(|(n, _)| *n == number) {
            return;
        }
        // Sampled only: an sRGB view of the texture cannot be a storage binding.
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            format: Some(self.texture_format),
            usage: Some(wgpu::TextureUsages::TEXTURE_BINDING),
            ..Default::default()
        });
        let bind = self.bindings(&view);
        self.shown = Some((number, bind));
    }

    /// The blit's bindings of `view`.
    fn bindings(&self, view: &wgpu::TextureView) -> wgpu::BindGroup {
        self.gpu
            .device()
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("sdfc view image"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::Sampler(&self.sampler),
                    },
                ],
            })
    }

    /// Uploads `image` (sRGB-encoded) as the texture to draw.
    pub fn upload(&mut self, image: &Image) {
        self.shown = None;
        let device = self.gpu.device();
        let size = wgpu::Extent3d {
            width: image.width,
            height: image.height,
            depth_or_array_layers: 1,
        };
        let same = self
            .image
            .as_ref()
            .is_some_and(|(t, _)| t.width() == image.width && t.height() == image.height);
        if !same {
            let texture = device.create_texture(&wgpu::TextureDescriptor {
                label: Some("sdfc view image"),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: self.texture_format,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            });
            let bind = self.bindings(&texture.create_view(&Default::default()));
            self.image = Some((texture, bind));
        }
        if let Some((texture, _)) = &self.image {
            self.gpu.queue().write_texture(
                texture.as_image_copy(),
                &image.to_rgba8(),
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(4 * image.width),
                    rows_per_image: Some(image.height),
                },
                size,
            );
        }
    }

    /// Draws the image into `view`.
    fn draw(&self, encoder: &mut wgpu::CommandEncoder, view: &wgpu::TextureView) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("sdfc view blit"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(EMPTY),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let bind = match (&self.shown, &self.image) {
            (Some((_, bind)), _) | (None, Some((_, bind))) => Some(bind),
            (None, None) => None,
        };
        if let Some(bind) = bind {
            let (w, h) = (self.config.width, self.config.height);
            let view_w = self.view_width.map_or(w, |v| v.clamp(1, w));
            pass.set_viewport(0.0, 0.0, view_w as f32, h as f32, 0.0, 1.0);
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, bind, &[]);
            pass.draw(0..3, 0..1);
        }
    }

    /// Draws the image to the surface, then `overlay`, and presents it, first writing what it
    /// shows to each of `shots` (PNG). `Ok(false)` when the surface had no texture to give
    /// this time.
    fn present(
        &mut self,
        shots: &[PathBuf],
        mut overlay: Option<&mut dyn Overlay>,
    ) -> Result<bool, Error> {
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f) => f,
            wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                return Ok(false)
            }
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(self.gpu.device(), &self.config);
                return Ok(false);
            }
            wgpu::CurrentSurfaceTexture::Validation => return Err(Error::Validation),
        };
        let device = self.gpu.device();
        let view = frame.texture.create_view(&Default::default());
        let size = (self.config.width, self.config.height);
        let mut encoder = device.create_command_encoder(&Default::default());
        self.draw(&mut encoder, &view);
        if let Some(o) = overlay.as_mut() {
            o.draw(&self.gpu, &mut encoder, &view, size);
        }
        self.gpu.queue().submit([encoder.finish()]);
        if !shots.is_empty() {
            let bytes = if self.copyable {
                self.read(&frame.texture)?
            } else {
                // The same draw into a texture of the surface's format and size.
                let texture = device.create_texture(&wgpu::TextureDescriptor {
                    label: Some("sdfc view screenshot"),
                    size: frame.texture.size(),
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: self.config.format,
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                    view_formats: &[],
                });
                let mut encoder = device.create_command_encoder(&Default::default());
                let view = texture.create_view(&Default::default());
                self.draw(&mut encoder, &view);
                if let Some(o) = overlay.as_mut() {
                    o.draw(&self.gpu, &mut encoder, &view, size);
                }
                self.gpu.queue().submit([encoder.finish()]);
                self.read(&texture)?
            };
            for path in shots {
                write_rgba_png(path, self.config.width, self.config.height, &bytes)?;
            }
        }
        self.gpu.queue().present(frame);
        Ok(true)
    }

    /// The pixels of `texture` (of the surface's format) as RGBA8 rows.
    fn read(&self, texture: &wgpu::Texture) -> Result<Vec<u8>, Error> {
        let device = self.gpu.device();
        let (w, h) = (texture.width(), texture.height());
        let row = (4 * w).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sdfc view screenshot"),
            size: row as u64 * h as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: Some(h),
                },
            },
            texture.size(),
        );
        self.gpu.queue().submit([encoder.finish()]);
        let slice = buffer.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| Error::Readback(Box::new(e)))?;
        rx.recv()
            .map_err(|e| Error::Readback(Box::new(e)))?
            .map_err(|e| Error::Readback(Box::new(e)))?;
        let mapped = slice
            .get_mapped_range()
            .map_err(|e| Error::Readback(Box::new(e)))?;
        let bgra = matches!(
            self.config.format,
            wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
        );
        let mut out = Vec::with_capacity(4 * w as usize * h as usize);
        for y in 0..h as usize {
            let start = y * row as usize;
            for px in mapped[start..start + 4 * w as usize].chunks_exact(4) {
                if bgra {
                    out.extend_from_slice(&[px[2], px[1], px[0], 255]);
                } else {
                    out.extend_from_slice(&[px[0], px[1], px[2], 255]);
                }
            }
        }
        drop(mapped);
        buffer.unmap();
        Ok(out)
    }
}
