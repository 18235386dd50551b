//! `sdfc compare`: how two renders of the same size differ (RMSE, PSNR, differing pixels).

use crate::image::read_png;
use crate::metrics;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `sdfc compare`.
#[derive(Debug, clap::Args)]
pub struct CompareArgs {
    /// First image (PNG).
    pub a: PathBuf,
    /// Second image (PNG).
    pub b: PathBuf,
    /// Per-channel difference (linear, 0 to 1) above which a pixel counts as differing.
    #[arg(long, default_value_t = 0.1)]
    pub threshold: f64,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Compares the two images; exit 2 when they cannot be read or differ in size.
pub fn run(args: CompareArgs) -> ExitCode {
    let read = |p: &PathBuf| read_png(p).map_err(|e| format!("cannot read `{}`: {e}", p.display()));
    let (a, b) = match (read(&args.a), read(&args.b)) {
        (Ok(a), Ok(b)) => (a, b),
        (Err(e), _) | (_, Err(e)) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let Some(d) = metrics::compare(&a, &b, args.threshold) else {
        eprintln!("error: the images differ in size: {}x{} and {}x{}", a.width, a.height, b.width, b.height);
        return ExitCode::from(2);
    };
    if args.json {
        match serde_json::to_string(&d) {
            Ok(s) => println!("{s}"),
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::from(2);
            }
        }
    } else {
        println!("rmse       {:.6}", d.rmse);
        println!("psnr       {:.2} dB", d.psnr);
        println!("differing  {:.4}% of pixels (threshold {})", d.differing * 100.0, d.threshold);
    }
    ExitCode::SUCCESS
}
