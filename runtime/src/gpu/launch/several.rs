//! Several devices rendering one frame: each device's worker takes the next band of whole rows
//! from one [`Queue`], reads it back into its place in the image, and hands it back when its
//! device fails, so that the others finish the frame ([`render_several`]).

use super::{Device, Faults, Output, Place, Share, Work};
use crate::gpu::reduce::{Rounds, Summary};
use crate::gpu::Phases;
use std::collections::VecDeque;
use std::ops::Range;
use std::sync::{mpsc, Condvar, Mutex};
use std::time::Instant;

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

/// The bands of a frame on several devices: the work, the queue of band indices, each band's
/// place in the image, where finished bands are told, the faults to inject, and the rounds of
/// the statistics' reduction when the work asks for them.
#[derive(Debug)]
pub struct Bands<'a> {
    work: &'a Work<'a>,
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
        let work = bands.work;
        let read = Instant::now();
        let collected = {
            let mut place = bands.places[band].lock().unwrap_or_else(|e| e.into_inner());
            self.collect_into(frame, work, work.band(band), slot, place.reborrow())
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
        let work = bands.work;
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
        let mut frame = match self.prepare(work) {
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
                    .submit(&mut frame, work, &[band])
                    .and_then(|()| self.start_read(&mut frame, work, work.band(band), slot)),
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
                rendered.push(work.band(p));
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
                    rendered.push(work.band(p));
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
                match self.reduce(&mut frame, work, &rendered, ask) {
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
        if let Err(e) = self.finish(frame, work) {
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

/// Renders `work` (whose tiles are bands, [`tiling`]) on several devices at once: each
/// device's worker takes the next band from one queue; the bands are assembled in order. A
/// device that fails hands its band back; the frame fails only when every device has.
pub fn render_several(
    devices: &[&dyn Worker],
    work: &Work,
    faults: &Faults,
    progress: &mut dyn FnMut(f64),
) -> Result<Output, SeveralError> {
    let start = Instant::now();
    let (tx, rx) = mpsc::channel();
    let pixels = work.pixels();
    // The finished pixels go into a buffer an earlier frame handed back when there is one
    // (every band overwrites its place), its pages in memory already.
    let (mut linear, mut rgba) = match work.finished() {
        true => (Vec::new(), crate::image::pixel_buffer(4 * pixels)),
        false => (crate::image::zeroed(pixels), Vec::new()),
    };
    let bands = Bands {
        work,
        faults,
        queue: Queue::new(0..work.tiles.len(), false),
        places: places(work, &mut rgba, &mut linear),
        events: tx,
        rounds: work
            .statistics
            .then(|| Rounds::new(work.pixels() as u64, devices.len())),
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
                    progress(done as f64 / work.tiles.len().max(1) as f64);
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
    if done < work.tiles.len() {
        return Err(SeveralError {
            rendered: done,
            tiles: work.tiles.len(),
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

/// Each band's place in the image (`rgba` where the work asks for finished pixels, else
/// `linear`), in the order of the work's bands, which follow each other from the first row.
fn places<'a>(
    work: &Work,
    rgba: &'a mut [u8],
    linear: &'a mut [[f32; 3]],
) -> Vec<Mutex<Place<'a>>> {
    let mut places = Vec::with_capacity(work.tiles.len());
    let (mut rgba, mut linear) = (rgba, linear);
    for i in 0..work.tiles.len() {
        let band = work.band(i);
        debug_assert_eq!(
            band.start,
            work.band(i.saturating_sub(1)).end * usize::from(i > 0),
            "bands follow each other"
        );
        let place = match work.finished() {
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
