//! The editor grammar and the reference in `docs/` stay in step with the compiler: every
//! built-in, record field, string escape, primitive row, diagnostic code (with an example
//! that produces it) and limit (with its default) is named where users read it.

use crate::common;
use crate::scan::root;

use sdfc_compiler::builtins::{self, BUILTINS};
use std::collections::BTreeSet;

fn read(rel: &str) -> String {
    let path = root().join(rel);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
}

#[test]
fn the_editor_grammar_knows_every_builtin() {
    let tm = read("grammar/sdf.tmLanguage.json");
    assert!(
        tm.contains("\"scopeName\": \"source.sdf\""),
        "the scope name is source.sdf"
    );
    for b in BUILTINS.iter() {
        let listed = [
            format!("|{}|", b.name),
            format!("({}|", b.name),
            format!("|{})", b.name),
        ];
        assert!(
            listed.iter().any(|l| tm.contains(l.as_str())),
            "sdf.tmLanguage.json does not highlight the builtin `{}`",
            b.name
        );
    }
}

/// The escapes docs/language.md's row for strings and grammar/sdf.ebnf's STRING list are the
/// lexer's, and each one lexes to its character (issue 37: the docs named two of four).
#[test]
fn the_string_escapes_in_the_docs_are_the_lexers() {
    use sdfc_compiler::lexer::{lex, Token, ESCAPES};
    let escapes: Vec<String> = ESCAPES.iter().map(|(k, _)| format!("\\{k}")).collect();
    let doc = read("docs/language.md");
    let row = doc
        .lines()
        .find(|l| l.starts_with("| String |"))
        .expect("docs/language.md has a row for strings");
    let listed: Vec<&str> = row
        .split('`')
        .skip(1)
        .step_by(2)
        .filter(|t| t.starts_with('\\'))
        .collect();
    assert_eq!(listed, escapes, "docs/language.md: {row}");
    let ebnf = read("grammar/sdf.ebnf");
    let rule: String = ebnf
        .lines()
        .skip_while(|l| !l.trim_start().starts_with("STRING"))
        .take_while(|l| !l.trim_start().starts_with("punct"))
        .collect();
    for e in &escapes {
        assert!(
            rule.contains(&format!("\"{e}\"")) || (e == "\\\"" && rule.contains("\"\\\" '\"'")),
            "grammar/sdf.ebnf's STRING lacks {e}: {rule}"
        );
    }
    for (k, v) in ESCAPES {
        let text = format!("\"a\\{k}b\"");
        let (tokens, diags) = lex(sdfc_compiler::FileId(0), &text);
        assert!(diags.is_empty(), "{text}: {diags:?}");
        assert_eq!(tokens[0].0, Token::Str(format!("a{v}b")), "{text}");
    }
}

/// The language reference's row of each primitive of the table (`compiler/src/prim/`) is the
/// one the table gives: signature, accepted values, and what it is (with "Exact." where its
/// distance is exact).
#[test]
fn the_language_reference_rows_of_the_primitives_are_the_tables() {
    let doc = read("docs/language.md");
    let mut wrong = Vec::new();
    for prim in sdfc_compiler::prim::all() {
        let b = builtins::builtin(prim.name).expect("every primitive is a builtin");
        let sig = b
            .sigs
            .iter()
            .find(|s| matches!(s.imp, builtins::Imp::Prim(p) if std::ptr::eq(p, prim)))
            .expect("every primitive is an overload of its name");
        let exact = match prim.field {
            sdfc_compiler::prim::Field::Exact => " Exact.",
            sdfc_compiler::prim::Field::Unproven => "",
        };
        let row = format!(
            "| `{}` | {} | {}{exact} |",
            builtins::signature(prim.name, sig),
            prim.accepts,
            prim.doc
        );
        if !doc.lines().any(|l| l == row) {
            wrong.push(row);
        }
    }
    assert!(
        wrong.is_empty(),
        "docs/language.md lacks these rows of the primitives' table (write them as shown):\n{}",
        wrong.join("\n")
    );
}

#[test]
fn the_language_reference_lists_every_signature_and_field() {
    let doc = read("docs/language.md");
    for b in BUILTINS.iter() {
        for sig in b.sigs {
            let text = format!("`{}`", builtins::signature(b.name, sig));
            assert!(doc.contains(&text), "docs/language.md does not list {text}");
        }
    }
    let records = builtins::MATERIALS
        .iter()
        .chain(builtins::LIGHTS)
        .chain([&builtins::CAMERA, &builtins::RENDER]);
    for rec in records {
        assert!(
            doc.contains(&format!("`{}`", rec.name)),
            "docs/language.md does not mention `{}`",
            rec.name
        );
        for f in rec.fields {
            assert!(
                doc.contains(&format!("| `{}` |", f.name)),
                "docs/language.md has no row for the field `{}` of `{}`",
                f.name,
                rec.name
            );
        }
    }
}

#[test]
fn every_diagnostic_code_is_documented_with_an_example() {
    let doc = read("docs/diagnostics.md");
    let mut codes = BTreeSet::new();
    common::codes_in(&root().join("compiler/src"), &mut codes);
    assert!(codes.len() > 10, "no diagnostic codes found");
    for code in codes {
        let row = doc.lines().find(|l| l.starts_with(&format!("| {code} |")));
        let row = row.unwrap_or_else(|| panic!("docs/diagnostics.md has no row for {code}"));
        assert!(
            example_produces(row, &code),
            "the examples column of the row of {code} has no example that produces {code}: {row}"
        );
    }
    // Every example file the table names exists.
    for part in doc.split("](../").skip(1) {
        let rel = part.split(')').next().expect("a link");
        assert!(
            root().join(rel).exists(),
            "docs/diagnostics.md links to {rel}, which does not exist"
        );
    }
}

/// Whether the last column of a table row of docs/diagnostics.md holds an example that
/// produces `code`: a linked `.sdf` file (checked from the file system, so imports work), or
/// an inline snippet, checked as written or as a scene statement (`scene { SNIPPET; }`).
fn example_produces(row: &str, code: &str) -> bool {
    let cells: Vec<&str> = row.trim().trim_matches('|').split(" | ").collect();
    let Some(examples) = cells.last() else {
        return false;
    };
    let produces = |diags: &[sdfc_compiler::Diagnostic]| diags.iter().any(|d| d.code == code);
    for part in examples.split("](../").skip(1) {
        let rel = part.split(')').next().unwrap_or("");
        if rel.ends_with(".sdf") {
            if let Ok(loaded) = common::load(&root().join(rel)) {
                if produces(&loaded.diagnostics) {
                    return true;
                }
            }
        }
    }
    let parts: Vec<&str> = examples.split('`').collect();
    for snippet in parts.iter().skip(1).step_by(2) {
        let snippet = snippet.replace("\\|", "|");
        for text in [snippet.clone(), format!("scene {{ {snippet}; }}")] {
            let (_, diags, _) = sdfc_compiler::check_str("example.sdf", &text);
            if produces(&diags) {
                return true;
            }
        }
    }
    false
}

#[test]
fn the_failure_paths_list_every_limit_with_its_default() {
    let doc = read("docs/failures.md");
    for limit in sdfc_compiler::Limit::ALL {
        let row = doc
            .lines()
            .find(|l| l.starts_with(&format!("| `{}` |", limit.name())))
            .unwrap_or_else(|| panic!("docs/failures.md has no row for the limit {limit}"));
        assert!(
            row.contains(&format!("| {} |", limit.default_value())),
            "docs/failures.md gives the limit {limit} another default than {}",
            limit.default_value()
        );
    }
}
