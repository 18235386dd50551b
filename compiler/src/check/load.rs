//! The files of one compilation: those `mesh(path)` reads through the caller's loader, and
//! the source files read in place of their imports, depth first.

use crate::diagnostics::Diagnostic;
use crate::files::Loader;
use crate::limits::{Limit, Limits};
use crate::span::{FileId, SourceMap, Span};
use crate::syntax::{self, ast};
use std::collections::HashMap;

/// The files `mesh(path)` reads, through the caller's loader, and the meshes read so far.
#[derive(Default)]
pub struct Files<'l> {
    /// The caller's loader (none: no file can be read).
    pub loader: Option<&'l mut dyn Loader>,
    /// The name of each source file, by `FileId` (a path is relative to its file's).
    pub names: Vec<String>,
    /// The meshes built, by file name and scale's bits: a file used twice is read once.
    pub meshes: HashMap<(String, u64), std::sync::Arc<crate::program::mesh::TriMesh>>,
    /// The next mesh's id, and where its data starts in `scene_data` (16-byte vectors).
    pub next_id: u32,
    pub next_base: u64,
    /// Triangles of every mesh so far (the `triangles` limit bounds their sum).
    pub triangles: u64,
}

impl std::fmt::Debug for Files<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.debug_struct("Files")
            .field("names", &self.names)
            .field("meshes", &self.meshes.len())
            .finish()
    }
}

/// The files of one compilation being read: parsed in place of their imports, depth
/// first, with their items appended in order.
pub(super) struct Load<'a> {
    pub(super) sources: &'a mut SourceMap,
    pub(super) loader: &'a mut dyn Loader,
    pub(super) limits: &'a Limits,
    /// The files being imported, outermost first (a file found here again is a cycle).
    pub(super) stack: Vec<FileId>,
    pub(super) items: &'a mut Vec<ast::Item>,
    pub(super) diags: &'a mut Vec<Diagnostic>,
    /// The deepest nesting of the files read ([`syntax::nesting`]).
    pub(super) depth: usize,
    /// Which file imports which (importer, imported).
    pub(super) imports: Vec<(FileId, FileId)>,
}

impl Load<'_> {
    /// Parses `file`, then its imports in place (depth first), appending items in order.
    pub(super) fn file(&mut self, file: FileId) {
        self.stack.push(file);
        let text = self.sources.text(file).to_string();
        let ((ast, parse_diags), depth) = syntax::parse_within(file, &text, Some(self.limits));
        self.depth = self.depth.max(depth);
        self.diags.extend(parse_diags);
        for item in ast.items {
            if let ast::Item::Import { path, span } = &item {
                self.import(file, path, *span);
            } else {
                self.items.push(item);
            }
        }
        self.stack.pop();
    }

    fn import(&mut self, from: FileId, path: &str, span: Span) {
        let from_name = self.sources.name(from).to_string();
        let (name, text) = match self.loader.load(&from_name, path) {
            Ok(x) => x,
            Err(e) => {
                // The diagnostic's label: where the error's message is shown to the user.
                self.diags.push(
                    Diagnostic::error("E0501", format!("cannot import `{path}`"), span)
                        .with_label(e.to_string()),
                );
                return;
            }
        };
        if let Some(existing) = self.sources.find(&name) {
            self.imports.push((from, existing));
            if self.stack.contains(&existing) {
                let chain: Vec<&str> = self
                    .stack
                    .iter()
                    .map(|f| self.sources.name(*f))
                    .chain([name.as_str()])
                    .collect();
                self.diags.push(
                    Diagnostic::error("E0500", "import cycle", span)
                        .with_label(format!("`{path}` is already being imported"))
                        .with_note(format!("the cycle is {}", chain.join(" → "))),
                );
            }
            // A file imported twice (not in a cycle) is read once.
            return;
        }
        let max = self.limits.count(Limit::Files);
        if self.sources.len() >= max {
            self.diags.push(
                Diagnostic::error("E0507", format!("more than {max} files are imported"), span)
                    .with_note(format!(
                        "this limit keeps compilation bounded; {}",
                        self.limits.raise(Limit::Files)
                    )),
            );
            return;
        }
        let id = self.sources.add(name, text);
        self.imports.push((from, id));
        self.file(id);
    }
}
