//! Generated code a user takes away (docs/embedding.md): the distance function alone
//! (`sdfc compile --part map`) in WGSL, GLSL, HLSL, MSL and Rust, used as a user would use
//! it: two scenes' parts in one WGSL module with a user's function calling both, validated by
//! naga and written by naga to the other languages; the part's function is the renderer's own
//! `map`, word for word; and the command line's refusals.

use sdfc_compiler::back::{self, shader::Lang, wgsl};
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

/// `sdfc compile FILE --emit LANG --part map --name NAME`, which must succeed.
fn part(file: &str, lang: &str, name: &str) -> String {
    let path = example(file);
    let out = sdfc(&[
        "compile",
        path.to_str().expect("utf-8 path"),
        "--emit",
        lang,
        "--part",
        "map",
        "--name",
        name,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
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
        features: Vec::new(),
        specialisation: wgsl::Specialisation::of(&Default::default()),
        data: None,
    };
    for lang in [Lang::SpirV, Lang::Msl, Lang::Glsl, Lang::Hlsl] {
        back::shader::write(&kernel, lang).unwrap_or_else(|e| panic!("{lang:?}: {e}"));
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

/// The part's function is the renderer kernel's `map`, word for word (the kernel's is
/// compared with the CPU renderer by tests/render.rs), and its table is the scene's
/// materials in order.
#[test]
fn the_part_is_the_kernels_own_map() {
    let path = example("seed4.sdf");
    let loaded = sdfc_runtime::frontend::load(&path).expect("readable");
    let scene = loaded.scene.expect("checks");
    let lowered = sdfc_compiler::lower::Lowered::new(&scene);
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
    let cases: [(&[&str], &str); 4] = [
        (
            &["--emit", "ptx", "--part", "map"],
            "`--part map` is written as",
        ),
        (
            &["--emit", "spirv", "--part", "map", "-o", "/dev/null"],
            "not `spirv`",
        ),
        (
            &["--emit", "wgsl", "--part", "map", "--name", "2d"],
            "not a name",
        ),
        (
            &["--emit", "wgsl", "--name", "x"],
            "`--name` names the distance function",
        ),
    ];
    for (args, wanted) in cases {
        let mut all = vec!["compile", file];
        all.extend_from_slice(args);
        let out = sdfc(&all);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(wanted), "{args:?}: {err}");
    }
}
