//! Speed against accuracy, apart from the command that measures it (`sdfc pareto`,
//! commands/pareto.rs): the settings a sweep varies and their ranges, the combinations of a
//! sweep, the Pareto front, the measured points and their report, as a table and as a chart
//! (`crate::chart`).

use crate::backend::Ran;
use crate::chart::{self, Chart};
use crate::cpu::reference::Convergence;
use crate::metrics::DepthDifference;
use crate::settings;
use sdfc_compiler::{diagnostics::scientific, Limit, Limits, Settings};

/// A `--sweep` that cannot be read, or sweeps above their limits: a usage error.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// Not `KEY=…`.
    #[error("--sweep expects KEY=LO..HI or KEY=V1,V2, like epsilon=1e-2..1e-6, not `{0}`")]
    Spec(String),
    /// A setting that is not swept.
    #[error("cannot sweep `{0}`; the swept settings are epsilon, max_steps, relaxation, aa and samples (and resolution with --mesh)")]
    Key(String),
    /// A value that is not a number.
    #[error("{key}: `{value}` is not a number")]
    Number {
        /// The swept setting.
        key: &'static str,
        /// The value given.
        value: String,
    },
    /// A count after `:` out of its range (`raise`: how to raise the `sweep_values` limit).
    #[error("{key}: the count after `:` must be 1 to {max}, not `{value}`; {raise}")]
    Count {
        /// The swept setting.
        key: &'static str,
        /// The count given.
        value: String,
        /// The `sweep_values` limit.
        max: usize,
        /// How to raise it.
        raise: String,
    },
    /// A logarithmic range with a bound that is not positive.
    #[error("{0}: a range must be of positive numbers")]
    NotPositive(&'static str),
    /// A range of more values than the `sweep_values` limit.
    #[error("{key}: the range {lo}..{hi} has {n} values, more than {max}; {raise}")]
    Range {
        /// The swept setting.
        key: &'static str,
        /// The range's bounds.
        lo: f64,
        /// The range's bounds.
        hi: f64,
        /// Its values.
        n: usize,
        /// The `sweep_values` limit.
        max: usize,
        /// How to raise it.
        raise: String,
    },
    /// A list of more values than the `sweep_values` limit.
    #[error("{key}: {n} values, more than {max}; {raise}")]
    Values {
        /// The swept setting.
        key: &'static str,
        /// Its values.
        n: usize,
        /// The `sweep_values` limit.
        max: usize,
        /// How to raise it.
        raise: String,
    },
    /// More combinations than the `sweep_points` limit.
    #[error("the sweeps give {count} combinations of settings, more than {max}; {raise}")]
    Points {
        /// The combinations.
        count: u64,
        /// The `sweep_points` limit.
        max: u64,
        /// How to raise it.
        raise: String,
    },
    /// A value the setting refuses.
    #[error(transparent)]
    Setting(#[from] settings::Error),
    /// A render setting swept with `--mesh`, which sweeps the resolution alone.
    #[error(
        "with --mesh the swept setting is resolution (like --sweep resolution=32..512), not `{0}`"
    )]
    NotMesh(&'static str),
}

/// A setting that can be swept.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Key {
    /// The hit tolerance ε (log-spaced, two values a decade).
    Epsilon,
    /// The step budget (log-spaced, one value an octave, whole numbers).
    MaxSteps,
    /// The over-relaxation factor ω (linear, steps of 0.2).
    Relaxation,
    /// Supersampling (every whole number).
    Aa,
    /// The path tracer's samples a pixel (log-spaced, one value an octave, whole numbers).
    Samples,
    /// The mesh's cells along the longest side of its bounds (`sdfc pareto --mesh`; not a
    /// render setting; log-spaced, one value an octave, whole numbers).
    Resolution,
}

impl Key {
    /// The name, as in `--set`.
    pub fn name(self) -> &'static str {
        match self {
            Key::Epsilon => "epsilon",
            Key::MaxSteps => "max_steps",
            Key::Relaxation => "relaxation",
            Key::Aa => "aa",
            Key::Samples => "samples",
            Key::Resolution => "resolution",
        }
    }

    fn parse(s: &str) -> Result<Key, Error> {
        match s {
            "epsilon" => Ok(Key::Epsilon),
            "max_steps" => Ok(Key::MaxSteps),
            "relaxation" => Ok(Key::Relaxation),
            "aa" => Ok(Key::Aa),
            "samples" => Ok(Key::Samples),
            "resolution" => Ok(Key::Resolution),
            _ => Err(Error::Key(s.into())),
        }
    }

    /// The setting's value in `s` (NaN for [`Key::Resolution`], which is not one).
    pub fn get(self, s: &Settings) -> f64 {
        match self {
            Key::Resolution => f64::NAN,
            Key::Epsilon => s.epsilon,
            Key::MaxSteps => s.max_steps as f64,
            Key::Relaxation => s.relaxation,
            Key::Aa => s.aa as f64,
            Key::Samples => s.samples as f64,
        }
    }

    /// Sets the value in `s`, checking its range as `--set` does (an error for
    /// [`Key::Resolution`], which is not a render setting).
    pub fn set(self, s: &mut Settings, v: f64, limits: &Limits) -> Result<(), settings::Error> {
        settings::set(s, self.name(), &format!("{v}"), limits)
    }

    /// Whether the values are whole numbers.
    fn integral(self) -> bool {
        matches!(
            self,
            Key::MaxSteps | Key::Aa | Key::Samples | Key::Resolution
        )
    }

    /// Whether the values are spaced logarithmically in a range.
    fn logarithmic(self) -> bool {
        matches!(
            self,
            Key::Epsilon | Key::MaxSteps | Key::Samples | Key::Resolution
        )
    }
}

/// One swept setting and its values, in the order given.
#[derive(Debug, Clone, PartialEq)]
pub struct Sweep {
    /// The setting.
    pub key: Key,
    /// Its values.
    pub values: Vec<f64>,
}

/// The sweeps used when none is given.
pub const DEFAULT_SWEEPS: &[&str] = &[
    "epsilon=1e-2..1e-6",
    "max_steps=32..1024",
    "relaxation=1..1.8",
];

/// Parses `KEY=LO..HI`, `KEY=LO..HI:N`, `KEY=V1,V2,...` or `KEY=V`.
///
/// A range `LO..HI` gives values from LO to HI, both included: for epsilon two a decade
/// spaced by √10 (1e-2..1e-6: 1e-2, 3.16e-3, 1e-3, … 1e-6), for max_steps one an octave
/// (32..1024: 32, 64, … 1024), for relaxation steps of 0.2 (1..1.8: 1, 1.2, … 1.8), for aa
/// every whole number. `:N` asks for N values instead, with the same spacing (logarithmic
/// for epsilon and max_steps, linear otherwise). Values are rounded to three significant
/// digits (whole numbers for max_steps and aa), duplicates dropped, and each checked as
/// `--set` checks it (within the default limits; see [`parse_sweep_within`]).
pub fn parse_sweep(spec: &str) -> Result<Sweep, Error> {
    parse_sweep_within(spec, &Limits::default())
}

/// [`parse_sweep`] with the values checked within `limits`.
pub fn parse_sweep_within(spec: &str, limits: &Limits) -> Result<Sweep, Error> {
    let (key, rest) = spec
        .split_once('=')
        .ok_or_else(|| Error::Spec(spec.into()))?;
    let key = Key::parse(key.trim())?;
    let rest = rest.trim();
    let raw = match rest.split_once("..") {
        Some((lo, hi)) => range(key, lo, hi, limits)?,
        None => rest
            .split(',')
            .map(|v| number(key, v))
            .collect::<Result<Vec<_>, _>>()?,
    };
    let max = limits.count(Limit::SweepValues);
    if raw.len() > max {
        return Err(Error::Values {
            key: key.name(),
            n: raw.len(),
            max,
            raise: limits.raise_to(Limit::SweepValues, raw.len() as u64),
        });
    }
    let mut values: Vec<f64> = Vec::new();
    for v in raw.into_iter().map(|v| round(key, v)) {
        if key == Key::Resolution {
            // The mesher checks the grid it makes of it.
            if v < 1.0 {
                return Err(Error::NotPositive(key.name()));
            }
        } else {
            key.set(&mut Settings::default(), v, limits)?;
        }
        if !values.contains(&v) {
            values.push(v);
        }
    }
    Ok(Sweep { key, values })
}

fn number(key: Key, v: &str) -> Result<f64, Error> {
    match v.trim().parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        _ => Err(Error::Number {
            key: key.name(),
            value: v.trim().into(),
        }),
    }
}

/// The values of `lo..hi[:n]` for `key`.
fn range(key: Key, lo: &str, hi: &str, limits: &Limits) -> Result<Vec<f64>, Error> {
    let max = limits.count(Limit::SweepValues);
    let (hi, count) = match hi.split_once(':') {
        Some((h, n)) => match n.trim().parse::<usize>() {
            Ok(n) if (1..=max).contains(&n) => (h, Some(n)),
            parsed => {
                return Err(Error::Count {
                    key: key.name(),
                    value: n.trim().into(),
                    max,
                    // The count asked for is the value that would do.
                    raise: match parsed {
                        Ok(n) if n > max => limits.raise_to(Limit::SweepValues, n as u64),
                        _ => limits.raise(Limit::SweepValues),
                    },
                });
            }
        },
        None => (hi, None),
    };
    let (lo, hi) = (number(key, lo)?, number(key, hi)?);
    let log = key.logarithmic();
    if log && (lo <= 0.0 || hi <= 0.0) {
        return Err(Error::NotPositive(key.name()));
    }
    let n = count.unwrap_or_else(|| match key {
        Key::Epsilon => (2.0 * (hi / lo).log10().abs()).round() as usize + 1,
        Key::MaxSteps | Key::Samples | Key::Resolution => {
            (hi / lo).log2().abs().round() as usize + 1
        }
        Key::Relaxation => ((hi - lo).abs() / 0.2).round() as usize + 1,
        Key::Aa => (hi - lo).abs().round() as usize + 1,
    });
    if n > max {
        return Err(Error::Range {
            key: key.name(),
            lo,
            hi,
            n,
            max,
            raise: limits.raise_to(Limit::SweepValues, n as u64),
        });
    }
    let at = |i: usize| {
        let f = if n == 1 {
            0.0
        } else {
            i as f64 / (n - 1) as f64
        };
        if log {
            lo * (hi / lo).powf(f)
        } else {
            lo + (hi - lo) * f
        }
    };
    Ok((0..n).map(at).collect())
}

/// Rounds to three significant digits, or to a whole number.
fn round(key: Key, v: f64) -> f64 {
    if key.integral() {
        return v.round();
    }
    if v == 0.0 {
        return 0.0;
    }
    let scale = 10f64.powi(2 - v.abs().log10().floor() as i32);
    (v * scale).round() / scale
}

/// Every combination of the sweeps' values applied to `base`, the first sweep varying
/// slowest, each checked within `limits`.
pub fn combinations(
    base: &Settings,
    sweeps: &[Sweep],
    limits: &Limits,
) -> Result<Vec<Settings>, Error> {
    // Counted before any is built: the product of a few sweeps grows fast.
    let count = sweeps
        .iter()
        .fold(1u64, |n, s| n.saturating_mul(s.values.len() as u64));
    let max = limits.get(Limit::SweepPoints);
    if count > max {
        return Err(Error::Points {
            count,
            max,
            raise: limits.raise_to(Limit::SweepPoints, count),
        });
    }
    let mut out = vec![base.clone()];
    for sweep in sweeps {
        let mut next = Vec::with_capacity(out.len() * sweep.values.len());
        for s in &out {
            for &v in &sweep.values {
                let mut t = s.clone();
                sweep.key.set(&mut t, v, limits)?;
                next.push(t);
            }
        }
        out = next;
    }
    Ok(out)
}

/// The Pareto front of points (cost, PSNR): a point is on it unless another is at least as
/// cheap and as accurate, and better in one of the two by more than the noise margins (a
/// fraction `cost_margin` of the cost, [`PSNR_MARGIN`] dB). A NaN PSNR is never on it.
pub fn front(points: &[(f64, f64)], cost_margin: f64) -> Vec<bool> {
    points
        .iter()
        .map(|&(c, q)| {
            !q.is_nan()
                && !points.iter().any(|&(c2, q2)| {
                    c2 <= c && q2 >= q && (c2 < c * (1.0 - cost_margin) || q2 > q + PSNR_MARGIN)
                })
        })
        .collect()
}

/// PSNR differences up to this (dB) count as equal for the front: settings that differ only
/// a little (ω 1.4 against 1.6) differ by this much through a few aliased pixels flipping.
pub const PSNR_MARGIN: f64 = 0.5;

/// Time differences up to this fraction count as equal for the front (timing noise).
pub const TIME_MARGIN: f64 = 0.05;

/// Differences of mean steps per pixel up to this fraction count as equal for the front.
pub const STEPS_MARGIN: f64 = 0.02;

/// One measured combination of settings.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Measured {
    /// ε.
    pub epsilon: f64,
    /// Step budget.
    pub max_steps: u32,
    /// Over-relaxation ω.
    pub relaxation: f64,
    /// Supersampling.
    pub aa: u32,
    /// The path tracer's samples a pixel (0 for a render that is not path traced).
    pub samples: u32,
    /// Median seconds per frame.
    pub median_s: f64,
    /// Fastest frame, seconds.
    pub min_s: f64,
    /// Mean marching steps per pixel.
    pub steps_mean: f64,
    /// Camera and secondary rays that ran out of steps.
    pub budget_misses: u64,
    /// PSNR against the reference, dB (null when identical).
    pub psnr: f64,
    /// RMSE against the reference.
    pub rmse: f64,
    /// Largest channel difference from the reference.
    pub max: f64,
    /// Fraction of pixels differing from the reference by more than 0.1.
    pub differing: f64,
    /// First-hit differences from the reference (null when this backend has no depth).
    pub depth: Option<DepthDifference>,
    /// On the Pareto front of time against PSNR.
    pub front_time: bool,
    /// On the Pareto front of steps per pixel against PSNR.
    pub front_steps: bool,
    /// These are the scene's own settings (what `sdfc render` uses).
    pub default: bool,
}

/// The reference a sweep was measured against.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ReferenceInfo {
    /// Supersampling of the reference (the largest of the points).
    pub aa: u32,
    /// The path tracer's samples of the reference (0 where the scene is not path traced).
    pub samples: u32,
    /// Its convergence check.
    pub convergence: Convergence,
    /// Seconds it took (with the check).
    pub seconds: f64,
}

/// The report of `sdfc pareto --json`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Report {
    /// The scene, the backend timed, its device, the float type of the timed renders and
    /// the size.
    #[serde(flatten)]
    pub ran: Ran,
    /// Frames timed per point.
    pub frames: u32,
    /// The reference.
    pub reference: ReferenceInfo,
    /// Whether the scene's own settings are on the front of time against PSNR.
    pub default_on_front_time: bool,
    /// Whether they are on the front of steps against PSNR.
    pub default_on_front_steps: bool,
    /// The points, in sweep order; the default is last when the sweep does not include it.
    pub points: Vec<Measured>,
}

/// A table's word for the fronts a point is on: that of time, the other (`other`, with its
/// word), both or neither.
pub fn front_word(time: bool, (other, word): (bool, &'static str)) -> &'static str {
    match (time, other) {
        (true, true) => "both",
        (true, false) => "time",
        (false, true) => word,
        _ => "",
    }
}

/// Whether two settings agree on the swept keys.
pub fn same(a: &Settings, b: &Settings) -> bool {
    [
        Key::Epsilon,
        Key::MaxSteps,
        Key::Relaxation,
        Key::Aa,
        Key::Samples,
    ]
    .iter()
    .all(|k| k.get(a) == k.get(b))
        && a.footprint == b.footprint
}

/// `ε 1e-4, 256 steps, ω 1, aa 1` (`ε footprint, …` where ε follows the pixel footprint).
pub fn describe(s: &Settings) -> String {
    let epsilon = if s.footprint {
        "footprint".to_string()
    } else {
        format!("{:e}", s.epsilon)
    };
    let samples = if s.path {
        format!(", {} samples", s.samples)
    } else {
        String::new()
    };
    format!(
        "ε {epsilon}, {} steps, ω {}, aa {}{samples}",
        s.max_steps, s.relaxation, s.aa
    )
}

/// Marks the points on the Pareto fronts of time and of steps against PSNR.
pub fn mark_fronts(points: &mut [Measured]) {
    let by_time: Vec<(f64, f64)> = points.iter().map(|m| (m.median_s, m.psnr)).collect();
    let by_steps: Vec<(f64, f64)> = points.iter().map(|m| (m.steps_mean, m.psnr)).collect();
    let (ft, fs) = (front(&by_time, TIME_MARGIN), front(&by_steps, STEPS_MARGIN));
    for ((m, t), s) in points.iter_mut().zip(ft).zip(fs) {
        m.front_time = t;
        m.front_steps = s;
    }
}

/// The points as a text table.
pub fn table(r: &Report) -> String {
    let mut out = format!(
        "{} on {} ({}), {}x{}; reference aa {}, agreement with its check {:.2} dB{}\n",
        r.ran.scene,
        r.ran.backend,
        r.ran.device,
        r.ran.width,
        r.ran.height,
        r.reference.aa,
        r.reference.convergence.difference.psnr,
        if r.reference.convergence.converged {
            ""
        } else {
            " (not converged)"
        }
    );
    out += &format!(
        "{:>9} {:>9} {:>5} {:>3} {:>7} {:>10} {:>9} {:>8} {:>7} {:>6} {:>6}\n",
        "epsilon",
        "max_steps",
        "ω",
        "aa",
        "samples",
        "median ms",
        "steps/px",
        "PSNR dB",
        "max",
        "front",
        "default"
    );
    for m in &r.points {
        let front = front_word(m.front_time, (m.front_steps, "steps"));
        out += &format!(
            "{:>9.2e} {:>9} {:>5} {:>3} {:>7} {:>10.3} {:>9.1} {:>8.2} {:>7.4} {:>6} {:>6}\n",
            m.epsilon,
            m.max_steps,
            m.relaxation,
            m.aa,
            m.samples,
            m.median_s * 1e3,
            m.steps_mean,
            m.psnr,
            m.max,
            front,
            if m.default { "yes" } else { "" }
        );
    }
    out
}

/// The chart of a report.
pub fn chart_of(r: &Report, target: f64) -> Chart {
    let name = std::path::Path::new(&r.ran.scene)
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| r.ran.scene.clone());
    let c = &r.reference.convergence;
    let default_label = r
        .points
        .iter()
        .find(|m| m.default)
        .map(|m| {
            format!(
                "scene's settings: ε {}, {} steps, ω {}",
                scientific(m.epsilon),
                m.max_steps,
                m.relaxation
            )
        })
        .unwrap_or_else(|| "scene's settings".into());
    Chart {
        title: format!("{name}: speed against accuracy ({} points)", r.points.len()),
        subtitle: format!(
            "{} on {}, {} {}x{}, median of {} frames; reference: CPU f64, ε {}, {} steps, aa {}{}; it agrees with ε {}, aa {}{} to {:.1} dB{}",
            r.ran.backend,
            r.ran.device,
            r.ran.precision,
            r.ran.width,
            r.ran.height,
            r.frames,
            scientific(c.epsilon),
            c.max_steps,
            r.reference.aa,
            match r.reference.samples {
                0 => String::new(),
                n => format!(", {n} samples"),
            },
            scientific(c.check_epsilon),
            c.check_aa,
            match r.reference.samples {
                0 => String::new(),
                n => format!(" and {n} other samples"),
            },
            c.difference.psnr,
            if c.converged { "" } else { " (not converged)" }
        ),
        default_label,
        panels: [
            chart::Panel {
                caption: "Time per frame against accuracy".into(),
                cost: "median time per frame (ms, log scale)".into(),
            },
            chart::Panel {
                caption: "Marching work against accuracy".into(),
                cost: "mean marching steps per pixel (log scale)".into(),
            },
        ],
        accuracy: chart::Accuracy {
            label: "PSNR against the reference (dB, higher is better)".into(),
            lower_is_better: false,
            target: Some((target, format!("{target} dB target"))),
        },
        points: r
            .points
            .iter()
            .map(|m| chart::Point {
                cost: [m.median_s * 1e3, m.steps_mean],
                accuracy: m.psnr,
                front: [m.front_time, m.front_steps],
                default: m.default,
            })
            .collect(),
    }
}
