//! The warnings of the analysis (W0002–W0007, W0014): constructs that make the field unreliable,
//! reported once per code and source span, for nodes the scene's root reaches.

use super::{fmt, Pass, MAX_STEP_LIPSCHITZ};
use crate::diagnostics::Diagnostic;
use crate::scene::{Combine, NodeId, V3};

const AXES: [&str; 3] = ["x", "y", "z"];

impl Pass<'_> {
    /// Records a warning on `id`'s span, once per code and span, for nodes the root reaches.
    fn warn(
        &mut self,
        code: &'static str,
        id: NodeId,
        message: String,
        label: String,
        notes: Vec<String>,
        help: &str,
    ) {
        if !self.usage.reachable[id.0 as usize] {
            return;
        }
        let span = self.scene.graph.span(id);
        if !self.reported.insert((code, span)) {
            return;
        }
        let mut d = Diagnostic::warning(code, message, span).with_label(label);
        for n in notes {
            d = d.with_note(n);
        }
        self.diagnostics.push(d.with_help(help));
    }

    pub(super) fn warn_exp(&mut self, id: NodeId, op: Combine, k: f64, reach: f64, size: f64) {
        let name = op.name(true);
        self.warn(
            "W0002",
            id,
            format!("the exponential {name} with k = {} is not local", fmt(k)),
            format!("it moves surfaces by up to k·ln 2 = {}, more than the smaller operand's half-size {}", fmt(reach), fmt(size)),
            vec!["the exponential smooth minimum changes the field wherever the operands are within a few k of each other, not only where they meet; the field stays a bound, but the shapes no longer look like the operands, and surfaces can appear between distant objects".into()],
            "use the default `variant: \"poly\"` (its blend stays where the operands are within k of each other and moves surfaces by at most k/4), or a smaller k",
        );
    }

    pub(super) fn warn_stretch(&mut self, id: NodeId, what: &str, rate: f64, rho: f64, sigma: f64) {
        self.warn(
            "W0003",
            id,
            format!("this {what} stretches distances up to {}-fold", fmt(sigma)),
            format!("rate {} at {} from its axis", fmt(rate), fmt(rho)),
            vec![
                format!("the {} field is then only {}-Lipschitz: the operand that holds it is divided by its own L (local bounds, docs/analysis.md), so rays within that operand's bounding volume take steps divided by its L, and the rest of the scene steps as before", match what { "twist" => "twisted", "bend" => "bent", _ => "tapered" }, fmt(sigma)),
            ],
            &format!("lower the rate, or {what} a narrower shape"),
        );
    }

    pub(super) fn warn_unbounded(&mut self, id: NodeId, what: &str, sigma: f64, rho: f64) {
        self.warn(
            "W0004",
            id,
            format!("this {what} acts on an unbounded shape, so its field has no Lipschitz bound"),
            format!("the shape reaches arbitrarily far from the {what} axis"),
            vec![format!(
                "the stretch grows with the distance from the axis; over the region rays can reach (up to {} from it) it is {}-fold, and renders clamp L to {}",
                fmt(rho),
                fmt(sigma),
                fmt(MAX_STEP_LIPSCHITZ)
            )],
            &format!("intersect the shape with a box before the {what}, so that it is bounded"),
        );
    }

    pub(super) fn warn_overlap(&mut self, id: NodeId, axis: usize, lo: f64, hi: f64, period: f64) {
        let need = 2.0 * lo.abs().max(hi.abs());
        self.warn(
            "W0005",
            id,
            "the repeated shape does not fit in its cell".into(),
            format!("on {} it spans {} … {}, but the cell is {} … {}", AXES[axis], fmt(lo), fmt(hi), fmt(-period / 2.0), fmt(period / 2.0)),
            vec!["only the copy in a point's own cell is evaluated: the parts of neighbouring copies that reach into the cell are cut off, and the field can overstate the distance, so rays may step through them".into()],
            &if need.is_finite() {
                format!("make the period on {} at least {}, or shrink the shape", AXES[axis], fmt(need))
            } else {
                "repeat a bounded shape".to_string()
            },
        );
    }

    pub(super) fn warn_off_centre(&mut self, id: NodeId, axis: usize) {
        self.warn(
            "W0006",
            id,
            "the repeated shape is not symmetric about its cell's centre".into(),
            format!("on {} the shape is not its own mirror image", AXES[axis]),
            vec!["only the copy in a point's own cell is evaluated; when the shape is off-centre, a neighbouring copy can be nearer than the own one, and the field overstates the distance".into()],
            "centre the shape in its cell: to shift every copy, translate after `repeat`, not before",
        );
    }

    pub(super) fn warn_scale(&mut self, id: NodeId, s: V3, ratio: f64) {
        self.warn(
            "W0007",
            id,
            format!("this scale stretches the shape by a ratio of {}", fmt(ratio)),
            format!("factors ({}, {}, {})", fmt(s[0]), fmt(s[1]), fmt(s[2])),
            vec![format!("a per-axis scale multiplies the field by its smallest factor: a bound that underestimates distances up to {}-fold along the stretched axes, so rays approaching that way take up to {} times more steps and may run out of them", fmt(ratio), fmt(ratio))],
            "build the shape at its final size instead (a box's half-extents, an ellipsoid's radii)",
        );
    }

    /// A deformation that maps several points of space to one point of its shape, or none
    /// (W0014): `what` is the deformation, `how` says where.
    pub(super) fn warn_fold(&mut self, id: NodeId, what: &str, how: String, help: &str) {
        self.warn(
            "W0014",
            id,
            format!("this {what} folds space over itself"),
            how,
            vec![format!("where the {what} folds, two parts of the shape land on one another or the shape is cut off; the field there is no longer a distance, and rays may step through surfaces")],
            help,
        );
    }

    pub(super) fn warn_polar(&mut self, id: NodeId, count: u32, cells: u32) {
        self.warn(
            "W0005",
            id,
            "the repeated shape reaches too far out of its sector".into(),
            format!("{count} copies, of which {cells} would be evaluated per point"),
            vec![format!("a polar repetition evaluates the copies whose sectors the shape reaches into, at most {} per point (with the repetitions nested in it); beyond that only the nearest copies are evaluated and the field can overstate the distance", super::MAX_WINDOW_CELLS)],
            "make the shape narrower around the axis, or use fewer copies",
        );
    }
}
