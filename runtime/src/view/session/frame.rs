//! The session's frames: whether one is wanted, rendered progressively (fewer pixels while a
//! frame exceeds its budget or the camera moves, jittered samples accumulated up to the
//! scene's `aa` while it is still), and the image or texture it leaves.

use super::{Accumulation, Device, FrameInfo, Good, Session, FRAME_BUDGET, MAX_SCALE};
use crate::backend::Prepared;
use crate::image::Image;
use crate::view::camera::{self};
use crate::view::grade::Grade;
use crate::view::resident::Resident;
use sdfc_compiler::{Camera, Scene};
use std::time::{Duration, Instant};

impl Session {
    /// The divisor of the resolution of a new scene's first frame: enough to bring the last
    /// full frame's time within the budget (1 before the first frame).
    pub(super) fn preview_scale(&self) -> u32 {
        let ratio = self
            .last_full
            .map_or(0.0, |t| t.as_secs_f64() / FRAME_BUDGET.as_secs_f64());
        (ratio.sqrt().ceil() as u32).clamp(1, MAX_SCALE)
    }

    /// Whether there is a frame to render: a scene is loaded and the camera moves or the image
    /// has fewer samples than the scene's `aa` asks for.
    /// While the scene's kernel compiles on another thread, only its end calls for a frame
    /// (before, the interpreted kernel's image converges, or there is nothing to render: in
    /// the grace period, the end of the period calls for one, at [`Session::grace_deadline`]).
    pub fn wants_frame(&self) -> bool {
        let Some(good) = &self.good else {
            return false;
        };
        if good
            .waiting
            .as_ref()
            .is_some_and(|w| w.finished(self.held(w.load)))
        {
            return true;
        }
        if self.broken.is_some() || good.kernel().is_none() {
            return false;
        }
        let a = &self.accumulation;
        self.moving()
            || self.playing()
            || !a.still
            || a.count < good.aa
            || (a.width, a.height) != self.size
    }

    /// Whether the image on show is final until something changes (converged, or nothing to
    /// render, and no kernel compiling to replace the one that rendered it).
    pub fn settled(&self) -> bool {
        !self.wants_frame() && !self.compiling()
    }

    /// Renders the next frame into the image on show. `Ok(None)` when there is nothing to
    /// render; `Err` is a render error (rendering stops until the next load or camera move).
    pub fn frame(&mut self) -> Result<Option<FrameInfo>, FrameError> {
        self.poll();
        if !self.wants_frame() {
            return Ok(None);
        }
        self.advance();
        // A playing animation renders as a moving camera does: one sample a frame.
        let moving = self.moving() || self.playing();
        let Some(base) = self.camera() else {
            return Ok(None);
        };
        let scale = self.frame_scale(moving);
        // A frame below full resolution is a single sample, replaced by the next frame.
        let low = scale > 1 || moving;
        self.preview = false;
        let (w, h) = (self.size.0.div_ceil(scale), self.size.1.div_ceil(scale));
        self.accumulate_at(low, w, h);
        let a = &mut self.accumulation;
        let Some(good) = self.good.as_mut().filter(|g| g.kernel().is_some()) else {
            return Ok(None);
        };
        good.aim(&base, low, a.count, (w, h));
        let start = Instant::now();
        let Some(prepared) = good.kernel() else {
            return Ok(None);
        };
        let kind = prepared.kernel_kind();
        let on = (&mut self.resident, (self.version, self.steps_wanted));
        let rendered = render_sample(prepared, (&good.scene, good.grade), on, a);
        let (count, steps) = match rendered {
            Ok(r) => r,
            Err(e) => {
                self.broken = Some(e.to_string());
                return Err(e);
            }
        };
        let time = start.elapsed();
        a.count = count;
        if !a.sum.is_empty() {
            self.shown = Some(a.mean(good.grade));
        }
        let info = FrameInfo {
            width: w,
            height: h,
            samples: a.count,
            target: good.aa,
            time,
            steps,
            moving,
            kernel: kind,
        };
        let interim = match good.waiting.as_mut() {
            Some(w) => {
                w.shown = true;
                w.interim.as_ref().and_then(|i| i.pipeline)
            }
            None => None,
        };
        self.pace(scale, moving, time);
        if let Some(t) = self.timings.as_mut().filter(|t| t.first_frame.is_none()) {
            t.first_frame = Some((time, w, h));
            t.first_kernel = kind;
            t.interim_pipeline = interim;
        }
        self.last = Some(info);
        Ok(Some(info))
    }

    /// The divisor of the resolution of the next frame: the moving camera's, a new scene's
    /// first frame's ([`Session::preview_scale`]), else 1.
    fn frame_scale(&self, moving: bool) -> u32 {
        if moving {
            self.scale
        } else if self.preview {
            self.preview_scale()
        } else {
            1
        }
    }

    /// Starts the accumulation again, empty, for a frame of `w` × `h` pixels unless it goes
    /// on: a `low` frame (below full resolution, or of a moving camera) starts it again, as do
    /// a change of size and the end of a low frame.
    fn accumulate_at(&mut self, low: bool, w: u32, h: u32) {
        let a = &mut self.accumulation;
        if low || !a.still || (a.width, a.height) != (w, h) {
            let on_cpu = matches!(self.device, Device::Cpu);
            *a = Accumulation {
                width: w,
                height: h,
                sum: match on_cpu {
                    true => vec![[0.0; 3]; w as usize * h as usize],
                    false => Vec::new(),
                },
                count: 0,
                still: !low,
            };
        }
    }

    /// Notes the time of a frame: a full-resolution frame's sets the next scene's preview
    /// scale; while moving, a frame over its budget lowers the resolution and one well
    /// within it raises it.
    fn pace(&mut self, scale: u32, moving: bool, time: Duration) {
        if scale == 1 {
            self.last_full = Some(time);
        }
        if moving {
            if time > FRAME_BUDGET && self.scale < MAX_SCALE {
                self.scale += 1;
            } else if time * 3 < FRAME_BUDGET && self.scale > 1 {
                self.scale -= 1;
            }
        }
    }

    /// The image on show: the mean of the samples accumulated (at the size of the last frame),
    /// or `None` before the first good frame. On wgpu it is read back from the device (for a
    /// screenshot or a test: frames themselves never are); a failed read is printed, and is
    /// `None`.
    pub fn image(&self) -> Option<Image> {
        match &self.resident {
            Some(r) => r.image().unwrap_or_else(|msg| {
                eprintln!("error: {msg}");
                None
            }),
            None => self.shown.clone(),
        }
    }

    /// The image on show as the host holds it: the CPU renderer's (a window uploads it to show
    /// it). `None` on wgpu, whose image stays on the device ([`Session::texture`]).
    pub fn host_image(&self) -> Option<&Image> {
        self.shown.as_ref()
    }

    /// On wgpu, the texture on show (sRGB bytes in an `Rgba8Unorm` texture, which may be
    /// viewed as `Rgba8UnormSrgb`), on the device that renders the frames, and its number,
    /// which changes when the texture does; `None` before the first frame and on the CPU.
    pub fn texture(&self) -> Option<(&wgpu::Texture, u64)> {
        self.resident.as_ref().and_then(Resident::texture)
    }

    /// Whether each frame's mean steps per pixel are wanted (the statistics in the title); on
    /// wgpu, where frames stay on the device, a frame then reads back their sum (two words).
    pub fn want_steps(&mut self, wanted: bool) {
        self.steps_wanted = wanted;
        // The frame on show was rendered without them: they are summed on the device now.
        let Some(last) = self.last.as_mut().filter(|l| wanted && l.steps.is_nan()) else {
            return;
        };
        if let Some(resident) = self.resident.as_mut() {
            match resident.last_steps() {
                Ok(Some(steps)) => last.steps = steps,
                Ok(None) => {}
                Err(msg) => eprintln!("error: {msg}"),
            }
        }
    }
}

impl Good {
    /// Sets the scene for the next sample, `count`, of a `w` × `h` frame seen from `base`: the
    /// camera jittered within the pixel (not for a `low` frame), one sample.
    fn aim(&mut self, base: &Camera, low: bool, count: u32, (w, h): (u32, u32)) {
        let path = self.scene.settings.path;
        let n = (self.aa as f64).sqrt().round() as u32;
        // A path-traced frame is one sample, the next of its random stream, jittered within
        // the pixel by the path tracer itself.
        let (dx, dy) = if low || path {
            (0.0, 0.0)
        } else {
            camera::sample_offset(count, n)
        };
        self.scene.camera = camera::jittered(base, dx, dy, w, h);
        let s = &mut self.scene.settings;
        (s.width, s.height, s.aa) = (w, h, 1);
        (s.samples, s.first_sample) = (1, count);
    }
}

impl Accumulation {
    /// The mean of the linear samples summed on the CPU, graded.
    fn mean(&self, grade: Grade) -> Image {
        let inv = 1.0 / self.count as f32;
        Image {
            width: self.width,
            height: self.height,
            linear: self
                .sum
                .iter()
                .map(|c| grade.apply([c[0] * inv, c[1] * inv, c[2] * inv]))
                .collect(),
        }
    }
}

/// Why a frame was not rendered: the scene does not fit its kernel or the CPU's render failed
/// (the backend's error), or the viewer's pass on the device failed.
#[derive(Debug, thiserror::Error)]
pub enum FrameError {
    #[error(transparent)]
    Backend(#[from] crate::backend::Error),
    #[error(transparent)]
    Pass(#[from] crate::view::resident::Error),
}

/// Renders a sample of `scene` through `prepared`: on wgpu the frame stays on the device,
/// rendered, accumulated and shown there (in `resident`, made on the first frame; the scene
/// data uploaded again when `version` changes; the steps summed when `steps_wanted`); on the
/// CPU it is added to `a`'s sums. The number of samples accumulated, and the frame's mean
/// steps (NaN where not summed).
fn render_sample(
    prepared: &Prepared,
    (scene, grade): (&Scene, Grade),
    (resident, (version, steps_wanted)): (&mut Option<Resident>, (u64, bool)),
    a: &mut Accumulation,
) -> Result<(u32, f64), FrameError> {
    let Some(crate::backend::WgpuPrepared {
        gpu,
        kernel,
        lipschitz,
        ..
    }) = prepared.as_wgpu()
    else {
        let frame = prepared.render(scene, &|_| {})?;
        for (sum, c) in a.sum.iter_mut().zip(&frame.render.image.linear) {
            for i in 0..3 {
                sum[i] += c[i];
            }
        }
        return Ok((a.count + 1, frame.render.stats.steps_mean));
    };
    let key = version << 1 | kernel.interpreted() as u64;
    // Made (and kept) before the scene is checked against its kernel.
    let resident = match resident.as_mut() {
        Some(r) => Ok(r),
        None => Resident::new(gpu.clone()).map(|r| resident.insert(r)),
    };
    prepared.check_contract(scene)?;
    let first = a.count == 0;
    let r = resident?.render(
        (kernel, *lipschitz),
        (scene, grade),
        key,
        first,
        steps_wanted,
    )?;
    Ok((r.count, r.steps.unwrap_or(f64::NAN)))
}
