//! Meshing and meshes, one test binary: `sdfc mesh` and the files it writes (`mesh`), how close
//! they lie to the surface (`mesh_surface`), the command's failure paths (`mesh_failures`), their
//! accuracy on printable parts (`mesh_accuracy`), fields meshed without `--bounds`
//! (`mesh_fields`), 3MF read back by independent readers (`mesh_3mf`), meshes read into
//! scenes (`mesh_import`), vertex colours of the normal and of moved shapes (`mesh_colour`),
//! meshes evaluated on a GPU against the CPU's (`mesh_gpu`), and meshes traced
//! analytically (`mesh_traced`).
//!
//! Filter by module: `cargo test --release --test mesh -- mesh_3mf::`.

#[path = "../common/mod.rs"]
mod common;
#[path = "../common/evaluators.rs"]
mod evaluators;
#[path = "../common/glb.rs"]
mod glb;
#[path = "../common/meshes.rs"]
mod meshes;

mod mesh;
mod mesh_3mf;
mod mesh_accuracy;
mod mesh_colour;
mod mesh_failures;
mod mesh_fields;
mod mesh_gpu;
mod mesh_import;
mod mesh_surface;
mod mesh_traced;
