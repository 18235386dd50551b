//! Images: linear float buffers, sRGB encoding and atomic PNG output.

use std::io::Write;
use std::path::{Path, PathBuf};

/// A linear-RGB image, row-major from the top-left pixel.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear colour of each pixel (not clamped).
    pub linear: Vec<[f32; 3]>,
}

/// Why an image could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// The PNG encoder or decoder refused the image.
    #[error("PNG error: {0}")]
    Encode(String),
    /// Creating, writing or renaming the file failed.
    #[error(transparent)]
    Io(#[from] std::io::Error),
}

impl Image {
    /// A black image.
    pub fn new(width: u32, height: u32) -> Self {
        Image {
            width,
            height,
            linear: vec![[0.0; 3]; width as usize * height as usize],
        }
    }

    /// The linear colour of pixel (x, y).
    pub fn pixel(&self, x: u32, y: u32) -> [f32; 3] {
        self.linear[y as usize * self.width as usize + x as usize]
    }

    /// Clamped, sRGB-encoded RGBA8 bytes (alpha 255): [`srgb_encode`] of every channel,
    /// through [`SrgbTable`] and in parallel rows, several times faster than computing each
    /// value (measured).
    pub fn to_rgba8(&self) -> Vec<u8> {
        use rayon::prelude::*;
        let table = SrgbTable::get();
        let mut out = vec![255u8; self.linear.len() * 4];
        let row = self.width.max(1) as usize;
        out.par_chunks_mut(row * 4)
            .zip(self.linear.par_chunks(row))
            .for_each(|(out, linear)| {
                for (o, c) in out.chunks_exact_mut(4).zip(linear) {
                    o[..3].copy_from_slice(&c.map(|x| table.encode(x)));
                }
            });
        out
    }

    /// The image as PNG file bytes (RGBA8, sRGB), compressed at the [`PngLevel::Fast`] level.
    pub fn encode_png(&self) -> Result<Vec<u8>, ImageError> {
        encode_png(self.width, self.height, &self.to_rgba8(), PngLevel::Fast)
    }
}

/// A finished frame: sRGB-encoded RGBA8 bytes (alpha 255), row-major from the top-left
/// pixel, as [`Image::to_rgba8`] gives them or as a GPU kernel finished them (the same
/// bytes: the kernel encodes with the thresholds of [`srgb_encode`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Rgba8 {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Four bytes a pixel.
    pub bytes: Vec<u8>,
}

impl Rgba8 {
    /// Hands the pixels' buffer back to the pool of [`pixel_buffer`] (the frame was written,
    /// or is no longer needed), for the next frame of the same size.
    pub fn recycle(self) {
        recycle(self.bytes);
    }
}

/// Buffers of finished pixels that frames no longer need, kept for the next frames of the
/// same size (a sequence's, a benchmark's): a new buffer of a frame's size is memory the
/// system maps and faults in page by page at its first write, and gives back when it is
/// freed, which took most of a 1920×1080 frame's host time. At most [`SPARE_COUNT`] buffers and [`SPARE_BYTES`] bytes are kept.
static SPARE: std::sync::Mutex<Vec<Vec<u8>>> = std::sync::Mutex::new(Vec::new());

/// The most buffers [`SPARE`] keeps.
const SPARE_COUNT: usize = 64;

/// The most bytes [`SPARE`] keeps: those of the frames that waited for the image writers at
/// once (`sdfc render --frames` bounds them to a gigabyte).
const SPARE_BYTES: usize = 1 << 30;

/// A buffer of `len` bytes for a frame's finished pixels, to be written whole: one handed
/// back ([`recycle`]) when there is one of that size (its bytes are those of an earlier
/// frame), else a new one of zeros (in huge pages where it is large: [`zeroed`]).
pub fn pixel_buffer(len: usize) -> Vec<u8> {
    let mut spare = SPARE.lock().unwrap_or_else(|e| e.into_inner());
    match spare.iter().rposition(|b| b.len() == len) {
        Some(i) => spare.swap_remove(i),
        None => {
            drop(spare);
            zeroed(len)
        }
    }
}

/// Keeps `bytes` for [`pixel_buffer`], dropping the buffers handed back longest ago when the
/// pool would hold more than [`SPARE_COUNT`] buffers or [`SPARE_BYTES`] bytes.
pub fn recycle(bytes: Vec<u8>) {
    if bytes.is_empty() || bytes.len() > SPARE_BYTES {
        return;
    }
    let mut spare = SPARE.lock().unwrap_or_else(|e| e.into_inner());
    let mut held: usize = spare.iter().map(Vec::len).sum();
    while !spare.is_empty() && (spare.len() >= SPARE_COUNT || held + bytes.len() > SPARE_BYTES) {
        held -= spare.remove(0).len();
    }
    spare.push(bytes);
}

/// The pixels of a frame to write: linear colours, encoded when written, or finished ones.
#[derive(Debug, Clone, PartialEq)]
pub enum Picture {
    /// Linear colours (EXR keeps them; the 8-bit formats encode them).
    Linear(Image),
    /// Pixels finished already (on the GPU).
    Finished(Rgba8),
}

impl Picture {
    /// Width and height in pixels.
    pub fn size(&self) -> (u32, u32) {
        match self {
            Picture::Linear(i) => (i.width, i.height),
            Picture::Finished(f) => (f.width, f.height),
        }
    }

    /// The sRGB-encoded RGBA8 bytes: encoded now ([`Image::to_rgba8`]) or as finished.
    pub fn rgba8(&self) -> std::borrow::Cow<'_, [u8]> {
        match self {
            Picture::Linear(i) => std::borrow::Cow::Owned(i.to_rgba8()),
            Picture::Finished(f) => std::borrow::Cow::Borrowed(&f.bytes),
        }
    }

    /// The linear image, when the picture has one.
    pub fn linear(&self) -> Option<&Image> {
        match self {
            Picture::Linear(i) => Some(i),
            Picture::Finished(_) => None,
        }
    }

    /// Bytes the picture holds.
    pub fn bytes(&self) -> u64 {
        match self {
            Picture::Linear(i) => 12 * i.linear.len() as u64,
            Picture::Finished(f) => f.bytes.len() as u64,
        }
    }
}

/// How hard the PNG encoder compresses (`--png-level`): the png crate's levels. `fastest`
/// and `fast` both deflate with fdeflate; `fastest` skips the per-row choice of filter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum PngLevel {
    /// Stored, not compressed: the largest files.
    None,
    /// fdeflate with one fixed filter.
    Fastest,
    /// fdeflate with adaptive filters: about a tenth of `balanced`'s time, in a file about
    /// 1.45 times as large (measured).
    #[default]
    Fast,
    /// zlib's default level.
    Balanced,
    /// zlib's best level.
    High,
}

impl PngLevel {
    fn compression(self) -> png::Compression {
        match self {
            PngLevel::None => png::Compression::NoCompression,
            PngLevel::Fastest => png::Compression::Fastest,
            PngLevel::Fast => png::Compression::Fast,
            PngLevel::Balanced => png::Compression::Balanced,
            PngLevel::High => png::Compression::High,
        }
    }
}

/// PNG file bytes of `rgba` (sRGB RGBA8, `width`×`height`) compressed at `level`.
pub fn encode_png(
    width: u32,
    height: u32,
    rgba: &[u8],
    level: PngLevel,
) -> Result<Vec<u8>, ImageError> {
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, width, height);
    encoder.set_compression(level.compression());
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let mut writer = encoder
        .write_header()
        .map_err(|e| ImageError::Encode(e.to_string()))?;
    writer
        .write_image_data(rgba)
        .map_err(|e| ImageError::Encode(e.to_string()))?;
    writer
        .finish()
        .map_err(|e| ImageError::Encode(e.to_string()))?;
    Ok(bytes)
}

/// A linear value clamped to [0, 1] and encoded with the sRGB transfer function (NaN is 0).
pub fn srgb_encode(c: f32) -> u8 {
    sdfc_compiler::wgsl::srgb::encode(c)
}

/// [`srgb_encode`] by table: `at[v]` is the least linear value (an f32 in [0, 1]) that
/// encodes to `v` or more, and `start[k]` the encoding of k / 4096, where the search for a
/// value in [k / 4096, (k + 1) / 4096) starts (the encoding rises by less than one over such
/// a step). `srgb_encode` never decreases as its argument grows (checked for every f32 in
/// [0, 1] by `image::tests::the_srgb_table_is_srgb_encode_for_every_f32`, ignored for its
/// time: 8 s in a release build), so the number of thresholds at or below a value is its
/// encoding.
#[derive(Debug)]
pub struct SrgbTable {
    at: [f32; 256],
    start: Vec<u8>,
}

impl SrgbTable {
    /// The table, computed once (the thresholds are `back::wgsl::srgb`'s).
    pub fn get() -> &'static SrgbTable {
        static TABLE: std::sync::OnceLock<SrgbTable> = std::sync::OnceLock::new();
        TABLE.get_or_init(|| {
            // The kernel's thresholds: the same table finishes pixels on the GPU.
            let at = *sdfc_compiler::wgsl::srgb::thresholds();
            let start = (0..=4096).map(|k| srgb_encode(k as f32 / 4096.0)).collect();
            SrgbTable { at, start }
        })
    }

    /// [`srgb_encode`]`(c)`.
    pub fn encode(&self, c: f32) -> u8 {
        let c = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
        // c · 4096 is exact (a power of two), so c lies at or above bucket k's start.
        let mut v = self.start[(c * 4096.0) as usize];
        while v < 255 && c >= self.at[v as usize + 1] {
            v += 1;
        }
        v
    }
}

/// The inverse of [`srgb_encode`]: an 8-bit sRGB value as linear colour.
pub fn srgb_decode(v: u8) -> f32 {
    sdfc_compiler::srgb_to_linear(v) as f32
}

/// Reads a PNG file (8-bit grey, grey-alpha, RGB or RGBA; alpha ignored) as a linear image.
pub fn read_png(path: &Path) -> Result<Image, ImageError> {
    let file = std::fs::File::open(path)?;
    let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder
        .read_info()
        .map_err(|e| ImageError::Encode(e.to_string()))?;
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| ImageError::Encode("image too large".into()))?;
    let mut buf = vec![0; size];
    let info = reader
        .next_frame(&mut buf)
        .map_err(|e| ImageError::Encode(e.to_string()))?;
    let channels = info.color_type.samples();
    let bytes = &buf[..info.buffer_size()];
    let linear = bytes
        .chunks_exact(channels)
        .map(|px| match channels {
            1 | 2 => [srgb_decode(px[0]); 3],
            _ => [srgb_decode(px[0]), srgb_decode(px[1]), srgb_decode(px[2])],
        })
        .collect();
    Ok(Image {
        width: info.width,
        height: info.height,
        linear,
    })
}

/// Writes `image` as a PNG file, atomically (see [`write_atomic`]).
pub fn write_png(path: &Path, image: &Image) -> Result<(), ImageError> {
    let bytes = image.encode_png()?;
    write_atomic(path, &bytes)?;
    Ok(())
}

/// Writes `bytes` to `path` through a temporary file in the same directory and a rename, so
/// that `path` is either untouched or complete; the temporary file is removed on failure.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

/// [`write_atomic`] for a file written piece by piece by `write` (through a buffer), so that
/// an encoder can stream into it without holding the whole file in memory.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let mut file = AtomicFile::create(path)?;
    write(&mut file)?;
    file.finish()
}

/// A file being written atomically: a temporary file beside the target, renamed onto it by
/// [`AtomicFile::finish`]; dropped unfinished (an error, a panic), the temporary file is
/// removed, and a process killed meanwhile leaves only the temporary file, never a partial
/// target.
#[derive(Debug)]
pub struct AtomicFile {
    tmp: PathBuf,
    path: PathBuf,
    file: Option<std::io::BufWriter<std::fs::File>>,
    /// Whether `finish` syncs the file to the disk before the rename.
    sync: bool,
}

impl AtomicFile {
    /// Starts writing `path`, synced to the disk before its rename: after a crash of the
    /// machine, a file found under its name is complete (which a sequence resuming by the
    /// files present relies on).
    pub fn create(path: &Path) -> std::io::Result<AtomicFile> {
        Self::open(path, true)
    }

    /// Starts writing `path`, complete or untouched whatever happens to the process, but not
    /// synced to the disk (after a crash of the machine it may be found empty), as a
    /// compiler writes its output: `sdfc render`'s still images. The fsync costs a small
    /// image many times its write, and far more while other programs write to the disk
    /// (measured).
    pub fn unsynced(path: &Path) -> std::io::Result<AtomicFile> {
        Self::open(path, false)
    }

    fn open(path: &Path, sync: bool) -> std::io::Result<AtomicFile> {
        refuse_read_only(path)?;
        let tmp = temp_path(path);
        let file = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)?;
        Ok(AtomicFile {
            tmp,
            path: path.to_path_buf(),
            file: Some(std::io::BufWriter::new(file)),
            sync,
        })
    }

    /// Gives the file the permissions of `meta` (the file it replaces), and its owner and
    /// group where the process may (as root; another user cannot give a file away, and the
    /// file stays theirs, as any rewrite would leave it).
    pub fn keep_metadata_of(&mut self, meta: &std::fs::Metadata) -> std::io::Result<()> {
        let Some(file) = self.file.as_ref().map(|b| b.get_ref()) else {
            return Ok(());
        };
        file.set_permissions(meta.permissions())?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            match std::os::unix::fs::fchown(file, Some(meta.uid()), Some(meta.gid())) {
                Err(e) if e.kind() == std::io::ErrorKind::PermissionDenied => {}
                other => other?,
            }
        }
        Ok(())
    }

    /// Flushes, syncs (unless [`AtomicFile::unsynced`]) and renames the file onto its target.
    pub fn finish(self) -> std::io::Result<()> {
        self.finish_timed().map(|_| ())
    }

    /// [`AtomicFile::finish`], saying how long each step took: the buffer's last bytes
    /// written, the file's data synced to the disk (`fsync`; none for
    /// [`AtomicFile::unsynced`]), and the rename onto the target.
    pub fn finish_timed(mut self) -> std::io::Result<Finished> {
        let Some(buffered) = self.file.take() else {
            return Ok(Finished::default());
        };
        let start = std::time::Instant::now();
        let file = buffered.into_inner().map_err(|e| e.into_error())?;
        let flush = start.elapsed();
        let start = std::time::Instant::now();
        if self.sync {
            file.sync_all()?;
        }
        drop(file);
        let sync = self.sync.then(|| start.elapsed());
        let start = std::time::Instant::now();
        std::fs::rename(&self.tmp, &self.path)?;
        self.tmp = PathBuf::new();
        Ok(Finished {
            flush,
            sync,
            rename: start.elapsed(),
        })
    }
}

/// How long the steps of [`AtomicFile::finish_timed`] took.
#[derive(Debug, Clone, Copy, Default)]
pub struct Finished {
    /// The buffer's last bytes written.
    pub flush: std::time::Duration,
    /// The file synced to the disk (`None`: not synced).
    pub sync: Option<std::time::Duration>,
    /// The rename onto the target.
    pub rename: std::time::Duration,
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match &mut self.file {
            Some(f) => f.write(buf),
            None => Err(std::io::Error::other("the file is finished")),
        }
    }

    fn flush(&mut self) -> std::io::Result<()> {
        match &mut self.file {
            Some(f) => f.flush(),
            None => Ok(()),
        }
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if !self.tmp.as_os_str().is_empty() {
            self.file = None;
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Refuses to replace a file that is read-only (no write permission in its mode): a rename
/// would replace it all the same, and a user who made a file read-only meant it to stay.
pub fn refuse_read_only(path: &Path) -> std::io::Result<()> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() && m.permissions().readonly() => Err(std::io::Error::new(
            std::io::ErrorKind::PermissionDenied,
            "the file is read-only, and is left as it is",
        )),
        _ => Ok(()),
    }
}

/// `.NAME.PID.tmp` beside `path`.
pub fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let tmp = format!(".{name}.{}.tmp", std::process::id());
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir.join(tmp),
        _ => PathBuf::from(tmp),
    }
}

/// A new vector of `len` zeroed elements for a frame's pixels, its memory asked for in huge
/// pages (Linux's transparent huge pages, `MADV_HUGEPAGE`) where it is large: the memory is
/// mapped untouched, and the first copy into it faults it in a page at a time, a 7680×4320
/// image's 133 MB in 32 400 pages of 4 KiB or 64 of 2 MiB. Elsewhere, or where the system
/// gives no huge pages, the pages are the small ones.
pub(crate) fn zeroed<T: Clone + Default>(len: usize) -> Vec<T> {
    let mut out = vec![T::default(); len];
    huge_pages(&mut out);
    out
}

/// Advises the kernel to back `memory`'s whole huge pages with huge pages (nothing for less
/// than a few of them, nor off Linux).
#[allow(unsafe_code)] // madvise: a hint about the pages of memory this function borrows.
fn huge_pages<T>(memory: &mut [T]) {
    #[cfg(target_os = "linux")]
    {
        const HUGE: usize = 2 << 20;
        let start = memory.as_mut_ptr() as usize;
        let end = start + std::mem::size_of_val(memory);
        let (from, to) = (start.next_multiple_of(HUGE), end / HUGE * HUGE);
        if to >= from + 4 * HUGE {
            // SAFETY: [from, to) lies within `memory`, borrowed mutably here; the advice
            // changes how its pages are backed, never their contents, and the kernel may
            // ignore it (its result is not needed).
            unsafe {
                libc::madvise(from as *mut libc::c_void, to - from, libc::MADV_HUGEPAGE);
            }
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = memory;
}

#[cfg(test)]
mod tests {
    /// A buffer handed back is the next one of its size given out (its memory, not a new
    /// one); one of another size is not.
    #[test]
    fn pixel_buffers_are_handed_out_again() {
        // A size no other test uses: the pool is the process's.
        let len = 4 * 7919;
        let first = super::pixel_buffer(len);
        assert_eq!(first, vec![0u8; len]);
        let at = first.as_ptr();
        super::recycle(first);
        assert!(super::pixel_buffer(len + 4).len() == len + 4);
        let again = super::pixel_buffer(len);
        assert_eq!((again.as_ptr(), again.len()), (at, len));
    }

    /// The table encodes as `srgb_encode` around every threshold (4 096 f32s either side),
    /// at the special values and at a million values drawn from [-0.1, 1.1].
    #[test]
    fn the_srgb_table_is_srgb_encode() {
        let table = super::SrgbTable::get();
        let check = |c: f32| assert_eq!(table.encode(c), super::srgb_encode(c), "{c:e}");
        for t in table.at {
            let b = t.to_bits();
            for d in b.saturating_sub(4096)..=b.saturating_add(4096).min(1.0f32.to_bits()) {
                check(f32::from_bits(d));
            }
        }
        for c in [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -0.0,
            0.0,
            1.0,
            -1.0,
            2.0,
        ] {
            check(c);
        }
        let mut rng = sdfc_compiler::Rng::new(11);
        for _ in 0..1_000_000 {
            check(rng.range(-0.1, 1.1) as f32);
        }
    }

    /// Every f32 in [0, 1] (about 10⁹ of them): ignored for its time, run with
    /// `cargo test --release -p sdfc-runtime --lib srgb -- --ignored`.
    #[test]
    #[ignore]
    fn the_srgb_table_is_srgb_encode_for_every_f32() {
        let table = super::SrgbTable::get();
        for b in 0..=1.0f32.to_bits() {
            let c = f32::from_bits(b);
            assert_eq!(table.encode(c), super::srgb_encode(c), "{c:e}");
        }
    }

    use super::*;

    #[test]
    fn srgb_endpoints() {
        assert_eq!(srgb_encode(0.0), 0);
        assert_eq!(srgb_encode(1.0), 255);
        assert_eq!(srgb_encode(2.0), 255);
        assert_eq!(srgb_encode(-1.0), 0);
        assert_eq!(srgb_encode(f32::NAN), 0);
        assert_eq!(srgb_encode(0.5), 188);
    }
}
