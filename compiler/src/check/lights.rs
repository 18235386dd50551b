//! The `light` blocks: a light of each kind (`point`, `directional`, `sun`, `sky`) from its
//! fields, with `softness`'s old spelling of the penumbra (W0012) and an unknown kind (E0211).

use super::eval::{self, Ctx};
use super::types::Value;
use super::{builtins, field_span, unknown_kind};
use crate::diagnostics::Diagnostic;
use crate::scene::{Light, Scene};
use crate::syntax::ast;
use std::collections::HashMap;

/// Adds the light of the block `b` of kind `kind` to the scene.
pub(super) fn light(cx: &mut Ctx, scene: &mut Scene, b: &ast::Block, kind: &ast::Ident) {
    let Some(rec) = builtins::LIGHTS.iter().find(|r| r.name == kind.name) else {
        let note = "the light kinds are point, directional, sun and sky";
        return unknown_kind(cx, "light", kind, builtins::LIGHTS, note);
    };
    let f = eval::record(cx, rec, &b.fields, kind);
    let (color, intensity) = (f["color"].v3(), f["intensity"].num());
    cx.places
        .lights
        .push(field_span(&b.fields, "position").unwrap_or(kind.span));
    let shadows = !matches!(f["shadows"], Value::Bool(false));
    let unit = |d: [f64; 3]| {
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
            .sqrt()
            .max(f64::MIN_POSITIVE);
        [d[0] / len, d[1] / len, d[2] / len]
    };
    if rec.name == "sky" {
        // `color` gives all three; those given beside it win.
        let given = |name: &str| field_span(&b.fields, name).is_some();
        let part = |name: &str| {
            if given(name) || !given("color") {
                f[name].v3()
            } else {
                color
            }
        };
        scene.lights.push(Light::Sky {
            zenith: part("zenith"),
            horizon: part("horizon"),
            ground: part("ground"),
            intensity,
            shadows,
            background: !matches!(f["background"], Value::Bool(false)),
        });
        return;
    }
    if rec.name == "sun" {
        scene.lights.push(Light::Directional {
            direction: unit(f["direction"].v3()),
            color,
            intensity,
            penumbra: f["angle"].num(),
            shadows,
        });
        return;
    }
    let penumbra = penumbra(cx, &b.fields, &f);
    scene.lights.push(if rec.name == "point" {
        Light::Point {
            position: f["position"].v3(),
            color,
            intensity,
            radius: f["radius"].num(),
            penumbra,
            shadows,
        }
    } else {
        Light::Directional {
            direction: unit(f["direction"].v3()),
            color,
            intensity,
            penumbra,
            shadows,
        }
    });
}

/// A light's penumbra angle: its `penumbra` field, or the angle of the sharpness of the old
/// `softness` field, with warning W0012 saying what to write instead (error E0203 for both).
fn penumbra(cx: &mut Ctx, fields: &[ast::Field], f: &HashMap<&'static str, Value>) -> f64 {
    let given = |name: &str| fields.iter().find(|x| x.name.name == name);
    let Some(old) = given("softness") else {
        return f["penumbra"].num();
    };
    if let Some(new) = given("penumbra") {
        cx.error(
            Diagnostic::error(
                "E0203",
                "a light has both `penumbra` and `softness`",
                old.name.span,
            )
            .with_label("the old spelling of the penumbra")
            .with_secondary(new.name.span, "the penumbra is given here")
            .with_help("remove `softness`"),
        );
        return f["penumbra"].num();
    }
    let k = f["softness"].num();
    let angle = crate::scene::penumbra_of_sharpness(k);
    if !f["softness"].is_abstract() {
        let write = if k > 0.0 {
            format!(
                "penumbra: {}deg",
                crate::diagnostics::number(angle.to_degrees(), 4)
            )
        } else {
            "nothing (hard shadows are the default)".to_string()
        };
        cx.error(
            Diagnostic::warning(
                "W0012",
                "`softness` is replaced by `penumbra`",
                old.name.span,
            )
            .with_label(format!("the sharpness k = {k} of the shadow's edge"))
            .with_note(
                "`softness` was the sharpness k of the soft-shadow estimate: larger values give \
                 harder shadows, small ones shadow nearly everything; `penumbra` is the angle \
                 over which a shadow's edge fades (0 is hard), with k = 1/tan(penumbra)",
            )
            .with_help(format!("for the same shadows write {write}")),
        );
    }
    angle
}
