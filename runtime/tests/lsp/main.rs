//! `sdfc lsp` at the protocol level: each request over the server's in-memory connection
//! (the same loop stdio drives), on a document with an import and a mistake, and a server
//! that keeps answering while the text is mutated at random through incremental changes;
//! and through a real editor's client, Neovim's (`in/lsp/neovim.lua`), talking to the
//! `sdfc lsp` process. Without `nvim` that test prints that it skipped, unless
//! `SDFC_REQUIRE_DEVICES=1` (set by `.ci/run`, which installs Debian's `neovim`): then it fails.
//!
//! This file holds the in-memory client and the documents' helpers; the tests are in
//! `requests`, `mutated` (random edits, latency), `wire` (the process's framing and ids) and
//! `neovim`.

mod mutated;
mod neovim;
mod requests;
mod wire;

use lsp_server::{Connection, Message, Notification, Request, RequestId, Response};
use sdfc_runtime::lsp::text::path_to_uri;
use sdfc_runtime::lsp::{Exit, ServeError};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// A client on one end of an in-memory connection, the server on a thread at the other.
struct Client {
    conn: Connection,
    server: Option<std::thread::JoinHandle<Result<Exit, ServeError>>>,
    next: i32,
    /// Diagnostics published so far, by URI (the latest).
    published: std::collections::HashMap<String, Value>,
}

impl Client {
    fn start() -> Client {
        let (server, client) = Connection::memory();
        let handle = std::thread::spawn(move || sdfc_runtime::lsp::serve(&server));
        let mut c = Client {
            conn: client,
            server: Some(handle),
            next: 0,
            published: Default::default(),
        };
        let caps = c.request("initialize", json!({ "capabilities": {} }));
        assert!(
            caps["capabilities"]["hoverProvider"] == json!(true),
            "{caps}"
        );
        c.notify("initialized", json!({}));
        c
    }

    fn notify(&self, method: &str, params: Value) {
        self.conn
            .sender
            .send(Notification::new(method.into(), params).into())
            .expect("server alive");
    }

    fn receive(&mut self) -> Message {
        let msg = self
            .conn
            .receiver
            .recv_timeout(Duration::from_secs(60))
            .expect("the server answers");
        if let Message::Notification(n) = &msg {
            if n.method == "textDocument/publishDiagnostics" {
                let uri = n.params["uri"].as_str().unwrap_or("").to_string();
                self.published.insert(uri, n.params["diagnostics"].clone());
            }
        }
        msg
    }

    /// Sends a request and returns its response (result or error).
    fn respond(&mut self, method: &str, params: Value) -> Response {
        self.next += 1;
        let id = RequestId::from(self.next);
        self.conn
            .sender
            .send(Request::new(id.clone(), method.into(), params).into())
            .expect("server alive");
        loop {
            if let Message::Response(r) = self.receive() {
                if r.id == id {
                    return r;
                }
            }
        }
    }

    /// Sends a request and returns its result, failing on an error response.
    fn request(&mut self, method: &str, params: Value) -> Value {
        match self.respond(method, params).response_result {
            Ok(v) => v,
            Err(e) => panic!("{method} failed: {} {}", e.code, e.message),
        }
    }

    /// Opens the document `uri` with `text` (version 1).
    fn open(&self, uri: &str, text: &str) {
        self.notify(
            "textDocument/didOpen",
            json!({ "textDocument": { "uri": uri, "languageId": "sdf", "version": 1, "text": text } }),
        );
    }

    /// The markdown of a hover at `position` (request parameters).
    fn hover(&mut self, position: Value) -> String {
        let h = self.request("textDocument/hover", position);
        h["contents"]["value"].as_str().unwrap().to_string()
    }

    /// The workspace edit of renaming the name at `position` (request parameters) to `new`.
    fn rename(&mut self, mut position: Value, new: &str) -> Value {
        position["newName"] = json!(new);
        self.request("textDocument/rename", position)
    }

    /// Waits for diagnostics of `uri` to be published.
    fn diagnostics(&mut self, uri: &str) -> Value {
        self.published.remove(uri);
        while !self.published.contains_key(uri) {
            self.receive();
        }
        self.published[uri].clone()
    }

    /// Stops the server, then removes the test's directory `dir`.
    fn finish(self, dir: &Path) {
        self.stop();
        let _ = std::fs::remove_dir_all(dir);
    }

    fn stop(mut self) {
        self.request("shutdown", Value::Null);
        self.notify("exit", Value::Null);
        let result = self
            .server
            .take()
            .expect("running")
            .join()
            .expect("no panic");
        assert!(matches!(result, Ok(Exit::Clean)), "{result:?}");
    }
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sdfc-lsp-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// A client of a fresh server with `text` open as the file `file` of a fresh directory for
/// the test `name`: the directory, the document's URI and the client.
fn opened(name: &str, file: &str, text: &str) -> (PathBuf, String, Client) {
    let dir = temp_dir(name);
    let doc = uri(&dir.join(file));
    let c = Client::start();
    c.open(&doc, text);
    (dir, doc, c)
}

fn uri(p: &Path) -> String {
    path_to_uri(p).expect("uri").as_str().to_string()
}

fn at(uri: &str, text: &str, needle: &str, shift: usize) -> Value {
    let offset = text
        .find(needle)
        .unwrap_or_else(|| panic!("`{needle}` in the text"))
        + shift;
    position(uri, text, offset)
}

/// The request parameters naming byte `offset` of `text` (a character boundary).
fn position(uri: &str, text: &str, offset: usize) -> Value {
    let before = &text[..offset];
    let line = before.matches('\n').count();
    let col = before
        .rsplit('\n')
        .next()
        .unwrap_or("")
        .encode_utf16()
        .count();
    json!({ "textDocument": { "uri": uri }, "position": { "line": line, "character": col } })
}

const LIB: &str = "// a library\nlet size = 0.5 * 2;\n\nfn post(h: float = 1) -> shape {\n    box((0.1, h, 0.1))\n}\n\nmaterial red = phong { color: (1, 0, 0) };\n";

const MAIN: &str = "import \"lib.sdf\";\n\nlight directional { direction: (-1, -1, 1) }\nlet ball = sphere(size).translate(0, 1, 0);\n\nscene {\n    union(ball, post(2)) @ red;\n    spher(1) @ red;\n}\n";
