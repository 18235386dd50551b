//! `sdfc view`, the live preview: a session that watches a scene file and its imports,
//! recompiles on every change, keeps the last good image when an edit has errors, and renders
//! progressively ([`session`]); and its presentation, in a window ([`window`], [`present`],
//! with the parameter panel: [`panel`], [`widgets`]) or headless (this module), with the
//! screenshots and scripted parameter changes that let tests and measurements see what it
//! shows.

pub mod camera;
pub mod compile;
pub mod grade;
pub mod panel;
pub mod present;
pub mod resident;
pub mod session;
pub mod watch;
pub mod widgets;
pub mod window;

use crate::backend::Backend;
use crate::gpu::Gpu;
use session::{Device, Options, Session};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::mpsc;
use std::sync::Arc;
use std::time::Duration;
use watch::Watch;

/// When the viewer stops by itself, and what it writes on the way (for tests and scripts).
#[derive(Debug, Clone, Default)]
pub struct Control {
    /// Stop after this many frames are presented (the converged image is presented again).
    pub frames: Option<u64>,
    /// With `frames`: write what the last frame shows here (PNG).
    pub screenshot: Option<PathBuf>,
    /// Write `reload-K.png` here once the image after load K (0 the first) has settled:
    /// converged, or, after a load that failed, the image still on show.
    pub screenshot_dir: Option<PathBuf>,
    /// Stop once the screenshot of load K is written.
    pub exit_after_reloads: Option<u32>,
    /// Start with the statistics shown in the title.
    pub stats: bool,
    /// Headless: once the first image has settled, orbit the camera for this many frames,
    /// print the frame rate, then the time to the converged image after the camera stops;
    /// the run ends once that image (and every `--change`'s) has settled.
    pub orbit_frames: Option<u32>,
    /// `--change NAME=VALUE`: once the image of the last load has settled (and its screenshot
    /// is written), give the parameter NAME the value VALUE as its control in the panel would
    /// (kept within its range and on its step), one change after another; each is a load.
    pub changes: Vec<(String, String)>,
}

/// A run of the viewer.
#[derive(Debug, Clone)]
pub struct Run {
    /// The scene file.
    pub file: PathBuf,
    /// How the session treats the scene (its job's backend: `auto`, `wgpu` or `cpu`).
    pub options: Options,
    /// When to stop.
    pub control: Control,
}

/// Runs the session without a window: loads, renders until the image converges, waits for
/// changes to the files, and repeats, writing the screenshots `control` asks for from the
/// session's image. For measuring the viewer on a machine without a display.
///
/// It stops, and only then:
/// - with `--frames N`, after N frames, each turn of the loop counting one whether it
///   rendered a sample or presented the settled image again (so a scene that converges in
///   fewer frames, `aa: 2` for one, still stops), except a turn that waited for a kernel's
///   pipeline compiling on another thread and rendered nothing; with `--screenshot`, the last frame's
///   image is written first, and when no scene has loaded there is none: an error (exit 1),
///   nothing written;
/// - with `--exit-after-reloads K`, once the screenshot of load K is written;
/// - when the files can no longer be watched;
/// - otherwise never by itself (a live preview without a window, like the window).
pub fn headless(run: Run) -> ExitCode {
    let device = match run.options.job.backend {
        Backend::Cpu => Device::Cpu,
        backend => match Gpu::open(backend == Backend::Auto) {
            Ok(gpu) => Device::Wgpu(Arc::new(gpu)),
            Err(e) if backend == Backend::Auto => {
                eprintln!("view: {}; rendering on the CPU", no_gpu(&e));
                Device::Cpu
            }
            Err(e) => {
                let source = crate::backend::Error::Wgpu(e);
                return crate::job::Error::unavailable(Backend::Wgpu, source).exit();
            }
        },
    };
    eprintln!(
        "view: rendering on {} ({}), headless",
        device.name(),
        device.describe()
    );
    let size = Session::initial_size(&run.file, &run.options);
    let mut session = Session::new(run.file.clone(), run.options.clone(), device);
    session.set_size(size.0, size.1);
    let (tx, rx) = mpsc::channel();
    let mut watch = match Watch::new(move |paths, seen| {
        let _ = tx.send((paths, seen));
    }) {
        Ok(w) => Some(w),
        Err(msg) => {
            eprintln!("warning: {msg}; the scene will not be reloaded when it changes");
            None
        }
    };
    let control = &run.control;
    let mut shot_for = Some(session.load().number);
    let mut frames = 0u64;
    let mut orbit = control.orbit_frames;
    let mut measured = false;
    let mut changes: std::collections::VecDeque<_> = control.changes.iter().collect();
    loop {
        if let Some(w) = watch.as_mut() {
            for problem in w.add(session.files()) {
                eprintln!("warning: {problem}");
            }
        }
        // Render until the image settles; a frame limit counts the settled image too.
        loop {
            // Nothing to render while a kernel compiles (in its grace period, or the
            // interpreted kernel's image has converged, or there is none yet): wait for it,
            // or for the end of the grace period.
            session.wait_for_compile(Duration::from_secs(1));
            let rendered = match session.frame() {
                Ok(Some(_)) => {
                    session.presented();
                    true
                }
                Ok(None) => false,
                Err(msg) => {
                    eprintln!("error: {msg}");
                    false
                }
            };
            // A turn spent waiting for a kernel to compile, with nothing rendered, is no frame.
            if !rendered && session.compiling() {
                continue;
            }
            frames += 1;
            let last = control.frames.is_some_and(|n| frames >= n);
            if last {
                if let Some(path) = &control.screenshot {
                    if session.image().is_none() {
                        eprintln!(
                            "error: `{}` has not loaded (see the errors above); no screenshot written",
                            run.file.display()
                        );
                        return ExitCode::from(1);
                    }
                    if let Err(msg) = write_image(&session, path) {
                        eprintln!("error: {msg}");
                        return ExitCode::from(2);
                    }
                }
                return ExitCode::SUCCESS;
            }
            if session.settled() {
                break;
            }
        }
        if let Some(n) = orbit.take() {
            measure_orbit(&mut session, n);
            measured = true;
        }
        if let (Some(k), Some(dir)) = (shot_for.take(), &control.screenshot_dir) {
            let path = dir.join(format!("reload-{k}.png"));
            if let Err(msg) = write_image(&session, &path) {
                eprintln!("error: {msg}");
                return ExitCode::from(2);
            }
            if control.exit_after_reloads == Some(k) {
                return ExitCode::SUCCESS;
            }
        }
        // `--change`'s next change, through the control the panel would show.
        if let Some((name, text)) = changes.pop_front() {
            match widgets::change(session.params(), name, text) {
                Ok(value) => shot_for = Some(session.set_param(name, &value).number),
                Err(msg) => {
                    eprintln!("error: --change {name}={text}: {msg}");
                    return ExitCode::from(2);
                }
            }
            continue;
        }
        // An orbit's measurement ends the run once its changes are made (unless frames are
        // counted, which end it themselves).
        if measured && control.frames.is_none() {
            return ExitCode::SUCCESS;
        }
        // Wait for a change that calls for a reload; while frames are counted, only look for
        // one, and present the settled image again (a display's next refresh).
        let wait = match control.frames {
            Some(_) => Duration::from_millis(1),
            None => Duration::from_secs(3600),
        };
        let (paths, seen) = match rx.recv_timeout(wait) {
            Ok(p) => p,
            Err(mpsc::RecvTimeoutError::Timeout) => continue,
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                eprintln!("view: no longer watching the files; stopping");
                return ExitCode::SUCCESS;
            }
        };
        if session.needs_reload(&paths) {
            shot_for = Some(session.load_edited(Some(seen)).number);
        }
    }
}

/// Orbits the camera by 4 pixels' drag a frame for `frames` frames, as a user would, and
/// prints the frame rate and the frames' size; then lets the camera stop and prints how long
/// the image takes to converge (the settling time after the last motion included).
fn measure_orbit(session: &mut Session, frames: u32) {
    let start = std::time::Instant::now();
    let mut last = None;
    for _ in 0..frames {
        session.rotate(4.0, 0.0);
        match session.frame() {
            Ok(Some(info)) => last = Some(info),
            Ok(None) => {}
            Err(msg) => {
                eprintln!("error: {msg}");
                return;
            }
        }
    }
    let elapsed = start.elapsed();
    let Some(info) = last else {
        eprintln!("view: orbit: nothing to render");
        return;
    };
    eprintln!(
        "view: orbit: {frames} frames in {:.3} s, {:.1} frames/s (last frame {}x{}, {:.2} ms)",
        elapsed.as_secs_f64(),
        frames as f64 / elapsed.as_secs_f64(),
        info.width,
        info.height,
        info.time.as_secs_f64() * 1e3
    );
    let stopped = std::time::Instant::now();
    let mut samples = 0;
    while !session.settled() {
        match session.frame() {
            Ok(Some(info)) => samples = info.samples,
            Ok(None) => std::thread::sleep(Duration::from_millis(1)),
            Err(msg) => {
                eprintln!("error: {msg}");
                return;
            }
        }
    }
    eprintln!(
        "view: orbit: converged ({samples} samples per pixel) {:.1} ms after the camera stopped ({} ms of it waiting for the camera to count as still)",
        stopped.elapsed().as_secs_f64() * 1e3,
        session::SETTLE.as_millis()
    );
}

/// What the viewer says when `auto` finds no GPU (`e`, from [`Gpu::open`] asked for a hardware
/// adapter): a software adapter such as lavapipe is not used, as `sdfc render` does not use
/// it, and the CPU renders; only when there is no adapter at all does a driver need installing.
fn no_gpu(e: &crate::gpu::wgpu::Error) -> String {
    let software: Vec<String> = crate::gpu::wgpu::adapters()
        .iter()
        .filter(|a| a.get_info().device_type == wgpu::DeviceType::Cpu)
        .map(|a| a.get_info().name)
        .collect();
    match software.first() {
        Some(name) => format!(
            "no GPU adapter, only the software adapter {name}, which `--backend auto` leaves to `--backend wgpu`"
        ),
        None => format!("no GPU adapter ({e})"),
    }
}

/// Writes the session's image (the background grey when there is none yet).
fn write_image(session: &Session, path: &Path) -> Result<(), PngError> {
    let (w, h) = session.size();
    let bytes = match session.image() {
        Some(image) => {
            if (image.width, image.height) != (w, h) {
                // Only a frame rendered while moving is smaller, and headless nothing moves.
                return Err(PngError::Size);
            }
            image.to_rgba8()
        }
        None => [5, 5, 5, 255].repeat(w as usize * h as usize),
    };
    write_rgba_png(path, w, h, &bytes)?;
    eprintln!("view: wrote {}", path.display());
    Ok(())
}

/// Why a PNG of the view could not be written.
#[derive(Debug, thiserror::Error)]
pub enum PngError {
    /// The encoder failed.
    #[error("cannot write `{}`: {error}", path.display())]
    Encode {
        path: PathBuf,
        error: png::EncodingError,
    },
    /// The file could not be written.
    #[error("cannot write `{}`: {error}", path.display())]
    Write {
        path: PathBuf,
        error: std::io::Error,
    },
    /// The image on show is smaller than the view (a frame rendered while moving).
    #[error("the image on show is not at the view's size")]
    Size,
}

/// Writes RGBA8 sRGB pixels as a PNG file, atomically.
pub fn write_rgba_png(path: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<(), PngError> {
    let encode = |error| PngError::Encode {
        path: path.to_path_buf(),
        error,
    };
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let mut writer = encoder.write_header().map_err(encode)?;
    writer.write_image_data(rgba).map_err(encode)?;
    writer.finish().map_err(encode)?;
    crate::image::write_atomic(path, &bytes).map_err(|error| PngError::Write {
        path: path.to_path_buf(),
        error,
    })
}
