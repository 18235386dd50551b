//! Render settings from command-line text: `--size WxH`, `--aa N` and `--set key=value`, each
//! checked against its range and, where one applies, its limit (`render`, `bench`, `pareto`
//! and `view` share them).

use sdfc_compiler::{Limit, Limits, Method, Settings};

/// Parses `WIDTHxHEIGHT` (each edge is checked against the `edge` limit when applied).
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, like 640x480, not `{s}`"))?;
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
) -> Result<(), String> {
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
            .ok_or_else(|| format!("--set expects KEY=VALUE, like max_steps=512, not `{item}`"))?;
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
];

/// The help of `--set`: every key of [`SETTING_KEYS`], with the form of the values that are
/// not numbers.
pub fn set_help() -> String {
    let keys: Vec<String> = SETTING_KEYS
        .iter()
        .map(|&key| match key {
            "background" => "background (as r,g,b)".to_string(),
            "method" => format!("method ({})", Method::NAMES.join(", ")),
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
pub fn set(s: &mut Settings, key: &str, value: &str, limits: &Limits) -> Result<(), String> {
    let limited = |limit: Limit, lo: u32| {
        let hi = limits.get(limit).min(u32::MAX as u64) as u32;
        int(key, value, lo, hi, Some((limits, limit)))
    };
    match key {
        "width" => s.width = limited(Limit::Edge, 1)?,
        "height" => s.height = limited(Limit::Edge, 1)?,
        "aa" => s.aa = limited(Limit::Aa, 1)?,
        "max_steps" => s.max_steps = limited(Limit::MaxSteps, 1)?,
        "max_depth" => s.max_depth = limited(Limit::MaxDepth, 0)?,
        "epsilon" => {
            s.epsilon = real(key, value, |v| v > 0.0 && v < 1.0, "a number in (0, 1)")?;
            s.footprint = false;
        }
        "max_dist" => s.max_dist = real(key, value, |v| v > 0.0, "a positive number")?,
        "relaxation" => {
            s.relaxation = real(
                key,
                value,
                |v| (1.0..2.0).contains(&v),
                "a number in [1, 2)",
            )?
        }
        "background" => s.background = colour(value)?,
        "method" => {
            s.method = Method::from_name(value).ok_or_else(|| {
                format!(
                    "method must be one of {}, not `{value}`",
                    Method::NAMES.join(", ")
                )
            })?
        }
        _ => {
            return Err(format!(
                "unknown render setting `{key}`; the settings are {}",
                SETTING_KEYS.join(", ")
            ));
        }
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
) -> Result<u32, String> {
    let parsed = value.parse::<u64>();
    match parsed {
        Ok(v) if (lo as u64..=hi as u64).contains(&v) => Ok(v as u32),
        _ => {
            let mut msg = format!("{key} must be a whole number from {lo} to {hi}, not `{value}`");
            if let (Some((limits, limit)), Ok(v)) = (limit, parsed) {
                if v > hi as u64 {
                    msg.push_str(&format!("; {}", limits.raise_to(limit, v)));
                }
            }
            Err(msg)
        }
    }
}

fn real(key: &str, value: &str, ok: impl Fn(f64) -> bool, what: &str) -> Result<f64, String> {
    match value.parse::<f64>() {
        Ok(v) if v.is_finite() && ok(v) => Ok(v),
        _ => Err(format!("{key} must be {what}, not `{value}`")),
    }
}

fn colour(value: &str) -> Result<[f64; 3], String> {
    let err = || {
        format!(
            "background must be three numbers r,g,b from 0 to 1, like 0.1,0.1,0.2, not `{value}`"
        )
    };
    let parts: Vec<f64> = value
        .trim_matches(|c| c == '(' || c == ')')
        .split(',')
        .map(|p| p.trim().parse::<f64>().map_err(|_| err()))
        .collect::<Result<_, _>>()?;
    match parts[..] {
        [r, g, b] if parts.iter().all(|v| (0.0..=1.0).contains(v)) => Ok([r, g, b]),
        _ => Err(err()),
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
                "background" => "0.1,0.2,0.3",
                "method" => "march",
                "epsilon" => "0.001",
                "relaxation" => "1.5",
                _ => "8",
            };
            let mut s = Settings::default();
            set(&mut s, key, value, &limits).unwrap_or_else(|e| panic!("{key}: {e}"));
        }
        assert!(help.contains("method (auto, trace, march)"), "{help}");
        let unknown = set(&mut Settings::default(), "speed", "1", &limits).unwrap_err();
        assert!(unknown.contains("unknown render setting"), "{unknown}");
    }
}
