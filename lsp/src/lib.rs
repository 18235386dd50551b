//! `sdfc lsp`: a Language Server Protocol server over standard input and output (the loop
//! and its transports; `server.rs` the state and the answers).
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
mod server;
pub mod text;
pub mod wire;

use lsp_server::{Connection, Message, RequestId, Response};
use lsp_types as lsp;
use sdfc_compiler::Limits;
use serde_json::value::RawValue;
use server::Server;
use std::process::ExitCode;
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
    fn refuse(&mut self, id: &RawValue, code: i32, message: &str) -> std::io::Result<()>;
}

struct WriteOutbox<W>(W);

impl<W: std::io::Write> Outbox for WriteOutbox<W> {
    fn send(&mut self, message: Message) -> std::io::Result<()> {
        wire::write(&mut self.0, &message)
    }

    fn refuse(&mut self, id: &RawValue, code: i32, message: &str) -> std::io::Result<()> {
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

    fn refuse(&mut self, id: &RawValue, code: i32, message: &str) -> std::io::Result<()> {
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
    let mut server = Server::new(limits);
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
