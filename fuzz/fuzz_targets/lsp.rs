//! Fuzz target: streams of messages through the whole language server in-process (framing,
//! classification, the life cycle, every request): nothing may panic, hang or end the
//! server early, and no answer may be an internal error (a panic the server caught).
//!
//! The input is split at NUL bytes. The first part is a document's text: the stream opens it
//! and asks every request of the server about it (so that the other targets' seeds, scene
//! texts, are seeds here too). Each further part that is JSON is sent framed as the protocol
//! says (so that mutations of a message keep its framing); any other part is sent as raw
//! bytes (so that the framing itself is fuzzed). The stream ends with `shutdown` and `exit`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use serde_json::{json, Value};

const URI: &str = "file:///fuzz/main.sdf";

fn framed(out: &mut Vec<u8>, body: &[u8]) {
    out.extend_from_slice(format!("Content-Length: {}\r\n\r\n", body.len()).as_bytes());
    out.extend_from_slice(body);
}

fn message(out: &mut Vec<u8>, id: Option<i64>, method: &str, params: Value) {
    let mut m = json!({ "jsonrpc": "2.0", "method": method, "params": params });
    if let Some(id) = id {
        m["id"] = json!(id);
    }
    framed(out, m.to_string().as_bytes());
}

fuzz_target!(|data: &[u8]| {
    let mut parts = data.split(|&b| b == 0);
    let text = String::from_utf8_lossy(parts.next().unwrap_or_default()).into_owned();
    let mut input = Vec::new();
    message(
        &mut input,
        Some(1),
        "initialize",
        json!({ "capabilities": {} }),
    );
    message(&mut input, None, "initialized", json!({}));
    message(
        &mut input,
        None,
        "textDocument/didOpen",
        json!({ "textDocument": { "uri": URI, "languageId": "sdf", "version": 1, "text": text } }),
    );
    // A position inside the text (its middle line), and the end.
    let lines = text.lines().count() as u32;
    let middle = json!({ "line": lines / 2, "character": 4 });
    let end = json!({ "line": lines, "character": 0 });
    let doc = json!({ "uri": URI });
    let at = |pos: &Value| json!({ "textDocument": doc, "position": pos });
    let range = json!({ "start": { "line": 0, "character": 0 }, "end": end });
    let mut id = 1;
    let mut ask = |input: &mut Vec<u8>, method: &str, params: Value| {
        id += 1;
        message(input, Some(id), method, params);
    };
    for pos in [&middle, &end] {
        ask(&mut input, "textDocument/hover", at(pos));
        ask(&mut input, "textDocument/completion", at(pos));
        ask(&mut input, "textDocument/signatureHelp", at(pos));
        ask(&mut input, "textDocument/definition", at(pos));
        let mut refs = at(pos);
        refs["context"] = json!({ "includeDeclaration": true });
        ask(&mut input, "textDocument/references", refs);
        let mut rename = at(pos);
        rename["newName"] = json!("renamed");
        ask(&mut input, "textDocument/rename", rename);
    }
    ask(
        &mut input,
        "textDocument/documentSymbol",
        json!({ "textDocument": doc }),
    );
    ask(
        &mut input,
        "textDocument/formatting",
        json!({ "textDocument": doc, "options": { "tabSize": 4, "insertSpaces": true } }),
    );
    ask(
        &mut input,
        "textDocument/codeAction",
        json!({ "textDocument": doc, "range": range, "context": { "diagnostics": [] } }),
    );
    for part in parts {
        if serde_json::from_slice::<Value>(part).is_ok() {
            framed(&mut input, part);
        } else {
            input.extend_from_slice(part);
        }
    }
    ask(&mut input, "shutdown", Value::Null);
    message(&mut input, None, "exit", Value::Null);

    let mut output = Vec::new();
    // A million evaluation steps, not the default 50 million: see the front_end target.
    let mut limits = sdfc_compiler::Limits::default();
    limits
        .set(sdfc_compiler::Limit::Fuel, 1_000_000)
        .expect("a valid limit");
    // Serving into memory cannot fail to write.
    let _ = sdfc_lsp::serve_bytes(&input, &mut output, limits);
    assert!(
        !output.windows(14).any(|w| w == b"\"code\":-32603,"),
        "an internal error (a panic caught while answering): {}",
        String::from_utf8_lossy(&output)
    );
});
