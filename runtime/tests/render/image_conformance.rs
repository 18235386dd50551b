//! Cross-backend conformance: every example rendered small on wgpu and on the CPU agrees
//! within its own tolerance, a little below the agreement measured on lavapipe
//! ([`AGREEMENT`]; other scenes within 30 dB and 2 %). On a machine without a wgpu adapter the test says it skipped,
//! unless `SDFC_REQUIRE_DEVICES=1` (set by CI, which installs lavapipe): then it fails.

use crate::common;
use common::load_small;

use sdfc_compiler::{wgsl, Lowered, Method, Scene};
use sdfc_runtime::{cpu, frontend, gpu, metrics};
use std::path::PathBuf;

/// Minimum PSNR (dB) between the wgpu and CPU renders of an example.
const MIN_PSNR: f64 = 30.0;
/// Most pixels allowed to differ by more than [`THRESHOLD`] in some channel.
const MAX_DIFFERING: f64 = 0.02;
/// Per-channel difference that counts a pixel as differing.
const THRESHOLD: f64 = 0.1;

fn open_gpu() -> Option<gpu::Gpu> {
    common::open_gpu("wgpu conformance")
}

/// A scene checked from source text; its diagnostics on failure.
fn checked(name: &str, text: &str) -> Scene {
    let (scene, diags, _) = sdfc_compiler::check_str(name, text);
    scene.unwrap_or_else(|| panic!("{name}: {diags:?}"))
}

/// Per example: the least PSNR (dB) and the largest fraction of pixels differing by more
/// than [`THRESHOLD`] between the wgpu and CPU renders at 96×64, each set a little below the
/// agreement measured on lavapipe (issue 16, item 6), so that a real divergence fails.
/// Measured values in the comments (lavapipe, LLVM 15, 2026-11-24): the PSNR bound is 3 dB
/// below it, the differing bound 3 pixels (of 6 144) above it.
const AGREEMENT: &[(&str, f64, f64)] = &[
    ("blends", 92.0, 0.0005),            // 95.6 dB, 0.0000 (0 px)
    ("cells", 89.0, 0.0005),             // 92.6 dB, 0.0000 (0 px), 2026-12-06
    ("checker_materials", 75.0, 0.0005), // 78.4 dB, 0.0000 (0 px), 2026-12-07 (a checker of two pbr materials)
    ("bolt", 95.0, 0.0005),              // 98.4 dB, 0.0000 (0 px), 2026-11-27
    ("bracket2d", 100.0, 0.0005),        // 103.1 dB, 0.0000 (0 px), 2026-11-27
    ("bent_pipe", 96.0, 0.0005),         // 99.6 dB, 0.0000 (0 px), 2026-12-06
    ("edges", 84.0, 0.0005),             // 87.4 dB, 0.0000 (0 px), 2026-11-27
    ("gallery", 89.0, 0.0005), // 92.8 dB, 0.0000 (0 px), 2026-12-06 (sky, sun, occlusion, fog, filmic)
    ("glow_blob", 73.0, 0.0005), // 76.5 dB, 0.0000 (0 px), 2026-12-07 (a glow of the marching steps)
    ("gear", 85.0, 0.0005),      // 88.9 dB, 0.0000 (0 px), 2026-11-27
    ("glass", 59.0, 0.0005),     // 62.0 dB, 0.0000 (0 px), 2026-12-06 (filtered checker)
    ("gyroid", 84.0, 0.0005),    // 87.2 dB, 0.0000 (0 px), 2026-11-27
    ("handle", 84.0, 0.0005),    // 87.6 dB, 0.0000 (0 px), 2026-12-06
    ("hull_bracket", 108.0, 0.0005), // 111.2 dB, 0.0000 (0 px), 2026-12-06
    ("knob", 98.0, 0.0005),      // 101.8 dB, 0.0000 (0 px), 2026-11-27
    ("lathe", 91.0, 0.0005),     // 94.3 dB, 0.0000 (0 px), 2026-11-27
    ("lattice", 87.0, 0.0005),   // 90.1 dB, 0.0000 (0 px)
    ("pawn", 91.0, 0.0005),      // 94.1 dB, 0.0000 (0 px), 2026-11-27
    ("phone_stand", 65.0, 0.0005), // 68.8 dB, 0.0000 (0 px), 2026-12-07 (hulls of balls and cylinders, in mm)
    ("plaque", 109.0, 0.0005),     // 112.0 dB, 0.0000 (0 px), 2026-11-27
    ("polyhedron", 62.0, 0.0005),  // 65.3 dB, 0.0000 (0 px), 2026-12-06 (filtered checker)
    ("primitives", 97.0, 0.0005),  // 100.8 dB, 0.0000 (0 px), 2026-12-06 (filtered checker)
    ("ring", 49.0, 0.0008),        // 52.6 dB, 0.0003 (2 px), 2026-11-27
    ("rock", 72.0, 0.0005),        // 75.7 dB, 0.0000 (0 px), 2026-11-27 (two noises, marble)
    ("seed1", 120.0, 0.0005),      // 123.5 dB, 0.0000 (0 px), 2026-12-06 (filtered checker)
    ("seed2", 115.0, 0.0005),      // 118.5 dB, 0.0000 (0 px), 2026-12-06 (filtered checker)
    ("seed3", 72.0, 0.0005),       // 75.9 dB, 0.0000 (0 px), 2026-12-06 (filtered checker)
    ("seed4", 72.0, 0.0005),       // 75.5 dB, 0.0000 (0 px), 2026-12-06 (filtered checker)
    ("seed5", 73.0, 0.0005),       // 76.2 dB, 0.0000 (0 px), 2026-12-06 (filtered checker)
    ("seed6", 100.0, 0.0005), // 125.5 dB, 0 px (ε of the pixel footprint since issue 24: nearly identical; bound kept far below)
    ("spring", 80.0, 0.0005), // 83.7 dB, 0.0000 (0 px), 2026-12-06
    ("star", 105.0, 0.0005),  // 108.9 dB, 0.0000 (0 px), 2026-11-27
    ("studio", 78.0, 0.0005), // 81.5 dB, 0.0000 (0 px), 2026-12-06 (pbr: GGX, metal, glass, emission)
    ("studio_path", 59.0, 0.0005), // 62.9 dB, 0.0000 (0 px), 2026-12-06 (path traced, 16 samples)
    ("surface_colour", 82.0, 0.0005), // 85.9 dB, 0.0000 (0 px), 2026-12-07 (colour of the normal, moved patterns)
    ("temple", 80.0, 0.0005),         // 83.9 dB, 0.0000 (0 px), 2026-12-06 (filtered checker)
    ("vase", 86.0, 0.0005),           // 89.1 dB, 0.0000 (0 px), 2026-11-27
];

#[test]
fn wgpu_matches_cpu_on_every_example() {
    let Some(gpu) = open_gpu() else { return };
    println!("adapter: {}", gpu.describe());
    let mut failures = Vec::new();
    for path in common::examples() {
        let scene = load_small(&path, 96, 64);
        let lowered = Lowered::new(&scene);
        let kernel = wgsl::write(&scene, &lowered).expect("valid kernel");
        let (on_gpu, on_cpu, d) = side_by_side(&gpu, &scene, &lowered, &kernel);
        println!(
            "{:<14} psnr {:6.1} dB  differing {:.4}  steps/px gpu {:.1} cpu {:.1}",
            path.file_stem().unwrap_or_default().to_string_lossy(),
            d.psnr,
            d.differing,
            on_gpu.render.stats.steps_mean,
            on_cpu.stats.steps_mean
        );
        assert_eq!(
            on_gpu.render.stats.counters.nans,
            0,
            "{}: NaN on the GPU",
            path.display()
        );
        let name = path.file_stem().unwrap_or_default().to_string_lossy();
        let Some(&(_, min_psnr, max_differing)) = AGREEMENT.iter().find(|(n, ..)| *n == name)
        else {
            failures.push(format!(
                "{}: no row in AGREEMENT (measured psnr {:.1} dB, differing {:.4})",
                path.display(),
                d.psnr,
                d.differing
            ));
            continue;
        };
        if d.psnr < min_psnr || d.differing > max_differing {
            failures.push(format!(
                "{}: psnr {:.1} dB (at least {min_psnr}), differing {:.4} (at most {max_differing})",
                path.display(),
                d.psnr,
                d.differing
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "backends disagree:\n{}",
        failures.join("\n")
    );
}

/// Renders `scene` on wgpu and on the CPU and asserts that they agree within the tolerance.
fn assert_agree(
    gpu: &gpu::Gpu,
    scene: &sdfc_compiler::Scene,
    lowered: &Lowered,
    kernel: &wgsl::Kernel,
    label: &str,
) {
    let on_gpu = gpu::render(gpu, scene, kernel, 1.0, &mut |_| {}).expect("gpu render");
    let on_cpu = cpu::render(scene, lowered, &cpu::Options::default(), &|| {});
    let pair = (&on_gpu.render.image, &on_cpu.image);
    common::assert_agree(label, pair, THRESHOLD, (MIN_PSNR, MAX_DIFFERING));
}

/// `scene` rendered through `kernel` on `gpu` and by the CPU with the default options, and
/// how far the GPU's image is from the CPU's.
fn side_by_side(
    gpu: &gpu::Gpu,
    scene: &sdfc_compiler::Scene,
    lowered: &Lowered,
    kernel: &wgsl::Kernel,
) -> (gpu::GpuRender, cpu::Render, metrics::Difference) {
    let on_gpu = gpu::render(gpu, scene, kernel, 1.0, &mut |_| {}).expect("gpu render");
    let on_cpu = cpu::render(scene, lowered, &cpu::Options::default(), &|| {});
    let d = metrics::compare(&on_gpu.render.image, &on_cpu.image, THRESHOLD).expect("same size");
    (on_gpu, on_cpu, d)
}

/// A distance program large enough that `map` and `sdf` are cut into functions
/// (examples/scaling/compound_100.sdf, about 15 000 instructions, its instances written as
/// code) renders on wgpu as on the CPU.
#[test]
fn a_kernel_with_outlined_blocks_matches_the_cpu() {
    let Some(gpu) = open_gpu() else { return };
    let path = PathBuf::from("../examples/scaling/compound_100.sdf");
    let scene = load_small(&path, 64, 48);
    let lowered = Lowered::new(&scene);
    let options = wgsl::Options {
        max_instances: usize::MAX,
        ..wgsl::Options::default()
    };
    let kernel = wgsl::write_with(&scene, &lowered, &options).expect("valid kernel");
    assert!(kernel.source.contains("fn map_block") && kernel.source.contains("fn sdf_block"));
    assert!(kernel.data.is_none());
    assert_agree(&gpu, &scene, &lowered, &kernel, "compound_100 as code");
}

/// A marched scene of `n` instances of every kind with closed-form distances (rotated, some
/// scaled, which the simplification absorbs into their sizes, painted or not) over a plane,
/// with shapes that must stay in the rest of the program: a twisted box and ellipsoids (a
/// bound, not an exact distance).
fn marched_scene(n: usize) -> String {
    let header = "material floor = checker { a: (0.9, 0.9, 0.88), b: (0.2, 0.22, 0.25), size: 0.75 };\n\
         material clay = phong { color: (0.85, 0.45, 0.25), specular: 0.3, shininess: 24 };\n\
         material mirror = phong { color: (0.9, 0.9, 0.95), diffuse: 0.2, specular: 1, shininess: 200, reflect: 0.5 };\n\
         material teal = phong { color: (0.15, 0.6, 0.6), specular: 0.5, shininess: 64 };\n\
         camera { position: (0, 4, -7), look_at: (0, 1, 3), fov: 60deg }\n\
         light point { position: (-4, 9, -6), intensity: 1.1, radius: 60, penumbra: 84.2894deg }\n\
         render { width: 96, height: 64, max_depth: 2, method: \"march\" }\n\
         scene {\n  plane() @ floor;\n  box((0.3, 1, 0.3)).twist(1.5).translate(0, 1, -3) @ teal;\n";
    scattered((0x9e37_79b9_u64, n), header, |i, (a, b), rng| {
        let turn = format!("rotate_y({a:.1}deg).rotate_x({b:.1}deg)");
        let shape = match i % 9 {
            0 => format!("sphere({:.3})", 0.2 + 0.1 * rng.uniform()),
            1 => format!("box((0.2, 0.15, 0.25)).{turn}"),
            2 => format!("round_box((0.2, 0.15, 0.25), 0.05).{turn}.scale(1.2)"),
            3 => format!("torus(0.25, 0.06).{turn}"),
            4 => format!("cylinder(0.15, 0.3).rotate_z({a:.1}deg).scale(0.9)"),
            5 => format!("capsule(0.1, 0.25).{turn}"),
            6 => format!("cone(0.2, 0.3).{turn}"),
            7 => format!("cone(0.2, 0.3).scale(1.1).rotate_z({a:.1}deg)"),
            _ => "ellipsoid((0.3, 0.15, 0.2))".to_string(),
        };
        let material = ["clay", "mirror", "teal", ""][i % 4];
        let paint = if material.is_empty() {
            String::new()
        } else {
            format!(" @ {material}")
        };
        (format!("{shape}.scale(2)"), paint)
    })
}

/// The text of a scene: `header`, which opens the scene block, then `n` shapes at random
/// places (the stream seeded by `seed`), each as `place` writes it from its index, two random
/// angles in degrees and the stream: what comes before its translation and what after; the
/// block closed.
fn scattered(
    (seed, n): (u64, usize),
    header: &str,
    mut place: impl FnMut(usize, (f64, f64), &mut sdfc_compiler::Rng) -> (String, String),
) -> String {
    let mut rng = sdfc_compiler::Rng::new(seed);
    let mut text = String::from(header);
    for i in 0..n {
        let mut next = || rng.uniform();
        let (x, y, z) = (16.0 * next() - 8.0, 0.4 + 2.0 * next(), 10.0 * next() - 2.0);
        let (a, b) = (360.0 * next(), 360.0 * next());
        let (before, after) = place(i, (a, b), &mut rng);
        text.push_str(&format!(
            "  {before}.translate({x:.3}, {y:.3}, {z:.3}){after};\n"
        ));
    }
    text.push_str("}\n");
    text
}

/// Marched scenes with more instances than the kernel writes as code read them and their
/// hierarchy from `scene_data` and render on wgpu as on the CPU: the lamp posts of
/// examples/scaling/compound_100.sdf (400 instances), and a scene of every kind of instance
/// with shapes that stay in the rest of the program.
#[test]
fn a_marched_scene_read_from_a_buffer_matches_the_cpu() {
    let text = marched_scene(360);
    let scene = checked("marched.sdf", &text);
    let lowered = Lowered::new(&scene);
    // The threshold set below the scene's instances whatever the default: the walk.
    let walk = wgsl::Options {
        max_instances: 256,
        ..wgsl::Options::default()
    };
    let split = lowered.instances(walk.max_instances).expect("split");
    // Of 360 children, the 40 ellipsoids stay, with the plane and the twisted box.
    assert_eq!(split.instances.len(), 320);
    assert!(split.instances.iter().any(|i| i.material.is_none()));
    let kernel = wgsl::write_with(&scene, &lowered, &walk).expect("valid kernel");
    assert!(kernel.contract.features.contains(&("SCENE_DATA", true)));
    assert!(kernel.source.contains("fn rest_map") && kernel.source.contains("const ROTATED"));
    let Some(gpu) = open_gpu() else { return };
    assert_agree(
        &gpu,
        &scene,
        &lowered,
        &kernel,
        "320 instances and the rest",
    );
    // The same field as the program written as code: on one device the two kernels render
    // alike up to rounding, far closer than the CPU tolerance.
    let options = wgsl::Options {
        max_instances: usize::MAX,
        ..wgsl::Options::default()
    };
    let code = wgsl::write_with(&scene, &lowered, &options).expect("valid kernel");
    assert!(code.data.is_none());
    let render = |k: &wgsl::Kernel| gpu::render(&gpu, &scene, k, 1.0, &mut |_| {}).expect("render");
    let (walked, written) = (render(&kernel).render, render(&code).render);
    let d = metrics::compare(&walked.image, &written.image, THRESHOLD).expect("same size");
    println!(
        "walked against written as code: psnr {:.1} dB, differing {:.4}",
        d.psnr, d.differing
    );
    assert!(d.psnr >= 50.0 && d.differing <= 0.002, "{d:?}");
    let path = PathBuf::from("../examples/scaling/compound_100.sdf");
    let scene = load_small(&path, 96, 64);
    let lowered = Lowered::new(&scene);
    let kernel = wgsl::write_with(&scene, &lowered, &walk).expect("valid kernel");
    assert!(kernel.data.is_some() && !kernel.source.contains("fn map_block"));
    assert_agree(&gpu, &scene, &lowered, &kernel, "compound_100");
}

/// Large marched scenes walk their instances nearest first and render on wgpu as on the
/// CPU: examples/scaling/compound_1000.sdf (4 000 instances, beyond the threshold), the
/// 1 024 spheres of examples/scaling/jittered_1024.sdf marched (`method: "march"`) and
/// walked (the threshold lowered for the test), and the 1 093 round cones between points and
/// 729 leaves of examples/scaling/tree.sdf, at 96×64.
#[test]
fn many_marched_instances_walked_nearest_first_match_the_cpu() {
    let Some(gpu) = open_gpu() else { return };
    let walk = wgsl::Options {
        max_instances: 256,
        ..wgsl::Options::default()
    };
    for (file, instances) in [
        ("compound_1000", 4000),
        ("jittered_1024", 1024),
        ("tree", 1822),
    ] {
        let path = PathBuf::from(format!("../examples/scaling/{file}.sdf"));
        let mut scene = load_small(&path, 96, 64);
        scene.settings.method = sdfc_compiler::Method::March;
        let lowered = Lowered::new(&scene);
        let split = lowered.instances(walk.max_instances).expect("split");
        assert_eq!(split.instances.len(), instances, "{file}");
        let kernel = wgsl::write_with(&scene, &lowered, &walk).expect("valid kernel");
        assert!(kernel.data.is_some() && kernel.source.contains("var stack: array<u32,"));
        assert_agree(&gpu, &scene, &lowered, &kernel, file);
    }
}

/// Cones, round cones, cylinders and segments between two points, bare, painted, and scaled, turned
/// and moved as a whole, are instances (their shapes along y in the frames of their
/// segments, two vectors of slots for the cones) and render on wgpu as on the CPU.
#[test]
fn shapes_between_points_walked_match_the_cpu() {
    let mut rng = sdfc_compiler::Rng::new(52);
    let mut next = move || rng.uniform();
    let mut text = String::from(
        "material clay = phong { color: (0.85, 0.45, 0.25), specular: 0.3, shininess: 24 };\n\
         material teal = phong { color: (0.15, 0.6, 0.6), specular: 0.5, shininess: 64 };\n\
         camera { position: (0, 4, -7), look_at: (0, 1, 3), fov: 60deg }\n\
         light point { position: (-4, 9, -6), intensity: 1.1, radius: 60 }\n\
         render { width: 96, height: 64, max_depth: 1 }\n\
         scene {\n  plane((0, 1, 0), 0);\n",
    );
    for i in 0..300 {
        let a = (16.0 * next() - 8.0, 0.2 + 2.0 * next(), 10.0 * next() - 2.0);
        let b = (a.0 + next() - 0.5, a.1 + next(), a.2 + next() - 0.5);
        let (a, b) = (
            format!("({:.3}, {:.3}, {:.3})", a.0, a.1, a.2),
            format!("({:.3}, {:.3}, {:.3})", b.0, b.1, b.2),
        );
        let shape = match i % 5 {
            0 => format!("cone({a}, {b}, 0.2, 0.05) @ clay"),
            1 => format!("round_cone({a}, {b}, 0.15, 0.08)"),
            2 => format!("cylinder({a}, {b}, 0.1) @ teal"),
            3 => format!("segment({a}, {b}, 0.08) @ clay"),
            _ => format!(
                "cone((0, 0, 0), (0, 1, 0), 0.2, 0.1).scale(0.8).rotate_z({:.1}deg).translate{a}",
                90.0 * next()
            ),
        };
        text.push_str(&format!("  {shape};\n"));
    }
    text.push_str("}\n");
    let scene = checked("between.sdf", &text);
    let lowered = Lowered::new(&scene);
    let split = lowered.instances(wgsl::MAX_INSTANCES).expect("split");
    assert_eq!(split.instances.len(), 300);
    let kernel = wgsl::write(&scene, &lowered).expect("valid kernel");
    assert!(kernel
        .source
        .contains("fn shape_capped_cone(p: vec3<f32>, s: vec4<f32>, t: vec4<f32>)"));
    let Some(gpu) = open_gpu() else { return };
    assert_agree(&gpu, &scene, &lowered, &kernel, "shapes between points");
}

/// A camera looking straight down (its view parallel to the default `up`) and one rolled by
/// `up` render on the GPU as on the CPU: the basis is computed once, in f64, for both.
#[test]
fn cameras_looking_straight_down_match_the_cpu() {
    let Some(gpu) = open_gpu() else { return };
    for up in ["", ", up: (1, 0, 1)"] {
        let text = format!(
            "camera {{ position: (0, 6, 0), look_at: (0, 0, 0){up} }}\n\
             light point {{ position: (2, 10, 1), penumbra: 4deg }}\n\
             render {{ width: 64, height: 64 }}\n\
             scene {{ plane((0, 1, 0), -1); sphere(1); box((0.4, 0.4, 0.4)).translate(0, 0, 2.5); }}"
        );
        let scene = checked("down.sdf", &text);
        let lowered = Lowered::new(&scene);
        let kernel = wgsl::write(&scene, &lowered).expect("valid kernel");
        assert_agree(&gpu, &scene, &lowered, &kernel, &format!("down{up}"));
    }
}

/// Glass sunk into the floor and into a box renders on the GPU as on the CPU, sphere traced
/// (the scene's media: rays inside the glass march the glass less the solids and shade the
/// solids they meet there) and traced (rays inside the glass stop at the nearer of its far
/// side and a solid's entry, and shade the solid within the glass).
#[test]
fn glass_overlapping_solids_matches_the_cpu() {
    let Some(gpu) = open_gpu() else { return };
    for method in ["march", "auto"] {
        let text = format!(
            "material glass = phong {{ color: (1, 1, 1), transparency: 0.9, ior: 1.5, reflect: 0.05 }};\n\
             material floor = checker {{ a: (0.9, 0.9, 0.9), b: (0.1, 0.1, 0.1), size: 0.5, reflect: 0.2 }};\n\
             camera {{ position: (0, 1.5, -3), look_at: (0, 0.2, 0), fov: 50deg }}\n\
             light point {{ position: (2, 5, -3) }}\n\
             render {{ width: 96, height: 72, method: \"{method}\" }}\n\
             scene {{ plane((0, 1, 0), 0) @ floor; sphere(0.8) @ glass; box((0.3, 0.3, 0.3)).translate(0.5, 0.3, 0); }}"
        );
        let scene = checked("media.sdf", &text);
        let lowered = Lowered::new(&scene);
        let kernel = wgsl::write(&scene, &lowered).expect("valid kernel");
        let traced = method == "auto";
        assert_eq!(kernel.contract.features.contains(&("MEDIA", true)), !traced);
        assert_eq!(
            kernel.contract.features.contains(&("ANALYTIC", true)),
            traced
        );
        assert_agree(
            &gpu,
            &scene,
            &lowered,
            &kernel,
            &format!("glass in solids, {method}"),
        );
        if traced {
            // The same walking the primitives in `scene_data`.
            let options = wgsl::Options {
                max_unrolled: 0,
                ..wgsl::Options::default()
            };
            let kernel = wgsl::write_with(&scene, &lowered, &options).expect("valid kernel");
            assert!(kernel.data.is_some());
            assert_agree(
                &gpu,
                &scene,
                &lowered,
                &kernel,
                "glass in solids, scene_data",
            );
        }
    }
}

/// Shadow rays pass through glass on the GPU as on the CPU even when no refracted ray is
/// traced (`max_depth: 0`, so the kernel has no refraction code).
#[test]
fn shadows_through_glass_match_without_secondary_rays() {
    let Some(gpu) = open_gpu() else { return };
    let text = "material glass = phong { transparency: 0.9, ior: 1.5 };\n\
                camera { position: (0, 3, -4), look_at: (0, 0, 0), fov: 50deg }\n\
                light point { position: (0, 6, 0), intensity: 1, radius: 50 }\n\
                render { width: 64, height: 48, max_depth: 0, method: \"march\" }\n\
                scene { plane(); sphere(0.8).translate(0, 1.2, 0) @ glass; }";
    let scene = checked("glass.sdf", text);
    let lowered = Lowered::new(&scene);
    let kernel = wgsl::write(&scene, &lowered).expect("valid kernel");
    assert!(kernel.contract.features.contains(&("TRANSPARENT", true)));
    assert!(kernel.contract.features.contains(&("REFRACTION", false)));
    assert_agree(&gpu, &scene, &lowered, &kernel, "glass shadow");
}

/// `--debug-nan` on wgpu: the kernel's `DEBUG_NAN` feature paints the same pixels magenta
/// as the CPU renderer; without it the kernel is the default one and paints none.
#[test]
fn debug_nan_marks_the_same_pixels_on_wgpu() {
    let Some(gpu) = open_gpu() else { return };
    let path = PathBuf::from("../compiler/tests/in/ok/nan_at_run_time.sdf");
    let scene = frontend::load(&path)
        .expect("readable")
        .scene
        .expect("valid scene");
    let lowered = Lowered::new(&scene);
    let magenta = |image: &sdfc_runtime::image::Image| -> Vec<bool> {
        image.linear.iter().map(|&c| c == cpu::NAN_COLOUR).collect()
    };
    let plain_kernel = wgsl::write(&scene, &lowered).expect("valid kernel");
    assert!(!plain_kernel.source.contains("DEBUG_NAN"));
    let plain = gpu::render(&gpu, &scene, &plain_kernel, 1.0, &mut |_| {}).expect("render");
    assert!(plain.render.stats.counters.nans > 0, "no NaN on the GPU");
    assert!(!magenta(&plain.render.image).contains(&true));
    let options = wgsl::Options {
        debug_nan: true,
        ..wgsl::Options::default()
    };
    let kernel = wgsl::write_with(&scene, &lowered, &options).expect("valid kernel");
    assert!(kernel.source.contains("+DEBUG_NAN"));
    let on_gpu = gpu::render(&gpu, &scene, &kernel, 1.0, &mut |_| {}).expect("render");
    let cpu_options = cpu::Options {
        debug_nan: true,
        ..cpu::Options::default()
    };
    let on_cpu = cpu::render(&scene, &lowered, &cpu_options, &|| {});
    let (g, c) = (magenta(&on_gpu.render.image), magenta(&on_cpu.image));
    let differ = g.iter().zip(&c).filter(|(a, b)| a != b).count();
    let marked = g.iter().filter(|&&m| m).count();
    println!("debug-nan: {marked} magenta pixels on wgpu, {differ} differ from the CPU");
    assert!(marked > 0);
    assert!(
        differ * 50 <= g.len(),
        "{differ} of {} pixels differ",
        g.len()
    );
}

/// A scene of `n` primitives above the unrolling threshold: spheres, boxes, cylinders and
/// capsules turned and scaled at pseudo-random places on a checkered, reflective floor, with
/// mirrors and a floating glass ball that touches nothing (so `auto` traces it).
fn mixed_scene(n: usize) -> String {
    let header = "material floor = checker { a: (0.9, 0.9, 0.88), b: (0.2, 0.22, 0.25), size: 0.75, reflect: 0.1 };\n\
         material clay = phong { color: (0.85, 0.45, 0.25), specular: 0.3, shininess: 24 };\n\
         material mirror = phong { color: (0.9, 0.9, 0.95), diffuse: 0.2, specular: 1, shininess: 200, reflect: 0.6 };\n\
         material teal = phong { color: (0.15, 0.6, 0.6), specular: 0.5, shininess: 64 };\n\
         material glass = phong { color: (0.95, 1, 0.95), ambient: 0, diffuse: 0.05, specular: 1, shininess: 180, reflect: 0.05, transparency: 0.9, ior: 1.5 };\n\
         camera { position: (0, 7, -15), look_at: (0, 1, 2), fov: 50deg }\n\
         light point { position: (-4, 9, -6), intensity: 1.1, radius: 60 }\n\
         light directional { direction: (1, -1, 0.6), color: (0.35, 0.35, 0.4) }\n\
         render { width: 96, height: 64, max_depth: 3 }\n\
         scene {\n  plane() @ floor;\n  sphere(0.9).translate(0, 5, -5) @ glass;\n";
    scattered((0x2545_f491_u64, n), header, |i, (a, b), rng| {
        let shape = match i % 4 {
            0 => format!(
                "sphere({:.3}).scale(({:.3}, 1, 1))",
                0.2 + 0.1 * rng.uniform(),
                0.6 + rng.uniform()
            ),
            1 => format!("box((0.2, 0.15, 0.25)).rotate_y({a:.1}deg).rotate_x({b:.1}deg)"),
            2 => format!(
                "cylinder(0.15, 0.3).rotate_z({a:.1}deg).scale({:.3})",
                0.8 + 0.4 * rng.uniform()
            ),
            _ => format!("capsule(0.1, 0.25).rotate_x({a:.1}deg).rotate_y({b:.1}deg)"),
        };
        let material = ["clay", "mirror", "teal"][i % 3];
        (shape, format!(" @ {material}"))
    })
}

/// A traced scene of more primitives than the kernel unrolls reads them and their hierarchy
/// from `scene_data` (binding 4) and renders on wgpu as on the CPU: every kind of primitive,
/// rotated and scaled, a plane, mirrors and glass.
#[test]
fn a_traced_scene_read_from_a_buffer_matches_the_cpu() {
    let text = mixed_scene(300);
    let scene = checked("mixed.sdf", &text);
    let traced = sdfc_compiler::analytic::choose(&scene);
    assert_eq!(traced.primitives().map(<[_]>::len), Some(302), "{traced:?}");
    let lowered = Lowered::new(&scene);
    let kernel = wgsl::write(&scene, &lowered).expect("valid kernel");
    assert!(kernel.contract.features.contains(&("SCENE_DATA", true)));
    assert!(kernel.data.is_some() && !kernel.source.contains("P0_R0"));
    let Some(gpu) = open_gpu() else { return };
    assert_agree(&gpu, &scene, &lowered, &kernel, "302 mixed primitives");
    let path = PathBuf::from("../examples/scaling/random_1000.sdf");
    let scene = load_small(&path, 96, 64);
    let lowered = Lowered::new(&scene);
    let kernel = wgsl::write(&scene, &lowered).expect("valid kernel");
    assert!(kernel.data.is_some());
    assert_agree(&gpu, &scene, &lowered, &kernel, "random_1000");
}

/// The walk over `scene_data` tests the primitives and groups of the unrolled code in the same
/// order with the same functions: on wgpu both kernels of one scene find the same hits (the
/// same statistics) and the same colours up to rounding (lavapipe's compiler folds and
/// contracts the unrolled code's constants: a few pixels differ in the last bits).
#[test]
fn the_buffer_walk_renders_what_the_unrolled_code_renders() {
    let text = mixed_scene(40);
    let scene = checked("mixed.sdf", &text);
    let lowered = Lowered::new(&scene);
    let unrolled = wgsl::write(&scene, &lowered).expect("valid kernel");
    let options = wgsl::Options {
        max_unrolled: 0,
        ..wgsl::Options::default()
    };
    let walked = wgsl::write_with(&scene, &lowered, &options).expect("valid kernel");
    assert!(unrolled.data.is_none() && walked.data.is_some());
    let Some(gpu) = open_gpu() else { return };
    let render = |k: &wgsl::Kernel| gpu::render(&gpu, &scene, k, 1.0, &mut |_| {}).expect("render");
    let (a, b) = (render(&unrolled).render, render(&walked).render);
    assert_eq!(a.stats.counters, b.stats.counters);
    assert!(a.stats.counters.hits > 0 && a.stats.counters.shadow_rays > 0);
    let (mut differ, mut largest) = (0, 0.0f32);
    for (x, y) in a.image.linear.iter().zip(&b.image.linear) {
        if x != y {
            differ += 1;
        }
        for k in 0..3 {
            largest = largest.max((x[k] - y[k]).abs());
        }
    }
    println!("unrolled against walked: {differ} pixels differ, by at most {largest:e}");
    assert!(
        differ * 100 <= a.image.linear.len(),
        "{differ} pixels differ"
    );
    assert!(largest <= 1e-5, "a colour differs by {largest}");
}

/// issue 16, item 5: a kernel specialised for ω = 1 (no `RELAX`) never renders ω = 1.8 as if
/// it were 1: the render is refused until the kernel is specialised again, and then the
/// over-relaxed march takes fewer steps, as on the CPU.
#[test]
fn a_sweep_of_relaxation_on_wgpu_takes_effect() {
    use sdfc_runtime::backend::{Backend, Prepared, Setup};
    if open_gpu().is_none() {
        return;
    }
    let plain = checked(
        "relax.sdf",
        "camera { position: (0, 1, -5), look_at: (0, 0.5, 0) }
         light point { position: (2, 4, -3) }
         render { width: 64, height: 48, relaxation: 1, method: \"march\" }
         scene { plane(); sphere(1).translate(0, 1, 0); torus(1, 0.2).translate(0, 0.3, 1); }",
    );
    let lowered = Lowered::new(&plain);
    let mut prepared =
        Prepared::from_program(Backend::Wgpu, &plain, lowered.clone(), &Setup::default())
            .expect("wgpu");
    let steps = |p: &Prepared, s: &Scene| {
        p.render(s, &|_| {})
            .expect("render")
            .render
            .stats
            .steps_mean
    };
    let at_one = steps(&prepared, &plain);
    let mut relaxed = plain.clone();
    relaxed.settings.relaxation = 1.8;
    let refused = prepared.render(&relaxed, &|_| {}).map(|_| ());
    assert!(
        refused
            .as_ref()
            .map_err(|e| e.to_string())
            .is_err_and(|e| e.contains("specialised") && e.contains("no over-relaxation")),
        "{refused:?}"
    );
    prepared.specialise(&relaxed).expect("specialised again");
    let at_relaxed = steps(&prepared, &relaxed);
    let cpu_one = cpu::render(&plain, &lowered, &cpu::Options::default(), &|| {})
        .stats
        .steps_mean;
    let cpu_relaxed = cpu::render(&relaxed, &lowered, &cpu::Options::default(), &|| {})
        .stats
        .steps_mean;
    println!(
        "steps/px: wgpu ω=1 {at_one:.2}, ω=1.8 {at_relaxed:.2}; cpu {cpu_one:.2}, {cpu_relaxed:.2}"
    );
    assert!(at_relaxed < 0.95 * at_one, "{at_relaxed} against {at_one}");
    assert!(
        (at_relaxed - cpu_relaxed).abs() < 0.05 * cpu_relaxed,
        "wgpu {at_relaxed} against cpu {cpu_relaxed}"
    );
    // And back: ω = 1 again needs the plain kernel.
    assert!(prepared.render(&plain, &|_| {}).is_err());
}

/// A field of two gradient noises (about 700 instructions a distance) seen at a grazing
/// angle with steps of an eighth of the distance (a declared L of 8), its rays taking
/// hundreds of steps. Through the interpreted kernel on a software adapter every loop of a
/// shader shares llvmpipe's budget of 65 535 iterations: at eight instructions an iteration
/// the first rays spent it and every loop after them stopped after one pass (15.1 dB against
/// the CPU, 47 % of the pixels, lavapipe 2026-11-27). The kernel the runtime writes for the
/// adapter (`interp::UNROLL_SOFTWARE` on a software one) renders it as the CPU does
/// (84.7 dB, 0 px).
const TWO_NOISES: &str = "camera { position: (0, 0.4, 0), look_at: (0, 0.3, 10), fov: 8deg }
light point { position: (0, 3, 20), intensity: 1, radius: 100, penumbra: 3deg }
render { width: 8, height: 4, max_steps: 2000, max_dist: 100, method: \"march\" }
scene {
  field(lipschitz: 8) { p.y + 0.15 * fbm(p * 1.5, octaves: 2) };
}
";

#[test]
fn a_field_of_two_noises_through_the_interpreted_kernel_matches_the_cpu() {
    let scene = checked("two_noises.sdf", TWO_NOISES);
    let lowered = Lowered::new(&scene);
    let Some(gpu) = open_gpu() else { return };
    let kernel = common::kernel_for(
        &scene,
        &lowered,
        wgsl::KernelChoice::Interpreted,
        gpu.is_cpu(),
    );
    assert!(kernel.interpreted());
    let (_, _, d) = side_by_side(&gpu, &scene, &lowered, &kernel);
    println!(
        "two noises, interpreted: psnr {:.1} dB, differing {:.4}",
        d.psnr, d.differing
    );
    assert!(d.psnr >= 80.0 && d.differing == 0.0, "{d:?}");
}

/// Colour fields (a marble of fbm noise on a sphere, a checker whose first colour is a
/// gradient by height) render on wgpu as on the CPU, through the analytically traced kernel,
/// the specialised marched kernel and the interpreted one; a colour field of constants
/// renders the plain colour's image on wgpu too.
#[test]
fn colour_fields_match_the_cpu_on_every_kernel() {
    let text = |marble: &str| {
        format!(
            "material marble = phong {{ color: {marble}, specular: 0.3, shininess: 24 }};\n\
             material floor = checker {{ a: field {{ vec3(0.3, 0.4 + 0.3 * clamp(p.z, 0, 1), 0.6) }}, b: (0.1, 0.1, 0.1), size: 1 }};\n\
             camera {{ position: (0, 1.5, -4), look_at: (0, 0.3, 0), fov: 50deg }}\n\
             light point {{ position: (3, 5, -4), intensity: 1.1, radius: 40 }}\n\
             render {{ width: 48, height: 32 }}\n\
             scene {{ plane((0, 1, 0), -0.8) @ floor; sphere(1) @ marble; }}"
        )
    };
    let marble = "field { mix(vec3(0.25, 0.22, 0.2), vec3(0.95, 0.93, 0.9), \
                  0.5 + 0.5 * sin(6 * p.x + 4 * fbm(p * 1.5, octaves: 2))) }";
    let scene = checked("colours.sdf", &text(marble));
    let Some(gpu) = open_gpu() else { return };
    for (method, choice) in common::KERNELS {
        let mut scene = scene.clone();
        scene.settings.method = method;
        let lowered = Lowered::new(&scene);
        let kernel = common::kernel_for(&scene, &lowered, choice, gpu.is_cpu());
        assert!(kernel.contract.has("COLOUR_FIELDS"));
        assert_eq!(
            kernel.interpreted(),
            choice == wgsl::KernelChoice::Interpreted
        );
        let (_, _, d) = side_by_side(&gpu, &scene, &lowered, &kernel);
        println!(
            "colour fields, {method:?}, {choice:?}: psnr {:.1} dB, differing {:.4}",
            d.psnr, d.differing
        );
        // Measured on lavapipe (2026-11-27): traced 128.3 dB, marched 80.6 dB with either
        // kernel, 0 px.
        let least = if method == Method::Auto { 120.0 } else { 77.0 };
        assert!(
            d.psnr >= least && d.differing == 0.0,
            "{method:?} {choice:?}: {d:?}"
        );
    }
    let constant = checked("constant.sdf", &text("field { vec3(0.9, 0.2, 0.2) }"));
    let plain = checked("plain.sdf", &text("(0.9, 0.2, 0.2)"));
    let render = |s: &Scene| {
        let lowered = Lowered::new(s);
        let kernel = wgsl::write(s, &lowered).expect("valid kernel");
        gpu::render(&gpu, s, &kernel, 1.0, &mut |_| {})
            .expect("render")
            .render
            .image
            .linear
    };
    assert!(render(&constant) == render(&plain));
}
