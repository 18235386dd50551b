//! `mesh(path)`: a triangle mesh file read through the caller's loader, checked, counted
//! against the `triangles` limit and shared between calls of the same file and scale.

use super::*;

impl Build<'_, '_> {
    /// The shape of the triangle mesh in the file `path` (relative to the calling file),
    /// scaled by `scale`: read once per file and scale, with a warning where it is open.
    pub(super) fn mesh(&mut self, path: &str, scale: f64) -> Result<Value, Refusal> {
        use crate::check::meshfile::{read, Error, Format};
        use crate::program::mesh::TriMesh;
        let format = Format::of(path).ok_or_else(|| Refusal::NotMeshFile { path: path.into() })?;
        let refused = |why| Refusal::Mesh {
            path: path.into(),
            why,
        };
        let (name, bytes) = self.read_bytes(path)?;
        let no_files = || Refusal::File(LoadError::NoFiles { path: path.into() });
        let files = self.files.as_deref_mut().ok_or_else(no_files)?;
        let key = (name.clone(), scale.to_bits());
        if let Some(m) = files.meshes.get(&key) {
            let node = Node::Mesh {
                mesh: crate::scene::MeshRef(std::sync::Arc::clone(m)),
            };
            return self.node(node);
        }
        let max = self.limits.get(Limit::Triangles);
        let used = files.triangles;
        let read = read(format, &bytes, max.saturating_sub(used)).map_err(|e| {
            refused(match e {
                // The limit is for all the scene's meshes: the value that would do is this
                // file's triangles and those read before it.
                Error::Limit { triangles, at, .. } => MeshRefusal::Limit {
                    at,
                    triangles,
                    others: used,
                    max,
                    raise: self
                        .limits
                        .raise_to(Limit::Triangles, triangles.saturating_add(used)),
                },
                e => MeshRefusal::Format(e),
            })
        })?;
        let mut mesh = TriMesh::new(path, &read.positions, &read.faces, scale)
            .map_err(|e| refused(MeshRefusal::Invalid(e)))?;
        mesh.id = files.next_id;
        mesh.base = u32::try_from(files.next_base).map_err(|_| refused(MeshRefusal::GpuData))?;
        files.next_id += 1;
        files.next_base += mesh.vectors();
        files.triangles += mesh.triangles().len() as u64;
        let r = mesh.report;
        if r.open_edges > 0 || r.non_manifold_edges > 0 {
            let mut what = Vec::new();
            if r.open_edges > 0 {
                what.push(format!("{} open edges (the rims of holes)", r.open_edges));
            }
            if r.non_manifold_edges > 0 {
                what.push(format!(
                    "{} edges shared by more than two triangles",
                    r.non_manifold_edges
                ));
            }
            self.warnings.push(
                crate::diagnostics::Diagnostic::warning(
                    "W0015",
                    format!("the mesh `{path}` is not closed: it has {}", what.join(" and ")),
                    self.span,
                )
                .with_label("this mesh")
                .with_note(
                    "the distance is exact, but the inside is decided by the nearest triangle's side: right away from the holes, while points that see a hole may take the wrong side, which shows as a seam or a sheet across it",
                ),
            );
        }
        let mesh = std::sync::Arc::new(mesh);
        files.meshes.insert(key, std::sync::Arc::clone(&mesh));
        self.node(Node::Mesh {
            mesh: crate::scene::MeshRef(mesh),
        })
    }
}
