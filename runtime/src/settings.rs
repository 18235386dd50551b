//! Render settings from command-line text: `--size WxH`, `--aa N` and `--set key=value`, each
//! checked against its range and, where one applies, its limit (`render`, `bench`, `pareto`
//! and `view` share them).

use sdfc_compiler::{Limit, Limits, Settings, Tonemap};

/// A setting given on the command line that cannot be read or is out of its range: a usage
/// error.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Error {
    /// `--size` not as `WIDTHxHEIGHT`.
    #[error("expected WIDTHxHEIGHT, like 640x480, not `{0}`")]
    Size(String),
    /// A `--set` not as `KEY=VALUE`.
    #[error("--set expects KEY=VALUE, like max_steps=512, not `{0}`")]
    NotKeyValue(String),
    /// A key `--set` does not know.
    #[error("unknown render setting `{0}`; the settings are {keys}", keys = SETTING_KEYS.join(", "))]
    Unknown(String),
    /// A whole number out of its range (`raise`: how to raise the limit that bounds it, for
    /// a value above it).
    #[error("{key} must be a whole number from {lo} to {hi}, not `{value}`{}", .raise.as_ref().map(|r| format!("; {r}")).unwrap_or_default())]
    Whole {
        /// The setting.
        key: String,
        /// The value given.
        value: String,
        /// The least value.
        lo: u32,
        /// The greatest value.
        hi: u32,
        /// How to raise the limit `hi` is.
        raise: Option<String>,
    },
    /// A number out of its range.
    #[error("{key} must be {what}, not `{value}`")]
    Real {
        /// The setting.
        key: String,
        /// The value given.
        value: String,
        /// What it must be.
        what: &'static str,
    },
    /// A `background` that is not a colour.
    #[error("background must be three numbers r,g,b from 0 to 1, like 0.1,0.1,0.2, not `{0}`")]
    Background(String),
    /// A `fog_color` that is not a colour.
    #[error("fog_color must be three numbers r,g,b from 0 to 1, like 0.6,0.65,0.7, not `{0}`")]
    FogColour(String),
    /// A `glow_color` that is not a colour.
    #[error("glow_color must be three numbers r,g,b from 0 to 1, like 0.02,0.03,0.05, not `{0}`")]
    GlowColour(String),
    /// A `tonemap` that is not one.
    #[error("tonemap must be one of {names}, not `{0}`", names = Tonemap::NAMES.join(", "))]
    Tonemap(String),
    /// A `method` that is not one.
    #[error("method must be one of {names}, not `{0}`", names = Settings::METHODS.join(", "))]
    Method(String),
}

/// Parses `WIDTHxHEIGHT` (each edge is checked against the `edge` limit when applied).
pub fn parse_size(s: &str) -> Result<(u32, u32), Error> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| Error::Size(s.into()))?;
    let ceiling = Limit::Edge.ceiling() as u32;
    let w = int("width", w.trim(), 1, ceiling, None)?;
    let h = int("height", h.trim(), 1, ceiling, None)?;
    Ok((w, h))
}

/// Applies `--size`, `--aa` and then each `--set key=value`, in order, within `limits`.
pub fn override_settings(
    s: &mut Settings,
    size: Option<(u32, u32)>,
    aa: Option<u32>,
    sets: &[String],
    limits: &Limits,
) -> Result<(), Error> {
    if let Some((w, h)) = size {
        set(s, "width", &w.to_string(), limits)?;
        set(s, "height", &h.to_string(), limits)?;
    }
    if let Some(n) = aa {
        set(s, "aa", &n.to_string(), limits)?;
    }
    for item in sets {
        let (key, value) = item
            .split_once('=')
            .ok_or_else(|| Error::NotKeyValue(item.clone()))?;
        set(s, key.trim(), value.trim(), limits)?;
    }
    Ok(())
}

/// The keys `--set` accepts.
pub const SETTING_KEYS: &[&str] = &[
    "width",
    "height",
    "aa",
    "max_steps",
    "epsilon",
    "max_depth",
    "max_dist",
    "relaxation",
    "background",
    "method",
    "occlusion",
    "fog",
    "fog_color",
    "glow",
    "glow_color",
    "exposure",
    "tonemap",
    "samples",
    "bounces",
];

/// The help of `--set`: every key of [`SETTING_KEYS`], with the form of the values that are
/// not numbers.
pub fn set_help() -> String {
    let keys: Vec<String> = SETTING_KEYS
        .iter()
        .map(|&key| match key {
            "background" => "background (as r,g,b)".to_string(),
            "method" => format!("method ({})", Settings::METHODS.join(", ")),
            "fog_color" => "fog_color (as r,g,b)".to_string(),
            "glow_color" => "glow_color (as r,g,b)".to_string(),
            "tonemap" => format!("tonemap ({})", Tonemap::NAMES.join(", ")),
            key => key.to_string(),
        })
        .collect();
    let (last, rest) = keys.split_last().expect("settings");
    format!(
        "Override a render setting: {} or {last}. May be repeated.",
        rest.join(", ")
    )
}

/// Sets one render setting from text, checking its range (the top of the range of width,
/// height, aa, max_steps and max_depth is a limit of `limits`).
pub fn set(s: &mut Settings, key: &str, value: &str, limits: &Limits) -> Result<(), Error> {
    let limited = |limit: Limit, lo: u32| {
        let hi = limits.get(limit).min(u32::MAX as u64) as u32;
        int(key, value, lo, hi, Some((limits, limit)))
    };
    // A number `ok` accepts (`what` says which); a distance, where 0 is none.
    let within = |ok: fn(f64) -> bool, what| real(key, value, ok, what);
    let distance = || {
        within(
            |v| (0.0..=1e9).contains(&v),
            "a distance from 0 (none) to 1e9",
        )
    };
    match key {
        "width" => s.width = limited(Limit::Edge, 1)?,
        "height" => s.height = limited(Limit::Edge, 1)?,
        "aa" => s.aa = limited(Limit::Aa, 1)?,
        "max_steps" => s.max_steps = limited(Limit::MaxSteps, 1)?,
        "max_depth" => s.max_depth = limited(Limit::MaxDepth, 0)?,
        "samples" => s.samples = limited(Limit::Samples, 1)?,
        "bounces" => s.bounces = limited(Limit::Bounces, 0)?,
        "epsilon" => {
            s.epsilon = within(|v| v > 0.0 && v < 1.0, "a number in (0, 1)")?;
            s.footprint = false;
        }
        "max_dist" => s.max_dist = within(|v| v > 0.0, "a positive number")?,
        "relaxation" => s.relaxation = within(|v| (1.0..2.0).contains(&v), "a number in [1, 2)")?,
        "background" => {
            s.background = colour(value).ok_or_else(|| Error::Background(value.into()))?
        }
        "occlusion" => s.occlusion = distance()?,
        "fog" => s.fog = distance()?,
        "fog_color" => {
            s.fog_color = Some(colour(value).ok_or_else(|| Error::FogColour(value.into()))?)
        }
        "glow" => s.glow = distance()?,
        "glow_color" => {
            s.glow_color = colour(value).ok_or_else(|| Error::GlowColour(value.into()))?
        }
        "exposure" => {
            s.exposure = within(
                |v| (-20.0..=20.0).contains(&v),
                "a number of stops from -20 to 20",
            )?
        }
        "tonemap" => {
            s.tonemap = Tonemap::from_name(value).ok_or_else(|| Error::Tonemap(value.into()))?;
            s.tonemap_why = None;
        }
        "method" => {
            if !s.set_method(value) {
                return Err(Error::Method(value.into()));
            }
        }
        _ => return Err(Error::Unknown(key.into())),
    }
    Ok(())
}

/// A whole number from `lo` to `hi`; with `limit`, one above `hi` says how to raise it.
fn int(
    key: &str,
    value: &str,
    lo: u32,
    hi: u32,
    limit: Option<(&Limits, Limit)>,
) -> Result<u32, Error> {
    let parsed = value.parse::<u64>();
    match parsed {
        Ok(v) if (lo as u64..=hi as u64).contains(&v) => Ok(v as u32),
        _ => Err(Error::Whole {
            key: key.into(),
            value: value.into(),
            lo,
            hi,
            raise: match (limit, parsed) {
                (Some((limits, limit)), Ok(v)) if v > hi as u64 => Some(limits.raise_to(limit, v)),
                _ => None,
            },
        }),
    }
}

fn real(
    key: &str,
    value: &str,
    ok: impl Fn(f64) -> bool,
    what: &'static str,
) -> Result<f64, Error> {
    match value.parse::<f64>() {
        Ok(v) if v.is_finite() && ok(v) => Ok(v),
        _ => Err(Error::Real {
            key: key.into(),
            value: value.into(),
            what,
        }),
    }
}

/// Three numbers `r,g,b` from 0 to 1, or `None`.
fn colour(value: &str) -> Option<[f64; 3]> {
    let parts: Vec<f64> = value
        .trim_matches(|c| c == '(' || c == ')')
        .split(',')
        .map(|p| p.trim().parse::<f64>().ok())
        .collect::<Option<_>>()?;
    match parts[..] {
        [r, g, b] if parts.iter().all(|v| (0.0..=1.0).contains(v)) => Some([r, g, b]),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_setting_is_in_the_help_and_accepted() {
        let help = set_help();
        let limits = Limits::default();
        for key in SETTING_KEYS {
            assert!(help.contains(key), "{key} is missing from `{help}`");
            let value = match *key {
                "background" | "fog_color" | "glow_color" => "0.1,0.2,0.3",
                "tonemap" => "filmic",
                "method" => "march",
                "epsilon" => "0.001",
                "relaxation" => "1.5",
                _ => "8",
            };
            let mut s = Settings::default();
            set(&mut s, key, value, &limits).unwrap_or_else(|e| panic!("{key}: {e}"));
        }
        assert!(help.contains("method (auto, trace, march, path)"), "{help}");
        let mut s = Settings::default();
        set(&mut s, "method", "path", &limits).expect("path");
        assert!(s.path && s.method == sdfc_compiler::Method::Auto);
        set(&mut s, "method", "march", &limits).expect("march");
        assert!(!s.path && s.method == sdfc_compiler::Method::March);
        assert_eq!(
            set(&mut s, "samples", "0", &limits)
                .unwrap_err()
                .to_string(),
            format!(
                "samples must be a whole number from 1 to {}, not `0`",
                limits.get(Limit::Samples)
            )
        );
        let unknown = set(&mut Settings::default(), "speed", "1", &limits).unwrap_err();
        assert_eq!(unknown, Error::Unknown("speed".into()));
        assert!(
            unknown
                .to_string()
                .starts_with("unknown render setting `speed`; the settings are width, height, aa,"),
            "{unknown}"
        );
    }

    #[test]
    fn each_refusal_says_what_the_value_must_be() {
        let limits = Limits::default();
        let refused = |key: &str, value: &str| {
            set(&mut Settings::default(), key, value, &limits)
                .unwrap_err()
                .to_string()
        };
        let edge = limits.get(Limit::Edge);
        assert_eq!(
            refused("width", &(edge + 1).to_string()),
            format!(
                "width must be a whole number from 1 to {edge}, not `{}`; {}",
                edge + 1,
                limits.raise_to(Limit::Edge, edge + 1)
            )
        );
        assert_eq!(
            refused("aa", "two"),
            format!(
                "aa must be a whole number from 1 to {}, not `two`",
                limits.get(Limit::Aa)
            )
        );
        assert_eq!(
            refused("epsilon", "2"),
            "epsilon must be a number in (0, 1), not `2`"
        );
        assert_eq!(
            refused("background", "red"),
            "background must be three numbers r,g,b from 0 to 1, like 0.1,0.1,0.2, not `red`"
        );
        assert_eq!(
            refused("tonemap", "aces"),
            "tonemap must be one of none, filmic, reinhard, not `aces`"
        );
        assert_eq!(
            refused("fog", "-1"),
            "fog must be a distance from 0 (none) to 1e9, not `-1`"
        );
        assert_eq!(
            refused("method", "fast"),
            "method must be one of auto, trace, march, path, not `fast`"
        );
        assert_eq!(
            parse_size("640by480").unwrap_err().to_string(),
            "expected WIDTHxHEIGHT, like 640x480, not `640by480`"
        );
        let mut s = Settings::default();
        let sets = ["max_steps".to_string()];
        assert_eq!(
            override_settings(&mut s, None, None, &sets, &limits).unwrap_err(),
            Error::NotKeyValue("max_steps".into())
        );
    }
}
