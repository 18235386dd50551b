//! Image error metrics: RMSE and PSNR on linear colour (clamped to [0, 1], the displayable
//! range), and the fraction of pixels that differ by more than a threshold.

use crate::image::Image;

/// How two images of the same size differ.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Difference {
    /// Root-mean-square error over all channels.
    pub rmse: f64,
    /// Peak signal-to-noise ratio in dB (peak 1); infinite for identical images.
    pub psnr: f64,
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
    for (p, q) in a.linear.iter().zip(&b.linear) {
        let mut worst = 0.0f64;
        for c in 0..3 {
            let d = clamp01(p[c]) - clamp01(q[c]);
            sum += d * d;
            worst = worst.max(d.abs());
        }
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
        differing: differing as f64 / n,
        threshold,
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
