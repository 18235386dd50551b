//! Reading scenes from disk: the file-system import loader, and the shared "load, check and
//! report" step of every subcommand.

use sdfc_compiler::check::{self, Loader};
use sdfc_compiler::diagnostics::{self, Diagnostic};
use sdfc_compiler::scene::Scene;
use sdfc_compiler::SourceMap;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

/// How diagnostics are printed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Default)]
pub enum DiagnosticFormat {
    /// Human-readable reports with source excerpts.
    #[default]
    Human,
    /// One JSON object per line, for editors.
    Json,
}

/// Loads imports relative to the importing file.
#[derive(Debug, Default)]
pub struct FsLoader;

impl Loader for FsLoader {
    fn load(&mut self, from: &str, path: &str) -> Result<(String, String), String> {
        let base = Path::new(from).parent().unwrap_or(Path::new("."));
        let full: PathBuf = base.join(path);
        let name = normalise(&full);
        let bytes =
            std::fs::read(&full).map_err(|e| format!("cannot read `{}`: {e}", full.display()))?;
        let text = String::from_utf8(bytes)
            .map_err(|_| format!("`{}` is not valid UTF-8", full.display()))?;
        Ok((name, text))
    }
}

/// A path written with `.` and `..` components folded, so that one file imported by two
/// routes has one name (which is how import cycles are found).
fn normalise(p: &Path) -> String {
    let mut parts: Vec<std::path::Component> = Vec::new();
    for c in p.components() {
        match c {
            std::path::Component::CurDir => {}
            std::path::Component::ParentDir
                if matches!(parts.last(), Some(std::path::Component::Normal(_))) =>
            {
                parts.pop();
            }
            other => parts.push(other),
        }
    }
    parts.iter().collect::<PathBuf>().display().to_string()
}

/// The result of loading and checking one scene file.
#[derive(Debug)]
pub struct Loaded {
    /// The checked scene, when there were no errors.
    pub scene: Option<Scene>,
    /// Everything the compiler said.
    pub diagnostics: Vec<Diagnostic>,
    /// The files read, for rendering diagnostics.
    pub sources: SourceMap,
}

/// Reads `path` and checks it. `Err` is an IO or encoding problem with the entry file itself,
/// already phrased for the user.
pub fn load(path: &Path) -> Result<Loaded, String> {
    let bytes =
        std::fs::read(path).map_err(|e| format!("cannot read `{}`: {e}", path.display()))?;
    let text = String::from_utf8(bytes).map_err(|e| {
        format!(
            "`{}` is not valid UTF-8 (first bad byte at offset {})",
            path.display(),
            e.utf8_error().valid_up_to()
        )
    })?;
    let mut sources = SourceMap::new();
    let entry = sources.add(normalise(path), text);
    let (scene, diagnostics) = check::check(&mut sources, entry, &mut FsLoader);
    Ok(Loaded {
        scene,
        diagnostics,
        sources,
    })
}

/// Prints diagnostics to stderr in the chosen format.
pub fn report(loaded: &Loaded, format: DiagnosticFormat) {
    if loaded.diagnostics.is_empty() {
        return;
    }
    let text = match format {
        DiagnosticFormat::Human => diagnostics::render(
            &loaded.diagnostics,
            &loaded.sources,
            std::io::stderr().is_terminal(),
        ),
        DiagnosticFormat::Json => diagnostics::to_json(&loaded.diagnostics, &loaded.sources),
    };
    eprint!("{text}");
}

/// Loads, checks and reports; returns the scene, or the exit code to stop with (1 for errors
/// in the scene, 2 for IO problems).
pub fn load_scene(path: &Path, format: DiagnosticFormat) -> Result<Scene, std::process::ExitCode> {
    let loaded = match load(path) {
        Ok(l) => l,
        Err(msg) => {
            eprintln!("error: {msg}");
            return Err(std::process::ExitCode::from(2));
        }
    };
    report(&loaded, format);
    loaded.scene.ok_or(std::process::ExitCode::from(1))
}
