//! The reference render that accuracy is measured against (docs/rendering.md, "Precision"): f64,
//! ε = 1e-6, a step budget of 100 000, no over-relaxation and steps of d/L (L from
//! `Options::lipschitz`), and its convergence check: a second render with ε ten times smaller
//! must agree with it.

use super::Render;
use crate::metrics::{self, DepthDifference, Difference};
use sdfc_compiler::scene::Settings;
use std::fmt;

/// The hit tolerance ε of the reference.
pub const EPSILON: f64 = 1e-6;

/// The step budget of the reference (large enough that no ordinary ray runs out).
pub const MAX_STEPS: u32 = 100_000;

/// The convergence check renders again with ε divided by this.
pub const CHECK_FACTOR: f64 = 10.0;

/// The reference counts as converged when the check render agrees with it to at least this
/// PSNR (dB). Test renders are judged against the reference at 40 dB, so the reference must
/// be at least ten times (10 dB) more accurate than that.
pub const CONVERGED_PSNR: f64 = 50.0;

/// Per-channel difference above which a pixel counts as differing in the check.
pub const THRESHOLD: f64 = 0.1;

/// Relative depth tolerance of the check's `behind` count.
pub const DEPTH_TOLERANCE: f64 = 1e-3;

/// The reference settings of a scene: ε, the step budget and the relaxation change; the size,
/// supersampling, depth limit and everything else stay.
pub fn settings(s: &Settings) -> Settings {
    Settings {
        epsilon: EPSILON,
        max_steps: MAX_STEPS.max(s.max_steps),
        relaxation: 1.0,
        ..s.clone()
    }
}

/// The settings of the convergence check for reference settings `s`: ε divided by
/// [`CHECK_FACTOR`].
pub fn check_settings(s: &Settings) -> Settings {
    Settings {
        epsilon: s.epsilon / CHECK_FACTOR,
        ..s.clone()
    }
}

/// How well a reference render agrees with its check render.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Convergence {
    /// ε of the reference.
    pub epsilon: f64,
    /// ε of the check render.
    pub check_epsilon: f64,
    /// Step budget of both.
    pub max_steps: u32,
    /// Colour difference between the two.
    pub difference: Difference,
    /// First-hit difference (the check render measured against the reference).
    pub depth: Option<DepthDifference>,
    /// Camera and secondary rays of the reference that ran out of steps.
    pub budget_misses: u64,
    /// Whether PSNR ≥ [`CONVERGED_PSNR`] and no ray ran out of steps.
    pub converged: bool,
}

/// Compares a reference render (rendered with `settings`) with its check render.
pub fn convergence(settings: &Settings, reference: &Render, check: &Render) -> Convergence {
    let difference =
        metrics::compare(&reference.image, &check.image, THRESHOLD).unwrap_or(Difference {
            rmse: f64::NAN,
            psnr: f64::NAN,
            max: f64::NAN,
            differing: f64::NAN,
            threshold: THRESHOLD,
        });
    let depth = match (&reference.depth, &check.depth) {
        (Some(r), Some(c)) => metrics::compare_depth(r, c, DEPTH_TOLERANCE),
        _ => None,
    };
    let budget_misses = reference.stats.counters.budget_misses;
    Convergence {
        epsilon: settings.epsilon,
        check_epsilon: settings.epsilon / CHECK_FACTOR,
        max_steps: settings.max_steps,
        difference,
        depth,
        budget_misses,
        converged: difference.psnr >= CONVERGED_PSNR && budget_misses == 0,
    }
}

impl fmt::Display for Convergence {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let d = &self.difference;
        write!(
            f,
            "reference       f64, ε {:e}, {} steps; against ε {:e}: PSNR {:.2} dB, max difference {:.4}, {:.3}% of pixels differ by more than {}",
            self.epsilon,
            self.max_steps,
            self.check_epsilon,
            d.psnr,
            d.max,
            d.differing * 100.0,
            d.threshold
        )?;
        if let Some(z) = &self.depth {
            write!(
                f,
                "\nreference depth {:.3}% missed, {:.3}% false hits, mean relative depth difference {:.2e}",
                z.missed * 100.0,
                z.false_hit * 100.0,
                z.mean_relative_error.unwrap_or(0.0)
            )?;
        }
        write!(
            f,
            "\nconverged       {} ({} rays out of steps; needs PSNR ≥ {CONVERGED_PSNR} dB and none)",
            if self.converged { "yes" } else { "no" },
            self.budget_misses
        )
    }
}
