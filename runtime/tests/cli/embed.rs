//! Generated code a user takes away (docs/embedding.md): the distance function alone
//! (`sdfc compile --part map`) in WGSL, GLSL, HLSL, MSL and Rust, used as a user would use
//! it: two scenes' parts in one WGSL module with a user's function calling both, validated by
//! naga and written by naga to the other languages; the part's function is the renderer's own
//! `map`, word for word; the command line's refusals; and the kernel run from the files
//! `--emit wgsl|params|layout` writes by a plain wgpu program (on lavapipe), giving `sdfc
//! render`'s image byte for byte; `--emit scene-data|params` the bytes the renderer binds; and the
//! Shadertoy page compiled as Shadertoy wraps it and rendered through WebGL.

use crate::cli::TestDir;
use crate::common::assert_has;
use crate::common::{run_ok, words};
use sdfc_compiler::{
    shader::{self, Lang},
    wgsl,
};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples")
        .join(name)
}

fn sdfc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .args(args)
        .output()
        .expect("run sdfc")
}

/// `sdfc` run with `args`, which must succeed: its output.
#[track_caller]
fn ok(args: &[&str]) -> Output {
    run_ok(Command::new(env!("CARGO_BIN_EXE_sdfc")).args(args), "sdfc")
}

/// `sdfc compile FILE --emit LANG --part map --name NAME`, which must succeed.
fn part(file: &str, lang: &str, name: &str) -> String {
    let path = example(file);
    let out = ok(&[
        "compile",
        path.to_str().expect("utf-8 path"),
        "--emit",
        lang,
        "--part",
        "map",
        "--name",
        name,
    ]);
    String::from_utf8(out.stdout).expect("text")
}

fn validate(source: &str) -> (naga::Module, naga::valid::ModuleInfo) {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("{}\n{source}", e.emit_to_string(source)));
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{}", e.emit_to_string(source)));
    (module, info)
}

/// A user's shader: two scenes' parts and a compute entry point that calls both functions
/// and reads both material tables.
const USER: &str = "
@group(0) @binding(0) var<storage, read_write> out: array<vec4<f32>>;

fn both(p: vec3<f32>) -> vec4<f32> {
    let a = one(p);
    let b = two(p - vec3<f32>(4.0, 0.0, 0.0));
    let m = one_MATERIALS[min(u32(a.y), one_MATERIAL_COUNT - 1u)];
    let n = two_MATERIALS[min(u32(b.y), two_MATERIAL_COUNT - 1u)];
    let d = min(a.x, two_distance(p - vec3<f32>(4.0, 0.0, 0.0)));
    return vec4<f32>(select(n.color, m.color, a.x < b.x), d);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let p = vec3<f32>(f32(id.x) * 0.01, 0.5, -1.0);
    out[id.x] = both(p);
}
";

#[test]
fn two_scenes_parts_and_a_users_function_validate_in_one_module() {
    let source = format!(
        "{}\n{}\n{USER}",
        part("seed1.sdf", "wgsl", "one"),
        part("seed2.sdf", "wgsl", "two")
    );
    let (module, info) = validate(&source);
    // The user's module goes on through naga to the other languages.
    let kernel = wgsl::Kernel {
        source: source.clone(),
        module,
        info,
        contract: wgsl::Contract::default(),
        data: None,
    };
    for lang in [Lang::SpirV, Lang::Msl, Lang::Glsl, Lang::Hlsl] {
        shader::write(&kernel, lang).unwrap_or_else(|e| panic!("{lang:?}: {e}"));
    }
}

#[test]
fn each_language_declares_the_named_functions_and_materials() {
    for (lang, map, distance) in [
        (
            "wgsl",
            "fn ball(p: vec3<f32>) -> vec2<f32>",
            "fn ball_distance(",
        ),
        ("glsl", "vec2 ball(vec3 p)", "float ball_distance("),
        ("hlsl", "float2 ball(float3 p)", "float ball_distance("),
        ("msl", "metal::float2 ball(", "float ball_distance("),
        (
            "rust",
            "pub fn ball(p: glam::Vec3) -> (f32, u32)",
            "pub fn ball_f64(",
        ),
    ] {
        let text = part("seed3.sdf", lang, "ball");
        assert!(text.contains(map), "{lang}: no `{map}`\n{text}");
        assert!(text.contains(distance), "{lang}: no `{distance}`");
        if lang != "rust" {
            assert!(text.contains("ball_MATERIALS"), "{lang}: no material table");
            // Nothing of the renderer comes along.
            for kernel_only in ["params", "counters", "shadow", "main("] {
                assert!(!text.contains(kernel_only), "{lang}: `{kernel_only}`");
            }
        }
    }
    // GLSL is a library: no entry point, no workgroup size.
    let glsl = part("seed3.sdf", "glsl", "ball");
    assert!(glsl.starts_with("#version 450 core\n"), "{glsl}");
    assert!(!glsl.contains("local_size_x") && !glsl.contains("void main"));
}

/// A scene's glow of the marching steps (`render { glow, glow_color }`) comes with its part in
/// every language: `NAME_LIPSCHITZ` and `NAME_glow(d)`, `glow_color·e^(−|d|/glow)`, for a
/// user's march to add at each step as the renderers do; a scene without a glow has neither.
#[test]
fn the_part_carries_the_glow_of_the_marching_steps() {
    for (lang, glow) in [
        ("wgsl", "fn blob_glow(d: f32) -> vec3<f32>"),
        ("glsl", "vec3 blob_glow(float d)"),
        ("hlsl", "float3 blob_glow(float d)"),
        ("msl", "metal::float3 blob_glow("),
        ("rust", "pub fn blob_glow(d: f32) -> [f32; 3]"),
    ] {
        let text = part("glow_blob.sdf", lang, "blob");
        assert!(text.contains(glow), "{lang}: no `{glow}`\n{text}");
        assert!(text.contains("blob_LIPSCHITZ"), "{lang}: no L");
        let plain = part("seed3.sdf", lang, "ball");
        assert!(
            !plain.contains("_glow") && !plain.contains("_LIPSCHITZ"),
            "{lang}"
        );
    }
    // glow: 0.05, glow_color: (0.006, 0.015, 0.04) (examples/glow_blob.sdf).
    let wgsl = part("glow_blob.sdf", "wgsl", "blob");
    assert_has(
        &wgsl,
        &["return vec3<f32>(0.006, 0.015, 0.04) * exp(-abs(d) * 20.0);"],
    );
    let rust = part("glow_blob.sdf", "rust", "blob");
    assert_has(&rust, &["let w = (-d.abs() * 20.0).exp();"]);
}

/// The part's function is the renderer kernel's `map`, word for word (the kernel's is
/// compared with the CPU renderer by runtime/tests/render/render.rs), and its table is the scene's
/// materials in order.
#[test]
fn the_part_is_the_kernels_own_map() {
    let path = example("seed4.sdf");
    let loaded = sdfc_runtime::frontend::load(&path).expect("readable");
    let scene = loaded.scene.expect("checks");
    let lowered = sdfc_compiler::Lowered::new(&scene);
    let kernel = wgsl::write(&scene, &lowered).expect("kernel");
    let part = wgsl::part::write(&scene, &lowered, "map").expect("part");
    let start = part.source.find("fn map(").expect("map");
    let end = start + part.source[start..].find("\n}\n").expect("end of map") + 3;
    assert!(
        kernel.source.contains(&part.source[start..end]),
        "the part's map is not the kernel's"
    );
    let table = part.source.matches("    map_Material(").count();
    assert_eq!(table, scene.materials.len());
    for (id, m) in scene.materials.iter().enumerate() {
        let comment = format!("    // {id}: {}\n    map_Material(", m.name);
        assert!(part.source.contains(&comment), "{comment}");
    }
}

#[test]
fn the_command_line_refuses_what_has_no_part() {
    let path = example("seed1.sdf");
    let file = path.to_str().expect("utf-8 path");
    let cases = [
        ("--emit wgsl --part map --name loop", "not a name"),
        ("--emit rust --part map --name min", "not a name"),
        ("--emit ptx --part map", "`--part map` is written as"),
        ("--emit spirv --part map -o /dev/null", "not `spirv`"),
        ("--emit wgsl --part map --name 2d", "not a name"),
        (
            "--emit wgsl --name x",
            "`--name` names the distance function",
        ),
    ];
    for (args, wanted) in cases {
        let mut all = vec!["compile", file];
        all.extend(words(args));
        let out = sdfc(&all);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(wanted), "{args:?}: {err}");
    }
}

/// The largest mean difference of the Shadertoy page's WebGL image from the CPU image, in
/// sRGB steps of 255.
const MEAN_LIMIT: f64 = 0.5;

const SMALL: &str = "material red = phong { color: (1, 0.2, 0.1), reflect: 0.2 };
material floor = checker { a: (0.9, 0.9, 0.9), b: (0.2, 0.2, 0.2), size: 0.5 };
camera { position: (0, 1, -5), look_at: (0, 0.5, 0), fov: 50deg }
light point { position: (2, 4, -3), intensity: 1, radius: 50, penumbra: 7deg }
render { width: 48, height: 32 }
scene {
  plane() @ floor;
  sphere(1).translate(0, 1, 0) @ red;
  box((0.4, 0.4, 0.4)).translate(1.5, 0.4, -0.5);
}
";

/// Whether CI asked for every device: then a missing adapter fails.
fn required() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true")
        || std::env::var("SDFC_REQUIRE_DEVICES").is_ok_and(|v| v == "1")
}

/// A member's offset in the layout of a binding, as a user's program reads it.
fn offset(binding: &serde_json::Value, member: &str) -> usize {
    binding["type"]["members"]
        .as_array()
        .expect("members")
        .iter()
        .find(|m| m["name"] == member)
        .and_then(|m| m["offset"].as_u64())
        .unwrap_or_else(|| panic!("no member {member}")) as usize
}

/// The kernel run from its files by a plain wgpu program (as docs/embedding.md shows):
/// `--emit wgsl`, `--emit params` and `--emit layout` written to files, then loaded,
/// bound and dispatched on the first adapter (lavapipe here), with no sdfc code; the image
/// equals `sdfc render --backend wgpu` of the same scene, byte for byte.
#[test]
fn the_kernel_runs_from_its_files_in_a_plain_wgpu_program() {
    let dir = std::env::temp_dir().join(format!("sdfc-embed-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let scene = dir.join("small.sdf");
    std::fs::write(&scene, SMALL).expect("scene");
    let file = scene.to_str().expect("utf-8");
    let at = |name: &str| dir.join(name).to_str().expect("utf-8").to_string();
    for (emit, out) in [
        ("wgsl", "k.wgsl"),
        ("params", "params.bin"),
        ("layout", "layout.json"),
    ] {
        ok(&["compile", file, "--emit", emit, "-o", &at(out)]);
    }
    let (wgsl, params, layout) = emitted(&dir);
    let bindings = layout["bindings"].as_array().expect("bindings");
    let p = &bindings[0];
    assert_eq!(
        (p["binding"].as_u64(), p["name"].as_str()),
        (Some(0), Some("params"))
    );
    assert_eq!(p["type"]["size"].as_u64(), Some(params.len() as u64));
    assert!(
        bindings.iter().all(|b| b["binding"].as_u64() != Some(4)),
        "no scene_data"
    );
    // The image size, read from Params at the offset the layout gives.
    let counts = offset(p, "counts");
    let word = |o: usize| u32::from_le_bytes(params[o..o + 4].try_into().expect("4 bytes"));
    let (width, height) = (word(counts), word(counts + 4));
    assert_eq!((width, height), (48, 32));
    let group = layout["workgroup_size"][0].as_u64().expect("workgroup") as u32;

    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter =
        match pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))
        {
            Ok(a) => a,
            Err(e) => {
                assert!(
                    !required(),
                    "SDFC_REQUIRE_DEVICES=1, but no wgpu adapter: {e}"
                );
                println!("embed: SKIPPED: no wgpu adapter ({e})");
                return;
            }
        };
    let kernel = Kernel {
        wgsl,
        entry_point: layout["entry_point"].as_str(),
        params: &params,
        size: (width, height),
        group,
    };
    let (bytes, rgba8) = kernel.dispatch(&adapter);
    let ours = sdfc_runtime::image::Image {
        width,
        height,
        linear: linear(&bytes),
    };

    ok(&["render", file, "--backend", "wgpu", "-o", &at("ref.png")]);
    let reference = sdfc_runtime::image::read_png(&dir.join("ref.png")).expect("png");
    assert_eq!((reference.width, reference.height), (width, height));
    let (a, b) = (ours.to_rgba8(), reference.to_rgba8());
    let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
    assert_eq!(differ, 0, "{differ} bytes differ from `sdfc render`");
    // The pixels the kernel finished (binding 5) are those bytes already.
    assert!(
        rgba8 == a,
        "the finished pixels differ from the encoded colours"
    );
    // Not a blank image: the sphere, the box and the floor's two colours are all there.
    let distinct: std::collections::BTreeSet<&[u8]> = a.chunks(4).collect();
    assert!(distinct.len() > 20, "{} colours", distinct.len());
    let _ = std::fs::remove_dir_all(&dir);
}

/// The kernel's text, the parameters' bytes and the layout `--emit` wrote into `dir`.
fn emitted(dir: &Path) -> (String, Vec<u8>, serde_json::Value) {
    let wgsl = std::fs::read_to_string(dir.join("k.wgsl")).expect("kernel");
    let params = std::fs::read(dir.join("params.bin")).expect("params");
    let layout: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("layout.json")).expect("layout"))
            .expect("json");
    (wgsl, params, layout)
}

/// The kernel as a user's program holds it: text, entry point, params, image and workgroup.
struct Kernel<'a> {
    wgsl: String,
    entry_point: Option<&'a str>,
    params: &'a [u8],
    size: (u32, u32),
    group: u32,
}

impl Kernel<'_> {
    /// The kernel dispatched once over the image on `adapter`'s device, bound as the layout
    /// says: the image read back (four f32 a pixel) and the finished pixels (RGBA8).
    fn dispatch(self, adapter: &wgpu::Adapter) -> (Vec<u8>, Vec<u8>) {
        let (device, queue) =
            pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor::default()))
                .expect("device");
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("sdfc kernel"),
            source: wgpu::ShaderSource::Wgsl(self.wgsl.into()),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: None,
            layout: None,
            module: &module,
            entry_point: self.entry_point,
            compilation_options: Default::default(),
            cache: None,
        });
        use wgpu::BufferUsages as U;
        let buffer = |size: u64, usage: U| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: None,
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        let (width, height) = self.size;
        let pixels = (width * height) as u64;
        let params_buf = buffer(self.params.len() as u64, U::UNIFORM | U::COPY_DST);
        queue.write_buffer(&params_buf, 0, self.params);
        let tile: Vec<u8> = [0, 0, width, height]
            .iter()
            .flat_map(|w: &u32| w.to_le_bytes())
            .collect();
        let tile_buf = buffer(16, U::UNIFORM | U::COPY_DST);
        queue.write_buffer(&tile_buf, 0, &tile);
        let image = buffer(pixels * 16, U::STORAGE | U::COPY_SRC);
        let stats = buffer(pixels * 4 * 8, U::STORAGE);
        let finished = buffer(pixels * 4, U::STORAGE | U::COPY_SRC);
        let readback = buffer(pixels * 16, U::MAP_READ | U::COPY_DST);
        let readback8 = buffer(pixels * 4, U::MAP_READ | U::COPY_DST);
        let bound = [&params_buf, &tile_buf, &image, &stats, &finished];
        let bind = bind_group(&device, &pipeline, bound);
        let mut enc = device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &bind, &[]);
            let group = self.group;
            pass.dispatch_workgroups(width.div_ceil(group), height.div_ceil(group), 1);
        }
        enc.copy_buffer_to_buffer(&image, 0, &readback, 0, pixels * 16);
        enc.copy_buffer_to_buffer(&finished, 0, &readback8, 0, pixels * 4);
        queue.submit([enc.finish()]);
        let slice = readback.slice(..);
        slice.map_async(wgpu::MapMode::Read, |r| r.expect("map"));
        let slice8 = readback8.slice(..);
        slice8.map_async(wgpu::MapMode::Read, |r| r.expect("map"));
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("poll");
        let bytes = slice.get_mapped_range().expect("mapped").to_vec();
        let rgba8 = slice8.get_mapped_range().expect("mapped").to_vec();
        (bytes, rgba8)
    }
}

/// Group 0's bindings 0, 1, 2, 3, 5: params, tile, image, stats and finished pixels.
fn bind_group(
    device: &wgpu::Device,
    pipeline: &wgpu::ComputePipeline,
    [params, tile, image, stats, finished]: [&wgpu::Buffer; 5],
) -> wgpu::BindGroup {
    fn entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
        wgpu::BindGroupEntry {
            binding,
            resource: buffer.as_entire_binding(),
        }
    }
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            entry(0, params),
            entry(1, tile),
            entry(2, image),
            entry(3, stats),
            entry(5, finished),
        ],
    })
}

/// The image's linear colours from the kernel's bytes (four f32 a pixel, the fourth unused).
fn linear(bytes: &[u8]) -> Vec<[f32; 3]> {
    bytes
        .chunks_exact(16)
        .map(|c| {
            let f = |k: usize| f32::from_le_bytes(c[4 * k..4 * k + 4].try_into().expect("4"));
            [f(0), f(1), f(2)]
        })
        .collect()
}

/// `--emit scene-data` writes the storage buffer the kernel of a large scene reads, the bytes
/// `sdfc render` binds; `--emit params` the uniform it fills; `--emit layout` names binding 4;
/// a scene without one is refused.
#[test]
fn scene_data_and_params_are_the_bytes_the_renderer_binds() {
    let path = example("scaling/random_1000.sdf");
    let file = path.to_str().expect("utf-8");
    let loaded = sdfc_runtime::frontend::load(&path).expect("readable");
    let scene = loaded.scene.expect("checks");
    let lowered = sdfc_compiler::Lowered::new(&scene);
    let kernel = wgsl::write(&scene, &lowered).expect("kernel");
    let data = sdfc(&["compile", file, "--emit", "scene-data"]);
    assert!(data.status.success());
    assert_eq!(Some(data.stdout), kernel.data);
    let params = sdfc(&["compile", file, "--emit", "params"]);
    assert_eq!(
        params.stdout,
        wgsl::uniforms(
            &kernel.contract.uniform,
            &scene,
            lowered.program.lipschitz()
        )
        .expect("the uniform fits the kernel")
    );
    let layout = sdfc(&["compile", file, "--emit", "layout"]);
    let layout: serde_json::Value = serde_json::from_slice(&layout.stdout).expect("json");
    let b4 = &layout["bindings"][4];
    assert_eq!(b4["binding"].as_u64(), Some(4));
    assert_eq!(b4["name"].as_str(), Some("scene_data"));
    assert_eq!(
        (b4["space"].as_str(), b4["access"].as_str()),
        (Some("storage"), Some("read"))
    );
    assert_eq!(b4["type"]["element"]["name"].as_str(), Some("vec4<f32>"));
    let small = example("seed1.sdf");
    let none = sdfc(&[
        "compile",
        small.to_str().expect("utf-8"),
        "--emit",
        "scene-data",
    ]);
    assert_eq!(none.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&none.stderr).contains("reads no `scene_data`"));
}

/// The program `name` on PATH ([`on_path`]) and a fresh temporary directory
/// `sdfc-{dir}-PID` for a test that runs it; without the program, `None`: the test is skipped
/// (which, where every device is required, fails, naming `what` is missing).
fn tool_and_dir(name: &str, what: &str, dir: &str) -> Option<(PathBuf, TestDir)> {
    let Some(tool) = on_path(name) else {
        assert!(!required(), "SDFC_REQUIRE_DEVICES=1, but no {what}");
        println!("embed: SKIPPED: no {name} on PATH");
        return None;
    };
    let dir = std::env::temp_dir().join(format!("sdfc-{dir}-{}", std::process::id()));
    Some((tool, TestDir::fresh(dir)))
}

/// A program on PATH (or at `$SDFC_CHROMIUM` for chromium), if there is one.
fn on_path(name: &str) -> Option<PathBuf> {
    if name == "chromium" {
        if let Some(path) = std::env::var_os("SDFC_CHROMIUM") {
            return Some(PathBuf::from(path));
        }
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|dir| dir.join(name))
        .find(|p| p.is_file())
}

/// What Shadertoy puts around an Image tab's code (its uniforms, and a `main` that calls
/// `mainImage` with the pixel's coordinates).
const SHADERTOY_HEAD: &str = "#version 300 es
precision highp float;
precision highp int;
precision mediump sampler3D;
uniform vec3 iResolution;
uniform float iTime;
uniform float iTimeDelta;
uniform int iFrame;
uniform float iChannelTime[4];
uniform vec4 iMouse;
uniform vec4 iDate;
uniform float iSampleRate;
uniform vec3 iChannelResolution[4];
uniform sampler2D iChannel0;
uniform sampler2D iChannel1;
uniform sampler2D iChannel2;
uniform sampler2D iChannel3;
out vec4 shadertoy_out_color;
";
const SHADERTOY_TAIL: &str = "
void main() {
    shadertoy_out_color = vec4(1.0, 1.0, 1.0, 1.0);
    vec4 color = vec4(1e20);
    mainImage(color, gl_FragCoord.xy);
    shadertoy_out_color = vec4(color.xyz, 1.0);
}
";

/// `sdfc compile FILE --emit shadertoy`, which must succeed: the page (standard output) and
/// what it says of the scene (standard error).
fn shadertoy(file: &Path) -> (String, String) {
    let out = ok(&[
        "compile",
        file.to_str().expect("utf-8"),
        "--emit",
        "shadertoy",
    ]);
    let said = String::from_utf8_lossy(&out.stderr).into_owned();
    (String::from_utf8(out.stdout).expect("text"), said)
}

/// The page of `file` wrapped the way Shadertoy wraps it.
fn shadertoy_wrapped(file: &Path) -> String {
    let (page, _) = shadertoy(file);
    assert!(page.contains("void mainImage(out vec4 fragColor, in vec2 fragCoord)"));
    assert!(!page.contains("#version") && !page.contains("precision "));
    format!("{SHADERTOY_HEAD}{page}{SHADERTOY_TAIL}")
}

/// The page renders camera rays with Phong shading: `--emit shadertoy` says what of a scene it
/// leaves out, on standard error, and says nothing for a scene it shows whole.
#[test]
fn the_shadertoy_page_says_what_it_leaves_out() {
    let said = |file: &Path| shadertoy(file).1;
    let studio = said(&example("studio.sdf"));
    for what in [
        "warning: the Shadertoy page",
        "pbr materials (shaded as the nearest Phong)",
        "sky lights",
        "refraction and transparency",
    ] {
        assert!(studio.contains(what), "{what}: {studio}");
    }
    assert!(said(&example("seed3.sdf")).contains("leaves out this scene's reflection"));
    let path = said(&example("studio_path.sdf"));
    assert_has(&path, &["path tracing (rendered by the Whitted model)"]);
    let plain = said(&example("blends.sdf"));
    assert!(!plain.contains("warning"), "{plain}");
}

/// `--emit shadertoy` of the report's scenes, wrapped as Shadertoy wraps it, compiles with
/// glslangValidator (Debian's `glslang-tools`) as a GLSL ES 3.00 fragment shader.
#[test]
fn the_shadertoy_page_compiles_as_shadertoy_wraps_it() {
    let glslang = "glslangValidator (glslang-tools)";
    let Some((glslang, dir)) = tool_and_dir("glslangValidator", glslang, "shadertoy") else {
        return;
    };
    for seed in 1..=6 {
        let frag = dir.join(format!("seed{seed}.frag"));
        std::fs::write(
            &frag,
            shadertoy_wrapped(&example(&format!("seed{seed}.sdf"))),
        )
        .expect("write");
        let what = format!("glslangValidator on seed{seed}");
        run_ok(Command::new(&glslang).arg(&frag), &what);
    }
}

/// The page rendered by headless Chromium through WebGL 2 (SwiftShader) looks like the CPU
/// image of a scene without reflections: the mean difference of the sRGB bytes is small.
#[test]
fn the_shadertoy_page_renders_the_scene_in_webgl() {
    let Some((chromium, dir)) = tool_and_dir("chromium", "chromium", "shadertoy-gl") else {
        return;
    };
    let scene = dir.join("small.sdf");
    std::fs::write(&scene, SMALL.replace(", reflect: 0.2", "")).expect("scene");
    assert_webgl_like_cpu(&chromium, &dir, &scene);
}

/// The page draws the glow of the marching steps (`render { glow, glow_color }`) as the CPU
/// renderer does, over the same over-relaxed steps: its WebGL image is the CPU's within the
/// same bounds, where the CPU's image without the glow is far from it (as the page was
/// before it drew the glow).
#[test]
fn the_shadertoy_page_draws_the_glow_of_the_marching_steps() {
    let Some((chromium, dir)) = tool_and_dir("chromium", "chromium", "shadertoy-glow") else {
        return;
    };
    let scene = dir.join("glow.sdf");
    let text = SMALL.replace(", reflect: 0.2", "").replace(
        "render { width: 48, height: 32 }",
        "render { width: 48, height: 32, glow: 0.1, glow_color: (0.02, 0.03, 0.05) }",
    );
    std::fs::write(&scene, text).expect("scene");
    let (_, warned) = shadertoy(&scene);
    assert!(!warned.contains("warning"), "{warned}");
    assert_webgl_like_cpu(&chromium, &dir, &scene);
    let (w, h) = (192, 128);
    let png = |name: &str, set: &[&str]| {
        let out = dir.join(name);
        let mut args = vec!["render", scene.to_str().expect("utf-8"), "--backend", "cpu"];
        args.extend(["--size", "192x128", "-o", out.to_str().expect("utf-8")]);
        args.extend(set);
        ok(&args);
        sdfc_runtime::image::read_png(&out).expect("png").to_rgba8()
    };
    let (glow, none) = (png("a.png", &[]), png("b.png", &["--set", "glow=0"]));
    let total: u64 = glow
        .iter()
        .zip(&none)
        .map(|(x, y)| x.abs_diff(*y) as u64)
        .sum();
    let apart = total as f64 / (w * h * 3) as f64;
    assert!(
        apart > 10.0 * MEAN_LIMIT,
        "the glow is {apart} steps of 255"
    );
}

/// The page of `scene` rendered by `chromium` (WebGL 2 through SwiftShader) at 192×128 in
/// `dir` looks like the CPU's image: the mean difference of the sRGB bytes (of 255) is under
/// `MEAN_LIMIT`, and under 1 % of the pixels are off by more than 24 in a channel.
fn assert_webgl_like_cpu(chromium: &Path, dir: &Path, scene: &Path) {
    let (w, h) = (192, 128);
    let frag = serde_json::to_string(&shadertoy_wrapped(scene)).expect("json");
    let html = format!(
        "<!doctype html><html><body style=\"margin:0;overflow:hidden\"><canvas id=\"c\" width=\"{w}\" height=\"{h}\"></canvas><script>
const gl = document.getElementById('c').getContext('webgl2', {{preserveDrawingBuffer: true}});
function shader(type, text) {{
  const s = gl.createShader(type); gl.shaderSource(s, text); gl.compileShader(s); return s;
}}
const p = gl.createProgram();
gl.attachShader(p, shader(gl.VERTEX_SHADER, '#version 300 es\\nin vec2 pos; void main() {{ gl_Position = vec4(pos, 0.0, 1.0); }}'));
gl.attachShader(p, shader(gl.FRAGMENT_SHADER, {frag}));
gl.linkProgram(p); gl.useProgram(p);
gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer());
gl.bufferData(gl.ARRAY_BUFFER, new Float32Array([-1, -1, 3, -1, -1, 3]), gl.STATIC_DRAW);
const at = gl.getAttribLocation(p, 'pos');
gl.enableVertexAttribArray(at); gl.vertexAttribPointer(at, 2, gl.FLOAT, false, 0, 0);
gl.uniform3f(gl.getUniformLocation(p, 'iResolution'), {w}, {h}, 1);
gl.viewport(0, 0, {w}, {h}); gl.drawArrays(gl.TRIANGLES, 0, 3);
</script></body></html>"
    );
    let page = dir.join("page.html");
    std::fs::write(&page, html).expect("page");
    let shot = dir.join("shot.png");
    let out = Command::new(chromium)
        .args([
            "--headless=new",
            "--no-sandbox",
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--hide-scrollbars",
            &format!("--window-size={w},{h}"),
            &format!("--screenshot={}", shot.display()),
        ])
        .arg(format!("file://{}", page.display()))
        .env("XDG_RUNTIME_DIR", dir)
        .output()
        .expect("run chromium");
    assert!(shot.is_file(), "{}", String::from_utf8_lossy(&out.stderr));
    let cpu = dir.join("cpu.png");
    let file = scene.to_str().expect("utf-8");
    let size = format!("{w}x{h}");
    ok(&[
        "render",
        file,
        "--backend",
        "cpu",
        "--size",
        &size,
        "-o",
        cpu.to_str().expect("utf-8"),
    ]);
    let a = sdfc_runtime::image::read_png(&shot)
        .expect("screenshot")
        .to_rgba8();
    let b = sdfc_runtime::image::read_png(&cpu).expect("cpu").to_rgba8();
    assert_eq!(a.len(), b.len(), "screenshot size");
    let total: u64 = a.iter().zip(&b).map(|(x, y)| x.abs_diff(*y) as u64).sum();
    let mean = total as f64 / (w * h * 3) as f64;
    let far = a
        .chunks(4)
        .zip(b.chunks(4))
        .filter(|(x, y)| x.iter().zip(y.iter()).any(|(p, q)| p.abs_diff(*q) > 24))
        .count();
    println!("shadertoy against cpu: mean |difference| {mean:.3} of 255, {far} pixels off by more than 24");
    assert!(
        mean < MEAN_LIMIT && far * 100 < 192 * 128,
        "mean {mean}, {far} pixels far off"
    );
}
