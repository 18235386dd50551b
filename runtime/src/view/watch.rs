//! Watching a scene's files: the directories holding the file and everything it imports are
//! watched (so an editor that saves by writing a new file and renaming it over the old one is
//! seen), events are debounced, and a fingerprint of the files' contents decides whether a
//! batch of events changed anything.

use notify_debouncer_full::notify::{RecommendedWatcher, RecursiveMode};
use notify_debouncer_full::{new_debouncer, DebounceEventResult, Debouncer, RecommendedCache};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime};

/// How long the file system must be quiet before a batch of events is reported. It is part of
/// every edit's way to the screen (a numeric edit's is meant to take at most 40 ms in all). A
/// save by writing a new file and renaming it is over within a millisecond; one that truncates
/// and writes in place may be seen half written, which a load finds out and reads again
/// (`session.rs`, `STABLE_READS`, `EMPTY_PATIENCE`), and the events of its end call for
/// another load when the contents differ from the ones loaded.
pub const DEBOUNCE: Duration = Duration::from_millis(15);

/// Why no files can be watched: the watcher could not be made.
#[derive(Debug, thiserror::Error)]
#[error("cannot watch files: {0}")]
pub struct WatchError(notify_debouncer_full::notify::Error);

/// Watches directories and calls back with the paths of each debounced batch of events.
pub struct Watch {
    debouncer: Debouncer<RecommendedWatcher, RecommendedCache>,
    dirs: BTreeSet<PathBuf>,
}

impl std::fmt::Debug for Watch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Watch").field("dirs", &self.dirs).finish()
    }
}

impl Watch {
    /// A watcher that calls `changed` (on its own thread) with the paths of every debounced
    /// batch of events and when the first of them was seen, or with no paths when the
    /// watcher reported an error (so that the files are looked at again).
    pub fn new(
        changed: impl Fn(Vec<PathBuf>, SystemTime) + Send + 'static,
    ) -> Result<Watch, WatchError> {
        let debouncer =
            new_debouncer(
                DEBOUNCE,
                None,
                move |result: DebounceEventResult| match result {
                    Ok(events) => {
                        let paths: Vec<PathBuf> = events
                            .iter()
                            .flat_map(|e| e.paths.iter().cloned())
                            .collect();
                        let first = events.iter().map(|e| e.time).min();
                        if !paths.is_empty() {
                            changed(paths, first.map_or_else(SystemTime::now, system_time));
                        }
                    }
                    Err(_) => changed(Vec::new(), SystemTime::now()),
                },
            )
            .map_err(WatchError)?;
        Ok(Watch {
            debouncer,
            dirs: BTreeSet::new(),
        })
    }

    /// Watches the directory of each of `files` not yet watched. Returns a message for each
    /// directory that cannot be watched (it is tried again at the next call).
    pub fn add(&mut self, files: &[PathBuf]) -> Vec<String> {
        let mut problems = Vec::new();
        for file in files {
            let dir = directory(file);
            if self.dirs.contains(&dir) {
                continue;
            }
            match self.debouncer.watch(&dir, RecursiveMode::NonRecursive) {
                Ok(()) => {
                    self.dirs.insert(dir);
                }
                Err(e) => problems.push(format!("cannot watch `{}`: {e}", dir.display())),
            }
        }
        problems
    }

    /// The directories watched.
    pub fn dirs(&self) -> impl Iterator<Item = &Path> {
        self.dirs.iter().map(|d| d.as_path())
    }
}

/// The wall-clock time of `instant` (a moment of the past).
fn system_time(instant: Instant) -> SystemTime {
    SystemTime::now() - instant.elapsed()
}

/// The absolute directory holding `file`.
fn directory(file: &Path) -> PathBuf {
    let absolute = std::path::absolute(file).unwrap_or_else(|_| file.to_path_buf());
    match absolute.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// The contents of a set of files (or that each could not be read) at one moment.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Fingerprint {
    files: Vec<(PathBuf, Option<Vec<u8>>)>,
}

/// The bytes of a scene's file as a load reads them (a FIFO or a device is not read: it would
/// block the watcher, or never end).
fn read(f: &Path) -> Option<Vec<u8>> {
    crate::frontend::read_file(f, sdfc_compiler::Limit::FileSize.default_value()).ok()
}

impl Fingerprint {
    /// Reads `files` now.
    pub fn of(files: &[PathBuf]) -> Fingerprint {
        Fingerprint {
            files: files.iter().map(|f| (f.clone(), read(f))).collect(),
        }
    }

    /// The contents a load saw: each file's path and bytes.
    pub fn from_sources<'a>(files: impl Iterator<Item = (PathBuf, &'a [u8])>) -> Fingerprint {
        Fingerprint {
            files: files.map(|(f, b)| (f, Some(b.to_vec()))).collect(),
        }
    }

    /// Whether the files have other contents now (or a different set can be read).
    pub fn changed(&self) -> bool {
        self.files
            .iter()
            .any(|(f, bytes)| read(f).as_ref() != bytes.as_ref())
    }

    /// The latest modification time of the files that exist.
    pub fn modified(files: &[PathBuf]) -> Option<SystemTime> {
        files
            .iter()
            .filter_map(|f| std::fs::metadata(f).and_then(|m| m.modified()).ok())
            .max()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fingerprint_sees_changes_and_removals() {
        let dir = std::env::temp_dir().join(format!("sdfc-watch-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("a.sdf");
        std::fs::write(&file, "scene { sphere(1); }").unwrap();
        let files = vec![file.clone()];
        let print = Fingerprint::of(&files);
        assert!(!print.changed());
        std::fs::write(&file, "scene { sphere(1); }").unwrap();
        assert!(
            !print.changed(),
            "the same contents written again is no change"
        );
        std::fs::write(&file, "scene { sphere(2); }").unwrap();
        assert!(print.changed());
        std::fs::remove_file(&file).unwrap();
        assert!(print.changed());
        assert!(!Fingerprint::of(&files).changed());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
