//! An animated scene's time `t` in the session: played or paused, advanced with the clock, and
//! the scene checked at each time.

use super::{Accumulation, Playback, Session};
use crate::backend::{Devices, Setup};
use crate::frontend::{self};
use crate::job::{self};
use crate::view::grade::Grade;
use sdfc_compiler::{Animation, LowerOptions, Scene};
use std::time::{Duration, Instant};

impl Playback {
    /// The clock, in seconds (within `duration`, when the scene states one).
    fn clock(&self) -> f64 {
        let age = self
            .paused
            .unwrap_or_else(|| self.origin.elapsed().as_secs_f64());
        if self.animation.duration > 0.0 {
            age.rem_euclid(self.animation.duration)
        } else {
            age
        }
    }

    /// The animation frame the clock is in.
    fn frame(&self) -> u64 {
        (self.clock() * self.animation.fps).floor() as u64
    }
}

impl Session {
    /// The playback of a newly loaded scene: `None` for a still; for an animated scene the
    /// clock of the last playback goes on (paused or not), or starts (paused at `--time`, if
    /// given). The files are read again for the frames to come; if they cannot be, the scene
    /// stays at the time it was loaded at.
    pub(super) fn playback_of(&mut self, scene: &Scene) -> Option<Playback> {
        if !scene.animation.animated() {
            return None;
        }
        let source = match frontend::Source::read(&self.file) {
            Ok(s) => s,
            Err(msg) => {
                eprintln!("view: the animation stays at t = 0: {msg}");
                return None;
            }
        };
        let (origin, paused) = match &self.playback {
            Some(p) => (p.origin, p.paused),
            None => (Instant::now(), self.options.time),
        };
        Some(Playback {
            source,
            animation: scene.animation,
            origin,
            paused,
            // The load checked the scene at t = 0.
            shown: Some(0),
        })
    }

    /// Whether an animated scene's time is playing.
    pub fn playing(&self) -> bool {
        self.playback.as_ref().is_some_and(|p| p.paused.is_none()) && self.broken.is_none()
    }

    /// Pauses a playing animation at its clock, or plays a paused one on from there.
    pub fn toggle_pause(&mut self) {
        if let Some(p) = self.playback.as_mut() {
            match p.paused.take() {
                Some(at) => p.origin = Instant::now() - Duration::from_secs_f64(at),
                None => p.paused = Some(p.clock()),
            }
            self.accumulation = Accumulation::default();
        }
    }

    /// The animation time on show, for the title; `None` for a still.
    pub fn time(&self) -> Option<f64> {
        let p = self.playback.as_ref()?;
        Some(Animation::time_of(p.animation.fps, p.shown.unwrap_or(0)))
    }

    /// Brings the scene to the animation frame the clock is in: the scene checked at that
    /// frame's time, lowered and prepared (the kernel kept when only numbers change). A frame
    /// that fails stops the clock there, with its problem in the title.
    pub(super) fn advance(&mut self) {
        let Some(p) = self.playback.as_mut() else {
            return;
        };
        let k = p.frame();
        if p.shown == Some(k) {
            return;
        }
        p.shown = Some(k);
        let time = Animation::time_of(p.animation.fps, k);
        if let Err(msg) = self.scene_at(time) {
            eprintln!("view: t = {time} s: {msg}");
            self.status = Some(format!("t = {time} s: {msg}"));
            if let Some(p) = self.playback.as_mut() {
                p.paused = Some(time);
            }
        }
    }

    /// Replaces the scene on show with the scene checked at `time`, through the job's path:
    /// checked, its settings applied and lowered (keeping its program's structure:
    /// [`LowerOptions::parametric`]), then prepared as the scene before was, with the kernel
    /// it had ([`job::Open::After`]), and the interpreted kernel shown meanwhile too.
    fn scene_at(&mut self, time: f64) -> Result<(), job::Error> {
        let job = &self.job();
        let on = (self.backend(), &Devices::Auto);
        let (Some(p), Some(good)) = (self.playback.as_mut(), self.good.as_mut()) else {
            return Ok(());
        };
        let mut frame = job.frame(&mut p.source, time, false, &LowerOptions::parametric())?;
        // Its frames render linear light; the grade (which may change with `t`) is applied
        // to their mean.
        let grade = Grade::take(&mut frame.scene.settings);
        // Each kernel stays the one it is (`Auto`: the one before's).
        let setup = Setup::default();
        if let Some(i) = good.waiting.as_mut().and_then(|w| w.interim.as_mut()) {
            let frame = frame.clone();
            let open = job::Open::After(&i.prepared);
            i.prepared = job::prepare_here(on, frame, &setup, open)?.prepared;
        }
        let open = job::Open::After(&good.prepared);
        let job::Ready {
            scene, prepared, ..
        } = job::prepare_here(on, frame, &setup, open)?;
        self.version += 1;
        good.file_camera = scene.camera.clone();
        good.scene = scene;
        good.grade = grade;
        good.prepared = prepared;
        Ok(())
    }
}
