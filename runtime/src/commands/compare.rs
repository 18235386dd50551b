//! `sdfc compare`: how two renders of the same size differ (RMSE, PSNR, largest difference,
//! differing pixels) and, when both carry a depth sidecar (`sdfc render --aux`), how their
//! first hits differ (missed, false and late hits, relative depth error).

use crate::depth::{self, Depth, DepthError};
use crate::image::read_png;
use crate::metrics::{self, DepthDifference, Difference};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `sdfc compare`.
#[derive(Debug, clap::Args)]
pub struct CompareArgs {
    /// The reference image (PNG).
    pub a: PathBuf,
    /// The image measured against it (PNG).
    pub b: PathBuf,
    /// Per-channel difference (linear, 0 to 1) above which a pixel counts as differing.
    #[arg(long, default_value_t = 0.1)]
    pub threshold: f64,
    /// Relative depth difference above which a hit of B lying behind A's counts as behind.
    #[arg(long, value_name = "REL", default_value_t = 1e-3)]
    pub depth_tolerance: f64,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// The report of `sdfc compare --json`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Report {
    /// The colour difference.
    #[serde(flatten)]
    pub colour: Difference,
    /// The first-hit difference, when both images have a depth sidecar.
    pub depth: Option<DepthDifference>,
    /// Why `depth` is absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub depth_note: Option<String>,
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
    let Some(colour) = metrics::compare(&a, &b, args.threshold) else {
        eprintln!(
            "error: the images differ in size: {}x{} and {}x{}",
            a.width, a.height, b.width, b.height
        );
        return ExitCode::from(2);
    };
    let (depth, depth_note) = match depth_difference(&args) {
        Ok(d) => (Some(d), None),
        Err(note) => (None, Some(note.to_string())),
    };
    let report = Report {
        colour,
        depth,
        depth_note,
    };
    if args.json {
        if let Err(code) = super::print_json(&report, false) {
            return code;
        }
    } else {
        print!("{}", text(&report));
    }
    ExitCode::SUCCESS
}

/// The report as text, one measure a line.
pub fn text(r: &Report) -> String {
    let d = &r.colour;
    let mut out = format!(
        "rmse       {:.6}\npsnr       {:.2} dB\nmax        {:.4}\ndiffering  {:.4}% of pixels (threshold {})\n",
        d.rmse,
        d.psnr,
        d.max,
        d.differing * 100.0,
        d.threshold
    );
    match (&r.depth, &r.depth_note) {
        (Some(z), _) => {
            out += &format!(
                "missed     {:.4}% of pixels (A hit, B missed)\n",
                z.missed * 100.0
            );
            out += &format!(
                "false hit  {:.4}% of pixels (B hit, A missed)\n",
                z.false_hit * 100.0
            );
            out += &format!(
                "behind     {:.4}% of pixels (B's hit behind A's by more than {} of the depth)\n",
                z.behind * 100.0,
                z.tolerance
            );
            match z.mean_relative_error {
                Some(e) => {
                    out += &format!(
                        "depth err  {e:.3e} mean relative, over {:.2}% of pixels hit by both\n",
                        z.both_hit * 100.0
                    )
                }
                None => out += "depth err  none (no pixel hit by both)\n",
            }
        }
        (None, Some(note)) => out += &format!("depth      not compared: {note}\n"),
        (None, None) => {}
    }
    out
}

/// The first-hit difference of the two images' sidecars, or why there is none.
fn depth_difference(args: &CompareArgs) -> Result<DepthDifference, NoDepth> {
    let a = sidecar(&args.a)?;
    let b = sidecar(&args.b)?;
    metrics::compare_depth(&a, &b, args.depth_tolerance).ok_or(NoDepth::Sizes {
        a: (a.width, a.height),
        b: (b.width, b.height),
    })
}

/// Why the images' depths are not compared.
#[derive(Debug, thiserror::Error)]
enum NoDepth {
    #[error("no sidecar `{}` (render with `sdfc render --aux` on the CPU; the GPU backends write none)", .0.display())]
    Missing(PathBuf),
    #[error("`{}` is older than its image, from an earlier render", .0.display())]
    Stale(PathBuf),
    #[error("cannot read `{}`: {error}", path.display())]
    Unreadable { path: PathBuf, error: DepthError },
    #[error("the sidecars differ in size: {}x{} and {}x{}", a.0, a.1, b.0, b.1)]
    Sizes { a: (u32, u32), b: (u32, u32) },
}

/// The depth sidecar of an image, if there is a current one: a sidecar older than its image
/// belongs to an earlier render and is ignored.
fn sidecar(image: &Path) -> Result<Depth, NoDepth> {
    let path = depth::sidecar_path(image);
    if !path.exists() {
        return Err(NoDepth::Missing(path));
    }
    let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    if let (Some(img), Some(side)) = (modified(image), modified(&path)) {
        if side < img {
            return Err(NoDepth::Stale(path));
        }
    }
    Depth::read(&path).map_err(|error| NoDepth::Unreadable { path, error })
}
