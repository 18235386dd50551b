//! The server's state and its answers: the open documents, their checked and indexed
//! analyses (kept until a document changes), and every request and notification served
//! from them.

use crate::documents::{Checked, Documents};
use crate::navigate::{self, Index};
use crate::{apply, formatting, text, Outbox, DEBOUNCE};
use crate::{complete, diagnostics, hover};
use lsp_server::{Notification, Request, Response};
use lsp_types as lsp;
use sdfc_compiler::{FileId, Limits, Span};
use std::collections::{HashMap, HashSet};
use std::path::PathBuf;
use std::rc::Rc;
use std::time::Instant;

/// A checked document with its index, kept until any document changes.
#[derive(Debug)]
struct Analysed {
    checked: Checked,
    index: Index,
    /// The lines of the entry document.
    lines: text::Lines,
}

/// The server's state.
#[derive(Debug, Default)]
pub(crate) struct Server {
    /// The limits of checking a document and reading its imports.
    limits: Limits,
    docs: Documents,
    /// The URI each open document was opened under, by normalised path.
    uris: HashMap<String, lsp::Uri>,
    cache: HashMap<String, Rc<Analysed>>,
    /// Documents whose diagnostics are due, and when.
    pub(crate) due: Option<Instant>,
    pending: HashSet<String>,
}

type Answer = Result<serde_json::Value, (i32, String)>;

fn params<P: serde::de::DeserializeOwned>(req: Request) -> Result<P, (i32, String)> {
    serde_json::from_value(req.params).map_err(|e| {
        (
            lsp_server::ErrorCode::InvalidParams as i32,
            format!("invalid parameters: {e}"),
        )
    })
}

fn json<T: serde::Serialize>(value: T) -> Answer {
    serde_json::to_value(value)
        .map_err(|e| (lsp_server::ErrorCode::InternalError as i32, e.to_string()))
}

/// The error answered to a request about a document that is not open.
fn not_open() -> (i32, String) {
    (
        lsp_server::ErrorCode::InvalidRequest as i32,
        "the document is not open".to_string(),
    )
}

/// The path a document's URI names (a `file:` URI's path; another scheme's URI as it is).
fn path_of(uri: &lsp::Uri) -> PathBuf {
    text::uri_to_path(uri).unwrap_or_else(|| PathBuf::from(uri.as_str()))
}

impl Server {
    /// A server that checks documents within `limits`, with nothing open.
    pub(crate) fn new(limits: Limits) -> Server {
        Server {
            limits,
            ..Server::default()
        }
    }

    pub(crate) fn notification(&mut self, n: Notification) {
        match n.method.as_str() {
            "textDocument/didOpen" => {
                if let Ok(p) = serde_json::from_value::<lsp::DidOpenTextDocumentParams>(n.params) {
                    let path = path_of(&p.text_document.uri);
                    self.docs.set(&path, p.text_document.text);
                    self.uris
                        .insert(sdfc_compiler::files::normalise(&path), p.text_document.uri);
                    self.changed(&path);
                }
            }
            "textDocument/didChange" => {
                if let Ok(p) = serde_json::from_value::<lsp::DidChangeTextDocumentParams>(n.params)
                {
                    let path = path_of(&p.text_document.uri);
                    let mut t = self.docs.get(&path).unwrap_or("").to_string();
                    for c in p.content_changes {
                        apply(&mut t, c);
                    }
                    self.docs.set(&path, t);
                    self.changed(&path);
                }
            }
            "textDocument/didClose" => {
                if let Ok(p) = serde_json::from_value::<lsp::DidCloseTextDocumentParams>(n.params) {
                    let path = path_of(&p.text_document.uri);
                    self.docs.close(&path);
                    self.cache.clear();
                    self.pending.remove(&sdfc_compiler::files::normalise(&path));
                }
            }
            "workspace/didChangeWatchedFiles" | "textDocument/didSave" => {
                // A file on disk that an open document imports may have changed.
                self.cache.clear();
                self.pending.extend(self.docs.paths().map(str::to_string));
                self.due = Some(Instant::now() + DEBOUNCE);
            }
            _ => {}
        }
    }

    /// Marks every open document (one may import the changed one) for new diagnostics.
    fn changed(&mut self, _path: &std::path::Path) {
        self.cache.clear();
        self.pending.extend(self.docs.paths().map(str::to_string));
        self.due = Some(Instant::now() + DEBOUNCE);
    }

    /// Answers a request: its result, or an error response (also when answering panics).
    pub(crate) fn answer(&mut self, req: Request) -> Response {
        let id = req.id.clone();
        let answer = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| self.request(req)));
        match answer {
            Ok(Ok(value)) => Response::new_ok(id, value),
            Ok(Err((code, message))) => Response::new_err(id, code, message),
            Err(_) => Response::new_err(
                id,
                lsp_server::ErrorCode::InternalError as i32,
                "sdfc lsp: internal error while answering (a bug: please report the file)".into(),
            ),
        }
    }

    /// Publishes the diagnostics of the documents marked.
    pub(crate) fn publish(&mut self, out: &mut dyn Outbox) -> std::io::Result<()> {
        self.due = None;
        for name in std::mem::take(&mut self.pending) {
            let Some(uri) = self.uris.get(&name).cloned() else {
                continue;
            };
            // A panic while checking (a bug) leaves this document without new diagnostics
            // rather than ending the server.
            let converted = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                let a = self.analysed(&uri)?;
                let c = &a.checked;
                Some(diagnostics::convert(&c.diagnostics, &c.sources, c.entry))
            }));
            let Ok(Some(diagnostics)) = converted else {
                continue;
            };
            let params = lsp::PublishDiagnosticsParams {
                uri,
                diagnostics,
                version: None,
            };
            out.send(Notification::new("textDocument/publishDiagnostics".into(), params).into())?;
        }
        Ok(())
    }

    /// The open document `uri` checked and indexed (cached until a document changes).
    fn analysed(&mut self, uri: &lsp::Uri) -> Option<Rc<Analysed>> {
        let path = path_of(uri);
        let name = sdfc_compiler::files::normalise(&path);
        if let Some(a) = self.cache.get(&name) {
            return Some(a.clone());
        }
        let checked = self.docs.check(&path, &self.limits)?;
        let index = Index::new(&checked.sources);
        let lines = text::Lines::new(checked.sources.text(checked.entry));
        let a = Rc::new(Analysed {
            checked,
            index,
            lines,
        });
        self.cache.insert(name, a.clone());
        Some(a)
    }

    /// [`Server::analysed`] for a request, which refuses a document that is not open.
    fn open(&mut self, uri: &lsp::Uri) -> Result<Rc<Analysed>, (i32, String)> {
        self.analysed(uri).ok_or_else(not_open)
    }

    /// The document a request points into, opened, and the byte offset of the point in its
    /// text.
    fn open_at(
        &mut self,
        p: &lsp::TextDocumentPositionParams,
    ) -> Result<(Rc<Analysed>, usize), (i32, String)> {
        let a = self.open(&p.text_document.uri)?;
        let c = &a.checked;
        let at = text::offset(c.sources.text(c.entry), p.position);
        Ok((a, at))
    }

    /// The location of `span`: the entry document's own URI, or an imported file's path.
    fn location(&self, a: &Analysed, uri: &lsp::Uri, span: Span) -> Option<lsp::Location> {
        let c = &a.checked;
        if span.file == c.entry {
            let t = c.sources.text(span.file);
            return Some(lsp::Location::new(
                uri.clone(),
                a.lines.range(t, span.start as usize, span.end as usize),
            ));
        }
        let name = c.sources.name(span.file);
        match self.uris.get(name) {
            Some(u) => Some(lsp::Location::new(
                u.clone(),
                text::range(
                    c.sources.text(span.file),
                    span.start as usize,
                    span.end as usize,
                ),
            )),
            None => diagnostics::location(&c.sources, span),
        }
    }

    fn request(&mut self, req: Request) -> Answer {
        match req.method.as_str() {
            "textDocument/hover" => {
                let p: lsp::HoverParams = params(req)?;
                let (a, at) = self.open_at(&p.text_document_position_params)?;
                let c = &a.checked;
                let t = c.sources.text(c.entry);
                json(hover::hover(c, &a.index, at).map(|(md, span)| lsp::Hover {
                    contents: lsp::HoverContents::Markup(lsp::MarkupContent {
                        kind: lsp::MarkupKind::Markdown,
                        value: md,
                    }),
                    range: Some(text::range(t, span.start as usize, span.end as usize)),
                }))
            }
            "textDocument/definition" => {
                let p: lsp::GotoDefinitionParams = params(req)?;
                let (a, at) = self.open_at(&p.text_document_position_params)?;
                let Some((decl, _)) = self.decl_at(&a, at) else {
                    return json(serde_json::Value::Null);
                };
                let uri = &p.text_document_position_params.text_document.uri;
                json(
                    self.location(&a, uri, decl.at)
                        .map(lsp::GotoDefinitionResponse::Scalar),
                )
            }
            "textDocument/references" => self.references(params(req)?),
            "textDocument/rename" => self.rename(params(req)?),
            "textDocument/codeAction" => {
                let p: lsp::CodeActionParams = params(req)?;
                let uri = p.text_document.uri;
                let a = self.open(&uri)?;
                let c = &a.checked;
                json(diagnostics::quick_fixes(
                    &c.diagnostics,
                    &c.sources,
                    c.entry,
                    &uri,
                    p.range,
                ))
            }
            "textDocument/completion" => {
                let p: lsp::CompletionParams = params(req)?;
                let (a, at) = self.open_at(&p.text_document_position)?;
                let c = &a.checked;
                let t = c.sources.text(c.entry);
                json(lsp::CompletionResponse::Array(complete::complete(
                    &a.index, c.entry, t, at,
                )))
            }
            "textDocument/signatureHelp" => {
                let p: lsp::SignatureHelpParams = params(req)?;
                let (a, at) = self.open_at(&p.text_document_position_params)?;
                let c = &a.checked;
                json(complete::signature_help(&a.index, &c.sources, c.entry, at))
            }
            "textDocument/formatting" => {
                let p: lsp::DocumentFormattingParams = params(req)?;
                let path = path_of(&p.text_document.uri);
                let t = self.docs.get(&path).ok_or_else(not_open)?;
                json(formatting(t))
            }
            "textDocument/documentSymbol" => {
                let p: lsp::DocumentSymbolParams = params(req)?;
                let a = self.open(&p.text_document.uri)?;
                json(lsp::DocumentSymbolResponse::Nested(symbols(&a)))
            }
            _ => Err((
                lsp_server::ErrorCode::MethodNotFound as i32,
                format!("`{}` is not supported", req.method),
            )),
        }
    }

    /// `textDocument/references`: every use of the declaration at the position.
    fn references(&mut self, p: lsp::ReferenceParams) -> Answer {
        let (a, at) = self.open_at(&p.text_document_position)?;
        let uri = &p.text_document_position.text_document.uri;
        let Some((decl, _)) = self.decl_at(&a, at) else {
            return json(serde_json::Value::Null);
        };
        let locations: Vec<lsp::Location> = a
            .index
            .references(&decl)
            .filter(|s| p.context.include_declaration || *s != decl.at)
            .filter_map(|s| self.location(&a, uri, s))
            .collect();
        json(locations)
    }

    /// `textDocument/rename`: every use of the declaration at the position renamed, in every
    /// document of the workspace that has one.
    fn rename(&mut self, p: lsp::RenameParams) -> Answer {
        let (a, at) = self.open_at(&p.text_document_position)?;
        let uri = &p.text_document_position.text_document.uri;
        let new = p.new_name;
        if let Some(why) = navigate::not_a_new_name(&new) {
            return Err((lsp_server::ErrorCode::InvalidParams as i32, why));
        }
        let Some((decl, _)) = self.decl_at(&a, at) else {
            return Err((
                lsp_server::ErrorCode::InvalidParams as i32,
                "no declaration of this file or its imports is here".into(),
            ));
        };
        // `Uri` hashes by its text, which nothing here mutates.
        #[allow(clippy::mutable_key_type)]
        let mut changes: HashMap<lsp::Uri, Vec<lsp::TextEdit>> = HashMap::new();
        for s in a.index.references(&decl) {
            if let Some(l) = self.location(&a, uri, s) {
                changes
                    .entry(l.uri)
                    .or_default()
                    .push(lsp::TextEdit::new(l.range, new.clone()));
            }
        }
        json(lsp::WorkspaceEdit {
            changes: Some(changes),
            ..Default::default()
        })
    }

    /// The declaration of the name at byte `at` of the entry document (or the declaration
    /// written there).
    fn decl_at(&self, a: &Analysed, at: usize) -> Option<(navigate::Decl, Span)> {
        let c = &a.checked;
        let (name, span) = a.index.use_at(c.entry, at)?;
        Some((a.index.resolve(name, *span)?.clone(), *span))
    }
}

/// The document's outline: functions (with their parameters), constants, materials, the
/// settings blocks and lights, and the scene with its statements.
#[allow(deprecated)] // `DocumentSymbol::deprecated` must be given.
fn symbols(a: &Analysed) -> Vec<lsp::DocumentSymbol> {
    use sdfc_compiler::ast;
    let c = &a.checked;
    let t = c.sources.text(c.entry);
    let r = |s: Span| a.lines.range(t, s.start as usize, s.end as usize);
    let sym = |name: String,
               kind: lsp::SymbolKind,
               span: Span,
               at: Span,
               children: Vec<lsp::DocumentSymbol>| lsp::DocumentSymbol {
        name,
        detail: None,
        kind,
        tags: None,
        deprecated: None,
        range: r(span),
        selection_range: r(at),
        children: (!children.is_empty()).then_some(children),
    };
    // A symbol without children, selected at its name.
    let named =
        |name: &ast::Ident, kind, span| sym(name.name.clone(), kind, span, name.span, vec![]);
    let Some(file) = a.index.files.get(c.entry.0 as usize) else {
        return Vec::new();
    };
    let _: FileId = c.entry;
    let mut out = Vec::new();
    for item in &file.items {
        match item {
            ast::Item::Let(l) => out.push(named(&l.name, lsp::SymbolKind::CONSTANT, l.span)),
            ast::Item::Fn(f) => {
                let params = f
                    .params
                    .iter()
                    .map(|p| named(&p.name, lsp::SymbolKind::VARIABLE, p.name.span))
                    .collect();
                out.push(sym(
                    f.name.name.clone(),
                    lsp::SymbolKind::FUNCTION,
                    f.span,
                    f.name.span,
                    params,
                ));
            }
            ast::Item::Material { name, span, .. } => {
                out.push(named(name, lsp::SymbolKind::STRUCT, *span))
            }
            ast::Item::Block(b) => {
                let name = match &b.kind {
                    Some(k) => format!("{} {}", b.keyword.name, k.name),
                    None => b.keyword.name.clone(),
                };
                out.push(sym(
                    name,
                    lsp::SymbolKind::OBJECT,
                    b.span,
                    b.keyword.span,
                    vec![],
                ))
            }
            ast::Item::Scene { stmts, span } => {
                let children = stmts
                    .iter()
                    .filter_map(|s| match s {
                        ast::Stmt::Let(l) => {
                            Some(named(&l.name, lsp::SymbolKind::VARIABLE, l.span))
                        }
                        ast::Stmt::Object(e) => {
                            let first = t
                                .get(e.span.range())
                                .unwrap_or("")
                                .lines()
                                .next()
                                .unwrap_or("");
                            Some(sym(
                                first.trim().to_string(),
                                lsp::SymbolKind::OBJECT,
                                e.span,
                                e.span,
                                vec![],
                            ))
                        }
                        ast::Stmt::For { var, span, .. } => Some(sym(
                            format!("for {}", var.name),
                            lsp::SymbolKind::OPERATOR,
                            *span,
                            var.span,
                            vec![],
                        )),
                        _ => None,
                    })
                    .collect();
                let at = Span {
                    end: span.start + 5.min(span.end - span.start),
                    ..*span
                };
                out.push(sym(
                    "scene".into(),
                    lsp::SymbolKind::NAMESPACE,
                    *span,
                    at,
                    children,
                ))
            }
            _ => {}
        }
    }
    out
}
