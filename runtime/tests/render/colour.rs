//! Colour from the surface (docs/language.md, "Colour fields"): a colour field reading the
//! normal `n`, and a colour field on a painted shape moved afterwards, in the shape's own
//! coordinates; on the CPU in f32 and f64, traced and marched, and on wgpu (the written and
//! the interpreted kernel) against the CPU.

use crate::common;

use sdfc_compiler::{Lowered, Method, Scene};
use sdfc_runtime::cpu::{self, Options, Precision};
use sdfc_runtime::{gpu, metrics};

/// Per-channel difference that counts a pixel as differing.
const THRESHOLD: f64 = 0.1;

fn checked(text: &str) -> Scene {
    let (scene, diags, _) = sdfc_compiler::check_str("colour.sdf", text);
    scene.unwrap_or_else(|| panic!("{diags:?}"))
}

/// A scene whose only light is its materials' ambient term of 1: each pixel shows its
/// colour field's value as it is.
fn lit_by_its_colours(camera: &str, material: &str, scene: &str) -> Scene {
    checked(&format!(
        "camera {{ {camera}, fov: 40deg }}\n\
         render {{ width: 64, height: 48 }}\n\
         material m = phong {{ color: {material}, ambient: 1, diffuse: 0, specular: 0 }};\n\
         scene {{ {scene} }}"
    ))
}

fn cpu_render(scene: &Scene, method: Method, precision: Precision) -> sdfc_runtime::image::Image {
    let mut s = scene.clone();
    s.settings.method = method;
    let options = Options {
        precision,
        ..Options::default()
    };
    cpu::render(&s, &Lowered::new(&s), &options, &|| {}).image
}

/// The two images differ by at most `differing` of their pixels and agree to `psnr` dB.
fn agree(
    a: &sdfc_runtime::image::Image,
    b: &sdfc_runtime::image::Image,
    psnr: f64,
    differing: f64,
    what: &str,
) {
    let d = metrics::compare(a, b, THRESHOLD).expect("same size");
    println!(
        "{what}: psnr {:.1} dB, differing {:.4}",
        d.psnr, d.differing
    );
    assert!(d.psnr >= psnr && d.differing <= differing, "{what}: {d:?}");
}

const CAMERA: &str = "position: (0, 0.6, -4), look_at: (0, 0, 0)";

/// `field { vec3(0.5) + 0.5 * n }` paints a unit sphere at the origin with its normals: the
/// picture of `vec3(0.5) + 0.5 * p`, since there the normal is the point itself.
#[test]
fn a_field_of_the_normal_paints_a_sphere_with_its_normals() {
    let normals = lit_by_its_colours(CAMERA, "field { vec3(0.5) + 0.5 * n }", "sphere(1) @ m;");
    let points = lit_by_its_colours(CAMERA, "field { vec3(0.5) + 0.5 * p }", "sphere(1) @ m;");
    agree_on_the_cpu(&normals, &points, (45.0, 0.0), "n and p");
}

/// `a` and `b` rendered on the CPU, marched and as they allow, in f32 and in f64: each pair of
/// pictures agrees as [`agree`] asks (`psnr` and `differing`), said under `what`.
fn agree_on_the_cpu(a: &Scene, b: &Scene, (psnr, differing): (f64, f64), what: &str) {
    for precision in [Precision::F32, Precision::F64] {
        for method in [Method::March, Method::Auto] {
            let x = cpu_render(a, method, precision);
            let y = cpu_render(b, method, precision);
            let label = format!("{what}, {method:?}, {precision:?}");
            agree(&x, &y, psnr, differing, &label);
        }
    }
}

/// The angle and offset of the moved sphere, and the same camera seen from the sphere:
/// `rotate_y(θ)` turns (x, y, z) into (x cos θ + z sin θ, y, −x sin θ + z cos θ).
const TURN_DEG: f64 = 40.0;
const OFFSET: [f64; 3] = [1.0, 0.3, 0.5];

/// `p` in the sphere's coordinates: rotate_y(−θ)(p − offset).
fn into_the_shape(p: [f64; 3]) -> [f64; 3] {
    let (s, c) = (-TURN_DEG.to_radians()).sin_cos();
    let q = [p[0] - OFFSET[0], p[1] - OFFSET[1], p[2] - OFFSET[2]];
    [q[0] * c + q[2] * s, q[1], -q[0] * s + q[2] * c]
}

/// A pattern of the point and the normal, smooth (so that rounding moves no edge).
const PATTERN: &str =
    "field { vec3(0.5 + 0.5 * sin(5 * p.x), 0.5 + 0.5 * sin(4 * p.y + 1), 0.5 + 0.5 * n.z) }";

/// The sphere painted, then turned and moved, and the camera placed and aimed in the world.
fn moved() -> Scene {
    let [x, y, z] = OFFSET;
    lit_by_its_colours(
        "position: (0.5, 1.4, -4.5), look_at: (1, 0.3, 0.5)",
        PATTERN,
        &format!("(sphere(1) @ m).rotate_y({TURN_DEG}deg).translate({x}, {y}, {z});"),
    )
}

/// The same: the sphere unmoved, the camera moved into its coordinates.
fn unmoved() -> Scene {
    let c = into_the_shape([0.5, 1.4, -4.5]);
    let l = into_the_shape([1.0, 0.3, 0.5]);
    lit_by_its_colours(
        &format!(
            "position: ({}, {}, {}), look_at: ({}, {}, {})",
            c[0], c[1], c[2], l[0], l[1], l[2]
        ),
        PATTERN,
        "sphere(1) @ m;",
    )
}

/// A colour field on a painted shape turned and moved afterwards moves with it: the picture
/// is that of the unmoved shape seen by the camera moved into its coordinates (the normal
/// turned with it too). Before, the pattern stayed in the world and the pictures differed.
#[test]
fn a_pattern_moves_with_its_shape() {
    let (moved, unmoved) = (moved(), unmoved());
    agree_on_the_cpu(&moved, &unmoved, (40.0, 0.002), "moved and unmoved");
    // Painted after the transforms, the same sphere keeps the world's coordinates: the
    // pattern does not move, and the pictures differ.
    let [x, y, z] = OFFSET;
    let in_the_world = lit_by_its_colours(
        "position: (0.5, 1.4, -4.5), look_at: (1, 0.3, 0.5)",
        PATTERN,
        &format!("sphere(1).rotate_y({TURN_DEG}deg).translate({x}, {y}, {z}) @ m;"),
    );
    let a = cpu_render(&in_the_world, Method::March, Precision::F32);
    let b = cpu_render(&unmoved, Method::March, Precision::F32);
    let d = metrics::compare(&a, &b, THRESHOLD).expect("same size");
    assert!(d.psnr < 25.0 && d.differing > 0.1, "{d:?}");
}

/// wgpu renders the normal's field and the moved pattern as the CPU does, with the written
/// kernel (traced and marched) and the interpreted one.
#[test]
fn colour_from_the_surface_matches_the_cpu_on_wgpu() {
    let Some(gpu) = common::open_gpu("colour from the surface") else {
        return;
    };
    let normals = lit_by_its_colours(CAMERA, "field { vec3(0.5) + 0.5 * n }", "sphere(1) @ m;");
    for scene in [normals, moved()] {
        for (method, choice) in common::KERNELS {
            let mut scene = scene.clone();
            scene.settings.method = method;
            let lowered = Lowered::new(&scene);
            let kernel = common::kernel_for(&scene, &lowered, choice, gpu.is_cpu());
            let on_gpu = gpu::render(&gpu, &scene, &kernel, 1.0, &mut |_| {}).expect("gpu render");
            let on_cpu = cpu_render(&scene, method, Precision::F32);
            agree(
                &on_gpu.render.image,
                &on_cpu,
                60.0,
                0.0,
                &format!("wgpu, {method:?}, {choice:?}"),
            );
        }
    }
}
