//! `sdfc check`: report every mistake in one or more scene files.

use crate::frontend::{self, DiagnosticFormat};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `sdfc check`.
#[derive(Debug, clap::Args)]
pub struct CheckArgs {
    /// Scene files to check.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// How to print diagnostics.
    #[arg(long, value_enum, default_value_t)]
    pub diagnostics: DiagnosticFormat,
}

/// Checks every file; exit 0 when all are clean, 1 when any has errors, 2 when any could not
/// be read.
pub fn run(args: CheckArgs) -> ExitCode {
    let mut code = 0u8;
    for file in &args.files {
        match frontend::load(file) {
            Err(msg) => {
                eprintln!("error: {msg}");
                code = 2;
            }
            Ok(loaded) => {
                frontend::report(&loaded, args.diagnostics);
                if loaded.scene.is_none() {
                    code = code.max(1);
                } else if args.diagnostics == DiagnosticFormat::Human {
                    eprintln!("{}: ok", file.display());
                }
            }
        }
    }
    ExitCode::from(code)
}
