//! `sdfc mesh` and walls or gaps thinner than a cell (`crate::mesh::thin`): the surface meshed
//! again on a grid fine enough for them, when the memory and cells limits allow it, and a
//! warning with the place and the cell that resolves what is still thinner than the cells.

use super::mesh::{check_memory, Meshed};
use super::mesh_region::{short, Region, DEFAULT_RESOLUTION};
use crate::frontend;
use crate::mesh::contour::{candidate_bytes, BYTES_PER_SURFACE_CELL};
use crate::mesh::thin::Thin;
use crate::mesh::Grid;
use sdfc_compiler::{Limit, Limits};

/// A feature is resolved by cells of at most this share of its thickness: two grid points
/// fall inside a wall along most edges across it, and its two faces are in different cells.
const CELLS_PER_THICKNESS: f64 = 0.9;

/// The mesh of `coarse`, or where its grid missed thin walls or gaps, the surface meshed
/// again by `again` on a grid of cells [`CELLS_PER_THICKNESS`] of their thickness (the cell
/// divided by a whole number), when the fine grid's surface (the coarse one's, scaled by the
/// area a cell covers) fits the memory and cells limits. What stays thinner than the cells
/// (too thin for the limits, or thinner than the fine grid's cells) is reported by `say`
/// with its place and the `--voxel` (and `--resolution`) that resolves it.
pub fn refine(
    checked: &frontend::Checked,
    region: Region,
    limits: &Limits,
    coarse: Meshed,
    again: &dyn Fn(Region) -> Result<Meshed, (u8, String)>,
    say: &(dyn Fn(String) + Sync),
) -> Result<Meshed, (u8, String)> {
    let Some(thin) = coarse.stats.thin else {
        return Ok(coarse);
    };
    let spell = region.spelling;
    let origin = checked.scene.origin;
    let voxel = coarse.grid.voxel;
    let finer = divisions(voxel, thin.thickness);
    let fine_voxel = voxel / finer as f64;
    let place = |t: &Thin| {
        let at = [0, 1, 2].map(|i| short(t.at[i] + origin[i]));
        format!("({}, {}, {})", at[0], at[1], at[2])
    };
    // `--voxel V` or, where the cell came from a resolution, `--resolution N` too.
    let resolves = |t: &Thin, v: f64| {
        let k = divisions(v, t.thickness);
        let needed = v / k as f64;
        let by_resolution = match region.voxel {
            None => format!(
                " or {} {}",
                spell.option("resolution"),
                (region.resolution.unwrap_or(DEFAULT_RESOLUTION) as f64 * voxel / needed).round()
                    as u64
            ),
            Some(_) => String::new(),
        };
        format!("{} {}{by_resolution}", spell.option("voxel"), short(needed))
    };
    let warn = |t: &Thin, v: f64, why: &str| {
        say(format!(
            "warning: a wall or gap about {} thick at {} is thinner than the cells of {}{why} ({} grid edges cross such features twice; the thinnest is {}): the mesh may lack it, or hold it with holes or in pieces; {} resolves it",
            short(t.thickness),
            place(t),
            short(v),
            t.edges,
            short(t.thinnest),
            resolves(t, v)
        ))
    };
    // The fine grid's surface, from the coarse one's: cells scale with the area they cover.
    let area = (finer * finer) as u64;
    let s = &coarse.stats;
    let fine_grid = Grid {
        voxel: fine_voxel,
        cells: coarse.grid.cells.map(|n| n.saturating_mul(finer)),
        ..coarse.grid
    };
    let candidates = s.candidates.saturating_add(s.added).saturating_mul(area);
    let bytes = candidate_bytes(&fine_grid, candidates).saturating_add(
        s.surface_cells
            .saturating_mul(area)
            .saturating_mul(BYTES_PER_SURFACE_CELL),
    );
    let cells = s
        .octree_cells
        .saturating_mul(area)
        .saturating_add(candidates);
    let refused = if check_memory(bytes, limits, spell).is_err() {
        Some(format!(
            ", and cells of {} for it would take about {} MiB, more than the memory limit of {} MiB",
            short(fine_voxel),
            crate::memory::mib(bytes),
            limits.get(Limit::Memory)
        ))
    } else if cells > limits.get(Limit::Cells) {
        Some(format!(
            ", and cells of {} for it would evaluate about {cells} cells, more than the cells limit of {}",
            short(fine_voxel),
            limits.get(Limit::Cells)
        ))
    } else {
        None
    };
    if let Some(why) = refused {
        warn(&thin, voxel, &why);
        return Ok(coarse);
    }
    say(format!(
        "mesh: {} grid edges cross a wall or gap thinner than a cell (about {} thick at {}): meshing again with cells of {}",
        thin.edges,
        short(thin.thickness),
        place(&thin),
        short(fine_voxel)
    ));
    let fine_region = Region {
        voxel: Some(fine_voxel),
        resolution: None,
        ..region
    };
    match again(fine_region) {
        Ok(mut fine) => {
            fine.seconds += coarse.seconds;
            fine.stats.refined_from = Some(voxel);
            if let Some(t) = fine.stats.thin {
                warn(&t, fine_voxel, "");
            }
            Ok(fine)
        }
        Err((_, why)) => {
            say(format!(
                "warning: not meshed again with cells of {}: {why}",
                short(fine_voxel)
            ));
            warn(&thin, voxel, "");
            Ok(coarse)
        }
    }
}

/// The whole number of parts to divide a cell `voxel` into for cells of at most
/// [`CELLS_PER_THICKNESS`] of `thickness` (at least 2).
fn divisions(voxel: f64, thickness: f64) -> u32 {
    let k = (voxel / (CELLS_PER_THICKNESS * thickness)).ceil();
    if k.is_finite() {
        k.clamp(2.0, u32::MAX as f64) as u32
    } else {
        u32::MAX
    }
}
