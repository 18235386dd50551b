//! The front end as its callers see it: the checker (`check/`) and then the passes that
//! need the scene's lowering, the placement warnings (`placement.rs`); one list of
//! diagnostics in source order.

mod placement;

use crate::check::{check_files, Constant, Loader, NoImports};
use crate::diagnostics::Diagnostic;
use crate::limits::Limits;
use crate::scene::Scene;
use crate::span::{FileId, SourceMap};
use placement::warnings;

/// Checks the file `entry` of `sources` and everything it imports (added to `sources`),
/// within the default [`Limits`]. Returns the scene when there are no errors, and all
/// diagnostics.
pub fn check(
    sources: &mut SourceMap,
    entry: FileId,
    loader: &mut dyn Loader,
) -> (Option<Scene>, Vec<Diagnostic>) {
    check_with(sources, entry, loader, &Limits::default())
}

/// [`check`] within the given limits (`--limit`), at the time 0.
pub fn check_with(
    sources: &mut SourceMap,
    entry: FileId,
    loader: &mut dyn Loader,
    limits: &Limits,
) -> (Option<Scene>, Vec<Diagnostic>) {
    check_at(sources, entry, loader, limits, 0.0)
}

/// [`check_with`] at the time `t` = `time` seconds: the scene of the frame at that time
/// (docs/animation.md). Its [`Scene::animation`] says whether anything read `t`.
pub fn check_at(
    sources: &mut SourceMap,
    entry: FileId,
    loader: &mut dyn Loader,
    limits: &Limits,
    time: f64,
) -> (Option<Scene>, Vec<Diagnostic>) {
    let (scene, diags, _) = check_files(sources, entry, loader, limits, time, &warnings);
    (scene, diags)
}

/// [`check_with`], with the values of the global constants that evaluated to a number,
/// vector, angle, bool, string or list of them (not shapes: their facts are the analysis's),
/// even when the scene has errors elsewhere.
pub fn check_with_constants(
    sources: &mut SourceMap,
    entry: FileId,
    loader: &mut dyn Loader,
    limits: &Limits,
) -> (Option<Scene>, Vec<Diagnostic>, Vec<Constant>) {
    check_files(sources, entry, loader, limits, 0.0, &warnings)
}

/// Checks a single source text that imports nothing (for tests and tools).
pub fn check_str(name: &str, text: &str) -> (Option<Scene>, Vec<Diagnostic>, SourceMap) {
    let mut sources = SourceMap::new();
    let entry = sources.add(name, text);
    let (scene, diags) = check(&mut sources, entry, &mut NoImports);
    (scene, diags, sources)
}
