//! The CPU renderer as a device of the tile scheduler ([`launch::Device`]), so that it can
//! take bands of an image beside GPU devices (`--devices cpu,0`): it renders each band it
//! takes with [`crate::cpu::render_rows`] in a thread pool of its own.

use super::launch::{self, Pixels, Work};
use super::reduce::{Answer, Ask};
use crate::cpu::{self, Counters, Options, Tapes};
use sdfc_compiler::Scene;
use std::ops::Range;
use std::time::Duration;

/// The CPU renderer of one scene, as a device.
#[derive(Debug, Clone, Copy)]
pub struct Device<'a> {
    scene: &'a Scene,
    tapes: &'a Tapes,
    options: &'a Options,
    threads: usize,
}

impl<'a> Device<'a> {
    /// Renders `scene` from its `tapes` with `options` on as many threads as the current
    /// rayon pool has.
    pub fn new(scene: &'a Scene, tapes: &'a Tapes, options: &'a Options) -> Self {
        Device {
            scene,
            tapes,
            options,
            threads: rayon::current_num_threads(),
        }
    }
}

/// Why the CPU device failed.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Its thread pool could not be started.
    #[error("cannot start the CPU's worker threads: {0}")]
    Threads(#[from] rayon::ThreadPoolBuildError),
    /// A tile that is not a band of whole rows (the scheduler gives the CPU bands).
    #[error("the CPU device renders bands of whole rows")]
    NotRows,
    /// Pixels read that no band rendered.
    #[error("the CPU did not render pixels {0:?}")]
    NotRendered(Range<usize>),
    /// A fault injected by `SDFC_FAULT_AFTER_TILES` (tests of the scheduler).
    #[error("{0}")]
    Injected(String),
}

/// The CPU's frame: its thread pool, the bands rendered and not yet read, and the steps and
/// counters of those read (their statistics, reduced on the host when asked).
#[derive(Debug)]
pub struct Frame {
    pool: rayon::ThreadPool,
    rendered: Vec<(Range<usize>, Vec<[f32; 3]>)>,
    statistics: Vec<(Range<usize>, Vec<u32>, Counters)>,
}

impl launch::Device for Device<'_> {
    type Frame = Frame;
    type Error = Error;

    fn describe(&self) -> String {
        format!("CPU, {} threads", self.threads)
    }

    fn prepare(&self, _work: &Work) -> Result<Frame, Error> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.threads)
            .build()
            .map_err(Error::Threads)?;
        Ok(Frame {
            pool,
            rendered: Vec::new(),
            statistics: Vec::new(),
        })
    }

    fn run(&self, f: &mut Frame, work: &Work, tiles: &[usize]) -> Result<(), Error> {
        for &i in tiles {
            let t = work.tiles[i];
            if t.0 != 0 || t.2 != work.width {
                return Err(Error::NotRows);
            }
            let rows = t.1..t.1 + t.3;
            let (linear, steps, counters) = f
                .pool
                .install(|| cpu::render_rows(self.scene, self.tapes, self.options, rows));
            let w = work.width as usize;
            let range = t.1 as usize * w..(t.1 + t.3) as usize * w;
            f.rendered.push((range.clone(), linear));
            f.statistics.push((range, steps, counters));
        }
        Ok(())
    }

    fn read(&self, f: &mut Frame, work: &Work, ranges: &[Range<usize>]) -> Result<Pixels, Error> {
        let mut out = Pixels::default();
        for r in ranges {
            let at = f
                .rendered
                .iter()
                .position(|(have, _)| have == r)
                .ok_or_else(|| Error::NotRendered(r.clone()))?;
            let (_, linear) = f.rendered.swap_remove(at);
            if work.finished() {
                // Finished here as a GPU finishes its pixels: clamped and sRGB-encoded.
                let start = std::time::Instant::now();
                let table = crate::image::SrgbTable::get();
                out.rgba.extend(linear.iter().flat_map(|c| {
                    [
                        table.encode(c[0]),
                        table.encode(c[1]),
                        table.encode(c[2]),
                        255,
                    ]
                }));
                out.convert += start.elapsed();
            } else {
                out.linear.extend(linear);
            }
        }
        Ok(out)
    }

    /// Reduced on the host, from the steps and counters of the bands rendered.
    fn reduce(
        &self,
        f: &mut Frame,
        _work: &Work,
        ranges: &[Range<usize>],
        ask: Ask,
    ) -> Result<Answer, Error> {
        let mut steps = Vec::new();
        let mut counters = Counters::default();
        for (r, s, c) in f.statistics.iter().filter(|(r, ..)| ranges.contains(r)) {
            debug_assert_eq!(r.len(), s.len());
            steps.extend_from_slice(s);
            counters.add(c);
        }
        Ok(Answer::of_steps(&steps, &counters, ask))
    }

    fn finish(&self, _f: Frame, _work: &Work) -> Result<Option<Duration>, Error> {
        Ok(None)
    }

    fn fault(&self, message: String) -> Error {
        Error::Injected(message)
    }
}
