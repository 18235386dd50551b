//! `sdfc mesh` and walls or gaps thinner than a cell (`crate::mesh::thin`): the surface meshed
//! again on a grid fine enough for them, when the memory and cells limits allow it, and a
//! warning with the place and the cell that resolves what is still thinner than the cells.

use super::mesh_region::{short, Region, DEFAULT_RESOLUTION};
use crate::frontend;
use crate::mesh::contour::{candidate_bytes, BYTES_PER_SURFACE_CELL};
use crate::mesh::thin::Thin;
use crate::mesh::{Grid, Stats};
use sdfc_compiler::{Limit, Limits};

/// A feature is resolved by cells of at most this share of its thickness: two grid points
/// fall inside a wall along most edges across it, and its two faces are in different cells.
const CELLS_PER_THICKNESS: f64 = 0.9;

/// Where a mesh of `region` missed thin walls or gaps: what to say about them.
#[derive(Debug, Clone, Copy)]
pub struct Thinness {
    /// The scene's origin (the field's coordinates are the scene's less it).
    origin: [f64; 3],
    region: Region,
    /// The cell of the grid first meshed.
    voxel: f64,
}

impl Thinness {
    /// For a mesh of `checked` over `region` on cells of `voxel`.
    pub fn new(checked: &frontend::Checked, region: Region, voxel: f64) -> Self {
        Thinness {
            origin: checked.scene.origin,
            region,
            voxel,
        }
    }

    /// The region to mesh again, where the grid of `stats` missed thin walls or gaps: cells
    /// of [`CELLS_PER_THICKNESS`] of their thickness (the cell divided by a whole number),
    /// when the fine grid's surface (the coarse one's, scaled by the area a cell covers) fits
    /// the memory limit (`fits`, of bytes) and the cells limit, announced. `None` where none
    /// was missed, or with a warning, where the limits leave no room.
    pub fn again(
        &self,
        grid: &Grid,
        stats: &Stats,
        limits: &Limits,
        fits: &dyn Fn(u64) -> bool,
        say: &(dyn Fn(String) + Sync),
    ) -> Option<Region> {
        let thin = stats.thin?;
        let finer = divisions(self.voxel, thin.thickness);
        let fine_voxel = self.voxel / finer as f64;
        let area = (finer as u64).saturating_mul(finer as u64);
        let fine_grid = Grid {
            voxel: fine_voxel,
            cells: grid.cells.map(|n| n.saturating_mul(finer)),
            ..*grid
        };
        let candidates = stats
            .candidates
            .saturating_add(stats.added)
            .saturating_mul(area);
        let bytes = candidate_bytes(&fine_grid, candidates).saturating_add(
            stats
                .surface_cells
                .saturating_mul(area)
                .saturating_mul(BYTES_PER_SURFACE_CELL),
        );
        let cells = stats
            .octree_cells
            .saturating_mul(area)
            .saturating_add(candidates);
        let refused = if !fits(bytes) {
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
            self.warn(&thin, self.voxel, &why, say);
            return None;
        }
        say(format!(
            "mesh: {} grid edges cross a wall or gap thinner than a cell (about {} thick at {}): meshing again with cells of {}",
            thin.edges,
            short(thin.thickness),
            self.place(&thin),
            short(fine_voxel)
        ));
        Some(Region {
            voxel: Some(fine_voxel),
            resolution: None,
            ..self.region
        })
    }

    /// After the mesh again on cells of `voxel`, with `stats`: what is still thinner.
    pub fn still(&self, voxel: f64, stats: &Stats, say: &(dyn Fn(String) + Sync)) {
        if let Some(t) = stats.thin {
            self.warn(&t, voxel, "", say);
        }
    }

    /// The mesh again refused (`why`): what the first grid, with `stats`, missed.
    pub fn refused(&self, stats: &Stats, why: &str, say: &(dyn Fn(String) + Sync)) {
        say(format!(
            "warning: not meshed again with cells finer than {}: {why}",
            short(self.voxel)
        ));
        if let Some(t) = stats.thin {
            self.warn(&t, self.voxel, "", say);
        }
    }

    fn place(&self, t: &Thin) -> String {
        let at = [0, 1, 2].map(|i| short(t.at[i] + self.origin[i]));
        format!("({}, {}, {})", at[0], at[1], at[2])
    }

    /// `--voxel V` or, where the cell came from a resolution, `--resolution N` too.
    fn resolves(&self, t: &Thin, v: f64) -> String {
        let spell = self.region.spelling;
        let needed = v / divisions(v, t.thickness) as f64;
        let by_resolution = match self.region.voxel {
            None => format!(
                " or {} {}",
                spell.option("resolution"),
                (self.region.resolution.unwrap_or(DEFAULT_RESOLUTION) as f64 * self.voxel / needed)
                    .round() as u64
            ),
            Some(_) => String::new(),
        };
        format!("{} {}{by_resolution}", spell.option("voxel"), short(needed))
    }

    fn warn(&self, t: &Thin, v: f64, why: &str, say: &(dyn Fn(String) + Sync)) {
        say(format!(
            "warning: a wall or gap about {} thick at {} is thinner than the cells of {}{why} ({} grid edges cross such features twice; the thinnest is {}): the mesh may lack it, or hold it with holes or in pieces; {} resolves it",
            short(t.thickness),
            self.place(t),
            short(v),
            t.edges,
            short(t.thinnest),
            self.resolves(t, v)
        ))
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
