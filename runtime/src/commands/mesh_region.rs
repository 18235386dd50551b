//! The region `sdfc mesh` meshes and the size of its cells: `--bounds`, `--resolution` and
//! `--voxel` checked against the scene's bounds from the analysis, and the messages that
//! name them (an unbounded scene's, with the bounds of its bounded parts).

use crate::frontend;
use crate::mesh::{Grid, AXIS_CELLS};
pub use sdfc_compiler::Spelling;
use sdfc_compiler::{analysis, Combine, Node, NodeId, Scene};

/// The default number of cells along the longest side.
pub const DEFAULT_RESOLUTION: u32 = 128;

/// The region `surface` meshes and the size of its cells (`--resolution`, `--voxel`,
/// `--bounds`; all `None`: the analysis's box at [`DEFAULT_RESOLUTION`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Region {
    /// Cells along the longest side of the bounds.
    pub resolution: Option<u32>,
    /// Edge of a cell, in scene units (instead of `resolution`).
    pub voxel: Option<f64>,
    /// The region to mesh (min, max), in the scene's coordinates.
    pub bounds: Option<[[f64; 3]; 2]>,
    /// How the messages name these options (the limits' as the limits say,
    /// [`Limits::spelling`]).
    pub spelling: Spelling,
}

/// A region given by its corners' coordinates, as the caller of [`surface`] writes it:
/// `sdfc mesh`'s flag (`--bounds=X0,Y0,Z0,X1,Y1,Z1`) or the parameter of the Python package's
/// `Scene.mesh` (`bounds=((x0, y0, z0), (x1, y1, z1))`).
fn bounds(spell: Spelling, lo: [&str; 3], hi: [&str; 3]) -> String {
    match spell {
        // With `=`: a negative first coordinate is not taken for a flag.
        Spelling::Flags => format!("--bounds={},{}", lo.join(","), hi.join(",")),
        Spelling::Parameters => {
            format!("bounds=(({}), ({}))", lo.join(", "), hi.join(", "))
        }
    }
}

/// The clip box (in the program's coordinates) and the cell of a mesh of `checked` over
/// `region`, and whether the field's bound is proven.
#[derive(Debug, Clone, Copy)]
pub struct Frame {
    /// The clip box, in the program's coordinates (the scene's, less its origin).
    pub clip: [[f64; 3]; 2],
    /// The edge of a cell.
    pub voxel: f64,
    /// Whether the field's bound is proven.
    pub proven: bool,
}

/// The [`Frame`] of [`surface`]: the region checked against the scene's bounds (the
/// analysis's, `analysis`), its cell from `--resolution` or `--voxel`.
pub fn frame(
    checked: &frontend::Checked,
    analysis: &analysis::Analysis,
    region: Region,
    say: &(dyn Fn(String) + Sync),
) -> Result<Frame, (u8, String)> {
    let usage = |msg: String| (2u8, msg);
    let spell = region.spelling;
    let [bounds_opt, resolution_opt, voxel_opt] =
        ["bounds", "resolution", "voxel"].map(|n| spell.option(n));
    let scene = &checked.scene;
    let Some(root) = analysis.root() else {
        return Err((
            1,
            "the scene has no objects: there is no surface to mesh".into(),
        ));
    };
    let origin = scene.origin;
    let b = root.bounds;
    // Known empty (an intersection of parts that do not meet, a profile revolved from beyond
    // its axis): no grid would find a surface, whatever its cells (it was told to try a
    // higher resolution, or that the scene was unbounded).
    if b.is_empty() {
        return Err((
            1,
            "the scene's solid is empty (its parts' bounds leave no point inside it): there is no surface to mesh".into(),
        ));
    }
    // The clip box and the grid, in the program's coordinates (the scene's, less `origin`).
    let clip = match region.bounds {
        Some([lo, hi]) => {
            let clip = [lo, hi].map(|c| [0, 1, 2].map(|i| c[i] - origin[i]));
            let apart = (0..3).any(|i| b.min[i] > clip[1][i] || b.max[i] < clip[0][i]);
            if apart {
                let at = |c: [f64; 3]| [0, 1, 2].map(|i| short(c[i] + origin[i]));
                let (lo, hi) = (at(b.min), at(b.max));
                return Err((
                    1,
                    format!(
                        "the region given with {bounds_opt} does not reach the scene's solid, which lies within `{}`: there is no surface to mesh in it",
                        bounds(spell, lo.each_ref().map(|s| s.as_str()), hi.each_ref().map(|s| s.as_str()))
                    ),
                ));
            }
            clip
        }
        None => {
            let open: Vec<&str> = ["x", "y", "z"]
                .into_iter()
                .enumerate()
                .filter(|&(i, _)| !(b.min[i].is_finite() && b.max[i].is_finite()))
                .map(|(_, a)| a)
                .collect();
            if !open.is_empty() {
                let hint = match bounded_part(scene, analysis) {
                    Some([lo, hi]) => {
                        // Grown by a tenth of the largest extent, so that what the box cuts
                        // (a floor plane) keeps some thickness.
                        let m = 0.1 * (0..3).map(|i| hi[i] - lo[i]).fold(0.0, f64::max);
                        let lo = [0, 1, 2].map(|i| short(lo[i] - m + origin[i]));
                        let hi = [0, 1, 2].map(|i| short(hi[i] + m + origin[i]));
                        format!(
                            "; its bounded objects with a margin are `{}`",
                            bounds(
                                spell,
                                lo.each_ref().map(|s| s.as_str()),
                                hi.each_ref().map(|s| s.as_str())
                            )
                        )
                    }
                    None => String::new(),
                };
                let corners = match spell {
                    Spelling::Flags => "--bounds X0,Y0,Z0,X1,Y1,Z1".to_string(),
                    Spelling::Parameters => bounds(spell, ["x0", "y0", "z0"], ["x1", "y1", "z1"]),
                };
                return Err(usage(format!(
                    "the scene is unbounded along {}: {}; give the region to mesh with `{corners}` (what reaches out of it is cut at its faces and the cut closed){hint}",
                    open.join(", "),
                    unbounded_parts(checked, analysis)
                )));
            }
            [b.min, b.max]
        }
    };
    let size = [0, 1, 2].map(|i| clip[1][i] - clip[0][i]);
    let longest = size.iter().copied().fold(0.0f64, f64::max);
    let voxel = match (region.voxel, region.resolution) {
        (Some(v), _) if v.is_finite() && v > 0.0 => v,
        (Some(v), _) => {
            return Err(usage(format!(
                "{voxel_opt} must be a positive number, not {v}"
            )))
        }
        (None, Some(0)) => return Err(usage(format!("{resolution_opt} must be at least 1"))),
        (None, r) => longest / r.unwrap_or(DEFAULT_RESOLUTION) as f64,
    };
    if !(voxel > 0.0 && voxel.is_finite()) {
        return Err(usage(format!(
            "the bounds are flat: give a region with some extent along every axis (`{bounds_opt}`)"
        )));
    }
    // Without --bounds the box is the analysis's, grown by a cell so that the clip never
    // touches the surface; one more cell all round is outside the clip, which closes the mesh.
    let clip = match region.bounds {
        Some(_) => clip,
        None => [clip[0].map(|x| x - voxel), clip[1].map(|x| x + voxel)],
    };
    let cells = Grid::cells_over(&clip, voxel);
    if cells.iter().any(|&n| n > AXIS_CELLS as f64) {
        return Err(usage(format!(
            "the grid would have {} cells along an axis; at most {AXIS_CELLS} are possible (a larger {voxel_opt} or a smaller {resolution_opt})",
            cells.iter().copied().fold(0.0f64, f64::max)
        )));
    }
    // Vertices are kept 10⁻³ of a cell apart; the files store f32 coordinates.
    let magnitude = clip
        .iter()
        .flatten()
        .map(|x| x.abs())
        .chain(origin.iter().map(|x| x.abs()))
        .fold(0.0f64, f64::max);
    if 1e-3 * voxel < 8.0 * f32::EPSILON as f64 * magnitude {
        say(format!(
            "warning: a cell of {} is too small for the f32 coordinates of mesh files at {}: vertices may share positions",
            short(voxel),
            short(magnitude)
        ));
    }
    Ok(Frame {
        clip,
        voxel,
        proven: root.proven,
    })
}

/// A length for a message: four decimals, or for a small one (a cell of 10⁻⁵) three
/// significant digits in scientific notation, never `0`.
pub fn short(x: f64) -> String {
    if x != 0.0 && x.abs() < 1e-3 {
        return sdfc_compiler::diagnostics::scientific(x);
    }
    sdfc_compiler::diagnostics::number(x, 4)
}

/// The objects that make the scene unbounded, for the message: each top-level object
/// (through the scene's top-level unions and paints) whose box is infinite, named by the
/// innermost node of it that is (`the plane at FILE:LINE:COL`, a field inside a translation),
/// with the axes it is unbounded along; a field's box is what its formula proves by interval
/// arithmetic, so a field is said to prove none. At most three, and how many more.
fn unbounded_parts(checked: &frontend::Checked, a: &analysis::Analysis) -> String {
    let scene = &checked.scene;
    let open = |id: NodeId| {
        let b = a.node(id).bounds;
        ["x", "y", "z"]
            .into_iter()
            .enumerate()
            .filter(|&(i, _)| !(b.min[i].is_finite() && b.max[i].is_finite()))
            .map(|(_, x)| x)
            .collect::<Vec<_>>()
    };
    let mut found = Vec::new();
    let mut stack: Vec<NodeId> = scene.root.into_iter().collect();
    while let Some(id) = stack.pop() {
        match scene.graph.node(id) {
            Node::Combine {
                op: Combine::Union,
                children,
            } => stack.extend(children.iter().rev().copied()),
            Node::Paint { child, .. } => stack.push(*child),
            _ if open(id).is_empty() => {}
            _ => {
                let mut at = id;
                while let Some(c) = scene
                    .graph
                    .node(at)
                    .children()
                    .into_iter()
                    .find(|&c| !open(c).is_empty())
                {
                    at = c;
                }
                let node = scene.graph.node(at);
                let span = scene.graph.span(at);
                let (line, col) = checked.sources.line_col(span);
                let axes = open(at).join(", ");
                let how = match node {
                    Node::Field { .. } => format!("whose formula proves no bound along {axes}"),
                    _ => format!("unbounded along {axes}"),
                };
                found.push(format!(
                    "the {} at {}:{line}:{col} ({how})",
                    analysis::kind(node),
                    checked.sources.name(span.file)
                ));
            }
        }
    }
    let more = found.len().saturating_sub(3);
    found.truncate(3);
    let mut text = found.join(", ");
    if more > 0 {
        text.push_str(&format!(" and {more} more"));
    }
    text
}

/// The box around the scene's bounded objects: the objects of its top-level unions whose
/// bounding box is finite (`None` when there are none).
fn bounded_part(scene: &Scene, a: &analysis::Analysis) -> Option<[[f64; 3]; 2]> {
    let mut stack: Vec<NodeId> = scene.root.into_iter().collect();
    let mut found: Option<[[f64; 3]; 2]> = None;
    while let Some(id) = stack.pop() {
        let b = a.node(id).bounds;
        let finite = (0..3).all(|i| b.min[i].is_finite() && b.max[i].is_finite());
        if finite && !b.is_empty() {
            found = Some(match found {
                None => [b.min, b.max],
                Some([lo, hi]) => [
                    [0, 1, 2].map(|i| lo[i].min(b.min[i])),
                    [0, 1, 2].map(|i| hi[i].max(b.max[i])),
                ],
            });
            continue;
        }
        match scene.graph.node(id) {
            Node::Combine {
                op: Combine::Union,
                children,
            } => stack.extend(children.iter().copied()),
            Node::Paint { child, .. } => stack.push(*child),
            _ => {}
        }
    }
    found
}

/// Why `--bounds` is refused ([`parse_bounds`]); each names the text given.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BoundsError {
    /// A part is not a number.
    #[error("expected six numbers X0,Y0,Z0,X1,Y1,Z1, not `{0}`")]
    NotNumbers(String),
    /// Not six numbers, or one not finite.
    #[error("expected six finite numbers X0,Y0,Z0,X1,Y1,Z1, not `{0}`")]
    NotSixFinite(String),
    /// A lower bound not below its upper one.
    #[error("each lower bound must be below the upper one (X0 < X1, Y0 < Y1, Z0 < Z1), not `{0}`")]
    Reversed(String),
}

/// Parses `X0,Y0,Z0,X1,Y1,Z1` into (min, max).
pub fn parse_bounds(s: &str) -> Result<[[f64; 3]; 2], BoundsError> {
    let v: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| BoundsError::NotNumbers(s.to_string()))?;
    if v.len() != 6 || v.iter().any(|x| !x.is_finite()) {
        return Err(BoundsError::NotSixFinite(s.to_string()));
    }
    let (lo, hi) = ([v[0], v[1], v[2]], [v[3], v[4], v[5]]);
    if (0..3).any(|i| !(lo[i] < hi[i])) {
        return Err(BoundsError::Reversed(s.to_string()));
    }
    Ok([lo, hi])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `--bounds` takes six finite numbers, each lower below its upper, and says which rule
    /// a refused text breaks.
    #[test]
    fn bounds_are_six_numbers_in_order() {
        assert_eq!(
            parse_bounds("-1, 0,-2,1,0.5,2"),
            Ok([[-1.0, 0.0, -2.0], [1.0, 0.5, 2.0]])
        );
        let refused = |s: &str| parse_bounds(s).unwrap_err();
        assert_eq!(
            refused("1,2,x,4,5,6"),
            BoundsError::NotNumbers("1,2,x,4,5,6".into())
        );
        assert_eq!(refused("1,2,3"), BoundsError::NotSixFinite("1,2,3".into()));
        assert_eq!(
            refused("0,0,0,1,inf,1"),
            BoundsError::NotSixFinite("0,0,0,1,inf,1".into())
        );
        assert_eq!(
            refused("1,0,0,0,1,1"),
            BoundsError::Reversed("1,0,0,0,1,1".into())
        );
        assert!(refused("1,0,0,1,1,1").to_string().contains("X0 < X1"));
    }
}
