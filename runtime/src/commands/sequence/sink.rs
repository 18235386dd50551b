//! Where the frames of `sdfc render --frames` go as they are rendered ([`Sink`]): numbered
//! image files, each written atomically; an animated PNG streamed into one atomic file; or a
//! video encoded by `ffmpeg` from raw frames on its standard input.

use crate::image::{AtomicFile, Picture, PngLevel};
use crate::job::Error;
use crate::output::Output;
use crate::sequence::{ffmpeg, Frames, Target};
use std::cell::RefCell;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::rc::Rc;

/// Where the frames go as they are rendered.
pub(super) enum Sink {
    /// Numbered files, each written atomically.
    Numbered(crate::sequence::Pattern, crate::output::Format),
    /// An animated PNG, streamed into one atomic file (opened at the first frame).
    Apng {
        path: PathBuf,
        frames: u64,
        fps: f64,
        file: Option<Rc<RefCell<AtomicFile>>>,
        writer: Option<png::Writer<Shared>>,
    },
    /// `ffmpeg` reading raw RGB frames on its standard input (started at the first frame).
    Video {
        path: PathBuf,
        ffmpeg: PathBuf,
        fps: f64,
        child: Option<(std::process::Child, PathBuf)>,
    },
}

/// An [`AtomicFile`] shared by the PNG encoder and the sink, which finishes it.
pub(super) struct Shared(Rc<RefCell<AtomicFile>>);

impl Write for Shared {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.borrow_mut().write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.0.borrow_mut().flush()
    }
}

impl Sink {
    pub(super) fn open(target: &Target, frames: Frames, fps: f64) -> Result<Sink, Error> {
        Ok(match target {
            Target::Numbered(p, f) => {
                crate::output::check_writable(&p.path(frames.start)).map_err(|why| {
                    Error::Io(format!(
                        "cannot write `{}`: {why}",
                        p.path(frames.start).display()
                    ))
                })?;
                Sink::Numbered(p.clone(), *f)
            }
            Target::Apng(path) => {
                crate::output::check_writable(path).map_err(|why| {
                    Error::Io(format!("cannot write `{}`: {why}", path.display()))
                })?;
                Sink::Apng {
                    path: path.clone(),
                    frames: frames.len(),
                    fps,
                    file: None,
                    writer: None,
                }
            }
            Target::Video(path) => {
                let ffmpeg = ffmpeg()?;
                crate::output::check_writable(path).map_err(|why| {
                    Error::Io(format!("cannot write `{}`: {why}", path.display()))
                })?;
                Sink::Video {
                    path: path.clone(),
                    ffmpeg,
                    fps,
                    child: None,
                }
            }
        })
    }

    /// Whether frame `k` is written already (only numbered files are: an animated PNG or a
    /// video is written whole).
    pub(super) fn exists(&self, k: u64) -> bool {
        match self {
            Sink::Numbered(p, _) => p.path(k).is_file(),
            _ => false,
        }
    }

    /// Where frame `k` went, for the log.
    pub(super) fn describe(&self, k: u64) -> String {
        match self {
            Sink::Numbered(p, _) => format!("wrote {}", p.path(k).display()),
            Sink::Apng { path, .. } | Sink::Video { path, .. } => {
                format!("added to {}", path.display())
            }
        }
    }

    pub(super) fn write(&mut self, k: u64, picture: &Picture) -> Result<(), Error> {
        let io = |path: &Path| {
            let path = path.display().to_string();
            move |e: std::io::Error| Error::Io(format!("cannot write `{path}`: {e}"))
        };
        match self {
            Sink::Numbered(p, format) => Output::File {
                path: p.path(k),
                format: *format,
            }
            // Synced: a rerun skips the frames whose files it finds.
            .write(picture, true, PngLevel::Fast)
            .map(|_| ())
            .map_err(|e| Error::Io(e.to_string())),
            Sink::Apng {
                path,
                frames,
                fps,
                file,
                writer,
            } => {
                if writer.is_none() {
                    let f = Rc::new(RefCell::new(AtomicFile::create(path).map_err(io(path))?));
                    *writer = Some(
                        apng(Shared(f.clone()), picture.size(), *frames, *fps).map_err(|e| {
                            Error::Io(format!("cannot write `{}`: {e}", path.display()))
                        })?,
                    );
                    *file = Some(f);
                }
                let w = writer.as_mut().expect("writer");
                w.write_image_data(&picture.rgba8())
                    .map_err(|e| Error::Io(format!("cannot write `{}`: {e}", path.display())))
            }
            Sink::Video {
                path,
                ffmpeg,
                fps,
                child,
            } => {
                if child.is_none() {
                    *child = Some(start_ffmpeg(ffmpeg, path, picture.size(), *fps)?);
                }
                let (c, _) = child.as_mut().expect("ffmpeg");
                let stdin = c.stdin.as_mut().expect("piped");
                stdin
                    .write_all(&rgb8(picture))
                    .map_err(|e| Error::Encode(format!("ffmpeg stopped reading frames: {e}")))
            }
        }
    }

    /// Finishes an animated PNG or a video (renamed onto the target when complete).
    pub(super) fn finish(self) -> Result<(), Error> {
        match self {
            Sink::Numbered(..) => Ok(()),
            Sink::Apng {
                path, file, writer, ..
            } => {
                let (Some(w), Some(f)) = (writer, file) else {
                    return Ok(());
                };
                let err = |e: String| Error::Io(format!("cannot write `{}`: {e}", path.display()));
                w.finish().map_err(|e| err(e.to_string()))?;
                let f = Rc::try_unwrap(f)
                    .map_err(|_| err("the encoder still holds the file".into()))?
                    .into_inner();
                f.finish().map_err(|e| err(e.to_string()))
            }
            Sink::Video { path, child, .. } => {
                let Some((mut c, tmp)) = child else {
                    return Ok(());
                };
                drop(c.stdin.take());
                let status = c
                    .wait()
                    .map_err(|e| Error::Encode(format!("ffmpeg: {e}")))?;
                if !status.success() {
                    let _ = std::fs::remove_file(&tmp);
                    return Err(Error::Encode(format!(
                        "ffmpeg failed ({status}) writing `{}`",
                        path.display()
                    )));
                }
                std::fs::rename(&tmp, &path)
                    .map_err(|e| Error::Io(format!("cannot write `{}`: {e}", path.display())))
            }
        }
    }
}

/// An APNG encoder of `frames` frames of `width`×`height` at `fps`, looping forever.
fn apng(
    out: Shared,
    (width, height): (u32, u32),
    frames: u64,
    fps: f64,
) -> Result<png::Writer<Shared>, png::EncodingError> {
    let mut encoder = png::Encoder::new(out, width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    encoder.set_animated(frames.min(u32::MAX as u64) as u32, 0)?;
    // The delay of a frame is 1/fps seconds, as a fraction of 16-bit integers.
    let (num, den) = if fps * 100.0 <= u16::MAX as f64 {
        (100, (fps * 100.0).round() as u16)
    } else {
        (1, fps.round() as u16)
    };
    encoder.set_frame_delay(num, den.max(1))?;
    encoder.write_header()
}

/// Starts `ffmpeg` encoding raw RGB frames of `width`×`height` from its standard input into a
/// temporary file beside `path` (renamed onto it when ffmpeg succeeds).
fn start_ffmpeg(
    ffmpeg: &Path,
    path: &Path,
    (width, height): (u32, u32),
    fps: f64,
) -> Result<(std::process::Child, PathBuf), Error> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = path.with_file_name(format!(".{}.{name}", std::process::id()));
    let mut cmd = std::process::Command::new(ffmpeg);
    cmd.args(["-hide_banner", "-loglevel", "error", "-y", "-f", "rawvideo"])
        .args(["-pix_fmt", "rgb24"])
        .args(["-s", &format!("{width}x{height}")])
        .args(["-framerate", &fps.to_string(), "-i", "-"]);
    if !path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gif"))
    {
        // Players expect 4:2:0 chroma, which needs even edges.
        cmd.args([
            "-vf",
            "pad=ceil(iw/2)*2:ceil(ih/2)*2",
            "-pix_fmt",
            "yuv420p",
        ]);
    }
    cmd.arg(&tmp).stdin(std::process::Stdio::piped());
    let child = cmd
        .spawn()
        .map_err(|e| Error::Encode(format!("cannot start `{}`: {e}", ffmpeg.display())))?;
    Ok((child, tmp))
}

/// Clamped sRGB bytes, three a pixel.
fn rgb8(picture: &Picture) -> Vec<u8> {
    picture
        .rgba8()
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect()
}
