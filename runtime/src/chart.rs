//! Charts of speed against accuracy (`sdfc pareto -o`): two panels, two costs (time per
//! frame and marching steps per pixel; for meshes, time and triangles), both on log axes,
//! against one accuracy (PSNR; for meshes, the distance to the surface on a log axis), with
//! the Pareto front and the default settings marked, drawn with plotters as SVG or PNG.
//!
//! SVG text is left to the viewer's fonts; PNG text is rasterised by ab_glyph from DejaVu
//! Sans, bundled by the `dejavu` crate, so no system font library is needed.

use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Once;

/// One measured point of a chart.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// Its costs, one a panel (on log axes).
    pub cost: [f64; 2],
    /// Its accuracy (may be infinite: drawn at the axis' better end).
    pub accuracy: f64,
    /// On the front of each panel's cost against the accuracy.
    pub front: [bool; 2],
    /// The scene's own settings.
    pub default: bool,
}

/// One panel: a cost against the accuracy.
#[derive(Debug, Clone)]
pub struct Panel {
    /// The caption above it.
    pub caption: String,
    /// The cost axis' description.
    pub cost: String,
}

/// The accuracy axis, shared by both panels.
#[derive(Debug, Clone)]
pub struct Accuracy {
    /// Its description.
    pub label: String,
    /// Lower values are better (a distance, drawn on a log axis); otherwise higher ones are
    /// (PSNR, on a linear axis).
    pub lower_is_better: bool,
    /// A value drawn as a dashed line (the accuracy target), with its legend, if any.
    pub target: Option<(f64, String)>,
}

/// What a chart shows.
#[derive(Debug, Clone)]
pub struct Chart {
    /// The title above both panels.
    pub title: String,
    /// A second line under the title (reference, machine).
    pub subtitle: String,
    /// The legend entry of the default point.
    pub default_label: String,
    /// The two panels, left and right.
    pub panels: [Panel; 2],
    /// The accuracy axis.
    pub accuracy: Accuracy,
    /// The points.
    pub points: Vec<Point>,
}

/// Chart size in pixels (SVG user units).
pub const SIZE: (u32, u32) = (1200, 540);

const FONT: &str = "sans-serif";
const GREY: RGBColor = RGBColor(110, 130, 170);
const FRONT: RGBColor = RGBColor(200, 40, 40);
const DEFAULT: RGBColor = RGBColor(20, 150, 60);

/// Why a chart could not be drawn or written.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The file's name says neither SVG nor PNG.
    #[error("`{}`: the chart must be a .svg or .png file", .0.display())]
    Extension(PathBuf),
    /// The file could not be written.
    #[error("cannot write `{}`: {error}", path.display())]
    Write {
        path: PathBuf,
        error: std::io::Error,
    },
    /// The plotting library failed to draw.
    #[error("drawing the chart: {0}")]
    Draw(Box<dyn std::error::Error + Send + Sync>),
    /// The PNG encoder failed.
    #[error("encoding the chart as PNG: {0}")]
    Png(#[from] ::png::EncodingError),
}

/// A drawing error of any plotting backend, as an [`Error`].
fn drawn<E: std::error::Error + Send + Sync + 'static>(e: DrawingAreaErrorKind<E>) -> Error {
    Error::Draw(Box::new(e))
}

/// Writes the chart to `path`: SVG for a `.svg` name, PNG for `.png`.
pub fn write(chart: &Chart, path: &Path) -> Result<(), Error> {
    let ext = path.extension().map(|e| e.to_string_lossy().to_lowercase());
    let bytes = match ext.as_deref() {
        Some("svg") => svg(chart)?.into_bytes(),
        Some("png") => png(chart)?,
        _ => return Err(Error::Extension(path.to_path_buf())),
    };
    crate::image::write_atomic(path, &bytes).map_err(|error| Error::Write {
        path: path.to_path_buf(),
        error,
    })
}

/// The chart as SVG text.
pub fn svg(chart: &Chart) -> Result<String, Error> {
    register_font();
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, SIZE).into_drawing_area();
        draw(&root, chart)?;
        root.present().map_err(drawn)?;
    }
    Ok(out)
}

/// The chart as PNG file bytes.
pub fn png(chart: &Chart) -> Result<Vec<u8>, Error> {
    register_font();
    let (w, h) = SIZE;
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        draw(&root, chart)?;
        root.present().map_err(drawn)?;
    }
    encode_rgb(&rgb, w, h)
}

fn encode_rgb(rgb: &[u8], w: u32, h: u32) -> Result<Vec<u8>, Error> {
    let mut bytes = Vec::new();
    let mut encoder = ::png::Encoder::new(&mut bytes, w, h);
    encoder.set_color(::png::ColorType::Rgb);
    encoder.set_depth(::png::BitDepth::Eight);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()?;
    Ok(bytes)
}

/// Makes DejaVu Sans the "sans-serif" of plotters' ab_glyph text (once per process).
fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bytes are a valid TrueType font; a failure would only leave text undrawn.
        let _ = plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
    });
}

/// The accuracy axis' range (lo, hi) and where a point of infinite accuracy is drawn: PSNR
/// from a little below the worst point to a little above the best finite one, infinite ones
/// at the top; a distance on a log axis around the points, zero at the bottom.
fn accuracy_range(chart: &Chart) -> (f64, f64, f64) {
    let a = &chart.accuracy;
    let target = a.target.as_ref().map(|t| t.0);
    if a.lower_is_better {
        let r = log_range(chart.points.iter().map(|p| p.accuracy).chain(target));
        return (r.start, r.end, r.start);
    }
    let finite: Vec<f64> = chart
        .points
        .iter()
        .map(|p| p.accuracy)
        .filter(|v| v.is_finite())
        .collect();
    let lo = finite.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = finite.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let (lo, hi) = if lo.is_finite() {
        (lo, hi)
    } else {
        (0.0, 60.0)
    };
    let (lo, hi) = match target {
        Some(t) => (lo.min(t), hi.max(t)),
        None => (lo, hi),
    };
    let top = hi + 3.0;
    ((lo - 3.0).floor(), top.ceil(), top)
}

/// A positive range around `values` for a log axis.
fn log_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !lo.is_finite() {
        return 0.1..10.0;
    }
    lo / 1.25..hi * 1.25
}

fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, chart: &Chart) -> Result<(), Error>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(drawn)?;
    let (head, body) = root.split_vertically(64);
    head.draw(&Text::new(
        chart.title.clone(),
        (20, 10),
        (FONT, 22).into_font(),
    ))
    .map_err(drawn)?;
    head.draw(&Text::new(
        chart.subtitle.clone(),
        (20, 38),
        (FONT, 14).into_font().color(&RGBColor(80, 80, 80)),
    ))
    .map_err(drawn)?;
    let (left, right) = body.split_horizontally(SIZE.0 / 2);
    if chart.accuracy.lower_is_better {
        let (lo, hi, _) = accuracy_range(chart);
        let ys = || (lo..hi).log_scale().with_key_points(log_ticks(lo, hi));
        panel(&left, chart, 0, ys())?;
        panel(&right, chart, 1, ys())
    } else {
        let (lo, hi, _) = accuracy_range(chart);
        panel(&left, chart, 0, lo..hi)?;
        panel(&right, chart, 1, lo..hi)
    }
}

/// Panel `k`: its cost on a log axis against the accuracy on `ys`, the front joined by a
/// line.
fn panel<DB: DrawingBackend, Y>(
    area: &DrawingArea<DB, Shift>,
    chart: &Chart,
    k: usize,
    ys: Y,
) -> Result<(), Error>
where
    DB::ErrorType: 'static,
    Y: plotters::coord::ranged1d::AsRangedCoord<Value = f64>,
    Y::CoordDescType: plotters::coord::ranged1d::ValueFormatter<f64>,
{
    let err = drawn::<DB::ErrorType>;
    let (_, _, infinite) = accuracy_range(chart);
    let y = |p: &Point| {
        if p.accuracy.is_finite() && !(chart.accuracy.lower_is_better && p.accuracy <= 0.0) {
            p.accuracy
        } else {
            infinite
        }
    };
    let x = |p: &Point| p.cost[k];
    let xs = log_range(chart.points.iter().map(x));
    let ticks = log_ticks(xs.start, xs.end);
    let mut c = ChartBuilder::on(area)
        .caption(&chart.panels[k].caption, (FONT, 16))
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(66)
        .build_cartesian_2d(xs.clone().log_scale().with_key_points(ticks), ys)
        .map_err(err)?;
    c.configure_mesh()
        .x_desc(&chart.panels[k].cost)
        .y_desc(&chart.accuracy.label)
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 13))
        .x_label_formatter(&|v| short(*v))
        .y_label_formatter(&|v| short(*v))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(err)?;
    if let Some((t, label)) = &chart.accuracy.target {
        c.draw_series(DashedLineSeries::new(
            [(xs.start, *t), (xs.end, *t)],
            6,
            4,
            BLACK.mix(0.6).stroke_width(1),
        ))
        .map_err(err)?
        .label(label.clone())
        .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], BLACK.mix(0.6)));
    }
    c.draw_series(
        chart
            .points
            .iter()
            .map(|p| Circle::new((x(p), y(p)), 3, GREY.filled())),
    )
    .map_err(err)?
    .label("settings tried")
    .legend(|(x, y)| Circle::new((x + 8, y), 3, GREY.filled()));
    let mut front: Vec<(f64, f64)> = chart
        .points
        .iter()
        .filter(|p| p.front[k])
        .map(|p| (x(p), y(p)))
        .collect();
    front.sort_by(|a, b| a.0.total_cmp(&b.0));
    c.draw_series(LineSeries::new(front.clone(), FRONT.stroke_width(2)))
        .map_err(err)?
        .label("Pareto front")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], FRONT.stroke_width(2)));
    c.draw_series(
        front
            .iter()
            .map(|&(a, b)| Circle::new((a, b), 3, FRONT.filled())),
    )
    .map_err(err)?;
    c.draw_series(
        chart
            .points
            .iter()
            .filter(|p| p.default)
            .map(|p| TriangleMarker::new((x(p), y(p)), 8, DEFAULT.filled())),
    )
    .map_err(err)?
    .label(chart.default_label.clone())
    .legend(|(x, y)| TriangleMarker::new((x + 8, y), 6, DEFAULT.filled()));
    // Better is up for PSNR and down for a distance: the legend goes where the points
    // are not (the costly and inaccurate corner).
    c.configure_series_labels()
        .position(if chart.accuracy.lower_is_better {
            SeriesLabelPosition::UpperRight
        } else {
            SeriesLabelPosition::LowerRight
        })
        .label_font((FONT, 12))
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(160, 160, 160))
        .draw()
        .map_err(err)
}

/// Tick values for a log axis from `lo` to `hi`: 1, 2 and 5 times powers of ten, or every
/// digit times a power of ten when that gives fewer than four.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let within = |mantissas: &[f64]| -> Vec<f64> {
        let mut out = Vec::new();
        let mut decade = 10f64.powi(lo.log10().floor() as i32);
        while decade <= hi {
            out.extend(
                mantissas
                    .iter()
                    .map(|m| m * decade)
                    .filter(|v| (lo..=hi).contains(v)),
            );
            decade *= 10.0;
        }
        out
    };
    let coarse = within(&[1.0, 2.0, 5.0]);
    if coarse.len() >= 4 {
        coarse
    } else {
        within(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
    }
}

/// A tick label: whole numbers plain, small values with two significant digits.
fn short(v: f64) -> String {
    if v >= 1.0 || v <= 0.0 {
        format!("{}", v.round())
    } else {
        let digits = (1 - v.log10().floor() as i32).max(2) as usize;
        format!("{v:.digits$}")
    }
}
