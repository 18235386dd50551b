//! Completion and signature help: names in scope, built-ins with their parameters (from the
//! builtins table), built-in constants, material kinds, the fields of materials, lights,
//! `camera` and `render`, and the strings a field or parameter accepts (`variant:`).

use super::navigate::{Index, What};
use lsp_types as lsp;
use sdfc_compiler::{
    builtins::{self, Range, BUILTINS},
    FileId, SourceMap, Span,
};

fn item(label: &str, kind: lsp::CompletionItemKind, detail: String) -> lsp::CompletionItem {
    lsp::CompletionItem {
        label: label.to_string(),
        kind: Some(kind),
        detail: (!detail.is_empty()).then_some(detail),
        ..Default::default()
    }
}

/// The strings accepted by the parameter or field called `name`, from the tables.
fn strings(name: &str) -> Vec<&'static str> {
    let records = builtins::MATERIALS
        .iter()
        .chain(builtins::LIGHTS)
        .chain([&builtins::CAMERA, &builtins::RENDER]);
    let params = BUILTINS
        .iter()
        .flat_map(|b| b.sigs.iter().flat_map(|s| s.params.iter()))
        .chain(records.flat_map(|r| r.fields.iter()));
    let mut out: Vec<&'static str> = Vec::new();
    for p in params.filter(|p| p.name == name) {
        if let Range::OneOf(values) = p.range {
            for v in values {
                if !out.contains(v) {
                    out.push(v);
                }
            }
        }
    }
    out
}

/// The completions at byte `offset` of `text` (file `file`).
pub fn complete(
    index: &Index,
    file: FileId,
    text: &str,
    offset: usize,
) -> Vec<lsp::CompletionItem> {
    let offset = offset.min(text.len());
    let before = text.get(..offset).unwrap_or("");
    let line = before.rsplit('\n').next().unwrap_or("");
    // In a string after `name: "`: the strings that field or parameter accepts.
    if line.matches('"').count() % 2 == 1 {
        let head = line[..line.rfind('"').unwrap_or(0)].trim_end();
        let head = head.strip_suffix(':').unwrap_or(head).trim_end();
        let name = head
            .rsplit(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .next()
            .unwrap_or("");
        return strings(name)
            .into_iter()
            .map(|s| {
                item(
                    s,
                    lsp::CompletionItemKind::ENUM_MEMBER,
                    format!("{name}: \"{s}\""),
                )
            })
            .collect();
    }
    // After `material NAME =`: the material kinds.
    let trimmed = line.trim_start();
    if trimmed.starts_with("material") && trimmed.trim_end().ends_with('=') {
        return builtins::MATERIALS
            .iter()
            .map(|m| {
                item(
                    m.name,
                    lsp::CompletionItemKind::CLASS,
                    "material kind".into(),
                )
            })
            .collect();
    }
    if trimmed.starts_with("light") && !trimmed.contains('{') {
        return builtins::LIGHTS
            .iter()
            .map(|m| item(m.name, lsp::CompletionItemKind::CLASS, "light kind".into()))
            .collect();
    }
    let mut out = Vec::new();
    // Inside a block: its fields.
    if let Some(record) = enclosing_block(before) {
        for p in record {
            out.push(item(
                p.name,
                lsp::CompletionItemKind::FIELD,
                match p.def.value() {
                    Some(v) => format!("{}: {} = {v}", p.name, p.ty),
                    None => format!("{}: {}", p.name, p.ty),
                },
            ));
        }
    }
    let here = Span::new(file, offset..offset);
    let mut seen = std::collections::HashSet::new();
    for d in &index.decls {
        let visible = match d.scope {
            None => true,
            Some(s) => s.file == file && s.start as usize <= offset && offset <= s.end as usize,
        };
        if !visible || !seen.insert(d.name.clone()) {
            continue;
        }
        // The declaration the name resolves to here, so that a hidden one is not offered.
        let Some(d) = index.resolve(&d.name, here) else {
            continue;
        };
        let kind = match d.what {
            What::Fn => lsp::CompletionItemKind::FUNCTION,
            What::Material => lsp::CompletionItemKind::COLOR,
            What::Let => lsp::CompletionItemKind::CONSTANT,
            What::Param | What::Loop => lsp::CompletionItemKind::VARIABLE,
        };
        out.push(item(&d.name, kind, String::new()));
    }
    for b in BUILTINS.iter() {
        let sigs: Vec<String> = b
            .sigs
            .iter()
            .map(|s| builtins::signature(b.name, s))
            .collect();
        out.push(item(
            b.name,
            lsp::CompletionItemKind::FUNCTION,
            sigs.join("\n"),
        ));
    }
    for (name, v) in builtins::CONSTANTS {
        out.push(item(
            name,
            lsp::CompletionItemKind::CONSTANT,
            format!("{name} = {v}"),
        ));
    }
    out.push(item(
        builtins::TIME,
        lsp::CompletionItemKind::VARIABLE,
        "time in seconds".into(),
    ));
    for kw in [
        "let", "fn", "material", "import", "scene", "camera", "render", "light", "for", "in", "if",
        "else", "field", "profile",
    ] {
        out.push(item(kw, lsp::CompletionItemKind::KEYWORD, String::new()));
    }
    out
}

/// The fields of the block the text before the cursor is inside (`camera {`, `render {`,
/// `light KIND {`, `material NAME = KIND {`).
fn enclosing_block(before: &str) -> Option<&'static [builtins::P]> {
    let mut depth = 0i32;
    for (i, c) in before.char_indices().rev() {
        match c {
            '}' | ')' => depth += 1,
            '(' if depth > 0 => depth -= 1,
            '(' => return None,
            '{' if depth > 0 => depth -= 1,
            '{' => {
                let head = before[..i].rsplit([';', '}', '{']).next().unwrap_or("");
                let words: Vec<&str> = head.split_whitespace().collect();
                return match words.as_slice() {
                    ["camera"] => Some(builtins::CAMERA.fields),
                    ["render"] => Some(builtins::RENDER.fields),
                    ["light", kind] => builtins::LIGHTS
                        .iter()
                        .find(|r| r.name == *kind)
                        .map(|r| r.fields),
                    ["material", _, "=", kind] => builtins::MATERIALS
                        .iter()
                        .find(|r| r.name == *kind)
                        .map(|r| r.fields),
                    _ => None,
                };
            }
            _ => {}
        }
    }
    None
}

/// Signature help at byte `offset` of the file `file`: the signatures of the call the cursor is in
/// (a built-in's overloads, or a function of the file), with the active parameter.
pub fn signature_help(
    index: &Index,
    sources: &SourceMap,
    file: FileId,
    offset: usize,
) -> Option<lsp::SignatureHelp> {
    let text = sources.text(file);
    let before = text.get(..offset.min(text.len()))?;
    let mut depth = 0i32;
    let mut commas = 0u32;
    let mut open = None;
    for (i, c) in before.char_indices().rev() {
        match c {
            ')' | ']' | '}' => depth += 1,
            '(' | '[' | '{' if depth > 0 => depth -= 1,
            '(' => {
                open = Some(i);
                break;
            }
            '[' | '{' | ';' => return None,
            ',' if depth == 0 => commas += 1,
            _ => {}
        }
    }
    let open = open?;
    let (name, _) = super::text::word_at(before, open.checked_sub(1)?)?;
    let mut sigs: Vec<lsp::SignatureInformation> = Vec::new();
    if let Some(b) = builtins::builtin(name) {
        for s in b.sigs {
            sigs.push(lsp::SignatureInformation {
                label: builtins::signature(b.name, s),
                documentation: None,
                parameters: Some(
                    s.params
                        .iter()
                        .map(|p| lsp::ParameterInformation {
                            label: lsp::ParameterLabel::Simple(p.name.to_string()),
                            documentation: None,
                        })
                        .collect(),
                ),
                active_parameter: None,
            });
        }
    } else {
        let at = Span::new(file, open - name.len()..open);
        let decl = index.resolve(name, at).filter(|d| d.what == What::Fn)?;
        let params: Vec<String> = index
            .decls
            .iter()
            .filter(|p| p.what == What::Param && p.scope == Some(decl.span))
            .map(|p| p.name.clone())
            .collect();
        let whole = sources.text(decl.span.file).get(decl.span.range())?;
        let src = whole.split('{').next()?.trim_end().to_string();
        sigs.push(lsp::SignatureInformation {
            label: src,
            documentation: None,
            parameters: Some(
                params
                    .into_iter()
                    .map(|p| lsp::ParameterInformation {
                        label: lsp::ParameterLabel::Simple(p),
                        documentation: None,
                    })
                    .collect(),
            ),
            active_parameter: None,
        });
    }
    // The first overload with enough parameters for the argument being written.
    let active = sigs
        .iter()
        .position(|s| {
            s.parameters
                .as_ref()
                .is_some_and(|p| p.len() as u32 > commas)
        })
        .unwrap_or(0);
    Some(lsp::SignatureHelp {
        signatures: sigs,
        active_signature: Some(active as u32),
        active_parameter: Some(commas),
    })
}
