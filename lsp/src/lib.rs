//! `sdfc lsp`: a Language Server Protocol server over standard input and output.
//!
//! Built on `lsp-types` and the message types of `lsp-server`, the synchronous pair
//! rust-analyzer is written on: the compiler is synchronous and checks a scene in
//! milliseconds, so one thread that reads a message, answers it and reads the next needs no
//! async runtime (as `tower-lsp` would bring). The framing is the server's own ([`wire`]): a
//! malformed message is answered with an error and the server reads on, where `lsp-server`'s
//! reader ends the connection. The one loop serves a byte stream ([`serve_stream`], stdio),
//! bytes in one thread ([`serve_bytes`], for fuzzing) or the in-memory
//! [`lsp_server::Connection::memory`] that tests drive with typed messages ([`serve`]).
//!
//! - [`documents`]: the open documents and checking one (imports from open documents first);
//! - [`diagnostics`]: the compiler's diagnostics as LSP's, and the quick fixes their help names;
//! - [`navigate`]: declarations and uses (definition, references, rename, symbols);
//! - [`hover`]: built-ins' signatures and docs, declarations, a shape's field facts;
//! - [`complete`]: completion and signature help;
//! - [`text`]: positions, URIs and the word under the cursor;
//! - [`wire`]: messages framed on a byte stream, every malformed one reported;
//!
//! and formatting through the compiler's formatter (`syntax::format`, as `sdfc fmt`).
//!
//! Diagnostics are published once the text has been still for [`DEBOUNCE`]; requests are
//! answered from the current text at once. A panic while answering one request becomes an
//! error response to it, and the server goes on.

pub mod complete;
pub mod diagnostics;
pub mod documents;
pub mod hover;
pub mod navigate;
pub mod text;
pub mod wire;

use documents::{Checked, Documents};
use lsp_server::{Connection, Message, Notification, Request, RequestId, Response};
use lsp_types as lsp;
use navigate::Index;
use sdfc_compiler::{FileId, Limits, Span};
use std::collections::{HashMap, HashSet};
use std::path::PathBuf;
use std::process::ExitCode;
use std::rc::Rc;
use std::time::{Duration, Instant};

/// How long the text must be still before diagnostics are published.
pub const DEBOUNCE: Duration = Duration::from_millis(150);

/// `sdfc lsp`: serves on stdin/stdout until the client says `exit`; exits 0 after
/// `shutdown`, else 1 (as the protocol says), and 2 when it cannot write to the client.
pub fn run(limits: Limits) -> ExitCode {
    match serve_stream(std::io::stdin(), std::io::stdout().lock(), limits) {
        Ok(exit) => {
            if let Exit::Closed { shutdown: false } = exit {
                eprintln!("sdfc lsp: the input ended before `shutdown` and `exit`");
            }
            ExitCode::from(exit.code())
        }
        Err(e) => {
            eprintln!("sdfc lsp: {e}");
            ExitCode::from(2)
        }
    }
}

/// How serving ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exit {
    /// `exit` after `shutdown`.
    Clean,
    /// `exit` without `shutdown`.
    WithoutShutdown,
    /// The input ended (after `shutdown` or not).
    Closed {
        /// Whether `shutdown` had been received.
        shutdown: bool,
    },
}

impl Exit {
    /// The process's exit status: 0 after `shutdown`, else 1.
    pub fn code(self) -> u8 {
        match self {
            Exit::Clean | Exit::Closed { shutdown: true } => 0,
            Exit::WithoutShutdown | Exit::Closed { shutdown: false } => 1,
        }
    }
}

/// Why serving stopped before `exit`.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// A message could not be written to the client.
    #[error("cannot write to the client: {0}")]
    Write(#[from] std::io::Error),
}

/// Serves the messages framed in `input` (read on a thread of its own, as they come) until
/// `exit` or the end of the input, writing to `output`, within `limits`.
pub fn serve_stream<R: std::io::Read + Send + 'static>(
    input: R,
    mut output: impl std::io::Write,
    limits: Limits,
) -> Result<Exit, ServeError> {
    let (sender, receiver) = crossbeam_channel::bounded::<wire::Incoming>(16);
    let message_limit = wire::message_limit(&limits);
    std::thread::spawn(move || {
        let reader = std::io::BufReader::new(input);
        let mut reader = wire::Reader::with_limit(reader, message_limit);
        // Ends at the end of the input, when it cannot be read, or when the server is gone.
        while let Ok(Some(frame)) = reader.next_frame() {
            if sender.send(wire::classify(frame)).is_err() {
                break;
            }
        }
    });
    serve_with(
        &mut ChannelInbox(receiver),
        &mut WriteOutbox(&mut output),
        limits,
    )
}

/// Serves the messages framed in `input`, in order, as if the client paused between each two
/// long enough for diagnostics to be published, until `exit` or the end of the input, writing
/// to `output`, within `limits`: the whole server in one thread, deterministic (for fuzzing).
pub fn serve_bytes(input: &[u8], output: &mut Vec<u8>, limits: Limits) -> Result<Exit, ServeError> {
    let mut inbox = BytesInbox {
        reader: wire::Reader::with_limit(input, wire::message_limit(&limits)),
    };
    serve_with(&mut inbox, &mut WriteOutbox(output), limits)
}

/// Serves an in-memory connection within the default limits (the same loop: tests drive it
/// with typed messages).
pub fn serve(connection: &Connection) -> Result<Exit, ServeError> {
    let mut inbox = ChannelInbox(connection.receiver.clone());
    serve_with(
        &mut inbox,
        &mut ConnectionOutbox(connection),
        Limits::default(),
    )
}

/// What the loop gets next.
enum Next {
    /// A message (or one refused).
    Incoming(wire::Incoming),
    /// The time to publish diagnostics has come.
    Timeout,
    /// The input ended.
    Closed,
}

/// Where messages come from.
trait Inbox {
    /// The next message, waiting at most `wait` when given.
    fn next(&mut self, wait: Option<Duration>) -> Next;
}

struct ChannelInbox<T>(crossbeam_channel::Receiver<T>);

impl<T: Into<wire::Incoming>> Inbox for ChannelInbox<T> {
    fn next(&mut self, wait: Option<Duration>) -> Next {
        let got = match wait {
            Some(wait) => match self.0.recv_timeout(wait) {
                Err(crossbeam_channel::RecvTimeoutError::Timeout) => return Next::Timeout,
                other => other.ok(),
            },
            None => self.0.recv().ok(),
        };
        got.map_or(Next::Closed, |m| Next::Incoming(m.into()))
    }
}

impl From<Message> for wire::Incoming {
    fn from(m: Message) -> Self {
        wire::Incoming::Message(m)
    }
}

/// Bytes read in order, the debounce passing before every message when diagnostics are due.
struct BytesInbox<'a> {
    reader: wire::Reader<&'a [u8]>,
}

impl Inbox for BytesInbox<'_> {
    fn next(&mut self, wait: Option<Duration>) -> Next {
        if wait.is_some() {
            return Next::Timeout;
        }
        match self.reader.next_frame() {
            Ok(Some(frame)) => Next::Incoming(wire::classify(frame)),
            _ => Next::Closed,
        }
    }
}

/// Where messages go.
trait Outbox {
    /// Sends a message.
    fn send(&mut self, message: Message) -> std::io::Result<()>;
    /// Answers what is not a message the server can handle with an error (to `id`, any JSON).
    fn refuse(
        &mut self,
        id: &serde_json::value::RawValue,
        code: i32,
        message: &str,
    ) -> std::io::Result<()>;
}

struct WriteOutbox<W>(W);

impl<W: std::io::Write> Outbox for WriteOutbox<W> {
    fn send(&mut self, message: Message) -> std::io::Result<()> {
        wire::write(&mut self.0, &message)
    }

    fn refuse(
        &mut self,
        id: &serde_json::value::RawValue,
        code: i32,
        message: &str,
    ) -> std::io::Result<()> {
        wire::write_error(&mut self.0, id, code, message)
    }
}

struct ConnectionOutbox<'a>(&'a Connection);

impl Outbox for ConnectionOutbox<'_> {
    fn send(&mut self, message: Message) -> std::io::Result<()> {
        self.0
            .sender
            .send(message)
            .map_err(|_| std::io::Error::from(std::io::ErrorKind::BrokenPipe))
    }

    fn refuse(
        &mut self,
        id: &serde_json::value::RawValue,
        code: i32,
        message: &str,
    ) -> std::io::Result<()> {
        // A connection of typed messages carries only ids that are ids: nothing is refused
        // for its id there.
        let id = serde_json::from_str::<RequestId>(id.get()).ok();
        match id {
            Some(id) => self.send(Response::new_err(id, code, message.into()).into()),
            None => Ok(()),
        }
    }
}

/// Where the server is in the protocol's life cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stage {
    /// Before `initialize`.
    Starting,
    /// Serving.
    Running,
    /// After `shutdown`: only `exit` is expected.
    ShutDown,
}

/// The loop: `initialize`, then requests and notifications until `exit` or the end of the
/// input. What is not a message is answered with an error and the loop goes on.
fn serve_with(
    inbox: &mut dyn Inbox,
    out: &mut dyn Outbox,
    limits: Limits,
) -> Result<Exit, ServeError> {
    use lsp_server::ErrorCode;
    let mut server = Server {
        limits,
        ..Server::default()
    };
    let mut stage = Stage::Starting;
    loop {
        let wait = server
            .due
            .map(|due| due.saturating_duration_since(Instant::now()));
        let msg = match inbox.next(wait) {
            Next::Incoming(wire::Incoming::Message(m)) => m,
            Next::Incoming(wire::Incoming::Refused { id, code, message }) => {
                out.refuse(&id, code, &message)?;
                continue;
            }
            Next::Timeout => {
                server.publish(out)?;
                continue;
            }
            Next::Closed => {
                return Ok(Exit::Closed {
                    shutdown: stage == Stage::ShutDown,
                })
            }
        };
        match msg {
            Message::Request(req) => {
                let id = req.id.clone();
                let refuse = |code: ErrorCode, message: &str| {
                    Response::new_err(id.clone(), code as i32, message.into())
                };
                let response = match (stage, req.method.as_str()) {
                    (Stage::Starting, "initialize") => {
                        stage = Stage::Running;
                        Response::new_ok(id, serde_json::json!({ "capabilities": capabilities() }))
                    }
                    (Stage::Starting, _) => refuse(
                        ErrorCode::ServerNotInitialized,
                        "the server is not initialised: `initialize` comes first",
                    ),
                    (Stage::Running, "initialize") => refuse(
                        ErrorCode::InvalidRequest,
                        "the server is already initialised",
                    ),
                    (Stage::Running, "shutdown") => {
                        stage = Stage::ShutDown;
                        Response::new_ok(id, serde_json::Value::Null)
                    }
                    (Stage::ShutDown, _) => refuse(
                        ErrorCode::InvalidRequest,
                        "the server is shut down: only `exit` is expected",
                    ),
                    (Stage::Running, _) => server.answer(req),
                };
                out.send(response.into())?;
            }
            Message::Notification(n) => {
                if n.method == "exit" {
                    return Ok(match stage {
                        Stage::ShutDown => Exit::Clean,
                        _ => Exit::WithoutShutdown,
                    });
                }
                if stage == Stage::Running {
                    let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                        server.notification(n)
                    }));
                }
            }
            Message::Response(_) => {}
        }
    }
}

/// What the server can do.
pub fn capabilities() -> lsp::ServerCapabilities {
    lsp::ServerCapabilities {
        text_document_sync: Some(lsp::TextDocumentSyncCapability::Kind(
            lsp::TextDocumentSyncKind::INCREMENTAL,
        )),
        hover_provider: Some(lsp::HoverProviderCapability::Simple(true)),
        definition_provider: Some(lsp::OneOf::Left(true)),
        references_provider: Some(lsp::OneOf::Left(true)),
        document_symbol_provider: Some(lsp::OneOf::Left(true)),
        rename_provider: Some(lsp::OneOf::Left(true)),
        document_formatting_provider: Some(lsp::OneOf::Left(true)),
        code_action_provider: Some(lsp::CodeActionProviderCapability::Simple(true)),
        completion_provider: Some(lsp::CompletionOptions {
            trigger_characters: Some(vec!["\"".into(), ".".into()]),
            ..Default::default()
        }),
        signature_help_provider: Some(lsp::SignatureHelpOptions {
            trigger_characters: Some(vec!["(".into(), ",".into()]),
            ..Default::default()
        }),
        ..Default::default()
    }
}

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
struct Server {
    /// The limits of checking a document and reading its imports.
    limits: Limits,
    docs: Documents,
    /// The URI each open document was opened under, by normalised path.
    uris: HashMap<String, lsp::Uri>,
    cache: HashMap<String, Rc<Analysed>>,
    /// Documents whose diagnostics are due, and when.
    due: Option<Instant>,
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

/// The path a document's URI names (a `file:` URI's path; another scheme's URI as it is).
fn path_of(uri: &lsp::Uri) -> PathBuf {
    text::uri_to_path(uri).unwrap_or_else(|| PathBuf::from(uri.as_str()))
}

impl Server {
    fn notification(&mut self, n: Notification) {
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
    fn answer(&mut self, req: Request) -> Response {
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
    fn publish(&mut self, out: &mut dyn Outbox) -> std::io::Result<()> {
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
        let unknown = || {
            Err((
                lsp_server::ErrorCode::InvalidRequest as i32,
                "the document is not open".to_string(),
            ))
        };
        match req.method.as_str() {
            "textDocument/hover" => {
                let p: lsp::HoverParams = params(req)?;
                let uri = p.text_document_position_params.text_document.uri;
                let Some(a) = self.analysed(&uri) else {
                    return unknown();
                };
                let c = &a.checked;
                let t = c.sources.text(c.entry);
                let at = text::offset(t, p.text_document_position_params.position);
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
                let uri = p.text_document_position_params.text_document.uri;
                let Some(a) = self.analysed(&uri) else {
                    return unknown();
                };
                let (decl, _) = match self.decl_at(&a, p.text_document_position_params.position) {
                    Some(d) => d,
                    None => return json(serde_json::Value::Null),
                };
                json(
                    self.location(&a, &uri, decl.at)
                        .map(lsp::GotoDefinitionResponse::Scalar),
                )
            }
            "textDocument/references" => {
                let p: lsp::ReferenceParams = params(req)?;
                let uri = p.text_document_position.text_document.uri;
                let Some(a) = self.analysed(&uri) else {
                    return unknown();
                };
                let Some((decl, _)) = self.decl_at(&a, p.text_document_position.position) else {
                    return json(serde_json::Value::Null);
                };
                let locations: Vec<lsp::Location> = a
                    .index
                    .references(&decl)
                    .filter(|s| p.context.include_declaration || *s != decl.at)
                    .filter_map(|s| self.location(&a, &uri, s))
                    .collect();
                json(locations)
            }
            "textDocument/rename" => {
                let p: lsp::RenameParams = params(req)?;
                let uri = p.text_document_position.text_document.uri;
                let Some(a) = self.analysed(&uri) else {
                    return unknown();
                };
                let new = p.new_name;
                if let Some(why) = navigate::not_a_new_name(&new) {
                    return Err((lsp_server::ErrorCode::InvalidParams as i32, why));
                }
                let Some((decl, _)) = self.decl_at(&a, p.text_document_position.position) else {
                    return Err((
                        lsp_server::ErrorCode::InvalidParams as i32,
                        "no declaration of this file or its imports is here".into(),
                    ));
                };
                // `Uri` hashes by its text, which nothing here mutates.
                #[allow(clippy::mutable_key_type)]
                let mut changes: HashMap<lsp::Uri, Vec<lsp::TextEdit>> = HashMap::new();
                for s in a.index.references(&decl) {
                    if let Some(l) = self.location(&a, &uri, s) {
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
            "textDocument/codeAction" => {
                let p: lsp::CodeActionParams = params(req)?;
                let uri = p.text_document.uri;
                let Some(a) = self.analysed(&uri) else {
                    return unknown();
                };
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
                let uri = p.text_document_position.text_document.uri;
                let Some(a) = self.analysed(&uri) else {
                    return unknown();
                };
                let c = &a.checked;
                let t = c.sources.text(c.entry);
                let at = text::offset(t, p.text_document_position.position);
                json(lsp::CompletionResponse::Array(complete::complete(
                    &a.index, c.entry, t, at,
                )))
            }
            "textDocument/signatureHelp" => {
                let p: lsp::SignatureHelpParams = params(req)?;
                let uri = p.text_document_position_params.text_document.uri;
                let Some(a) = self.analysed(&uri) else {
                    return unknown();
                };
                let c = &a.checked;
                let at = text::offset(
                    c.sources.text(c.entry),
                    p.text_document_position_params.position,
                );
                json(complete::signature_help(&a.index, &c.sources, c.entry, at))
            }
            "textDocument/formatting" => {
                let p: lsp::DocumentFormattingParams = params(req)?;
                let path = path_of(&p.text_document.uri);
                let Some(t) = self.docs.get(&path) else {
                    return unknown();
                };
                json(formatting(t))
            }
            "textDocument/documentSymbol" => {
                let p: lsp::DocumentSymbolParams = params(req)?;
                let Some(a) = self.analysed(&p.text_document.uri) else {
                    return unknown();
                };
                json(lsp::DocumentSymbolResponse::Nested(symbols(&a)))
            }
            _ => Err((
                lsp_server::ErrorCode::MethodNotFound as i32,
                format!("`{}` is not supported", req.method),
            )),
        }
    }

    /// The declaration of the name at `pos` of the entry document (or the declaration written
    /// there).
    fn decl_at(&self, a: &Analysed, pos: lsp::Position) -> Option<(navigate::Decl, Span)> {
        let c = &a.checked;
        let at = text::offset(c.sources.text(c.entry), pos);
        let (name, span) = a.index.use_at(c.entry, at)?;
        Some((a.index.resolve(name, *span)?.clone(), *span))
    }
}

/// The edits that format the text `t` (`sdfc fmt`'s layout): one replacing the whole text
/// when it changes, none when it is formatted or does not parse (its diagnostics say why).
pub fn formatting(t: &str) -> Vec<lsp::TextEdit> {
    match sdfc_compiler::format::format(t) {
        Ok(out) if out != t => vec![lsp::TextEdit::new(text::range(t, 0, t.len()), out)],
        _ => Vec::new(),
    }
}

/// Applies one change to a document's text (the whole text, or a range of it).
pub fn apply(t: &mut String, change: lsp::TextDocumentContentChangeEvent) {
    match change.range {
        None => *t = change.text,
        Some(r) => {
            let start = text::offset(t, r.start);
            let end = text::offset(t, r.end).max(start);
            t.replace_range(start..end, &change.text);
        }
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
    let Some(file) = a.index.files.get(c.entry.0 as usize) else {
        return Vec::new();
    };
    let _: FileId = c.entry;
    let mut out = Vec::new();
    for item in &file.items {
        match item {
            ast::Item::Let(l) => out.push(sym(
                l.name.name.clone(),
                lsp::SymbolKind::CONSTANT,
                l.span,
                l.name.span,
                vec![],
            )),
            ast::Item::Fn(f) => {
                let params = f
                    .params
                    .iter()
                    .map(|p| {
                        sym(
                            p.name.name.clone(),
                            lsp::SymbolKind::VARIABLE,
                            p.name.span,
                            p.name.span,
                            vec![],
                        )
                    })
                    .collect();
                out.push(sym(
                    f.name.name.clone(),
                    lsp::SymbolKind::FUNCTION,
                    f.span,
                    f.name.span,
                    params,
                ));
            }
            ast::Item::Material { name, span, .. } => out.push(sym(
                name.name.clone(),
                lsp::SymbolKind::STRUCT,
                *span,
                name.span,
                vec![],
            )),
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
                        ast::Stmt::Let(l) => Some(sym(
                            l.name.name.clone(),
                            lsp::SymbolKind::VARIABLE,
                            l.span,
                            l.name.span,
                            vec![],
                        )),
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
