//! The compiler's diagnostics as LSP diagnostics (code linked to docs/diagnostics.md,
//! secondary labels as related information, notes and help in the message), and the quick
//! fixes that their help names: ``did you mean `X`?`` and ``write `X` `` replace the
//! primary span with `X`.

use super::text;
use lsp_types as lsp;
use sdfc_compiler::{Diagnostic, FileId, Severity, SourceMap, Span};
use std::path::Path;

/// The table of codes, linked from every diagnostic (the file beside the sources the
/// server was built from).
fn docs_uri() -> Option<lsp::Uri> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/diagnostics.md");
    text::path_to_uri(Path::new(&sdfc_compiler::files::normalise(&path)))
}

/// The location of a span in `sources` (its file named by a path).
pub fn location(sources: &SourceMap, span: Span) -> Option<lsp::Location> {
    let uri = text::path_to_uri(&absolute(sources.name(span.file)))?;
    let t = sources.text(span.file);
    Some(lsp::Location::new(
        uri,
        text::range(t, span.start as usize, span.end as usize),
    ))
}

/// A source name as an absolute path (names are paths as the client gave them, or relative
/// to the importing file).
pub fn absolute(name: &str) -> std::path::PathBuf {
    let p = Path::new(name);
    if p.is_absolute() {
        p.to_path_buf()
    } else {
        std::env::current_dir().unwrap_or_default().join(p)
    }
}

/// The LSP diagnostics of the document `entry`: those in it as they are, and one at the
/// top of it for each error in a file it imports (with that place as related information).
pub fn convert(diags: &[Diagnostic], sources: &SourceMap, entry: FileId) -> Vec<lsp::Diagnostic> {
    let entry_text = sources.text(entry);
    let lines = text::Lines::new(entry_text);
    let docs = docs_uri();
    diags
        .iter()
        .filter(|d| d.span().file == entry || d.is_error())
        .map(|d| {
            let span = d.span();
            let mut message = d.message.clone();
            let primary = &d.labels[0].message;
            if !primary.is_empty() {
                message.push_str(&format!("\n{primary}"));
            }
            for n in &d.notes {
                message.push_str(&format!("\nnote: {n}"));
            }
            if let Some(h) = &d.help {
                message.push_str(&format!("\nhelp: {h}"));
            }
            let mut related: Vec<lsp::DiagnosticRelatedInformation> = d.labels[1..]
                .iter()
                .filter_map(|l| {
                    Some(lsp::DiagnosticRelatedInformation {
                        location: location(sources, l.span)?,
                        message: if l.message.is_empty() {
                            "here".into()
                        } else {
                            l.message.clone()
                        },
                    })
                })
                .collect();
            let range = if span.file == entry {
                lines.range(entry_text, span.start as usize, span.end as usize)
            } else {
                message = format!("in `{}`: {message}", sources.name(span.file));
                if let Some(location) = location(sources, span) {
                    related.insert(
                        0,
                        lsp::DiagnosticRelatedInformation {
                            location,
                            message: d.message.clone(),
                        },
                    );
                }
                lsp::Range::default()
            };
            lsp::Diagnostic {
                range,
                severity: Some(match d.severity {
                    Severity::Error => lsp::DiagnosticSeverity::ERROR,
                    Severity::Warning => lsp::DiagnosticSeverity::WARNING,
                    Severity::Note => lsp::DiagnosticSeverity::INFORMATION,
                }),
                code: Some(lsp::NumberOrString::String(d.code.to_string())),
                code_description: docs.clone().map(|href| lsp::CodeDescription { href }),
                source: Some("sdfc".into()),
                message,
                related_information: (!related.is_empty()).then_some(related),
                tags: None,
                data: None,
            }
        })
        .collect()
}

/// The text a help proposes in place of the primary span: ``did you mean `X`?`` or
/// ``write `X` ``.
pub fn replacement(help: &str) -> Option<&str> {
    let rest = help
        .strip_prefix("did you mean `")
        .or_else(|| help.strip_prefix("write `"))?;
    let end = rest.find('`')?;
    let tail = rest[end + 1..].trim();
    (tail.is_empty() || tail == "?").then(|| &rest[..end])
}

/// The quick fixes of the diagnostics of `entry` that overlap `range`.
pub fn quick_fixes(
    diags: &[Diagnostic],
    sources: &SourceMap,
    entry: FileId,
    uri: &lsp::Uri,
    range: lsp::Range,
) -> Vec<lsp::CodeActionOrCommand> {
    let t = sources.text(entry);
    let (from, to) = (text::offset(t, range.start), text::offset(t, range.end));
    let lsp_diags = convert(diags, sources, entry);
    diags
        .iter()
        .filter(|d| d.span().file == entry)
        .filter(|d| {
            let s = d.span();
            (s.start as usize) <= to && from <= (s.end as usize)
        })
        .filter_map(|d| {
            let new = replacement(d.help.as_deref()?)?;
            let span = d.span();
            let edit = lsp::TextEdit::new(
                text::range(t, span.start as usize, span.end as usize),
                new.to_string(),
            );
            let this = lsp_diags.iter().find(|l| {
                l.code == Some(lsp::NumberOrString::String(d.code.into()))
                    && l.range.start == text::position(t, span.start as usize)
            });
            Some(lsp::CodeActionOrCommand::CodeAction(lsp::CodeAction {
                title: format!("Replace with `{new}`"),
                kind: Some(lsp::CodeActionKind::QUICKFIX),
                diagnostics: this.map(|l| vec![l.clone()]),
                edit: Some(lsp::WorkspaceEdit {
                    changes: Some([(uri.clone(), vec![edit])].into_iter().collect()),
                    ..Default::default()
                }),
                is_preferred: Some(true),
                ..Default::default()
            }))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::replacement;

    #[test]
    fn helps_that_name_a_replacement() {
        assert_eq!(replacement("did you mean `sphere`?"), Some("sphere"));
        assert_eq!(replacement("write `0.5`"), Some("0.5"));
        assert_eq!(replacement("write a vector as `(x, y, z)`"), None);
        assert_eq!(replacement("did you mean `a` or `b`?"), None);
    }
}
