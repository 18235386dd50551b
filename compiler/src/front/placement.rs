//! The warnings about where the camera and lights stand (W0008–W0010): a scene without
//! lights, a camera or a point light inside a solid, found by evaluating the scene's distance
//! program, lowered literally, at its position. They run after the checker, on a scene
//! without errors, where the lowering is available.

use crate::check::Places;
use crate::diagnostics::Diagnostic;
use crate::eval::eval_point;
use crate::lower::{lower_with, LowerOptions};
use crate::scene::{Light, Scene};

/// W0008 (no lights), W0009 (the camera inside a solid), W0010 (a point light inside a
/// solid). Run on a scene without errors. The distance at a position is that of the program
/// lowered literally (`LowerOptions::level(0)`: the field as written, whose sign is the
/// scene's solid), evaluated in f64.
pub fn warnings(scene: &Scene, places: &Places) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    let Some(scene_span) = places.scene else {
        return out;
    };
    if scene.root.is_none() {
        // W0001 says it all.
        return out;
    }
    if scene.lights.is_empty() {
        out.push(
            Diagnostic::warning("W0008", "the scene has no lights", scene_span)
                .with_label("lit only by its materials' `ambient` term")
                .with_note(
                    "without a light every surface shows only `ambient` × its colour (`ambient` is 0.1 by default): a nearly black picture",
                )
                .with_help("add a light: `light directional { direction: (-1, -1, 1) }`"),
        );
    }
    let program = lower_with(scene, &LowerOptions::level(0));
    let distance = |p: [f64; 3]| eval_point::<f64>(&program, p);
    let (d, m) = distance(scene.camera.position);
    if d < 0.0 {
        let (span, default) = match places.camera {
            Some(s) => (s, false),
            None => (scene_span, true),
        };
        let mut diag = Diagnostic::warning("W0009", "the camera is inside a solid", span)
            .with_label(format!(
                "the scene's distance here is {}{}",
                fmt(d),
                painted(scene, m)
            ))
            .with_note("every camera ray starts inside the shape: the picture shows its inside, or nothing of the scene")
            .with_help("move the camera out of the shape (a plane is solid on the side its normal points away from)");
        if default {
            let p = scene.camera.position;
            diag = diag.with_note(format!(
                "there is no `camera` block, and the default camera is at ({}, {}, {})",
                fmt(p[0]),
                fmt(p[1]),
                fmt(p[2])
            ));
        }
        out.push(diag);
    }
    for (light, span) in scene.lights.iter().zip(&places.lights) {
        let Light::Point { position, .. } = light else {
            continue;
        };
        let (d, m) = distance(*position);
        if d < 0.0 {
            out.push(
                Diagnostic::warning("W0010", "the light is inside a solid", *span)
                    .with_label(format!(
                        "the scene's distance here is {}{}",
                        fmt(d),
                        painted(scene, m)
                    ))
                    .with_note("no surface outside the shape receives its light: every shadow ray towards it is blocked")
                    .with_help("move the light out of the shape"),
            );
        }
    }
    out
}

/// `, in a shape painted `red`` for a painted material, or nothing.
fn painted(scene: &Scene, m: u32) -> String {
    match scene.materials.get(m as usize) {
        Some(mat) if m > 0 => format!(", in a shape painted `{}`", mat.name),
        _ => String::new(),
    }
}

/// A number with at most three decimals and no trailing zeros.
fn fmt(x: f64) -> String {
    crate::diagnostics::number(x, 3)
}
