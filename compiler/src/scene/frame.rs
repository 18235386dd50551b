//! The maps a colour field's point goes through from the world to the coordinates of the
//! shape its material paints ([`Frame`], docs/language.md "Colour fields"): a leaf of the
//! scene IR, which [`Material::frame`](super::Material) holds; `paint.rs` finds them, the
//! lowering applies them (`lower/field.rs`).

/// One map from the coordinates outside a node to those of its child, as a colour field's
/// point goes through it (the distance's own maps, `lower/graph.rs`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Frame {
    /// `q = matrix · p + offset` (rows): translations, rotations, reflections, scales and
    /// shears, composed.
    Affine {
        matrix: [[f64; 3]; 3],
        offset: [f64; 3],
    },
    /// `q = |p|` along the axes set (`mirror`).
    Mirror([bool; 3]),
    /// The point in its copy's cell (`repeat`), as the distance finds it.
    Repeat {
        period: [f64; 3],
        count: Option<[f64; 3]>,
    },
}

impl Frame {
    /// `self` followed by `inner` as one frame, where both are affine.
    pub(super) fn then(self, inner: Frame) -> Option<Frame> {
        match (self, inner) {
            (
                Frame::Affine {
                    matrix: a,
                    offset: s,
                },
                Frame::Affine {
                    matrix: b,
                    offset: t,
                },
            ) => {
                // b(a p + s) + t
                let matrix =
                    [0, 1, 2].map(|i| [0, 1, 2].map(|j| (0..3).map(|k| b[i][k] * a[k][j]).sum()));
                let offset = [0, 1, 2].map(|i| (0..3).map(|k| b[i][k] * s[k]).sum::<f64>() + t[i]);
                Some(Frame::Affine { matrix, offset })
            }
            _ => None,
        }
    }
}
