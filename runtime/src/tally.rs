//! Where a sequence's time went (`sdfc render --frames --stats`): durations summed by place
//! (the main thread, each device's worker, the image writers' pool) and by step, added from
//! any thread, and printed as one line a place.

use std::sync::Mutex;
use std::time::Duration;

/// Durations summed by place and step, in the order they were first added.
#[derive(Debug, Default)]
pub struct Tally {
    sums: Mutex<Vec<Sum>>,
}

#[derive(Debug)]
struct Sum {
    place: String,
    step: &'static str,
    total: Duration,
    times: u64,
}

impl Tally {
    /// Adds `time` to `step` at `place`.
    pub fn add(&self, place: &str, step: &'static str, time: Duration) {
        let mut sums = self.sums.lock().unwrap_or_else(|e| e.into_inner());
        match sums.iter_mut().find(|s| s.step == step && s.place == place) {
            Some(s) => {
                s.total += time;
                s.times += 1;
            }
            None => sums.push(Sum {
                place: place.to_string(),
                step,
                total: time,
                times: 1,
            }),
        }
    }

    /// The time spent since `since` added to `step` at `place`.
    pub fn since(&self, place: &str, step: &'static str, since: std::time::Instant) {
        self.add(place, step, since.elapsed());
    }

    /// The phases of a GPU frame rendered at `place`.
    pub fn phases(&self, place: &str, p: &crate::gpu::Phases) {
        self.add(place, "setup", p.setup);
        self.add(place, "launches", p.launches);
        self.add(place, "readback", p.readback);
        self.add(place, "conversion", p.convert);
    }

    /// One line a place: each step's total in ms, how many times it was added and its mean.
    pub fn report(&self) -> String {
        let sums = self.sums.lock().unwrap_or_else(|e| e.into_inner());
        let mut places: Vec<&str> = Vec::new();
        for s in sums.iter() {
            if !places.contains(&s.place.as_str()) {
                places.push(&s.place);
            }
        }
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        let mut out = String::new();
        for place in places {
            let steps: Vec<String> = sums
                .iter()
                .filter(|s| s.place == place)
                .map(|s| {
                    format!(
                        "{} {:.1} ms ({} × {:.2})",
                        s.step,
                        ms(s.total),
                        s.times,
                        ms(s.total) / s.times.max(1) as f64
                    )
                })
                .collect();
            out.push_str(&format!("  {place}: {}\n", steps.join(", ")));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_are_summed_by_place_in_the_order_first_added() {
        let t = Tally::default();
        t.add("device 0", "launches", Duration::from_millis(2));
        t.add("main thread", "check", Duration::from_millis(1));
        t.add("device 0", "launches", Duration::from_millis(4));
        t.add("device 0", "readback", Duration::from_millis(1));
        assert_eq!(
            t.report(),
            "  device 0: launches 6.0 ms (2 × 3.00), readback 1.0 ms (1 × 1.00)\n  main thread: check 1.0 ms (1 × 1.00)\n"
        );
    }
}
