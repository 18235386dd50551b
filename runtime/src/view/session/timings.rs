//! The timings of a load that `--timings` prints once its first frame is on show: reading and
//! checking, lowering, the kernel or tapes, the pipeline, the first frame, and from the edit
//! (or the panel's change of a parameter) to that frame.

use super::*;

/// Times of one load, printed (with `--timings`) once its first frame is shown.
#[derive(Debug, Clone)]
pub(super) struct Timings {
    pub(super) number: u32,
    /// What called for the load when it was not an edit of the files: the panel's change of a
    /// parameter (`width = 60`).
    pub(super) cause: Option<String>,
    /// Reading and checking.
    pub(super) check: Duration,
    /// Lowering to the distance program.
    pub(super) lower: Duration,
    /// Tapes (CPU) or kernel generation and validation (wgpu).
    pub(super) prepare: Duration,
    /// Whether a kernel (or the CPU's tapes) was built; false when the last scene's wgpu
    /// kernel was kept (an edit of numbers only).
    pub(super) built: bool,
    /// The kernel's pipeline: compiled, or found among those compiled.
    pub(super) pipeline: Option<PipelineTime>,
    /// Whether the pipeline compiled on another thread (`pipeline` is then its time, once
    /// ready before the first frame).
    pub(super) background: bool,
    /// Whether the interpreted kernel could show the scene while it compiled (else the image
    /// before stayed on show until it was ready).
    pub(super) interim: bool,
    /// The kernel of the first frame: `interpreted` while the specialised one compiled.
    pub(super) first_kernel: Option<&'static str>,
    /// The time to prepare the interpreted kernel (with `auto`, when the specialised pipeline
    /// was not compiled yet).
    pub(super) interim_prepare: Duration,
    /// The interpreted kernel's pipeline, when it rendered the first frame.
    pub(super) interim_pipeline: Option<PipelineTime>,
    /// When the specialised pipeline compiled on another thread was ready before any frame
    /// of the interpreted kernel: how long after its compile started the session took it,
    /// and whether that was within the grace period.
    pub(super) ready: Option<(Duration, bool)>,
    /// When the newest of the scene's files was modified.
    pub(super) modified: Option<SystemTime>,
    /// When the load began.
    pub(super) began: SystemTime,
    /// The first frame's render time and size, once rendered.
    pub(super) first_frame: Option<(Duration, u32, u32)>,
    /// Whether the first frame's timings are printed (and the first full frame's are due).
    pub(super) printed: bool,
}

impl Timings {
    /// What the load's line says of its kernel's pipeline: how it was had, and with `auto`
    /// whether the specialised kernel was ready within the grace period `grace` or was shown
    /// interpreted while it compiled.
    pub(super) fn pipeline_words(&self, grace: Duration) -> String {
        let got = |p: PipelineTime| match p.cached {
            true => format!("cached ({:.1} ms)", ms(p.time)),
            false => format!("compiled {:.1} ms", ms(p.time)),
        };
        let grace = ms(grace);
        match (self.pipeline, self.background, self.ready) {
            (Some(p), false, _) => format!(", pipeline {}", got(p)),
            (Some(p), true, Some((ready, _))) if !self.interim => format!(
                ", pipeline {} on another thread, shown once ready {:.1} ms after its compile started (no interpreted kernel meanwhile: the image before stayed on show)",
                got(p),
                ms(ready)
            ),
            (Some(p), true, Some((ready, true))) => format!(
                ", pipeline {} on another thread, specialised compiled within the grace period in {:.1} ms (grace {grace:.0} ms, no interpreted frame)",
                got(p),
                ms(ready)
            ),
            (Some(p), true, Some((ready, false))) => format!(
                ", pipeline {} on another thread, specialised ready {:.1} ms after its compile started (after the {grace:.0} ms grace period, before an interpreted frame)",
                got(p),
                ms(ready)
            ),
            (Some(p), true, None) => format!(", pipeline {} on another thread", got(p)),
            (None, true, _) => format!(
                ", pipeline compiling on another thread, not ready within the {grace:.0} ms grace period, interpreted while compiling (interpreted kernel {:.2} ms, its pipeline {})",
                ms(self.interim_prepare),
                match self.interim_pipeline {
                    Some(p) if p.cached => "was cached".to_string(),
                    Some(p) => format!("compiled {:.1} ms", ms(p.time)),
                    None => "was ready".to_string(),
                }
            ),
            (None, false, _) => String::new(),
        }
    }
}

impl Session {
    /// Called once a frame is on show: prints the timings of the load whose first frame it
    /// is, with `--timings` (edit to pixel: from the modification of the newest of the
    /// scene's files until now; change to pixel, for a load the panel's change of a parameter
    /// called for: from the change until now).
    pub fn presented(&mut self) {
        let Some(t) = self.timings.as_ref() else {
            return;
        };
        let Some((time, w, h)) = t.first_frame else {
            return;
        };
        let edit = match t.cause {
            Some(_) => "change",
            None => "edit",
        };
        let label = t
            .cause
            .as_ref()
            .map(|c| format!(" ({c})"))
            .unwrap_or_default();
        if t.printed {
            // The first frame was smaller: say when the full resolution followed.
            let full = self.accumulation.still && self.accumulation.count > 0;
            if full {
                if let (true, Some(m)) = (self.options.timings, t.modified.filter(|_| t.number > 0))
                {
                    if let Ok(total) = SystemTime::now().duration_since(m) {
                        eprintln!(
                            "view: load {}{label}: first full-resolution frame shown {:.1} ms after the {edit}",
                            t.number,
                            ms(total)
                        );
                    }
                }
                self.timings = None;
            }
            return;
        }
        if self.options.timings {
            let pipeline = t.pipeline_words(self.options.grace);
            let now = SystemTime::now();
            let to_pixel = match (
                t.modified.filter(|_| t.number > 0),
                now.duration_since(t.began),
            ) {
                (Some(m), Ok(shown)) => match (t.began.duration_since(m), now.duration_since(m)) {
                    (Ok(seen), Ok(total)) => format!(
                        "; {edit} to pixel {:.1} ms (seen after {:.1} ms, shown {:.1} ms later)",
                        ms(total),
                        ms(seen),
                        ms(shown)
                    ),
                    _ => String::new(),
                },
                _ => String::new(),
            };
            eprintln!(
                "view: load {}{label} timings: check {:.1} ms, lower {:.2} ms, {} {:.2} ms{pipeline}, first frame {:.1} ms ({w}x{h}{}){to_pixel}",
                t.number,
                ms(t.check),
                ms(t.lower),
                match (&self.device, t.built) {
                    (Device::Cpu, _) => "tapes",
                    (_, true) => "kernel",
                    (_, false) => "kernel kept (numbers only)",
                },
                ms(t.prepare),
                ms(time),
                t.first_kernel.map(|k| format!(", {k}")).unwrap_or_default(),
            );
        }
        if (w, h) == self.size {
            self.timings = None;
        } else if let Some(t) = self.timings.as_mut() {
            t.printed = true;
        }
    }
}
