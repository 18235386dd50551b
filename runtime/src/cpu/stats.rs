//! Render statistics: ray counts, the stability counters of docs/rendering.md (hits, misses by
//! budget, overshoots, NaNs) and the distribution of sphere-tracing steps per pixel.

use std::fmt;

/// Event counts, summed over tiles.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Counters {
    /// Camera rays (one per sample).
    pub camera_rays: u64,
    /// Reflected and refracted rays.
    pub secondary_rays: u64,
    /// Shadow rays.
    pub shadow_rays: u64,
    /// Camera and secondary rays that reached a surface.
    pub hits: u64,
    /// Camera and secondary rays that left through `max_dist`.
    pub misses: u64,
    /// Camera and secondary rays that ran out of steps (shown as background).
    pub budget_misses: u64,
    /// Evaluations, on any ray, that landed inside a surface (d < -ε·t).
    pub overshoots: u64,
    /// Evaluations that returned NaN (the ray then stops).
    pub nans: u64,
    /// Sphere-tracing steps of all rays (field evaluations while marching).
    pub steps: u64,
    /// Marching loops a software adapter ended on its own budget of iterations, from which
    /// its distances were wrong (always 0 on the CPU and on a GPU).
    pub cut: u64,
}

impl Counters {
    /// Adds another tile's counts.
    pub fn add(&mut self, o: &Counters) {
        self.camera_rays += o.camera_rays;
        self.secondary_rays += o.secondary_rays;
        self.shadow_rays += o.shadow_rays;
        self.hits += o.hits;
        self.misses += o.misses;
        self.budget_misses += o.budget_misses;
        self.overshoots += o.overshoots;
        self.nans += o.nans;
        self.steps += o.steps;
        self.cut += o.cut;
    }
}

/// The statistics of one render.
#[derive(Debug, Default, Clone, PartialEq, serde::Serialize)]
pub struct Stats {
    /// Event counts.
    #[serde(flatten)]
    pub counters: Counters,
    /// Pixels rendered.
    pub pixels: u64,
    /// Mean marching steps per pixel (all of its samples and their secondary and shadow rays).
    pub steps_mean: f64,
    /// 99th percentile of steps per pixel.
    pub steps_p99: u32,
    /// Most steps taken for one pixel.
    pub steps_max: u32,
}

impl Stats {
    /// Statistics from the counters and the distribution of the steps reduced elsewhere (on a
    /// GPU, `gpu::reduce`): `pixels` pixels, the most steps of one and the 99th percentile;
    /// the mean is the counters' steps over the pixels. The same as [`Stats::new`] of the
    /// per-pixel steps.
    pub fn reduced(counters: Counters, pixels: u64, max: u32, p99: u32) -> Self {
        Stats {
            counters,
            pixels,
            steps_mean: if pixels == 0 {
                0.0
            } else {
                counters.steps as f64 / pixels as f64
            },
            steps_p99: p99,
            steps_max: max,
        }
    }

    /// Statistics from the counters and the steps taken for each pixel.
    pub fn new(counters: Counters, steps_per_pixel: &[u32]) -> Self {
        let n = steps_per_pixel.len();
        let total: u64 = steps_per_pixel.iter().map(|&s| s as u64).sum();
        let max = steps_per_pixel.iter().copied().max().unwrap_or(0);
        // The percentile by selection, in linear time (a sort of a 1080p frame's two million
        // values took longer than the frame).
        let p99 = if n == 0 {
            0
        } else {
            let mut steps = steps_per_pixel.to_vec();
            let at = ((n - 1) as f64 * 0.99).round() as usize;
            *steps.select_nth_unstable(at).1
        };
        Stats {
            counters,
            pixels: n as u64,
            steps_mean: if n == 0 { 0.0 } else { total as f64 / n as f64 },
            steps_p99: p99,
            steps_max: max,
        }
    }
}

impl fmt::Display for Stats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let c = &self.counters;
        writeln!(f, "pixels          {}", self.pixels)?;
        writeln!(
            f,
            "rays            {} camera, {} secondary, {} shadow",
            c.camera_rays, c.secondary_rays, c.shadow_rays
        )?;
        writeln!(
            f,
            "steps/pixel     mean {:.1}, p99 {}, max {}",
            self.steps_mean, self.steps_p99, self.steps_max
        )?;
        writeln!(f, "hits            {}", c.hits)?;
        writeln!(
            f,
            "misses          {} by distance, {} by step budget",
            c.misses, c.budget_misses
        )?;
        writeln!(f, "overshoots      {}", c.overshoots)?;
        write!(f, "NaNs            {}", c.nans)
    }
}
