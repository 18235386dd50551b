//! Each request on a document with an import and a mistake, formatting, rename, hover on a
//! parameter, and a byte-order mark, over the in-memory connection.

use crate::{at, opened, temp_dir, uri, Client, LIB, MAIN};
use serde_json::{json, Value};

#[test]
fn every_request_on_a_document_with_an_import_and_a_mistake() {
    let dir = temp_dir("requests");
    std::fs::write(dir.join("lib.sdf"), LIB).expect("write");
    let main_uri = uri(&dir.join("main.sdf"));
    let lib_uri = uri(&dir.join("lib.sdf"));
    let mut c = Client::start();
    c.open(&main_uri, MAIN);
    let text = the_mistake_and_its_fix(&mut c, &main_uri);
    hovers(&mut c, &main_uri, &text);
    definition_references_and_rename(&mut c, &main_uri, &lib_uri, &text);
    completion(&mut c, &main_uri, &text);
    signature_help(&mut c, &main_uri, &text);
    outline(&mut c, &main_uri);

    // A document that is not open is an error, not a crash.
    let r = c.respond(
        "textDocument/hover",
        at(&uri(&dir.join("other.sdf")), "x", "x", 0),
    );
    assert!(r.response_result.is_err());
    c.finish(&dir);
}

/// The mistake of [`MAIN`], at its place, with its code linked and a quick fix; fixed
/// through an incremental change, the diagnostics go away. The text fixed.
fn the_mistake_and_its_fix(c: &mut Client, main_uri: &str) -> String {
    let diags = c.diagnostics(main_uri);
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
    let edit = &actions[0]["edit"]["changes"][main_uri][0];
    assert_eq!(edit["newText"], "sphere", "{actions}");
    assert_eq!(edit["range"], d["range"]);

    c.notify(
        "textDocument/didChange",
        json!({ "textDocument": { "uri": main_uri, "version": 2 },
                "contentChanges": [{ "range": d["range"], "text": "sphere" }] }),
    );
    let diags = c.diagnostics(main_uri);
    assert!(
        diags.as_array().unwrap().iter().all(|d| d["severity"] != 1),
        "{diags}"
    );
    MAIN.replace("spher(", "sphere(")
}

/// Hover: a shape's facts, a built-in's signature and doc line, an imported constant.
fn hovers(c: &mut Client, main_uri: &str, text: &str) {
    let md = c.hover(at(main_uri, text, "union", 1));
    assert!(
        md.contains("distance field bound (L = 1)")
            && md.contains("bounding box: (-1, -2, -1) to (1, 2, 1)"),
        "{md}"
    );
    assert!(
        md.contains("union(shapes...: shape) -> shape") || md.contains("union("),
        "{md}"
    );
    let md = c.hover(at(main_uri, text, "ball,", 0));
    assert!(
        md.contains("let ball = sphere(size)") && md.contains("L = 1"),
        "{md}"
    );
    let md = c.hover(at(main_uri, text, "sphere(size", 0));
    assert!(
        md.contains("sphere(radius: float = 1) -> shape") && md.contains("A sphere"),
        "{md}"
    );
    let md = c.hover(at(main_uri, text, "size)", 0));
    assert!(
        md.contains("let size = 0.5 * 2;")
            && md.contains("= `1` (float)")
            && md.contains("lib.sdf"),
        "{md}"
    );
}

/// Definition and references across the import; rename edits both files.
fn definition_references_and_rename(c: &mut Client, main_uri: &str, lib_uri: &str, text: &str) {
    let def = c.request("textDocument/definition", at(main_uri, text, "post(2)", 0));
    assert_eq!(def["uri"], lib_uri, "{def}");
    assert_eq!(
        def["range"]["start"],
        json!({ "line": 3, "character": 3 }),
        "{def}"
    );
    let mut refs = at(main_uri, text, "red;", 0);
    refs["context"] = json!({ "includeDeclaration": true });
    let refs = c.request("textDocument/references", refs);
    assert_eq!(refs.as_array().unwrap().len(), 3, "{refs}");
    let edit = c.rename(at(main_uri, text, "ball,", 0), "orb");
    assert_eq!(
        edit["changes"][main_uri].as_array().unwrap().len(),
        2,
        "{edit}"
    );
    let edit = c.rename(at(main_uri, text, "size)", 0), "side");
    assert_eq!(
        edit["changes"][lib_uri].as_array().unwrap().len(),
        1,
        "{edit}"
    );
    assert_eq!(
        edit["changes"][main_uri].as_array().unwrap().len(),
        1,
        "{edit}"
    );
}

/// Completion: names in scope, built-ins, fields, strings.
fn completion(c: &mut Client, main_uri: &str, text: &str) {
    let items = c.request("textDocument/completion", at(main_uri, text, "union", 0));
    let labels = strings(&items, "label");
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
        at(main_uri, text, "direction:", 0),
    );
    let labels = strings(&items, "label");
    assert!(
        labels.contains(&"direction") && labels.contains(&"color"),
        "{labels:?}"
    );
}

/// Signature help inside a call.
fn signature_help(c: &mut Client, main_uri: &str, text: &str) {
    let s = c.request(
        "textDocument/signatureHelp",
        at(main_uri, text, "post(2)", 5),
    );
    assert_eq!(
        s["signatures"][0]["label"], "fn post(h: float = 1) -> shape",
        "{s}"
    );
    assert_eq!(s["activeParameter"], 0);
    let s = c.request(
        "textDocument/signatureHelp",
        at(main_uri, text, "translate(0, 1", 13),
    );
    assert!(
        s["signatures"][0]["label"]
            .as_str()
            .unwrap()
            .starts_with("translate("),
        "{s}"
    );
    assert_eq!(s["activeParameter"], 1);
}

/// The outline.
fn outline(c: &mut Client, main_uri: &str) {
    let syms = c.request(
        "textDocument/documentSymbol",
        json!({ "textDocument": { "uri": main_uri } }),
    );
    let names = strings(&syms, "name");
    assert_eq!(names, ["light directional", "ball", "scene"], "{syms}");
    assert_eq!(syms[2]["children"].as_array().unwrap().len(), 2);
}

/// The string `key` of each item of the list `items`.
fn strings<'a>(items: &'a Value, key: &str) -> Vec<&'a str> {
    items
        .as_array()
        .unwrap()
        .iter()
        .map(|i| i[key].as_str().unwrap())
        .collect()
}

/// `textDocument/formatting`: one edit that replaces the whole text with `sdfc fmt`'s layout
/// (on the unsaved text), none for formatted text or text that does not parse.
#[test]
fn formatting_replaces_the_text_with_the_formatters() {
    let text = "let r=2*3; // six\nscene { sphere( r ) ; }";
    let (dir, doc, mut c) = opened("fmt", "messy.sdf", text);
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
    c.finish(&dir);
}

/// Rename refuses a new name that is a keyword or would hide a built-in (the file's uses of
/// it would then mean the renamed declaration), and one that is not a name at all.
#[test]
fn rename_refuses_keywords_and_built_in_names() {
    let text = "let r = 1;\nscene {\n    sphere(r * pi);\n}\n";
    let (dir, main_uri, mut c) = opened("rename", "main.sdf", text);
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
    let edit = c.rename(at(&main_uri, text, "r = 1", 0), "radius");
    assert_eq!(
        edit["changes"][&main_uri].as_array().map(Vec::len),
        Some(2),
        "{edit}"
    );
    c.finish(&dir);
}

/// A byte-order mark at the start of a document is skipped: no diagnostic about it, and the
/// positions of the first line count it as the client does (one UTF-16 unit).
#[test]
fn a_byte_order_mark_is_skipped_by_the_language_server() {
    let text = "\u{feff}let r = 1;\nscene {\n    sphere(r);\n}\n";
    let (dir, main_uri, mut c) = opened("bom", "main.sdf", text);
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
    c.finish(&dir);
}

#[test]
fn a_parameters_hover_shows_its_range_description_and_value() {
    let text = "param width = 40.0 in 10..100 step 1 \"Box width (mm)\";\n\
                light directional { direction: (-1, -1, 1) }\n\
                scene { box((width / 100, 0.5, 0.5)); }\n";
    let (_dir, main_uri, mut c) = opened("param-hover", "part.sdf", text);
    let md = c.hover(at(&main_uri, text, "width /", 0));
    assert!(
        md.contains("param width = 40.0 in 10..100 step 1 \"Box width (mm)\";")
            && md.contains("= `40` (float)"),
        "{md}"
    );
}
