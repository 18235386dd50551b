//! Diagnostics as data: severity, code, message, labelled spans, notes and a hint.
//!
//! Every stage of the compiler returns its diagnostics instead of printing them; the edge (the
//! CLI, an editor integration) renders them with [`render`] (ariadne) or [`to_json`].

use crate::span::{SourceMap, Span};
use serde::Serialize;

/// How bad a diagnostic is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    /// Something the user may want to know (for example what an analysis derived).
    Note,
    /// The scene compiles, but probably not as meant.
    Warning,
    /// The scene does not compile.
    Error,
}

/// A span with a message attached to it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Label {
    /// Where.
    pub span: Span,
    /// What is said about that place (may be empty).
    pub message: String,
}

/// One problem found in a source file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Diagnostic {
    /// Error, warning or note.
    pub severity: Severity,
    /// A stable code such as `E0101`; the table lives in `docs/diagnostics.md`.
    pub code: &'static str,
    /// One line saying what is wrong.
    pub message: String,
    /// The primary label comes first.
    pub labels: Vec<Label>,
    /// Extra facts, one sentence each.
    pub notes: Vec<String>,
    /// A suggestion that would fix it, when there is one.
    pub help: Option<String>,
}

impl Diagnostic {
    /// A new error with a primary label.
    pub fn error(code: &'static str, message: impl Into<String>, span: Span) -> Self {
        Self::new(Severity::Error, code, message, span)
    }

    /// A new warning with a primary label.
    pub fn warning(code: &'static str, message: impl Into<String>, span: Span) -> Self {
        Self::new(Severity::Warning, code, message, span)
    }

    /// A new note with a primary label.
    pub fn note(code: &'static str, message: impl Into<String>, span: Span) -> Self {
        Self::new(Severity::Note, code, message, span)
    }

    fn new(severity: Severity, code: &'static str, message: impl Into<String>, span: Span) -> Self {
        Diagnostic {
            severity,
            code,
            message: message.into(),
            labels: vec![Label {
                span,
                message: String::new(),
            }],
            notes: Vec::new(),
            help: None,
        }
    }

    /// Sets the primary label's message.
    pub fn with_label(mut self, message: impl Into<String>) -> Self {
        self.labels[0].message = message.into();
        self
    }

    /// Adds a secondary label.
    pub fn with_secondary(mut self, span: Span, message: impl Into<String>) -> Self {
        self.labels.push(Label {
            span,
            message: message.into(),
        });
        self
    }

    /// Adds a note.
    pub fn with_note(mut self, note: impl Into<String>) -> Self {
        self.notes.push(note.into());
        self
    }

    /// Sets the hint.
    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    /// The primary span.
    pub fn span(&self) -> Span {
        self.labels[0].span
    }

    /// True for errors.
    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }
}

/// True when any diagnostic is an error.
pub fn has_errors(diags: &[Diagnostic]) -> bool {
    diags.iter().any(Diagnostic::is_error)
}

/// Renders diagnostics as ariadne reports, without colour (stable for snapshots and logs)
/// or with colour (for a terminal).
pub fn render(diags: &[Diagnostic], sources: &SourceMap, colour: bool) -> String {
    use ariadne::{Config, Label as ALabel, Report, ReportKind};
    let mut out = Vec::new();
    let mut cache = SourceCache(sources, Vec::new());
    for d in diags {
        let kind = match d.severity {
            Severity::Error => ReportKind::Error,
            Severity::Warning => ReportKind::Warning,
            Severity::Note => ReportKind::Advice,
        };
        let primary = d.span();
        let mut report = Report::build(kind, (primary.file, primary.range()))
            .with_config(
                Config::default()
                    .with_color(colour)
                    .with_index_type(ariadne::IndexType::Byte),
            )
            .with_code(d.code)
            .with_message(&d.message);
        for (i, l) in d.labels.iter().enumerate() {
            let mut label = ALabel::new((l.span.file, l.span.range())).with_order(i as i32);
            if !l.message.is_empty() {
                label = label.with_message(&l.message);
            }
            report = report.with_label(label);
        }
        for n in &d.notes {
            report = report.with_note(n);
        }
        if let Some(h) = &d.help {
            report = report.with_help(h);
        }
        // Writing into a Vec cannot fail for IO reasons; a failure would be a span bug,
        // which falls back to the plain form below.
        if report.finish().write(&mut cache, &mut out).is_err() {
            out.extend_from_slice(
                format!("{}[{}]: {}\n", kind_word(d.severity), d.code, d.message).as_bytes(),
            );
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

fn kind_word(s: Severity) -> &'static str {
    match s {
        Severity::Error => "error",
        Severity::Warning => "warning",
        Severity::Note => "note",
    }
}

/// The JSON-lines form for editors: one object per diagnostic, with file names and
/// line/column positions (1-based) next to the byte offsets.
pub fn to_json(diags: &[Diagnostic], sources: &SourceMap) -> String {
    let mut out = String::new();
    for d in diags {
        let labels: Vec<_> = d
            .labels
            .iter()
            .map(|l| {
                let (line, col) = sources.line_col(l.span);
                serde_json::json!({
                    "file": sources.name(l.span.file),
                    "start": l.span.start, "end": l.span.end,
                    "line": line, "column": col,
                    "message": l.message,
                })
            })
            .collect();
        let v = serde_json::json!({
            "severity": d.severity, "code": d.code, "message": d.message,
            "labels": labels, "notes": d.notes, "help": d.help,
        });
        out.push_str(&v.to_string());
        out.push('\n');
    }
    out
}

struct SourceCache<'a>(
    &'a SourceMap,
    Vec<(crate::span::FileId, ariadne::Source<String>)>,
);

impl ariadne::Cache<crate::span::FileId> for SourceCache<'_> {
    type Storage = String;

    fn fetch(
        &mut self,
        id: &crate::span::FileId,
    ) -> Result<&ariadne::Source<String>, impl std::fmt::Debug> {
        if !self.1.iter().any(|(f, _)| f == id) {
            let text = self.0.text(*id).to_string();
            self.1.push((*id, ariadne::Source::from(text)));
        }
        self.1
            .iter()
            .find(|(f, _)| f == id)
            .map(|(_, s)| s)
            .ok_or("unknown file")
    }

    fn display<'b>(&self, id: &'b crate::span::FileId) -> Option<impl std::fmt::Display + 'b> {
        Some(self.0.name(*id).to_string())
    }
}

/// A small number for a message in scientific notation, rounded to three significant
/// digits: `9.71e-4`, `1e-6`.
pub fn scientific(x: f64) -> String {
    let rounded: f64 = format!("{x:.2e}").parse().unwrap_or(x);
    format!("{rounded:e}")
}

/// A number for a message: at most `decimals` decimals, no trailing zeros, no `-0`, and `∞`
/// for an infinite value.
pub fn number(x: f64, decimals: usize) -> String {
    if !x.is_finite() && !x.is_nan() {
        return if x > 0.0 { "∞".into() } else { "-∞".into() };
    }
    let s = format!("{x:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}
