//! `_Scene`, a scene held by Python: its text, settings and limits, and what it does
//! (check, render, distances, mesh, compile), each call through the runtime's job with the
//! kernel and device prepared last kept for the next.

use super::*;

/// A scene: its text, the name it goes by, the render settings to override and the limits.
#[pyclass(frozen, name = "_Scene", module = "sdfc._sdfc")]
pub(crate) struct Scene {
    name: String,
    text: String,
    set: Vec<String>,
    pub(crate) limits: Limits,
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
        let overrides = Overrides {
            size,
            aa,
            set: self.set.clone(),
            ..Overrides::default()
        };
        Job {
            quiet: true,
            ..Job::new(backend, overrides, self.limits.clone())
        }
    }

    /// The scene checked at `time` with the settings overridden, or its errors.
    pub(crate) fn checked(
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
                job::Error::Backend(e @ sdfc_runtime::backend::Error::NotTraceable(_)) => {
                    Failure::Value(e.to_string())
                }
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
        // The render prepared last for the same backend and outputs is taken over: its
        // device kept, and its kernel where the text is unchanged.
        let before = self.kept.take_render(ask.backend, image_only);
        let job::Ready {
            scene, prepared, ..
        } = match (before, ask.backend) {
            (Some(before), _) => {
                job::prepare(pool, on, frame, &setup, job::Open::Replacing(before))?
            }
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
                "linear" => super::bytes(image.linear.iter().flatten().copied()),
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
            let d = super::bytes(depth.distance.iter().copied());
            let c = super::bytes(depth.coverage.iter().copied());
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
            let (d, m) = (
                super::bytes(d.iter().copied()),
                super::bytes(m.iter().copied()),
            );
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
