//! The camera the user moves in the session (orbit, pan, zoom, reset) and the size of the
//! frames it renders.

use super::{Accumulation, Options, Session, SETTLE};
use crate::frontend::{self, Loaded};
use crate::view::camera::Orbit;
use sdfc_compiler::Camera;
use sdfc_compiler::Limit;
use std::path::Path;
use std::time::Instant;

impl Session {
    /// The size a view of `file` starts at: `size`, or the scene's (640×480 when the file does
    /// not compile yet). Nothing is printed.
    pub fn initial_size(file: &Path, options: &Options) -> (u32, u32) {
        let job = &options.job;
        if let Some(size) = job.overrides.size {
            return size;
        }
        match frontend::load_with(file, &job.limits) {
            Ok(Loaded {
                scene: Some(mut scene),
                ..
            }) => match job.settings(&mut scene) {
                Ok(()) => (scene.settings.width, scene.settings.height),
                Err(_) => (640, 480),
            },
            _ => (640, 480),
        }
    }

    /// Sets the view's size (the window's), clamped to the `edge` limit.
    pub fn set_size(&mut self, width: u32, height: u32) {
        let edge = self
            .options
            .job
            .limits
            .get(Limit::Edge)
            .min(u32::MAX as u64) as u32;
        let size = (width.clamp(1, edge), height.clamp(1, edge));
        if size != self.size {
            self.size = size;
            self.accumulation = Accumulation::default();
        }
    }

    /// The view's size.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// The camera frames are rendered from.
    pub(super) fn camera(&self) -> Option<Camera> {
        match (&self.user_camera, &self.good) {
            (Some(orbit), _) => Some(orbit.camera()),
            (None, Some(good)) => Some(good.file_camera.clone()),
            (None, None) => None,
        }
    }

    /// The orbit to move (starting from the file's camera), marking the camera as moving.
    pub(super) fn orbit(&mut self) -> Option<&mut Orbit> {
        let camera = self.camera()?;
        self.moving_until = Some(Instant::now() + SETTLE);
        self.broken = None;
        Some(
            self.user_camera
                .get_or_insert_with(|| Orbit::from_camera(&camera)),
        )
    }

    /// Orbits by a drag of (`dx`, `dy`) pixels.
    pub fn rotate(&mut self, dx: f64, dy: f64) {
        if let Some(o) = self.orbit() {
            o.orbit(dx, dy);
        }
    }

    /// Pans by a drag of (`dx`, `dy`) pixels.
    pub fn pan(&mut self, dx: f64, dy: f64) {
        let height = self.size.1;
        if let Some(o) = self.orbit() {
            o.pan(dx, dy, height);
        }
    }

    /// Zooms by `lines` wheel lines (positive: closer).
    pub fn zoom(&mut self, lines: f64) {
        if let Some(o) = self.orbit() {
            o.zoom(lines);
        }
    }

    /// Returns to the file's camera.
    pub fn reset_camera(&mut self) {
        if self.user_camera.take().is_some() {
            self.accumulation = Accumulation::default();
            self.broken = None;
        }
    }

    /// Whether the user has moved the camera away from the file's.
    pub fn camera_moved(&self) -> bool {
        self.user_camera.is_some()
    }

    pub(super) fn moving(&self) -> bool {
        self.moving_until.is_some_and(|t| Instant::now() < t)
    }
}
