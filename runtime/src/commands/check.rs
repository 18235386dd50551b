//! `sdfc check`: report every mistake in one or more scene files, and what the analysis
//! derived about each scene's distance field.

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
    #[command(flatten)]
    pub limits: super::LimitArgs,
}

/// Checks every file; exit 0 when all are clean, 1 when any has errors, 2 when any could not
/// be read. For a clean file, the human format ends with one line: `FILE: ok` and what the
/// field is (exact, a bound or approximate) with the L the renderers step with.
pub fn run(args: CheckArgs) -> ExitCode {
    let mut code = 0u8;
    let limits = args.limits.limits();
    for file in &args.files {
        match frontend::load_with(file, &limits) {
            Err(msg) => {
                eprintln!("error: {msg}");
                code = 2;
            }
            Ok(loaded) => {
                frontend::report(&loaded, args.diagnostics);
                match &loaded.scene {
                    None => code = code.max(1),
                    Some(scene) if args.diagnostics == DiagnosticFormat::Human => {
                        eprintln!(
                            "{}: ok; {}; {}",
                            file.display(),
                            frontend::summary(&loaded, scene),
                            frontend::method(&loaded, scene)
                        );
                    }
                    Some(_) => {}
                }
            }
        }
    }
    ExitCode::from(code)
}
