//! How far from the camera the scene's bounded parts reach: the default `max_dist` covers
//! them, and a `max_dist` the written scene sets that leaves one out is W0017.

use super::bounds::{Bound, Bounds};
use super::ir::{Combine, Node, Scene};
use crate::diagnostics::Diagnostic;
use crate::span::Span;

/// A bounded part of the scene (a child of its root union): where it is written, and the
/// least and the most distance from the camera to its bounding volume.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Part {
    pub span: Span,
    pub near: f64,
    pub far: f64,
}

/// The bounded parts of `scene`, seen from its camera (unbounded ones, such as a floor
/// plane, are left out: rays cross them wherever `max_dist` ends).
pub fn parts(scene: &Scene) -> Vec<Part> {
    let Some(root) = scene.root else {
        return Vec::new();
    };
    let bounds = Bounds::new(&scene.graph);
    let eye = scene.camera.position;
    let mut out = Vec::new();
    let mut stack = vec![root];
    while let Some(id) = stack.pop() {
        match scene.graph.node(id) {
            Node::Paint { child, .. } => stack.push(*child),
            Node::Combine {
                op: Combine::Union,
                children,
            } => stack.extend(children.iter().rev()),
            _ => {
                if let Some(b) = bounds.get(id).filter(Bound::finite) {
                    out.push(seen(scene.graph.span(id), &b, eye));
                }
            }
        }
    }
    out
}

/// A part's distances from the eye: to the nearest point of its box, and to its farthest
/// point by the tighter of its box and its sphere.
fn seen(span: Span, b: &Bound, eye: [f64; 3]) -> Part {
    let gap = |i: usize| (eye[i] - b.aabb.c[i]).abs();
    let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let near = norm([0, 1, 2].map(|i| (gap(i) - b.aabb.h[i]).max(0.0)));
    let corner = norm([0, 1, 2].map(|i| gap(i) + b.aabb.h[i]));
    let centre = norm([0, 1, 2].map(|i| eye[i] - b.sphere.c[i]));
    Part {
        span,
        near,
        far: corner.min(centre + b.sphere.r),
    }
}

/// The `max_dist` a scene gets when it does not set one: `default`, or more where a bounded
/// part reaches farther from the camera (with a margin of 1 %, so that its far side is hit
/// by rays that end there).
pub fn default_max_dist(parts: &[Part], default: f64) -> f64 {
    parts.iter().map(|p| p.far * 1.01).fold(default, f64::max)
}

/// W0017 for each bounded part that reaches beyond the `max_dist` the scene sets (written
/// at `setting`).
pub fn beyond(parts: &[Part], max_dist: f64, setting: Span) -> Vec<Diagnostic> {
    let show = crate::scene::dump_num;
    parts
        .iter()
        .filter(|p| p.far > max_dist)
        .map(|p| {
            let message = if p.near > max_dist {
                format!(
                    "this shape lies {} to {} units from the camera, all beyond `max_dist` ({}): it is not seen",
                    show(p.near),
                    show(p.far),
                    show(max_dist)
                )
            } else {
                format!(
                    "this shape reaches {} units from the camera, beyond `max_dist` ({}): rays stop before its far side",
                    show(p.far),
                    show(max_dist)
                )
            };
            Diagnostic::warning("W0017", message, p.span)
                .with_label("cut off by `max_dist`")
                .with_secondary(setting, "`max_dist` is set here")
                .with_help(format!(
                    "raise `max_dist` to {} or more, or leave it out: the default covers every bounded part",
                    show((p.far * 1.01).ceil())
                ))
        })
        .collect()
}
