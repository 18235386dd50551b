//! `sdfc bench`.

use std::process::ExitCode;

/// Arguments of `sdfc bench`.
#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// Scene file.
    pub file: std::path::PathBuf,
}

/// Runs `sdfc bench`.
pub fn run(_args: BenchArgs) -> ExitCode {
    eprintln!("error: not built yet");
    ExitCode::from(2)
}
