//! The `sdfc lsp` process on the wire: framing, malformed messages answered with errors, odd
//! ids, requests after shutdown, how `exit` ends it, and a stream served on one thread.

use sdfc_runtime::lsp::Exit;
use serde_json::{json, Value};
use std::time::Duration;

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
