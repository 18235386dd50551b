//! A real editor's client, Neovim's (`in/lsp/neovim.lua`), talking to the `sdfc lsp` process.

use crate::temp_dir;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::time::Duration;

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
