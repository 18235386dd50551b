//! A server that keeps answering while the text is mutated at random through incremental
//! changes, and the latency of requests on every example.

use crate::{position, temp_dir, uri, Client};
use serde_json::json;
use std::path::{Path, PathBuf};

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
        c.open(&doc, &text);
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
    c.finish(&dir);
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
        c.open(&doc, &text);
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
