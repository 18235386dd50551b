//! Hover: a built-in's signatures and its line of docs/language.md's table (which
//! compiler/tests/compiler/tidy.rs keeps equal to the builtins table), a built-in constant's value, a
//! declaration's text (a global constant's with its value, as the checker evaluated it),
//! and for a shape what the analysis derived for it: exact, bound or
//! approximate, L, bounding box, and whether the scene is traced or marched (the facts
//! `sdfc check` prints, from the same functions).

use super::documents::Checked;
use super::navigate::{Decl, Index, What};
use sdfc_compiler::{
    analysis, analytic,
    builtins::{self, BUILTINS},
    FileId, NodeId, Span,
};

/// docs/language.md, whose tables give each built-in's valid values and a line on what it does.
const LANGUAGE: &str = include_str!("../../docs/language.md");

/// The "valid values" and "what it does" cells of the row of docs/language.md whose first
/// cell is the signature `sig`.
pub fn doc_line(sig: &str) -> Option<(String, String)> {
    let first = format!("| `{sig}` |");
    let row = LANGUAGE.lines().find(|l| l.starts_with(&first))?;
    let cells: Vec<&str> = row[first.len()..]
        .trim_end()
        .trim_end_matches('|')
        .split(" | ")
        .map(str::trim)
        .collect();
    Some((
        cells.first()?.to_string(),
        cells.get(1).map_or(String::new(), |c| c.to_string()),
    ))
}

/// Markdown for a built-in: each signature with its valid values and what it does.
pub fn builtin(name: &str) -> Option<String> {
    let b = builtins::builtin(name)?;
    let mut out = String::new();
    let mut last_doc = String::new();
    for sig in b.sigs {
        let s = builtins::signature(b.name, sig);
        out.push_str(&format!("```sdf\n{s}\n```\n"));
        if let Some((valid, what)) = doc_line(&s) {
            // `″` in the table repeats the line above.
            let what = if what == "″" {
                last_doc.clone()
            } else {
                what
            };
            if !valid.is_empty() && valid != "—" {
                out.push_str(&format!("Valid: {valid}\n\n"));
            }
            if !what.is_empty() && what != last_doc {
                out.push_str(&format!("{what}\n\n"));
            }
            last_doc = what;
        }
    }
    Some(out.trim_end().to_string())
}

/// The smallest shape node of the scene written within `span` or around it, in `file`.
fn node_at(checked: &Checked, file: FileId, span: Span) -> Option<NodeId> {
    let scene = checked.scene.as_ref()?;
    let g = &scene.graph;
    let covers =
        |s: Span, inner: Span| s.file == inner.file && s.start <= inner.start && inner.end <= s.end;
    let within = g
        .ids()
        .filter(|&id| g.span(id).file == file && covers(span, g.span(id)))
        .max_by_key(|&id| g.span(id).end - g.span(id).start);
    within.or_else(|| {
        g.ids()
            .filter(|&id| covers(g.span(id), span))
            .min_by_key(|&id| g.span(id).end - g.span(id).start)
    })
}

fn num(x: f64) -> String {
    if !x.is_finite() {
        return if x > 0.0 {
            "∞".into()
        } else if x < 0.0 {
            "-∞".into()
        } else {
            "NaN".into()
        };
    }
    let s = format!("{x:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// What the analysis derived for the shape at `span` (a node written there, or the
/// smallest around it), as markdown lines.
pub fn shape_facts(checked: &Checked, span: Span) -> Option<String> {
    let scene = checked.scene.as_ref()?;
    let id = node_at(checked, span.file, span)?;
    let analysis = analysis::analyse(scene);
    let d = analysis.node(id);
    let node = scene.graph.node(id);
    let word = analysis::describe(d.facts.exactness);
    let proven = if d.proven { "" } else { ", no bound proven" };
    let b = d.bounds;
    let bounds = if b.min.iter().chain(&b.max).all(|x| x.is_finite()) {
        format!(
            "({}, {}, {}) to ({}, {}, {})",
            num(b.min[0]),
            num(b.min[1]),
            num(b.min[2]),
            num(b.max[0]),
            num(b.max[1]),
            num(b.max[2])
        )
    } else {
        "unbounded".into()
    };
    let method = analytic::traceable(scene).choose(scene.settings.method);
    let method = match method {
        analytic::Choice::March(analytic::Reason::Node { what, .. }) => {
            format!("method: march (the {what} has no closed-form ray intersection)")
        }
        analytic::Choice::March(analytic::Reason::Overlap { .. }) => {
            "method: march (transparent shapes overlap)".to_string()
        }
        other => other.describe(),
    };
    Some(format!(
        "**{}**: distance field {word} (L = {}{proven})  \nbounding box: {bounds}  \nscene {method}",
        analysis::kind(node),
        num(d.facts.lipschitz),
    ))
}

/// Markdown for the declaration `decl`: its text up to its body, and for a `let` of a shape
/// that shape's facts.
pub fn declaration(checked: &Checked, decl: &Decl) -> String {
    let text = checked.sources.text(decl.span.file);
    let whole = text.get(decl.span.range()).unwrap_or("");
    let head = match decl.what {
        What::Fn => whole
            .split('{')
            .next()
            .unwrap_or(whole)
            .trim_end()
            .to_string(),
        What::Material => whole.to_string(),
        What::Let => whole.trim_end_matches(';').to_string() + ";",
        What::Param => {
            format!("(parameter) {}", whole)
        }
        What::Loop => format!("(loop variable) {whole}: int"),
    };
    let head = if head.len() > 400 {
        let mut cut = 400;
        while !head.is_char_boundary(cut) {
            cut -= 1;
        }
        format!("{}…", &head[..cut])
    } else {
        head
    };
    let mut out = format!("```sdf\n{head}\n```");
    if decl.what == What::Let {
        if let Some(c) = checked.constants.iter().find(|c| c.at == decl.at) {
            out.push_str(&format!("\n\n= `{}` ({})", c.value, c.ty));
        }
    }
    if let Some(facts) = decl.value.and_then(|v| shape_facts(checked, v)) {
        out.push_str(&format!("\n\n{facts}"));
    }
    let name = checked.sources.name(decl.span.file);
    if decl.span.file != checked.entry {
        out.push_str(&format!("\n\nfrom `{name}`"));
    }
    out
}

/// The hover at byte `offset` of the entry document.
pub fn hover(checked: &Checked, index: &Index, offset: usize) -> Option<(String, Span)> {
    let file = checked.entry;
    let text = checked.sources.text(file);
    let (word, range) = super::text::word_at(text, offset)?;
    let span = Span::new(file, range);
    if let Some((name, at)) = index.use_at(file, offset) {
        if let Some(decl) = index.resolve(name, *at) {
            // At a call of a user function, or at a name, the call's shape facts come first.
            let mut out = declaration(checked, decl);
            if decl.what == What::Fn && decl.at != *at {
                if let Some(facts) = shape_facts(checked, *at) {
                    out = format!("{facts}\n\n{out}");
                }
            }
            return Some((out, *at));
        }
    }
    if let Some(doc) = builtin(word) {
        let facts = BUILTINS
            .iter()
            .any(|b| b.name == word)
            .then(|| shape_facts(checked, span))
            .flatten();
        return Some((
            match facts {
                Some(f) => format!("{f}\n\n{doc}"),
                None => doc,
            },
            span,
        ));
    }
    if let Some(v) = builtins::constant(word) {
        return Some((
            format!("```sdf\n{word}: float = {v}\n```\nbuilt-in constant"),
            span,
        ));
    }
    if word == builtins::TIME {
        return Some((
            "```sdf\nt: float\n```\nthe time in seconds (docs/animation.md)".into(),
            span,
        ));
    }
    None
}
