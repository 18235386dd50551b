//! `sdfc._sdfc`, the native module of the Python package `sdfc` (python/sdfc): checking a
//! scene, rendering it, its distances at points, its mesh and its compiled forms, through the
//! same functions `sdfc check`, `sdfc render`, `sdfc mesh` and `sdfc compile` call. Arrays
//! cross as bytes, which python/sdfc/__init__.py views as NumPy arrays; work that takes
//! long runs on a thread of its own with the GIL released, while the calling thread waits
//! and turns a Ctrl-C into `KeyboardInterrupt`.

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};
use rayon::prelude::*;
use sdfc_compiler::{
    analysis, analytic, Diagnostic, Evaluator, Limits, LowerOptions, Lowered, Outputs, Severity,
    SourceMap, Spelling, Tape, DEFAULT_CHUNK,
};
use sdfc_runtime::backend::{Backend, Devices, Kernel, Setup};
use sdfc_runtime::commands::compile::{self, Emit, Part};
use sdfc_runtime::cpu::Precision;
use sdfc_runtime::frontend::{self, Source};
use sdfc_runtime::gpu::points::RunError;
use sdfc_runtime::gpu::Gpu;
use sdfc_runtime::image::Image;
use sdfc_runtime::job::{self, Job, Overrides};
use std::sync::OnceLock;
use std::time::Duration;

mod kept;
mod mesh;
mod scene;
mod table;

use scene::Scene;

create_exception!(
    _sdfc,
    CompileError,
    PyException,
    "A scene with errors; `.diagnostics` holds them."
);

/// Why a call failed, carried back from its worker thread.
enum Failure {
    /// The scene has errors (or a later stage reported one at a place in it).
    Compile(Vec<Diagnostic>, SourceMap),
    /// A bad argument.
    Value(String),
    /// The work itself failed (a backend, a limit).
    Runtime(String),
}

impl Failure {
    fn into_py(self, py: Python<'_>) -> PyErr {
        match self {
            Failure::Compile(diags, sources) => compile_error(py, &diags, &sources),
            Failure::Value(m) => PyValueError::new_err(m),
            Failure::Runtime(m) => PyRuntimeError::new_err(m),
        }
    }
}

impl From<job::Error> for Failure {
    fn from(e: job::Error) -> Failure {
        match e {
            job::Error::Scene(s) => Failure::Compile(s.diagnostics, s.sources),
            job::Error::Usage(m) => Failure::Value(m),
            e @ (job::Error::Setting(_) | job::Error::Arguments(_) | job::Error::Read(_)) => {
                Failure::Value(e.to_string())
            }
            other => Failure::Runtime(other.to_string()),
        }
    }
}

/// `CompileError(message)` with `.diagnostics`, the list of them as dictionaries (the
/// package turns them into `Diagnostic` objects).
fn compile_error(py: Python<'_>, diags: &[Diagnostic], sources: &SourceMap) -> PyErr {
    let first = diags
        .iter()
        .find(|d| d.is_error())
        .or(diags.first())
        .map(|d| {
            let (line, col) = d
                .labels
                .first()
                .map_or((0, 0), |l| sources.line_col(l.span));
            format!(
                "{}:{line}:{col}: {}[{}]: {}",
                name(d, sources),
                word(d.severity),
                d.code,
                d.message
            )
        })
        .unwrap_or_else(|| "the scene has errors".into());
    let err = CompileError::new_err(first);
    let list = diagnostics(py, diags, sources);
    if let Ok(list) = list {
        let _ = err.value(py).setattr("diagnostics", list);
    }
    err
}

fn word(s: Severity) -> &'static str {
    match s {
        Severity::Error => "error",
        Severity::Warning => "warning",
        Severity::Note => "note",
    }
}

fn name<'s>(d: &Diagnostic, sources: &'s SourceMap) -> &'s str {
    d.labels.first().map_or("", |l| sources.name(l.span.file))
}

/// Every diagnostic as a dictionary: severity, code, message, file, line, column (1-based,
/// in characters), end line and column, the text of the primary span, notes and help.
fn diagnostics<'py>(
    py: Python<'py>,
    diags: &[Diagnostic],
    sources: &SourceMap,
) -> PyResult<Bound<'py, PyList>> {
    let list = PyList::empty(py);
    for d in diags {
        let item = PyDict::new(py);
        item.set_item("severity", word(d.severity))?;
        item.set_item("code", d.code)?;
        item.set_item("message", &d.message)?;
        match d.labels.first() {
            Some(l) => {
                let (line, col) = sources.line_col(l.span);
                let end = sdfc_compiler::Span {
                    start: l.span.end,
                    ..l.span
                };
                let (end_line, end_col) = sources.line_col(end);
                let text = sources.text(l.span.file);
                let span_text = text.get(l.span.range()).unwrap_or("");
                item.set_item("file", sources.name(l.span.file))?;
                item.set_item("line", line)?;
                item.set_item("column", col)?;
                item.set_item("end_line", end_line)?;
                item.set_item("end_column", end_col)?;
                item.set_item("span_text", span_text)?;
                item.set_item("label", &l.message)?;
            }
            None => {
                item.set_item("file", "")?;
                item.set_item("line", 0)?;
                item.set_item("column", 0)?;
                item.set_item("end_line", 0)?;
                item.set_item("end_column", 0)?;
                item.set_item("span_text", "")?;
                item.set_item("label", "")?;
            }
        }
        item.set_item("notes", d.notes.clone())?;
        item.set_item("help", d.help.clone())?;
        list.append(item)?;
    }
    Ok(list)
}

/// The name a scene given as text goes by (its imports are read from the current directory).
const TEXT_NAME: &str = "<string>.sdf";

/// `check(source, path, limits)`: (diagnostics, facts or None). `source` None reads `path`.
#[pyfunction]
#[pyo3(signature = (source=None, path=None, limits=Vec::new()))]
fn check<'py>(
    py: Python<'py>,
    source: Option<String>,
    path: Option<String>,
    limits: Vec<String>,
) -> PyResult<(Bound<'py, PyList>, Option<Bound<'py, PyDict>>)> {
    let limits = limits_of(&limits).map_err(|f| f.into_py(py))?;
    let mut src = open(source, path).map_err(|f| f.into_py(py))?;
    let loaded = src.check(&limits, 0.0);
    let list = diagnostics(py, &loaded.diagnostics, &loaded.sources)?;
    let Some(scene) = &loaded.scene else {
        return Ok((list, None));
    };
    let facts = PyDict::new(py);
    let analysis = analysis::analyse(scene);
    match analysis.root() {
        Some(root) => {
            facts.set_item("exactness", analysis::describe(root.facts.exactness))?;
            facts.set_item("lipschitz", root.facts.lipschitz)?;
            facts.set_item("proven", root.proven)?;
            facts.set_item("step_lipschitz", analysis.step_lipschitz())?;
            // The box in the scene's coordinates (the analysis's is the program's, less
            // the origin); infinite along an axis where the solid is unbounded.
            let o = scene.origin;
            let b = root.bounds;
            let at = |c: [f64; 3]| (c[0] + o[0], c[1] + o[1], c[2] + o[2]);
            facts.set_item("box", (at(b.min), at(b.max)))?;
        }
        None => {
            facts.set_item("exactness", py.None())?;
            facts.set_item("lipschitz", py.None())?;
            facts.set_item("proven", py.None())?;
            facts.set_item("step_lipschitz", py.None())?;
            facts.set_item("box", py.None())?;
        }
    }
    let traceable = analytic::traceable(scene);
    facts.set_item(
        "method",
        match traceable.choose(scene.settings.method) {
            analytic::Choice::March(_) => "march",
            _ => "trace",
        },
    )?;
    facts.set_item("summary", frontend::summary(&loaded, scene))?;
    facts.set_item(
        "method_reason",
        frontend::method(&loaded, scene, &traceable),
    )?;
    facts.set_item("animated", scene.animation.animated())?;
    Ok((list, Some(facts)))
}

/// The scene's text: `source`, or the file at `path` (which also names the text, for its
/// imports and diagnostics).
fn open(source: Option<String>, path: Option<String>) -> Result<Source, Failure> {
    match (source, path) {
        (Some(text), path) => Ok(Source::from_text(
            path.as_deref().unwrap_or(TEXT_NAME),
            text,
        )),
        (None, Some(path)) => {
            Source::read(std::path::Path::new(&path)).map_err(|e| Failure::Value(e.to_string()))
        }
        (None, None) => Err(Failure::Value(
            "give the scene's text (source=...) or its file (path=...)".into(),
        )),
    }
}

/// The default limits with each `NAME=VALUE` of `limits` applied, in order; their messages
/// name the parameter `limits` (`limits={"memory": 8192}`) rather than `--limit`.
fn limits_of(limits: &[String]) -> Result<Limits, Failure> {
    let mut l = Limits::default().spelled(Spelling::Parameters);
    for setting in limits {
        l.apply(setting)
            .map_err(|e| Failure::Value(e.to_string()))?;
    }
    Ok(l)
}

/// The worker threads every call shares (one per core).
/// A number that crosses to Python as its native-endian bytes.
trait NativeBytes: Copy {
    /// The bytes, as `to_ne_bytes` gives them.
    fn extend(self, out: &mut Vec<u8>);
}

macro_rules! native_bytes {
    ($($t:ty),*) => {
        $(impl NativeBytes for $t {
            fn extend(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_ne_bytes());
            }
        })*
    };
}
native_bytes!(f32, f64, u32);

/// Numbers as one array of native-endian bytes, the form arrays cross to Python in.
fn bytes<T: NativeBytes>(values: impl IntoIterator<Item = T>) -> Vec<u8> {
    let mut out = Vec::new();
    for x in values {
        x.extend(&mut out);
    }
    out
}

fn pool() -> Result<&'static rayon::ThreadPool, Failure> {
    static POOL: OnceLock<Result<rayon::ThreadPool, job::Threads>> = OnceLock::new();
    POOL.get_or_init(|| job::thread_pool(None, &sdfc_compiler::Limits::default()))
        .as_ref()
        .map_err(|e| Failure::Runtime(e.to_string()))
}

/// Runs `work` on a thread of its own with the GIL released; the calling thread checks for
/// signals every 50 ms, so that Ctrl-C raises `KeyboardInterrupt` at once (the work is left
/// to finish on its thread, and its result dropped).
fn interruptible<T: Send + 'static>(
    py: Python<'_>,
    work: impl FnOnce() -> Result<T, Failure> + Send + 'static,
) -> PyResult<T> {
    use std::sync::mpsc::{channel, RecvTimeoutError};
    let (tx, mut rx) = channel();
    std::thread::Builder::new()
        .name("sdfc".into())
        .spawn(move || {
            let _ = tx.send(work());
        })
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start a thread: {e}")))?;
    loop {
        let (got, back) = py.detach(move || (rx.recv_timeout(Duration::from_millis(50)), rx));
        rx = back;
        match got {
            Ok(result) => return result.map_err(|f| f.into_py(py)),
            Err(RecvTimeoutError::Timeout) => py.check_signals()?,
            Err(RecvTimeoutError::Disconnected) => {
                return Err(PyRuntimeError::new_err("sdfc's worker thread panicked"))
            }
        }
    }
}

/// The process's CUDA device (its primary context and compute capability), opened on first
/// use and held while the module is loaded.
fn cuda_device() -> &'static Result<sdfc_runtime::gpu::points::CudaDevice, RunError> {
    static CUDA: OnceLock<Result<sdfc_runtime::gpu::points::CudaDevice, RunError>> =
        OnceLock::new();
    CUDA.get_or_init(sdfc_runtime::gpu::points::open_cuda)
}

/// The process's wgpu device, opened on first use: renders and distances share it and the
/// pipelines compiled on it.
fn wgpu_device() -> Result<&'static std::sync::Arc<Gpu>, &'static sdfc_runtime::gpu::Error> {
    static WGPU: OnceLock<Result<std::sync::Arc<Gpu>, sdfc_runtime::gpu::Error>> = OnceLock::new();
    WGPU.get_or_init(|| Gpu::open(false).map(std::sync::Arc::new))
        .as_ref()
}

fn backend(name: &str) -> PyResult<Backend> {
    match name {
        "auto" => Ok(Backend::Auto),
        "cpu" => Ok(Backend::Cpu),
        "wgpu" => Ok(Backend::Wgpu),
        "cuda" => Ok(Backend::Cuda),
        other => Err(PyValueError::new_err(format!(
            "backend must be \"auto\", \"cpu\", \"wgpu\" or \"cuda\", not {other:?}"
        ))),
    }
}

#[pymodule]
fn _sdfc(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_class::<Scene>()?;
    m.add_function(wrap_pyfunction!(table::builtins, m)?)?;
    m.add_function(wrap_pyfunction!(table::records, m)?)?;
    m.add_function(wrap_pyfunction!(table::range_error, m)?)?;
    m.add_function(wrap_pyfunction!(table::fmt, m)?)?;
    m.add("CompileError", m.py().get_type::<CompileError>())?;
    Ok(())
}
