//! `sdfc compile`: write a scene as one of the textual targets.

use crate::frontend::{self, DiagnosticFormat};
use sdfc_compiler::{scene, syntax};
use std::path::PathBuf;
use std::process::ExitCode;

/// What `sdfc compile` writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Emit {
    /// The syntax tree of the entry file.
    Ast,
    /// The checked scene IR.
    Ir,
}

/// Arguments of `sdfc compile`.
#[derive(Debug, clap::Args)]
pub struct CompileArgs {
    /// Scene file.
    pub file: PathBuf,
    /// The target to write.
    #[arg(long, value_enum)]
    pub emit: Emit,
    /// Output file (default: standard output).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// How to print diagnostics.
    #[arg(long, value_enum, default_value_t)]
    pub diagnostics: DiagnosticFormat,
}

/// Compiles and writes the requested target.
pub fn run(args: CompileArgs) -> ExitCode {
    let loaded = match frontend::load(&args.file) {
        Ok(l) => l,
        Err(msg) => {
            eprintln!("error: {msg}");
            return ExitCode::from(2);
        }
    };
    frontend::report(&loaded, args.diagnostics);
    let text = match args.emit {
        Emit::Ast => {
            // The AST is shown even for a file with errors in later stages, but not with
            // syntax errors (the tree would be partial).
            let entry = sdfc_compiler::FileId(0);
            let (ast, diags) = syntax::parse(entry, loaded.sources.text(entry));
            if sdfc_compiler::diagnostics::has_errors(&diags) {
                return ExitCode::from(1);
            }
            syntax::dump(&ast)
        }
        Emit::Ir => match &loaded.scene {
            Some(s) => scene::dump(s),
            None => return ExitCode::from(1),
        },
    };
    write_output(args.output.as_deref(), &text)
}

/// Writes `text` to a file (atomically) or to standard output.
pub fn write_output(path: Option<&std::path::Path>, text: &str) -> ExitCode {
    match path {
        None => {
            print!("{text}");
            ExitCode::SUCCESS
        }
        Some(p) => match crate::output::write_atomic(p, text.as_bytes()) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("error: cannot write `{}`: {e}", p.display());
                ExitCode::from(2)
            }
        },
    }
}
