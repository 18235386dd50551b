//! The WGSL and PTX of distances at points: a compute entry point joined to a WGSL module
//! that declares `map` (the scene's part, or the marched kernel with its instances walked in
//! `scene_data`), validated by naga, and its PTX. The runtime's `gpu::points` runs them over a
//! buffer of points through wgpu or CUDA; the distance conformance tests compare every
//! evaluator with them, the snapshot tests keep their PTX, and the Python package's
//! `Scene.distance(points, backend=…)` answers with them.

use super::{ptx, wgsl};
use crate::lower::Lowered;
use crate::scene::ir::{Method, Scene};

/// One evaluation: the distance and the material id at a point.
pub type Value<T> = (T, u32);

/// The workgroup size of [`entry`].
pub const WORKGROUP: u32 = 64;

/// The name of [`entry`]'s entry point.
pub const ENTRY_POINT: &str = "eval_points";

/// The entry point joined to a module that declares `map` (distance, material id) and, where
/// given, the distance alone as `alone`, its two buffers in bind group `group`: thread `i`
/// evaluates them at point `i` (x, y, z; w unused) and writes (distance, material id, distance
/// alone or `map`'s distance again, 0).
/// The buffers hold a whole number of workgroups (the points padded, [`point_words`]), so
/// that no thread needs `arrayLength`, which PTX cannot know. With `warm` (a name), an odd
/// thread first calls it at the point before its own, so that the instance walk starts from
/// another point's hint.
pub fn entry(group: u32, alone: Option<&str>, warm: Option<&str>) -> String {
    let alone = alone.map_or("m.x".to_string(), |f| format!("{f}(p)"));
    let warm = warm.map_or(String::new(), |f| {
        format!("if (id.x & 1u) == 1u {{\n        _ = {f}(eval_points_in[id.x - 1u].xyz);\n    }}\n    ")
    });
    format!(
        "
@group({group}) @binding(0) var<storage, read> eval_points_in: array<vec4<f32>>;
@group({group}) @binding(1) var<storage, read_write> eval_points_out: array<vec4<f32>>;

@compute @workgroup_size({WORKGROUP})
fn {ENTRY_POINT}(@builtin(global_invocation_id) id: vec3<u32>) {{
    let p = eval_points_in[id.x].xyz;
    {warm}let m = map(p);
    eval_points_out[id.x] = vec4<f32>(m, {alone}, 0.0);
}}
"
    )
}

/// A WGSL module with [`entry`], validated by naga, and what it binds besides its points.
#[derive(Debug)]
pub struct PointsModule {
    pub source: String,
    pub module: naga::Module,
    pub info: naga::valid::ModuleInfo,
    /// The bind group of the points and results.
    pub group: u32,
    /// The bytes of `scene_data` (group 0, binding 4), where the module reads it.
    pub data: Option<Vec<u8>>,
}

/// Why a module of distances at points cannot be written.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The scene's WGSL part or kernel that the entry point joins is invalid.
    #[error("{0}")]
    Wgsl(#[from] wgsl::Error),
    /// naga cannot parse the joined module: its message, placed in the source.
    #[error("{}", .error.emit_to_string(.text))]
    Parse {
        error: naga::front::wgsl::ParseError,
        /// The joined module.
        text: String,
    },
    /// naga finds the joined module invalid: its message, placed in the source.
    #[error("{}", .error.emit_to_string(.text))]
    Invalid {
        error: Box<naga::WithSpan<naga::valid::ValidationError>>,
        /// The joined module.
        text: String,
    },
    /// The PTX writer cannot translate the entry point.
    #[error("PTX: {0}")]
    Ptx(#[from] ptx::Error),
}

fn validated(source: String, group: u32, data: Option<Vec<u8>>) -> Result<PointsModule, Error> {
    let module = match naga::front::wgsl::parse_str(&source) {
        Ok(m) => m,
        Err(error) => {
            return Err(Error::Parse {
                error,
                text: source,
            })
        }
    };
    let validation = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module);
    let info = match validation {
        Ok(info) => info,
        Err(error) => {
            let error = Box::new(error);
            return Err(Error::Invalid {
                error,
                text: source,
            });
        }
    };
    Ok(PointsModule {
        source,
        module,
        info,
        group,
        data,
    })
}

/// The part of `scene` (as lowered), `map` and, with `alone`, `map_distance`, with [`entry`];
/// for a scene with a mesh, which has no part, [`mesh_module`].
pub fn points_module(scene: &Scene, lowered: &Lowered, alone: bool) -> Result<PointsModule, Error> {
    if lowered.program.meshes().next().is_some() {
        return mesh_module(scene, alone);
    }
    let part = wgsl::part::write(scene, lowered, "map")?;
    let alone = alone.then_some("map_distance");
    validated(
        format!("{}\n{}", part.source, entry(0, alone, None)),
        0,
        None,
    )
}

/// A scene with a mesh has no part (its triangles are data, not code): its marched kernel,
/// with the meshes in `scene_data`, its `map` and, with `alone`, `sdf` with [`entry`] (in bind
/// group 1, beside the kernel's group 0).
fn mesh_module(scene: &Scene, alone: bool) -> Result<PointsModule, Error> {
    let mut marched = scene.clone();
    marched.settings.method = Method::March;
    let lowered = Lowered::new(&marched);
    let kernel = wgsl::write(&marched, &lowered)?;
    validated(
        format!(
            "{}\n{}",
            kernel.source,
            entry(1, alone.then_some("sdf"), None)
        ),
        1,
        kernel.data,
    )
}

/// The marched kernel of `scene` with every instance of its root union walked in
/// `scene_data`, its `map` and `sdf` with [`entry`] (in bind group 1, beside the kernel's
/// group 0), every other point's walks hinted by `sdf` at the point before it; none where
/// the scene has no instances.
pub fn walk_module(scene: &Scene) -> Option<Result<PointsModule, Error>> {
    let mut marched = scene.clone();
    marched.settings.method = Method::March;
    let lowered = Lowered::new(&marched);
    lowered.instances(0)?;
    let options = wgsl::Options {
        max_instances: 0,
        ..Default::default()
    };
    let kernel = match wgsl::write_with(&marched, &lowered, &options) {
        Ok(k) => k,
        Err(e) => return Some(Err(e.into())),
    };
    let walked = kernel.source.contains("fn walk_map(");
    let data = kernel.data.filter(|_| walked)?;
    Some(validated(
        format!("{}\n{}", kernel.source, entry(1, Some("sdf"), Some("sdf"))),
        1,
        Some(data),
    ))
}

/// The PTX of a [`PointsModule`]'s entry point for `sm`.
pub fn points_ptx(m: &PointsModule, sm: u32) -> Result<String, Error> {
    let options = ptx::Options {
        sm,
        entry_point: ENTRY_POINT.into(),
    };
    Ok(ptx::write(&m.module, &m.info, &options)?.text)
}
