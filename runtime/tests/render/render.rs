//! Properties of CPU renders: coverage of a sphere seen head-on, the camera's orientation,
//! bit-identical output whatever the number of threads, f64 against f32, statistics, the debug
//! view of NaN; and the helpers and scenes `shading` and `regressions` share.

use crate::common;
use common::*;
use glam::DVec3;
use sdfc_compiler::{Light, Lowered, Method, Node, Scene};
use sdfc_runtime::cpu::{self, Options, Precision, Render};

/// Renders `scene` sphere traced, whatever it allows (the step-related tests).
pub(crate) fn render(scene: &Scene) -> Render {
    render_as(Method::March, scene)
}

/// Both intersection methods: the properties below hold for either (analytic tracing is
/// chosen for these scenes only when it is allowed; otherwise both renders march).
pub(crate) const METHODS: [Method; 2] = [Method::March, Method::Auto];

/// Renders `scene` with the intersection `method`.
pub(crate) fn render_as(method: Method, scene: &Scene) -> Render {
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
fn basis(scene: &Scene) -> (DVec3, DVec3, DVec3, DVec3, f64) {
    let c = &scene.camera;
    let w = (DVec3::from(c.look_at) - DVec3::from(c.position)).normalize();
    let u = w.cross(c.up.into()).normalize();
    let v = u.cross(w);
    (c.position.into(), u, v, w, (c.fov / 2.0).tan())
}

/// The pixel whose centre ray passes through the world point `x`.
pub(crate) fn project(scene: &Scene, x: [f64; 3]) -> (u32, u32) {
    let (eye, u, v, w, tan) = basis(scene);
    let (wd, ht) = (scene.settings.width as f64, scene.settings.height as f64);
    let d = DVec3::from(x) - eye;
    let bx = d.dot(u) / d.dot(w) / (tan * wd / ht);
    let by = d.dot(v) / d.dot(w) / tan;
    let (ax, ay) = ((bx + 1.0) / 2.0, (1.0 - by) / 2.0);
    (
        (ax * wd - 0.5).round() as u32,
        (ay * ht - 0.5).round() as u32,
    )
}

pub(crate) fn luminance(c: [f32; 3]) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

pub(crate) fn small(scene: &mut Scene, w: u32, h: u32) {
    scene.settings.width = w;
    scene.settings.height = h;
    scene.settings.background = [0.0, 0.0, 0.0];
}

/// `scene` seen from `position` towards `look_at`, [`small`].
pub(crate) fn seen_from(
    scene: &mut Scene,
    (position, look_at): ([f64; 3], [f64; 3]),
    (w, h): (u32, u32),
) {
    scene.camera.position = position;
    scene.camera.look_at = look_at;
    small(scene, w, h);
}

#[test]
fn a_sphere_seen_head_on_covers_the_predicted_pixels() {
    for method in METHODS {
        let mut scene = single(Node::Sphere { radius: 1.0 });
        seen_from(&mut scene, ([0.0, 0.0, -5.0], [0.0, 0.0, 0.0]), (96, 72));
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
                let dir = (w + u * (bx * tan * wd / ht) + v * (by * tan)).normalize();
                predicted += (eye.cross(dir).length() < 1.0) as i64;
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
    seen_from(&mut scene, ([0.0, 6.0, 0.0], [0.0, 0.0, 0.0]), (64, 64));
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
pub(crate) fn shadow_scene(penumbra: f64) -> Scene {
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
    seen_from(&mut scene, ([0.0, 4.0, -6.0], [0.0, 0.0, 0.0]), (160, 120));
    scene
}

pub(crate) fn mirror_scene(reflect: f64) -> Scene {
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
    seen_from(&mut scene, ([0.0, 1.0, -4.0], [0.0, 0.0, 2.0]), (120, 90));
    scene
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
