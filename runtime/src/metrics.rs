//! Image error metrics: RMSE, PSNR and the largest difference on linear colour (clamped to
//! [0, 1], the displayable range), the fraction of pixels that differ by more than a threshold,
//! and, from the depth and hit buffers of two renders, how their first hits differ.

use crate::depth::Depth;
use crate::image::Image;

/// How two images of the same size differ.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Difference {
    /// Root-mean-square error over all channels.
    pub rmse: f64,
    /// Peak signal-to-noise ratio in dB (peak 1); infinite for identical images.
    pub psnr: f64,
    /// Largest difference of one channel of one pixel.
    pub max: f64,
    /// Fraction of pixels with some channel differing by more than the threshold.
    pub differing: f64,
    /// The threshold used for `differing`.
    pub threshold: f64,
}

/// Compares two images of the same size; `None` when the sizes differ.
pub fn compare(a: &Image, b: &Image, threshold: f64) -> Option<Difference> {
    if (a.width, a.height) != (b.width, b.height) || a.linear.len() != b.linear.len() {
        return None;
    }
    let mut sum = 0.0;
    let mut differing = 0usize;
    let mut max = 0.0f64;
    for (p, q) in a.linear.iter().zip(&b.linear) {
        let mut worst = 0.0f64;
        for c in 0..3 {
            let d = clamp01(p[c]) - clamp01(q[c]);
            sum += d * d;
            worst = worst.max(d.abs());
        }
        max = max.max(worst);
        if worst > threshold {
            differing += 1;
        }
    }
    let n = a.linear.len().max(1) as f64;
    let mse = sum / (3.0 * n);
    let psnr = if mse == 0.0 {
        f64::INFINITY
    } else {
        -10.0 * mse.log10()
    };
    Some(Difference {
        rmse: mse.sqrt(),
        psnr,
        max,
        differing: differing as f64 / n,
        threshold,
    })
}

/// How the first hits of a test render differ from those of a reference render. Fractions
/// are of all pixels; a pixel is a hit when at least half of its camera rays hit.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct DepthDifference {
    /// Pixels the reference hit and the test missed.
    pub missed: f64,
    /// Pixels the test hit and the reference missed.
    pub false_hit: f64,
    /// Pixels both hit where the test's hit lies behind the reference's by more than
    /// `tolerance` times the reference distance.
    pub behind: f64,
    /// Pixels both hit.
    pub both_hit: f64,
    /// Mean of |t_test − t_ref| / t_ref over the pixels both hit (`None` when there are none).
    pub mean_relative_error: Option<f64>,
    /// The relative tolerance used for `behind`.
    pub tolerance: f64,
}

/// Compares the depth buffers of a reference and a test render of the same size; `None`
/// when the sizes differ.
pub fn compare_depth(reference: &Depth, test: &Depth, tolerance: f64) -> Option<DepthDifference> {
    if (reference.width, reference.height) != (test.width, test.height)
        || reference.len() != test.len()
    {
        return None;
    }
    let (mut missed, mut false_hit, mut behind, mut both) = (0usize, 0usize, 0usize, 0usize);
    let mut relative = 0.0f64;
    for i in 0..reference.len() {
        match (reference.hit(i), test.hit(i)) {
            (true, false) => missed += 1,
            (false, true) => false_hit += 1,
            (true, true) => {
                both += 1;
                let (r, t) = (reference.distance[i] as f64, test.distance[i] as f64);
                let scale = r.abs().max(f64::MIN_POSITIVE);
                relative += (t - r).abs() / scale;
                if t - r > tolerance * scale {
                    behind += 1;
                }
            }
            (false, false) => {}
        }
    }
    let n = reference.len().max(1) as f64;
    Some(DepthDifference {
        missed: missed as f64 / n,
        false_hit: false_hit as f64 / n,
        behind: behind as f64 / n,
        both_hit: both as f64 / n,
        mean_relative_error: (both > 0).then(|| relative / both as f64),
        tolerance,
    })
}

fn clamp01(x: f32) -> f64 {
    if x.is_nan() {
        1.0
    } else {
        (x as f64).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(pixels: &[[f32; 3]]) -> Image {
        Image {
            width: pixels.len() as u32,
            height: 1,
            linear: pixels.to_vec(),
        }
    }

    #[test]
    fn hand_computed_values() {
        let a = image(&[[0.0; 3], [1.0; 3]]);
        let b = image(&[[0.1, 0.0, 0.0], [1.0; 3]]);
        let d = compare(&a, &b, 0.05).expect("same size");
        // One channel of six differs by 0.1: mse = 0.01 / 6.
        assert!((d.rmse - (0.01f64 / 6.0).sqrt()).abs() < 1e-9);
        assert!((d.psnr - (-10.0 * (0.01f64 / 6.0).log10())).abs() < 1e-6);
        assert_eq!(d.differing, 0.5);
        assert_eq!(compare(&a, &a, 0.0).map(|d| d.psnr), Some(f64::INFINITY));
        assert!(compare(&a, &image(&[[0.0; 3]]), 0.1).is_none());
    }

    #[test]
    fn out_of_range_values_are_clamped() {
        let a = image(&[[2.0, -1.0, 0.5]]);
        let b = image(&[[1.0, 0.0, 0.5]]);
        assert_eq!(compare(&a, &b, 0.0).map(|d| d.rmse), Some(0.0));
    }
}
