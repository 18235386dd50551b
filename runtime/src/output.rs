//! Where an image goes: the format its file name's extension names (PNG, JPEG or OpenEXR), or
//! PNG on standard output for `-`; checked before a render starts, so that a long render is
//! never thrown away because its output cannot be written. Files are written atomically
//! ([`crate::image::AtomicFile`]); JPEG and OpenEXR are streamed into them.

use crate::image::{encode_png, AtomicFile, Image, Picture, PngLevel};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// An image file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// 8-bit sRGB PNG.
    Png,
    /// 8-bit sRGB JPEG (quality [`JPEG_QUALITY`]).
    Jpeg,
    /// OpenEXR: the linear values, unclamped, as 32-bit floats (uncompressed scanlines).
    Exr,
}

/// The JPEG quality `sdfc render -o out.jpg` writes with.
pub const JPEG_QUALITY: u8 = 92;

/// The extensions understood, for messages.
pub const EXTENSIONS: &str = "`.png`, `.jpg` (or `.jpeg`) and `.exr`";

impl Format {
    /// The format an extension names (case-insensitive), if any.
    pub fn from_extension(ext: &str) -> Option<Format> {
        match ext.to_ascii_lowercase().as_str() {
            "png" => Some(Format::Png),
            "jpg" | "jpeg" => Some(Format::Jpeg),
            "exr" => Some(Format::Exr),
            _ => None,
        }
    }

    /// Writes the picture in this format to `w`: JPEG and OpenEXR are streamed, PNG is
    /// encoded first (at `png`). OpenEXR needs the linear colours: `Err` for finished pixels.
    pub fn write(self, picture: &Picture, png: PngLevel, w: &mut dyn Write) -> std::io::Result<()> {
        match self {
            Format::Png => {
                let (width, height) = picture.size();
                let bytes = encode_png(width, height, &picture.rgba8(), png)
                    .map_err(std::io::Error::other)?;
                w.write_all(&bytes)
            }
            Format::Jpeg => write_jpeg(picture, w),
            Format::Exr => match picture.linear() {
                Some(image) => write_exr(image, w),
                None => Err(std::io::Error::other(
                    "OpenEXR keeps linear colours, and this frame was finished as 8-bit sRGB",
                )),
            },
        }
    }

    /// Whether this format keeps linear colours (not the finished 8-bit pixels).
    pub fn linear(self) -> bool {
        self == Format::Exr
    }
}

/// The picture's PNG bytes (at `level`), with the steps of their encoding: the sRGB encoding
/// (nothing to do for pixels finished on the GPU) and the PNG's filtering and compression.
fn png_steps(
    picture: &Picture,
    level: PngLevel,
) -> Result<(Vec<u8>, Vec<Step>), crate::image::ImageError> {
    let start = Instant::now();
    let rgba = picture.rgba8();
    let srgb = start.elapsed();
    let start = Instant::now();
    let (width, height) = picture.size();
    let bytes = encode_png(width, height, &rgba, level)?;
    let png = start.elapsed();
    let mut steps = vec![match picture.linear() {
        Some(_) => ("sRGB", srgb, "clamped and encoded by table".to_string()),
        None => (
            "sRGB",
            srgb,
            "none here: clamped and encoded by the kernel on the GPU".to_string(),
        ),
    }];
    steps.push((
        "PNG",
        png,
        format!(
            "filtered and compressed at the `{}` level",
            clap::ValueEnum::to_possible_value(&level)
                .map_or_else(String::new, |v| v.get_name().to_string())
        ),
    ));
    Ok((bytes, steps))
}

/// A step of writing an image and its time, with what it was ([`Output::write`]).
pub type Step = (&'static str, Duration, String);

/// Why an output named on the command line cannot be written ([`Output::new`]).
#[derive(Debug, thiserror::Error)]
#[error("cannot write `{}`: {why}", .path.display())]
pub struct CannotWrite {
    /// The output.
    pub path: PathBuf,
    /// Why.
    pub why: Refused,
}

/// Why a path cannot be written to: its format, or the file system ([`check_writable`]).
#[derive(Debug, thiserror::Error)]
pub enum Refused {
    /// The file name has no extension to name a format.
    #[error("the file name has no extension; the formats are {EXTENSIONS}, or `-` for PNG on standard output")]
    NoExtension,
    /// The extension names no format sdfc writes.
    #[error("`.{0}` is not an image format sdfc writes; the formats are {EXTENSIONS}, or `-` for PNG on standard output")]
    Format(String),
    /// The path is a directory.
    #[error("it is a directory")]
    Directory,
    /// The file is read-only.
    #[error("{0}")]
    ReadOnly(std::io::Error),
    /// Its directory does not exist.
    #[error("the directory `{}` does not exist", .0.display())]
    NoDirectory(PathBuf),
    /// What would be its directory is not one.
    #[error("`{}` is not a directory", .0.display())]
    NotDirectory(PathBuf),
    /// No file can be created in its directory.
    #[error("cannot create a file in `{}`: {source}", .dir.display())]
    Create {
        /// The directory.
        dir: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

/// Where `sdfc render` writes its image.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Output {
    /// PNG bytes on standard output (`-o -`).
    Stdout,
    /// A file in the format its extension names.
    File {
        /// The file.
        path: PathBuf,
        /// Its format.
        format: Format,
    },
}

impl Output {
    /// The output `-o PATH` names: `-` is standard output; otherwise the extension must name
    /// a format and the file must be writable (its directory exists and takes a new file, and
    /// the path is not a directory). Nothing is left behind by the check.
    pub fn new(path: &Path) -> Result<Output, CannotWrite> {
        if path.as_os_str() == "-" {
            return Ok(Output::Stdout);
        }
        let cannot = |why| CannotWrite {
            path: path.to_path_buf(),
            why,
        };
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().into_owned())
            .unwrap_or_default();
        let Some(format) = Format::from_extension(&ext) else {
            return Err(cannot(match ext.is_empty() {
                true => Refused::NoExtension,
                false => Refused::Format(ext),
            }));
        };
        check_writable(path).map_err(cannot)?;
        Ok(Output::File {
            path: path.to_path_buf(),
            format,
        })
    }

    /// Writes `picture` (a PNG compressed at `png`): to the file atomically (synced to the disk before its rename when
    /// `sync`: [`AtomicFile::create`], else [`AtomicFile::unsynced`]), or to standard output.
    /// Says where the time went (`sdfc render --stats`): (step, time, what) for the
    /// encoding, the write, and for a file its `fsync` and rename.
    pub fn write(
        &self,
        picture: &Picture,
        sync: bool,
        png: PngLevel,
    ) -> Result<Vec<Step>, WriteError> {
        let (path, format) = match self {
            Output::Stdout => {
                let (bytes, mut steps) = png_steps(picture, png)
                    .map_err(|e| WriteError::Stdout(std::io::Error::other(e)))?;
                let start = Instant::now();
                let mut out = std::io::stdout().lock();
                out.write_all(&bytes)
                    .and_then(|()| out.flush())
                    .map_err(WriteError::Stdout)?;
                steps.push(("write", start.elapsed(), "to standard output".to_string()));
                return Ok(steps);
            }
            Output::File { path, format } => (path, *format),
        };
        let cannot = |error: std::io::Error| WriteError::File {
            path: path.clone(),
            error,
        };
        let mut steps = Vec::new();
        let encoded = if format == Format::Png {
            let (bytes, encoded) =
                png_steps(picture, png).map_err(|e| cannot(std::io::Error::other(e)))?;
            steps.extend(encoded);
            Some(bytes)
        } else {
            None
        };
        let file = match sync {
            true => AtomicFile::create(path),
            false => AtomicFile::unsynced(path),
        };
        let mut file = file.map_err(cannot)?;
        let start = Instant::now();
        match &encoded {
            Some(bytes) => file.write_all(bytes),
            None => format.write(picture, png, &mut file),
        }
        .map_err(cannot)?;
        let wrote = start.elapsed();
        let done = file.finish_timed().map_err(cannot)?;
        steps.push(match encoded {
            Some(_) => (
                "write",
                wrote + done.flush,
                "to a temporary file beside it".into(),
            ),
            None => (
                "encode",
                wrote + done.flush,
                "encoded and streamed into a temporary file beside it".into(),
            ),
        });
        if let Some(t) = done.sync {
            steps.push(("fsync", t, "its data synced to the disk".into()));
        }
        steps.push(("rename", done.rename, "onto the image's name".into()));
        Ok(steps)
    }

    /// The file, or `None` for standard output.
    pub fn path(&self) -> Option<&Path> {
        match self {
            Output::Stdout => None,
            Output::File { path, .. } => Some(path),
        }
    }
}

impl std::fmt::Display for Output {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Output::Stdout => f.write_str("standard output"),
            Output::File { path, .. } => write!(f, "{}", path.display()),
        }
    }
}

/// A frame handed to a [`Writers`] pool: its number, where it goes and its pixels, and
/// when its render started (for the log).
#[derive(Debug)]
pub struct Task {
    /// The frame's number.
    pub k: u64,
    /// Its file.
    pub output: Output,
    /// Its pixels.
    pub picture: Picture,
    /// When its render started.
    pub started: Instant,
}

impl Task {
    /// Frame `k`'s `picture`, its render started at `started`, for the file `path`.
    pub fn file(k: u64, path: PathBuf, format: Format, picture: Picture, started: Instant) -> Task {
        Task {
            k,
            output: Output::File { path, format },
            picture,
            started,
        }
    }
}

/// Why an image could not be written.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// Encoding it or writing it to standard output failed.
    #[error("cannot write the image to standard output: {0}")]
    Stdout(std::io::Error),
    /// Encoding it or writing its file failed.
    #[error("cannot write `{}`: {error}", path.display())]
    File {
        path: PathBuf,
        error: std::io::Error,
    },
    /// A [`Writers`] pool's threads have ended: it takes no more frames.
    #[error("the image writers have ended")]
    Ended,
}

/// A frame a [`Writers`] pool has written (or failed to write): its number, the error, and
/// the seconds from the start of its render to its file's rename.
#[derive(Debug)]
pub struct Written {
    /// The frame's number.
    pub k: u64,
    /// Why the file could not be written.
    pub result: Result<(), WriteError>,
    /// Seconds from the start of its render until its file was written.
    pub seconds: f64,
    /// Where the writing went: encoding, write, `fsync` and rename ([`Output::write`]).
    pub steps: Vec<Step>,
}

/// Images encoded and written (atomically, synced) on a pool of threads while the caller
/// renders the next frames (`sdfc render --frames` to numbered files): PNG, JPEG and
/// OpenEXR encoders are single-threaded, and a 1920×1080 PNG takes longer to compress than
/// a GPU takes to render most frames. At most `depth` frames wait for a thread: [`Writers::submit`]
/// blocks beyond that, which bounds the memory the frames hold.
#[derive(Debug)]
pub struct Writers {
    tasks: Option<std::sync::mpsc::SyncSender<Task>>,
    written: std::sync::mpsc::Receiver<Written>,
    threads: Vec<std::thread::JoinHandle<()>>,
}

/// A handle that hands frames to a [`Writers`] pool from other threads.
#[derive(Debug, Clone)]
pub struct Submit(std::sync::mpsc::SyncSender<Task>);

impl Submit {
    /// Hands `task` to the pool, waiting while `depth` frames wait already. `Err` when the
    /// pool has ended.
    pub fn submit(&self, task: Task) -> Result<(), WriteError> {
        self.0.send(task).map_err(|_| WriteError::Ended)
    }
}

impl Writers {
    /// A pool of `threads` threads (at least one), with at most `depth` frames waiting;
    /// each PNG is compressed at `png`.
    pub fn new(threads: usize, depth: usize, png: PngLevel) -> Writers {
        let (tasks, queue) = std::sync::mpsc::sync_channel::<Task>(depth.max(1));
        let (done, written) = std::sync::mpsc::channel();
        let queue = std::sync::Arc::new(std::sync::Mutex::new(queue));
        let threads = (0..threads.max(1))
            .map(|i| {
                let (queue, done) = (queue.clone(), done.clone());
                std::thread::Builder::new()
                    .name(format!("sdfc-writer-{i}"))
                    .spawn(move || loop {
                        let task = match queue.lock() {
                            Ok(q) => q.recv(),
                            Err(_) => return,
                        };
                        let Ok(task) = task else { return };
                        // Synced: a rerun skips the frames whose files it finds.
                        let (result, steps) = match task.output.write(&task.picture, true, png) {
                            Ok(steps) => (Ok(()), steps),
                            Err(e) => (Err(e), Vec::new()),
                        };
                        let written = Written {
                            k: task.k,
                            result,
                            seconds: task.started.elapsed().as_secs_f64(),
                            steps,
                        };
                        // The next frame's pixels are read back into its buffer.
                        if let Picture::Finished(f) = task.picture {
                            f.recycle();
                        }
                        if done.send(written).is_err() {
                            return;
                        }
                    })
                    .expect("a thread for the image writers")
            })
            .collect();
        Writers {
            tasks: Some(tasks),
            written,
            threads,
        }
    }

    /// The threads of a pool for this machine: one per core.
    pub fn cores() -> usize {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    }

    /// A handle for other threads.
    pub fn submitter(&self) -> Submit {
        Submit(self.tasks.clone().expect("the pool is open"))
    }

    /// Hands `task` to the pool ([`Submit::submit`]).
    pub fn submit(&self, task: Task) -> Result<(), WriteError> {
        self.submitter().submit(task)
    }

    /// The frames written since the last call, without waiting.
    pub fn written(&self) -> Vec<Written> {
        self.written.try_iter().collect()
    }

    /// The next frame written, waiting up to `timeout`.
    pub fn next_written(&self, timeout: Duration) -> Option<Written> {
        self.written.recv_timeout(timeout).ok()
    }

    /// Waits for every frame handed over (by every [`Submit`] handle, which must be dropped
    /// first) and returns those not yet reported.
    pub fn finish(mut self) -> Vec<Written> {
        drop(self.tasks.take());
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
        self.written.try_iter().collect()
    }
}

/// Checks that a new file can be written at `path`: the path is not a directory nor a
/// read-only file, and a file can be created in its directory (created and removed again).
pub fn check_writable(path: &Path) -> Result<(), Refused> {
    if path.is_dir() {
        return Err(Refused::Directory);
    }
    crate::image::refuse_read_only(path).map_err(Refused::ReadOnly)?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if !dir.exists() {
        return Err(Refused::NoDirectory(dir.to_path_buf()));
    }
    if !dir.is_dir() {
        return Err(Refused::NotDirectory(dir.to_path_buf()));
    }
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let probe = dir.join(format!(".{name}.{}.probe", std::process::id()));
    std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
        .map_err(|source| Refused::Create {
            dir: dir.to_path_buf(),
            source,
        })?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// The picture as a baseline JPEG (sRGB, clamped like the PNG), streamed to `w`.
fn write_jpeg(picture: &Picture, w: &mut dyn Write) -> std::io::Result<()> {
    let (width, height) = picture.size();
    let (Ok(width), Ok(height)) = (u16::try_from(width), u16::try_from(height)) else {
        return Err(std::io::Error::other(
            "JPEG images are at most 65535 pixels wide and high",
        ));
    };
    let rgb: Vec<u8> = picture
        .rgba8()
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    jpeg_encoder::Encoder::new(w, JPEG_QUALITY)
        .encode(&rgb, width, height, jpeg_encoder::ColorType::Rgb)
        .map_err(|e| std::io::Error::other(format!("JPEG error: {e}")))
}

/// The image as a single-part scanline OpenEXR file, streamed to `sink`: channels B, G and R
/// (the order the format sorts them in) as 32-bit floats, linear and unclamped, one
/// uncompressed scanline per chunk, increasing y (the OpenEXR file layout: magic number and
/// version, the header's attributes, the offset table, then the chunks).
pub fn write_exr(image: &Image, sink: &mut dyn Write) -> std::io::Result<()> {
    let (w, h) = (image.width as usize, image.height as usize);
    let mut out = Vec::with_capacity(400);
    out.extend_from_slice(&20000630i32.to_le_bytes());
    out.extend_from_slice(&[2, 0, 0, 0]);
    let mut attribute = |name: &str, kind: &str, value: &[u8]| {
        for s in [name, kind] {
            out.extend_from_slice(s.as_bytes());
            out.push(0);
        }
        out.extend_from_slice(&(value.len() as i32).to_le_bytes());
        out.extend_from_slice(value);
    };
    let mut channels = Vec::new();
    for name in ["B", "G", "R"] {
        channels.extend_from_slice(name.as_bytes());
        channels.push(0);
        channels.extend_from_slice(&2i32.to_le_bytes()); // FLOAT
        channels.extend_from_slice(&[0, 0, 0, 0]); // pLinear, reserved
        channels.extend_from_slice(&1i32.to_le_bytes()); // x sampling
        channels.extend_from_slice(&1i32.to_le_bytes()); // y sampling
    }
    channels.push(0);
    let window: Vec<u8> = [0, 0, w as i32 - 1, h as i32 - 1]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    attribute("channels", "chlist", &channels);
    attribute("compression", "compression", &[0]);
    attribute("dataWindow", "box2i", &window);
    attribute("displayWindow", "box2i", &window);
    attribute("lineOrder", "lineOrder", &[0]);
    attribute("pixelAspectRatio", "float", &1f32.to_le_bytes());
    attribute("screenWindowCenter", "v2f", &[0; 8]);
    attribute("screenWindowWidth", "float", &1f32.to_le_bytes());
    out.push(0);
    let line = 12 * w;
    let first = out.len() + 8 * h;
    sink.write_all(&out)?;
    for y in 0..h {
        sink.write_all(&((first + y * (8 + line)) as u64).to_le_bytes())?;
    }
    for y in 0..h {
        sink.write_all(&(y as i32).to_le_bytes())?;
        sink.write_all(&(line as i32).to_le_bytes())?;
        let row = &image.linear[y * w..(y + 1) * w];
        for c in [2, 1, 0] {
            for px in row {
                sink.write_all(&px[c].to_le_bytes())?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_come_from_extensions() {
        assert_eq!(Format::from_extension("PNG"), Some(Format::Png));
        assert_eq!(Format::from_extension("jpeg"), Some(Format::Jpeg));
        assert_eq!(Format::from_extension("jpg"), Some(Format::Jpeg));
        assert_eq!(Format::from_extension("exr"), Some(Format::Exr));
        assert_eq!(Format::from_extension("tiff"), None);
        assert_eq!(Output::new(Path::new("-")).unwrap(), Output::Stdout);
        let err = Output::new(Path::new("picture.tiff")).unwrap_err();
        assert_eq!(
            err.to_string(),
            format!("cannot write `picture.tiff`: `.tiff` is not an image format sdfc writes; the formats are {EXTENSIONS}, or `-` for PNG on standard output")
        );
        let err = Output::new(Path::new("picture")).unwrap_err();
        assert!(matches!(err.why, Refused::NoExtension), "{err}");
        let err = Output::new(Path::new("/nonexistent-sdfc/x.png")).unwrap_err();
        assert_eq!(
            err.to_string(),
            "cannot write `/nonexistent-sdfc/x.png`: the directory `/nonexistent-sdfc` does not exist"
        );
    }

    /// Frames handed to the pool are all written, whatever order the threads finish in,
    /// each file the frame's pixels; an unwritable one comes back as an error.
    #[test]
    fn the_writers_pool_writes_every_frame() {
        let dir = std::env::temp_dir().join(format!("sdfc-writers-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a directory");
        let writers = Writers::new(3, 2, PngLevel::Fastest);
        let mut images = Vec::new();
        for k in 0..6u64 {
            let mut image = Image::new(5, 4);
            image.linear[k as usize] = [1.0, 0.5, 0.25];
            images.push(image.clone());
            let output = Output::File {
                path: dir.join(format!("f{k}.png")),
                format: Format::Png,
            };
            let picture = if k % 2 == 0 {
                Picture::Linear(image)
            } else {
                Picture::Finished(crate::image::Rgba8 {
                    width: 5,
                    height: 4,
                    bytes: image.to_rgba8(),
                })
            };
            let started = Instant::now();
            writers
                .submit(Task {
                    k,
                    output,
                    picture,
                    started,
                })
                .expect("open");
        }
        let bad = Output::File {
            path: dir.join("missing").join("f.png"),
            format: Format::Png,
        };
        let picture = Picture::Linear(Image::new(1, 1));
        let started = Instant::now();
        writers
            .submit(Task {
                k: 9,
                output: bad,
                picture,
                started,
            })
            .expect("open");
        let mut done = writers.finish();
        done.sort_by_key(|w| w.k);
        assert_eq!(
            done.iter().map(|w| w.k).collect::<Vec<_>>(),
            [0, 1, 2, 3, 4, 5, 9]
        );
        assert!(done[..6].iter().all(|w| w.result.is_ok()));
        assert!(done[6].result.is_err());
        for (k, image) in images.iter().enumerate() {
            let read = crate::image::read_png(&dir.join(format!("f{k}.png"))).expect("a PNG");
            assert_eq!(read.to_rgba8(), image.to_rgba8(), "frame {k}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn exr_keeps_the_linear_values_in_its_scanlines() {
        let mut image = Image::new(3, 2);
        image.linear[4] = [2.5, -0.25, 0.125];
        let mut bytes = Vec::new();
        write_exr(&image, &mut bytes).expect("written");
        assert_eq!(&bytes[..4], &20000630i32.to_le_bytes());
        // The offset table follows the header's terminating zero; the chunk of row 1 starts
        // with its y, its size, then B, G, R of its three pixels.
        let header_end = bytes.len() - 2 * 8 - 2 * (8 + 36);
        assert_eq!(bytes[header_end - 1], 0);
        let at = |o: usize| u64::from_le_bytes(bytes[o..o + 8].try_into().expect("8 bytes"));
        let row1 = at(header_end + 8) as usize;
        let f = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().expect("4 bytes"));
        assert_eq!(
            i32::from_le_bytes(bytes[row1..row1 + 4].try_into().expect("y")),
            1
        );
        let data = row1 + 8;
        // Pixel (1, 1): B at index 1, G at 3 + 1, R at 6 + 1.
        assert_eq!(f(data + 4), 0.125);
        assert_eq!(f(data + 16), -0.25);
        assert_eq!(f(data + 28), 2.5);
        assert_eq!(bytes.len(), row1 + 8 + 36);
    }
}
