//! Reading scenes from disk: the file-system import loader, and the shared "load, check,
//! report and lower" steps of every subcommand, and the lines `sdfc check` (and `sdfc view`)
//! print about a clean scene: what its distance field is, and how it is rendered.

use sdfc_compiler::{
    analysis::{self, Analysis},
    analytic::{Choice, Reason, Traceable},
    check_at,
    diagnostics::{self, Diagnostic},
    lower_within, Exactness, Limit, Limits, LoadError, Loader, LowerOptions, Lowered, Scene,
    SourceMap, Span,
};
// Reading files is the compiler's (`sdfc_compiler::files`); its names are used here as before.
pub use sdfc_compiler::files::{normalise, read_file, without_bom, FileError, FsLoader};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// How diagnostics are printed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Default)]
pub enum DiagnosticFormat {
    /// Human-readable reports with source excerpts.
    #[default]
    Human,
    /// One JSON object per line, for editors.
    Json,
}

/// The result of loading and checking one scene file.
#[derive(Debug)]
pub struct Loaded {
    /// The checked scene, when there were no errors.
    pub scene: Option<Scene>,
    /// Everything the compiler said.
    pub diagnostics: Vec<Diagnostic>,
    /// The files read, for rendering diagnostics.
    pub sources: SourceMap,
    /// The other files the scene read (meshes, fonts), each by its name with the bytes read.
    pub data: Vec<(String, Vec<u8>)>,
}

/// Why a scene's entry file cannot be read ([`Source::read`]), phrased for the user.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file cannot be read (or is not a regular file, or is over the `file_size` limit).
    #[error("cannot read `{}`: {source}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: FileError,
    },
    /// Its bytes are not UTF-8.
    #[error("`{}` is not valid UTF-8 (first bad byte at offset {offset})", .path.display())]
    Utf8 {
        /// The file.
        path: PathBuf,
        /// The offset of the first byte that is not.
        offset: usize,
    },
}

/// Reads `path` and checks it within the default limits. `Err` is an IO or encoding problem
/// with the entry file itself.
pub fn load(path: &Path) -> Result<Loaded, ReadError> {
    load_with(path, &Limits::default())
}

/// [`load`] within the given limits.
pub fn load_with(path: &Path, limits: &Limits) -> Result<Loaded, ReadError> {
    Ok(Source::read_within(path, limits)?.check(limits, 0.0))
}

/// A scene file and its imports read once, to be checked at many times: the frames of an
/// animated scene (docs/animation.md) all come from the same text, even if the files
/// change while a sequence renders.
#[derive(Debug)]
pub struct Source {
    name: String,
    text: String,
    /// Imports read so far, by the importing file and the path written.
    imports: std::collections::HashMap<(String, String), Result<(String, String), LoadError>>,
    /// The name each file was first read under, by its canonical path (symbolic links
    /// resolved): a file reached by two routes, a link and its target, has one name, so it
    /// is read once (and an import of the entry file through a link is a cycle).
    names: std::collections::HashMap<PathBuf, String>,
    /// The `file_size` limit of the files read, in MiB.
    file_size: u64,
    /// The other files the last check read as bytes, by name.
    data: Vec<(String, Vec<u8>)>,
}

impl Source {
    /// Reads the entry file within the default limits. `Err` is an IO or encoding problem.
    pub fn read(path: &Path) -> Result<Source, ReadError> {
        Source::read_within(path, &Limits::default())
    }

    /// Reads the entry file (and later its imports) within the `file_size` limit of `limits`.
    /// `Err` is an IO or encoding problem.
    pub fn read_within(path: &Path, limits: &Limits) -> Result<Source, ReadError> {
        let file_size = limits.get(Limit::FileSize);
        let bytes = read_file(path, file_size).map_err(|source| ReadError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let text = String::from_utf8(bytes).map_err(|e| ReadError::Utf8 {
            path: path.to_path_buf(),
            offset: e.utf8_error().valid_up_to(),
        })?;
        let text = without_bom(text);
        let name = normalise(path);
        let mut names = std::collections::HashMap::new();
        if let Ok(canonical) = std::fs::canonicalize(path) {
            names.insert(canonical, name.clone());
        }
        Ok(Source {
            name,
            text,
            imports: Default::default(),
            names,
            file_size,
            data: Vec::new(),
        })
    }

    /// A scene given as text, named `name` (a path: its imports are read relative to it;
    /// for text of no file, a name in the current directory).
    pub fn from_text(name: &str, text: String) -> Source {
        let path = Path::new(name);
        let name = normalise(path);
        let mut names = std::collections::HashMap::new();
        if let Ok(canonical) = std::fs::canonicalize(path) {
            names.insert(canonical, name.clone());
        }
        Source {
            name,
            text,
            imports: Default::default(),
            names,
            file_size: Limit::FileSize.default_value(),
            data: Vec::new(),
        }
    }

    /// The entry file's text.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// Checks the scene within `limits` at the time `t` = `time` seconds.
    pub fn check(&mut self, limits: &Limits, time: f64) -> Loaded {
        self.file_size = limits.get(Limit::FileSize);
        self.data.clear();
        let mut sources = SourceMap::new();
        let entry = sources.add(self.name.clone(), self.text.clone());
        let (scene, diagnostics) = check_at(&mut sources, entry, self, limits, time);
        Loaded {
            scene,
            diagnostics,
            sources,
            data: std::mem::take(&mut self.data),
        }
    }
}

impl Loader for Source {
    fn load(&mut self, from: &str, path: &str) -> Result<(String, String), LoadError> {
        let key = (from.to_string(), path.to_string());
        if let Some(done) = self.imports.get(&key) {
            return done.clone();
        }
        let mut loaded = self.loader().load(from, path);
        if let Ok((name, _)) = &mut loaded {
            if let Ok(canonical) = std::fs::canonicalize(FsLoader::resolve(from, path)) {
                name.clone_from(self.names.entry(canonical).or_insert_with(|| name.clone()));
            }
        }
        self.imports.insert(key, loaded.clone());
        loaded
    }

    fn load_bytes(&mut self, from: &str, path: &str) -> Result<(String, Vec<u8>), LoadError> {
        let read = self.loader().load_bytes(from, path);
        if let Ok((name, bytes)) = &read {
            if !self.data.iter().any(|(n, _)| n == name) {
                self.data.push((name.clone(), bytes.clone()));
            }
        }
        read
    }
}

impl Source {
    fn loader(&self) -> FsLoader {
        FsLoader {
            file_size: self.file_size,
        }
    }
}

/// Prints diagnostics to stderr in the chosen format.
pub fn report(loaded: &Loaded, format: DiagnosticFormat) {
    print_diagnostics(&loaded.diagnostics, &loaded.sources, format);
}

/// Prints `diags` about `sources` in the chosen format: the human form on stderr, the JSON
/// lines on stdout (the stream a script or an editor reads; `sdfc compile`, whose stdout
/// carries its output, uses [`print_diagnostics_on_stderr`]).
pub fn print_diagnostics(diags: &[Diagnostic], sources: &SourceMap, format: DiagnosticFormat) {
    print_to(diags, sources, format, format == DiagnosticFormat::Json);
}

/// How many diagnostics the human form shows; the rest are counted in one line (a file with
/// 20 000 errors would otherwise flood the terminal). The JSON form, for tools, has them all.
pub const SHOWN: usize = 100;

/// [`print_diagnostics`], always on stderr.
pub fn print_diagnostics_on_stderr(
    diags: &[Diagnostic],
    sources: &SourceMap,
    format: DiagnosticFormat,
) {
    print_to(diags, sources, format, false);
}

fn print_to(diags: &[Diagnostic], sources: &SourceMap, format: DiagnosticFormat, stdout: bool) {
    use std::io::Write;
    if diags.is_empty() {
        return;
    }
    let text = match format {
        DiagnosticFormat::Human => {
            let shown = &diags[..diags.len().min(SHOWN)];
            let mut text = diagnostics::render(shown, sources, std::io::stderr().is_terminal());
            if let Some(rest) = diags.get(SHOWN..).filter(|r| !r.is_empty()) {
                let errors = rest.iter().filter(|d| d.is_error()).count();
                let stopped = if diagnostics::stopped(rest) {
                    "; checking stopped after these (the last one says where)"
                } else {
                    ""
                };
                text.push_str(&format!(
                    "… and {} more diagnostics ({errors} errors) not shown; the first {SHOWN} are above{stopped}\n",
                    rest.len()
                ));
            }
            text
        }
        DiagnosticFormat::Json => diagnostics::to_json(diags, sources),
    };
    if stdout {
        let mut out = std::io::stdout().lock();
        // The JSON lines are the command's output: one that cannot be written (a full disk)
        // ends the run with the reason, as any other output would. (A closed pipe ends the
        // process quietly before this, by SIGPIPE; where it does not, it is not an error
        // worth a message.)
        match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
            Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => unwritable_stdout(&e),
            _ => {}
        }
    } else {
        // Nothing is left to tell about a standard error that cannot be written.
        let _ = std::io::stderr().lock().write_all(text.as_bytes());
    }
}

/// Ends the process on output that cannot be written: `error: cannot write to standard
/// output: …`, exit 2 (what `sdfc` does for every write to standard output that fails).
pub fn unwritable_stdout(e: &dyn std::fmt::Display) -> ! {
    eprintln!("error: cannot write to standard output: {e}");
    std::process::exit(2)
}

/// Prints an error about a file that is not a diagnostic (it cannot be read, it is not
/// UTF-8): `error: MSG` on stderr, or in the JSON format one object of the diagnostics' shape
/// on stdout, with the code `io` and no labels, so that the stream stays JSON lines.
pub fn print_io_error(e: &ReadError, format: DiagnosticFormat) {
    let msg = e.to_string();
    match format {
        DiagnosticFormat::Human => eprintln!("error: {msg}"),
        DiagnosticFormat::Json => {
            let v = serde_json::json!({
                "severity": "error", "code": "io", "message": msg,
                "labels": [], "notes": [], "help": null,
            });
            println!("{v}");
        }
    }
}

/// A scene that checked without errors, with the files it was read from (for the
/// diagnostics of later stages).
#[derive(Debug)]
pub struct Checked {
    /// The scene.
    pub scene: Scene,
    /// The files it was read from.
    pub sources: SourceMap,
    /// How diagnostics are printed.
    pub format: DiagnosticFormat,
}

impl Checked {
    /// Lowers the scene within `limits` ([`lower_within`]). A program larger than the
    /// `program` limit is reported (E0507) and gives exit code 1, before any back end or
    /// render starts.
    pub fn lower(&self, options: &LowerOptions, limits: &Limits) -> Result<Lowered, ExitCode> {
        match lower_within(&self.scene, options, limits) {
            Ok(lowered) => Ok(lowered),
            Err(d) => {
                print_diagnostics(&[d], &self.sources, self.format);
                Err(ExitCode::from(1))
            }
        }
    }
}

/// Loads, checks within `limits` and reports; returns the checked scene, or the exit code to
/// stop with (1 for errors in the scene, 2 for IO problems).
pub fn load_scene(
    path: &Path,
    format: DiagnosticFormat,
    limits: &Limits,
) -> Result<Checked, ExitCode> {
    load_scene_code(path, format, limits).map_err(ExitCode::from)
}

/// [`load_scene`] with the exit code as a number (1 or 2), for commands that pass it on.
pub fn load_scene_code(
    path: &Path,
    format: DiagnosticFormat,
    limits: &Limits,
) -> Result<Checked, u8> {
    let loaded = match load_with(path, limits) {
        Ok(l) => l,
        Err(e) => {
            print_io_error(&e, format);
            return Err(2);
        }
    };
    report(&loaded, format);
    match loaded.scene {
        Some(scene) => Ok(Checked {
            scene,
            sources: loaded.sources,
            format,
        }),
        None => Err(1),
    }
}

/// What the analysis derived for the scene, in one clause: `distance field: bound (L = 1)`,
/// or, when inexact, with the construct responsible, and, where L > 1, that the lowering
/// divides it out locally (each operand by its own L, `docs/analysis.md`).
pub fn summary(loaded: &Loaded, scene: &Scene) -> String {
    let analysis = analysis::analyse(scene);
    let Some(root) = analysis.root() else {
        return "no objects".into();
    };
    let facts = root.facts;
    let word = analysis::describe(facts.exactness);
    let l = facts.lipschitz;
    let cause = cause(loaded, scene, &analysis);
    let step = analysis.step_lipschitz();
    match facts.exactness {
        Exactness::Exact | Exactness::Bound => format!("distance field: {word} (L = {})", num(l)),
        Exactness::Approximate if !root.proven => format!(
            "distance field: {word}, no bound proven{cause}; steps with L = {}{}",
            num(step),
            if scene.settings.footprint {
                "; ε follows the pixel footprint"
            } else {
                ""
            }
        ),
        Exactness::Approximate if step < l => format!(
            "distance field: {word}, L = {}{cause}, clamped to {}; divided out locally",
            num(l),
            num(step)
        ),
        Exactness::Approximate if l > 1.0 => format!(
            "distance field: {word}, L = {}{cause}; divided out locally",
            num(l)
        ),
        Exactness::Approximate => format!("distance field: {word}, L = {}{cause}", num(l)),
    }
}

/// How the scene is rendered and why: `method: trace (...)` or `method: march (...)`, with
/// the location of the node that rules out analytic tracing; `traceable` is the lowering's
/// ([`Lowered::traceable`]), or for `sdfc check` of a scene it does not lower,
/// `analytic::traceable`.
pub fn method(loaded: &Loaded, scene: &Scene, traceable: &Traceable) -> String {
    match traceable.choose(scene.settings.method) {
        Choice::March(Reason::Node { what, span }) => format!(
            "method: march (the {what} at {} has no closed-form ray intersection)",
            at(loaded, span)
        ),
        Choice::March(Reason::Overlap { span }) => format!(
            "method: march (the transparent shape at {} overlaps or touches another transparent one)",
            at(loaded, span)
        ),
        choice => choice.describe_in(&scene.limits),
    }
}

/// The tone curve the pixels are graded by and why: `tone curve: filmic (the default where
/// it has a `pbr` material; ...)`, `tone curve: none (the default where it has no ...)` or
/// `tone curve: reinhard (set by `tonemap`)`.
pub fn tone_curve(scene: &Scene) -> String {
    let name = scene.settings.tonemap.name();
    match scene.settings.tonemap_why {
        Some(why) if scene.settings.tonemap != sdfc_compiler::Tonemap::None => format!(
            "tone curve: {name} (the default where {why}; `tonemap: \"none\"` keeps the linear light)"
        ),
        Some(why) => format!("tone curve: {name} (the default where {why})"),
        None => format!("tone curve: {name} (set by `tonemap`)"),
    }
}

/// `FILE:LINE:COL` of a span.
fn at(loaded: &Loaded, span: Span) -> String {
    let (line, col) = loaded.sources.line_col(span);
    format!("{}:{line}:{col}", loaded.sources.name(span.file))
}

/// ` (the twist at FILE:LINE:COL)` for the node that made the field inexact, or nothing.
fn cause(loaded: &Loaded, scene: &Scene, analysis: &Analysis) -> String {
    let Some(id) = analysis.root().and_then(|r| r.cause) else {
        return String::new();
    };
    let kind = analysis::kind(scene.graph.node(id));
    format!(" (the {kind} at {})", at(loaded, scene.graph.span(id)))
}

/// A number with at most three decimals and no trailing zeros.
fn num(x: f64) -> String {
    let s = format!("{x:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}
