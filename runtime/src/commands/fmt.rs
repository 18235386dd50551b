//! `sdfc fmt`: rewrites scene files in the formatter's layout (`syntax::format`), or with
//! `--check` names those that would change.

use crate::frontend::{self, DiagnosticFormat};
use crate::image::AtomicFile;
use sdfc_compiler::{
    format::{format, Error},
    Limit, SourceMap,
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
    /// The limits (`file_size`: each file is read whole, up to it).
    #[command(flatten)]
    pub limits: super::LimitArgs,
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
/// A folder is entered once, however many symbolic links lead to it (`seen`, its canonical
/// paths): a link to a folder above it was followed until the system refused the path (each
/// file listed 40 times; with two such links, 2⁴⁰ paths).
fn sdf_files(
    dir: &Path,
    seen: &mut std::collections::HashSet<PathBuf>,
    out: &mut Vec<PathBuf>,
) -> std::io::Result<()> {
    if !seen.insert(std::fs::canonicalize(dir)?) {
        return Ok(());
    }
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)?
        .map(|e| e.map(|e| e.path()))
        .collect::<Result<_, _>>()?;
    entries.sort();
    for p in entries {
        let name = p.file_name().map(|n| n.to_string_lossy().into_owned());
        if p.is_dir() {
            if !name.is_some_and(|n| n.starts_with('.') || n == "target") {
                sdf_files(&p, seen, out)?;
            }
        } else if p.extension().is_some_and(|x| x == "sdf") {
            out.push(p);
        }
    }
    Ok(())
}

/// Formats standard input (at most `file_size` MiB) to standard output (with `--check`,
/// writes nothing).
fn stdin(check: bool, file_size: u64) -> ExitCode {
    let limit = file_size.saturating_mul(1 << 20);
    let mut bytes = Vec::new();
    if let Err(e) = std::io::stdin()
        .lock()
        .take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
    {
        eprintln!("error: cannot read standard input: {e}");
        return ExitCode::from(2);
    }
    if bytes.len() as u64 > limit {
        eprintln!(
            "error: cannot read standard input: it is over the file_size limit of {file_size} MiB; raise it with `--limit file_size=N`"
        );
        return ExitCode::from(2);
    }
    let text = match String::from_utf8(bytes) {
        Ok(t) => t,
        Err(e) => {
            eprintln!(
                "error: standard input is not valid UTF-8 (first bad byte at offset {})",
                e.utf8_error().valid_up_to()
            );
            return ExitCode::from(2);
        }
    };
    let out = match format_text("<stdin>", &text) {
        Outcome::Refused => return ExitCode::from(1),
        Outcome::Same => text,
        Outcome::Changed(_) if check => {
            return match super::write_stdout(b"<stdin>\n") {
                Ok(()) => ExitCode::from(1),
                Err(code) => code,
            };
        }
        Outcome::Changed(out) => out,
    };
    if check {
        return ExitCode::SUCCESS;
    }
    match super::write_stdout(out.as_bytes()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(code) => code,
    }
}

/// Formats each file in place (written whole or not at all, through [`AtomicFile`]; a
/// symbolic link's target is rewritten); exit 0 when all are formatted (or with `--check`,
/// already were), 1 when a file has syntax errors or would change, 2 when a file cannot be
/// read or written.
pub fn run(args: FmtArgs) -> ExitCode {
    if let Some((name, _)) = args.limits.param.first() {
        eprintln!("error: `sdfc fmt` rewrites text and checks no scene: `--param {name}=…` would change nothing");
        return ExitCode::from(2);
    }
    let file_size = args.limits.limits().get(Limit::FileSize);
    if args.files.is_empty() || args.files == [PathBuf::from("-")] {
        return stdin(args.check, file_size);
    }
    let mut files = Vec::new();
    let mut code = 0u8;
    let mut folders = std::collections::HashSet::new();
    for f in &args.files {
        if f.is_dir() {
            if let Err(e) = sdf_files(f, &mut folders, &mut files) {
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
        let text = match frontend::read_file(file, file_size) {
            Ok(bytes) => match String::from_utf8(bytes) {
                Ok(t) => t,
                Err(e) => {
                    eprintln!(
                        "error: {name} is not valid UTF-8 (first bad byte at offset {})",
                        e.utf8_error().valid_up_to()
                    );
                    code = 2;
                    continue;
                }
            },
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
                if let Err(failed) = super::write_stdout(format!("{name}\n").as_bytes()) {
                    return failed;
                }
                code = code.max(1);
            }
            Outcome::Changed(out) => {
                let target = std::fs::canonicalize(file).unwrap_or_else(|_| file.clone());
                // The new file takes the old one's permissions (and owner, where the process
                // may give it: as root) before it replaces it.
                let written = AtomicFile::unsynced(&target).and_then(|mut w| {
                    w.keep_metadata_of(&std::fs::metadata(&target)?)?;
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
