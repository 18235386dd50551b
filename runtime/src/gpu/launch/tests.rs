//! Tests of the tile scheduler with fake devices: tilings, one device's overlapped rows, several
//! devices' bands and their failures, injected faults.

use super::*;
use std::sync::Mutex;

/// The work of `tiles` over a `width`×`height` image, untimed and without statistics, its
/// pixels going to `target`.
fn plain(tiles: &[Tile], (width, height): (u32, u32), target: Target) -> Work<'_> {
    Work {
        uniforms: &[],
        data: None,
        width,
        height,
        tiles,
        timed: false,
        statistics: false,
        target,
    }
}

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
    fn prepare(&self, _work: &Work) -> Result<usize, Self::Error> {
        Ok(0)
    }
    fn run(&self, ran: &mut usize, _work: &Work, tiles: &[usize]) -> Result<(), Self::Error> {
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
        _: &Work,
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
        _: &Work,
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
    fn finish(&self, _: usize, _: &Work) -> Result<Option<Duration>, Self::Error> {
        Ok(None)
    }
    fn fault(&self, message: String) -> Failed {
        Failed(message)
    }
}

#[test]
fn several_devices_assemble_the_bands_in_order_and_survive_a_failing_one() {
    let tiles = tiling(37, 29, 512, 3);
    let work = Work {
        statistics: true,
        ..plain(&tiles, (37, 29), Target::Linear)
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
        render_several(&devices, &work, &Faults::default(), &mut |_| {}).expect("one survives");
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
        render_several(&devices, &work, &Faults::default(), &mut |_| {}).expect_err("all fail");
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
/// devices' are), copied at `start_read` into one of two slots; what it did is logged as
/// (device, step, first pixel or tile). Of `bands`, a band's pixels are its indices and a
/// submission is logged by its band's first pixel; else (rows of tiles, finished pixels) a
/// pixel's bytes are its index's and every tile submitted is logged.
struct Slotted<'a> {
    log: &'a Mutex<Vec<(usize, &'static str, usize)>>,
    id: usize,
    bands: bool,
}

impl Slotted<'_> {
    /// What the device reads back at once: a band or a row of tiles.
    fn unit(&self) -> &'static str {
        if self.bands {
            "band"
        } else {
            "row"
        }
    }

    fn log(&self, step: &'static str, at: usize) {
        self.log.lock().expect("log").push((self.id, step, at));
    }
}

impl Device for Slotted<'_> {
    type Frame = [Option<Range<usize>>; 2];
    type Error = Failed;
    fn describe(&self) -> String {
        if self.bands { "overlapping" } else { "rows" }.into()
    }
    fn prepare(&self, _work: &Work) -> Result<Self::Frame, Self::Error> {
        Ok([None, None])
    }
    fn run(&self, _: &mut Self::Frame, _: &Work, _: &[usize]) -> Result<(), Self::Error> {
        let unit = self.unit();
        Err(Failed(format!("run is not called: {unit}s are submitted")))
    }
    fn submit(&self, _: &mut Self::Frame, work: &Work, tiles: &[usize]) -> Result<(), Self::Error> {
        if self.bands {
            self.log("submit", work.band(tiles[0]).start);
        } else {
            tiles.iter().for_each(|&t| self.log("submit", t));
        }
        Ok(())
    }
    fn start_read(
        &self,
        slots: &mut Self::Frame,
        _: &Work,
        range: Range<usize>,
        slot: usize,
    ) -> Result<(), Self::Error> {
        // The slot is free: its band was collected before it is used again.
        let unit = self.unit();
        assert!(slots[slot].is_none(), "slot {slot} still holds a {unit}");
        self.log("start", range.start);
        slots[slot] = Some(range);
        Ok(())
    }
    fn collect(
        &self,
        slots: &mut Self::Frame,
        _: &Work,
        range: Range<usize>,
        slot: usize,
    ) -> Result<Pixels, Self::Error> {
        assert_eq!(slots[slot].take().as_ref(), Some(&range), "slot {slot}");
        self.log("collect", range.start);
        Ok(if self.bands {
            Pixels {
                linear: range.map(|i| [i as f32, 0.0, 0.0]).collect(),
                ..Pixels::default()
            }
        } else {
            Pixels {
                rgba: range.flat_map(|i| [i as u8; 4]).collect(),
                ..Pixels::default()
            }
        })
    }
    fn read(
        &self,
        _: &mut Self::Frame,
        _: &Work,
        _: &[Range<usize>],
    ) -> Result<Pixels, Self::Error> {
        let unit = self.unit();
        Err(Failed(format!("read is not called: {unit}s are collected")))
    }
    fn reduce(
        &self,
        _: &mut Self::Frame,
        _: &Work,
        _: &[Range<usize>],
        ask: Ask,
    ) -> Result<Answer, Self::Error> {
        Ok(Answer::empty(ask))
    }
    fn finish(&self, slots: Self::Frame, _: &Work) -> Result<Option<Duration>, Self::Error> {
        let unit = self.unit();
        assert_eq!(slots, [None, None], "every {unit} collected");
        Ok(None)
    }
    fn fault(&self, message: String) -> Failed {
        Failed(message)
    }
}

#[test]
fn a_band_is_collected_while_the_next_one_renders() {
    let tiles = tiling(16, 64, 512, 2);
    let work = plain(&tiles, (16, 64), Target::Linear);
    let log = Mutex::new(Vec::new());
    let band = |id| Slotted {
        log: &log,
        id,
        bands: true,
    };
    let (a, b) = (band(0), band(1));
    let devices: [&dyn Worker; 2] = [&a, &b];
    let out = render_several(&devices, &work, &Faults::default(), &mut |_| {}).expect("renders");
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

#[test]
fn one_device_collects_a_row_of_tiles_while_the_next_renders() {
    // Squares of 8 pixels over 20×20: three rows of three tiles (8, 8 and 4 pixels high).
    let tiles = squares(20, 20, 8);
    let work = plain(&tiles, (20, 20), Target::Finished);
    let log = Mutex::new(Vec::new());
    let rows = Slotted {
        log: &log,
        id: 0,
        bands: false,
    };
    let out = render_one(&rows, &work, &Faults::default(), &mut |_| {}).expect("renders");
    let expected: Vec<u8> = (0..400).flat_map(|i| [i as u8; 4]).collect();
    assert_eq!(out.rgba, expected);
    let log: Vec<_> = log.into_inner().expect("log");
    let log: Vec<_> = log.into_iter().map(|(_, step, at)| (step, at)).collect();
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
    let log = Mutex::new(Vec::new());
    let rows = Slotted {
        log: &log,
        id: 0,
        bands: false,
    };
    let faults = Faults::parse("4").expect("parses");
    let err = render_one(&rows, &work, &faults, &mut |_| {}).expect_err("fails");
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

/// A device that logs the steps the scheduler asks of it.
#[derive(Default)]
struct Logged(Mutex<Vec<&'static str>>);

impl Logged {
    fn log(&self, step: &'static str) {
        self.0.lock().expect("the log").push(step);
    }
}

impl Device for Logged {
    type Frame = ();
    type Error = Failed;
    fn describe(&self) -> String {
        "logged".into()
    }
    fn prepare(&self, _: &Work) -> Result<(), Failed> {
        self.log("prepare");
        Ok(())
    }
    fn run(&self, _: &mut (), _: &Work, _: &[usize]) -> Result<(), Failed> {
        self.log("run");
        Ok(())
    }
    fn submit(&self, _: &mut (), _: &Work, _: &[usize]) -> Result<(), Failed> {
        self.log("submit");
        Ok(())
    }
    fn read(&self, _: &mut (), _: &Work, _: &[Range<usize>]) -> Result<Pixels, Failed> {
        self.log("read");
        Ok(Pixels::default())
    }
    fn reduce(&self, _: &mut (), _: &Work, _: &[Range<usize>], a: Ask) -> Result<Answer, Failed> {
        self.log("reduce");
        Ok(Answer::empty(a))
    }
    fn finish(&self, _: (), _: &Work) -> Result<Option<Duration>, Failed> {
        self.log("finish");
        Ok(None)
    }
    fn fault(&self, message: String) -> Failed {
        Failed(message)
    }
}

#[test]
fn a_frame_kept_on_the_device_is_submitted_without_waiting_and_never_read_back() {
    // 20 tiles: three batches.
    let tiles = squares(80, 64, 16);
    let mut work = plain(&tiles, (80, 64), Target::Resident);
    let device = Logged::default();
    let mut done = Vec::new();
    let out = render_one(&device, &work, &Faults::default(), &mut |p| done.push(p)).expect("kept");
    assert!(out.linear.is_empty() && out.rgba.is_empty());
    let log = std::mem::take(&mut *device.0.lock().expect("the log"));
    assert_eq!(log, ["prepare", "submit", "submit", "submit", "finish"]);
    assert_eq!(done.last(), Some(&1.0));
    // Read back as linear colours, the same tiles are waited for and read.
    work.target = Target::Linear;
    render_one(&device, &work, &Faults::default(), &mut |_| {}).expect("read back");
    let log = std::mem::take(&mut *device.0.lock().expect("the log"));
    assert_eq!(log, ["prepare", "run", "run", "run", "read", "finish"]);
}
