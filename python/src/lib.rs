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
mod table;

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

/// A scene: its text, the name it goes by, the render settings to override and the limits.
#[pyclass(frozen, name = "_Scene", module = "sdfc._sdfc")]
struct Scene {
    name: String,
    text: String,
    set: Vec<String>,
    limits: Limits,
    /// The render and the distance kernel prepared last.
    kept: kept::Kept,
}

/// What a render is asked for.
#[derive(Clone, Copy)]
struct Ask {
    size: Option<(u32, u32)>,
    aa: Option<u32>,
    backend: Backend,
    time: f64,
}

impl Scene {
    fn source(&self) -> Source {
        Source::from_text(&self.name, self.text.clone())
    }

    /// The job of a call: the scene's settings and `size` and `aa` overridden, its limits,
    /// `backend`; its diagnostics come back in its errors, unprinted.
    fn job(&self, size: Option<(u32, u32)>, aa: Option<u32>, backend: Backend) -> Job {
        Job {
            backend,
            overrides: Overrides {
                size,
                aa,
                set: self.set.clone(),
                ..Overrides::default()
            },
            limits: self.limits.clone(),
            quiet: true,
            ..Job::default()
        }
    }

    /// The scene checked at `time` with the settings overridden, or its errors.
    fn checked(
        &self,
        time: f64,
        size: Option<(u32, u32)>,
        aa: Option<u32>,
    ) -> Result<frontend::Checked, Failure> {
        let job = self.job(size, aa, Backend::Auto);
        let mut loaded = self.source().check(&job.limits, time);
        let scene = job.scene(&mut loaded, true)?;
        Ok(frontend::Checked {
            scene,
            sources: loaded.sources,
            format: frontend::DiagnosticFormat::Human,
        })
    }

    /// `checked`'s scene lowered within the limits, or the diagnostic of a program above
    /// them.
    fn lowered(&self, checked: &frontend::Checked) -> Result<Lowered, Failure> {
        let job = self.job(None, None, Backend::Auto);
        Ok(job.lower(&checked.scene, &checked.sources, &LowerOptions::default())?)
    }

    /// Renders as `sdfc render` does: checked, lowered, prepared, held to the memory limit.
    fn image(&self, ask: Ask) -> Result<Image, Failure> {
        Ok(self.rendered(ask, true)?.image)
    }

    /// The whole render, through the job's path as `sdfc render`'s: the image, and with
    /// `image_only` false its statistics and (on the CPU) its depth buffers.
    fn rendered(&self, ask: Ask, image_only: bool) -> Result<sdfc_runtime::cpu::Render, Failure> {
        let job = self.job(ask.size, ask.aa, ask.backend);
        let frame = job
            .frame(&mut self.source(), ask.time, true, &LowerOptions::default())
            .map_err(|e| match e {
                // Settings the scene cannot be rendered with (`method=trace` of a scene that
                // cannot be traced): a bad argument.
                job::Error::Backend(e) => Failure::Value(e.to_string()),
                e => e.into(),
            })?;
        let pool = pool()?;
        let setup = Setup {
            precision: Precision::F32,
            debug_nan: false,
            parameters: false,
            kernel: Kernel::Auto.choice(),
            image_only,
            // The arrays are the linear colours.
            finished: false,
            software: false,
        };
        let on = (ask.backend, &Devices::Auto);
        // The render prepared last for the same backend and outputs is prepared again as the
        // viewer's later loads are: its kernel kept where its text is unchanged.
        let before = self.kept.take_render(ask.backend, image_only);
        let job::Ready {
            scene, prepared, ..
        } = match (&before, ask.backend) {
            (Some(before), _) => job::prepare(pool, on, frame, &setup, job::Open::After(before))?,
            // The process's wgpu device, whose compiled pipelines later renders reuse.
            (None, Backend::Wgpu) => {
                let gpu = wgpu_device().map_err(|e| Failure::Runtime(e.to_string()))?;
                let open = job::Open::Gpu(gpu.clone());
                job::prepare(pool, on, frame, &setup, open)
                    .map_err(|e| Failure::Runtime(format!("the wgpu backend: {e}")))?
            }
            (None, backend) => {
                if matches!(backend, Backend::Cuda | Backend::Auto) {
                    // Holding the device's primary context keeps it from being torn down
                    // and built again (a fifth of a second) between renders.
                    let _ = cuda_device();
                }
                job::prepare(pool, on, frame, &setup, job::Open::Backend)?
            }
        };
        drop(before);
        job::check_memory(
            pool,
            &prepared,
            &scene,
            job::Use::Written {
                reference: false,
                aux: !image_only,
            },
            &job.limits,
            false,
        )?;
        let frame = pool
            .install(|| prepared.render(&scene, &|_| {}))
            .map_err(|e| Failure::Runtime(e.to_string()))?;
        self.kept.keep_render(ask.backend, image_only, prepared);
        Ok(frame.render)
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

#[pymethods]
impl Scene {
    /// Checks the scene at t = 0 (raising `CompileError`) and keeps it.
    #[new]
    #[pyo3(signature = (source=None, path=None, set=Vec::new(), limits=Vec::new(), params=Vec::new()))]
    fn new(
        py: Python<'_>,
        source: Option<String>,
        path: Option<String>,
        set: Vec<String>,
        limits: Vec<String>,
        params: Vec<(String, String)>,
    ) -> PyResult<Scene> {
        let mut limits = limits_of(&limits).map_err(|f| f.into_py(py))?;
        for (name, value) in &params {
            limits.set_param(name, value);
        }
        let src = open(source, path.clone()).map_err(|f| f.into_py(py))?;
        let scene = Scene {
            name: path.unwrap_or_else(|| TEXT_NAME.into()),
            text: src.text().to_string(),
            set,
            limits,
            kept: kept::Kept::default(),
        };
        scene.checked(0.0, None, None).map_err(|f| f.into_py(py))?;
        Ok(scene)
    }

    /// The settings a render without overrides uses: width, height, aa, fps, duration, and
    /// whether the scene reads `t`.
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let checked = self.checked(0.0, None, None).map_err(|f| f.into_py(py))?;
        let s = &checked.scene;
        let d = PyDict::new(py);
        d.set_item("width", s.settings.width)?;
        d.set_item("height", s.settings.height)?;
        d.set_item("aa", s.settings.aa)?;
        d.set_item("fps", s.animation.fps)?;
        d.set_item("duration", s.animation.duration)?;
        d.set_item("animated", s.animation.animated())?;
        Ok(d)
    }

    /// The scene's parameters (`param`), in source order: each a dict of name, type, value,
    /// default, doc, and min, max, step or choices where the parameter states them.
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let checked = self.checked(0.0, None, None).map_err(|f| f.into_py(py))?;
        let set = |d: &Bound<'py, PyDict>, key: &str, v: &sdfc_compiler::ParamValue| match v {
            sdfc_compiler::ParamValue::Float(x) => d.set_item(key, *x),
            sdfc_compiler::ParamValue::Int(i) => d.set_item(key, *i),
            sdfc_compiler::ParamValue::Bool(b) => d.set_item(key, *b),
            sdfc_compiler::ParamValue::Str(s) => d.set_item(key, s),
        };
        let mut out = Vec::new();
        for p in &checked.scene.params {
            let d = PyDict::new(py);
            d.set_item("name", &p.name)?;
            d.set_item("type", p.default.type_name())?;
            set(&d, "value", &p.value)?;
            set(&d, "default", &p.default)?;
            d.set_item("doc", &p.doc)?;
            match &p.accepts {
                sdfc_compiler::Accepts::Any => {}
                sdfc_compiler::Accepts::Range { lo, hi, step } => {
                    d.set_item("min", lo)?;
                    d.set_item("max", hi)?;
                    if let Some(s) = step {
                        d.set_item("step", s)?;
                    }
                }
                sdfc_compiler::Accepts::Choices(c) => d.set_item("choices", c.clone())?,
            }
            out.push(d);
        }
        Ok(out)
    }

    /// Renders: (width, height, bytes) with float32 linear RGB (`encoding` "linear"), uint8
    /// sRGB RGB ("srgb") or a PNG file's bytes ("png").
    #[pyo3(signature = (size=None, backend="auto", aa=None, t=0.0, encoding="linear"))]
    fn render<'py>(
        self_: Py<Self>,
        py: Python<'py>,
        size: Option<(u32, u32)>,
        backend: &str,
        aa: Option<u32>,
        t: f64,
        encoding: &str,
    ) -> PyResult<(u32, u32, Bound<'py, PyBytes>)> {
        let ask = Ask {
            size,
            aa,
            backend: self::backend(backend)?,
            time: t,
        };
        if !matches!(encoding, "linear" | "srgb" | "png") {
            return Err(PyValueError::new_err(format!(
                "encoding must be \"linear\", \"srgb\" or \"png\", not {encoding:?}"
            )));
        }
        let encoding = encoding.to_string();
        let scene = self_.clone_ref(py);
        let (w, h, bytes) = interruptible(py, move || {
            let image = scene.get().image(ask)?;
            let bytes = match encoding.as_str() {
                "linear" => image
                    .linear
                    .iter()
                    .flatten()
                    .flat_map(|x| x.to_ne_bytes())
                    .collect(),
                "srgb" => image
                    .to_rgba8()
                    .chunks_exact(4)
                    .flat_map(|p| [p[0], p[1], p[2]])
                    .collect(),
                _ => image
                    .encode_png()
                    .map_err(|e| Failure::Runtime(e.to_string()))?,
            };
            Ok((image.width, image.height, bytes))
        })?;
        Ok((w, h, PyBytes::new(py, &bytes)))
    }

    /// Where each pixel's camera rays first hit a surface, as `sdfc render --aux` writes it:
    /// (width, height, distances as f32 bytes with NaN where nothing was hit, coverage as f32
    /// bytes). Only the CPU renderer keeps depth buffers.
    #[pyo3(signature = (size=None, backend="cpu", aa=None, t=0.0))]
    #[allow(clippy::type_complexity)]
    fn depth<'py>(
        self_: Py<Self>,
        py: Python<'py>,
        size: Option<(u32, u32)>,
        backend: &str,
        aa: Option<u32>,
        t: f64,
    ) -> PyResult<(u32, u32, Bound<'py, PyBytes>, Bound<'py, PyBytes>)> {
        let ask = Ask {
            size,
            aa,
            backend: self::backend(backend)?,
            time: t,
        };
        let name = backend.to_string();
        let scene = self_.clone_ref(py);
        let (w, h, d, c) = interruptible(py, move || {
            let render = scene.get().rendered(ask, false)?;
            let Some(depth) = render.depth else {
                return Err(Failure::Value(format!(
                    "the {name} backend keeps no depth buffers; depth() needs backend=\"cpu\""
                )));
            };
            let d: Vec<u8> = depth
                .distance
                .iter()
                .flat_map(|x| x.to_ne_bytes())
                .collect();
            let c: Vec<u8> = depth
                .coverage
                .iter()
                .flat_map(|x| x.to_ne_bytes())
                .collect();
            Ok((depth.width, depth.height, d, c))
        })?;
        Ok((w, h, PyBytes::new(py, &d), PyBytes::new(py, &c)))
    }

    /// Distances and material ids at `points` (native-endian f64 triples): through the batch
    /// interpreter in f64 (`backend` "cpu"), or in f32 by the scene's WGSL part through wgpu
    /// or, as PTX, through CUDA: (distances as f64 or f32 bytes, ids as u32 bytes).
    #[pyo3(signature = (points, t=0.0, backend="cpu"))]
    fn distance<'py>(
        &self,
        py: Python<'py>,
        points: &[u8],
        t: f64,
        backend: &str,
    ) -> PyResult<(Bound<'py, PyBytes>, Bound<'py, PyBytes>)> {
        if points.len() % 24 != 0 {
            return Err(PyValueError::new_err("points must be (n, 3) float64"));
        }
        let backend = match backend {
            "cpu" | "wgpu" | "cuda" => backend.to_string(),
            other => {
                return Err(PyValueError::new_err(format!(
                    "backend must be \"cpu\", \"wgpu\" or \"cuda\", not {other:?}"
                )))
            }
        };
        let checked = self.checked(t, None, None).map_err(|f| f.into_py(py))?;
        let lowered = self.lowered(&checked).map_err(|f| f.into_py(py))?;
        let origin = checked.scene.origin;
        let xyz: Vec<[f64; 3]> = points
            .chunks_exact(24)
            .map(|c| {
                let f = |i: usize| {
                    let mut b = [0u8; 8];
                    b.copy_from_slice(&c[8 * i..8 * i + 8]);
                    f64::from_ne_bytes(b)
                };
                // The program's coordinates are the scene's less its origin.
                [f(0) - origin[0], f(1) - origin[1], f(2) - origin[2]]
            })
            .collect();
        if backend != "cpu" {
            let scene = checked.scene;
            let (d, m) = py
                .detach(|| self.kept.distances(&backend, &scene, &lowered, &xyz))
                .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
            return Ok((PyBytes::new(py, &d), PyBytes::new(py, &m)));
        }
        let pool = pool().map_err(|f| f.into_py(py))?;
        let (d, m) = py.detach(|| {
            let tape = Tape::new(&lowered.program, Outputs::DistanceAndMaterial);
            let mut d = vec![0.0f64; xyz.len()];
            let mut m = vec![0u32; xyz.len()];
            const TASK: usize = 4096;
            pool.install(|| {
                xyz.par_chunks(TASK)
                    .zip(d.par_chunks_mut(TASK).zip(m.par_chunks_mut(TASK)))
                    .for_each_init(
                        || {
                            (
                                Evaluator::<f64>::new(&tape, DEFAULT_CHUNK),
                                [vec![], vec![], vec![]],
                            )
                        },
                        |(eval, cols), (p, (d, m))| {
                            for (i, col) in cols.iter_mut().enumerate() {
                                col.clear();
                                col.extend(p.iter().map(|q| q[i]));
                            }
                            let [x, y, z] = &*cols;
                            eval.eval(x, y, z, d, Some(m));
                        },
                    )
            });
            let d: Vec<u8> = d.iter().flat_map(|x| x.to_ne_bytes()).collect();
            let m: Vec<u8> = m.iter().flat_map(|x| x.to_ne_bytes()).collect();
            (d, m)
        });
        Ok((PyBytes::new(py, &d), PyBytes::new(py, &m)))
    }

    /// The surface as `sdfc mesh` meshes it: (positions as f64 bytes, triangles as u32
    /// bytes, linear vertex colours as f32 bytes).
    #[pyo3(signature = (resolution=None, voxel=None, bounds=None, sharp=true, t=0.0))]
    #[allow(clippy::type_complexity)]
    fn mesh<'py>(
        self_: Py<Self>,
        py: Python<'py>,
        resolution: Option<u32>,
        voxel: Option<f64>,
        bounds: Option<([f64; 3], [f64; 3])>,
        sharp: bool,
        t: f64,
    ) -> PyResult<(
        Bound<'py, PyBytes>,
        Bound<'py, PyBytes>,
        Bound<'py, PyBytes>,
    )> {
        let ask = mesh::Ask::new(resolution, voxel, bounds, sharp, t)?;
        let scene = self_.clone_ref(py);
        let (p, tri, c) = interruptible(py, move || mesh::arrays(scene.get(), ask))?;
        Ok((
            PyBytes::new(py, &p),
            PyBytes::new(py, &tri),
            PyBytes::new(py, &c),
        ))
    }

    /// Meshes as `mesh` does and writes the mesh to `path` as `sdfc mesh -o PATH --up UP`
    /// does, in the format its extension names (.stl, .obj, .ply, .glb, .3mf): (triangles,
    /// vertices).
    #[pyo3(signature = (path, resolution=None, voxel=None, bounds=None, sharp=true, t=0.0, up=None))]
    #[allow(clippy::too_many_arguments)]
    fn save(
        self_: Py<Self>,
        py: Python<'_>,
        path: std::path::PathBuf,
        resolution: Option<u32>,
        voxel: Option<f64>,
        bounds: Option<([f64; 3], [f64; 3])>,
        sharp: bool,
        t: f64,
        up: Option<&str>,
    ) -> PyResult<(usize, usize)> {
        let ask = mesh::Ask::new(resolution, voxel, bounds, sharp, t)?;
        let up = up.map(mesh::up).transpose()?;
        let scene = self_.clone_ref(py);
        interruptible(py, move || mesh::save(scene.get(), ask, &path, up))
    }

    /// `sdfc compile --emit EMIT --part PART`: the bytes of the target.
    #[pyo3(signature = (emit, part="kernel", name=None, sm=70, t=0.0))]
    fn compile<'py>(
        &self,
        py: Python<'py>,
        emit: &str,
        part: &str,
        name: Option<String>,
        sm: u32,
        t: f64,
    ) -> PyResult<Bound<'py, PyBytes>> {
        let emit = match emit {
            "ast" => Emit::Ast,
            "ir" => Emit::Ir,
            "program" => Emit::Program,
            "rust" => Emit::Rust,
            "wgsl" => Emit::Wgsl,
            "spirv" => Emit::Spirv,
            "msl" => Emit::Msl,
            "glsl" => Emit::Glsl,
            "hlsl" => Emit::Hlsl,
            "ptx" => Emit::Ptx,
            "params" => Emit::Params,
            "scene-data" => Emit::SceneData,
            "layout" => Emit::Layout,
            "shadertoy" => Emit::Shadertoy,
            other => {
                return Err(PyValueError::new_err(format!(
                    "emit must be one of ast, ir, program, rust, wgsl, spirv, msl, glsl, hlsl, ptx, params, scene-data, layout, shadertoy; not {other:?}"
                )))
            }
        };
        let part = match part {
            "kernel" => Part::Kernel,
            "map" => Part::Map,
            other => {
                return Err(PyValueError::new_err(format!(
                    "part must be \"kernel\" or \"map\", not {other:?}"
                )))
            }
        };
        if name.is_some() && part != Part::Map {
            return Err(PyValueError::new_err(
                "name names the distance function of part=\"map\"",
            ));
        }
        if emit == Emit::Ast {
            let src = self.source();
            let mut sources = SourceMap::new();
            let entry = sources.add(self.name.clone(), src.text().to_string());
            let (ast, diags) = sdfc_compiler::parse(entry, sources.text(entry));
            if sdfc_compiler::diagnostics::has_errors(&diags) {
                return Err(compile_error(py, &diags, &sources));
            }
            return Ok(PyBytes::new(py, sdfc_compiler::dump_ast(&ast).as_bytes()));
        }
        let checked = self.checked(t, None, None).map_err(|f| f.into_py(py))?;
        if emit == Emit::Ir {
            return Ok(PyBytes::new(
                py,
                sdfc_compiler::dump_ir(&checked.scene).as_bytes(),
            ));
        }
        let lowered = self.lowered(&checked).map_err(|f| f.into_py(py))?;
        let bytes = match part {
            Part::Kernel => compile::emit(&checked.scene, &lowered, emit, sm, None),
            Part::Map => {
                let name =
                    name.unwrap_or_else(|| sdfc_compiler::wgsl::part::DEFAULT_NAME.to_string());
                if !sdfc_compiler::wgsl::part::valid_name(&name) {
                    return Err(PyValueError::new_err(format!(
                        "{name:?} is not a name for a function"
                    )));
                }
                compile::emit_map(&checked.scene, &lowered, emit, &name)
            }
        };
        bytes
            .map(|b| PyBytes::new(py, &b))
            .map_err(PyRuntimeError::new_err)
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
