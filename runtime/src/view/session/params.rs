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

#[cfg(test)]
mod tests {
    use super::*;

    const BALL: &str = "param r = 0.5 in 0.2..1.0 step 0.1 \"Ball radius\";\n\
        camera { position: (0, 1, -4), look_at: (0, 0.5, 0), fov: 50deg }\n\
        light point { position: (2, 4, -3), intensity: 1 }\n\
        render { width: 16, height: 12 }\n\
        scene { plane((0, 1, 0), 0); sphere(r).translate(0, r, 0); }\n";

    #[test]
    fn a_value_set_loads_the_scene_with_it_and_stays_while_the_file_accepts_it() {
        let dir = std::env::temp_dir().join(format!("sdfc-params-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("ball.sdf");
        std::fs::write(&file, BALL).unwrap();
        let mut options = Options::default();
        // The command line's value: the panel starts from it, and its own value wins.
        options.job.limits.set_param("r", "0.6");
        let mut s = Session::new(file.clone(), options, Device::Cpu);
        let r = |s: &Session| s.params()[0].value.clone();
        assert!(s.load().ok);
        assert_eq!(r(&s), ParamValue::Float(0.6));
        let before = s.version;
        let out = s.set_param("r", &ParamValue::Float(0.8));
        assert!(out.ok && out.number == 1, "{out:?}");
        assert_eq!(r(&s), ParamValue::Float(0.8));
        assert!(s.version > before, "the scene on show is the new one");
        assert_eq!(
            s.timings.as_ref().and_then(|t| t.cause.clone()).as_deref(),
            Some("r = 0.8")
        );
        // An edit that keeps the parameter and its range keeps the value.
        std::fs::write(&file, BALL.replace("Ball radius", "Radius")).unwrap();
        assert!(s.load().ok);
        assert_eq!(
            (r(&s), s.params()[0].doc.as_str()),
            (ParamValue::Float(0.8), "Radius")
        );
        // A narrower range passes it over: `--param`'s value stands, and the panel forgets
        // its value, so that widening the range again does not bring it back.
        std::fs::write(&file, BALL.replace("0.2..1.0", "0.2..0.7")).unwrap();
        assert!(s.load().ok);
        assert_eq!(r(&s), ParamValue::Float(0.6));
        std::fs::write(&file, BALL).unwrap();
        assert!(s.load().ok);
        assert_eq!(r(&s), ParamValue::Float(0.6));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
