//! The scene's parameters in the viewer's session: those of the scene on show, for the panel
//! ([`super::super::panel`]), and a change of one's value, which loads the scene again with it
//! through the path an edit of the file takes (checked, lowered keeping the program's
//! structure, prepared as the scene before was: a kernel kept when only numbers change, a new
//! one compiled on another thread when the structure does). The values the panel set are
//! offered to every later load, and kept while the scene accepts them.

use super::*;
use crate::view::widgets;
use sdfc_compiler::{ParamValue, Parameter};

impl Session {
    /// The parameters of the scene on show, with the values it was checked with (none before
    /// the first good load).
    pub fn params(&self) -> &[Parameter] {
        self.good.as_ref().map_or(&[], |g| &g.scene.params)
    }

    /// Gives the parameter `name` the value `value` (one it accepts: the panel's controls
    /// give no other) and loads the scene with it; `--timings` prints the load's times and
    /// the time from the change to the first frame on show. A value the scene no longer
    /// accepts at a later load is passed over there, and the file's default (or `--param`'s
    /// value) stands.
    pub fn set_param(&mut self, name: &str, value: &ParamValue) -> Outcome {
        let changed = SystemTime::now();
        let text = widgets::text(value);
        self.panel.retain(|(n, _)| n != name);
        self.panel.push((name.to_string(), text));
        self.load_because(Some(changed), Some(format!("{name} = {value}")))
    }

    /// After a load: forgets the values the panel set that the scene passed over (a
    /// parameter renamed or removed, a value outside a narrower range), so that they do not
    /// come back with a later edit.
    pub(super) fn keep_taken_values(&mut self) {
        let params = match &self.good {
            Some(g) => &g.scene.params,
            None => return,
        };
        self.panel.retain(|(name, text)| {
            params
                .iter()
                .any(|p| p.name == *name && widgets::text(&p.value) == *text)
        });
    }

    /// The job of a load: the command line's, with the values the panel set offered to the
    /// scene's parameters (over the `--param` values).
    pub(super) fn job(&self) -> Job {
        let mut job = self.options.job.clone();
        for (name, text) in &self.panel {
            job.limits.offer_param(name, text);
        }
        job
    }
}
