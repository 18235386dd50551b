//! Colours as written: W0011, a component above 1 in a record's colour field (the 0–255
//! habit), and the sRGB bytes of `#rrggbb` (and of images read back) as linear values.

use super::types::Value;
use crate::diagnostics::Diagnostic;
use crate::span::Span;

/// The record fields that are colours (of materials, lights and the background).
const COLOUR_FIELDS: &[&str] = &["color", "a", "b", "background"];

/// W0011 for a colour field with a component above 1: the 0–255 habit.
pub fn warning(record: &str, field: &str, v: &Value, span: Span) -> Option<Diagnostic> {
    let Value::Vec3(c) = v else { return None };
    if !COLOUR_FIELDS.contains(&field) || c.iter().all(|x| *x <= 1.0) {
        return None;
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
    Some(d)
}

/// A number with at most three decimals and no trailing zeros.
fn fmt(x: f64) -> String {
    crate::diagnostics::number(x, 3)
}

/// An sRGB byte as the linear value the renderer's colours are (the sRGB transfer function,
/// IEC 61966-2-1).
pub fn srgb_to_linear(byte: u8) -> f64 {
    let c = f64::from(byte) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}
