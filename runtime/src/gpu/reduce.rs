//! A frame's statistics reduced where they were rendered: the sums `sdfc render --stats`
//! prints (the counters, the most steps of a pixel) and the 99th percentile of the steps,
//! found by histograms of narrower bins around it, one round each, until the bins are one step
//! wide. A GPU device answers each round with the reduction module of
//! `sdfc_compiler::wgsl::reduce` and reads back a few kilobytes; the CPU device sums its
//! own bands. Several devices answer each round together ([`Rounds`]), and their answers add
//! up: the result is the one the per-pixel statistics of the whole frame give on the host
//! ([`crate::cpu::Stats::new`]), exactly.

use crate::cpu::Counters;
use sdfc_compiler::wgsl::{
    reduce::Query, reduce::BINS, reduce::MOST_STEPS_WORD, reduce::RECORD, reduce::WORKGROUP,
};
use std::ops::Range;
use std::sync::{Condvar, Mutex};

/// What a round asks of a device.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ask {
    /// The counters and the most steps of a pixel.
    Sums,
    /// How many pixels took each of [`BINS`] step counts `base + width·b ..
    /// base + width·(b + 1)`.
    Histogram { base: u32, width: u32 },
}

/// A device's answer to an [`Ask`], over the pixels it rendered.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Answer {
    Sums { counters: Counters, max: u32 },
    Counts(Vec<u64>),
}

impl Answer {
    /// The answer to `ask` over no pixels.
    pub fn empty(ask: Ask) -> Answer {
        match ask {
            Ask::Sums => Answer::Sums {
                counters: Counters::default(),
                max: 0,
            },
            Ask::Histogram { .. } => Answer::Counts(vec![0; BINS as usize]),
        }
    }

    /// Adds another device's answer to the same ask.
    fn merge(&mut self, other: Answer) {
        match (self, other) {
            (
                Answer::Sums { counters, max },
                Answer::Sums {
                    counters: c,
                    max: m,
                },
            ) => {
                counters.add(&c);
                *max = (*max).max(m);
            }
            (Answer::Counts(a), Answer::Counts(b)) => {
                for (x, y) in a.iter_mut().zip(b) {
                    *x += y;
                }
            }
            // Answers to different asks: a bug of the caller's.
            (a, b) => debug_assert!(false, "answers to different asks: {a:?} and {b:?}"),
        }
    }

    /// The answer of per-pixel `steps` and their `counters` (the CPU renderer's, or the
    /// statistics read back whole).
    pub fn of_steps(steps: &[u32], counters: &Counters, ask: Ask) -> Answer {
        match ask {
            Ask::Sums => Answer::Sums {
                counters: *counters,
                max: steps.iter().copied().max().unwrap_or(0),
            },
            Ask::Histogram { base, width } => {
                let mut counts = vec![0u64; BINS as usize];
                for &s in steps.iter().filter(|&&s| s >= base) {
                    let b = ((s - base) / width.max(1)) as usize;
                    if let Some(c) = counts.get_mut(b) {
                        *c += 1;
                    }
                }
                Answer::Counts(counts)
            }
        }
    }

    /// The answer in the totals the reduction module wrote (records of [`RECORD`] words).
    pub fn of_totals(words: &[u32], ask: Ask) -> Answer {
        let records = words.chunks_exact(RECORD as usize);
        match ask {
            Ask::Sums => {
                let mut sums = [0u64; sdfc_compiler::wgsl::STATS_WORDS as usize];
                let mut max = 0;
                for r in records {
                    for (k, s) in sums.iter_mut().enumerate() {
                        *s += r[2 * k] as u64 | (r[2 * k + 1] as u64) << 32;
                    }
                    max = max.max(r[MOST_STEPS_WORD as usize]);
                }
                // The kernel's statistics words, in order (kernel.wgsl).
                let counters = Counters {
                    steps: sums[0],
                    hits: sums[1],
                    misses: sums[2],
                    budget_misses: sums[3],
                    overshoots: sums[4],
                    nans: sums[5],
                    secondary_rays: sums[6],
                    shadow_rays: sums[7],
                    cut: sums[8],
                    camera_rays: 0,
                };
                Answer::Sums { counters, max }
            }
            Ask::Histogram { .. } => {
                let mut counts = vec![0u64; BINS as usize];
                for r in records {
                    for (c, &w) in counts.iter_mut().zip(r) {
                        *c += w as u64;
                    }
                }
                Answer::Counts(counts)
            }
        }
    }
}

/// The reduced statistics of a frame: the counters (all but the camera rays), the most steps
/// of a pixel and the 99th percentile of the steps ([`crate::cpu::Stats::new`]'s).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Summary {
    pub counters: Counters,
    pub max: u32,
    pub p99: u32,
}

/// The rounds of a frame's reduction: what to ask next, and the summary once done.
#[derive(Debug, Clone)]
pub struct Selection {
    /// The rank of the 99th percentile among the pixels' steps, in increasing order.
    at: u64,
    pixels: u64,
    ask: Option<Ask>,
    /// Pixels with fewer steps than the current histogram's base.
    below: u64,
    summary: Summary,
}

impl Selection {
    /// The reduction of a frame of `pixels` pixels: first the sums.
    pub fn new(pixels: u64) -> Selection {
        Selection {
            // As `Stats::new` selects it.
            at: (pixels.saturating_sub(1) as f64 * 0.99).round() as u64,
            pixels,
            ask: Some(Ask::Sums),
            below: 0,
            summary: Summary::default(),
        }
    }

    /// What the next round asks; `None` when the summary is complete.
    pub fn ask(&self) -> Option<Ask> {
        self.ask
    }

    /// The summary (complete once [`Selection::ask`] is `None`).
    pub fn summary(&self) -> Summary {
        self.summary
    }

    /// Takes the round's answer (every device's, merged).
    pub fn answer(&mut self, answer: Answer) {
        let bins = BINS as u64;
        let histogram = |base: u64, width: u64| Ask::Histogram {
            base: base as u32,
            width: width as u32,
        };
        self.ask = match (self.ask, answer) {
            (Some(Ask::Sums), Answer::Sums { counters, max }) => {
                self.summary.counters = counters;
                self.summary.max = max;
                // Every pixel took no step, or there is none: the percentile is 0.
                (self.pixels > 0 && max > 0).then(|| histogram(0, (max as u64 + 1).div_ceil(bins)))
            }
            (Some(Ask::Histogram { base, width }), Answer::Counts(counts)) => {
                let mut below = self.below;
                let bin = counts.iter().position(|&c| {
                    below += c;
                    below > self.at
                });
                match bin {
                    Some(b) => {
                        self.below = below - counts[b];
                        let start = base as u64 + b as u64 * width as u64;
                        if width <= 1 {
                            self.summary.p99 = start as u32;
                            None
                        } else {
                            Some(histogram(start, (width as u64).div_ceil(bins)))
                        }
                    }
                    // Fewer pixels than the rank (a device lost): the most steps.
                    None => {
                        self.summary.p99 = self.summary.max;
                        None
                    }
                }
            }
            _ => None,
        };
    }
}

/// The threads of the reduction's first stage for a frame of `pixels` pixels (each writes a
/// partial record; at most 16 384, 4 MiB of records) and of its second (at most 256, whose
/// 64 KiB of totals are read back).
pub fn threads(pixels: usize) -> (u32, u32) {
    let first = (pixels.div_ceil(64) as u32)
        .next_multiple_of(WORKGROUP)
        .clamp(WORKGROUP, 16_384);
    (first, first.min(256))
}

/// The dispatches of one round over the pixels `ranges` of a frame of `pixels` pixels: a
/// first-stage dispatch for each range (the later ones adding to the partial records), then
/// the second stage. Empty when there are no ranges.
pub fn queries(pixels: usize, ranges: &[Range<usize>], ask: Ask) -> Vec<Query> {
    if ranges.is_empty() {
        return Vec::new();
    }
    let (first, second) = threads(pixels);
    let (mode, base, width) = match ask {
        Ask::Sums => (0, 0, 1),
        Ask::Histogram { base, width } => (1, base, width.max(1)),
    };
    let mut out: Vec<Query> = ranges
        .iter()
        .enumerate()
        .map(|(i, r)| Query {
            first: r.start as u32,
            count: (r.end - r.start) as u32,
            threads: first,
            stage: 0,
            mode,
            base,
            width,
            add: i > 0,
        })
        .collect();
    out.push(Query {
        first: 0,
        count: first,
        threads: second,
        stage: 1,
        mode,
        base,
        width,
        add: false,
    });
    out
}

/// The rounds of several devices: each device answers every round over the bands it
/// rendered, and the round's answers are merged; the last device to answer opens the next
/// round. A device that fails leaves; the others finish the rounds without its pixels (the
/// bands it rendered before failing then count in no statistics).
#[derive(Debug)]
pub struct Rounds {
    state: Mutex<RoundState>,
    changed: Condvar,
}

#[derive(Debug)]
struct RoundState {
    selection: Selection,
    /// Devices that will still answer.
    present: usize,
    round: usize,
    answered: usize,
    merged: Option<Answer>,
    /// A device left after some of its bands had been accepted.
    lost: bool,
}

impl Rounds {
    /// The rounds of a frame of `pixels` pixels rendered by `devices` devices.
    pub fn new(pixels: u64, devices: usize) -> Rounds {
        Rounds {
            state: Mutex::new(RoundState {
                selection: Selection::new(pixels),
                present: devices,
                round: 0,
                answered: 0,
                merged: None,
                lost: false,
            }),
            changed: Condvar::new(),
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, RoundState> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// What round `round` asks, once it is open (waiting for the others' answers to the
    /// round before); `None` when the rounds are over.
    pub fn ask(&self, round: usize) -> Option<Ask> {
        let mut s = self.lock();
        while s.round < round && s.selection.ask().is_some() {
            s = self.changed.wait(s).unwrap_or_else(|e| e.into_inner());
        }
        s.selection.ask()
    }

    /// A device's answer to the open round.
    pub fn answer(&self, answer: Answer) {
        let mut s = self.lock();
        match &mut s.merged {
            Some(m) => m.merge(answer),
            None => s.merged = Some(answer),
        }
        s.answered += 1;
        self.advance(&mut s);
    }

    /// A device answers no more rounds; `lost` when some of the frame's pixels were its.
    pub fn leave(&self, lost: bool) {
        let mut s = self.lock();
        s.present = s.present.saturating_sub(1);
        s.lost |= lost;
        self.advance(&mut s);
    }

    /// Opens the next round when every device present has answered this one.
    fn advance(&self, s: &mut RoundState) {
        if s.answered < s.present || s.selection.ask().is_none() {
            return;
        }
        let ask = s.selection.ask().unwrap_or(Ask::Sums);
        let merged = s.merged.take().unwrap_or_else(|| Answer::empty(ask));
        s.selection.answer(merged);
        s.round += 1;
        s.answered = 0;
        self.changed.notify_all();
    }

    /// The summary once the rounds are over, and whether a device's pixels are missing
    /// from it.
    pub fn summary(&self) -> (Summary, bool) {
        let s = self.lock();
        (s.selection.summary(), s.lost)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs the rounds over `steps` split among devices at `cuts`, answered on the host.
    fn summarise(steps: &[u32], cuts: &[usize]) -> Summary {
        let mut sel = Selection::new(steps.len() as u64);
        let mut parts = Vec::new();
        let mut at = 0;
        for &c in cuts.iter().chain([&steps.len()]) {
            parts.push(&steps[at..c]);
            at = c;
        }
        let mut rounds = 0;
        while let Some(ask) = sel.ask() {
            let mut merged = Answer::empty(ask);
            for p in &parts {
                let c = Counters {
                    steps: p.iter().map(|&s| s as u64).sum(),
                    ..Counters::default()
                };
                merged.merge(Answer::of_steps(p, &c, ask));
            }
            sel.answer(merged);
            rounds += 1;
            assert!(rounds < 10, "the rounds end");
        }
        sel.summary()
    }

    #[test]
    fn the_rounds_find_the_hosts_percentile_exactly() {
        let mut rng = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            rng
        };
        for (n, top) in [
            (0, 1),
            (1, 1),
            (7, 1),
            (100, 3),
            (1000, 64),
            (5000, 65),
            (4096, 100_000),
            (777, u32::MAX as u64),
        ] {
            let steps: Vec<u32> = (0..n).map(|_| (next() % top) as u32).collect();
            let c = Counters {
                steps: steps.iter().map(|&s| s as u64).sum(),
                ..Counters::default()
            };
            let expected = crate::cpu::Stats::new(c, &steps);
            for cuts in [vec![], vec![n / 3, n / 2]] {
                let s = summarise(&steps, &cuts);
                assert_eq!(s.p99, expected.steps_p99, "{n} pixels below {top}");
                assert_eq!(s.max, expected.steps_max, "{n} pixels below {top}");
                assert_eq!(s.counters.steps, expected.counters.steps);
            }
        }
    }

    #[test]
    fn the_queries_cover_the_ranges_then_sum_the_partial_records() {
        let q = queries(
            1000,
            &[0..10, 20..1000],
            Ask::Histogram { base: 5, width: 3 },
        );
        assert_eq!(q.len(), 3);
        assert_eq!((q[0].first, q[0].count, q[0].add), (0, 10, false));
        assert_eq!((q[1].first, q[1].count, q[1].add), (20, 980, true));
        let (first, second) = threads(1000);
        assert_eq!((first, second), (64, 64));
        assert_eq!((q[2].stage, q[2].count, q[2].threads), (1, first, second));
        assert!(q.iter().all(|q| (q.mode, q.base, q.width) == (1, 5, 3)));
        assert_eq!(threads(7680 * 4320), (16_384, 256));
        assert!(queries(10, &[], Ask::Sums).is_empty());
    }

    #[test]
    fn totals_add_up_as_64_bit_counts() {
        let mut words = vec![0u32; 2 * RECORD as usize];
        words[0] = u32::MAX;
        words[RECORD as usize] = 1;
        words[1] = 2;
        words[MOST_STEPS_WORD as usize] = 9;
        words[RECORD as usize + MOST_STEPS_WORD as usize] = 4;
        let Answer::Sums { counters, max } = Answer::of_totals(&words, Ask::Sums) else {
            panic!("sums")
        };
        assert_eq!(counters.steps, (2u64 << 32) + u32::MAX as u64 + 1);
        assert_eq!(max, 9);
    }
}
