//! `sdfc mesh`: the scene's surface as a triangle mesh (STL, OBJ, PLY, glTF or 3MF), from an
//! octree pruned by the compiler's proven bounds and patches that keep sharp features
//! (`crate::mesh`, `docs/mesh.md`); the region and cell size are `mesh_region`'s.

use super::mesh_region::{frame, short, Frame};
pub use super::mesh_region::{parse_bounds, BoundsError, Region, Spelling, DEFAULT_RESOLUTION};
use super::mesh_thin::Thinness;
use crate::backend::Backend;
use crate::frontend::{self, DiagnosticFormat};
use crate::memory::{mib, MIB};
use crate::mesh::contour::{self, Stop, BYTES_PER_SURFACE_CELL};
use crate::mesh::device::Gpu;
use crate::mesh::write::{Format, Unsaved, Up};
use crate::mesh::{octree, Field, Grid, Mesh, Settings, Stats};
use sdfc_compiler::{analysis, Limit, Limits, LowerOptions};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

/// Arguments of `sdfc mesh`.
#[derive(Debug, clap::Args)]
pub struct MeshArgs {
    /// Scene file.
    pub file: PathBuf,
    /// Output mesh: .stl (binary), .obj, .ply (binary, vertex colours), .glb (binary glTF,
    /// one material per scene material: a primitive each, sharing one buffer of positions,
    /// which importers load as separate parts with the border vertices duplicated; write .ply
    /// for one welded mesh with colours) or .3mf (millimetres, one closed object per material
    /// with its colour, for multi-material printers).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Cells along the longest side of the bounds [default: 128].
    #[arg(long, value_name = "N", conflicts_with = "voxel")]
    pub resolution: Option<u32>,
    /// Edge of a cell, in scene units (instead of --resolution).
    #[arg(long, value_name = "SIZE")]
    pub voxel: Option<f64>,
    /// The region to mesh, X0,Y0,Z0,X1,Y1,Z1 (default: the scene's bounding box from the
    /// analysis). What reaches out of it is cut at its faces and the cut is closed; a scene
    /// with unbounded parts (a plane, an infinite repetition) needs it.
    #[arg(long, value_name = "X0,Y0,Z0,X1,Y1,Z1", value_parser = parse_bounds, allow_hyphen_values = true)]
    pub bounds: Option<[[f64; 3]; 2]>,
    /// Mesh setting: `sharp=on|off` (inner vertices at sharp edges and corners, and edges
    /// flipped along them; off: every inner vertex on the surface near its patch's centre),
    /// `refine=N` (root-finding rounds per edge vertex, 0 to 50), `thin=on|off` (mesh again
    /// on finer cells where walls or gaps thinner than a cell were missed; off: only warn).
    /// May be repeated.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// The file's up axis: y, the scene's up, or z, the build plate's normal that slicers
    /// read (the scene turned a quarter turn about x, its +y the file's +z) [default: z for
    /// .3mf, y for the others].
    #[arg(long, value_enum)]
    pub up: Option<Up>,
    /// Print what meshing did (cells evaluated, surface cells, features, flips).
    #[arg(long)]
    pub stats: bool,
    /// Worker threads (default: one per core).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// What evaluates the field's points: the CPU (f64), or a GPU through wgpu or CUDA (f32,
    /// the scene's points kernel; the mesh agrees with the CPU's within docs/mesh.md's
    /// tolerance); `auto` picks as `render` does (CUDA, a wgpu GPU, else the CPU).
    #[arg(long, value_enum, default_value = "cpu")]
    pub backend: crate::backend::Backend,
    #[command(flatten)]
    pub limits: super::LimitArgs,
}

/// Runs `sdfc mesh`.
pub fn run(args: MeshArgs) -> ExitCode {
    keep_freed_memory();
    match mesh(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err((code, msg)) => {
            if !msg.is_empty() {
                eprintln!("error: {msg}");
            }
            ExitCode::from(code)
        }
    }
}

fn mesh(args: &MeshArgs) -> Result<(), (u8, String)> {
    let usage = |msg: String| (2u8, msg);
    let limits = args.limits.limits();
    let format = Format::of(&args.output).ok_or_else(|| {
        usage(format!(
            "cannot tell the mesh format of `{}`; name it .stl, .obj, .ply, .glb or .3mf",
            args.output.display()
        ))
    })?;
    crate::output::check_writable(&args.output)
        .map_err(|why| usage(format!("cannot write `{}`: {why}", args.output.display())))?;
    let mut settings = settings(&args.set).map_err(usage)?;
    settings.measure = args.stats;
    settings.backend = crate::mesh::device::resolve(args.backend);
    let pool = crate::job::thread_pool(args.threads, &limits).map_err(|e| usage(e.to_string()))?;
    // 1 for errors in the scene, 2 for a file that cannot be read, as `check` and `render`.
    let checked = frontend::load_scene_code(&args.file, DiagnosticFormat::Human, &limits)
        .map_err(|code| (code, String::new()))?;
    settings.materials = format.carries_materials(&checked.scene);
    let bar = super::progress_bar(1000, "{msg:>9} {bar:40} {percent:>3}% {elapsed_precise}");
    let progress = |name: &'static str, f: f64| {
        if let Some(b) = &bar {
            b.set_message(name);
            b.set_position((f * 1000.0) as u64);
        }
    };
    let say = |text: String| match &bar {
        Some(b) => b.suspend(|| eprintln!("{text}")),
        None => eprintln!("{text}"),
    };
    let region = Region {
        resolution: args.resolution,
        voxel: args.voxel,
        bounds: args.bounds,
        spelling: Spelling::Flags,
    };
    // 3MF: an object per material, where the scene has several.
    let parts = match format {
        Format::ThreeMf => crate::mesh::parts::by_material(&checked.scene),
        _ => Vec::new(),
    };
    if parts.len() > 1 {
        let how = Meshing {
            settings: &settings,
            limits: &limits,
            pool: &pool,
            progress: &progress,
            say: &say,
        };
        let result = objects(args, &checked, parts, region, &how);
        if let Some(b) = &bar {
            b.finish_and_clear();
        }
        return result;
    }
    let result = surface(&checked, region, &settings, &limits, &pool, &progress, &say);
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let Meshed {
        mesh,
        stats,
        grid,
        seconds,
    } = result?;
    if mesh.triangles.is_empty() {
        let why = match args.bounds {
            Some(_) => "the region given with --bounds holds none of the surface, or its cells are too coarse to find it (a higher --resolution)".to_string(),
            None => format!(
                "cells of {} are too coarse to find it (a higher --resolution)",
                short(grid.voxel)
            ),
        };
        let [nx, ny, nz] = grid.cells;
        return Err((
            1,
            format!(
                "the mesh has no triangles: no surface crosses the grid of {nx}x{ny}x{nz} cells; {why}; `{}` is not written",
                args.output.display()
            ),
        ));
    }
    // The file's bytes are in the surface cells' share of the announcement.
    let colours = sdfc_compiler::Colours::new(&checked.scene);
    let palette = crate::mesh::write::Palette::new(&checked.scene, &colours);
    let up = args.up.unwrap_or(format.default_up());
    crate::mesh::write::save(format, &mesh, &palette, up, &args.output).map_err(|e| {
        let (code, e) = match e {
            Unsaved::Encode(e) => (1, e),
            Unsaved::Write(e) => (2, e),
        };
        (
            code,
            format!("cannot write `{}`: {e}", args.output.display()),
        )
    })?;
    eprintln!(
        "wrote {} ({} triangles, {} vertices, {:.3} s)",
        args.output.display(),
        mesh.triangles.len(),
        mesh.positions.len(),
        seconds
    );
    if args.stats {
        print!("{}", describe(&grid, &stats, seconds));
    }
    Ok(())
}

/// Has the allocator keep the memory a mesh frees for its next buffers, for the rest of this
/// process (the command's): one arena for every thread, and blocks up to 32 MiB neither
/// mapped apart nor handed back to the system, so that a buffer freed between two steps is
/// not faulted in page by page again (on the fogleman example, 30 500 page faults to 18 200).
#[allow(unsafe_code)]
fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: `mallopt` sets glibc's allocator parameters, called here before the command's
    // threads start; a value it refuses leaves the default (its result is not needed).
    unsafe {
        libc::mallopt(libc::M_ARENA_MAX, 1);
        libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20);
        libc::mallopt(libc::M_TRIM_THRESHOLD, 1 << 30);
    }
}

/// How to mesh: what [`surface`] takes besides the scene and the region.
struct Meshing<'a> {
    settings: &'a Settings,
    limits: &'a Limits,
    pool: &'a rayon::ThreadPool,
    progress: &'a (dyn Fn(&'static str, f64) + Sync),
    say: &'a (dyn Fn(String) + Sync),
}

/// `sdfc mesh -o FILE.3mf` for a scene of several materials: each part
/// (`mesh::parts`) meshed on the whole scene's grid, so that where two parts touch their
/// faces are meshed alike (and all of them again on one finer grid where one misses walls or
/// gaps thinner than a cell), then written as an object each.
fn objects(
    args: &MeshArgs,
    checked: &frontend::Checked,
    parts: Vec<crate::mesh::parts::Part>,
    region: Region,
    how: &Meshing,
) -> Result<(), (u8, String)> {
    let out = args.output.display();
    let whole = frame(checked, &analysis::analyse(&checked.scene), region, how.say)?;
    let origin = checked.scene.origin;
    let bounds = whole.clip.map(|c| [0, 1, 2].map(|i| c[i] + origin[i]));
    let colours = sdfc_compiler::Colours::new(&checked.scene);
    let palette = crate::mesh::write::Palette::new(&checked.scene, &colours);
    let failed = |e: std::io::Error| (1, format!("cannot write `{out}`: {e}"));
    let mut model = crate::mesh::threemf::Model::new(&palette).map_err(failed)?;
    let n = parts.len();
    let within = Region {
        resolution: None,
        voxel: Some(whole.voxel),
        bounds: Some(bounds),
        spelling: region.spelling,
    };
    // Every part on the whole scene's grid, so that where two parts touch their faces are
    // meshed alike; where one misses walls or gaps thinner than a cell, every part again on
    // the finest grid any asks for (or none, where one cannot be), for the same reason.
    let mut meshed = Vec::new();
    let mut fine: Option<Region> = None;
    for (k, part) in parts.into_iter().enumerate() {
        let name = palette
            .materials
            .get(part.material as usize)
            .map_or_else(|| format!("material {}", part.material), |m| m.name.clone());
        let reaches = analysis::analyse(&part.scene).root().is_some_and(|r| {
            let b = r.bounds;
            !b.is_empty()
                && (0..3).all(|i| b.min[i] <= whole.clip[1][i] && b.max[i] >= whole.clip[0][i])
        });
        if !reaches {
            (how.say)(format!(
                "mesh: the part of material `{name}` lies outside the region: no object for it"
            ));
            continue;
        }
        (how.say)(format!("mesh: part {} of {n}, material `{name}`", k + 1));
        let one = frontend::Checked {
            scene: part.scene,
            sources: checked.sources.clone(),
            format: checked.format,
        };
        let progress =
            |stage: &'static str, f: f64| (how.progress)(stage, (k as f64 + f) / n as f64);
        let coarse = how.surface_on(&one, within, &progress)?;
        let thin = Thinness::new(&one, within, coarse.grid.voxel);
        let asked = finer(
            &thin,
            &coarse,
            how.settings,
            how.limits,
            region.spelling,
            how.say,
        );
        if let Some(r) = asked {
            if fine.is_none_or(|f| r.voxel < f.voxel) {
                fine = Some(r);
            }
        }
        meshed.push((name, part.material, one, thin, coarse));
    }
    if let Some(fine) = fine {
        meshed = again(meshed, fine, how);
    }
    let (mut objects, mut triangles, mut vertices, mut seconds) = (0, 0, 0, 0.0);
    for (name, material, _, _, meshed) in meshed {
        if meshed.mesh.triangles.is_empty() {
            (how.say)(format!(
                "mesh: the part of material `{name}` has no triangles at cells of {}: no object for it",
                short(meshed.grid.voxel)
            ));
            continue;
        }
        model
            .object(
                &name,
                material,
                &meshed.mesh,
                &palette,
                args.up.unwrap_or(Format::ThreeMf.default_up()),
            )
            .map_err(failed)?;
        objects += 1;
        triangles += meshed.mesh.triangles.len();
        vertices += meshed.mesh.positions.len();
        seconds += meshed.seconds;
        if args.stats {
            print!(
                "object          `{name}`\n{}",
                describe(&meshed.grid, &meshed.stats, meshed.seconds)
            );
        }
    }
    if objects == 0 {
        return Err((
            1,
            format!("the mesh has no triangles: no part's surface was found at cells of {} (a higher --resolution); `{out}` is not written", short(whole.voxel)),
        ));
    }
    let bytes = model.finish().map_err(failed)?;
    crate::mesh::write::save_bytes(&args.output, &bytes)
        .map_err(|e| (2, format!("cannot write `{out}`: {e}")))?;
    eprintln!(
        "wrote {out} ({objects} objects, {triangles} triangles, {vertices} vertices, {seconds:.3} s)"
    );
    Ok(())
}

/// A part of a 3MF meshed: its material's name and id, scene, thinness and mesh.
type Part = (String, u32, frontend::Checked, Thinness, Meshed);

/// The parts meshed again on `fine`; where one cannot be, every part as it was, saying why.
fn again(meshed: Vec<Part>, fine: Region, how: &Meshing) -> Vec<Part> {
    let mut again = Vec::new();
    for (k, (name, _, one, _, _)) in meshed.iter().enumerate() {
        (how.say)(format!("mesh: part {} again, material `{name}`", k + 1));
        let progress = |stage: &'static str, f: f64| {
            (how.progress)(stage, (k as f64 + f) / meshed.len() as f64)
        };
        match how.surface_on(one, fine, &progress) {
            Ok(m) => again.push(m),
            Err((_, why)) => {
                for (_, _, _, thin, coarse) in &meshed {
                    thin.refused(&coarse.stats, &why, how.say);
                }
                return meshed;
            }
        }
    }
    meshed
        .into_iter()
        .zip(again)
        .map(|((name, material, one, thin, coarse), m)| {
            let m = refined(&thin, coarse, m, how.say);
            (name, material, one, thin, m)
        })
        .collect()
}

/// A surface meshed by [`surface`]: the mesh in the scene's coordinates, its grid, what
/// meshing did and how long it took.
#[derive(Debug)]
pub struct Meshed {
    /// The mesh.
    pub mesh: Mesh,
    /// What meshing did.
    pub stats: Stats,
    /// The grid it was meshed on.
    pub grid: Grid,
    /// Seconds from the octree's start to the mesh.
    pub seconds: f64,
}

/// Meshes a checked scene's surface over `region` within `limits` on `pool`: what `sdfc
/// mesh` does before it writes the file (and what the Python package's `Scene.mesh` calls).
/// `progress` gets the stage's name and the fraction done of the whole; `say` the
/// announcements and warnings. `Err` is the exit code (2 for a usage problem, 1 for a scene
/// or limit that refuses the mesh) and the message (empty when already reported).
///
/// Where the grid misses walls or gaps thinner than a cell ([`crate::mesh::thin`]), the
/// surface is meshed again on a grid fine enough for them ([`Thinness`]) when the
/// limits allow it; what is still thinner than the cells is reported with its place and
/// the cell that resolves it.
pub fn surface(
    checked: &frontend::Checked,
    region: Region,
    settings: &Settings,
    limits: &Limits,
    pool: &rayon::ThreadPool,
    progress: &(dyn Fn(&'static str, f64) + Sync),
    say: &(dyn Fn(String) + Sync),
) -> Result<Meshed, (u8, String)> {
    let how = Meshing {
        settings,
        limits,
        pool,
        progress,
        say,
    };
    let coarse = how.surface_on(checked, region, progress)?;
    let thin = Thinness::new(checked, region, coarse.grid.voxel);
    let Some(fine) = finer(&thin, &coarse, settings, limits, region.spelling, say) else {
        return Ok(coarse);
    };
    match how.surface_on(checked, fine, progress) {
        Ok(fine) => Ok(refined(&thin, coarse, fine, say)),
        Err((_, why)) => {
            thin.refused(&coarse.stats, &why, say);
            Ok(coarse)
        }
    }
}

/// The region to mesh `coarse` again on where it missed walls or gaps thinner than a cell
/// (`None` with a warning where the limits or `--set thin=off` leave it as it is).
fn finer(
    thin: &Thinness,
    coarse: &Meshed,
    settings: &Settings,
    limits: &Limits,
    spell: Spelling,
    say: &(dyn Fn(String) + Sync),
) -> Option<Region> {
    if !settings.thin {
        thin.still(coarse.grid.voxel, &coarse.stats, say);
        return None;
    }
    let fits = |bytes: u64| check_memory(bytes, limits, spell).is_ok();
    thin.again(&coarse.grid, &coarse.stats, limits, &fits, say)
}

/// `fine`, meshed again after `coarse`: its time the two's, and what it still misses said.
fn refined(
    thin: &Thinness,
    coarse: Meshed,
    mut fine: Meshed,
    say: &(dyn Fn(String) + Sync),
) -> Meshed {
    fine.seconds += coarse.seconds;
    fine.stats.refined_from = Some(coarse.grid.voxel);
    fine.stats.before = coarse.stats.before;
    fine.stats.evaluating += coarse.stats.evaluating;
    fine.stats.launches += coarse.stats.launches;
    thin.still(fine.grid.voxel, &fine.stats, say);
    fine
}

impl Meshing<'_> {
    /// [`surface`] of `checked` over `region` on one grid, its progress told to `progress`.
    fn surface_on(
        &self,
        checked: &frontend::Checked,
        region: Region,
        progress: &(dyn Fn(&'static str, f64) + Sync),
    ) -> Result<Meshed, (u8, String)> {
        let Meshing {
            settings,
            limits,
            pool,
            say,
            ..
        } = *self;
        let analysis = analysis::analyse(&checked.scene);
        let Frame {
            clip,
            voxel,
            proven,
        } = frame(checked, &analysis, region, say)?;
        let spell = region.spelling;
        let resolution_opt = spell.option("resolution");
        let origin = checked.scene.origin;
        let grid = Grid::over(&clip, voxel);
        let lowered = checked
            .lower(&LowerOptions::default(), limits)
            .map_err(|_| (1, String::new()))?;
        let field = field_on(checked, &lowered, (proven, clip), settings, say)?;
        if !proven {
            say(format!(
            "warning: the scene's distance field has no proven bound{}, so no cell can be ruled out; meshing the dense grid of {} cells",
            cause(checked, &analysis),
            grid.dense_cells()
        ));
        }
        let max_cells = limits.get(Limit::Cells);
        let octree_bytes = octree::bytes(&grid, proven, max_cells);
        let [nx, ny, nz] = grid.cells;
        say(format!(
            "mesh: {nx}x{ny}x{nz} cells of {}: allocating at most {} MiB to find the surface",
            short(voxel),
            mib(octree_bytes)
        ));
        check_memory(octree_bytes, limits, spell).map_err(|m| (1, m))?;
        let stage = |name: &'static str, base: f64, share: f64| {
            move |f: f64| progress(name, base + share * f)
        };
        // The most candidates whose corners the memory limit lets contouring hold: the octree
        // stops at the first level that proves more, with the message the check after it gives.
        let fits = |n: u64| check_memory(contour::candidate_bytes(&grid, n), limits, spell).is_ok();
        let max_candidates = most(fits);
        let started = Instant::now();
        let before = super::started().0.elapsed().as_secs_f64();
        let candidates = pool
        .install(|| {
            octree::candidates(
                &field,
                &grid,
                max_cells,
                max_candidates,
                &stage("octree", 0.0, 0.3),
            )
        })
        .map_err(|refused| match refused {
            octree::Refused::Cells(n) => (
                1,
                format!(
                    "meshing would evaluate {n} cells or more, more than the cells limit of {max_cells}; {} (or mesh at a lower {resolution_opt})",
                    limits.raise_to(Limit::Cells, n)
                ),
            ),
            octree::Refused::Candidates(n) => (
                1,
                refuse_memory(contour::candidate_bytes(&grid, n), true, limits, spell),
            ),
        })?;
        let n = candidates.cells.len() as u64;
        let bound = contour::candidate_bytes(&grid, n);
        say(format!(
            "mesh: {n} cells may hold surface: allocating at most {} MiB for their corners",
            mib(bound)
        ));
        check_memory(bound, limits, spell).map_err(|m| (1, m))?;
        let surface_check = |cells: u64| {
            let total = bound.saturating_add(cells.saturating_mul(BYTES_PER_SURFACE_CELL));
            say(format!(
                "mesh: {cells} cells hold surface: allocating at most {} MiB in all",
                mib(total)
            ));
            check_memory(total, limits, spell)
        };
        // The cells the closure may hold: as many as the memory limit allows at 52 bytes each
        // (a key and a point), within the cells limit.
        let memory_cells = (limits.get(Limit::Memory).saturating_mul(MIB) / 52).min(max_cells);
        let octree_evaluated = candidates.evaluated;
        let result = pool.install(|| {
            contour::contour(
                &field,
                &grid,
                candidates,
                settings,
                memory_cells,
                &surface_check,
                &stage("contour", 0.3, 0.7),
            )
        });
        let (mut mesh, mut stats): (Mesh, Stats) = result.map_err(|stop| match stop {
        Stop::Refused(msg) => (1, msg),
        Stop::Cells(cells) => (
            1,
            format!(
                "the surface reaches {cells} cells, more than the cells and memory limits allow ({memory_cells}); {}",
                limits.raise_to(Limit::Cells, cells)
            ),
        ),
    })?;
        let seconds = started.elapsed().as_secs_f64();
        if let Some(gpu) = field.gpu() {
            if let Some(why) = gpu.failure() {
                return Err((
                    1,
                    format!("--backend {} failed while meshing: {why}", gpu.name),
                ));
            }
            stats.backend = gpu.name;
            stats.launches = gpu.launches();
        } else {
            stats.backend = "cpu";
        }
        stats.before = Some(before);
        stats.evaluating = field.evaluating();
        if settings.measure {
            // Measured in f64 by the CPU, whatever evaluated the mesh.
            let exact = Field::new(&lowered.program, proven, clip);
            stats.error = Some(pool.install(|| crate::mesh::error(&exact, &mesh)));
        }
        stats.octree_cells = octree_evaluated;
        stats.dense = !proven;
        for p in &mut mesh.positions {
            *p = [0, 1, 2].map(|i| p[i] + origin[i]);
        }
        Ok(Meshed {
            mesh,
            stats,
            grid,
            seconds,
        })
    }
}

/// The field of `lowered` over `clip`, evaluated by the CPU or the GPU `settings` name.
fn field_on(
    checked: &frontend::Checked,
    lowered: &sdfc_compiler::Lowered,
    (proven, clip): (bool, [[f64; 3]; 2]),
    settings: &Settings,
    say: &(dyn Fn(String) + Sync),
) -> Result<Field, (u8, String)> {
    let field = Field::new(&lowered.program, proven, clip);
    Ok(match settings.backend {
        Backend::Cpu | Backend::Auto => field,
        backend => {
            let gpu = Gpu::open(backend, &checked.scene, lowered, &clip)
                .map_err(|e| (1, e.to_string()))?;
            // Once a process: the parts of a 3MF and a finer mesh share the device.
            static SAID: std::sync::Once = std::sync::Once::new();
            SAID.call_once(|| say(format!("mesh: evaluating on {}: {}", gpu.name, gpu.device)));
            field.on(gpu)
        }
    })
}

/// The `--stats` report.
pub fn describe(grid: &Grid, s: &Stats, seconds: f64) -> String {
    let dense = grid.dense_points() as f64;
    format!(
        "grid            {}x{}x{} cells of {}{}\n\
         octree cells    {} evaluated{}\n\
         candidates      {} cells ({} added by crossed edges)\n\
         surface cells   {}\n\
         evaluations     {} points ({:.2} % of the dense grid's {} points) on {}{}, {:.3} s\n\
         sharp patches   {} ({} edges flipped, {} inner vertices projected onto the surface)\n\
         {}{}{}\
         time            {:.3} s\n",
        grid.cells[0],
        grid.cells[1],
        grid.cells[2],
        short(grid.voxel),
        match s.refined_from {
            Some(v) => format!(
                " (refined from cells of {}: walls or gaps thinner than a cell)",
                short(v)
            ),
            None => String::new(),
        },
        s.octree_cells,
        if s.dense {
            " (no proven bound: dense grid)"
        } else {
            ""
        },
        s.candidates,
        s.added,
        s.surface_cells,
        s.evaluated,
        100.0 * s.evaluated as f64 / dense,
        grid.dense_points(),
        if s.backend.is_empty() { "cpu" } else { s.backend },
        match s.launches {
            0 => String::new(),
            n => format!(", in {n} launches"),
        },
        s.evaluating,
        s.features,
        s.flips,
        s.projected,
        match s.thin {
            Some(t) => format!(
                "thin features   {} grid edges cross a wall or gap twice; the thinnest {} ({:.1} % of a cell)\n",
                t.edges,
                short(t.thinnest),
                100.0 * t.thinnest / grid.voxel
            ),
            None => String::new(),
        },
        match s.error {
            Some([v, f]) => format!(
                "distance        vertices {} ({:.2} % of a cell), triangle centres {} ({:.2} %): the largest |f| (exact fields: the distance to the surface)\n",
                short(v),
                100.0 * v / grid.voxel,
                short(f),
                100.0 * f / grid.voxel
            ),
            None => String::new(),
        },
        match s.before {
            Some(b) => format!(
                "before meshing  {b:.3} s (reading, checking, lowering{})\n",
                if s.launches > 0 {
                    ", the device and its kernel"
                } else {
                    ""
                }
            ),
            None => String::new(),
        },
        seconds
    )
}

/// The largest `n` for which `fits(n)` holds (`fits` true up to some `n`, false beyond; 0
/// when it fails at 1).
fn most(fits: impl Fn(u64) -> bool) -> u64 {
    let (mut lo, mut hi) = (0u64, 1u64 << 50);
    if fits(hi) {
        return hi;
    }
    // fits(lo) is taken as true, fits(hi) is false.
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if fits(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

fn check_memory(bytes: u64, limits: &Limits, spell: Spelling) -> Result<(), String> {
    if mib(bytes) <= limits.get(Limit::Memory) {
        return Ok(());
    }
    Err(refuse_memory(bytes, false, limits, spell))
}

/// The message of a mesh refused by the memory limit, needing `bytes`: the bound announced,
/// or with `lower`, a lower bound of it (the octree proved enough surface before its end).
fn refuse_memory(bytes: u64, lower: bool, limits: &Limits, spell: Spelling) -> String {
    let needed = mib(bytes);
    let amount = if lower {
        format!("{needed} MiB or more")
    } else {
        format!("up to {needed} MiB")
    };
    format!(
        "the mesh would allocate {amount}, more than the memory limit of {} MiB; {} (or mesh at a lower {})",
        limits.get(Limit::Memory),
        limits.raise_to(Limit::Memory, needed),
        spell.option("resolution")
    )
}

/// ` (the fractal at FILE:LINE:COL)` for the node that left the bound unproven.
fn cause(checked: &frontend::Checked, a: &analysis::Analysis) -> String {
    let Some(id) = a.root().and_then(|r| r.cause) else {
        return String::new();
    };
    let scene = &checked.scene;
    let span = scene.graph.span(id);
    let (line, col) = checked.sources.line_col(span);
    format!(
        " (the {} at {}:{line}:{col})",
        analysis::kind(scene.graph.node(id)),
        checked.sources.name(span.file)
    )
}

/// The mesh settings of `--set`.
pub(super) fn settings(sets: &[String]) -> Result<Settings, String> {
    let mut s = Settings::default();
    for item in sets {
        let (key, value) = item
            .split_once('=')
            .ok_or_else(|| format!("--set expects KEY=VALUE, like sharp=off, not `{item}`"))?;
        match (key.trim(), value.trim()) {
            ("sharp", "on" | "true") => s.sharp = true,
            ("sharp", "off" | "false") => s.sharp = false,
            ("sharp", v) => return Err(format!("sharp must be on or off, not `{v}`")),
            ("thin", "on" | "true") => s.thin = true,
            ("thin", "off" | "false") => s.thin = false,
            ("thin", v) => return Err(format!("thin must be on or off, not `{v}`")),
            ("refine", v) => {
                s.refine = v.parse::<u32>().ok().filter(|n| *n <= 50).ok_or_else(|| {
                    format!("refine must be a whole number from 0 to 50, not `{v}`")
                })?
            }
            (k, _) => {
                return Err(format!(
                    "unknown mesh setting `{k}`; the settings are sharp, refine, thin"
                ))
            }
        }
    }
    Ok(s)
}
