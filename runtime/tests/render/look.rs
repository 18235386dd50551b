//! The look (docs/rendering.md, "The look"), on every backend: ambient occlusion as its
//! formula predicts, fog by the documented amount, exposure and tone curves, and the checker
//! filtered over each sample's footprint.

use crate::common;

use common::{checked, render_everywhere};
use sdfc_compiler::{look, Scene, Tonemap};
use sdfc_runtime::image::Image;

/// A white floor and a wall standing on it along x = 0 (the box spans x from 0 to 2), lit by
/// the ambient term alone (ambient 1, no lights: a pixel is its occlusion), seen straight
/// down from above x = −1.
const CREASE: &str = "
material white = phong { color: (1, 1, 1), ambient: 1, diffuse: 0, specular: 0 };
camera { position: (-1, 10, 0), look_at: (-1, 0, 0), fov: 20deg }
render { width: 64, height: 64, background: (0, 0, 0), tonemap: \"none\" OCCLUSION }
scene { plane() @ white; box((1, 1, 3)).translate(1, 1, 0) @ white; }
";

/// The floor point of pixel column `px` on the middle row of [`CREASE`]'s image: the camera
/// looks down (−y) with +z up in the image and −x to its right.
fn crease_x(scene: &Scene, px: u32) -> f64 {
    let w = scene.settings.width as f64;
    let bx = 2.0 * (px as f64 + 0.5) / w - 1.0;
    let tan = (scene.camera.fov * 0.5).tan();
    -1.0 - 10.0 * bx * tan
}

/// The occlusion the formula gives at a floor point `x` in front of the wall (at distance −x
/// from it): dᵢ = min(hᵢ, −x), the nearer of the floor and the wall.
fn crease_ao(r: f64, x: f64) -> f64 {
    let n = look::OCCLUSION_SAMPLES;
    let sum: f64 = (1..=n)
        .map(|i| {
            let h = r * i as f64 / n as f64;
            (h - h.min(-x)).max(0.0) / h
        })
        .sum();
    (1.0 - look::OCCLUSION_STRENGTH / n as f64 * sum).clamp(0.0, 1.0)
}

/// Occlusion darkens the floor at the foot of the wall by the formula's amount, and leaves the
/// open floor (beyond R of the wall) as bright as without it; every backend agrees.
#[test]
fn occlusion_darkens_a_crease_by_the_formulas_amount() {
    let r = 0.5;
    let scene = checked(
        "crease",
        &CREASE.replace("OCCLUSION", &format!(", occlusion: {r}")),
    );
    let plain = checked("plain crease", &CREASE.replace("OCCLUSION", ""));
    let y = scene.settings.height / 2;
    let mut darkened = 0;
    for (backend, image) in render_everywhere("crease", &scene) {
        for px in 0..scene.settings.width {
            let x = crease_x(&scene, px);
            // Away from the pixel on the wall's edge, where the footprint straddles it.
            if x > -0.02 {
                continue;
            }
            let expected = crease_ao(r, x);
            let got = image.pixel(px, y)[0] as f64;
            assert!(
                (got - expected).abs() < 0.02,
                "{backend}: at x = {x:.3} the occlusion is {got:.4}, the formula {expected:.4}"
            );
            if expected < 0.9 {
                darkened += 1;
            }
        }
    }
    assert!(darkened >= 4, "the crease spans {darkened} pixels");
    // A uniform sky of 1 instead of the ambient term: its light is scaled by the same
    // occlusion (k_d = 1, E/π = 1).
    let sky = checked(
        "sky crease",
        &CREASE
            .replace("OCCLUSION", &format!(", occlusion: {r}"))
            .replace("ambient: 1, diffuse: 0", "ambient: 0, diffuse: 1")
            .replace(
                "scene {",
                "light sky { color: (1, 1, 1), background: false }\nscene {",
            ),
    );
    for (backend, image) in render_everywhere("sky crease", &sky) {
        for px in 0..sky.settings.width {
            let x = crease_x(&sky, px);
            if x > -0.02 {
                continue;
            }
            let (expected, got) = (crease_ao(r, x), image.pixel(px, y)[0] as f64);
            assert!(
                (got - expected).abs() < 0.02,
                "{backend}: sky light at x = {x:.3} is {got:.4}, the occlusion {expected:.4}"
            );
        }
    }
    for (backend, image) in render_everywhere("plain crease", &plain) {
        let far = (0..plain.settings.width)
            .find(|&px| crease_x(&plain, px) < -r - 0.05)
            .expect("open floor");
        assert_eq!(image.pixel(far, y)[0], 1.0, "{backend}: open floor");
    }
}

/// A red wall facing the camera at distance 4 in blue fog of distance D: the centre pixel is
/// e·red + (1 − e)·blue with e = e^(−4/D), a miss is the fog's colour, and no fog leaves
/// the wall red.
#[test]
fn fog_moves_a_far_pixel_towards_its_colour_by_the_documented_amount() {
    let text = "
material red = phong { color: (1, 0, 0), ambient: 1, diffuse: 0, specular: 0 };
camera { position: (0, 0, -4), look_at: (0, 0, 0), fov: 30deg }
render { width: 33, height: 33, background: (0, 0, 0) FOG }
scene { box((1, 1, 0.5)).translate(0, 0, 0.5) @ red; }
";
    let d = 3.0;
    let fog = checked(
        "fog",
        &text.replace("FOG", &format!(", fog: {d}, fog_color: (0, 0, 1)")),
    );
    let clear = checked("clear", &text.replace("FOG", ""));
    let e = (-4.0f64 / d).exp();
    for (backend, image) in render_everywhere("fog", &fog) {
        let c = image.pixel(16, 16);
        assert!(
            (c[0] as f64 - e).abs() < 1e-4 && (c[2] as f64 - (1.0 - e)).abs() < 1e-4,
            "{backend}: the wall is {c:?}, e = {e}"
        );
        assert_eq!(image.pixel(0, 0), [0.0, 0.0, 1.0], "{backend}: a miss");
    }
    for (backend, image) in render_everywhere("clear", &clear) {
        assert_eq!(image.pixel(16, 16), [1.0, 0.0, 0.0], "{backend}");
        assert_eq!(image.pixel(0, 0), [0.0, 0.0, 0.0], "{backend}");
    }
}

/// A wall of grey 0.3 filling the image: exposure doubles it per stop, and each tone curve
/// maps it as `look::grade` states.
#[test]
fn exposure_and_tone_curves_grade_the_pixel() {
    let text = "
material grey = phong { color: (0.3, 0.3, 0.3), ambient: 1, diffuse: 0, specular: 0 };
camera { position: (0, 0, -4), look_at: (0, 0, 0), fov: 10deg }
render { width: 8, height: 8 GRADE }
scene { box((5, 5, 0.5)).translate(0, 0, 0.5) @ grey; }
";
    for (exposure, tonemap) in [
        (0.0, Tonemap::None),
        (1.0, Tonemap::None),
        (0.0, Tonemap::Filmic),
        (1.5, Tonemap::Filmic),
        (-1.0, Tonemap::Reinhard),
    ] {
        let settings = format!(", exposure: {exposure}, tonemap: \"{}\"", tonemap.name());
        let scene = checked("grade", &text.replace("GRADE", &settings));
        let expected = look::grade(tonemap, exposure, 0.3);
        for (backend, image) in render_everywhere("grade", &scene) {
            let got = image.pixel(4, 4)[1] as f64;
            assert!(
                (got - expected).abs() < 1e-5,
                "{backend}: exposure {exposure}, {tonemap:?}: {got} against {expected}"
            );
        }
    }
}

/// The mean absolute difference of the rows `rows` of two images.
fn band_error(a: &Image, b: &Image, rows: std::ops::Range<u32>) -> f64 {
    let mut sum = 0.0;
    let mut n = 0;
    for y in rows {
        for x in 0..a.width {
            let (p, q) = (a.pixel(x, y), b.pixel(x, y));
            sum += (0..3).map(|c| (p[c] - q[c]).abs() as f64).sum::<f64>() / 3.0;
            n += 1;
        }
    }
    sum / n as f64
}

/// A checker floor running to the horizon at one sample a pixel: towards the horizon, where
/// many cells fall in a pixel, the filtered checker is close to the picture of 12×12 samples
/// a pixel (before the filter, one sample picked a cell at random there: moiré); near the
/// camera, where a pixel sees one cell, it is the checker as before.
#[test]
fn a_checker_is_filtered_over_the_pixels_footprint() {
    let text = "
material floor = checker { a: (1, 1, 1), b: (0, 0, 0), size: 0.5, ambient: 1, diffuse: 0, specular: 0 };
";
    // The rows just below the horizon (row 50 is the horizon's neighbourhood at this tilt).
    let (one, truth, horizon) = common::floor_to_the_horizon(text);
    let far = horizon + 1..horizon + 12;
    for (backend, image) in render_everywhere("one sample", &one) {
        let error = band_error(&image, &truth, far.clone());
        println!("{backend}: far rows {far:?} differ by {error:.4} on average");
        assert!(error < 0.05, "{backend}: far rows differ by {error:.4}");
        // Near the camera a pixel sees one cell: its colour is the cell's, 0 or 1, except
        // where it straddles an edge.
        let y = one.settings.height - 1;
        let pure = (0..one.settings.width)
            .filter(|&x| {
                let c = image.pixel(x, y)[0];
                c.abs() < 1e-3 || (c - 1.0).abs() < 1e-3
            })
            .count();
        assert!(
            pure * 10 >= one.settings.width as usize * 8,
            "{backend}: {pure} pure pixels"
        );
    }
}

/// The furnace for sky light: a diffuse white sphere (k_d = 1, no ambient) under a sky of
/// radiance 1 all round, without occlusion, is 1 wherever it is seen, from every side (the
/// sky's irradiance over π is 1 for every normal); the background, which the sky is not here,
/// stays black.
#[test]
fn a_white_sphere_under_a_uniform_sky_is_white() {
    let scene = checked(
        "furnace",
        "
material white = phong { color: (1, 1, 1), ambient: 0, diffuse: 1, specular: 0 };
camera { position: (0, 2, -4), look_at: (0, 0, 0), fov: 40deg }
light sky { color: (1, 1, 1), background: false }
render { width: 48, height: 48, background: (0, 0, 0), tonemap: \"none\" }
scene { sphere(1) @ white; }
",
    );
    for (backend, image) in render_everywhere("furnace", &scene) {
        let mut seen = 0;
        for y in 0..48 {
            for x in 0..48 {
                let c = image.pixel(x, y);
                if c == [0.0; 3] {
                    continue;
                }
                seen += 1;
                for v in c {
                    assert!((v - 1.0).abs() < 1e-4, "{backend}: ({x}, {y}) is {c:?}");
                }
            }
        }
        assert!(seen > 400, "{backend}: the sphere covers {seen} pixels");
    }
}

/// A sky that is the background: a miss shows its gradient, `horizon + (zenith − horizon)·y`
/// for a direction of height y, and its ground below the horizon.
#[test]
fn the_background_may_be_the_sky() {
    let scene = checked(
        "sky background",
        "
camera { position: (0, 0, 0), look_at: (0, 0, 1), fov: 90deg }
light sky { zenith: (0, 0, 1), horizon: (1, 1, 1), ground: (0.2, 0.1, 0) }
render { width: 9, height: 9, tonemap: \"none\" }
scene { sphere(0.1).translate(0, 0, -50); }
",
    );
    let row = |j: u32| {
        let by = 1.0 - 2.0 * (j as f64 + 0.5) / 9.0;
        by / (1.0 + by * by).sqrt()
    };
    for (backend, image) in render_everywhere("sky background", &scene) {
        let y = row(0);
        let top = image.pixel(4, 0);
        let expected = [1.0 - y, 1.0 - y, 1.0];
        for k in 0..3 {
            assert!(
                (top[k] as f64 - expected[k]).abs() < 1e-5,
                "{backend}: {top:?} against {expected:?}"
            );
        }
        assert_eq!(image.pixel(4, 8), [0.2, 0.1, 0.0], "{backend}: the ground");
    }
}

/// Seen from above: a white floor (k_d = 1) lit by a sun from above and to the side,
/// shadowed by a square slab floating above it. The penumbra (pixels between 5 % and 95 % of
/// the lit floor) widens with the sun's `angle`, alike on every backend; `shadows: false`
/// leaves no shadow at all.
#[test]
fn a_suns_penumbra_widens_with_its_angle() {
    let text = "
material white = phong { color: (1, 1, 1), ambient: 0, diffuse: 1, specular: 0 };
camera { position: (-2, 10, 0), look_at: (-2, 0, 0), up: (0, 0, 1), fov: 10deg }
light sun { direction: (-1, -2, 0) SUN }
render { width: 96, height: 96, background: (0, 0, 0) }
scene { plane() @ white; box((1, 0.05, 1)).translate(0, 2, 0) @ white; }
";
    // The lit floor: N·L.
    let lit = 2.0 / 5.0f32.sqrt();
    let mut widths = Vec::new();
    for angle in ["1deg", "4deg"] {
        let scene = checked("sun", &text.replace("SUN", &format!(", angle: {angle}")));
        let mut found = None;
        for (backend, image) in render_everywhere("sun", &scene) {
            let partial = (0..96)
                .filter(|&x| {
                    let v = image.pixel(x, 48)[0] / lit;
                    v > 0.05 && v < 0.95
                })
                .count();
            println!("{backend}: angle {angle}: {partial} pixels in the penumbra");
            if let Some(first) = found {
                assert!(partial.abs_diff(first) <= 1, "{backend} against the CPU");
            }
            found.get_or_insert(partial);
        }
        widths.push(found.expect("the CPU"));
    }
    assert!(widths[0] >= 1 && widths[1] > 2 * widths[0], "{widths:?}");
    let dark = |image: &Image| {
        (0..96)
            .filter(|&x| image.pixel(x, 48)[0] < 0.5 * lit)
            .count()
    };
    let shadowed = checked("shadows", &text.replace("SUN", ", angle: 4deg"));
    for (backend, image) in render_everywhere("shadows", &shadowed) {
        assert!(
            dark(&image) >= 10,
            "{backend}: {} dark pixels",
            dark(&image)
        );
    }
    let unshadowed = checked(
        "no shadows",
        &text.replace("SUN", ", angle: 4deg, shadows: false"),
    );
    for (backend, image) in render_everywhere("no shadows", &unshadowed) {
        // The slab's side, facing away from the sun, may show as a dark pixel.
        assert!(dark(&image) <= 2, "{backend}: {} dark pixels", dark(&image));
    }
}
