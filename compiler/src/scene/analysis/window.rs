//! The windows of neighbouring copies a repetition evaluates (`docs/analysis.md`,
//! "Repetition" and "Polar repetition"): how many cells on each side, and a lower bound of
//! the distance to every copy left out.

use super::{Aabb, Window, MAX_WINDOW_CELLS, TOLERANCE};
use crate::scene::ir::V3;

/// The copies a polar repetition of `count` copies evaluates around the point's own sector,
/// for a child within ±`alpha` of angle 0: `reach[0]` sectors on each side, and `beyond` the
/// factor sin γ with γ = (2r + 1)·π/count − α, so that ρ·sin γ (ρ the distance from the
/// axis) is a lower bound of the distance to every copy outside the window (infinite when
/// the window holds every copy). `docs/analysis.md`, "Polar repetition", derives it.
pub(super) fn polar_window(count: u32, alpha: f64) -> Window {
    let n = f64::from(count);
    let sector = std::f64::consts::PI / n;
    // The least r ≥ 1 with (2r + 1)·π/n > α, plus a sliver, so that γ is not 0.
    let mut r = ((alpha / sector - 1.0) * 0.5).floor() + 1.0;
    r = r.max(1.0);
    if (2.0 * r + 1.0) * sector - alpha < 1e-6 {
        r += 1.0;
    }
    if 2.0 * r + 1.0 >= n {
        return Window {
            reach: [(count / 2).max(1), 0, 0],
            beyond: f64::INFINITY,
        };
    }
    let gamma = ((2.0 * r + 1.0) * sector - alpha).min(std::f64::consts::FRAC_PI_2);
    Window {
        reach: [r as u32, 0, 0],
        beyond: gamma.sin(),
    }
}

/// The window of neighbouring cells that makes a repetition of a child with box `extent` a
/// bound read up to level `margin`, or `None` when it would exceed [`MAX_WINDOW_CELLS`].
///
/// Along an axis of period s where the child fits and is symmetric, the own cell suffices
/// (reach 0). Elsewhere, with h the child's farthest extent from its cell's centre, a copy r + 1
/// or more cells away lies at least (r + ½)·s − h from the point along that axis (the point is
/// within ½·s of its own cell's centre, or outside the array beyond it): the reach r is the
/// least ≥ 1 that makes this exceed the margin, and `beyond` is its minimum over such axes.
/// A finite repetition whose window holds every copy on an axis needs no bound there.
pub(super) fn window(
    extent: &Aabb,
    symmetric: [bool; 3],
    period: V3,
    count: Option<V3>,
    margin: f64,
) -> Option<Window> {
    let mut w = Window {
        reach: [0; 3],
        beyond: f64::INFINITY,
    };
    let mut cells = 1.0;
    for (i, s, n) in repeated_axes(extent, period, count) {
        let (lo, hi, half) = (extent.min[i], extent.max[i], s * 0.5);
        let fits = lo >= -half - TOLERANCE && hi <= half + TOLERANCE;
        if fits && symmetric[i] {
            continue;
        }
        let h = lo.abs().max(hi.abs());
        let mut r = ((h + margin) / s - 0.5).floor() + 1.0;
        r = r.max(1.0);
        if r >= n - 1.0 {
            r = n - 1.0;
        } else {
            w.beyond = w.beyond.min((r + 0.5) * s - h);
        }
        cells *= 2.0 * r + 1.0;
        if !(cells <= MAX_WINDOW_CELLS as f64) {
            return None;
        }
        w.reach[i] = r as u32;
    }
    Some(w)
}

/// The axes along which a repetition of a non-empty shape makes copies: (axis, period,
/// number of copies, infinite for an infinite repetition).
pub(super) fn repeated_axes(
    extent: &Aabb,
    period: V3,
    count: Option<V3>,
) -> impl Iterator<Item = (usize, f64, f64)> {
    let empty = extent.is_empty();
    (0..3).filter_map(move |i| {
        let n = count.map_or(f64::INFINITY, |n| n[i]);
        (period[i] != 0.0 && n > 1.0 && !empty).then_some((i, period[i], n))
    })
}
