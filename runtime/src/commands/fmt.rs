//! `sdfc fmt`: rewrites scene files in the formatter's layout (`syntax::format`), or with
//! `--check` names those that would change.

use crate::frontend::{self, DiagnosticFormat};
use crate::image::AtomicFile;
use sdfc_compiler::{
    format::{format, Error},
    SourceMap,
};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `sdfc fmt`.
#[derive(Debug, clap::Args)]
pub struct FmtArgs {
    /// Scene files, or folders whose `.sdf` files (at any depth) are formatted; none, or `-`:
    /// standard input to standard output.
    pub files: Vec<PathBuf>,
    /// Change nothing: name each file that would change, and exit 1 if any would.
    #[arg(long)]
    pub check: bool,
}

/// What became of one text.
enum Outcome {
    Same,
    Changed(String),
    /// Not formatted (syntax errors, printed): exit 1.
    Refused,
}

/// Formats `text`, printing its syntax errors under `name`.
fn format_text(name: &str, text: &str) -> Outcome {
    match format(text) {
        Ok(out) if out == text => Outcome::Same,
        Ok(out) => Outcome::Changed(out),
        Err(Error::Syntax(diags)) => {
            let mut sources = SourceMap::new();
            // The formatter parses its text as file 0, the first a map adds.
            sources.add(name, text);
            frontend::print_diagnostics(&diags, &sources, DiagnosticFormat::Human);
            eprintln!("{name}: not formatted: it has syntax errors");
            Outcome::Refused
        }
        Err(e @ Error::Internal(_)) => {
            eprintln!("{name}: not formatted: {e}");
            Outcome::Refused
        }
    }
}

/// The `.sdf` files under `dir`, sorted, at any depth (hidden folders and `target` skipped).
fn sdf_files(dir: &Path, out: &mut Vec<PathBuf>) -> std::io::Result<()> {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)?
        .map(|e| e.map(|e| e.path()))
        .collect::<Result<_, _>>()?;
    entries.sort();
    for p in entries {
        let name = p.file_name().map(|n| n.to_string_lossy().into_owned());
        if p.is_dir() {
            if !name.is_some_and(|n| n.starts_with('.') || n == "target") {
                sdf_files(&p, out)?;
            }
        } else if p.extension().is_some_and(|x| x == "sdf") {
            out.push(p);
        }
    }
    Ok(())
}

/// Formats standard input to standard output (with `--check`, writes nothing).
fn stdin(check: bool) -> ExitCode {
    let mut text = String::new();
    if let Err(e) = std::io::stdin().read_to_string(&mut text) {
        eprintln!("error: cannot read standard input: {e}");
        return ExitCode::from(2);
    }
    let out = match format_text("<stdin>", &text) {
        Outcome::Refused => return ExitCode::from(1),
        Outcome::Same => text,
        Outcome::Changed(out) if check => {
            println!("<stdin>");
            drop(out);
            return ExitCode::from(1);
        }
        Outcome::Changed(out) => out,
    };
    if check {
        return ExitCode::SUCCESS;
    }
    let _ = std::io::stdout().lock().write_all(out.as_bytes());
    ExitCode::SUCCESS
}

/// Formats each file in place (written whole or not at all, through [`AtomicFile`]; a
/// symbolic link's target is rewritten); exit 0 when all are formatted (or with `--check`,
/// already were), 1 when a file has syntax errors or would change, 2 when a file cannot be
/// read or written.
pub fn run(args: FmtArgs) -> ExitCode {
    if args.files.is_empty() || args.files == [PathBuf::from("-")] {
        return stdin(args.check);
    }
    let mut files = Vec::new();
    let mut code = 0u8;
    for f in &args.files {
        if f.is_dir() {
            if let Err(e) = sdf_files(f, &mut files) {
                eprintln!("error: cannot list {}: {e}", f.display());
                code = 2;
            }
        } else {
            files.push(f.clone());
        }
    }
    // A file named twice, or named and inside a folder named, is formatted (and its errors
    // reported) once.
    let mut seen = std::collections::HashSet::new();
    files.retain(|f| seen.insert(std::fs::canonicalize(f).unwrap_or_else(|_| f.clone())));
    for file in &files {
        let name = file.display().to_string();
        let text = match std::fs::read_to_string(file) {
            Ok(t) => t,
            Err(e) => {
                eprintln!("error: cannot read {name}: {e}");
                code = 2;
                continue;
            }
        };
        match format_text(&name, &text) {
            Outcome::Same => {}
            Outcome::Refused => code = code.max(1),
            Outcome::Changed(_) if args.check => {
                println!("{name}");
                code = code.max(1);
            }
            Outcome::Changed(out) => {
                let target = std::fs::canonicalize(file).unwrap_or_else(|_| file.clone());
                let written = AtomicFile::unsynced(&target).and_then(|mut w| {
                    w.write_all(out.as_bytes())?;
                    w.finish()
                });
                if let Err(e) = written {
                    eprintln!("error: cannot write {name}: {e}");
                    code = 2;
                }
            }
        }
    }
    ExitCode::from(code)
}
