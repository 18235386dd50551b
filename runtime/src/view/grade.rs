//! The viewer's grade: the exposure and tone curve of the scene on show, taken out of the
//! scene its frames render (so that they render linear light, which adds up as samples do)
//! and applied to the mean of the samples accumulated, as `sdfc render` grades the mean of
//! its samples (docs/rendering.md, "The look"; docs/viewer.md).

use sdfc_compiler::{look, Settings, Tonemap};

/// A scene's exposure (in stops) and tone curve.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Grade {
    pub exposure: f64,
    pub tonemap: Tonemap,
}

impl Grade {
    /// Takes the grade out of `settings`, leaving them ungraded (exposure 0, tone curve
    /// `none`: a kernel or the CPU renderer then writes the linear light of its samples), and
    /// returns it.
    pub fn take(settings: &mut Settings) -> Grade {
        let grade = Grade {
            exposure: settings.exposure,
            tonemap: settings.tonemap,
        };
        settings.exposure = 0.0;
        settings.tonemap = Tonemap::None;
        grade
    }

    /// Whether the grade changes a colour (without it the mean is shown as it is).
    pub fn grades(&self) -> bool {
        self.exposure != 0.0 || self.tonemap != Tonemap::None
    }

    /// 2^exposure, the factor before the tone curve.
    pub fn scale(&self) -> f32 {
        self.exposure.exp2() as f32
    }

    /// A linear colour (a mean of samples) graded: `look::grade` on each channel; unchanged,
    /// bit for bit, without a grade.
    pub fn apply(&self, c: [f32; 3]) -> [f32; 3] {
        if !self.grades() {
            return c;
        }
        c.map(|x| look::grade(self.tonemap, self.exposure, x as f64) as f32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Taking the grade leaves the settings ungraded, and applying it grades as the formula
    /// does; no grade is the identity.
    #[test]
    fn a_grade_taken_is_applied_to_the_mean() {
        let mut s = Settings {
            exposure: 1.0,
            tonemap: Tonemap::Filmic,
            ..Settings::default()
        };
        let g = Grade::take(&mut s);
        assert_eq!((s.exposure, s.tonemap), (0.0, Tonemap::None));
        assert_eq!(Grade::take(&mut s), Grade::default());
        assert_eq!(g.scale(), 2.0);
        let c = g.apply([0.1, 0.5, 4.0]);
        for (a, x) in c.iter().zip([0.1, 0.5, 4.0]) {
            let want = look::grade(Tonemap::Filmic, 1.0, x) as f32;
            assert_eq!(*a, want);
        }
        assert!(c[2] <= 1.0 && c[0] > 0.0);
        let odd = [0.123_456_79, 7.5, -0.0];
        assert_eq!(Grade::default().apply(odd), odd);
    }
}
