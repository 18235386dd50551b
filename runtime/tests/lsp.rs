//! `sdfc lsp` at the protocol level: each request over the server's in-memory connection
//! (the same loop stdio drives), on a document with an import and a mistake, and a server
//! that keeps answering while the text is mutated at random through incremental changes;
//! and through a real editor's client, Neovim's (`in/lsp/neovim.lua`), talking to the
//! `sdfc lsp` process. Without `nvim` that test prints that it skipped, unless
//! `SDFC_REQUIRE_DEVICES=1` (set by `.ci/run`, which installs Debian's `neovim`): then it fails.

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

    /// Waits for diagnostics of `uri` to be published.
    fn diagnostics(&mut self, uri: &str) -> Value {
        self.published.remove(uri);
        while !self.published.contains_key(uri) {
            self.receive();
        }
        self.published[uri].clone()
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

#[test]
fn every_request_on_a_document_with_an_import_and_a_mistake() {
    let dir = temp_dir("requests");
    std::fs::write(dir.join("lib.sdf"), LIB).expect("write");
    let main = dir.join("main.sdf");
    let main_uri = uri(&main);
    let lib_uri = uri(&dir.join("lib.sdf"));
    let mut c = Client::start();
    c.notify(
        "textDocument/didOpen",
        json!({ "textDocument": { "uri": main_uri, "languageId": "sdf", "version": 1, "text": MAIN } }),
    );

    // The mistake, at its place, with its code linked and a quick fix.
    let diags = c.diagnostics(&main_uri);
    let d = &diags.as_array().expect("a list")[0];
    assert_eq!(d["code"], "E0201", "{diags}");
    assert_eq!(
        d["range"]["start"],
        json!({ "line": 7, "character": 4 }),
        "{d}"
    );
    assert_eq!(
        d["range"]["end"],
        json!({ "line": 7, "character": 9 }),
        "{d}"
    );
    assert!(d["codeDescription"]["href"]
        .as_str()
        .unwrap()
        .ends_with("docs/diagnostics.md"));
    let actions = c.request(
        "textDocument/codeAction",
        json!({ "textDocument": { "uri": main_uri }, "range": d["range"], "context": { "diagnostics": [] } }),
    );
    let edit = &actions[0]["edit"]["changes"][&main_uri][0];
    assert_eq!(edit["newText"], "sphere", "{actions}");
    assert_eq!(edit["range"], d["range"]);

    // Fix it through an incremental change: the diagnostics go away.
    c.notify(
        "textDocument/didChange",
        json!({ "textDocument": { "uri": main_uri, "version": 2 },
                "contentChanges": [{ "range": d["range"], "text": "sphere" }] }),
    );
    let diags = c.diagnostics(&main_uri);
    assert!(
        diags.as_array().unwrap().iter().all(|d| d["severity"] != 1),
        "{diags}"
    );
    let text = MAIN.replace("spher(", "sphere(");

    // Hover: a shape's facts, a built-in's signature and doc line, an imported constant.
    let h = c.request("textDocument/hover", at(&main_uri, &text, "union", 1));
    let md = h["contents"]["value"].as_str().unwrap();
    assert!(
        md.contains("distance field bound (L = 1)")
            && md.contains("bounding box: (-1, -2, -1) to (1, 2, 1)"),
        "{md}"
    );
    assert!(
        md.contains("union(shapes...: shape) -> shape") || md.contains("union("),
        "{md}"
    );
    let h = c.request("textDocument/hover", at(&main_uri, &text, "ball,", 0));
    let md = h["contents"]["value"].as_str().unwrap();
    assert!(
        md.contains("let ball = sphere(size)") && md.contains("L = 1"),
        "{md}"
    );
    let h = c.request("textDocument/hover", at(&main_uri, &text, "sphere(size", 0));
    let md = h["contents"]["value"].as_str().unwrap();
    assert!(
        md.contains("sphere(radius: float = 1) -> shape") && md.contains("A sphere"),
        "{md}"
    );
    let h = c.request("textDocument/hover", at(&main_uri, &text, "size)", 0));
    let md = h["contents"]["value"].as_str().unwrap();
    assert!(
        md.contains("let size = 0.5 * 2;")
            && md.contains("= `1` (float)")
            && md.contains("lib.sdf"),
        "{md}"
    );

    // Definition and references across the import; rename edits both files.
    let def = c.request(
        "textDocument/definition",
        at(&main_uri, &text, "post(2)", 0),
    );
    assert_eq!(def["uri"], lib_uri.as_str(), "{def}");
    assert_eq!(
        def["range"]["start"],
        json!({ "line": 3, "character": 3 }),
        "{def}"
    );
    let mut refs = at(&main_uri, &text, "red;", 0);
    refs["context"] = json!({ "includeDeclaration": true });
    let refs = c.request("textDocument/references", refs);
    assert_eq!(refs.as_array().unwrap().len(), 3, "{refs}");
    let mut rename = at(&main_uri, &text, "ball,", 0);
    rename["newName"] = json!("orb");
    let edit = c.request("textDocument/rename", rename);
    assert_eq!(
        edit["changes"][&main_uri].as_array().unwrap().len(),
        2,
        "{edit}"
    );
    let mut rename = at(&main_uri, &text, "size)", 0);
    rename["newName"] = json!("side");
    let edit = c.request("textDocument/rename", rename);
    assert_eq!(
        edit["changes"][&lib_uri].as_array().unwrap().len(),
        1,
        "{edit}"
    );
    assert_eq!(
        edit["changes"][&main_uri].as_array().unwrap().len(),
        1,
        "{edit}"
    );

    // Completion: names in scope, built-ins, fields, strings.
    let items = c.request("textDocument/completion", at(&main_uri, &text, "union", 0));
    let labels: Vec<&str> = items
        .as_array()
        .unwrap()
        .iter()
        .map(|i| i["label"].as_str().unwrap())
        .collect();
    for want in [
        "ball",
        "post",
        "size",
        "red",
        "sphere",
        "smooth_union",
        "pi",
    ] {
        assert!(labels.contains(&want), "{want} in {labels:?}");
    }
    let items = c.request(
        "textDocument/completion",
        at(&main_uri, &text, "direction:", 0),
    );
    let labels: Vec<&str> = items
        .as_array()
        .unwrap()
        .iter()
        .map(|i| i["label"].as_str().unwrap())
        .collect();
    assert!(
        labels.contains(&"direction") && labels.contains(&"color"),
        "{labels:?}"
    );

    // Signature help inside a call.
    let s = c.request(
        "textDocument/signatureHelp",
        at(&main_uri, &text, "post(2)", 5),
    );
    assert_eq!(
        s["signatures"][0]["label"], "fn post(h: float = 1) -> shape",
        "{s}"
    );
    assert_eq!(s["activeParameter"], 0);
    let s = c.request(
        "textDocument/signatureHelp",
        at(&main_uri, &text, "translate(0, 1", 13),
    );
    assert!(
        s["signatures"][0]["label"]
            .as_str()
            .unwrap()
            .starts_with("translate("),
        "{s}"
    );
    assert_eq!(s["activeParameter"], 1);

    // The outline.
    let syms = c.request(
        "textDocument/documentSymbol",
        json!({ "textDocument": { "uri": main_uri } }),
    );
    let names: Vec<&str> = syms
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["light directional", "ball", "scene"], "{syms}");
    assert_eq!(syms[2]["children"].as_array().unwrap().len(), 2);

    // A document that is not open is an error, not a crash.
    let r = c.respond(
        "textDocument/hover",
        at(&uri(&dir.join("other.sdf")), "x", "x", 0),
    );
    assert!(r.response_result.is_err());
    c.stop();
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every example and test input, mutated at random by incremental changes (deleting,
/// inserting pieces of the language, splicing in other files), with requests at random
/// places after each change: every request gets an answer that is not an internal error.
#[test]
fn never_crashes_on_mutated_text() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut corpus = Vec::new();
    for dir in ["examples", "compiler/tests/in/ok", "compiler/tests/in/err"] {
        let Ok(entries) = std::fs::read_dir(root.join(dir)) else {
            continue;
        };
        let mut files: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
        files.sort();
        for p in files
            .into_iter()
            .filter(|p| p.extension().is_some_and(|e| e == "sdf"))
        {
            if let Ok(t) = std::fs::read_to_string(&p) {
                corpus.push(t);
            }
        }
    }
    assert!(corpus.len() > 20);
    const SNIPPETS: &[&str] = &[
        "(",
        ")",
        "{",
        "}",
        ";",
        ",",
        "\"",
        "é",
        "𝔸",
        "\n",
        "sphere(",
        "@",
        "let x = ",
        "fn f(",
        "union(",
        "[for i in 0..3 { ",
        "//",
        "/*",
        "1e400",
        "-",
        ".",
        "deg",
    ];
    let mut rng = sdfc_compiler::Rng::new(0x15D_F0C5);
    let dir = temp_dir("mutated");
    let doc = uri(&dir.join("m.sdf"));
    let mut c = Client::start();
    let methods = [
        "textDocument/hover",
        "textDocument/definition",
        "textDocument/completion",
        "textDocument/signatureHelp",
        "textDocument/documentSymbol",
        "textDocument/references",
        "textDocument/formatting",
    ];
    for round in 0..12 {
        let mut text = corpus[rng.below(corpus.len())].clone();
        c.notify(
            "textDocument/didOpen",
            json!({ "textDocument": { "uri": doc, "languageId": "sdf", "version": 1, "text": text } }),
        );
        for step in 0..25 {
            // A change at a random line and character, possibly past the end of either.
            let lines = text.matches('\n').count() + 2;
            let pos = |rng: &mut sdfc_compiler::Rng| json!({ "line": rng.below(lines), "character": rng.below(90) });
            let (a, b) = (pos(&mut rng), pos(&mut rng));
            let (start, end) = if (a["line"].as_u64(), a["character"].as_u64())
                <= (b["line"].as_u64(), b["character"].as_u64())
            {
                (a, b)
            } else {
                (b, a)
            };
            let insert = match rng.below(3) {
                0 => String::new(),
                1 => SNIPPETS[rng.below(SNIPPETS.len())].to_string(),
                _ => {
                    let other: Vec<char> = corpus[rng.below(corpus.len())].chars().collect();
                    let from = rng.below(other.len());
                    other[from..(from + rng.below(60)).min(other.len())]
                        .iter()
                        .collect()
                }
            };
            let change = json!({ "range": { "start": start, "end": end }, "text": insert });
            let mut t = text.clone();
            let ev: lsp_types::TextDocumentContentChangeEvent =
                serde_json::from_value(change.clone()).unwrap();
            sdfc_runtime::lsp::apply(&mut t, ev);
            text = t;
            c.notify(
                "textDocument/didChange",
                json!({ "textDocument": { "uri": doc, "version": 2 + step }, "contentChanges": [change] }),
            );
            let method = methods[rng.below(methods.len())];
            let mut p = json!({ "textDocument": { "uri": doc }, "position": pos(&mut rng) });
            if method == "textDocument/references" {
                p["context"] = json!({ "includeDeclaration": true });
            }
            if method == "textDocument/formatting" {
                p["options"] = json!({ "tabSize": 2, "insertSpaces": true });
            }
            let r = c.respond(method, p);
            assert!(
                r.response_result.is_ok(),
                "round {round} step {step}: {method}: {:?}\n{text}",
                r.response_result
            );
        }
        c.notify(
            "textDocument/didClose",
            json!({ "textDocument": { "uri": doc } }),
        );
    }
    c.stop();
    let _ = std::fs::remove_dir_all(&dir);
}

/// `textDocument/formatting`: one edit that replaces the whole text with `sdfc fmt`'s layout
/// (on the unsaved text), none for formatted text or text that does not parse.
#[test]
fn formatting_replaces_the_text_with_the_formatters() {
    let dir = temp_dir("fmt");
    let path = dir.join("messy.sdf");
    let doc = uri(&path);
    let text = "let r=2*3; // six\nscene { sphere( r ) ; }";
    let mut c = Client::start();
    c.notify(
        "textDocument/didOpen",
        json!({ "textDocument": { "uri": doc, "languageId": "sdf", "version": 1, "text": text } }),
    );
    let opts = json!({ "textDocument": { "uri": doc }, "options": { "tabSize": 4, "insertSpaces": true } });
    let edits = c.request("textDocument/formatting", opts.clone());
    let formatted = "let r = 2 * 3; // six\nscene {\n  sphere(r);\n}\n";
    assert_eq!(
        edits,
        json!([{ "range": { "start": { "line": 0, "character": 0 }, "end": { "line": 1, "character": 23 } }, "newText": formatted }])
    );
    for (version, t) in [(2, formatted), (3, "let r = ;\n")] {
        c.notify(
            "textDocument/didChange",
            json!({ "textDocument": { "uri": doc, "version": version }, "contentChanges": [{ "text": t }] }),
        );
        assert_eq!(
            c.request("textDocument/formatting", opts.clone()),
            json!([]),
            "{t}"
        );
    }
    c.stop();
    let _ = std::fs::remove_dir_all(&dir);
}

/// The time each request takes on every example, printed (run with `--nocapture`; nothing
/// is asserted about the times): the check of the whole document after a change, then a
/// hover, a completion, a definition, the outline and the formatting at the middle of the
/// scene.
#[test]
fn request_latency_on_every_example() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&root)
        .expect("examples")
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "sdf"))
        .collect();
    files.sort();
    let mut c = Client::start();
    println!(
        "example            check+publish  hover  completion  definition  symbols  format (ms)"
    );
    for path in files {
        let text = std::fs::read_to_string(&path).expect("read");
        let doc = uri(&path);
        let t0 = std::time::Instant::now();
        c.notify(
            "textDocument/didOpen",
            json!({ "textDocument": { "uri": doc, "languageId": "sdf", "version": 1, "text": text } }),
        );
        c.diagnostics(&doc);
        // Less the debounce, which the client waits on purpose.
        let publish = t0.elapsed().saturating_sub(sdfc_runtime::lsp::DEBOUNCE);
        let mut needle = text.find("scene").map_or(0, |i| i + 12).min(text.len());
        while !text.is_char_boundary(needle) {
            needle -= 1;
        }
        let mut times = vec![publish];
        for method in [
            "textDocument/hover",
            "textDocument/completion",
            "textDocument/definition",
            "textDocument/documentSymbol",
            "textDocument/formatting",
        ] {
            // Each request after a change, so that the document is checked again.
            c.notify(
                "textDocument/didChange",
                json!({ "textDocument": { "uri": doc, "version": 2 }, "contentChanges": [{ "text": text }] }),
            );
            let mut p = position(&doc, &text, needle);
            if method == "textDocument/formatting" {
                p["options"] = json!({ "tabSize": 2, "insertSpaces": true });
            }
            let t = std::time::Instant::now();
            let r = c.respond(method, p);
            assert!(r.response_result.is_ok());
            times.push(t.elapsed());
        }
        let ms: Vec<String> = times
            .iter()
            .map(|d| format!("{:.1}", d.as_secs_f64() * 1e3))
            .collect();
        println!(
            "{:<18} {:>13}  {:>5}  {:>10}  {:>10}  {:>7}  {:>6}",
            path.file_name().unwrap().to_string_lossy(),
            ms[0],
            ms[1],
            ms[2],
            ms[3],
            ms[4],
            ms[5]
        );
        c.notify(
            "textDocument/didClose",
            json!({ "textDocument": { "uri": doc } }),
        );
    }
    c.stop();
}

/// The path of `name` found on `PATH`.
fn on_path(name: &str) -> Option<PathBuf> {
    std::env::split_paths(&std::env::var_os("PATH")?)
        .map(|d| d.join(name))
        .find(|p| p.is_file())
}

/// Neovim's own LSP client (`nvim --headless` running `in/lsp/neovim.lua`) drives the server
/// process: the diagnostic of a misspelt built-in at its range, its quick fix applied by
/// Neovim and the diagnostic gone, a hover on the shape showing its L, and the definition of
/// a function of the imported file opened at its name.
#[test]
fn neovim_gets_diagnostics_applies_a_fix_hovers_and_goes_to_a_definition() {
    let Some(nvim) = on_path("nvim") else {
        assert!(
            std::env::var("SDFC_REQUIRE_DEVICES").as_deref() != Ok("1"),
            "SDFC_REQUIRE_DEVICES=1 but nvim is not installed (apt-get install neovim)"
        );
        eprintln!("neovim test SKIPPED: nvim is not on PATH (apt-get install neovim)");
        return;
    };
    let dir = temp_dir("neovim");
    std::fs::write(
        dir.join("lib.sdf"),
        "// a library\nfn post(h: float = 1) -> shape {\n  box((0.1, h, 0.1))\n}\n",
    )
    .expect("write");
    std::fs::write(
        dir.join("main.sdf"),
        "import \"lib.sdf\";\nscene {\n  sphre(1);\n  post(2).translate(1, 0, 0);\n}\n",
    )
    .expect("write");
    let out = dir.join("seen.json");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/in/lsp/neovim.lua");
    let mut child = std::process::Command::new(nvim)
        .args(["--headless", "--clean", "-c"])
        .arg(format!("luafile {}", script.display()))
        .env("SDFC_BIN", env!("CARGO_BIN_EXE_sdfc"))
        .env("SDFC_DIR", &dir)
        .env("SDFC_OUT", &out)
        .current_dir(&dir)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("start nvim");
    // The script waits at most 20 s a step and always quits; a Neovim that does not is
    // stopped rather than left to hang the suite.
    let started = std::time::Instant::now();
    while child.try_wait().expect("wait").is_none() {
        if started.elapsed() > Duration::from_secs(180) {
            let _ = child.kill();
            panic!("nvim did not quit");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let output = child.wait_with_output().expect("nvim");
    let seen: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap_or_default())
        .unwrap_or_else(|e| {
            panic!(
                "nvim wrote no result ({e}): {}",
                String::from_utf8_lossy(&output.stderr)
            )
        });
    assert_eq!(seen["ok"], json!(true), "{seen:#}");
    let d = &seen["diagnostic"];
    assert_eq!(
        (&d["lnum"], &d["col"], &d["end_lnum"], &d["end_col"]),
        (&json!(2), &json!(2), &json!(2), &json!(7)),
        "{seen:#}"
    );
    assert!(
        d["message"].as_str().unwrap_or("").contains("sphre"),
        "{seen:#}"
    );
    assert!(
        seen["fix"].as_str().unwrap_or("").contains("sphere"),
        "{seen:#}"
    );
    assert_eq!(seen["fixed_line"], json!("  sphere(1);"), "{seen:#}");
    let hover = seen["hover"].as_str().unwrap_or("");
    assert!(
        hover.contains("exact") && hover.contains("L = 1"),
        "{seen:#}"
    );
    assert_eq!(
        seen["definition"],
        json!({ "file": "lib.sdf", "row": 2, "col": 3 }),
        "{seen:#}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `body` framed as the protocol says.
fn framed(body: &[u8]) -> Vec<u8> {
    let mut out = format!("Content-Length: {}\r\n\r\n", body.len()).into_bytes();
    out.extend_from_slice(body);
    out
}

fn framed_json(v: Value) -> Vec<u8> {
    framed(v.to_string().as_bytes())
}

/// Runs `sdfc lsp` on `input` (written whole, then the input closed) and returns the
/// messages it wrote and its exit status.
fn run_lsp(input: Vec<u8>) -> (Vec<Value>, Option<i32>) {
    let (messages, status, _) = run_lsp_raw(input);
    (messages, status)
}

/// [`run_lsp`], and the bytes it wrote.
fn run_lsp_raw(input: Vec<u8>) -> (Vec<Value>, Option<i32>, Vec<u8>) {
    use std::io::{Read, Write};
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .arg("lsp")
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("start sdfc lsp");
    let mut stdin = child.stdin.take().expect("stdin");
    let writer = std::thread::spawn(move || {
        // The server may exit before reading everything (after `exit`).
        let _ = stdin.write_all(&input);
    });
    let mut out = Vec::new();
    child
        .stdout
        .take()
        .expect("stdout")
        .read_to_end(&mut out)
        .expect("read");
    let started = std::time::Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().expect("wait") {
            break s;
        }
        if started.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("sdfc lsp did not exit");
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    writer.join().expect("writer");
    let mut messages = Vec::new();
    let mut rest = out.as_slice();
    while !rest.is_empty() {
        let end = rest
            .windows(4)
            .position(|w| w == b"\r\n\r\n")
            .expect("a header");
        let header = std::str::from_utf8(&rest[..end]).expect("ASCII header");
        let length: usize = header
            .strip_prefix("Content-Length: ")
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("header {header:?}"));
        let body = &rest[end + 4..end + 4 + length];
        messages.push(serde_json::from_slice(body).expect("JSON"));
        rest = &rest[end + 4 + length..];
    }
    (messages, status.code(), out)
}

fn initialize() -> Vec<u8> {
    framed_json(
        json!({ "jsonrpc": "2.0", "id": 1, "method": "initialize", "params": { "capabilities": {} } }),
    )
}

/// Each malformed message, between `initialize` and a valid request, is answered with the
/// JSON-RPC error the protocol gives it (a parse error for bytes that are not a JSON message,
/// an invalid request for JSON that is not one), and the valid request after it is answered.
#[test]
fn malformed_messages_are_answered_with_errors_and_the_server_reads_on() {
    const PARSE: i64 = -32700;
    const INVALID: i64 = -32600;
    let cases: Vec<(&str, Vec<u8>, &[i64])> = vec![
        (
            "a huge Content-Length",
            b"Content-Length: 1000000000000\r\n\r\n".to_vec(),
            &[PARSE],
        ),
        (
            "a Content-Length of 4 GB",
            b"Content-Length: 4000000000\r\n\r\n{}".to_vec(),
            &[PARSE],
        ),
        ("not JSON", framed(b"not json"), &[PARSE]),
        ("truncated JSON", framed(b"{\"id\": 2, \"meth"), &[PARSE]),
        (
            "a batch",
            framed(b"[{\"jsonrpc\":\"2.0\",\"id\":3,\"method\":\"shutdown\"}]"),
            &[INVALID],
        ),
        ("not UTF-8", framed(b"{\"a\":\"\xff\xfe\"}"), &[PARSE]),
        (
            "a short Content-Length",
            b"Content-Length: 3\r\n\r\n{\"jsonrpc\":\"2.0\"}".to_vec(),
            &[PARSE, PARSE],
        ),
        (
            "a long Content-Length",
            b"Content-Length: 500\r\n\r\n{\"jsonrpc\":\"2.0\"}".to_vec(),
            &[PARSE],
        ),
        (
            "a negative Content-Length",
            b"Content-Length: -5\r\n\r\n{}".to_vec(),
            &[PARSE],
        ),
        (
            "a zero Content-Length",
            b"Content-Length: 0\r\n\r\n".to_vec(),
            &[PARSE],
        ),
        (
            "no Content-Length",
            b"Content-Type: application/json\r\n\r\n{}".to_vec(),
            &[PARSE],
        ),
        (
            "a Content-Length that is not a number",
            b"Content-Length: twelve\r\n\r\n{}".to_vec(),
            &[PARSE],
        ),
        ("a message that is a number", framed(b"42"), &[INVALID]),
        (
            "a request whose method is not a string",
            framed(b"{\"jsonrpc\":\"2.0\",\"id\":5,\"method\":7}"),
            &[INVALID],
        ),
    ];
    let symbols = json!({ "jsonrpc": "2.0", "id": 99, "method": "textDocument/documentSymbol",
        "params": { "textDocument": { "uri": "file:///nowhere/a.sdf" } } });
    for (what, bad, codes) in cases {
        let mut input = initialize();
        input.extend(bad);
        input.extend(framed_json(symbols.clone()));
        let (messages, _) = run_lsp(input);
        assert_eq!(messages[0]["id"], json!(1), "{what}: {messages:?}");
        let errors: Vec<i64> = messages[1..messages.len() - 1]
            .iter()
            .map(|m| m["error"]["code"].as_i64().unwrap_or(0))
            .collect();
        assert_eq!(errors, codes, "{what}: {messages:#?}");
        // The valid request after it is answered (the document is not open: an error naming
        // that, from the request's own handler).
        let last = messages.last().expect("an answer");
        assert_eq!(last["id"], json!(99), "{what}: {messages:#?}");
        assert_eq!(
            last["error"]["message"],
            json!("the document is not open"),
            "{what}: {last}"
        );
    }
}

/// Framing with bare line feeds (no carriage returns) and a header of any case is read.
#[test]
fn framing_with_line_feeds_alone_is_read() {
    let body = json!({ "jsonrpc": "2.0", "id": 1, "method": "initialize", "params": { "capabilities": {} } })
        .to_string();
    let mut input = format!("content-length: {}\n\n{body}", body.len()).into_bytes();
    input.extend(framed_json(
        json!({ "jsonrpc": "2.0", "id": 2, "method": "shutdown" }),
    ));
    input.extend(framed_json(json!({ "jsonrpc": "2.0", "method": "exit" })));
    let (messages, status) = run_lsp(input);
    assert_eq!(messages.len(), 2, "{messages:#?}");
    assert!(messages[0]["result"]["capabilities"].is_object());
    assert_eq!(messages[1]["id"], json!(2));
    assert_eq!(status, Some(0));
}

/// Ids the protocol does not allow (a fraction, an integer beyond 32 bits, an object) are
/// refused with an error to that id, not ignored; a request after `shutdown` is refused;
/// `exit` after `shutdown` exits 0 and without it 1, as the protocol says.
#[test]
fn odd_ids_and_requests_after_shutdown_are_refused_and_exit_says_how_it_ended() {
    let hover = |id: &str| {
        framed(
            format!(
                "{{\"jsonrpc\":\"2.0\",\"id\":{id},\"method\":\"textDocument/hover\",\"params\":{{}}}}"
            )
            .as_bytes(),
        )
    };
    let mut input = initialize();
    input.extend(hover("1.5"));
    input.extend(hover("1180591620717411303424"));
    input.extend(hover("{\"a\":1}"));
    input.extend(framed_json(
        json!({ "jsonrpc": "2.0", "id": 2, "method": "shutdown" }),
    ));
    input.extend(hover("3"));
    input.extend(framed_json(json!({ "jsonrpc": "2.0", "method": "exit" })));
    let (messages, status, raw) = run_lsp_raw(input);
    assert_eq!(messages.len(), 6, "{messages:#?}");
    assert_eq!(messages[1]["id"], json!(1.5), "{:#}", messages[1]);
    assert_eq!(messages[1]["error"]["code"], json!(-32600));
    assert!(
        String::from_utf8_lossy(&raw).contains("\"id\":1180591620717411303424"),
        "the id as it was written"
    );
    assert!(messages[2]["id"].is_number(), "{:#}", messages[2]);
    assert_eq!(messages[2]["error"]["code"], json!(-32600));
    assert_eq!(messages[3]["id"], json!({ "a": 1 }));
    assert_eq!(messages[3]["error"]["code"], json!(-32600));
    assert_eq!(messages[4]["id"], json!(2));
    assert_eq!(messages[4]["result"], Value::Null);
    assert_eq!(messages[5]["id"], json!(3));
    assert_eq!(
        messages[5]["error"]["code"],
        json!(-32600),
        "{:#}",
        messages[5]
    );
    assert_eq!(status, Some(0));

    let mut input = initialize();
    input.extend(framed_json(json!({ "jsonrpc": "2.0", "method": "exit" })));
    let (_, status) = run_lsp(input);
    assert_eq!(status, Some(1), "exit without shutdown");
    let (messages, status) = run_lsp(initialize());
    assert_eq!(messages.len(), 1);
    assert_eq!(status, Some(1), "the input closed without shutdown");
}

/// Rename refuses a new name that is a keyword or would hide a built-in (the file's uses of
/// it would then mean the renamed declaration), and one that is not a name at all.
#[test]
fn rename_refuses_keywords_and_built_in_names() {
    let dir = temp_dir("rename");
    let main = dir.join("main.sdf");
    let main_uri = uri(&main);
    let text = "let r = 1;\nscene {\n    sphere(r * pi);\n}\n";
    let mut c = Client::start();
    c.notify(
        "textDocument/didOpen",
        json!({ "textDocument": { "uri": main_uri, "languageId": "sdf", "version": 1, "text": text } }),
    );
    for (new, why) in [
        ("let", "keyword"),
        ("scene", "keyword"),
        ("true", "keyword"),
        ("sphere", "built-in function"),
        ("pi", "built-in constant"),
        ("t", "time"),
        ("2r", "not a name"),
        ("a b", "not a name"),
        ("", "not a name"),
    ] {
        let mut rename = at(&main_uri, text, "r = 1", 0);
        rename["newName"] = json!(new);
        let r = c.respond("textDocument/rename", rename);
        let e = r
            .response_result
            .err()
            .unwrap_or_else(|| panic!("`{new}` accepted"));
        assert_eq!(e.code, -32602, "{new}: {}", e.message);
        assert!(e.message.contains(why), "{new}: {}", e.message);
    }
    let mut rename = at(&main_uri, text, "r = 1", 0);
    rename["newName"] = json!("radius");
    let edit = c.request("textDocument/rename", rename);
    assert_eq!(
        edit["changes"][&main_uri].as_array().map(Vec::len),
        Some(2),
        "{edit}"
    );
    c.stop();
    let _ = std::fs::remove_dir_all(&dir);
}

/// `serve_bytes` (the fuzz target's entry) serves a whole stream in one thread: diagnostics
/// are published before the next message, requests answered, and `exit` after `shutdown` is
/// a clean end.
#[test]
fn serve_bytes_serves_a_stream_in_one_thread() {
    let mut input = initialize();
    input.extend(framed_json(
        json!({ "jsonrpc": "2.0", "method": "initialized", "params": {} }),
    ));
    input.extend(framed_json(
        json!({ "jsonrpc": "2.0", "method": "textDocument/didOpen",
        "params": { "textDocument": { "uri": "file:///nowhere/a.sdf", "languageId": "sdf",
        "version": 1, "text": "scene {\n  sphre(1);\n}\n" } } }),
    ));
    input.extend(b"Content-Length: 3\r\n\r\n[1]");
    input.extend(framed_json(
        json!({ "jsonrpc": "2.0", "id": 2, "method": "textDocument/documentSymbol",
        "params": { "textDocument": { "uri": "file:///nowhere/a.sdf" } } }),
    ));
    input.extend(framed_json(
        json!({ "jsonrpc": "2.0", "id": 3, "method": "shutdown" }),
    ));
    input.extend(framed_json(json!({ "jsonrpc": "2.0", "method": "exit" })));
    let mut output = Vec::new();
    let exit =
        sdfc_runtime::lsp::serve_bytes(&input, &mut output, Default::default()).expect("written");
    assert_eq!(exit, Exit::Clean);
    let text = String::from_utf8(output).expect("UTF-8");
    let diagnostics = text.find("publishDiagnostics").expect("diagnostics");
    assert!(text[diagnostics..].contains("sphre"), "{text}");
    let batch = text.find("batches").expect("the batch refused");
    let symbols = text.find("\"id\":2").expect("the symbols");
    assert!(diagnostics < batch && batch < symbols, "{text}");
    assert!(
        text.contains("{\"jsonrpc\":\"2.0\",\"id\":3,\"result\":null}"),
        "{text}"
    );
}

/// A byte-order mark at the start of a document is skipped: no diagnostic about it, and the
/// positions of the first line count it as the client does (one UTF-16 unit).
#[test]
fn a_byte_order_mark_is_skipped_by_the_language_server() {
    let dir = temp_dir("bom");
    let main_uri = uri(&dir.join("main.sdf"));
    let text = "\u{feff}let r = 1;\nscene {\n    sphere(r);\n}\n";
    let mut c = Client::start();
    c.notify(
        "textDocument/didOpen",
        json!({ "textDocument": { "uri": main_uri, "languageId": "sdf", "version": 1, "text": text } }),
    );
    let diags = c.diagnostics(&main_uri);
    assert!(
        diags
            .as_array()
            .expect("a list")
            .iter()
            .all(|d| d["severity"] != json!(1)),
        "{diags:#}"
    );
    let def = c.request("textDocument/definition", at(&main_uri, text, "r);", 0));
    assert_eq!(
        def["range"]["start"],
        json!({ "line": 0, "character": 5 }),
        "{def}"
    );
    c.stop();
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_parameters_hover_shows_its_range_description_and_value() {
    let dir = temp_dir("param-hover");
    let main = dir.join("part.sdf");
    let main_uri = uri(&main);
    let text = "param width = 40.0 in 10..100 step 1 \"Box width (mm)\";\n\
                light directional { direction: (-1, -1, 1) }\n\
                scene { box((width / 100, 0.5, 0.5)); }\n";
    let mut c = Client::start();
    c.notify(
        "textDocument/didOpen",
        json!({ "textDocument": { "uri": main_uri, "languageId": "sdf", "version": 1, "text": text } }),
    );
    let h = c.request("textDocument/hover", at(&main_uri, text, "width /", 0));
    let md = h["contents"]["value"].as_str().unwrap();
    assert!(
        md.contains("param width = 40.0 in 10..100 step 1 \"Box width (mm)\";")
            && md.contains("= `40` (float)"),
        "{md}"
    );
}
