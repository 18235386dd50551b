//! The warnings about where the camera and lights stand, and about light and colour values
//! that are probably not what was meant (W0008–W0011): a scene without lights, a camera or a
//! point light inside a solid (found by evaluating the lowered distance program at its
//! position), a colour component above 1.

use super::eval::Ctx;
use super::types::Value;
use crate::diagnostics::Diagnostic;
use crate::lower::{lower_with, LowerOptions};
use crate::scene::{Light, Scene};
use crate::span::Span;

/// Where the parts of a scene that have a position were written, for the warnings' spans.
#[derive(Debug, Default)]
pub struct Places {
    /// The camera's `position` (its value, or the `camera` keyword when it is left out);
    /// `None` without a `camera` block.
    pub camera: Option<Span>,
    /// Per light of `Scene::lights`, in order: its `position` value, or its kind.
    pub lights: Vec<Span>,
    /// The `scene` keyword.
    pub scene: Option<Span>,
}

/// The record fields that are colours (of materials, lights and the background).
const COLOUR_FIELDS: &[&str] = &["color", "a", "b", "background"];

/// W0011 for a colour field with a component above 1: the 0–255 habit.
pub fn colour(cx: &mut Ctx, record: &str, field: &str, v: &Value, span: Span) {
    let Value::Vec3(c) = v else { return };
    if !COLOUR_FIELDS.contains(&field) || c.iter().all(|x| *x <= 1.0) {
        return;
    }
    let scaled = c.map(|x| fmt(x / 255.0));
    let mut d = Diagnostic::warning(
        "W0011",
        format!("`{field}` of `{record}` has a component above 1"),
        span,
    )
    .with_label(format!("this is {v}"))
    .with_note("colours go from 0 to 1 in each channel; above 1 is brighter than white");
    if record == "point" || record == "directional" {
        d = d.with_note("to make a light brighter, raise its `intensity` instead");
    }
    let max = c.iter().fold(0.0f64, |a, x| a.max(*x));
    if max > 2.0 && max <= 255.0 {
        d = d.with_help(format!(
            "if these are 0–255 values, divide them by 255: `({}, {}, {})`",
            scaled[0], scaled[1], scaled[2]
        ));
    }
    cx.error(d);
}

/// W0008 (no lights), W0009 (the camera inside a solid), W0010 (a point light inside a
/// solid). Run on a scene without errors. The distance at a position is that of the program
/// lowered literally (`LowerOptions::level(0)`: the field as written, whose sign is the
/// scene's solid), evaluated in f64.
pub fn placement(cx: &mut Ctx, scene: &Scene) {
    let places = std::mem::take(&mut cx.places);
    let Some(scene_span) = places.scene else {
        return;
    };
    if scene.root.is_none() {
        // W0001 says it all.
        return;
    }
    if scene.lights.is_empty() {
        cx.error(
            Diagnostic::warning("W0008", "the scene has no lights", scene_span)
                .with_label("lit only by its materials' `ambient` term")
                .with_note(
                    "without a light every surface shows only `ambient` × its colour (`ambient` is 0.1 by default): a nearly black picture",
                )
                .with_help("add a light: `light directional { direction: (-1, -1, 1) }`"),
        );
    }
    let program = lower_with(scene, &LowerOptions::level(0));
    let distance = |p: [f64; 3]| crate::eval::eval_point::<f64>(&program, p);
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
        cx.error(diag);
    }
    for (light, span) in scene.lights.iter().zip(&places.lights) {
        let Light::Point { position, .. } = light else {
            continue;
        };
        let (d, m) = distance(*position);
        if d < 0.0 {
            cx.error(
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
