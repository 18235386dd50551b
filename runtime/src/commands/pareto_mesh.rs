//! `sdfc pareto --mesh`: meshing's speed against its accuracy. Meshes a scene at every
//! resolution of a sweep (as `sdfc mesh` does, through `mesh::surface`), times each (median
//! of several runs), measures the largest distance from the mesh's vertices and triangle
//! centres to the surface (the distance program in f64), marks the Pareto fronts of time and
//! of triangles against that distance, and prints the table, the JSON or the chart.

use super::mesh::{settings, surface, Meshed, Region, Spelling, DEFAULT_RESOLUTION};
use super::pareto::ParetoArgs;
use crate::chart::{self, Chart};
use crate::frontend::{self, DiagnosticFormat};
use crate::pareto::{front, parse_sweep_within, Error, Key, Sweep, TIME_MARGIN};
use sdfc_compiler::analysis;
use std::process::ExitCode;

/// The resolutions swept when none is given: 32 to 256 cells, one an octave.
pub const DEFAULT_SWEEP: &str = "resolution=32..256";

/// Triangle counts within this fraction count as equal for the front.
const TRIANGLES_MARGIN: f64 = 0.02;

/// One resolution, measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct MeshPoint {
    /// Cells along the longest side of the bounds.
    pub resolution: u32,
    /// The edge of a cell, in scene units.
    pub cell: f64,
    /// Triangles of the mesh.
    pub triangles: usize,
    /// Vertices of the mesh.
    pub vertices: usize,
    /// Median seconds from the octree's start to the mesh (as `sdfc mesh` reports it).
    pub median_s: f64,
    /// The largest |f| at a vertex (for an exact field, its distance to the surface).
    pub vertex_distance: f64,
    /// The largest |f| at a triangle's centre.
    pub centre_distance: f64,
    /// The larger of the two: the accuracy charted.
    pub distance: f64,
    /// On the front of time against distance.
    pub front_time: bool,
    /// On the front of triangles against distance.
    pub front_triangles: bool,
    /// `sdfc mesh`'s default resolution.
    pub default: bool,
}

/// What `sdfc pareto --mesh` measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct MeshReport {
    /// The scene file.
    pub scene: String,
    /// The field's exactness (`exact`: the distances are to the surface; otherwise |f|,
    /// which a bound understates).
    pub exactness: String,
    /// Worker threads.
    pub threads: usize,
    /// Runs timed at each resolution.
    pub runs: u32,
    /// The resolutions, in the order swept.
    pub points: Vec<MeshPoint>,
}

/// Runs `sdfc pareto --mesh`.
pub fn run(args: &ParetoArgs) -> ExitCode {
    match measure(args) {
        Ok(report) => finish(args, &report),
        Err((code, msg)) => {
            if !msg.is_empty() {
                eprintln!("error: {msg}");
            }
            ExitCode::from(code)
        }
    }
}

/// The resolutions of the `--sweep`s (only `resolution` is swept with `--mesh`).
fn resolutions(args: &ParetoArgs, limits: &sdfc_compiler::Limits) -> Result<Vec<u32>, Error> {
    let specs: Vec<&str> = if args.sweep.is_empty() {
        vec![DEFAULT_SWEEP]
    } else {
        args.sweep.iter().map(String::as_str).collect()
    };
    let mut out = Vec::new();
    for spec in specs {
        let Sweep { key, values } = parse_sweep_within(spec, limits)?;
        if key != Key::Resolution {
            return Err(Error::NotMesh(key.name()));
        }
        for v in values {
            let r = v.min(f64::from(u32::MAX)) as u32;
            if !out.contains(&r) {
                out.push(r);
            }
        }
    }
    Ok(out)
}

/// Meshes the scene at every resolution, `args.frames` times each.
fn measure(args: &ParetoArgs) -> Result<MeshReport, (u8, String)> {
    let usage = |msg: String| (2u8, msg);
    super::pareto::check_output(args.output.as_deref()).map_err(|e| usage(e.to_string()))?;
    let limits = args.limits.limits();
    let resolutions = resolutions(args, &limits).map_err(|e| usage(e.to_string()))?;
    let mut settings = settings(&args.set).map_err(usage)?;
    let pool = crate::job::thread_pool(args.threads, &limits).map_err(|e| usage(e.to_string()))?;
    let checked = frontend::load_scene_code(&args.file, DiagnosticFormat::Human, &limits)
        .map_err(|code| (code, String::new()))?;
    let exactness = analysis::analyse(&checked.scene)
        .root()
        .map_or("empty".to_string(), |r| {
            analysis::describe(r.facts.exactness).to_string()
        });
    let mut points = Vec::new();
    for (k, &resolution) in resolutions.iter().enumerate() {
        let region = Region {
            resolution: Some(resolution),
            voxel: None,
            bounds: args.bounds,
            spelling: Spelling::Flags,
        };
        let mut times = Vec::new();
        let mut last = None;
        for run in 0..args.frames {
            // The distances are measured once, after the timed runs' last (outside its time).
            settings.measure = run + 1 == args.frames;
            // Announcements are the mesh command's; only the first resolution's are shown.
            let say = |text: String| {
                if run == 0 && (k == 0 || text.starts_with("warning")) {
                    eprintln!("{text}");
                }
            };
            let meshed = surface(
                &checked,
                region,
                &settings,
                &limits,
                &pool,
                &|_, _| {},
                &say,
            )?;
            times.push(meshed.seconds);
            last = Some(meshed);
        }
        let Some(Meshed {
            mesh, stats, grid, ..
        }) = last
        else {
            continue;
        };
        times.sort_by(f64::total_cmp);
        let [vertex_distance, centre_distance] = stats.error.unwrap_or([f64::NAN; 2]);
        eprintln!(
            "resolution {resolution}: {} triangles, {:.3} s",
            mesh.triangles.len(),
            times[times.len() / 2]
        );
        points.push(MeshPoint {
            resolution,
            cell: grid.voxel,
            triangles: mesh.triangles.len(),
            vertices: mesh.positions.len(),
            median_s: times[times.len() / 2],
            vertex_distance,
            centre_distance,
            distance: vertex_distance.max(centre_distance),
            front_time: false,
            front_triangles: false,
            default: resolution == DEFAULT_RESOLUTION,
        });
    }
    mark_fronts(&mut points);
    Ok(MeshReport {
        scene: args.file.display().to_string(),
        exactness,
        threads: pool.current_num_threads(),
        runs: args.frames,
        points,
    })
}

/// Marks the fronts of time and of triangles against the distance (smaller is better: the
/// front takes it in decibels, −20·log10 of the distance, so that distances within about
/// 6 % count as equal, [`crate::pareto::PSNR_MARGIN`]; a mesh with no triangles is never on
/// it).
fn mark_fronts(points: &mut [MeshPoint]) {
    let quality = |m: &MeshPoint| {
        if m.triangles == 0 {
            f64::NAN
        } else {
            -20.0 * m.distance.max(f64::MIN_POSITIVE).log10()
        }
    };
    let by_time: Vec<(f64, f64)> = points.iter().map(|m| (m.median_s, quality(m))).collect();
    let by_triangles: Vec<(f64, f64)> = points
        .iter()
        .map(|m| (m.triangles as f64, quality(m)))
        .collect();
    let (ft, fg) = (
        front(&by_time, TIME_MARGIN),
        front(&by_triangles, TRIANGLES_MARGIN),
    );
    for ((m, t), g) in points.iter_mut().zip(ft).zip(fg) {
        m.front_time = t;
        m.front_triangles = g;
    }
}

/// What the distances measured in a field of `exactness` are, and the caution a table adds
/// where they are |f| (which may understate them).
fn distances(exactness: &str) -> (&'static str, &'static str) {
    if exactness == "exact" {
        ("distances to the surface", "")
    } else {
        ("distances are |f|", ", which may understate them")
    }
}

/// The points as a text table.
pub fn table(r: &MeshReport) -> String {
    let (what, caution) = distances(&r.exactness);
    let mut out = format!(
        "{}: meshed on {} threads, median of {} runs; the field is {} ({what}{caution})\n",
        r.scene, r.threads, r.runs, r.exactness,
    );
    out += &format!(
        "{:>10} {:>10} {:>10} {:>10} {:>10} {:>12} {:>12} {:>8} {:>6} {:>7}\n",
        "resolution",
        "cell",
        "triangles",
        "vertices",
        "median ms",
        "vertex dist",
        "centre dist",
        "% cell",
        "front",
        "default"
    );
    for m in &r.points {
        let front = crate::pareto::front_word(m.front_time, (m.front_triangles, "tris"));
        out += &format!(
            "{:>10} {:>10.4} {:>10} {:>10} {:>10.1} {:>12.3e} {:>12.3e} {:>8.2} {:>6} {:>7}\n",
            m.resolution,
            m.cell,
            m.triangles,
            m.vertices,
            m.median_s * 1e3,
            m.vertex_distance,
            m.centre_distance,
            100.0 * m.distance / m.cell,
            front,
            if m.default { "yes" } else { "" }
        );
    }
    out
}

/// The chart of a report: time and triangles against the largest distance.
pub fn chart_of(r: &MeshReport) -> Chart {
    let name = std::path::Path::new(&r.scene)
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| r.scene.clone());
    Chart {
        title: format!(
            "{name}: meshing speed against accuracy ({} resolutions)",
            r.points.len()
        ),
        subtitle: format!(
            "sdfc mesh on {} threads, median of {} runs; distance: the largest of vertices and triangle centres; the field is {}: {}",
            r.threads,
            r.runs,
            r.exactness,
            distances(&r.exactness).0,
        ),
        default_label: format!("sdfc mesh's default, resolution {DEFAULT_RESOLUTION}"),
        panels: [
            chart::Panel {
                caption: "Time against accuracy".into(),
                cost: "median time to mesh (ms, log scale)".into(),
            },
            chart::Panel {
                caption: "Size against accuracy".into(),
                cost: "triangles (log scale)".into(),
            },
        ],
        accuracy: chart::Accuracy {
            label: "largest distance to the surface (log scale, lower is better)".into(),
            lower_is_better: true,
            target: None,
        },
        points: r
            .points
            .iter()
            .map(|m| chart::Point {
                cost: [m.median_s * 1e3, m.triangles as f64],
                accuracy: m.distance,
                front: [m.front_time, m.front_triangles],
                default: m.default,
            })
            .collect(),
    }
}

/// Prints the report and draws the chart.
fn finish(args: &ParetoArgs, report: &MeshReport) -> ExitCode {
    super::pareto::publish(args, report, &table(report), || chart_of(report))
}
