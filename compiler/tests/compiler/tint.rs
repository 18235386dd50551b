//! WGSL that browsers accept: every example's kernel, and a kernel for every possible
//! combination of the kernel template's features (648 of them), compiled by Chromium's WebGPU
//! compiler (Tint, on SwiftShader).
//!
//! naga accepts code that Tint rejects (a literal of `f32::MAX` written as `3.4028235e38`, whose
//! exact value lies above `f32::MAX`), so this test hands the kernels to headless Chromium: a
//! page served on 127.0.0.1 calls `createShaderModule` and `getCompilationInfo` for every kernel
//! (Tint's front end: parsing, resolution, validation; a few milliseconds a kernel), and
//! `createComputePipelineAsync` (Tint's SPIR-V writer, then SwiftShader's compiler: 0.3 s to
//! 18 s a kernel, the largest examples the slowest) for the report's six scenes (`seed*`) and
//! for a set of feature combinations holding every pair of values of two features, then
//! reports each error with the kernel's name. The examples are `examples/*.sdf`,
//! `examples/scaling/*_10.sdf` and `*_1000.sdf` (whose instances are read from `scene_data`),
//! and `tests/in/ok/*.sdf`; and `examples/animation/*.sdf` as a sequence's kernels are
//! written, their constants read from `scene_data` (`Options::parameters`), with pipelines;
//! and the distance function alone (`sdfc compile --part map`) of every scene that gets a
//! pipeline (a module without an entry point: no pipeline of its own); and the interpreted
//! kernels of the examples (`--kernel interpreted`, one per distinct text), with pipelines.
//!
//! The browser is `$SDFC_CHROMIUM`, or `chromium` (Debian's package) on PATH. Without it, or
//! without a WebGPU adapter, the test prints that it skipped, unless `CI=true` or
//! `SDFC_REQUIRE_DEVICES=1` (set by `.ci/run`, which installs it): then it fails. Nothing but
//! 127.0.0.1 is reached, and the browser is killed after `deadline` (or when it exits early,
//! which fails). `SDFC_TINT_PIPELINES=all` makes a pipeline of every kernel (minutes).

use crate::common;
use rayon::prelude::*;
use sdfc_compiler::wgsl::{self, Options};
use std::collections::{BTreeMap, BTreeSet};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// The longest the browser may take for `kernels` kernels, `pipelines` of them with pipelines
/// (each well under a second on SwiftShader, on two busy cores).
fn deadline(kernels: usize, pipelines: usize) -> Duration {
    Duration::from_secs(60)
        + Duration::from_millis(100) * kernels as u32
        + Duration::from_secs(5) * pipelines as u32
}

/// The features of the kernel template, in the order of a combination's bits.
const FEATURES: [&str; 13] = [
    "ANALYTIC",
    "RELAX",
    "POINT",
    "DIRECTIONAL",
    "SOFT",
    "CHECKER",
    "MATERIALS",
    "TRANSPARENT",
    "SECONDARY",
    "REFRACTION",
    "SCENE_DATA",
    "DEBUG_NAN",
    "MEDIA",
];

/// One kernel for the browser.
#[derive(serde::Serialize)]
struct Job {
    name: String,
    code: String,
    /// Whether a compute pipeline is made of it too.
    pipeline: bool,
}

/// What the page reports of one kernel.
#[derive(serde::Deserialize, Debug)]
struct Report {
    name: String,
    /// Tint's errors and the pipeline's, as text; empty when it was accepted.
    errors: Vec<String>,
    /// Milliseconds from the module's creation to its last answer.
    ms: f64,
}

/// What the page posts: one report, the end, that WebGPU is unavailable, or an error of its
/// own.
#[derive(serde::Deserialize, Debug)]
#[serde(tag = "kind", rename_all = "lowercase")]
enum Message {
    Report(Report),
    Done { adapter: String },
    Unavailable { message: String },
    Fatal { message: String },
}

/// Whether CI asked for every device: then a missing browser or adapter fails.
fn required() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true")
        || std::env::var("SDFC_REQUIRE_DEVICES").is_ok_and(|v| v == "1")
}

fn skip(why: &str) {
    assert!(!required(), "CI=true or SDFC_REQUIRE_DEVICES=1, but {why}");
    println!("tint: SKIPPED: {why}");
}

/// The `.sdf` files directly inside `dir` (relative to the workspace root) whose names pass
/// `keep`, sorted.
fn sdf_files(dir: &str, keep: impl Fn(&str) -> bool) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(Path::new("..").join(dir))
        .unwrap_or_else(|e| panic!("cannot list {dir}: {e}"))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "sdf"))
        .filter(|p| keep(&p.file_stem().unwrap_or_default().to_string_lossy()))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no .sdf files in {dir}");
    files
}

/// Whether every kernel gets a pipeline (`SDFC_TINT_PIPELINES=all`), not only those of
/// `example_jobs` and `combo_jobs`.
fn all_pipelines() -> bool {
    std::env::var("SDFC_TINT_PIPELINES").is_ok_and(|v| v == "all")
}

/// The kernels of the examples and of `tests/in/ok`, with pipelines for the report's six
/// scenes (`seed*`).
fn example_jobs() -> Vec<Job> {
    let examples = sdf_files("examples", |_| true);
    let scaling = sdf_files("examples/scaling", |n| {
        n.ends_with("_10") || n.ends_with("_1000")
    });
    let ok = sdf_files("compiler/tests/in/ok", |_| true);
    let animated = sdf_files("examples/animation", |_| true);
    let all = examples.iter().chain(&scaling).chain(&ok).map(|p| {
        let seed = p
            .file_stem()
            .is_some_and(|s| s.to_string_lossy().starts_with("seed"));
        (p, seed || all_pipelines(), false)
    });
    let all = all.chain(animated.iter().map(|p| (p, true, true)));
    all.flat_map(|(path, pipeline, parameters)| {
        let loaded = common::load(path).expect("readable");
        let scene = loaded
            .scene
            .unwrap_or_else(|| panic!("{} has errors", path.display()));
        let lowered = sdfc_compiler::Lowered::new(&scene);
        let options = Options {
            parameters,
            ..Options::default()
        };
        let kernel = wgsl::write_with(&scene, &lowered, &options)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(
            kernel.contract.features.contains(&("PARAMS", true)),
            parameters
        );
        let name = path
            .strip_prefix("..")
            .unwrap_or(path)
            .display()
            .to_string();
        // The distance function alone (`sdfc compile --part map`) of the report's scenes.
        let part = pipeline.then(|| Job {
            name: format!("{name} --part map"),
            code: wgsl::part::write(&scene, &lowered, "map")
                .unwrap_or_else(|e| panic!("{name}: {e}"))
                .source,
            pipeline: false,
        });
        let kernel = Job {
            name,
            code: kernel.source,
            pipeline,
        };
        std::iter::once(kernel).chain(part)
    })
    .collect()
}

/// The interpreted kernels (`--kernel interpreted`) of the examples, marched: one job per
/// distinct text (most examples share one), with pipelines.
fn interpreted_jobs() -> Vec<Job> {
    let mut seen = BTreeMap::new();
    // With the scene that imports a triangle mesh, whose kernel calls the mesh walk.
    let mesh = sdf_files("examples/mesh", |n| n == "import");
    for path in sdf_files("examples", |_| true).into_iter().chain(mesh) {
        let loaded = common::load(&path).expect("readable");
        let mut scene = loaded
            .scene
            .unwrap_or_else(|| panic!("{} has errors", path.display()));
        scene.settings.method = sdfc_compiler::Method::March;
        let lowered = sdfc_compiler::Lowered::new(&scene);
        let options = Options {
            kernel: wgsl::KernelChoice::Interpreted,
            ..Options::default()
        };
        let kernel = wgsl::write_with(&scene, &lowered, &options)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let name = path
            .strip_prefix("..")
            .unwrap_or(&path)
            .display()
            .to_string();
        seen.entry(kernel.source).or_insert(name);
    }
    seen.into_iter()
        .map(|(code, name)| Job {
            name: format!("{name} --kernel interpreted"),
            code,
            pipeline: true,
        })
        .collect()
}

/// A combination of features, one bit each in the order of `FEATURES`.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct Combo(u32);

impl Combo {
    fn has(self, feature: &str) -> bool {
        let i = FEATURES
            .iter()
            .position(|f| *f == feature)
            .expect("a feature");
        self.0 & (1 << i) != 0
    }

    /// Whether some scene has exactly these features: relaxation and soft lights only in a
    /// marched scene, softness only with a light, a checker, transparency or reflections only
    /// with a material besides the default one, refraction exactly when transparency meets
    /// secondary rays, media (glass overlapping a solid) only for refraction in a marched
    /// scene.
    fn possible(self) -> bool {
        let h = |f| self.has(f);
        !(h("ANALYTIC") && (h("RELAX") || h("SOFT")))
            && (!h("MEDIA") || (h("REFRACTION") && !h("ANALYTIC")))
            && (h("MATERIALS") || !(h("CHECKER") || h("TRANSPARENT") || h("SECONDARY")))
            && (!h("SOFT") || h("POINT") || h("DIRECTIONAL"))
            && h("REFRACTION") == (h("TRANSPARENT") && h("SECONDARY"))
    }

    fn name(self) -> String {
        let on: Vec<&str> = FEATURES.iter().copied().filter(|f| self.has(f)).collect();
        format!("features[{}]", on.join(" "))
    }

    /// A scene with these features (lights, materials and settings), and the options.
    fn scene(self) -> (String, Options) {
        let h = |f| self.has(f);
        let mut optics = String::new();
        if h("TRANSPARENT") {
            optics.push_str(", transparency: 0.6, ior: 1.4");
        }
        if h("SECONDARY") && !h("TRANSPARENT") {
            optics.push_str(", reflect: 0.3");
        }
        let mut text = String::new();
        if h("MATERIALS") {
            let kind = if h("CHECKER") {
                "checker { a: (0.9, 0.9, 0.9), b: (0.1, 0.1, 0.1), size: 0.5"
            } else {
                "phong { color: (0.9, 0.2, 0.1), specular: 0.5, shininess: 32"
            };
            text += &format!("material m0 = {kind}{optics} }};\n");
        }
        text += "camera { position: (0, 2, -6), look_at: (0, 0.8, 0) }\n";
        let soft = |on: bool| if on { ", penumbra: 7deg" } else { "" };
        if h("POINT") {
            text += &format!(
                "light point {{ position: (3, 6, -4){} }}\n",
                soft(h("SOFT"))
            );
        }
        if h("DIRECTIONAL") {
            text += &format!(
                "light directional {{ direction: (1, -1.5, 1){} }}\n",
                soft(h("SOFT") && !h("POINT"))
            );
        }
        text += &format!(
            "render {{ width: 64, height: 48, max_depth: {}, relaxation: {}, method: \"{}\" }}\n",
            if h("SECONDARY") { 2 } else { 0 },
            if h("RELAX") { "1.5" } else { "1" },
            if h("ANALYTIC") { "trace" } else { "march" }
        );
        // The others keep the default material (material 0).
        let paint = if h("MATERIALS") { " @ m0" } else { "" };
        text += &format!("scene {{\n  sphere(1).translate(-1.5, 1, 0){paint};\n");
        text += "  sphere(0.7).translate(1.5, 0.7, 0);\n";
        text += "  box((0.4, 0.4, 0.4)).translate(0, 0.4, 2);\n";
        if h("MEDIA") {
            // A floor under the glass ball, which rests on it.
            text += "  plane();\n";
        }
        if !h("ANALYTIC") {
            // Not an instance: a marched scene's `rest_map` has something in it.
            text += "  box((0.3, 0.6, 0.3)).twist(1).translate(0, 0.6, -1.5);\n";
        }
        text += "}\n";
        let mut options = Options {
            debug_nan: h("DEBUG_NAN"),
            ..Options::default()
        };
        if h("SCENE_DATA") {
            options.max_unrolled = 0;
            options.max_instances = 0;
        }
        (text, options)
    }
}

/// The features a kernel was specialised for, as a combination.
fn combo_of(kernel: &wgsl::Kernel) -> Combo {
    let on: BTreeSet<&str> = kernel
        .contract
        .features
        .iter()
        .filter(|(_, on)| *on)
        .map(|(n, _)| *n)
        .collect();
    let bits = FEATURES
        .iter()
        .enumerate()
        .filter(|(_, f)| on.contains(*f))
        .fold(0, |acc, (i, _)| acc | (1 << i));
    Combo(bits)
}

/// Every possible combination, with pipelines for a subset in which every pair of values of
/// two features (among the possible combinations) occurs.
fn combo_jobs() -> Vec<Job> {
    let combos: Vec<Combo> = (0..1u32 << FEATURES.len())
        .map(Combo)
        .filter(|c| c.possible())
        .collect();
    let pairs = |c: Combo| {
        let mut out = Vec::new();
        for i in 0..FEATURES.len() {
            for j in i + 1..FEATURES.len() {
                out.push((i, j, c.0 >> i & 1, c.0 >> j & 1));
            }
        }
        out
    };
    let mut uncovered: BTreeSet<_> = combos.iter().flat_map(|&c| pairs(c)).collect();
    let mut with_pipeline = BTreeSet::new();
    while !uncovered.is_empty() {
        let best = combos
            .iter()
            .copied()
            .max_by_key(|&c| pairs(c).iter().filter(|p| uncovered.contains(*p)).count())
            .expect("combinations");
        pairs(best).iter().for_each(|p| {
            uncovered.remove(p);
        });
        with_pipeline.insert(best);
    }
    combos
        .par_iter()
        .map(|&combo| {
            let (text, options) = combo.scene();
            let (scene, diags, _) = sdfc_compiler::check_str("features.sdf", &text);
            let scene = scene.unwrap_or_else(|| panic!("{}:\n{text}\n{diags:?}", combo.name()));
            let lowered = sdfc_compiler::Lowered::new(&scene);
            let kernel = wgsl::write_with(&scene, &lowered, &options)
                .unwrap_or_else(|e| panic!("{}: {e}", combo.name()));
            assert!(
                combo_of(&kernel) == combo,
                "the scene meant for {} gives {}:\n{text}",
                combo.name(),
                combo_of(&kernel).name()
            );
            Job {
                name: combo.name(),
                code: kernel.source,
                pipeline: with_pipeline.contains(&combo) || all_pipelines(),
            }
        })
        .collect()
}

#[test]
fn features_are_the_templates() {
    // Every `//#if` flag of the template is one of FEATURES, and every feature is a flag.
    // The template is the kernel and its shading part, appended to it.
    let template = ["kernel.wgsl", "shading.wgsl"]
        .map(|f| {
            std::fs::read_to_string(format!("src/back/wgsl/{f}")).expect("the kernel template")
        })
        .concat();
    let flags: BTreeSet<&str> = template
        .lines()
        .filter_map(|l| l.trim().strip_prefix("//#if "))
        .map(|f| f.trim().trim_start_matches('!'))
        .collect();
    // Not among the combinations: colour fields reach Tint through the examples that use
    // them (rock.sdf), the sky, occlusion, fog and the tone curve (GRADE) through
    // gallery.sdf, which uses all four, the physically based material (PBR, and FRESNEL
    // with it, whose blocks are all in its kernel) through studio.sdf, the path tracer
    // (PATH) through studio_path.sdf, a checker of two materials (MATERIAL_CHECKER) through
    // checker_materials.sdf and the glow of the marching steps (GLOW) through glow_blob.sdf.
    let by_examples = [
        "COLOUR_FIELDS",
        "MATERIAL_CHECKER",
        "GLOW",
        "SKY",
        "OCCLUSION",
        "FOG",
        "GRADE",
        "FRESNEL",
        "PBR",
        "PATH",
    ];
    let combined: BTreeSet<&str> = flags
        .iter()
        .copied()
        .filter(|f| !by_examples.contains(f))
        .collect();
    for f in by_examples {
        assert!(flags.contains(f), "{f}");
    }
    assert_eq!(combined, FEATURES.iter().copied().collect::<BTreeSet<_>>());
}

/// The page: compiles every kernel of `/jobs` and posts one message per kernel to `/report`.
const PAGE: &str = r#"<!doctype html>
<title>sdfc: WGSL through Tint</title>
<script>
const post = (m) => fetch('/report', {method: 'POST', body: JSON.stringify(m)});
(async () => {
  if (!navigator.gpu) return post({kind: 'unavailable', message: 'navigator.gpu is missing'});
  const adapter = await navigator.gpu.requestAdapter();
  if (!adapter) return post({kind: 'unavailable', message: 'no WebGPU adapter'});
  const device = await adapter.requestDevice();
  let lost = null;
  device.lost.then((i) => { lost = `device lost: ${i.message}`; });
  const jobs = await (await fetch('/jobs')).json();
  const pending = [];
  for (const job of jobs) {
    const errors = [];
    const start = performance.now();
    device.pushErrorScope('validation');
    const module = device.createShaderModule({code: job.code, label: job.name});
    const info = await module.getCompilationInfo();
    for (const m of info.messages) {
      if (m.type === 'error') errors.push(`${m.lineNum}:${m.linePos}: ${m.message}`);
    }
    // The scope repeats the compilation's errors: kept only when there are none.
    const scope = device.popErrorScope().then((e) => { if (e && errors.length === 0) errors.push(e.message); });
    let pipeline = Promise.resolve();
    if (job.pipeline && errors.length === 0) {
      pipeline = device.createComputePipelineAsync({layout: 'auto', compute: {module, entryPoint: 'main'}})
        .then(() => {}, (e) => { errors.push(`pipeline: ${e.message}`); });
    }
    const done = Promise.all([scope, pipeline]).then(() => {
      if (lost) errors.push(lost);
      return post({kind: 'report', name: job.name, errors, ms: performance.now() - start});
    });
    pending.push(done);
    // At most two pipelines are compiled at once.
    if (pending.length >= 2) await pending.shift();
  }
  await Promise.all(pending);
  const i = adapter.info || {};
  await post({kind: 'done', adapter: `${i.vendor} ${i.architecture} ${i.description}`.trim()});
})().catch((e) => post({kind: 'fatal', message: `page: ${e}`}));
</script>
"#;

/// Serves the page and the jobs, and forwards each posted message, until the receiver is gone.
fn serve(listener: TcpListener, jobs: String, messages: mpsc::Sender<String>) {
    for stream in listener.incoming() {
        let Ok(stream) = stream else { continue };
        match answer(stream, &jobs) {
            Ok(Some(body)) => {
                if messages.send(body).is_err() {
                    return;
                }
            }
            Ok(None) => {}
            // The browser may drop a request it no longer needs (its icon).
            Err(_) => {}
        }
    }
}

/// Answers one request (HTTP/1.1, one per connection); returns the body of a POST.
fn answer(stream: TcpStream, jobs: &str) -> std::io::Result<Option<String>> {
    stream.set_read_timeout(Some(Duration::from_secs(30)))?;
    let mut reader = BufReader::new(stream);
    let mut request = String::new();
    reader.read_line(&mut request)?;
    let mut length = 0usize;
    loop {
        let mut line = String::new();
        if reader.read_line(&mut line)? == 0 || line.trim().is_empty() {
            break;
        }
        if let Some((key, value)) = line.split_once(':') {
            if key.eq_ignore_ascii_case("content-length") {
                length = value.trim().parse().unwrap_or(0);
            }
        }
    }
    let mut body = vec![0; length];
    reader.read_exact(&mut body)?;
    let path = request.split_whitespace().nth(1).unwrap_or("");
    let (status, kind, content) = match (request.starts_with("POST"), path) {
        (false, "/") => ("200 OK", "text/html", PAGE),
        (false, "/jobs") => ("200 OK", "application/json", jobs),
        (true, "/report") => ("200 OK", "text/plain", ""),
        _ => ("404 Not Found", "text/plain", ""),
    };
    let mut stream = reader.into_inner();
    write!(
        stream,
        "HTTP/1.1 {status}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{content}",
        content.len()
    )?;
    stream.flush()?;
    Ok((path == "/report").then(|| String::from_utf8_lossy(&body).into_owned()))
}

/// The browser, killed and its profile removed when dropped.
struct Browser {
    child: Child,
    profile: PathBuf,
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_dir_all(&self.profile);
    }
}

/// The browser's path: `$SDFC_CHROMIUM`, or `chromium` on PATH.
fn chromium() -> Option<PathBuf> {
    if let Some(path) = std::env::var_os("SDFC_CHROMIUM") {
        return Some(PathBuf::from(path));
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|dir| dir.join("chromium"))
        .find(|p| p.is_file())
}

fn launch(exe: &Path, url: &str) -> std::io::Result<Browser> {
    let profile = std::env::temp_dir().join(format!("sdfc-tint-{}", std::process::id()));
    std::fs::create_dir_all(&profile)?;
    let child = Command::new(exe)
        .args([
            "--headless=new",
            "--enable-unsafe-webgpu",
            "--no-sandbox",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--disable-extensions",
            "--no-first-run",
            "--no-default-browser-check",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(url)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()?;
    Ok(Browser { child, profile })
}

#[test]
fn kernels_pass_tint() {
    let started = Instant::now();
    let mut jobs = example_jobs();
    jobs.extend(combo_jobs());
    jobs.extend(interpreted_jobs());
    let generated = started.elapsed();
    let Some(exe) = chromium() else {
        return skip("no chromium on PATH (set SDFC_CHROMIUM to another)");
    };
    let names: BTreeSet<String> = jobs.iter().map(|j| j.name.clone()).collect();
    assert_eq!(names.len(), jobs.len(), "two kernels of one name");
    let pipelines = jobs.iter().filter(|j| j.pipeline).count();
    let listener = TcpListener::bind("127.0.0.1:0").expect("a port on 127.0.0.1");
    let url = format!("http://{}/", listener.local_addr().expect("an address"));
    let body = serde_json::to_string(&jobs).expect("JSON");
    let (send, receive) = mpsc::channel();
    std::thread::spawn(move || serve(listener, body, send));
    let mut browser = launch(&exe, &url).unwrap_or_else(|e| panic!("cannot start {exe:?}: {e}"));
    let allowed = deadline(jobs.len(), pipelines);
    let end = Instant::now() + allowed;
    let mut reports: BTreeMap<String, Vec<String>> = BTreeMap::new();
    let mut times: Vec<(f64, String)> = Vec::new();
    let adapter = loop {
        let missing = || {
            let missing: Vec<&String> =
                names.iter().filter(|n| !reports.contains_key(*n)).collect();
            format!(
                "{} kernels unreported, from {:?}",
                missing.len(),
                missing.first()
            )
        };
        if let Ok(Some(status)) = browser.child.try_wait() {
            panic!(
                "the browser exited ({status}) before it finished; {}",
                missing()
            );
        }
        let text = match receive.recv_timeout(Duration::from_secs(1)) {
            Ok(text) => text,
            Err(_) if Instant::now() < end => continue,
            Err(_) => panic!(
                "the browser did not finish within {allowed:?}; {}",
                missing()
            ),
        };
        match serde_json::from_str::<Message>(&text) {
            Ok(Message::Report(r)) => {
                times.push((r.ms, r.name.clone()));
                reports.insert(r.name, r.errors);
            }
            Ok(Message::Done { adapter }) => break adapter,
            Ok(Message::Unavailable { message }) => {
                drop(browser);
                return skip(&format!("the browser has no WebGPU: {message}"));
            }
            Ok(Message::Fatal { message }) => panic!("the page failed: {message}"),
            Err(e) => panic!("a message that is not understood: {e}: {text}"),
        }
    };
    drop(browser);
    let rejected: Vec<String> = reports
        .iter()
        .filter(|(_, errors)| !errors.is_empty())
        .map(|(name, errors)| format!("{name}:\n  {}", errors.join("\n  ")))
        .collect();
    println!(
        "tint: {} kernels ({pipelines} with pipelines) on {adapter}: generated in {:.1} s, all in {:.1} s",
        jobs.len(),
        generated.as_secs_f64(),
        started.elapsed().as_secs_f64()
    );
    times.sort_by(|a, b| b.0.total_cmp(&a.0));
    let slowest: Vec<String> = times
        .iter()
        .take(5)
        .map(|(ms, name)| format!("{name} {:.2} s", ms / 1000.0))
        .collect();
    println!("tint: slowest: {}", slowest.join(", "));
    assert_eq!(reports.len(), jobs.len(), "kernels without a report");
    assert!(
        rejected.is_empty(),
        "{} of {} kernels rejected by Tint:\n{}",
        rejected.len(),
        jobs.len(),
        rejected.join("\n")
    );
}
