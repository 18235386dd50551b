//! `Scene.mesh` and `Scene.save` of the native module: the surface meshed as `sdfc mesh`
//! meshes it (`commands::mesh::surface`), as arrays or written to a mesh file in the format
//! its extension names, by the writers `sdfc mesh -o` uses.

use super::{bytes, pool, Failure, Scene};
use pyo3::exceptions::PyValueError;
use pyo3::PyResult;
use sdfc_runtime::commands::mesh as mesher;
use sdfc_runtime::frontend::Checked;
use sdfc_runtime::mesh::write::{Format, Palette, Unsaved, Up};
use sdfc_runtime::mesh::Mesh;
use std::path::Path;

/// What a mesh is asked for: the cells (`resolution` along the longest side, or `voxel` a
/// cell's edge), the region, sharp features, the time.
#[derive(Clone, Copy)]
pub struct Ask {
    resolution: Option<u32>,
    voxel: Option<f64>,
    bounds: Option<([f64; 3], [f64; 3])>,
    sharp: bool,
    t: f64,
}

impl Ask {
    /// The request, or `ValueError` for both `resolution` and `voxel` or bounds that are
    /// not a box.
    pub fn new(
        resolution: Option<u32>,
        voxel: Option<f64>,
        bounds: Option<([f64; 3], [f64; 3])>,
        sharp: bool,
        t: f64,
    ) -> PyResult<Ask> {
        if resolution.is_some() && voxel.is_some() {
            return Err(PyValueError::new_err("give resolution or voxel, not both"));
        }
        if let Some((lo, hi)) = bounds {
            if (0..3).any(|i| !(lo[i] < hi[i] && lo[i].is_finite() && hi[i].is_finite())) {
                return Err(PyValueError::new_err(
                    "bounds are ((x0, y0, z0), (x1, y1, z1)) with each lower bound below the upper one",
                ));
            }
        }
        Ok(Ask {
            resolution,
            voxel,
            bounds,
            sharp,
            t,
        })
    }
}

/// The scene's surface, and the checked scene it came from; the materials found where
/// the mesh goes to a file of `format` that carries them ([`Format::carries_materials`]),
/// or, without one, everywhere (the arrays' colours).
fn surface(scene: &Scene, ask: Ask, format: Option<Format>) -> Result<(Mesh, Checked), Failure> {
    let checked = scene.checked(ask.t, None, None)?;
    let region = mesher::Region {
        resolution: ask.resolution,
        voxel: ask.voxel,
        bounds: ask.bounds.map(|(lo, hi)| [lo, hi]),
        spelling: mesher::Spelling::Parameters,
    };
    let settings = sdfc_runtime::mesh::Settings {
        sharp: ask.sharp,
        materials: format.is_none_or(|f| f.carries_materials(&checked.scene)),
        ..Default::default()
    };
    let say = |text: String| {
        if text.starts_with("warning") {
            eprintln!("{text}");
        }
    };
    let meshed = mesher::surface(
        &checked,
        region,
        &settings,
        &scene.limits,
        pool()?,
        &|_, _| {},
        &say,
    )
    .map_err(|(code, msg)| match code {
        2 => Failure::Value(msg),
        _ if msg.is_empty() => Failure::Runtime("the mesh failed".into()),
        _ => Failure::Runtime(msg),
    })?;
    Ok((meshed.mesh, checked))
}

/// A mesh as bytes: positions (f64), triangles (u32), linear vertex colours (f32).
pub type Arrays = (Vec<u8>, Vec<u8>, Vec<u8>);

/// The mesh as [`Arrays`].
pub fn arrays(scene: &Scene, ask: Ask) -> Result<Arrays, Failure> {
    let (mesh, checked) = surface(scene, ask, None)?;
    let colours = sdfc_compiler::Colours::new(&checked.scene);
    let palette = Palette::new(&checked.scene, &colours);
    let p = bytes(mesh.positions.iter().flatten().copied());
    let tri = bytes(mesh.triangles.iter().flatten().copied());
    let c = bytes(
        palette
            .vertex_colours(&mesh, 0)
            .into_iter()
            .flatten()
            .map(|x| x as f32),
    );
    Ok((p, tri, c))
}

/// The axis `up=` names ("y" or "z"), as `sdfc mesh --up`.
pub fn up(name: &str) -> PyResult<Up> {
    match name {
        "y" => Ok(Up::Y),
        "z" => Ok(Up::Z),
        other => Err(PyValueError::new_err(format!(
            "up must be \"y\" (the scene's up) or \"z\" (a slicer's), not {other:?}"
        ))),
    }
}

/// Meshes and writes the file at `path` (replacing it whole, as `sdfc mesh -o` does) with
/// `up` up (`None`: the format's default, z for 3MF): (triangles, vertices). A name whose
/// format is unknown, a place that cannot be written and a mesh with no triangles are
/// refused, the last two before and without writing.
pub fn save(
    scene: &Scene,
    ask: Ask,
    path: &Path,
    up: Option<Up>,
) -> Result<(usize, usize), Failure> {
    let format = Format::of(path).ok_or_else(|| {
        Failure::Value(format!(
            "cannot tell the mesh format of `{}`; name it .stl, .obj, .ply, .glb or .3mf",
            path.display()
        ))
    })?;
    sdfc_runtime::output::check_writable(path)
        .map_err(|why| Failure::Value(format!("cannot write `{}`: {why}", path.display())))?;
    let (mesh, checked) = surface(scene, ask, Some(format))?;
    if mesh.triangles.is_empty() {
        return Err(Failure::Runtime(format!(
            "the mesh has no triangles: no surface crosses the grid (a higher resolution, or bounds that hold the surface); `{}` is not written",
            path.display()
        )));
    }
    let colours = sdfc_compiler::Colours::new(&checked.scene);
    let palette = Palette::new(&checked.scene, &colours);
    let up = up.unwrap_or(format.default_up());
    sdfc_runtime::mesh::write::save(format, &mesh, &palette, up, path).map_err(|e| {
        let (Unsaved::Encode(e) | Unsaved::Write(e)) = e;
        Failure::Value(format!("cannot write `{}`: {e}", path.display()))
    })?;
    Ok((mesh.triangles.len(), mesh.positions.len()))
}
