//! The reference render that accuracy is measured against (docs/rendering.md, "Precision";
//! docs/accuracy.md): f64, a step budget of 100 000, no over-relaxation and steps of d/L (L
//! from `Options::lipschitz`), and its convergence check, a second render that refines it and
//! must agree with it. For a field with a proven distance bound the reference uses ε = 1e-6 and
//! the check ε ten times smaller. A field with no proven bound (a fractal) has detail below any
//! ε, so point samples at ever smaller ε never converge: its reference is the area average of
//! the pixel (at least [`AREA_AA`]² samples) of the surface seen at the pixel footprint's ε, and
//! the check doubles the samples per axis.

use super::Render;
use crate::metrics::{self, DepthDifference, Difference};
use sdfc_compiler::{diagnostics::scientific, Scene, Settings};
use std::fmt;

/// The hit tolerance ε of the reference of a field with a proven bound.
pub const EPSILON: f64 = 1e-6;

/// The step budget of the reference (large enough that no ordinary ray runs out).
pub const MAX_STEPS: u32 = 100_000;

/// The convergence check of a proven field renders again with ε divided by this.
pub const CHECK_FACTOR: f64 = 10.0;

/// The least supersampling (samples per axis) of the area-averaged reference of a field with
/// no proven bound; its check doubles it. Seed 6 at 320×240: 8 against 16 agree to 55.5 dB,
/// 4 against 8 to 47.2 dB (docs/accuracy.md).
pub const AREA_AA: u32 = 8;

/// The reference counts as converged when the check render agrees with it to at least this
/// PSNR (dB). Test renders are judged against the reference at 40 dB, so the reference must
/// be at least ten times (10 dB) more accurate than that.
pub const CONVERGED_PSNR: f64 = 50.0;

/// A path-traced reference has this many times the samples of the renders it measures (four
/// octaves: its noise 12 dB below theirs), `sdfc pareto`'s; its check is a render of as many
/// other samples of the random stream.
pub const PATH_FACTOR: u32 = 16;

/// Per-channel difference above which a pixel counts as differing in the check.
pub const THRESHOLD: f64 = 0.1;

/// Relative depth tolerance of the check's `behind` count.
pub const DEPTH_TOLERANCE: f64 = 1e-3;

/// The reference settings of a scene whose field has (`proven`) or has not a proven distance
/// bound: ε, the step budget, the relaxation and, without a bound, the pixel footprint's ε and
/// at least [`AREA_AA`]² samples; the size, depth limit and everything else stay.
pub fn settings(s: &Settings, proven: bool) -> Settings {
    let base = Settings {
        max_steps: MAX_STEPS.max(s.max_steps),
        relaxation: 1.0,
        ..s.clone()
    };
    if proven {
        Settings {
            epsilon: EPSILON,
            footprint: false,
            ..base
        }
    } else {
        Settings {
            footprint: true,
            aa: s.aa.max(AREA_AA),
            ..base
        }
    }
}

/// The reference settings of `scene` ([`settings`], with its field's proven bound or not).
pub fn settings_of(scene: &Scene) -> Settings {
    let analysis = sdfc_compiler::analysis::analyse(scene);
    let proven = analysis.root().is_none_or(|root| root.proven);
    settings(&scene.settings, proven)
}

/// The settings of the convergence check for reference settings `s`: ε divided by
/// [`CHECK_FACTOR`], or for an area-averaged reference (ε from the footprint) twice the
/// samples per axis; a path-traced one's also other samples of the random stream.
pub fn check_settings(s: &Settings) -> Settings {
    // A path-traced reference's own error is mostly its noise: the check draws as many
    // samples again, the next of the random stream (and ε ten times smaller).
    let s = &Settings {
        first_sample: if s.path {
            s.first_sample.wrapping_add(s.samples)
        } else {
            s.first_sample
        },
        ..s.clone()
    };
    if s.footprint {
        Settings {
            aa: s.aa * 2,
            ..s.clone()
        }
    } else {
        Settings {
            epsilon: s.epsilon / CHECK_FACTOR,
            ..s.clone()
        }
    }
}

/// How well a reference render agrees with its check render.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Convergence {
    /// ε of the reference.
    pub epsilon: f64,
    /// ε of the check render.
    pub check_epsilon: f64,
    /// Supersampling (samples per axis) of the reference.
    pub aa: u32,
    /// Supersampling of the check render.
    pub check_aa: u32,
    /// Step budget of both.
    pub max_steps: u32,
    /// Colour difference between the two.
    pub difference: Difference,
    /// First-hit difference (the check render measured against the reference).
    pub depth: Option<DepthDifference>,
    /// Camera and secondary rays of the reference that ran out of steps.
    pub budget_misses: u64,
    /// Whether PSNR ≥ [`CONVERGED_PSNR`] and the rays that ran out of steps amount to less
    /// than one pixel (fewer than aa² of them: none at aa 1).
    pub converged: bool,
}

/// The samples of one pixel (aa²) of settings `s`.
fn samples_per_pixel(s: &Settings) -> u64 {
    u64::from(s.aa.max(1)).pow(2)
}

/// Compares the render of the reference `scene` with its check render (rendered with
/// [`check_settings`]).
pub fn convergence(scene: &Scene, reference: &Render, check: &Render) -> Convergence {
    let settings = &scene.settings;
    let checked = check_settings(settings);
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
        epsilon: scene.epsilon(),
        check_epsilon: checked.hit_epsilon(scene.camera.fov),
        aa: settings.aa,
        check_aa: checked.aa,
        max_steps: settings.max_steps,
        difference,
        depth,
        budget_misses,
        converged: difference.psnr >= CONVERGED_PSNR && budget_misses < samples_per_pixel(settings),
    }
}

impl fmt::Display for Convergence {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let d = &self.difference;
        write!(
            f,
            "reference       f64, ε {}, aa {}, {} steps; against ε {}, aa {}: PSNR {:.2} dB, max difference {:.4}, {:.3}% of pixels differ by more than {}",
            scientific(self.epsilon),
            self.aa,
            self.max_steps,
            scientific(self.check_epsilon),
            self.check_aa,
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
            "\nconverged       {} ({} rays out of steps; needs PSNR ≥ {CONVERGED_PSNR} dB and fewer than {}, one pixel's samples)",
            if self.converged { "yes" } else { "no" },
            self.budget_misses,
            self.aa * self.aa
        )
    }
}
