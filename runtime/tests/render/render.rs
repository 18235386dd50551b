//! Properties of CPU renders: coverage of a sphere seen head-on, shadows, mirrors, clear
//! glass, light falloff, bit-identical output whatever the number of threads, and the
//! explained artefacts of issue 24, item 4.

use crate::common;

use common::*;
use sdfc_compiler::{Light, Lowered, Method, Node, Pattern, Scene};
use sdfc_runtime::cpu::{self, Options, Precision, Render};

/// Renders `scene` sphere traced, whatever it allows (the step-related tests).
fn render(scene: &Scene) -> Render {
    render_as(Method::March, scene)
}

/// Both intersection methods: the properties below hold for either (analytic tracing is
/// chosen for these scenes only when it is allowed; otherwise both renders march).
const METHODS: [Method; 2] = [Method::March, Method::Auto];

/// Renders `scene` with the intersection `method`.
fn render_as(method: Method, scene: &Scene) -> Render {
    let mut scene = scene.clone();
    scene.settings.method = method;
    cpu::render(&scene, &Lowered::new(&scene), &Options::default(), &|| {})
}

fn render_with(scene: &Scene, options: &Options, threads: usize) -> Render {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    pool.install(|| cpu::render(scene, &Lowered::new(scene), options, &|| {}))
}

/// The camera of docs/rendering.md, "Camera", written again for a camera whose `up` is not
/// parallel to the view: (eye, u, v, w, tan(fov/2)).
fn basis(scene: &Scene) -> ([f64; 3], [f64; 3], [f64; 3], [f64; 3], f64) {
    let c = &scene.camera;
    let w = normalize(sub3(c.look_at, c.position));
    let u = normalize(cross(w, c.up));
    let v = cross(u, w);
    (c.position, u, v, w, (c.fov / 2.0).tan())
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let l = len3(a);
    a.map(|x| x / l)
}

/// The pixel whose centre ray passes through the world point `x`.
fn project(scene: &Scene, x: [f64; 3]) -> (u32, u32) {
    let (eye, u, v, w, tan) = basis(scene);
    let (wd, ht) = (scene.settings.width as f64, scene.settings.height as f64);
    let d = sub3(x, eye);
    let bx = dot(d, u) / dot(d, w) / (tan * wd / ht);
    let by = dot(d, v) / dot(d, w) / tan;
    let (ax, ay) = ((bx + 1.0) / 2.0, (1.0 - by) / 2.0);
    (
        (ax * wd - 0.5).round() as u32,
        (ay * ht - 0.5).round() as u32,
    )
}

fn luminance(c: [f32; 3]) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

fn small(scene: &mut Scene, w: u32, h: u32) {
    scene.settings.width = w;
    scene.settings.height = h;
    scene.settings.background = [0.0, 0.0, 0.0];
}

#[test]
fn a_sphere_seen_head_on_covers_the_predicted_pixels() {
    for method in METHODS {
        let mut scene = single(Node::Sphere { radius: 1.0 });
        scene.camera.position = [0.0, 0.0, -5.0];
        scene.camera.look_at = [0.0, 0.0, 0.0];
        small(&mut scene, 96, 72);
        let r = render_as(method, &scene);
        let covered = r.image.linear.iter().filter(|c| c[0] > 0.0).count() as i64;
        // A pixel is covered when its centre ray passes within the radius of the centre.
        let (eye, u, v, w, tan) = basis(&scene);
        let (wd, ht) = (96.0, 72.0);
        let mut predicted = 0i64;
        for y in 0..72 {
            for x in 0..96 {
                let bx = 2.0 * (x as f64 + 0.5) / wd - 1.0;
                let by = 1.0 - 2.0 * (y as f64 + 0.5) / ht;
                let dir = normalize(
                    [0, 1, 2].map(|i| w[i] + bx * tan * wd / ht * u[i] + by * tan * v[i]),
                );
                predicted += (len3(cross(eye, dir)) < 1.0) as i64;
            }
        }
        assert!(predicted > 300, "{predicted}");
        assert!(
            (covered - predicted).abs() <= 3,
            "covered {covered}, predicted {predicted}"
        );
        assert_eq!(r.stats.counters.hits as i64, covered);
    }
}

/// A camera looking straight down (its view parallel to the default `up`) sees the scene:
/// a sphere at the centre of the image and a marker sphere towards +z in the image's upper
/// half (the stand-in up is +z); with `up` along +x the image rolls and the marker moves to
/// the right, where the test's own projection puts it.
#[test]
fn a_camera_looking_straight_down_sees_the_scene_and_up_rolls_it() {
    let mut b = Build::new();
    let centre = b.add(Node::Sphere { radius: 1.0 });
    let marker = b.add(Node::Sphere { radius: 0.4 });
    let marker = b.at(marker, [0.0, 0.0, 2.5]);
    let root = b.add(Node::Combine {
        op: sdfc_compiler::Combine::Union,
        children: vec![centre, marker],
    });
    b.point_light([0.0, 10.0, 0.0], 0.0);
    let mut scene = b.finish(root);
    scene.camera.position = [0.0, 6.0, 0.0];
    scene.camera.look_at = [0.0, 0.0, 0.0];
    small(&mut scene, 64, 64);
    // Where the marker must appear: with up = +z (the stand-in), and rolled with up = +x.
    let mut facing = scene.clone();
    facing.camera.up = [0.0, 0.0, 1.0];
    let (mx, my) = project(&facing, [0.0, 0.0, 2.5]);
    assert!(mx == 32 && my < 16, "marker projected to ({mx}, {my})");
    let mut rolled = scene.clone();
    rolled.camera.up = [1.0, 0.0, 0.0];
    let (rx, ry) = project(&rolled, [0.0, 0.0, 2.5]);
    assert!(
        rx > 48 && ry.abs_diff(32) <= 1,
        "rolled marker projected to ({rx}, {ry})"
    );
    for method in METHODS {
        let r = render_as(method, &scene);
        let lit = |(x, y): (u32, u32)| luminance(r.image.linear[(y * 64 + x) as usize]) > 0.0;
        assert!(lit((32, 32)), "{method:?}: the centre sphere is not seen");
        assert!(
            lit((mx, my)),
            "{method:?}: the marker is not above the centre"
        );
        assert!(
            !lit((mx, 63 - my)),
            "{method:?}: something below the centre"
        );
        assert!(!lit((2, 2)), "{method:?}: a corner is not background");
        let r = render_as(method, &rolled);
        let lit = |(x, y): (u32, u32)| luminance(r.image.linear[(y * 64 + x) as usize]) > 0.0;
        assert!(
            lit((rx, ry)),
            "{method:?}: rolled marker not at ({rx}, {ry})"
        );
        assert!(!lit((mx, my)), "{method:?}: the rolled image did not roll");
    }
}

/// A grey floor, a sphere above it, a light up and to the side.
fn shadow_scene(penumbra: f64) -> Scene {
    let mut b = Build::new();
    let floor = b.add(Node::Plane {
        normal: [0.0, 1.0, 0.0],
        height: 0.0,
    });
    let s = b.add(Node::Sphere { radius: 0.5 });
    let s = b.at(s, [0.0, 1.0, 0.0]);
    let root = b.add(Node::Combine {
        op: sdfc_compiler::Combine::Union,
        children: vec![floor, s],
    });
    b.point_light([2.0, 5.0, 0.0], penumbra);
    let mut scene = b.finish(root);
    scene.camera.position = [0.0, 4.0, -6.0];
    scene.camera.look_at = [0.0, 0.0, 0.0];
    small(&mut scene, 160, 120);
    scene
}

#[test]
fn a_shadowed_pixel_is_darker_than_its_lit_neighbour() {
    for method in METHODS {
        for penumbra in [0.0, (1.0f64 / 8.0).atan()] {
            let scene = shadow_scene(penumbra);
            let r = render_as(method, &scene);
            // The shadow's centre on the floor, on the line from the light through the sphere.
            let (sx, sy) = project(&scene, [-0.5, 0.0, 0.0]);
            let (lx, ly) = project(&scene, [-0.5, 0.0, -1.2]);
            let (dark, lit) = (
                luminance(r.image.pixel(sx, sy)),
                luminance(r.image.pixel(lx, ly)),
            );
            assert!(
                dark < 0.5 * lit,
                "penumbra {penumbra}: shadow {dark}, lit {lit}"
            );
            // Hard shadows leave only the ambient term: k_a · C.
            if penumbra == 0.0 {
                assert!(
                    (r.image.pixel(sx, sy)[0] - 0.1 * 0.8).abs() < 1e-4,
                    "{:?}",
                    r.image.pixel(sx, sy)
                );
            }
        }
    }
}

/// A red ball above a floor whose reflectivity is `reflect`.
/// A glass ball half sunk into a checkered floor shows the floor through it (refracted rays
/// inside the glass find the floor's surface there), not a dull dome of background colour:
/// within the ball's lower half, both checker colours are seen.
#[test]
fn glass_sunk_into_the_floor_shows_the_floor_through_it() {
    let text = "material glass = phong { color: (1, 1, 1), transparency: 0.9, ior: 1.5 };\n\
                material floor = checker { a: (0.9, 0.9, 0.9), b: (0.1, 0.1, 0.1), size: 0.5 };\n\
                camera { position: (0, 1.5, -3), look_at: (0, 0.2, 0), fov: 50deg }\n\
                light point { position: (2, 5, -3) }\n\
                render { width: 320, height: 240 }\n\
                scene { plane((0, 1, 0), 0) @ floor; sphere(0.8) @ glass; }";
    let (scene, diags, _) = sdfc_compiler::check_str("glass.sdf", text);
    let scene = scene.unwrap_or_else(|| panic!("{diags:?}"));
    let r = render(&scene);
    // The pixels of the ball's lower half, above the floor's horizon line behind it.
    let (mut bright, mut dark, mut all) = (0, 0, 0);
    for y in 110..150 {
        for x in 130..190 {
            let l = luminance(r.image.pixel(x, y));
            bright += (l > 0.4) as u32;
            dark += (l < 0.2) as u32;
            all += 1;
        }
    }
    assert!(
        bright * 8 > all && dark * 8 > all,
        "{bright} bright and {dark} dark of {all} pixels: the floor is not seen through the glass"
    );
}

/// `penumbra` means what its name says: the wider it is, the more of the floor around the
/// shadow lies in a partial shadow, and the further the image is from the hard shadow's.
#[test]
fn a_wider_penumbra_gives_a_softer_shadow() {
    let hard = render(&shadow_scene(0.0));
    let apart = |deg: f64| {
        let r = render(&shadow_scene(deg.to_radians()));
        let partial = r
            .image
            .linear
            .iter()
            .zip(&hard.image.linear)
            .filter(|(a, b)| (luminance(**a) - luminance(**b)).abs() > 0.01)
            .count();
        partial
    };
    let (narrow, medium, wide) = (apart(1.0), apart(5.0), apart(20.0));
    assert!(
        narrow < medium && medium < wide && narrow > 0,
        "pixels off the hard shadow: 1° {narrow}, 5° {medium}, 20° {wide}"
    );
}

fn mirror_scene(reflect: f64) -> Scene {
    let mut b = Build::new();
    let grey = b.material([0.5, 0.5, 0.5], reflect, 0.0);
    let red = b.material([1.0, 0.0, 0.0], 0.0, 0.0);
    let floor = b.add(Node::Plane {
        normal: [0.0, 1.0, 0.0],
        height: 0.0,
    });
    let floor = b.paint(floor, grey);
    let s = b.add(Node::Sphere { radius: 0.5 });
    let s = b.at(s, [0.0, 0.6, 2.0]);
    let s = b.paint(s, red);
    let root = b.add(Node::Combine {
        op: sdfc_compiler::Combine::Union,
        children: vec![floor, s],
    });
    b.point_light([0.0, 5.0, -2.0], 0.0);
    let mut scene = b.finish(root);
    scene.camera.position = [0.0, 1.0, -4.0];
    scene.camera.look_at = [0.0, 0.0, 2.0];
    small(&mut scene, 120, 90);
    scene
}

#[test]
fn a_mirror_shows_the_reflected_object() {
    for method in METHODS {
        // Where the camera sees the ball's mirror image (its centre reflected in y = 0).
        let with = render_as(method, &mirror_scene(0.9));
        let without = render_as(method, &mirror_scene(0.0));
        let (x, y) = project(&mirror_scene(0.9), [0.0, -0.6, 2.0]);
        let (m, plain) = (with.image.pixel(x, y), without.image.pixel(x, y));
        assert!(m[0] > 2.0 * m[1] + 0.05, "mirror pixel not red: {m:?}");
        assert!(
            (plain[0] - plain[1]).abs() < 1e-4,
            "plain floor pixel not grey: {plain:?}"
        );
        assert!(
            with.stats.counters.secondary_rays > 0 && without.stats.counters.secondary_rays == 0
        );
    }
}

/// A checkerboard wall behind where a ball may stand.
fn glass_scene(ball: Option<(f64, f64)>) -> Scene {
    let mut b = Build::new();
    let wall = b.add(Node::Plane {
        normal: [0.0, 0.0, -1.0],
        height: -3.0,
    });
    let mut root = wall;
    if let Some((transparency, ior)) = ball {
        let glass = b.material([1.0, 1.0, 1.0], 0.0, transparency);
        b.scene.materials[glass.0 as usize].ior = ior;
        b.scene.materials[glass.0 as usize].specular = 0.0;
        let s = b.add(Node::Sphere { radius: 1.0 });
        let s = b.paint(s, glass);
        root = b.add(Node::Combine {
            op: sdfc_compiler::Combine::Union,
            children: vec![wall, s],
        });
    }
    b.scene.materials[0].pattern = Pattern::Checker {
        a: [0.9, 0.9, 0.9].into(),
        b: [0.1, 0.1, 0.1].into(),
        size: 0.5,
    };
    b.point_light([0.0, 0.0, -6.0], 4.0);
    let mut scene = b.finish(root);
    scene.camera.position = [0.0, 0.0, -5.0];
    scene.camera.look_at = [0.0, 0.0, 0.0];
    small(&mut scene, 96, 72);
    scene
}

#[test]
fn clear_glass_of_index_one_is_invisible() {
    for method in METHODS {
        let bare = render_as(method, &glass_scene(None));
        let clear = render_as(method, &glass_scene(Some((1.0, 1.0))));
        let differ = bare
            .image
            .linear
            .iter()
            .zip(&clear.image.linear)
            .filter(|(a, b)| (a[0] - b[0]).abs() > 0.02)
            .count();
        assert!(
            differ * 50 < bare.image.linear.len(),
            "{differ} pixels differ"
        );
        assert!(clear.stats.counters.secondary_rays > 0);
        // Real glass bends the checkerboard: many pixels change, none is NaN.
        let glass = render_as(method, &glass_scene(Some((0.9, 1.5))));
        let changed = bare
            .image
            .linear
            .iter()
            .zip(&glass.image.linear)
            .filter(|(a, b)| (a[0] - b[0]).abs() > 0.02)
            .count();
        assert!(changed > 300, "{changed}");
        assert!(glass
            .image
            .linear
            .iter()
            .all(|c| c.iter().all(|v| v.is_finite())));
    }
}

#[test]
fn a_point_light_does_not_reach_past_its_radius() {
    for method in METHODS {
        let mut scene = shadow_scene(0.0);
        if let Some(Light::Point { radius, .. }) = scene.lights.first_mut() {
            *radius = 2.0;
        }
        let r = render_as(method, &scene);
        let (x, y) = project(&scene, [1.5, 0.0, -1.5]);
        assert!(
            (r.image.pixel(x, y)[0] - 0.08).abs() < 1e-5,
            "{:?}",
            r.image.pixel(x, y)
        );
    }
}

fn busy() -> Scene {
    let mut scene = mirror_scene(0.5);
    let glass = {
        let mut m = scene.materials[2].clone();
        m.transparency = 0.6;
        m.reflect = 0.2;
        m
    };
    scene.materials[2] = glass;
    if let Some(Light::Point { penumbra, .. }) = scene.lights.first_mut() {
        *penumbra = (1.0f64 / 6.0).atan();
    }
    scene.settings.aa = 2;
    scene.settings.width = 72;
    scene.settings.height = 40;
    scene
}

#[test]
fn output_is_bit_identical_whatever_the_thread_count() {
    let scene = busy();
    let options = Options {
        tile: 8,
        ..Options::default()
    };
    let one = render_with(&scene, &options, 1);
    for threads in [2, 3] {
        let other = render_with(&scene, &options, threads);
        assert!(one.image == other.image, "{threads} threads");
        assert_eq!(one.stats, other.stats);
    }
    assert_eq!(
        render_with(&scene, &options, 2).image,
        one.image,
        "run to run"
    );
}

#[test]
fn f64_and_f32_renders_agree() {
    let scene = busy();
    let a = render(&scene);
    let b = render_with(
        &scene,
        &Options {
            precision: Precision::F64,
            ..Options::default()
        },
        2,
    );
    let mean: f64 = a
        .image
        .linear
        .iter()
        .zip(&b.image.linear)
        .map(|(x, y)| (x[0] - y[0]).abs() as f64)
        .sum::<f64>()
        / a.image.linear.len() as f64;
    assert!(mean < 0.01, "{mean}");
}

#[test]
fn over_relaxation_changes_little() {
    let mut scene = shadow_scene(8.0);
    let plain = render(&scene);
    scene.settings.relaxation = 1.6;
    let relaxed = render(&scene);
    let differ = plain
        .image
        .linear
        .iter()
        .zip(&relaxed.image.linear)
        .filter(|(a, b)| (a[0] - b[0]).abs() > 0.02)
        .count();
    assert!(differ * 100 < plain.image.linear.len(), "{differ}");
}

#[test]
fn statistics_add_up() {
    let r = render(&busy());
    let c = &r.stats.counters;
    assert_eq!(c.camera_rays, 72 * 40 * 4);
    assert_eq!(
        c.hits + c.misses + c.budget_misses + c.nans,
        c.camera_rays + c.secondary_rays
    );
    assert_eq!(r.stats.pixels, 72 * 40);
    assert!(
        r.stats.steps_max >= r.stats.steps_p99
            && r.stats.steps_p99 as f64 >= r.stats.steps_mean * 0.5
    );
    assert_eq!(c.nans, 0);
}

#[test]
fn a_tiny_step_budget_misses_by_budget() {
    let mut scene = shadow_scene(0.0);
    scene.settings.max_steps = 2;
    let r = render(&scene);
    assert!(r.stats.counters.budget_misses > 0);
    assert_eq!(r.stats.steps_max, 2);
}

/// The scene of `compiler/tests/in/ok/nan_at_run_time.sdf`: NaN at run time in f32, beyond about 1.8
/// from the origin, with finite constants.
fn nan_scene() -> Scene {
    let text =
        std::fs::read_to_string("../compiler/tests/in/ok/nan_at_run_time.sdf").expect("scene");
    let (scene, diags, _) = sdfc_compiler::check_str("nan.sdf", &text);
    scene.unwrap_or_else(|| panic!("{diags:?}"))
}

fn is_magenta(c: [f32; 3]) -> bool {
    c == cpu::NAN_COLOUR
}

#[test]
fn debug_nan_paints_the_pixels_whose_rays_met_nan_magenta() {
    let scene = nan_scene();
    let plain = render(&scene);
    assert!(plain.stats.counters.nans > 0, "the scene meets no NaN");
    assert!(!plain.image.linear.iter().any(|&c| is_magenta(c)));
    let debug = cpu::render(
        &scene,
        &Lowered::new(&scene),
        &Options {
            debug_nan: true,
            ..Options::default()
        },
        &|| {},
    );
    assert_eq!(debug.stats, plain.stats);
    let background = scene.settings.background.map(|x| x as f32);
    let mut magenta = 0;
    for (&d, &p) in debug.image.linear.iter().zip(&plain.image.linear) {
        if is_magenta(d) {
            magenta += 1;
            // Here the camera ray met the NaN: without the flag it shows the background.
            assert_eq!(p, background);
        } else {
            assert_eq!(d, p, "a pixel without NaN changed");
        }
    }
    let pixels = plain.image.linear.len();
    assert!(
        magenta > pixels / 10 && magenta < pixels / 2,
        "{magenta} of {pixels} pixels are magenta"
    );
    // In f64 nothing overflows: no NaN, nothing painted.
    let f64 = cpu::render(
        &scene,
        &Lowered::new(&scene),
        &Options {
            debug_nan: true,
            precision: Precision::F64,
            ..Options::default()
        },
        &|| {},
    );
    assert_eq!(f64.stats.counters.nans, 0);
    assert!(!f64.image.linear.iter().any(|&c| is_magenta(c)));
}

#[test]
fn debug_nan_leaves_an_image_without_nan_unchanged() {
    let scene = busy();
    let debug = Options {
        debug_nan: true,
        ..Options::default()
    };
    let with = render_with(&scene, &debug, 2);
    let without = render_with(&scene, &Options::default(), 2);
    assert_eq!(with.stats.counters.nans, 0);
    assert!(with.image == without.image);
}

/// The world is right-handed with y up: looking along +z (as the default camera does), +x
/// is on the left of the picture (README, docs/language.md §8).
#[test]
fn looking_along_plus_z_plus_x_is_on_the_left() {
    let text = "camera { position: (0, 0, -5), look_at: (0, 0, 0), fov: 40deg }\n\
                light directional { direction: (0, 0, 1) }\n\
                render { width: 40, height: 20, background: (0, 0, 0) }\n\
                scene { sphere(0.5).translate(1, 0, 0); }";
    let (scene, diags, _) = sdfc_compiler::check_str("hand.sdf", text);
    let scene = scene.unwrap_or_else(|| panic!("{diags:?}"));
    let image = render(&scene).image;
    let light = |xs: std::ops::Range<u32>| {
        xs.flat_map(|x| (0..20).map(move |y| (x, y)))
            .map(|(x, y)| luminance(image.pixel(x, y)))
            .sum::<f32>()
    };
    assert!(light(0..20) > 1.0, "the left half is dark");
    assert_eq!(light(20..40), 0.0, "the right half shows something");
}

fn checked(name: &str, text: &str) -> Scene {
    let (scene, diags, _) = sdfc_compiler::check_str(name, text);
    scene.unwrap_or_else(|| panic!("{diags:?}"))
}

/// Issue 24, item 4 (docs/rendering.md, "Secondary rays"): in a glass `smooth_union` blob,
/// the dark crescents are rays that total internal reflection keeps inside the glass until
/// `max_depth`, and the speckled band is the distant checkerboard seen through the glass.
/// On a plain floor, raising `max_depth` from 5 to 30 removes nearly all the dark pixels,
/// and the band is smooth.
#[test]
fn the_glass_blobs_crescents_are_max_depth_and_its_band_the_checker() {
    let blob = "material glass = phong { color: (1, 1, 1), transparency: 0.9, ior: 1.5 };\n\
                material floor = phong { color: (0.5, 0.5, 0.5) };\n\
                camera { position: (0, 2, -6), look_at: (0, 0.8, 0), fov: 35deg }\n\
                light point { position: (4, 6, -4), intensity: 1, radius: 30 }\n\
                render { width: 480, height: 360 }\n\
                scene {\n\
                  plane((0, 1, 0), -0.5) @ floor;\n\
                  smooth_union(0.4, sphere(0.8).translate(0, 1, 0), torus(1.0, 0.3).rotate_x(90deg)) @ glass;\n\
                }";
    let dark = |depth: u32| {
        let mut scene = checked("blob.sdf", blob);
        scene.settings.max_depth = depth;
        let g = grey(&render(&scene).image);
        let band = roughness(&g, 480, (180, 158, 300, 176));
        (g.iter().filter(|&&l| l < 0.15).count(), band)
    };
    let ((shallow, band), (deep, _)) = (dark(5), dark(30));
    println!("dark pixels: {shallow} at max_depth 5, {deep} at 30; band roughness {band:.5}");
    assert!(shallow > 500, "{shallow} dark pixels at max_depth 5");
    assert!(deep * 20 < shallow, "{deep} dark pixels at max_depth 30");
    assert!(
        band < 0.003,
        "the band through the glass is rough: {band:.5}"
    );
}

/// A traced render evaluates no distance program, so its tapes are never prepared (issue 37:
/// a large traced scene spent most of its preparation on them); a marched render of the
/// same scene prepares them, and both give the image they gave when tapes were prepared up
/// front.
#[test]
fn a_traced_render_prepares_no_tapes() {
    let mut scene = single(Node::Sphere { radius: 1.0 });
    small(&mut scene, 32, 24);
    let lowered = Lowered::new(&scene);
    for (method, marches) in [(Method::Trace, false), (Method::March, true)] {
        scene.settings.method = method;
        let tapes = cpu::Tapes::new(&lowered);
        let r = cpu::render_tapes(&scene, &tapes, &Options::default(), &|| {});
        assert!(
            r.stats.counters.hits > 20,
            "{method:?}: {} hits",
            r.stats.counters.hits
        );
        assert_eq!(tapes.prepared(), marches, "{method:?}");
        let prepared = cpu::Tapes::new(&lowered);
        prepared.prepare();
        let again = cpu::render_tapes(&scene, &prepared, &Options::default(), &|| {});
        assert_eq!(r.image.linear, again.image.linear, "{method:?}");
    }
}

/// A material whose colour (and a checker whose colours) are colour fields of constants
/// renders the image of the plain colours, bit for bit, sphere traced and traced
/// analytically, in f32 and in the f64 reference; a field that varies changes it.
#[test]
fn a_constant_colour_field_renders_as_the_plain_colour() {
    let text = |red: &str, a: &str| {
        format!(
            "material red = phong {{ color: {red}, specular: 0.4 }};\n\
             material floor = checker {{ a: {a}, b: (0.1, 0.12, 0.15), size: 0.5 }};\n\
             camera {{ position: (0, 1.5, -4), look_at: (0, 0.3, 0) }}\n\
             light point {{ position: (3, 5, -4) }}\n\
             render {{ width: 48, height: 32 }}\n\
             scene {{ plane((0, 1, 0), -0.8) @ floor; sphere(1) @ red; }}"
        )
    };
    let scene = |t: &str| {
        let (scene, diags, _) = sdfc_compiler::check_str("colours.sdf", t);
        scene.unwrap_or_else(|| panic!("{diags:?}"))
    };
    let plain = scene(&text("(0.9, 0.2, 0.2)", "(0.9, 0.9, 0.85)"));
    let fields = scene(&text(
        "field { vec3(0.9, 0.2, 0.2) }",
        "field { (0.9, 0.9, 0.85) }",
    ));
    let varying = scene(&text(
        "field { vec3(0.9, 0.2 + 0.2 * sin(8 * p.y), 0.2) }",
        "(0.9, 0.9, 0.85)",
    ));
    for precision in [Precision::F32, Precision::F64] {
        let options = Options {
            precision,
            ..Options::default()
        };
        for method in METHODS {
            let run = |s: &Scene| {
                let mut s = s.clone();
                s.settings.method = method;
                cpu::render(&s, &Lowered::new(&s), &options, &|| {})
                    .image
                    .linear
            };
            let want = run(&plain);
            assert!(
                run(&fields) == want,
                "{precision:?} {method:?}: the constant fields change the image"
            );
            assert!(
                run(&varying) != want,
                "{precision:?} {method:?}: a field that varies"
            );
        }
    }
}

/// A profile written as a formula of the plane's point renders as the built-in profile it
/// spells: `profile { length(p) - r }` extruded and revolved against `circle(r)`, both
/// sphere traced, in f32 and in the f64 reference (the formula is only known to be a bound,
/// the built-in exact: the steps differ, the surfaces do not).
#[test]
fn a_profile_formula_renders_as_the_profile_it_spells() {
    let text = |disc: &str| {
        format!(
            "material red = phong {{ color: (0.9, 0.2, 0.2), specular: 0.4 }};\n\
             camera {{ position: (0, 1.5, -4), look_at: (0, 0, 0) }}\n\
             light point {{ position: (3, 5, -4) }}\n\
             render {{ width: 64, height: 48, method: \"march\" }}\n\
             scene {{ plane((0, 1, 0), -0.8) @ red;\n\
             extrude({disc}, 0.6).rotate_y(30deg).translate(-0.9, 0, 0);\n\
             revolve({disc}.translate(0.6, 0)).translate(1, 0, 0); }}"
        )
    };
    let scene = |t: &str| {
        let (scene, diags, _) = sdfc_compiler::check_str("profile.sdf", t);
        scene.unwrap_or_else(|| panic!("{diags:?}"))
    };
    let built_in = scene(&text("circle(0.5)"));
    let formula = scene(&text("profile { length(p) - 0.5 }"));
    let other = scene(&text("profile { length(p) - 0.45 }"));
    for precision in [Precision::F32, Precision::F64] {
        let options = Options {
            precision,
            ..Options::default()
        };
        let run = |s: &Scene| cpu::render(s, &Lowered::new(s), &options, &|| {}).image;
        let want = run(&built_in);
        let d = sdfc_runtime::metrics::compare(&run(&formula), &want, 0.1).expect("same size");
        println!(
            "{precision:?}: {:.1} dB, {:.4} differing",
            d.psnr, d.differing
        );
        assert!(d.psnr > 60.0 && d.differing == 0.0, "{precision:?}: {d:?}");
        // A different radius is seen.
        let d = sdfc_runtime::metrics::compare(&run(&other), &want, 0.1).expect("same size");
        assert!(d.psnr < 40.0, "{precision:?}: {d:?}");
    }
}

/// The fraction of `image`'s pixels that are not the background.
fn coverage(image: &sdfc_runtime::image::Image, background: [f64; 3]) -> f64 {
    let off = |c: &[f32; 3]| (0..3).any(|i| (f64::from(c[i]) - background[i]).abs() > 0.02);
    image.linear.iter().filter(|c| off(c)).count() as f64 / image.linear.len() as f64
}

/// A marched surface 73 units away, within the default `max_dist` of 100, is seen on every
/// backend: the first over-relaxed step (ω·73 > 100) crosses `max_dist`, and only a step the
/// march has verified may end the ray as a miss (docs/rendering.md, "Marching").
#[test]
fn a_surface_near_max_dist_is_not_lost_to_a_relaxed_step() {
    let text = "camera { position: (0, 0, -74), look_at: (0, 0, 0), fov: 3deg }\n\
                render { width: 32, height: 24, method: \"march\" }\n\
                scene { sphere(1).round(0.01); }";
    let (scene, diags, _) = sdfc_compiler::check_str("far.sdf", text);
    let scene = scene.unwrap_or_else(|| panic!("{diags:?}"));
    assert!(scene.settings.relaxation > 1.0 && scene.settings.max_dist == 100.0);
    for (backend, image) in render_everywhere("far sphere", &scene) {
        let c = coverage(&image, scene.settings.background);
        println!("{backend}: {:.1} % of pixels on the sphere", 100.0 * c);
        assert!(
            c > 0.15,
            "{backend}: the sphere covers {:.3} of the picture",
            c
        );
    }
}

/// A warp written as a field, `distance(s, q)`, shows `s`'s materials on every backend: the
/// red sphere stays red (it rendered all grey, the default material).
#[test]
fn a_warp_written_as_a_field_shows_the_warped_shapes_materials() {
    let text = "material red = phong { color: (0.9, 0.1, 0.1) };\n\
                material grey = phong { color: (0.5, 0.5, 0.5) };\n\
                camera { position: (0, 1, -4), look_at: (0.7, 0, 0), fov: 50deg }\n\
                light point { position: (2, 4, -4) }\n\
                render { width: 48, height: 32 }\n\
                let s = union(sphere(0.5) @ red, box(0.3).translate(1.5, 0, 0) @ grey);\n\
                scene { field { distance(s, vec3(p.x, p.y + 0.2 * sin(3 * p.x), p.z)) }; }";
    let (scene, diags, _) = sdfc_compiler::check_str("warp.sdf", text);
    let scene = scene.unwrap_or_else(|| panic!("{diags:?}"));
    for (backend, image) in render_everywhere("warp", &scene) {
        let red = image
            .linear
            .iter()
            .filter(|c| c[0] > 0.2 && c[0] > 3.0 * c[1])
            .count();
        let grey = image
            .linear
            .iter()
            .filter(|c| c[0] > 0.1 && (c[0] - c[1]).abs() < 0.02)
            .count();
        println!("{backend}: {red} red and {grey} grey pixels");
        assert!(red > 20 && grey > 10, "{backend}: {red} red, {grey} grey");
    }
}

/// A scene whose bounded parts lie beyond the default `max_dist` of 100 is seen (the default
/// covers them from the camera) on every backend: it was an empty picture without a word.
#[test]
fn a_scene_beyond_a_hundred_units_is_seen_with_the_default_max_dist() {
    let text = "camera { position: (0, 0, -150), look_at: (0, 0, 0), fov: 3deg }\n\
                light point { position: (0, 10, -100) }\n\
                render { width: 32, height: 24 }\n\
                scene { sphere(3); }";
    let (scene, diags, _) = sdfc_compiler::check_str("far.sdf", text);
    let scene = scene.unwrap_or_else(|| panic!("{diags:?}"));
    for (backend, image) in render_everywhere("far scene", &scene) {
        let c = coverage(&image, scene.settings.background);
        println!("{backend}: {:.1} % of pixels on the sphere", 100.0 * c);
        assert!(
            c > 0.08,
            "{backend}: the sphere covers {c:.3} of the picture"
        );
    }
}
