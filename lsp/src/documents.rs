//! The open documents and the checking of one of them: imports are read from other open
//! documents first (their unsaved text), then from disk, through the checker's `Loader`.

use sdfc_compiler::files::{normalise, FsLoader};
use sdfc_compiler::{
    check_with_constants, Constant, Diagnostic, FileId, Limit, Limits, LoadError, Loader, Scene,
    SourceMap,
};
use std::collections::HashMap;
use std::path::Path;

/// The text of every open document, by its normalised path.
#[derive(Debug, Default)]
pub struct Documents {
    open: HashMap<String, String>,
}

impl Documents {
    /// Sets the text of the document at `path` (opened or changed).
    pub fn set(&mut self, path: &Path, text: String) {
        self.open.insert(normalise(path), text);
    }

    /// Forgets a closed document.
    pub fn close(&mut self, path: &Path) {
        self.open.remove(&normalise(path));
    }

    /// The text of an open document.
    pub fn get(&self, path: &Path) -> Option<&str> {
        self.open.get(&normalise(path)).map(String::as_str)
    }

    /// The normalised paths of the open documents.
    pub fn paths(&self) -> impl Iterator<Item = &str> {
        self.open.keys().map(String::as_str)
    }

    /// Checks the open document at `path` with everything it imports. `None` when it is not
    /// open.
    pub fn check(&self, path: &Path, limits: &Limits) -> Option<Checked> {
        let name = normalise(path);
        let text = self.open.get(&name)?.clone();
        let mut sources = SourceMap::new();
        let entry = sources.add(name, text);
        let mut loader = OpenFirst {
            docs: self,
            files: FsLoader {
                file_size: limits.get(Limit::FileSize),
            },
        };
        let (scene, diagnostics, constants) =
            check_with_constants(&mut sources, entry, &mut loader, limits);
        Some(Checked {
            scene,
            diagnostics,
            constants,
            sources,
            entry,
        })
    }
}

/// What checking one document gave.
#[derive(Debug)]
pub struct Checked {
    /// The scene, when there were no errors.
    pub scene: Option<Scene>,
    /// Everything the compiler said, about this file and its imports.
    pub diagnostics: Vec<Diagnostic>,
    /// The values of the global constants (of this file and its imports) that evaluated.
    pub constants: Vec<Constant>,
    /// The document (first) and the files it imports.
    pub sources: SourceMap,
    /// The document's id in `sources`.
    pub entry: FileId,
}

impl Checked {
    /// The id of the file named `name` (a normalised path) among the sources.
    pub fn file(&self, name: &str) -> Option<FileId> {
        (0..self.sources.len() as u32)
            .map(FileId)
            .find(|&f| self.sources.name(f) == name)
    }
}

/// Reads imports from the open documents, else from disk as the command line does.
struct OpenFirst<'a> {
    docs: &'a Documents,
    files: FsLoader,
}

impl Loader for OpenFirst<'_> {
    fn load(&mut self, from: &str, path: &str) -> Result<(String, String), LoadError> {
        let base = Path::new(from).parent().unwrap_or(Path::new("."));
        let name = normalise(&base.join(path));
        match self.docs.open.get(&name) {
            Some(text) => Ok((name, text.clone())),
            None => self.files.load(from, path),
        }
    }

    fn load_bytes(&mut self, from: &str, path: &str) -> Result<(String, Vec<u8>), LoadError> {
        self.files.load_bytes(from, path)
    }
}
