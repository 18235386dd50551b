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

/// The start of the note on the last error kept where checking stopped early.
const STOPPED: &str = "checking stopped here";

/// The note on the last error kept where checking stopped after `errors` errors.
pub fn stopped_note(errors: usize) -> String {
    format!("{STOPPED}, after {errors} errors: fix these and check again")
}

/// Whether checking stopped early at one of `diags` (its note says so).
pub fn stopped(diags: &[Diagnostic]) -> bool {
    diags
        .iter()
        .any(|d| d.notes.iter().any(|n| n.starts_with(STOPPED)))
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
        if d.labels.iter().any(|l| on_a_long_line(sources, l.span)) {
            out.extend_from_slice(excerpted(d, sources).as_bytes());
            continue;
        }
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
        let order = label_order(d, sources);
        for (l, order) in d.labels.iter().zip(order) {
            let mut label = ALabel::new((l.span.file, l.span.range())).with_order(order);
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

/// The order ariadne is given the labels in: by file (the primary's first), then by the line
/// each ends on, then as the diagnostic lists them. ariadne starts a new excerpt whenever a
/// label lies on an earlier line than the one before it, and heads that excerpt with the
/// primary label's line and column: a note given after the primary but above it ("first
/// defined here") would be shown under the primary's location.
fn label_order(d: &Diagnostic, sources: &SourceMap) -> Vec<i32> {
    let mut files = Vec::new();
    for l in &d.labels {
        if !files.contains(&l.span.file) {
            files.push(l.span.file);
        }
    }
    let keys: Vec<(usize, usize, usize)> = d
        .labels
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let file = files.iter().position(|f| *f == l.span.file).unwrap_or(0);
            let last = l.span.end.max(l.span.start.saturating_add(1)) - 1;
            let (line, _) = sources.line_col(Span {
                start: last,
                end: last,
                ..l.span
            });
            (file, line, i)
        })
        .collect();
    let mut by_key: Vec<usize> = (0..keys.len()).collect();
    by_key.sort_by_key(|&i| keys[i]);
    let mut order = vec![0; keys.len()];
    for (rank, i) in by_key.into_iter().enumerate() {
        order[i] = rank as i32;
    }
    order
}

/// Lines longer than this (in bytes) are shown as an excerpt around the span, not whole: a
/// scene written on one line of 300 KB would otherwise be repeated in every diagnostic.
pub(crate) const LONG_LINE: usize = 240;

/// Bytes of context shown on each side of a span on a long line.
const CONTEXT: usize = 60;

/// The byte range of the line that holds `at` in `text`.
fn line_around(text: &str, at: usize) -> std::ops::Range<usize> {
    let at = floor_boundary(text, at.min(text.len()));
    let start = text[..at].rfind('\n').map_or(0, |i| i + 1);
    let end = text[at..].find('\n').map_or(text.len(), |i| at + i);
    start..end
}

fn floor_boundary(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

fn ceil_boundary(s: &str, mut i: usize) -> usize {
    while i < s.len() && !s.is_char_boundary(i) {
        i += 1;
    }
    i
}

fn on_a_long_line(sources: &SourceMap, span: Span) -> bool {
    line_around(sources.text(span.file), span.start as usize).len() > LONG_LINE
}

/// A diagnostic in the plain form, each label with an excerpt of its line of at most
/// `2 × CONTEXT` bytes around the span (and the first `CONTEXT` bytes of a long span), marked
/// with `…` where the line goes on, and carets under the span.
fn excerpted(d: &Diagnostic, sources: &SourceMap) -> String {
    let mut out = format!("{}[{}]: {}\n", kind_word(d.severity), d.code, d.message);
    for l in &d.labels {
        let text = sources.text(l.span.file);
        let (line_no, col) = sources.line_col(l.span);
        out.push_str(&format!(
            "   ╭─[ {}:{line_no}:{col} ]\n",
            sources.name(l.span.file)
        ));
        let line = line_around(text, l.span.start as usize);
        let start = floor_boundary(text, (l.span.start as usize).clamp(line.start, line.end));
        let end = ceil_boundary(
            text,
            (l.span.end as usize).clamp(start, line.end.min(start + CONTEXT)),
        );
        let from = floor_boundary(text, start.saturating_sub(CONTEXT).max(line.start));
        let to = ceil_boundary(text, (end + CONTEXT).min(line.end));
        let lead = if from > line.start { "…" } else { "" };
        let tail = if to < line.end { "…" } else { "" };
        out.push_str(&format!("{line_no:>3} │ {lead}{}{tail}\n", &text[from..to]));
        let pad = lead.chars().count() + text[from..start].chars().count();
        let width = text[start..end].chars().count().max(1);
        out.push_str(&format!(
            "    │ {}{} {}\n",
            " ".repeat(pad),
            "^".repeat(width),
            l.message
        ));
    }
    for n in &d.notes {
        out.push_str(&format!("    │ Note: {n}\n"));
    }
    if let Some(h) = &d.help {
        out.push_str(&format!("    │ Help: {h}\n"));
    }
    out
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

#[cfg(test)]
mod tests {
    use super::*;

    /// An error in the middle of a 300 KB line shows an excerpt around it, not the line.
    #[test]
    fn a_long_line_is_shown_as_a_bounded_excerpt() {
        let mut text = "let a = 1; ".repeat(30_000);
        let at = text.len() / 2;
        text.insert_str(at, "sphre(1); ");
        let mut sources = SourceMap::new();
        let file = sources.add("long.sdf", text.clone());
        let d = Diagnostic::error(
            "E0301",
            "unknown function `sphre`",
            Span::new(file, at..at + 5),
        )
        .with_label("not defined")
        .with_help("did you mean `sphere`?");
        let out = render(std::slice::from_ref(&d), &sources, false);
        assert!(out.len() < 1000, "{} bytes", out.len());
        assert!(
            out.contains("error[E0301]: unknown function `sphre`"),
            "{out}"
        );
        assert!(out.contains("…") && out.contains("sphre(1);"), "{out}");
        assert!(out.contains("long.sdf:1:"), "{out}");
        // The carets stand under the span: as many columns in as `sphre` is in the excerpt.
        let lines: Vec<&str> = out.lines().collect();
        let shown = lines.iter().find(|l| l.contains("sphre(1);")).unwrap();
        let carets = lines.iter().find(|l| l.contains("^^^^^")).unwrap();
        let col = |s: &str, pat: &str| s[..s.find(pat).unwrap()].chars().count();
        assert_eq!(col(shown, "sphre"), col(carets, "^^^^^"), "{out}");
        assert!(!carets.contains("^^^^^^"), "{out}");
        // A short line keeps the full report.
        let mut sources = SourceMap::new();
        let file = sources.add("short.sdf", "scene { sphre(1); }\n");
        let d = Diagnostic::error("E0301", "unknown function `sphre`", Span::new(file, 8..13));
        let out = render(&[d], &sources, false);
        assert!(out.contains("scene { sphre(1); }"), "{out}");
        assert!(!out.contains('…'), "{out}");
    }

    /// A secondary label above the primary one is shown in the same excerpt, under the
    /// primary's location, not in a second excerpt headed by the primary's line and column.
    #[test]
    fn a_label_above_the_primary_shares_its_excerpt() {
        let mut sources = SourceMap::new();
        let file = sources.add("twice.sdf", "let a = 1;\nlet a = 2;\nscene { }\n");
        let d = Diagnostic::error("E0207", "duplicate", Span::new(file, 15..16))
            .with_label("defined again here")
            .with_secondary(Span::new(file, 4..5), "first defined here");
        let out = render(&[d], &sources, false);
        assert_eq!(out.matches("twice.sdf:").count(), 1, "{out}");
        assert!(out.contains("twice.sdf:2:5"), "{out}");
        let first = out.find("first defined here").expect("the secondary label");
        let again = out.find("defined again here").expect("the primary label");
        assert!(first < again, "{out}");
    }
}
