//! The one tile scheduler of every launcher: a frame is cut into tiles, each tile is one
//! dispatch (or launch) on a [`Device`], and the scheduler owns the tiling, the batches and
//! progress, the fault injection of `SDFC_FAULT_AFTER_TILES`, the phases and timing, and the
//! assembly of the image and its statistics. A device (wgpu, CUDA, the CPU renderer) only
//! prepares a frame's buffers, runs tiles, reads pixels back and says how long its tiles took.
//!
//! One device renders the image in squares of [`super::TILE`] pixels. Finished pixels are
//! read back a row of squares at a time ([`rows`]), each row's readback queued behind its
//! launches and collected straight into the frame's buffer while the next row renders; linear
//! colours are read back whole at the end. Several devices ([`render_several`]) take bands of whole rows from one
//! queue, each worker the next band when it is free, and read back each band as it finishes
//! straight into its place in the image (a band is contiguous in the image, so a device reads
//! back only what it rendered, and the pixels cross the host's memory once); a device that
//! fails hands its band back to the queue and the others finish the frame.

use super::reduce::{Answer, Ask, Selection, Summary};
use super::Phases;
use std::ops::Range;
use std::time::{Duration, Instant};

/// A tile: x, y, width and height in pixels.
pub type Tile = (u32, u32, u32, u32);

/// Tiles per submission when one device renders a frame: the host waits after each batch
/// (progress, and a bound on how much work is queued at once).
const TILES_PER_SUBMIT: usize = 8;

/// What every device renders of a frame: the kernel's inputs (uniforms and scene data), the
/// image size and the tiles, whether to time them and reduce the statistics, and where the
/// pixels go ([`Target`]). (A render request as a whole is a [`crate::job::Job`].)
#[derive(Debug, Clone, Copy)]
pub struct Work<'a> {
    /// Bytes of the scene uniform (binding 0).
    pub uniforms: &'a [u8],
    /// Bytes of the read-only `scene_data` (binding 4), when the kernel declares it.
    pub data: Option<&'a [u8]>,
    /// Image size.
    pub width: u32,
    pub height: u32,
    /// The tile table.
    pub tiles: &'a [Tile],
    /// Whether to time the tiles on the device (timestamps or events); without it the
    /// frame's time is its wall time.
    pub timed: bool,
    /// Whether to reduce the per-pixel statistics on the device to the frame's counters and
    /// steps ([`Device::reduce`], `--stats`, `bench`): a few kilobytes read back where the
    /// statistics themselves are 66 MB at 1920×1080. Without them the frame's steps are zero
    /// and its counters empty (the kernel still writes them on the device).
    pub statistics: bool,
    /// Where the frame's pixels go: read back as linear colours or finished pixels, or kept
    /// on the device.
    pub target: Target,
}

/// Where a frame's pixels go once its tiles have rendered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// Read back as linear colours (16 bytes a pixel on the device, 12 on the host).
    Linear,
    /// Read back as finished pixels (RGBA8, sRGB-encoded on the device: 4 bytes a pixel):
    /// the frame then has no linear image.
    Finished,
    /// Kept on the device, nothing read back (but the statistics, when asked for): the tiles
    /// are submitted without waiting for them, for a caller that goes on with the pixels there
    /// (the viewer accumulates them: a wgpu `Kernel` given the buffers it renders into,
    /// `wgpu::ResidentFrame`). Several devices read their bands back, as linear colours: a
    /// frame kept on the device is one device's.
    Resident,
}

impl Target {
    /// [`Target::Finished`] when `finished`, else [`Target::Linear`].
    pub fn read_back(finished: bool) -> Target {
        match finished {
            true => Target::Finished,
            false => Target::Linear,
        }
    }
}

impl Work<'_> {
    /// Whether the finished pixels are read back ([`Target::Finished`]).
    pub fn finished(&self) -> bool {
        self.target == Target::Finished
    }

    /// The image's pixels.
    pub fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// The pixels of tile `i`, which must span whole rows (a band).
    fn band(&self, i: usize) -> Range<usize> {
        let t = self.tiles[i];
        debug_assert!(t.0 == 0 && t.2 == self.width, "a band spans whole rows");
        let w = self.width as usize;
        t.1 as usize * w..(t.1 + t.3) as usize * w
    }
}

/// Pixels read back from a device, in the order of the ranges asked for: linear colours (or,
/// where the work asks for them, finished RGBA8 bytes), and how long converting them from the
/// device's layout took.
#[derive(Debug, Default)]
pub struct Pixels {
    pub linear: Vec<[f32; 3]>,
    pub rgba: Vec<u8>,
    pub convert: Duration,
}

/// The per-device steps of a render.
pub trait Device: Sync {
    /// A frame's buffers on the device.
    type Frame;
    /// What goes wrong on it.
    type Error: std::fmt::Display;
    /// The device, for messages.
    fn describe(&self) -> String;
    /// Allocates a frame's buffers and uploads the uniforms, the scene data and the tile table.
    fn prepare(&self, work: &Work) -> Result<Self::Frame, Self::Error>;
    /// Runs the tiles `tiles` (indices into the work's table) and waits until they are done.
    fn run(&self, frame: &mut Self::Frame, work: &Work, tiles: &[usize])
        -> Result<(), Self::Error>;
    /// Reads back the pixels of `ranges` (row-major pixel indices), one after the other.
    fn read(
        &self,
        frame: &mut Self::Frame,
        work: &Work,
        ranges: &[Range<usize>],
    ) -> Result<Pixels, Self::Error>;
    /// Starts the tiles `tiles` without waiting for them: several devices overlap a band's
    /// readback with the next band's launches ([`Device::start_read`]). By default
    /// [`Device::run`], which waits.
    fn submit(
        &self,
        frame: &mut Self::Frame,
        work: &Work,
        tiles: &[usize],
    ) -> Result<(), Self::Error> {
        self.run(frame, work, tiles)
    }
    /// Starts reading back the pixels of `range` once the work submitted so far is done, into
    /// readback buffer `slot` (0 or 1: a band's pixels are collected from one while the next
    /// band's are copied into the other). By default nothing: [`Device::collect`] reads.
    fn start_read(
        &self,
        _frame: &mut Self::Frame,
        _work: &Work,
        _range: Range<usize>,
        _slot: usize,
    ) -> Result<(), Self::Error> {
        Ok(())
    }
    /// The finished pixels of `range` whose read was started into `slot`, handed to `take`
    /// once they are copied (the work submitted after them may still be running): how long
    /// the copy was waited for, or `None` where no read of `range` was started into `slot`.
    /// By default `None`: [`Device::collect`] reads.
    fn copied(
        &self,
        _frame: &mut Self::Frame,
        _range: &Range<usize>,
        _slot: usize,
        _take: &mut dyn FnMut(&[u8]),
    ) -> Result<Option<Duration>, Self::Error> {
        Ok(None)
    }
    /// The pixels of `range` whose read was started into `slot`, once they are copied
    /// ([`Device::copied`]); where none was started, [`Device::read`].
    fn collect(
        &self,
        frame: &mut Self::Frame,
        work: &Work,
        range: Range<usize>,
        slot: usize,
    ) -> Result<Pixels, Self::Error> {
        let mut rgba = Vec::new();
        let copied = self.copied(frame, &range, slot, &mut |b| {
            rgba = super::to_vec_parallel(b)
        })?;
        match copied {
            Some(_) => Ok(Pixels {
                rgba,
                ..Pixels::default()
            }),
            None => self.read(frame, work, std::slice::from_ref(&range)),
        }
    }
    /// [`Device::collect`] straight into `place`, the band's place in the image: the pixels
    /// cross the host's memory once, on the worker's thread. Says how long it waited for the
    /// device (the band's launches and its copy across the bus) and converted. Finished pixels
    /// whose read was started are copied from the device's buffer into their place, the wait
    /// for the copy timed apart; others are collected, then copied ([`collect_copied`]).
    fn collect_into(
        &self,
        frame: &mut Self::Frame,
        work: &Work,
        range: Range<usize>,
        slot: usize,
        place: Place<'_>,
    ) -> Result<Collected, Self::Error> {
        let place = match place {
            Place::Rgba(out) => {
                let copy = &mut |b: &[u8]| super::copy_parallel(&mut *out, b);
                if let Some(wait) = self.copied(frame, &range, slot, copy)? {
                    return Ok(Collected {
                        wait,
                        convert: Duration::ZERO,
                    });
                }
                Place::Rgba(out)
            }
            place => place,
        };
        collect_copied(self, frame, work, (range, slot), place)
    }
    /// The statistics of the pixels of `ranges` (rendered in `frame`) reduced as `ask` asks,
    /// on the device ([`super::reduce`]).
    fn reduce(
        &self,
        frame: &mut Self::Frame,
        work: &Work,
        ranges: &[Range<usize>],
        ask: Ask,
    ) -> Result<Answer, Self::Error>;
    /// Errors the device held back so far (on several devices, each band is checked before
    /// it is accepted).
    fn check(&self, _frame: &mut Self::Frame) -> Result<(), Self::Error> {
        Ok(())
    }
    /// Ends the frame: errors the device held back, and the time of its tiles when the work
    /// is timed and the device can time them.
    fn finish(&self, frame: Self::Frame, work: &Work) -> Result<Option<Duration>, Self::Error>;
    /// The error a device fault of the testing aid is reported as (the path a real device
    /// error takes).
    fn fault(&self, message: String) -> Self::Error;
}

/// Where a band's pixels go in the image being assembled ([`Device::collect_into`]): its
/// finished RGBA8 bytes, or its linear colours.
#[derive(Debug)]
pub enum Place<'a> {
    Rgba(&'a mut [u8]),
    Linear(&'a mut [[f32; 3]]),
}

impl Place<'_> {
    /// The same place, borrowed again.
    fn reborrow(&mut self) -> Place<'_> {
        match self {
            Place::Rgba(p) => Place::Rgba(p),
            Place::Linear(p) => Place::Linear(p),
        }
    }

    /// `pixels` copied in (those the work asked for).
    fn fill(self, pixels: &Pixels) {
        match self {
            Place::Rgba(p) => {
                debug_assert_eq!(p.len(), pixels.rgba.len(), "a band's bytes");
                super::copy_parallel(p, &pixels.rgba)
            }
            Place::Linear(p) => {
                debug_assert_eq!(p.len(), pixels.linear.len(), "a band's pixels");
                super::copy_parallel(p, &pixels.linear)
            }
        }
    }
}

/// How long [`Device::collect_into`] waited for the device, and converted.
#[derive(Debug, Clone, Copy, Default)]
pub struct Collected {
    pub wait: Duration,
    pub convert: Duration,
}

/// [`Device::collect`], copied into `place`: what [`Device::collect_into`] does where the
/// device has nothing better (its wait is not told apart from the copy).
pub fn collect_copied<D: Device + ?Sized>(
    device: &D,
    frame: &mut D::Frame,
    work: &Work,
    (range, slot): (Range<usize>, usize),
    place: Place<'_>,
) -> Result<Collected, D::Error> {
    let pixels = device.collect(frame, work, range, slot)?;
    place.fill(&pixels);
    Ok(Collected {
        wait: Duration::ZERO,
        convert: pixels.convert,
    })
}

/// A frame rendered by the scheduler: its linear colours, or its finished RGBA8 bytes when
/// the work asked for them ([`Work::finished`]).
#[derive(Debug)]
pub struct Output {
    pub linear: Vec<[f32; 3]>,
    pub rgba: Vec<u8>,
    /// The statistics reduced on the devices (empty unless the work asked for them).
    pub summary: Summary,
    pub phases: Phases,
    /// The tiles' time on the device, where measured.
    pub device_time: Option<Duration>,
    /// Wall time from the first launch until the last tile finished.
    pub wall: Duration,
    /// What each device did, when several rendered the frame.
    pub shares: Vec<Share>,
}

/// What one device did in a frame rendered by several.
#[derive(Debug, Clone)]
pub struct Share {
    /// The device.
    pub device: String,
    /// Tiles it rendered (and read back).
    pub tiles: usize,
    /// Where its worker's time went (setup, launches, readback, conversion).
    pub phases: Phases,
    /// Why it stopped, if it failed.
    pub failure: Option<String>,
}

/// The testing aid `SDFC_FAULT_AFTER_TILES`: `N` makes every device report a device error
/// after N tiles (N tiles render, the next fails), `D:N` only the device at position D of the
/// render's device list (0-based); entries are separated by commas. Unset, or not in that
/// form, nothing is injected.
pub const FAULT_AFTER_TILES: &str = "SDFC_FAULT_AFTER_TILES";

/// The faults asked for by [`FAULT_AFTER_TILES`].
#[derive(Debug, Clone, Default)]
pub struct Faults {
    text: String,
    entries: Vec<(Option<usize>, usize)>,
}

impl Faults {
    /// From the environment.
    pub fn from_env() -> Faults {
        std::env::var(FAULT_AFTER_TILES)
            .ok()
            .and_then(|t| Faults::parse(&t))
            .unwrap_or_default()
    }

    fn parse(text: &str) -> Option<Faults> {
        let entries = text
            .split(',')
            .map(|e| match e.split_once(':') {
                Some((d, n)) => Some((Some(d.trim().parse().ok()?), n.trim().parse().ok()?)),
                None => Some((None, e.trim().parse().ok()?)),
            })
            .collect::<Option<Vec<_>>>()?;
        Some(Faults {
            text: text.trim().to_string(),
            entries,
        })
    }

    /// After how many tiles the device at `position` fails.
    fn after(&self, position: usize) -> Option<usize> {
        self.entries
            .iter()
            .filter(|(d, _)| d.is_none_or(|d| d == position))
            .map(|&(_, n)| n)
            .min()
    }

    /// The message of the device error injected at the device's tile `tile` (0-based), if
    /// one is.
    pub fn injected(&self, position: usize, tile: usize) -> Option<String> {
        self.injected_within(position, tile..tile + 1)
    }

    /// The message of the device error injected at one of the device's tiles `tiles`
    /// (0-based, counted over every frame it rendered), if one is.
    pub fn injected_within(&self, position: usize, tiles: Range<usize>) -> Option<String> {
        let tile = self.after(position).filter(|t| tiles.contains(t))?;
        Some(format!(
            "device error injected at tile {} by {FAULT_AFTER_TILES}={} (a testing aid)",
            tile + 1,
            self.text
        ))
    }
}

/// The tiles of a frame rendered by `devices` devices: squares of `edge` pixels for one,
/// bands of whole rows for several (at most about `edge`² pixels each; [`BANDS`] in all, and
/// at least [`BANDS_PER_DEVICE`] a device, so that a device is not left waiting long for
/// another's last band at the end).
pub fn tiling(width: u32, height: u32, edge: u32, devices: usize) -> Vec<Tile> {
    if devices <= 1 {
        return squares(width, height, edge);
    }
    let by_area = (edge.max(8) * edge.max(8) / width.max(1)).max(1);
    let bands = BANDS.max(BANDS_PER_DEVICE * devices as u32);
    let by_count = height.div_ceil(bands).max(1);
    let rows = by_area.min(by_count);
    (0..height)
        .step_by(rows as usize)
        .map(|y| (0, y, width, rows.min(height - y)))
        .collect()
}

/// The bands of a frame on several devices, unless [`BANDS_PER_DEVICE`] asks for more. Each
/// band costs a launch, a wait and a copy out on its device's thread, so fewer bands cost
/// less, while more bands let a device that finishes early take work from one that does
/// not: on four devices, four bands a device measured faster than eight.
pub const BANDS: u32 = 16;

/// The fewest bands a device of several takes in a frame, on average.
pub const BANDS_PER_DEVICE: u32 = 4;

/// Splits the image into tiles of at most `edge` pixels a side.
pub fn squares(width: u32, height: u32, edge: u32) -> Vec<Tile> {
    let edge = edge.max(8);
    let mut out = Vec::new();
    for y in (0..height).step_by(edge as usize) {
        for x in (0..width).step_by(edge as usize) {
            out.push((x, y, edge.min(width - x), edge.min(height - y)));
        }
    }
    out
}

/// Renders `work` on one device. Finished pixels ([`Target::Finished`]): a row of tiles at a
/// time, each row's readback queued behind its launches and the row before collected while
/// it renders, straight into the frame's buffer (one of [`crate::image::pixel_buffer`]'s).
/// Linear colours: the tiles in batches, waiting after each (progress, the injected fault),
/// then the image read back whole. Kept on the device ([`Target::Resident`]): the tiles
/// submitted in batches without waiting, nothing read back.
pub fn render_one<D: Device>(
    device: &D,
    work: &Work,
    faults: &Faults,
    progress: &mut dyn FnMut(f64),
) -> Result<Output, D::Error> {
    let setup = Instant::now();
    let mut frame = device.prepare(work)?;
    let setup = setup.elapsed();
    let start = Instant::now();
    let whole = 0..work.pixels();
    let (pixels, wall, readback) = match work.target {
        Target::Finished => {
            let (rgba, collecting) = overlapped(device, &mut frame, work, faults, progress)?;
            let pixels = Pixels {
                rgba,
                ..Pixels::default()
            };
            (
                pixels,
                start.elapsed().saturating_sub(collecting),
                collecting,
            )
        }
        Target::Linear => {
            batches((device, &mut frame), (work, true), faults, progress)?;
            let wall = start.elapsed();
            let readback = Instant::now();
            let pixels = device.read(&mut frame, work, std::slice::from_ref(&whole))?;
            let readback = readback.elapsed().saturating_sub(pixels.convert);
            (pixels, wall, readback)
        }
        Target::Resident => {
            batches((device, &mut frame), (work, false), faults, progress)?;
            (Pixels::default(), start.elapsed(), Duration::ZERO)
        }
    };
    let reducing = Instant::now();
    let mut summary = Summary::default();
    if work.statistics {
        let mut selection = Selection::new(work.pixels() as u64);
        while let Some(ask) = selection.ask() {
            let answer = device.reduce(&mut frame, work, std::slice::from_ref(&whole), ask)?;
            selection.answer(answer);
        }
        summary = selection.summary();
    }
    let readback = readback + reducing.elapsed();
    let device_time = device.finish(frame, work)?;
    Ok(Output {
        linear: pixels.linear,
        rgba: pixels.rgba,
        summary,
        phases: Phases {
            setup,
            launches: wall,
            readback,
            convert: pixels.convert,
        },
        device_time,
        wall,
        shares: Vec::new(),
    })
}

/// Runs `work`'s tiles on one device in batches of [`TILES_PER_SUBMIT`], waiting after each
/// when `wait` (progress, and a bound on the work queued at once), else submitting them all
/// without waiting (a frame kept on the device: the caller's next pass is queued behind them).
fn batches<D: Device>(
    (device, frame): (&D, &mut D::Frame),
    (work, wait): (&Work, bool),
    faults: &Faults,
    progress: &mut dyn FnMut(f64),
) -> Result<(), D::Error> {
    let all: Vec<usize> = (0..work.tiles.len()).collect();
    for batch in all.chunks(TILES_PER_SUBMIT) {
        match wait {
            true => device.run(frame, work, batch)?,
            false => device.submit(frame, work, batch)?,
        }
        if let Some(msg) = batch.iter().find_map(|&i| faults.injected(0, i)) {
            return Err(device.fault(msg));
        }
        let done = batch.last().map_or(0, |&i| i + 1);
        progress((done as f64 / all.len().max(1) as f64).min(1.0));
    }
    Ok(())
}

/// The finished pixels of `work`'s tiles on one device, a row of tiles at a time ([`rows`]):
/// each row's launches submitted with its readback queued behind them, the row before
/// collected into the frame's buffer while it renders. Returns the pixels and the time spent
/// reading them back (starting the copies, and copying into the frame's buffer; the waits for
/// the device count among the launches).
fn overlapped<D: Device>(
    device: &D,
    frame: &mut D::Frame,
    work: &Work,
    faults: &Faults,
    progress: &mut dyn FnMut(f64),
) -> Result<(Vec<u8>, Duration), D::Error> {
    let mut rgba = crate::image::pixel_buffer(4 * work.pixels());
    let mut reading = Duration::ZERO;
    let rows = rows(work.tiles);
    let w = work.width as usize;
    let pixels = |r: &Range<u32>| r.start as usize * w..r.end as usize * w;
    // Collects the pixels of `range` from readback buffer `slot`: the time spent copying.
    let collect = |frame: &mut D::Frame, range: Range<usize>, slot, rgba: &mut [u8]| {
        let t = Instant::now();
        let place = Place::Rgba(&mut rgba[4 * range.start..4 * range.end]);
        let collected = device.collect_into(frame, work, range, slot, place)?;
        Ok(t.elapsed().saturating_sub(collected.wait))
    };
    for (i, (tiles, lines)) in rows.iter().enumerate() {
        let tiles: Vec<usize> = tiles.clone().collect();
        device.submit(frame, work, &tiles)?;
        if let Some(msg) = tiles.iter().find_map(|&t| faults.injected(0, t)) {
            return Err(device.fault(msg));
        }
        let t = Instant::now();
        device.start_read(frame, work, pixels(lines), i % 2)?;
        reading += t.elapsed();
        if i > 0 {
            reading += collect(frame, pixels(&rows[i - 1].1), (i - 1) % 2, &mut rgba)?;
            progress(tiles[0] as f64 / work.tiles.len().max(1) as f64);
        }
    }
    if let Some((_, lines)) = rows.last() {
        reading += collect(frame, pixels(lines), (rows.len() - 1) % 2, &mut rgba)?;
    }
    device.check(frame)?;
    progress(1.0);
    Ok((rgba, reading))
}

/// The rows of `tiles` ([`squares`], in the order they cut the image): for each row of
/// tiles, the indices of its tiles and the image rows they cover together (contiguous in the
/// image, so read back as one range).
pub fn rows(tiles: &[Tile]) -> Vec<(Range<usize>, Range<u32>)> {
    let mut out: Vec<(Range<usize>, Range<u32>)> = Vec::new();
    for (i, t) in tiles.iter().enumerate() {
        match out.last_mut() {
            Some((indices, lines)) if lines.start == t.1 => {
                indices.end = i + 1;
                lines.end = lines.end.max(t.1 + t.3);
            }
            _ => out.push((i..i + 1, t.1..t.1 + t.3)),
        }
    }
    out
}

mod several;
#[cfg(test)]
mod tests;

pub use several::{render_several, Bands, Queue, SeveralError, Worker};
