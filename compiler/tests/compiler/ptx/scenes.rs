//! The kernels of scenes through the PTX back end: large maps, the examples, every renderer
//! feature, outlined blocks, instances and scenes read from a buffer, the interpreted
//! kernel, and the parameters a launch is checked against.

use super::*;

/// The `.sdf` files of `dir`, sorted.
fn sdf_files(dir: &Path) -> Vec<PathBuf> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "sdf"))
        .collect();
    paths.sort();
    paths
}

/// A `map` of a few thousand expressions, like a large scene's.
fn big_kernel(n: usize) -> String {
    let mut s =
        String::from("@group(0) @binding(0) var<storage, read_write> out: array<vec2<f32>>;\n");
    s.push_str("fn map(p: vec3<f32>) -> vec2<f32> {\n    var d = length(p) - 1.0;\n");
    for i in 0..n {
        let c = i as f32 * 0.37;
        s.push_str(&format!(
            "    let s{i} = length(p - vec3<f32>({c:.2}, {:.2}, 0.5)) - 0.3;\n    d = min(d, max(s{i}, -p.y + {:.2} * sin(p.x)));\n",
            c * 0.5,
            c * 0.1
        ));
    }
    s.push_str("    return vec2<f32>(d, 1.0);\n}\n");
    s.push_str(
        "@compute @workgroup_size(64)\nfn main(@builtin(global_invocation_id) g: vec3<u32>) {\n",
    );
    s.push_str("    out[g.x] = map(vec3<f32>(f32(g.x), 0.0, 1.0)) + map(vec3<f32>(0.0, f32(g.x), 1.0));\n}\n");
    s
}

/// A large kernel translates, with `map` as one function (its time is printed, not asserted:
/// speed is measured in benchmarks, not in tests on shared machines).
#[test]
fn a_large_kernel_translates_with_map_as_one_function() {
    let src = big_kernel(300);
    let (module, info) = parse_strict(&src);
    let exprs: usize = module
        .functions
        .iter()
        .map(|(_, f)| f.expressions.len())
        .sum();
    let mut best = std::time::Duration::MAX;
    let mut text = String::new();
    for _ in 0..5 {
        let start = Instant::now();
        text = ptx::write(&module, &info, &options(80)).unwrap().text;
        best = best.min(start.elapsed());
    }
    println!(
        "{exprs} naga expressions -> {} lines of PTX in {best:.2?} (best of 5)",
        text.lines().count()
    );
    assert!(exprs > 3000, "the kernel has {exprs} expressions");
    // `map` is large and called twice: a .func, not two copies.
    assert!(text.contains(".func (.param .align 4 .b8 fn_map_retval[8]) fn_map("));
    keep("big.wgsl", src.as_bytes());
    if let Some(p) = ptxas() {
        println!("    {}", summary(&assemble(&p, &text, "big", 80)));
    }
}

/// The project's renderer kernel, specialised to each example scene.
#[test]
fn example_scenes_assemble() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples");
    let paths = sdf_files(&dir);
    assert!(
        paths.len() >= 6,
        "the report's six scenes at least: {paths:?}"
    );
    let ptxas = ptxas();
    for path in paths {
        let loaded = crate::common::load(&path).unwrap();
        // An example that does not check is a failure, not one fewer kernel to assemble.
        let Some(scene) = loaded.scene else {
            panic!(
                "{} does not check:\n{}",
                path.display(),
                sdfc_compiler::diagnostics::render(&loaded.diagnostics, &loaded.sources, false)
            )
        };
        let lowered = sdfc_compiler::Lowered::new(&scene);
        let kernel = sdfc_compiler::wgsl::write(&scene, &lowered).unwrap();
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        keep(&format!("scene_{name}.wgsl"), kernel.source.as_bytes());
        keep(
            &format!("scene_{name}.uniforms"),
            &sdfc_compiler::wgsl::uniforms(&kernel.contract.uniform, &scene, 1.0)
                .expect("the uniform fits the kernel"),
        );
        // The best of three translations: a shared machine's noise only adds time.
        let mut took = std::time::Duration::MAX;
        let mut text = String::new();
        for _ in 0..3 {
            let start = Instant::now();
            text = ptx::write(&kernel.module, &kernel.info, &options(80))
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
                .text;
            took = took.min(start.elapsed());
        }
        let exprs: usize = kernel
            .module
            .functions
            .iter()
            .map(|(_, f)| f.expressions.len())
            .sum();
        println!(
            "{name}: {exprs} naga expressions, {} lines of PTX in {took:.2?} (best of 3)",
            text.lines().count()
        );
        if let Some(p) = &ptxas {
            println!(
                "    {}",
                summary(&assemble(p, &text, &format!("scene_{name}"), 80))
            );
        }
    }
}

/// The kernel of every renderer feature (`tests/in/kernel`, one feature each, whose WGSL
/// `snapshots.rs` shows) translates and assembles: as written, with `--debug-nan` and the
/// program's constants in `scene_data` (animation's kernels), and with the traced primitives
/// or the marched instances read from `scene_data`.
#[test]
fn every_renderer_feature_kernel_assembles() {
    use sdfc_compiler::wgsl;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/in/kernel");
    let paths = sdf_files(&dir);
    assert!(paths.len() >= 10, "{paths:?}");
    let variants = [
        ("plain", wgsl::Options::default()),
        (
            "nan_params",
            wgsl::Options {
                debug_nan: true,
                parameters: true,
                ..Default::default()
            },
        ),
        (
            "data",
            wgsl::Options {
                max_unrolled: 1,
                max_instances: 1,
                ..Default::default()
            },
        ),
    ];
    let ptxas = ptxas();
    for path in paths {
        let (scene, lowered) = load_lowered(&path);
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        for (variant, opts) in &variants {
            let kernel = wgsl::write_with(&scene, &lowered, opts)
                .unwrap_or_else(|e| panic!("{name} ({variant}): {e}"));
            let text = ptx::write(&kernel.module, &kernel.info, &options(70))
                .unwrap_or_else(|e| panic!("{name} ({variant}): {e}"))
                .text;
            if let Some(p) = &ptxas {
                assemble(p, &text, &format!("feature_{name}_{variant}"), 70);
            }
        }
    }
}

/// The scene of the file `path` (relative to the compiler's folder), checked and lowered.
fn load_lowered(path: impl AsRef<Path>) -> (sdfc_compiler::Scene, sdfc_compiler::Lowered) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
    let scene = crate::common::load(&path).unwrap().scene.unwrap();
    let lowered = sdfc_compiler::Lowered::new(&scene);
    (scene, lowered)
}

/// `--debug-nan` reaches CUDA through the same kernel: its `DEBUG_NAN` feature translates.
#[test]
fn the_debug_nan_kernel_assembles() {
    let (scene, lowered) = load_lowered("tests/in/ok/nan_at_run_time.sdf");
    let debug = sdfc_compiler::wgsl::Options {
        debug_nan: true,
        ..Default::default()
    };
    let kernel = sdfc_compiler::wgsl::write_with(&scene, &lowered, &debug).unwrap();
    let plain = sdfc_compiler::wgsl::write(&scene, &lowered).unwrap();
    let text = ptx::write(&kernel.module, &kernel.info, &options(80))
        .unwrap()
        .text;
    let without = ptx::write(&plain.module, &plain.info, &options(80))
        .unwrap()
        .text;
    assert_ne!(text, without, "the feature changes the kernel");
    if let Some(p) = ptxas() {
        println!("    {}", summary(&assemble(&p, &text, "debug_nan", 80)));
    }
}

/// A distance program large enough that `map` and `sdf` are cut into functions (guarded
/// blocks outlined) translates, and assembles.
#[test]
fn a_kernel_with_outlined_blocks_assembles() {
    let (scene, lowered) = load_lowered("../examples/scaling/compound_100.sdf");
    // Its 400 instances written as code, not read from `scene_data`.
    let code = sdfc_compiler::wgsl::Options {
        max_instances: usize::MAX,
        ..Default::default()
    };
    let kernel = sdfc_compiler::wgsl::write_with(&scene, &lowered, &code).unwrap();
    assert!(kernel.source.contains("fn map_block") && kernel.source.contains("fn sdf_block"));
    let text = ptx::write(&kernel.module, &kernel.info, &options(80))
        .unwrap()
        .text;
    assert!(text.contains(".entry"));
    if let Some(p) = ptxas() {
        println!("    {}", summary(&assemble(&p, &text, "outlined", 80)));
    }
}

/// The most bytes of WGSL and lines of PTX of a marched kernel whose instances are read from
/// `scene_data`, whatever their number (about 24 KB and 5 030 lines for the lamp posts, whose
/// walks evaluate the instances' shapes in two places, the hint and the leaves; their kernels
/// written as code are megabytes).
const WALKED_WGSL_BYTES: usize = 26_000;
const WALKED_PTX_LINES: usize = 5_400;

/// The kernels of marched scenes beyond `MAX_INSTANCES` instances (1 000 and 10 000 lamp
/// posts of examples/scaling, 4 000 and 40 000 instances) stay small, translate and
/// assemble.
#[test]
fn marched_kernels_reading_instances_from_a_buffer_are_small_and_assemble() {
    let ptxas = ptxas();
    for n in [1000, 10000] {
        let name = format!("compound_{n}");
        let (scene, lowered) = load_lowered(format!("../examples/scaling/{name}.sdf"));
        let kernel = sdfc_compiler::wgsl::write(&scene, &lowered).unwrap();
        let data = kernel.data.as_ref().expect("instances read from a buffer");
        keep(&format!("{name}.wgsl"), kernel.source.as_bytes());
        keep(&format!("buffer_{name}.data"), data);
        let text = ptx::write(&kernel.module, &kernel.info, &options(80))
            .unwrap()
            .text;
        println!(
            "{name}: {} bytes of WGSL, {} lines of PTX, {} bytes of scene data",
            kernel.source.len(),
            text.lines().count(),
            data.len()
        );
        assert!(kernel.source.len() < WALKED_WGSL_BYTES, "{name}: WGSL");
        assert!(text.lines().count() < WALKED_PTX_LINES, "{name}: PTX");
        assert!(text.contains("main_param_4") && text.contains("ld.global.nc"));
        if let Some(p) = &ptxas {
            println!("    {}", summary(&assemble(p, &text, &name, 80)));
        }
    }
}

/// The kernel of a traced scene beyond `MAX_UNROLLED` primitives (read from `scene_data`, a
/// fifth kernel parameter, and walked in a loop) translates and assembles: 10 000 random
/// spheres, and every kind of primitive, rotated and scaled, with glass and mirrors.
#[test]
fn kernels_reading_the_scene_from_a_buffer_assemble() {
    let mixed = "material a = phong { color: (0.8, 0.4, 0.2), reflect: 0.3 };\n\
                 material b = phong { color: (0.2, 0.5, 0.6) };\n\
                 material g = phong { transparency: 0.9, ior: 1.5 };\n\
                 render { max_depth: 2 }\n\
                 scene {\n  plane() @ b;\n  sphere(0.5).translate(0, 9, 0) @ g;\n\
                 for i in 0..80 {\n\
                 let x = 10 * hash(3 * i) - 5;\n    let z = 10 * hash(3 * i + 1) - 5;\n\
                 sphere(0.2).translate(x, 1, z) @ a;\n\
                 box((0.2, 0.1, 0.2)).rotate_y(degrees(360 * hash(3 * i + 2))).translate(x, 2, z) @ b;\n\
                 cylinder(0.1, 0.2).scale(1.5).translate(x, 3, z) @ a;\n\
                 capsule(0.1, 0.2).rotate_x(30deg).translate(x, 4, z) @ b;\n  }\n}\n";
    let (scene, diags, _) = sdfc_compiler::check_str("mixed.sdf", mixed);
    let mixed = scene.unwrap_or_else(|| panic!("{diags:?}"));
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/scaling/random_10000.sdf");
    let random = crate::common::load(&path).unwrap().scene.unwrap();
    let ptxas = ptxas();
    for (name, scene) in [("mixed", mixed), ("random_10000", random)] {
        let lowered = sdfc_compiler::Lowered::new(&scene);
        let kernel = sdfc_compiler::wgsl::write(&scene, &lowered).unwrap();
        let data = kernel.data.as_ref().expect("read from a buffer");
        keep(&format!("buffer_{name}.data"), data);
        let text = ptx::write(&kernel.module, &kernel.info, &options(80))
            .unwrap()
            .text;
        assert!(text.contains("@group(0) @binding(4) var<storage, read> scene_data"));
        assert!(text.contains("main_param_4"));
        assert!(
            text.contains("ld.global.nc"),
            "{name}: scene data read through the cache"
        );
        for sm in [70, 80, 90] {
            let text = ptx::write(&kernel.module, &kernel.info, &options(sm))
                .unwrap()
                .text;
            if let Some(p) = &ptxas {
                println!(
                    "{name} sm_{sm}: {}",
                    summary(&assemble(p, &text, &format!("buffer_{name}"), sm))
                );
            }
        }
    }
}

/// The interpreted kernel (compiler/src/back/wgsl/interp.rs) translates and assembles: one
/// kernel per set of features among the examples (marched), each assembled once.
#[test]
fn interpreted_kernels_assemble() {
    use sdfc_compiler::wgsl;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples");
    let mut paths = sdf_files(&dir);
    // A scene that imports a triangle mesh, whose kernel calls the mesh walk.
    paths.push(dir.join("mesh/import.sdf"));
    let ptxas = ptxas();
    let mut seen = std::collections::BTreeMap::new();
    for path in paths {
        let mut scene = crate::common::load(&path).unwrap().scene.unwrap();
        scene.settings.method = sdfc_compiler::Method::March;
        let lowered = sdfc_compiler::Lowered::new(&scene);
        let interpreted = wgsl::Options {
            kernel: wgsl::KernelChoice::Interpreted,
            ..Default::default()
        };
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        let kernel = wgsl::write_with(&scene, &lowered, &interpreted).unwrap();
        assert!(kernel.interpreted());
        if let Some(other) = seen.get(&kernel.source) {
            println!("{name}: the kernel of {other}");
            continue;
        }
        let text = ptx::write(&kernel.module, &kernel.info, &options(80))
            .unwrap_or_else(|e| panic!("{name}: {e}"))
            .text;
        println!("{name}: {} lines of PTX", text.lines().count());
        keep(
            &format!("interpreted_{name}.wgsl"),
            kernel.source.as_bytes(),
        );
        if let Some(p) = &ptxas {
            println!(
                "    {}",
                summary(&assemble(p, &text, &format!("interpreted_{name}"), 80))
            );
        }
        seen.insert(kernel.source, name);
    }
    assert!(seen.len() >= 2, "several specialisations");
}

/// The writer returns the kernel's parameters as the PTX declares them: each buffer's
/// address in (group, binding) order with its address space and least size, named as in
/// the `.entry`; `check_arguments` (which the CUDA launcher calls before its `unsafe` launch)
/// accepts what the launcher passes and names what differs otherwise.
#[test]
fn the_parameters_are_returned_and_launches_checked_against_them() {
    use ptx::{check_arguments, Argument, Fault, Mismatch, Space};
    let text = "render { max_depth: 2 }\n\
                scene {\n  for i in 0..300 { sphere(0.2).translate(i * 0.5, 0, 0); }\n}\n";
    let (scene, diags, _) = sdfc_compiler::check_str("row.sdf", text);
    let scene = scene.unwrap_or_else(|| panic!("{diags:?}"));
    let lowered = sdfc_compiler::Lowered::new(&scene);
    let kernel = sdfc_compiler::wgsl::write(&scene, &lowered).unwrap();
    let data = kernel.data.as_ref().expect("scene data");
    let written = ptx::write(&kernel.module, &kernel.info, &options(80)).unwrap();
    let names: Vec<(&str, u32)> = written
        .params
        .iter()
        .map(|p| (p.var.as_str(), p.binding))
        .collect();
    assert_eq!(
        names,
        [
            ("params", 0),
            ("tile", 1),
            ("image", 2),
            ("stats", 3),
            ("scene_data", 4),
            ("pixels", 5)
        ]
    );
    for p in &written.params {
        assert!(
            written
                .text
                .contains(&format!(".param .{} {}", p.ty, p.name)),
            "{} declared as returned",
            p.name
        );
    }
    let uniform = u64::from(kernel.contract.uniform.size);
    assert_eq!(written.params[0].min_bytes, uniform);
    assert_eq!(written.params[2].stride, Some(16));
    let pixels = 64 * 48;
    let arg = |binding, space, bytes| Argument {
        group: 0,
        binding,
        space,
        bytes,
        size: 8,
    };
    let rw = Space::Storage { writable: true };
    let mut args = vec![
        arg(0, Space::Uniform, uniform),
        arg(1, Space::Uniform, 16),
        arg(2, rw, 16 * pixels),
        arg(3, rw, 4 * 8 * pixels),
        arg(4, Space::Storage { writable: false }, data.len() as u64),
        arg(5, rw, 4 * pixels),
    ];
    check_arguments(&written.params, &args).expect("the launcher's arguments");
    let refused = |args: &[Argument], what: &str| {
        let e = check_arguments(&written.params, args).expect_err(what);
        println!("{what}: {e}");
        e
    };
    let fault = |e: Mismatch| match e {
        Mismatch::Argument { fault, .. } => fault,
        other => panic!("{other}"),
    };
    let e = refused(&args[..5], "no finished pixels");
    assert!(matches!(e, Mismatch::Count { passed: 5, .. }));
    assert!(e.to_string().contains("takes 6 buffers"));
    let mut small = args.clone();
    small[0].bytes = uniform - 16;
    let e = fault(refused(&small, "a short uniform"));
    assert!(matches!(e, Fault::Short { .. }), "{e}");
    let mut swapped = args.clone();
    swapped.swap(2, 3);
    let e = fault(refused(&swapped, "image and statistics swapped"));
    assert_eq!(
        e,
        Fault::Binding {
            group: 0,
            binding: 3
        }
    );
    args[4].space = rw;
    let e = fault(refused(&args, "scene data passed writable"));
    assert_eq!(e, Fault::Space(rw));
    assert!(e.to_string().contains("read_write"));
}
