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

use super::reduce::{Answer, Ask, Rounds, Selection, Summary};
use super::Phases;
use std::collections::VecDeque;
use std::ops::Range;
use std::sync::{mpsc, Condvar, Mutex};
use std::time::{Duration, Instant};

/// A tile: x, y, width and height in pixels.
pub type Tile = (u32, u32, u32, u32);

/// Tiles per submission when one device renders a frame: the host waits after each batch
/// (progress, and a bound on how much work is queued at once).
const TILES_PER_SUBMIT: usize = 8;

/// What every device renders of a frame: the kernel's inputs, the image size and the tiles.
#[derive(Debug, Clone, Copy)]
pub struct Job<'a> {
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
    /// Whether to read back the finished pixels (RGBA8, sRGB-encoded on the device: 4 bytes
    /// a pixel) instead of the linear colours (16 bytes a pixel on the device, 12 on the
    /// host): the frame then has no linear image.
    pub finished: bool,
}

impl Job<'_> {
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
/// for a job that asks for them, finished RGBA8 bytes), and how long converting them from the
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
    fn prepare(&self, job: &Job) -> Result<Self::Frame, Self::Error>;
    /// Runs the tiles `tiles` (indices into the job's table) and waits until they are done.
    fn run(&self, frame: &mut Self::Frame, job: &Job, tiles: &[usize]) -> Result<(), Self::Error>;
    /// Reads back the pixels of `ranges` (row-major pixel indices), one after the other.
    fn read(
        &self,
        frame: &mut Self::Frame,
        job: &Job,
        ranges: &[Range<usize>],
    ) -> Result<Pixels, Self::Error>;
    /// Starts the tiles `tiles` without waiting for them: several devices overlap a band's
    /// readback with the next band's launches ([`Device::start_read`]). By default
    /// [`Device::run`], which waits.
    fn submit(
        &self,
        frame: &mut Self::Frame,
        job: &Job,
        tiles: &[usize],
    ) -> Result<(), Self::Error> {
        self.run(frame, job, tiles)
    }
    /// Starts reading back the pixels of `range` once the work submitted so far is done, into
    /// readback buffer `slot` (0 or 1: a band's pixels are collected from one while the next
    /// band's are copied into the other). By default nothing: [`Device::collect`] reads.
    fn start_read(
        &self,
        _frame: &mut Self::Frame,
        _job: &Job,
        _range: Range<usize>,
        _slot: usize,
    ) -> Result<(), Self::Error> {
        Ok(())
    }
    /// The pixels of `range` whose read was started into `slot`, once they are copied (the
    /// work submitted after them may still be running). By default [`Device::read`].
    fn collect(
        &self,
        frame: &mut Self::Frame,
        job: &Job,
        range: Range<usize>,
        _slot: usize,
    ) -> Result<Pixels, Self::Error> {
        self.read(frame, job, std::slice::from_ref(&range))
    }
    /// [`Device::collect`] straight into `place`, the band's place in the image: the pixels
    /// cross the host's memory once, on the worker's thread. Says how long it waited for the
    /// device (the band's launches and its copy across the bus) and converted. By default
    /// `collect`, copied ([`collect_copied`]).
    fn collect_into(
        &self,
        frame: &mut Self::Frame,
        job: &Job,
        range: Range<usize>,
        slot: usize,
        place: Place<'_>,
    ) -> Result<Collected, Self::Error> {
        collect_copied(self, frame, job, (range, slot), place)
    }
    /// The statistics of the pixels of `ranges` (rendered in `frame`) reduced as `ask` asks,
    /// on the device ([`super::reduce`]).
    fn reduce(
        &self,
        frame: &mut Self::Frame,
        job: &Job,
        ranges: &[Range<usize>],
        ask: Ask,
    ) -> Result<Answer, Self::Error>;
    /// Errors the device held back so far (on several devices, each band is checked before
    /// it is accepted).
    fn check(&self, _frame: &mut Self::Frame) -> Result<(), Self::Error> {
        Ok(())
    }
    /// Ends the frame: errors the device held back, and the time of its tiles when the job
    /// is timed and the device can time them.
    fn finish(&self, frame: Self::Frame, job: &Job) -> Result<Option<Duration>, Self::Error>;
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

    /// `pixels` copied in (those the job asked for).
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
    job: &Job,
    (range, slot): (Range<usize>, usize),
    place: Place<'_>,
) -> Result<Collected, D::Error> {
    let pixels = device.collect(frame, job, range, slot)?;
    place.fill(&pixels);
    Ok(Collected {
        wait: Duration::ZERO,
        convert: pixels.convert,
    })
}

/// A frame rendered by the scheduler: its linear colours, or its finished RGBA8 bytes when
/// the job asked for them ([`Job::finished`]).
#[derive(Debug)]
pub struct Output {
    pub linear: Vec<[f32; 3]>,
    pub rgba: Vec<u8>,
    /// The statistics reduced on the devices (empty unless the job asked for them).
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

/// Renders `job` on one device. Finished pixels ([`Job::finished`]): a row of tiles at a
/// time, each row's readback queued behind its launches and the row before collected while
/// it renders, straight into the frame's buffer (one of [`crate::image::pixel_buffer`]'s).
/// Linear colours: the tiles in batches, waiting after each (progress, the injected fault),
/// then the image read back whole.
pub fn render_one<D: Device>(
    device: &D,
    job: &Job,
    faults: &Faults,
    progress: &mut dyn FnMut(f64),
) -> Result<Output, D::Error> {
    let setup = Instant::now();
    let mut frame = device.prepare(job)?;
    let setup = setup.elapsed();
    let start = Instant::now();
    let whole = 0..job.pixels();
    let (pixels, wall, readback) = match job.finished {
        true => {
            let (rgba, collecting) = overlapped(device, &mut frame, job, faults, progress)?;
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
        false => {
            let all: Vec<usize> = (0..job.tiles.len()).collect();
            for batch in all.chunks(TILES_PER_SUBMIT) {
                device.run(&mut frame, job, batch)?;
                if let Some(msg) = batch.iter().find_map(|&i| faults.injected(0, i)) {
                    return Err(device.fault(msg));
                }
                let done = batch.last().map_or(0, |&i| i + 1);
                progress((done as f64 / all.len().max(1) as f64).min(1.0));
            }
            let wall = start.elapsed();
            let readback = Instant::now();
            let pixels = device.read(&mut frame, job, std::slice::from_ref(&whole))?;
            let readback = readback.elapsed().saturating_sub(pixels.convert);
            (pixels, wall, readback)
        }
    };
    let reducing = Instant::now();
    let mut summary = Summary::default();
    if job.statistics {
        let mut selection = Selection::new(job.pixels() as u64);
        while let Some(ask) = selection.ask() {
            let answer = device.reduce(&mut frame, job, std::slice::from_ref(&whole), ask)?;
            selection.answer(answer);
        }
        summary = selection.summary();
    }
    let readback = readback + reducing.elapsed();
    let device_time = device.finish(frame, job)?;
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

/// The finished pixels of `job`'s tiles on one device, a row of tiles at a time ([`rows`]):
/// each row's launches submitted with its readback queued behind them, the row before
/// collected into the frame's buffer while it renders. Returns the pixels and the time spent
/// reading them back (starting the copies, and copying into the frame's buffer; the waits for
/// the device count among the launches).
fn overlapped<D: Device>(
    device: &D,
    frame: &mut D::Frame,
    job: &Job,
    faults: &Faults,
    progress: &mut dyn FnMut(f64),
) -> Result<(Vec<u8>, Duration), D::Error> {
    let mut rgba = crate::image::pixel_buffer(4 * job.pixels());
    let mut reading = Duration::ZERO;
    let rows = rows(job.tiles);
    let w = job.width as usize;
    let pixels = |r: &Range<u32>| r.start as usize * w..r.end as usize * w;
    // Collects the pixels of `range` from readback buffer `slot`: the time spent copying.
    let collect = |frame: &mut D::Frame, range: Range<usize>, slot, rgba: &mut [u8]| {
        let t = Instant::now();
        let place = Place::Rgba(&mut rgba[4 * range.start..4 * range.end]);
        let collected = device.collect_into(frame, job, range, slot, place)?;
        Ok(t.elapsed().saturating_sub(collected.wait))
    };
    for (i, (tiles, lines)) in rows.iter().enumerate() {
        let tiles: Vec<usize> = tiles.clone().collect();
        device.submit(frame, job, &tiles)?;
        if let Some(msg) = tiles.iter().find_map(|&t| faults.injected(0, t)) {
            return Err(device.fault(msg));
        }
        let t = Instant::now();
        device.start_read(frame, job, pixels(lines), i % 2)?;
        reading += t.elapsed();
        if i > 0 {
            reading += collect(frame, pixels(&rows[i - 1].1), (i - 1) % 2, &mut rgba)?;
            progress(tiles[0] as f64 / job.tiles.len().max(1) as f64);
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

/// A device as a worker of [`render_several`] (any [`Device`] is one).
pub trait Worker: Sync {
    /// The device, for messages.
    fn name(&self) -> String;
    /// Takes bands from `bands` until none is left, sending each finished band's pixels.
    fn work(&self, bands: &Bands, position: usize) -> Share;
}

/// Work waiting for whichever worker is free: the bands of a frame, or the frames of a
/// sequence (`sdfc render --frames` on several devices). A worker that fails hands its item
/// back, and the others take it.
#[derive(Debug)]
pub struct Queue<T> {
    state: Mutex<State<T>>,
    changed: Condvar,
}

#[derive(Debug)]
struct State<T> {
    waiting: VecDeque<T>,
    /// Items taken by a worker and not yet finished or handed back.
    taken: usize,
    /// Whether more items may still be pushed.
    open: bool,
    /// Whether the work was given up: no item is handed out any more.
    abandoned: bool,
}

impl<T> Queue<T> {
    /// A queue of `items`; with `open`, more may be [pushed](Queue::push) until
    /// [`Queue::close`].
    pub fn new(items: impl IntoIterator<Item = T>, open: bool) -> Self {
        Queue {
            state: Mutex::new(State {
                waiting: items.into_iter().collect(),
                taken: 0,
                open,
                abandoned: false,
            }),
            changed: Condvar::new(),
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, State<T>> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Adds an item at the back.
    pub fn push(&self, item: T) {
        self.lock().waiting.push_back(item);
        self.changed.notify_all();
    }

    /// No more items will be pushed.
    pub fn close(&self) {
        self.lock().open = false;
        self.changed.notify_all();
    }

    /// Items waiting for a worker.
    pub fn waiting(&self) -> usize {
        self.lock().waiting.len()
    }

    /// The next item if one is waiting now, without waiting for one.
    pub fn try_take(&self) -> Option<T> {
        let mut s = self.lock();
        if s.abandoned {
            return None;
        }
        let item = s.waiting.pop_front()?;
        s.taken += 1;
        Some(item)
    }

    /// The next item, waiting while one may still come (pushed, or handed back by another
    /// worker); `None` when every item is done.
    pub fn take(&self) -> Option<T> {
        let mut s = self.lock();
        loop {
            if s.abandoned {
                return None;
            }
            if let Some(item) = s.waiting.pop_front() {
                s.taken += 1;
                return Some(item);
            }
            if s.taken == 0 && !s.open {
                return None;
            }
            s = self.changed.wait(s).unwrap_or_else(|e| e.into_inner());
        }
    }

    /// What `f` makes of the next item, left waiting for whichever worker takes it, once
    /// one is there (waiting as [`Queue::take`] does); `None` when every item is done.
    pub fn first<R>(&self, f: impl FnOnce(&T) -> R) -> Option<R> {
        let mut s = self.lock();
        loop {
            if s.abandoned {
                return None;
            }
            if let Some(item) = s.waiting.front() {
                return Some(f(item));
            }
            if s.taken == 0 && !s.open {
                return None;
            }
            s = self.changed.wait(s).unwrap_or_else(|e| e.into_inner());
        }
    }

    /// The work is given up (an error, or a worker that panicked holding an item): those
    /// waiting are dropped, and the workers end after the items they hold.
    pub fn abandon(&self) {
        let mut s = self.lock();
        s.open = false;
        s.abandoned = true;
        s.waiting.clear();
        drop(s);
        self.changed.notify_all();
    }

    /// A taken item is finished.
    pub fn done(&self) {
        self.lock().taken -= 1;
        self.changed.notify_all();
    }

    /// A taken item goes back to the front, for another worker.
    pub fn hand_back(&self, item: T) {
        let mut s = self.lock();
        s.taken -= 1;
        s.waiting.push_front(item);
        drop(s);
        self.changed.notify_all();
    }
}

/// The bands of a frame on several devices: the job, the queue of band indices, each band's
/// place in the image, where finished bands are told, the faults to inject, and the rounds of
/// the statistics' reduction when the job asks for them.
#[derive(Debug)]
pub struct Bands<'a> {
    job: &'a Job<'a>,
    faults: &'a Faults,
    queue: Queue<usize>,
    /// Each band's place in the image, written by the worker that collects it (again by
    /// another, if the first failed before the band was accepted).
    places: Vec<Mutex<Place<'a>>>,
    events: mpsc::Sender<Event>,
    rounds: Option<Rounds>,
}

/// What a worker tells the calling thread of [`render_several`].
#[derive(Debug, Clone, Copy)]
enum Event {
    /// A band is in its place in the image.
    Band,
    /// The worker has ended (every band taken, or its device failed): the calling thread
    /// waits for these, not polls, so a frame ends as soon as its last worker does.
    Ended,
}

/// Collecting a band a device rendered, on its worker's thread.
trait Accept: Device {
    /// Collects `band`'s pixels from readback buffer `slot` into the band's place in the
    /// image, checks the device's errors and tells the band finished; the phases and tiles go
    /// to `share`: the wait for the device counts among the launches (as one device's wait
    /// for its tiles does), the copy out as readback.
    fn accept(
        &self,
        frame: &mut Self::Frame,
        bands: &Bands,
        (band, slot): (usize, usize),
        share: &mut Share,
    ) -> Result<(), Self::Error> {
        let job = bands.job;
        let read = Instant::now();
        let collected = {
            let mut place = bands.places[band].lock().unwrap_or_else(|e| e.into_inner());
            self.collect_into(frame, job, job.band(band), slot, place.reborrow())
                .and_then(|c| self.check(frame).map(|()| c))?
        };
        share.phases.launches += collected.wait;
        share.phases.readback += read
            .elapsed()
            .saturating_sub(collected.wait + collected.convert);
        share.phases.convert += collected.convert;
        share.tiles += 1;
        let _ = bands.events.send(Event::Band);
        bands.queue.done();
        Ok(())
    }
}

impl<D: Device> Accept for D {}

impl<D: Device> Worker for D {
    fn name(&self) -> String {
        self.describe()
    }

    fn work(&self, bands: &Bands, position: usize) -> Share {
        let job = bands.job;
        let queue = &bands.queue;
        let mut share = Share {
            device: self.describe(),
            tiles: 0,
            phases: Phases::default(),
            failure: None,
        };
        let setup = Instant::now();
        // Leaves the statistics' rounds when the worker ends without answering them.
        let leave = |lost: bool| {
            if let Some(r) = &bands.rounds {
                r.leave(lost)
            }
        };
        let mut frame = match self.prepare(job) {
            Ok(f) => f,
            Err(e) => {
                leave(false);
                share.failure = Some(e.to_string());
                return share;
            }
        };
        share.phases.setup = setup.elapsed();
        let mut rendered: Vec<Range<usize>> = Vec::new();
        // A band is launched, its readback queued behind it, and the band before it collected
        // while it renders: the device idles only while a band's pixels cross the bus.
        let mut pending: Option<(usize, usize)> = None;
        let mut started = 0;
        let mut next = queue.take();
        while let Some(band) = next {
            let slot = started % 2;
            let launch = Instant::now();
            let ran = match bands.faults.injected(position, started) {
                Some(msg) => Err(self.fault(msg)),
                None => self
                    .submit(&mut frame, job, &[band])
                    .and_then(|()| self.start_read(&mut frame, job, job.band(band), slot)),
            };
            started += 1;
            share.phases.launches += launch.elapsed();
            if let Some((p, p_slot)) = pending.take() {
                if let Err(e) = self.accept(&mut frame, bands, (p, p_slot), &mut share) {
                    queue.hand_back(p);
                    if ran.is_ok() {
                        queue.hand_back(band);
                    }
                    share.failure = Some(e.to_string());
                    break;
                }
                rendered.push(job.band(p));
            }
            if let Err(e) = ran {
                queue.hand_back(band);
                share.failure = Some(e.to_string());
                break;
            }
            pending = Some((band, slot));
            // The next band if one is waiting; else the pending band is collected first, then
            // whatever comes (a band another device hands back).
            next = queue.try_take();
            if next.is_none() {
                if let Some((p, p_slot)) = pending.take() {
                    if let Err(e) = self.accept(&mut frame, bands, (p, p_slot), &mut share) {
                        queue.hand_back(p);
                        share.failure = Some(e.to_string());
                        break;
                    }
                    rendered.push(job.band(p));
                }
                next = queue.take();
            }
        }
        // Every band is rendered (or this device failed): the statistics of the bands this
        // device rendered, a round at a time with the other devices. A device that failed
        // answers for the bands it rendered before, if it still can.
        if let Some(rounds) = &bands.rounds {
            let read = Instant::now();
            let mut round = 0;
            while let Some(ask) = rounds.ask(round) {
                match self.reduce(&mut frame, job, &rendered, ask) {
                    Ok(answer) => rounds.answer(answer),
                    Err(e) => {
                        rounds.leave(!rendered.is_empty());
                        share.failure.get_or_insert(e.to_string());
                        return share;
                    }
                }
                round += 1;
            }
            share.phases.readback += read.elapsed();
        }
        if share.failure.is_some() {
            return share;
        }
        if let Err(e) = self.finish(frame, job) {
            share.failure = Some(e.to_string());
        }
        share
    }
}

/// Why a frame on several devices failed: every device did, before the frame's tiles were
/// all rendered.
#[derive(Debug, Clone, PartialEq)]
pub struct SeveralError {
    /// The tiles rendered before the last device failed.
    pub rendered: usize,
    /// The frame's tiles.
    pub tiles: usize,
    /// Each failed device: its position in the list, its description and why it failed.
    pub failures: Vec<(usize, String, String)>,
}

impl std::fmt::Display for SeveralError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "every device failed ({} of {} tiles rendered): ",
            self.rendered, self.tiles
        )?;
        for (k, (i, device, why)) in self.failures.iter().enumerate() {
            let sep = if k == 0 { "" } else { "; " };
            write!(f, "{sep}device {i} ({device}): {why}")?;
        }
        Ok(())
    }
}

impl std::error::Error for SeveralError {}

/// Renders `job` (whose tiles are bands, [`tiling`]) on several devices at once: each
/// device's worker takes the next band from one queue; the bands are assembled in order. A
/// device that fails hands its band back; the frame fails only when every device has.
pub fn render_several(
    devices: &[&dyn Worker],
    job: &Job,
    faults: &Faults,
    progress: &mut dyn FnMut(f64),
) -> Result<Output, SeveralError> {
    let start = Instant::now();
    let (tx, rx) = mpsc::channel();
    let pixels = job.pixels();
    // The finished pixels go into a buffer an earlier frame handed back when there is one
    // (every band overwrites its place), its pages in memory already.
    let (mut linear, mut rgba) = match job.finished {
        true => (Vec::new(), crate::image::pixel_buffer(4 * pixels)),
        false => (crate::image::zeroed(pixels), Vec::new()),
    };
    let bands = Bands {
        job,
        faults,
        queue: Queue::new(0..job.tiles.len(), false),
        places: places(job, &mut rgba, &mut linear),
        events: tx,
        rounds: job
            .statistics
            .then(|| Rounds::new(job.pixels() as u64, devices.len())),
    };
    let mut done = 0usize;
    let shares = std::thread::scope(|scope| {
        let bands = &bands;
        let handles: Vec<_> = devices
            .iter()
            .enumerate()
            .map(|(i, d)| {
                let work = move || {
                    let run = std::panic::AssertUnwindSafe(|| d.work(bands, i));
                    let share = std::panic::catch_unwind(run).unwrap_or_else(|_| {
                        // Its band is lost: the frame cannot be finished.
                        bands.queue.abandon();
                        if let Some(r) = &bands.rounds {
                            r.leave(true);
                        }
                        Share {
                            device: d.name(),
                            tiles: 0,
                            phases: Phases::default(),
                            failure: Some("its worker panicked".into()),
                        }
                    });
                    let _ = bands.events.send(Event::Ended);
                    share
                };
                (i, scope.spawn(work))
            })
            .collect();
        // The workers put the bands in their places; the calling thread counts them, and
        // the workers' ends, until every worker has ended (each says so last, panicked or
        // not, so the count is reached).
        let mut ended = 0;
        while ended < devices.len() {
            match rx.recv() {
                Ok(Event::Band) => {
                    done += 1;
                    progress(done as f64 / job.tiles.len().max(1) as f64);
                }
                Ok(Event::Ended) => ended += 1,
                Err(_) => break,
            }
        }
        let mut shares: Vec<(usize, Share)> = Vec::new();
        for (i, h) in handles {
            let share = h.join().unwrap_or_else(|_| Share {
                device: devices[i].name(),
                tiles: 0,
                phases: Phases::default(),
                failure: Some("its worker panicked".into()),
            });
            shares.push((i, share));
        }
        shares.sort_by_key(|(i, _)| *i);
        shares.into_iter().map(|(_, s)| s).collect::<Vec<_>>()
    });
    if done < job.tiles.len() {
        return Err(SeveralError {
            rendered: done,
            tiles: job.tiles.len(),
            failures: shares
                .iter()
                .enumerate()
                .filter_map(|(i, s)| {
                    let why = s.failure.clone()?;
                    Some((i, s.device.clone(), why))
                })
                .collect(),
        });
    }
    let wall = start.elapsed();
    // The workers ran side by side and put the bands in place: the frame's phases are those
    // of the one that took longest (the frame waited for it).
    let phases = shares
        .iter()
        .map(|s| s.phases)
        .max_by_key(|p| p.total())
        .unwrap_or_default();
    let Bands { rounds, .. } = bands;
    let summary = rounds.map_or_else(Summary::default, |r| r.summary().0);
    Ok(Output {
        linear,
        rgba,
        summary,
        phases,
        device_time: None,
        wall,
        shares,
    })
}

/// Each band's place in the image (`rgba` for a job of finished pixels, else `linear`), in
/// the order of the job's bands, which follow each other from the first row.
fn places<'a>(job: &Job, rgba: &'a mut [u8], linear: &'a mut [[f32; 3]]) -> Vec<Mutex<Place<'a>>> {
    let mut places = Vec::with_capacity(job.tiles.len());
    let (mut rgba, mut linear) = (rgba, linear);
    for i in 0..job.tiles.len() {
        let band = job.band(i);
        debug_assert_eq!(
            band.start,
            job.band(i.saturating_sub(1)).end * usize::from(i > 0),
            "bands follow each other"
        );
        let place = match job.finished {
            true => {
                let (here, rest) = std::mem::take(&mut rgba).split_at_mut(4 * band.len());
                rgba = rest;
                Place::Rgba(here)
            }
            false => {
                let (here, rest) = std::mem::take(&mut linear).split_at_mut(band.len());
                linear = rest;
                Place::Linear(here)
            }
        };
        places.push(Mutex::new(place));
    }
    places
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fake device's failure: what it says.
    #[derive(Debug)]
    struct Failed(String);

    impl std::fmt::Display for Failed {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.write_str(&self.0)
        }
    }

    #[test]
    fn squares_cover_the_image_once() {
        let t = squares(100, 70, 32);
        assert_eq!(t.len(), 4 * 3);
        let area: u32 = t.iter().map(|t| t.2 * t.3).sum();
        assert_eq!(area, 100 * 70);
    }

    #[test]
    fn rows_of_squares_cover_the_image_once() {
        for (w, h) in [(1920, 1080), (7680, 4320), (4100, 16), (3840, 2160), (1, 1)] {
            let tiles = squares(w, h, 2048);
            let rows = rows(&tiles);
            assert_eq!(rows.len() as u32, h.div_ceil(2048), "{w}x{h}");
            assert_eq!((rows[0].1.start, rows[rows.len() - 1].1.end), (0, h));
            assert!(rows.windows(2).all(|p| p[0].1.end == p[1].1.start));
            assert!(rows.windows(2).all(|p| p[0].0.end == p[1].0.start));
            assert_eq!(rows[rows.len() - 1].0.end, tiles.len());
            for (indices, lines) in &rows {
                let covered: u32 = indices.clone().map(|i| tiles[i].2).sum();
                assert_eq!(covered, w, "a row of tiles spans the width");
                assert!(indices
                    .clone()
                    .all(|i| tiles[i].1 == lines.start && tiles[i].1 + tiles[i].3 == lines.end));
            }
        }
    }

    #[test]
    fn bands_cover_the_image_once_in_whole_rows() {
        for (w, h, n) in [(7680, 4320, 2), (100, 70, 3), (1, 1, 2), (640, 480, 4)] {
            let t = tiling(w, h, 512, n);
            assert!(t.iter().all(|t| t.0 == 0 && t.2 == w));
            assert_eq!(t.iter().map(|t| t.3).sum::<u32>(), h);
            assert!(t.windows(2).all(|p| p[0].1 + p[0].3 == p[1].1));
            let fewest = (BANDS_PER_DEVICE as usize * n).min(h as usize);
            assert!(t.len() >= fewest, "{w}x{h}: {}", t.len());
        }
    }

    /// A device that "renders" a pixel as its index, and fails on its `fails`-th tile
    /// (counting in `failed` the devices that failed); one with `wait` renders nothing until
    /// one has failed, so that the others take tiles whatever the threads' scheduling.
    struct Fake<'a> {
        fails: Option<usize>,
        wait: bool,
        failed: &'a std::sync::atomic::AtomicUsize,
    }

    impl Device for Fake<'_> {
        type Frame = usize;
        type Error = Failed;
        fn describe(&self) -> String {
            "fake".into()
        }
        fn prepare(&self, _job: &Job) -> Result<usize, Self::Error> {
            Ok(0)
        }
        fn run(&self, ran: &mut usize, _job: &Job, tiles: &[usize]) -> Result<(), Self::Error> {
            use std::sync::atomic::Ordering;
            while self.wait && self.failed.load(Ordering::SeqCst) == 0 {
                std::thread::yield_now();
            }
            *ran += tiles.len();
            match self.fails {
                Some(n) if *ran > n => {
                    self.failed.fetch_add(1, Ordering::SeqCst);
                    Err(Failed("lost".into()))
                }
                _ => Ok(()),
            }
        }
        fn read(
            &self,
            _: &mut usize,
            _: &Job,
            ranges: &[Range<usize>],
        ) -> Result<Pixels, Self::Error> {
            let mut p = Pixels::default();
            for r in ranges {
                p.linear.extend(r.clone().map(|i| [i as f32, 0.0, 0.0]));
            }
            Ok(p)
        }
        /// A pixel's steps are its index.
        fn reduce(
            &self,
            _: &mut usize,
            _: &Job,
            ranges: &[Range<usize>],
            ask: Ask,
        ) -> Result<Answer, Self::Error> {
            let steps: Vec<u32> = ranges
                .iter()
                .flat_map(|r| r.clone())
                .map(|i| i as u32)
                .collect();
            let counters = crate::cpu::Counters {
                steps: steps.iter().map(|&s| s as u64).sum(),
                ..Default::default()
            };
            Ok(Answer::of_steps(&steps, &counters, ask))
        }
        fn finish(&self, _: usize, _: &Job) -> Result<Option<Duration>, Self::Error> {
            Ok(None)
        }
        fn fault(&self, message: String) -> Failed {
            Failed(message)
        }
    }

    #[test]
    fn several_devices_assemble_the_bands_in_order_and_survive_a_failing_one() {
        let tiles = tiling(37, 29, 512, 3);
        let job = Job {
            uniforms: &[],
            data: None,
            width: 37,
            height: 29,
            tiles: &tiles,
            timed: false,
            statistics: true,
            finished: false,
        };
        let failed = std::sync::atomic::AtomicUsize::new(0);
        let good = Fake {
            fails: None,
            wait: true,
            failed: &failed,
        };
        let lost = Fake {
            fails: Some(1),
            wait: false,
            failed: &failed,
        };
        let devices: [&dyn Worker; 3] = [&lost, &good, &lost];
        let out =
            render_several(&devices, &job, &Faults::default(), &mut |_| {}).expect("one survives");
        let n = 37 * 29;
        assert!(out.linear.iter().enumerate().all(|(i, p)| p[0] == i as f32));
        // The statistics of the bands every device rendered, reduced a round at a time: those
        // of the whole frame (the failed devices' bands were rendered again by the good one).
        assert_eq!(out.summary.counters.steps, (0..n as u64).sum::<u64>());
        assert_eq!(out.summary.max, n as u32 - 1);
        assert_eq!(out.summary.p99, ((n - 1) as f64 * 0.99).round() as u32);
        // The good device waited for a failure; a device that failed had rendered one band.
        assert_eq!(out.shares[1].failure, None);
        let lost_shares = [&out.shares[0], &out.shares[2]];
        assert!(lost_shares
            .iter()
            .any(|s| s.failure.as_deref() == Some("lost")));
        assert!(lost_shares.iter().all(|s| s.tiles <= 1));
        assert_eq!(
            out.shares.iter().map(|s| s.tiles).sum::<usize>(),
            tiles.len()
        );
        // Every device fails: an error naming each.
        let devices: [&dyn Worker; 2] = [&lost, &lost];
        let err =
            render_several(&devices, &job, &Faults::default(), &mut |_| {}).expect_err("all fail");
        let text = err.to_string();
        assert!(text.starts_with("every device failed (2 of "), "{text}");
        assert!(
            text.contains("device 0 (fake): lost; device 1 (fake): lost"),
            "{text}"
        );
        let devices: Vec<_> = err
            .failures
            .iter()
            .map(|(i, _, why)| (*i, why.as_str()))
            .collect();
        assert_eq!(devices, [(0, "lost"), (1, "lost")]);
    }

    /// A device whose reads are started behind its launches and collected later (as the GPU
    /// devices' are): a band's pixels are its indices, copied at `start_read` into one of two
    /// slots; what it did is logged.
    struct Overlapping<'a> {
        log: &'a Mutex<Vec<(usize, &'static str, usize)>>,
        id: usize,
    }

    impl Device for Overlapping<'_> {
        type Frame = [Option<Range<usize>>; 2];
        type Error = Failed;
        fn describe(&self) -> String {
            "overlapping".into()
        }
        fn prepare(&self, _job: &Job) -> Result<Self::Frame, Self::Error> {
            Ok([None, None])
        }
        fn run(&self, _: &mut Self::Frame, _: &Job, _: &[usize]) -> Result<(), Self::Error> {
            Err(Failed("run is not called: bands are submitted".into()))
        }
        fn submit(
            &self,
            _: &mut Self::Frame,
            job: &Job,
            tiles: &[usize],
        ) -> Result<(), Self::Error> {
            let band = job.band(tiles[0]);
            self.log
                .lock()
                .expect("log")
                .push((self.id, "submit", band.start));
            Ok(())
        }
        fn start_read(
            &self,
            slots: &mut Self::Frame,
            _: &Job,
            range: Range<usize>,
            slot: usize,
        ) -> Result<(), Self::Error> {
            // The slot is free: its band was collected before it is used again.
            assert!(slots[slot].is_none(), "slot {slot} still holds a band");
            self.log
                .lock()
                .expect("log")
                .push((self.id, "start", range.start));
            slots[slot] = Some(range);
            Ok(())
        }
        fn collect(
            &self,
            slots: &mut Self::Frame,
            _: &Job,
            range: Range<usize>,
            slot: usize,
        ) -> Result<Pixels, Self::Error> {
            assert_eq!(slots[slot].take().as_ref(), Some(&range), "slot {slot}");
            self.log
                .lock()
                .expect("log")
                .push((self.id, "collect", range.start));
            Ok(Pixels {
                linear: range.map(|i| [i as f32, 0.0, 0.0]).collect(),
                ..Pixels::default()
            })
        }
        fn read(
            &self,
            _: &mut Self::Frame,
            _: &Job,
            _: &[Range<usize>],
        ) -> Result<Pixels, Self::Error> {
            Err(Failed("read is not called: bands are collected".into()))
        }
        fn reduce(
            &self,
            _: &mut Self::Frame,
            _: &Job,
            _: &[Range<usize>],
            ask: Ask,
        ) -> Result<Answer, Self::Error> {
            Ok(Answer::empty(ask))
        }
        fn finish(&self, slots: Self::Frame, _: &Job) -> Result<Option<Duration>, Self::Error> {
            assert_eq!(slots, [None, None], "every band collected");
            Ok(None)
        }
        fn fault(&self, message: String) -> Failed {
            Failed(message)
        }
    }

    #[test]
    fn a_band_is_collected_while_the_next_one_renders() {
        let tiles = tiling(16, 64, 512, 2);
        let job = Job {
            uniforms: &[],
            data: None,
            width: 16,
            height: 64,
            tiles: &tiles,
            timed: false,
            statistics: false,
            finished: false,
        };
        let log = Mutex::new(Vec::new());
        let (a, b) = (
            Overlapping { log: &log, id: 0 },
            Overlapping { log: &log, id: 1 },
        );
        let devices: [&dyn Worker; 2] = [&a, &b];
        let out = render_several(&devices, &job, &Faults::default(), &mut |_| {}).expect("renders");
        assert!(out.linear.iter().enumerate().all(|(i, p)| p[0] == i as f32));
        let log = log.into_inner().expect("log");
        for band in tiles.iter().map(|t| t.1 as usize * 16) {
            let at = |what| log.iter().filter(|e| e.1 == what && e.2 == band).count();
            assert_eq!(
                (at("submit"), at("start"), at("collect")),
                (1, 1, 1),
                "band {band}"
            );
        }
        // A device that rendered two bands or more submitted the next before collecting the
        // one before.
        for id in [0, 1] {
            let mine: Vec<_> = log.iter().filter(|e| e.0 == id).map(|e| e.1).collect();
            if mine.iter().filter(|&&w| w == "submit").count() >= 2 {
                let first_collect = mine.iter().position(|&w| w == "collect").expect("collects");
                let submits_before = mine[..first_collect].iter().filter(|&&w| w == "submit");
                assert_eq!(submits_before.count(), 2, "device {id}: {mine:?}");
            }
        }
    }

    #[test]
    fn a_queue_waits_for_items_handed_back_and_ends_when_abandoned() {
        let q = Queue::new([1, 2], false);
        assert_eq!(q.take(), Some(1));
        assert_eq!(q.take(), Some(2));
        q.hand_back(2);
        assert_eq!(q.take(), Some(2));
        q.done();
        // One item is still taken: another worker waits for it until it is done.
        std::thread::scope(|s| {
            let waiter = s.spawn(|| q.take());
            std::thread::sleep(Duration::from_millis(20));
            q.done();
            assert_eq!(waiter.join().expect("joins"), None);
        });
        let open = Queue::new([7], true);
        assert_eq!(open.take(), Some(7));
        open.abandon();
        assert_eq!(open.take(), None);
    }

    #[test]
    fn the_first_item_is_seen_without_taking_it() {
        let q = Queue::new(std::iter::empty::<u32>(), true);
        std::thread::scope(|s| {
            // A worker looking before anything is pushed waits for the first item.
            let looker = s.spawn(|| q.first(|&k| k * 10));
            std::thread::sleep(Duration::from_millis(20));
            q.push(3);
            assert_eq!(looker.join().expect("joins"), Some(30));
        });
        // Seen, not taken: it is still there for whichever worker takes it.
        assert_eq!(q.waiting(), 1);
        assert_eq!(q.take(), Some(3));
        q.done();
        q.close();
        assert_eq!(q.first(|&k| k), None);
    }

    /// One device whose finished pixels are read back into two slots, started behind the
    /// launches and collected later: a pixel's bytes are its index's; what it did is logged.
    struct Rows {
        log: Mutex<Vec<(&'static str, usize)>>,
    }

    impl Device for Rows {
        type Frame = [Option<Range<usize>>; 2];
        type Error = Failed;
        fn describe(&self) -> String {
            "rows".into()
        }
        fn prepare(&self, _job: &Job) -> Result<Self::Frame, Self::Error> {
            Ok([None, None])
        }
        fn run(&self, _: &mut Self::Frame, _: &Job, _: &[usize]) -> Result<(), Self::Error> {
            Err(Failed("run is not called: rows are submitted".into()))
        }
        fn submit(&self, _: &mut Self::Frame, _: &Job, tiles: &[usize]) -> Result<(), Self::Error> {
            let mut log = self.log.lock().expect("log");
            log.extend(tiles.iter().map(|&t| ("submit", t)));
            Ok(())
        }
        fn start_read(
            &self,
            slots: &mut Self::Frame,
            _: &Job,
            range: Range<usize>,
            slot: usize,
        ) -> Result<(), Self::Error> {
            assert!(slots[slot].is_none(), "slot {slot} still holds a row");
            self.log.lock().expect("log").push(("start", range.start));
            slots[slot] = Some(range);
            Ok(())
        }
        fn collect(
            &self,
            slots: &mut Self::Frame,
            _: &Job,
            range: Range<usize>,
            slot: usize,
        ) -> Result<Pixels, Self::Error> {
            assert_eq!(slots[slot].take().as_ref(), Some(&range), "slot {slot}");
            self.log.lock().expect("log").push(("collect", range.start));
            Ok(Pixels {
                rgba: range.flat_map(|i| [i as u8; 4]).collect(),
                ..Pixels::default()
            })
        }
        fn read(
            &self,
            _: &mut Self::Frame,
            _: &Job,
            _: &[Range<usize>],
        ) -> Result<Pixels, Self::Error> {
            Err(Failed("read is not called: rows are collected".into()))
        }
        fn reduce(
            &self,
            _: &mut Self::Frame,
            _: &Job,
            _: &[Range<usize>],
            ask: Ask,
        ) -> Result<Answer, Self::Error> {
            Ok(Answer::empty(ask))
        }
        fn finish(&self, slots: Self::Frame, _: &Job) -> Result<Option<Duration>, Self::Error> {
            assert_eq!(slots, [None, None], "every row collected");
            Ok(None)
        }
        fn fault(&self, message: String) -> Failed {
            Failed(message)
        }
    }

    #[test]
    fn one_device_collects_a_row_of_tiles_while_the_next_renders() {
        // Squares of 8 pixels over 20×20: three rows of three tiles (8, 8 and 4 pixels high).
        let tiles = squares(20, 20, 8);
        let job = Job {
            uniforms: &[],
            data: None,
            width: 20,
            height: 20,
            tiles: &tiles,
            timed: false,
            statistics: false,
            finished: true,
        };
        let rows = Rows {
            log: Mutex::new(Vec::new()),
        };
        let out = render_one(&rows, &job, &Faults::default(), &mut |_| {}).expect("renders");
        let expected: Vec<u8> = (0..400).flat_map(|i| [i as u8; 4]).collect();
        assert_eq!(out.rgba, expected);
        let log = rows.log.lock().expect("log").clone();
        let s = |t| ("submit", t);
        assert_eq!(
            log,
            [
                s(0),
                s(1),
                s(2),
                ("start", 0),
                s(3),
                s(4),
                s(5),
                ("start", 160),
                ("collect", 0),
                s(6),
                s(7),
                s(8),
                ("start", 320),
                ("collect", 160),
                ("collect", 320),
            ]
        );
        // A fault at the fifth tile ends the frame after its row was submitted.
        let rows = Rows {
            log: Mutex::new(Vec::new()),
        };
        let faults = Faults::parse("4").expect("parses");
        let err = render_one(&rows, &job, &faults, &mut |_| {}).expect_err("fails");
        assert!(err.0.contains("injected at tile 5"), "{err}");
    }

    #[test]
    fn faults_parse_per_device() {
        let f = Faults::parse("1:2, 5").expect("parses");
        assert_eq!(f.after(0), Some(5));
        assert_eq!(f.after(1), Some(2));
        assert!(Faults::parse("x").is_none());
        assert!(Faults::parse("1:").is_none());
        let one = Faults::parse("1").expect("parses");
        assert_eq!(
            one.injected(0, 1).as_deref(),
            Some("device error injected at tile 2 by SDFC_FAULT_AFTER_TILES=1 (a testing aid)")
        );
    }
}
