//! The controls of the viewer's parameter panel, apart from any drawing: which control a
//! parameter declaration gets (a slider for a number or an int in a range, with its step; a
//! checkbox for a bool; a list for a string's choices; a number field or a text field for one
//! that accepts any value), and the checked parameter value a control's raw value stands for
//! (kept within the range and on the step). The panel ([`super::panel`]) draws them with
//! egui; `--change NAME=VALUE` sets them from text, through the same mapping.

use sdfc_compiler::{Accepts, ParamValue, Parameter};

/// What a control shows and edits.
#[derive(Debug, Clone, PartialEq)]
pub enum Kind {
    /// A slider from `lo` to `hi`, whose values are `lo + k·step` (whole numbers for an int).
    Slider {
        lo: f64,
        hi: f64,
        step: Option<f64>,
        int: bool,
    },
    /// A number field with no bounds (a number or an int that accepts any value).
    Number { int: bool },
    /// A checkbox.
    Check,
    /// A list of strings to choose from.
    Choice(Vec<String>),
    /// A text field (a string that accepts any value).
    Text,
}

/// A control's raw value, as its widget edits it.
#[derive(Debug, Clone, PartialEq)]
pub enum Raw {
    Number(f64),
    Bool(bool),
    Text(String),
}

/// One parameter's control: its name, description and what it accepts (for the label), its
/// kind and its value.
#[derive(Debug, Clone, PartialEq)]
pub struct Control {
    pub name: String,
    pub doc: String,
    /// What the parameter accepts, as `sdfc check` writes it (`10..100 step 1`).
    pub accepts: String,
    pub kind: Kind,
    /// The value shown: always one the parameter accepts.
    pub value: ParamValue,
}

impl Control {
    /// The control of `p`, showing the value the scene was checked with.
    pub fn of(p: &Parameter) -> Control {
        let int = matches!(p.default, ParamValue::Int(_));
        let kind = match (&p.default, &p.accepts) {
            (ParamValue::Bool(_), _) => Kind::Check,
            (ParamValue::Str(_), Accepts::Choices(c)) => Kind::Choice(c.clone()),
            (ParamValue::Str(_), _) => Kind::Text,
            (_, &Accepts::Range { lo, hi, step }) => Kind::Slider { lo, hi, step, int },
            (_, _) => Kind::Number { int },
        };
        Control {
            name: p.name.clone(),
            doc: p.doc.clone(),
            accepts: p.accepts.to_string(),
            kind,
            value: p.value.clone(),
        }
    }

    /// The raw value of the widget showing [`Control::value`].
    pub fn raw(&self) -> Raw {
        match &self.value {
            ParamValue::Float(x) => Raw::Number(*x),
            ParamValue::Int(i) => Raw::Number(*i as f64),
            ParamValue::Bool(b) => Raw::Bool(*b),
            ParamValue::Str(s) => Raw::Text(s.clone()),
        }
    }

    /// The parameter value the widget's raw value `raw` stands for: a number kept within the
    /// slider's range and moved to its nearest step (a whole number for an int), a choice
    /// among the list's; `None` when `raw` stands for none (not a finite number, a string
    /// that is not a choice, a raw value of another kind).
    pub fn value_of(&self, raw: &Raw) -> Option<ParamValue> {
        match (&self.kind, raw) {
            (&Kind::Slider { lo, hi, step, int }, Raw::Number(x)) if x.is_finite() => {
                let x = snap(*x, lo, hi, step, int);
                Some(match int {
                    true => ParamValue::Int(x as i64),
                    false => ParamValue::Float(x),
                })
            }
            (Kind::Number { int: true }, Raw::Number(x)) if x.is_finite() => {
                Some(ParamValue::Int(x.round().clamp(-9.0e15, 9.0e15) as i64))
            }
            (Kind::Number { int: false }, Raw::Number(x)) if x.is_finite() => {
                Some(ParamValue::Float(*x))
            }
            (Kind::Check, Raw::Bool(b)) => Some(ParamValue::Bool(*b)),
            (Kind::Choice(c), Raw::Text(s)) if c.contains(s) => Some(ParamValue::Str(s.clone())),
            (Kind::Text, Raw::Text(s)) => Some(ParamValue::Str(s.clone())),
            _ => None,
        }
    }

    /// The raw value written `text` (`--change NAME=VALUE`), as the widget would hold it.
    pub fn parse(&self, text: &str) -> Option<Raw> {
        match &self.kind {
            Kind::Slider { .. } | Kind::Number { .. } => {
                text.trim().parse::<f64>().ok().map(Raw::Number)
            }
            Kind::Check => match text.trim() {
                "true" => Some(Raw::Bool(true)),
                "false" => Some(Raw::Bool(false)),
                _ => None,
            },
            Kind::Choice(_) | Kind::Text => Some(Raw::Text(text.to_string())),
        }
    }

    /// Sets the control to the value `raw` stands for; returns that value when it differs
    /// from the one shown (a change to apply), `None` when there is none or it is the same.
    pub fn set(&mut self, raw: &Raw) -> Option<ParamValue> {
        let v = self.value_of(raw)?;
        if v == self.value {
            return None;
        }
        self.value = v.clone();
        Some(v)
    }
}

/// The decimals a slider with a step shows: as many as its step and its lower end are written
/// with (0 for `10..100 step 1`, 2 for `0..1 step 0.05`), at most 6; `None` without a step
/// (the slider's own choice).
pub fn decimals(lo: f64, step: Option<f64>) -> Option<usize> {
    let step = step?;
    let whole = |x: f64, d: i32| {
        let scaled = x * 10f64.powi(d);
        (scaled - scaled.round()).abs() < 1e-6 * scaled.abs().max(1.0)
    };
    Some(
        (0..6)
            .find(|&d| whole(step, d) && whole(lo, d))
            .unwrap_or(6) as usize,
    )
}

/// The value `text` stands for in control `c` (`--change`'s value, read as its widget reads
/// what it is given).
pub fn value_from_text(c: &Control, text: &str) -> Result<ParamValue, ChangeError> {
    c.parse(text)
        .and_then(|raw| c.value_of(&raw))
        .ok_or_else(|| ChangeError::NotAValue {
            text: text.to_string(),
            name: c.name.clone(),
            accepts: c.accepts.clone(),
        })
}

/// Why `--change NAME=VALUE` is refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ChangeError {
    /// The scene on show declares no parameter `name`; `declared` are those it does.
    #[error("the scene has no parameter `{name}`{}", declared_names(.declared))]
    Unknown { name: String, declared: Vec<String> },
    /// The text is no value the parameter's control takes.
    #[error("`{text}` is not a value of `{name}` ({accepts})")]
    NotAValue {
        text: String,
        name: String,
        /// What the parameter accepts, as `sdfc check` writes it.
        accepts: String,
    },
}

/// The end of [`ChangeError::Unknown`]'s message: the parameters the scene declares.
fn declared_names(declared: &[String]) -> String {
    match declared.is_empty() {
        true => ": it declares none".to_string(),
        false => {
            let names: Vec<String> = declared.iter().map(|n| format!("`{n}`")).collect();
            format!("; its parameters: {}", names.join(", "))
        }
    }
}

/// The value `--change NAME=VALUE` gives the parameter `name` of `params` (the scene on show),
/// through its control, as the panel would.
pub fn change(params: &[Parameter], name: &str, text: &str) -> Result<ParamValue, ChangeError> {
    let p = params
        .iter()
        .find(|p| p.name == name)
        .ok_or_else(|| unknown(params, name))?;
    value_from_text(&Control::of(p), text)
}

/// Why `--change` names no parameter of the scene on show.
pub fn unknown(params: &[Parameter], name: &str) -> ChangeError {
    ChangeError::Unknown {
        name: name.to_string(),
        declared: params.iter().map(|p| p.name.clone()).collect(),
    }
}

/// `x` within `lo..=hi`, on the nearest of `lo + k·step` that is not above `hi` (and a whole
/// number for an int: the nearest step that is one, else the nearest whole number in range).
fn snap(x: f64, lo: f64, hi: f64, step: Option<f64>, int: bool) -> f64 {
    let x = x.clamp(lo, hi);
    let on = |v: f64| !int || v.fract() == 0.0;
    let x = match step.filter(|s| *s > 0.0 && s.is_finite()) {
        Some(s) => {
            let k = ((x - lo) / s).round();
            let last = ((hi - lo) / s).floor();
            // The nearest step at or below the top whose value suits the type.
            let candidates = [k, k - 1.0, k + 1.0];
            let found = candidates
                .into_iter()
                .filter(|k| *k >= 0.0 && *k <= last)
                .map(|k| (lo + k * s).min(hi))
                .filter(|v| on(*v))
                .min_by(|a, b| (a - x).abs().total_cmp(&(b - x).abs()));
            found.unwrap_or(x)
        }
        None => x,
    };
    match int {
        // Whole, within the range (a range whose ends are not whole holds its whole numbers).
        true => x.round().clamp(lo.ceil(), hi.floor().max(lo.ceil())),
        false => x,
    }
}

/// The text a value is written as for [`sdfc_compiler::Limits::offer_param`]: a number as
/// Rust writes it (read back exactly), a string as it is.
pub fn text(v: &ParamValue) -> String {
    match v {
        ParamValue::Float(x) => format!("{x:?}"),
        ParamValue::Int(i) => i.to_string(),
        ParamValue::Bool(b) => b.to_string(),
        ParamValue::Str(s) => s.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn param(default: ParamValue, accepts: Accepts) -> Parameter {
        Parameter {
            name: "p".into(),
            value: default.clone(),
            default,
            accepts,
            doc: "A parameter".into(),
            span: sdfc_compiler::Span {
                file: sdfc_compiler::FileId(0),
                start: 0,
                end: 1,
            },
        }
    }

    fn range(lo: f64, hi: f64, step: Option<f64>) -> Accepts {
        Accepts::Range { lo, hi, step }
    }

    #[test]
    fn each_declaration_gets_its_control() {
        let f = ParamValue::Float(40.0);
        let c = Control::of(&param(f.clone(), range(10.0, 100.0, Some(1.0))));
        assert_eq!(
            c.kind,
            Kind::Slider {
                lo: 10.0,
                hi: 100.0,
                step: Some(1.0),
                int: false
            }
        );
        assert_eq!(
            (c.accepts.as_str(), c.doc.as_str()),
            ("10..100 step 1", "A parameter")
        );
        let c = Control::of(&param(ParamValue::Int(3), range(1.0, 6.0, None)));
        assert!(matches!(c.kind, Kind::Slider { int: true, .. }));
        assert_eq!(c.raw(), Raw::Number(3.0));
        assert_eq!(
            Control::of(&param(f, Accepts::Any)).kind,
            Kind::Number { int: false }
        );
        let b = Control::of(&param(ParamValue::Bool(true), Accepts::Any));
        assert_eq!((b.kind.clone(), b.raw()), (Kind::Check, Raw::Bool(true)));
        let choices = vec!["round".to_string(), "square".to_string()];
        let s = ParamValue::Str("round".into());
        let c = Control::of(&param(s.clone(), Accepts::Choices(choices.clone())));
        assert_eq!(c.kind, Kind::Choice(choices));
        assert_eq!(Control::of(&param(s, Accepts::Any)).kind, Kind::Text);
    }

    #[test]
    fn a_slider_gives_values_within_its_range_and_on_its_step() {
        let cases = [
            (ParamValue::Float(40.0), 10.0, 100.0, Some(1.0)),
            (ParamValue::Float(0.5), 0.1, 0.95, Some(0.2)),
            (ParamValue::Float(2.0), -3.0, 7.5, Some(2.5)),
            (ParamValue::Float(0.3), 0.0, 1.0, None),
            (ParamValue::Int(3), 1.0, 6.0, None),
            (ParamValue::Int(4), 0.0, 10.0, Some(2.0)),
            (ParamValue::Int(2), 0.5, 9.5, Some(1.5)),
        ];
        let raws = [
            -1e9, -3.0, 0.0, 0.1, 0.149, 0.31, 0.5, 1.49, 2.5, 3.3, 5.99, 6.4, 7.49, 9.0, 9.4,
            99.5, 100.0, 1e9,
        ];
        for (default, lo, hi, step) in cases {
            let p = param(default, range(lo, hi, step));
            let c = Control::of(&p);
            for x in raws {
                let v = c.value_of(&Raw::Number(x)).expect("a value");
                assert!(p.accepts(&v), "{x} gave {v:?}, outside {lo}..{hi}");
                let n = v.number().unwrap();
                if let Some(s) = step {
                    let k = (n - lo) / s;
                    let whole = matches!(v, ParamValue::Int(_));
                    // An int on a step that is never whole (0.5 + 1.5k) takes the nearest
                    // whole number.
                    assert!(
                        (k - k.round()).abs() < 1e-9 || (whole && step == Some(1.5)),
                        "{x} gave {n}, off the step {s} from {lo}"
                    );
                }
                // The nearest allowed value: no value on the step and in range is closer.
                if let (Some(s), false) = (step, matches!(v, ParamValue::Int(_))) {
                    let best = (0..=((hi - lo) / s).floor() as i64)
                        .map(|k| lo + k as f64 * s)
                        .map(|v| (v - x.clamp(lo, hi)).abs())
                        .fold(f64::INFINITY, f64::min);
                    assert!((n - x.clamp(lo, hi)).abs() <= best + 1e-9, "{x} gave {n}");
                }
            }
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                assert_eq!(c.value_of(&Raw::Number(bad)), None);
            }
        }
        let c = Control::of(&param(ParamValue::Float(0.5), range(0.1, 0.95, Some(0.2))));
        assert_eq!(
            c.value_of(&Raw::Number(0.64)),
            Some(ParamValue::Float(0.1 + 3.0 * 0.2))
        );
        // The top of the range is not on the step: the last step below it is the largest.
        assert_eq!(
            c.value_of(&Raw::Number(0.95)),
            Some(ParamValue::Float(0.1 + 4.0 * 0.2))
        );
        let c = Control::of(&param(ParamValue::Int(4), range(0.0, 10.0, Some(2.0))));
        assert_eq!(c.value_of(&Raw::Number(4.9)), Some(ParamValue::Int(4)));
        assert_eq!(c.value_of(&Raw::Number(5.1)), Some(ParamValue::Int(6)));
    }

    #[test]
    fn other_controls_give_checked_values_and_refuse_what_they_do_not_show() {
        let choices = vec!["round".to_string(), "square".to_string()];
        let p = param(ParamValue::Str("round".into()), Accepts::Choices(choices));
        let mut c = Control::of(&p);
        assert_eq!(c.parse("oval").and_then(|r| c.value_of(&r)), None);
        let square = c.parse("square").unwrap();
        assert_eq!(c.set(&square), Some(ParamValue::Str("square".into())));
        // The same value again is no change.
        assert_eq!(c.set(&square), None);
        assert!(p.accepts(&c.value));
        let mut b = Control::of(&param(ParamValue::Bool(true), Accepts::Any));
        assert_eq!(b.parse("yes"), None);
        assert_eq!(
            b.set(&b.parse("false").unwrap()),
            Some(ParamValue::Bool(false))
        );
        assert_eq!(b.value_of(&Raw::Number(1.0)), None);
        let n = Control::of(&param(ParamValue::Int(3), Accepts::Any));
        assert_eq!(n.value_of(&Raw::Number(2.6)), Some(ParamValue::Int(3)));
        assert_eq!(n.parse("x"), None);
        // The text offered to the checker reads back as the same value.
        for v in [0.1 + 0.2, 1e-300, 60.0, -2.5] {
            assert_eq!(text(&ParamValue::Float(v)).parse::<f64>(), Ok(v));
        }
        assert_eq!(text(&ParamValue::Str("a b".into())), "a b");
        assert_eq!(decimals(10.0, Some(1.0)), Some(0));
        assert_eq!(decimals(0.0, Some(0.05)), Some(2));
        assert_eq!(decimals(0.1, Some(0.2)), Some(1));
        assert_eq!(decimals(0.0, None), None);
    }
}
