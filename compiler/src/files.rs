//! Scene files: the interface the checker reads imports and meshes through (`Loader`, and why
//! a file cannot be read, `LoadError`); on disk, reading one within the `file_size` limit
//! (never a FIFO or a device), the byte-order mark some editors write, the loader that
//! resolves `import` against the importing file, and the one name a file has however it was
//! reached.

use crate::limits::Limit;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Reads imported files for the checker (the compiler itself does no IO).
pub trait Loader {
    /// Reads `path` as written in an `import` of the file named `from`. Returns the file's
    /// canonical name (equal names mean the same file) and its text, or why it could not be
    /// read.
    fn load(&mut self, from: &str, path: &str) -> Result<(String, String), LoadError>;

    /// Reads `path` as written in a `mesh(path)` of the file named `from`, as bytes: its
    /// name and its contents, or why it could not be read. By default no file can be.
    fn load_bytes(&mut self, _from: &str, path: &str) -> Result<(String, Vec<u8>), LoadError> {
        Err(LoadError::NoFiles { path: path.into() })
    }
}

/// Why a [`Loader`] cannot read a file; its message is the label of the checker's diagnostic.
#[derive(Debug, Clone, thiserror::Error)]
pub enum LoadError {
    /// The file cannot be read (missing, not a regular file, over the `file_size` limit).
    #[error("cannot read `{}`: {source}", .path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        source: Arc<FileError>,
    },
    /// Its bytes are not UTF-8.
    #[error("`{}` is not valid UTF-8", .path.display())]
    NotUtf8 {
        /// The file.
        path: PathBuf,
    },
    /// The loader reads no imports (text checked on its own).
    #[error("imports are not available here (`{path}`)")]
    NoImports {
        /// The path the import names.
        path: String,
    },
    /// The loader reads no files of data (meshes, fonts).
    #[error("files cannot be read here (`{path}`)")]
    NoFiles {
        /// The path the call names.
        path: String,
    },
}

/// A loader for sources with no imports: every import is an error.
#[derive(Debug, Default)]
pub struct NoImports;

impl Loader for NoImports {
    fn load(&mut self, _from: &str, path: &str) -> Result<(String, String), LoadError> {
        Err(LoadError::NoImports { path: path.into() })
    }
}

/// Why a file cannot be read ([`read_file`]).
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    /// The operating system's error.
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// It is not a regular file (a FIFO or a device would be read forever, or block).
    #[error("it is {kind}, not a regular file")]
    NotAFile {
        /// What it is: `a directory`, `a FIFO`, `a character device`, ….
        kind: &'static str,
    },
    /// It is larger than the `file_size` limit.
    #[error("it is over the file_size limit of {limit_mib} MiB; raise it with `--limit file_size={}`", .size.map_or_else(|| "N".to_string(), |s| s.div_ceil(1 << 20).to_string()))]
    TooLarge {
        /// The limit, in MiB.
        limit_mib: u64,
        /// Its size in bytes, when known.
        size: Option<u64>,
    },
}

/// What a file that is not a regular file is, in words.
fn kind(t: std::fs::FileType) -> Option<&'static str> {
    if t.is_file() {
        return None;
    }
    if t.is_dir() {
        return Some("a directory");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return Some("a FIFO");
        }
        if t.is_char_device() {
            return Some("a character device");
        }
        if t.is_block_device() {
            return Some("a block device");
        }
        if t.is_socket() {
            return Some("a socket");
        }
    }
    Some("not a file")
}

/// Reads the regular file at `path` whole, if it is at most `limit_mib` MiB (the `file_size`
/// limit). A FIFO, a device, a socket or a directory is refused at once: it is opened without
/// blocking (a FIFO with no writer would wait for one) and looked at before anything is read;
/// and no more than the limit and a byte is ever read, whatever the file's size says.
pub fn read_file(path: &Path, limit_mib: u64) -> Result<Vec<u8>, FileError> {
    use std::io::Read;
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    let meta = file.metadata()?;
    if let Some(kind) = kind(meta.file_type()) {
        return Err(FileError::NotAFile { kind });
    }
    let limit = limit_mib.saturating_mul(1 << 20);
    let too_large = |size| FileError::TooLarge { limit_mib, size };
    if meta.len() > limit {
        return Err(too_large(Some(meta.len())));
    }
    let mut bytes = Vec::with_capacity(usize::try_from(meta.len()).unwrap_or(0));
    file.take(limit.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(None));
    }
    Ok(bytes)
}

/// `text` without the byte-order mark that some editors write at the start of a UTF-8 file
/// (so that the columns of the first line count from its first visible character).
pub fn without_bom(mut text: String) -> String {
    if text.starts_with(crate::lexer::BOM) {
        text.drain(..crate::lexer::BOM.len_utf8());
    }
    text
}

/// Loads imports relative to the importing file, each within the `file_size` limit.
#[derive(Debug)]
pub struct FsLoader {
    /// The `file_size` limit, in MiB.
    pub file_size: u64,
}

impl Default for FsLoader {
    fn default() -> Self {
        FsLoader {
            file_size: Limit::FileSize.default_value(),
        }
    }
}

impl FsLoader {
    /// The bytes of the file at `full`, within the `file_size` limit.
    fn read(&self, full: &Path) -> Result<Vec<u8>, LoadError> {
        read_file(full, self.file_size).map_err(|e| LoadError::Read {
            path: full.to_path_buf(),
            source: Arc::new(e),
        })
    }

    /// The file that `import "path"` in the file named `from` reads.
    pub fn resolve(from: &str, path: &str) -> PathBuf {
        let base = Path::new(from).parent().unwrap_or(Path::new("."));
        base.join(path)
    }
}

impl Loader for FsLoader {
    fn load(&mut self, from: &str, path: &str) -> Result<(String, String), LoadError> {
        let full = FsLoader::resolve(from, path);
        let name = normalise(&full);
        let bytes = self.read(&full)?;
        let text = String::from_utf8(bytes).map_err(|_| LoadError::NotUtf8 { path: full })?;
        Ok((name, without_bom(text)))
    }

    fn load_bytes(&mut self, from: &str, path: &str) -> Result<(String, Vec<u8>), LoadError> {
        let full = FsLoader::resolve(from, path);
        let bytes = self.read(&full)?;
        Ok((normalise(&full), bytes))
    }
}

/// A path written with `.` and `..` components folded, so that one file imported by two
/// routes has one name (which is how import cycles are found).
pub fn normalise(p: &Path) -> String {
    let mut parts: Vec<std::path::Component> = Vec::new();
    for c in p.components() {
        match c {
            std::path::Component::CurDir => {}
            std::path::Component::ParentDir
                if matches!(parts.last(), Some(std::path::Component::Normal(_))) =>
            {
                parts.pop();
            }
            other => parts.push(other),
        }
    }
    parts.iter().collect::<PathBuf>().display().to_string()
}
