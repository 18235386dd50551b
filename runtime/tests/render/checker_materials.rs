//! A checker of two materials (docs/rendering.md, "The checker's footprint"), on every
//! backend: where a pixel sees one cell it is that material's picture, reflections included,
//! and towards the horizon the two materials blend over the footprint instead of shimmering.

use crate::common;

use common::{checked, render_everywhere};
use sdfc_runtime::image::Image;

/// A floor of FLOOR under a lamp, with a red ball the floor may reflect.
const TILES: &str = "
material shiny = phong { color: (0.2, 0.3, 0.9), specular: 0.8, shininess: 60, reflect: 0.4 };
material matte = phong { color: (0.9, 0.8, 0.2), specular: 0, ambient: 0.3 };
material tiles = checker { a: shiny, b: matte, size: 1 };
material red = phong { color: (0.9, 0.1, 0.1) };
camera { position: (0, 1.5, -4), look_at: (0, 0.3, 0), fov: 45deg }
light point { position: (1, 4, -2), intensity: 1.2 }
render { width: 96, height: 64, max_depth: 2 }
scene { plane() @ FLOOR; sphere(0.5).translate(0, 0.5, 0.5) @ red; }
";

/// Each pixel of the checker's picture is the picture of the floor in one material or the
/// other (its reflection of the ball and its highlight included) wherever the pixel sees one
/// cell, and both materials show.
#[test]
fn each_cell_shades_as_its_material() {
    let tiles = checked("tiles", &TILES.replace("FLOOR", "tiles"));
    let shiny = checked("shiny", &TILES.replace("FLOOR", "shiny"));
    let matte = checked("matte", &TILES.replace("FLOOR", "matte"));
    let (a, b) = (
        render_everywhere("shiny", &shiny),
        render_everywhere("matte", &matte),
    );
    for (backend, image) in render_everywhere("tiles", &tiles) {
        let own = |r: &[(&str, Image)]| {
            r.iter()
                .find(|(n, _)| *n == backend)
                .map(|(_, i)| i.clone())
                .expect("the same backends")
        };
        let (a, b) = (own(&a), own(&b));
        let same = |p: [f32; 3], q: [f32; 3]| (0..3).all(|c| (p[c] - q[c]).abs() < 1e-5);
        let (mut as_a, mut as_b, mut floor) = (0, 0, 0);
        for y in 40..64 {
            for x in 0..96 {
                let (p, pa, pb) = (image.pixel(x, y), a.pixel(x, y), b.pixel(x, y));
                if same(pa, pb) {
                    continue; // the ball, the same in both
                }
                floor += 1;
                as_a += same(p, pa) as u32;
                as_b += same(p, pb) as u32;
            }
        }
        println!("{backend}: {as_a} pixels as shiny, {as_b} as matte of {floor}");
        assert!(
            (as_a + as_b) * 10 >= floor * 8,
            "{backend}: only {} of {floor} pixels are one material's",
            as_a + as_b
        );
        assert!(
            as_a * 5 >= floor && as_b * 5 >= floor,
            "{backend}: {as_a} and {as_b}"
        );
    }
}

/// Towards the horizon, at one sample a pixel, a checker of two materials that differ in
/// `ambient` alone (a pixel is its ambient term: linear in it, so the blend of parameters is
/// the filter's mean) is close to the picture of 12×12 samples a pixel, as a checker of two
/// colours is.
#[test]
fn two_materials_blend_over_the_pixels_footprint() {
    let text = "
material bright = phong { color: (1, 1, 1), ambient: 1, diffuse: 0, specular: 0 };
material dark = phong { color: (1, 1, 1), ambient: 0, diffuse: 0, specular: 0 };
material floor = checker { a: bright, b: dark, size: 0.5 };
";
    let (one, truth, horizon) = common::floor_to_the_horizon(text);
    for (backend, image) in render_everywhere("one sample", &one) {
        let mut sum = 0.0;
        for y in horizon + 1..horizon + 12 {
            for x in 0..one.settings.width {
                sum += (image.pixel(x, y)[0] - truth.pixel(x, y)[0]).abs() as f64;
            }
        }
        let error = sum / (11.0 * one.settings.width as f64);
        println!("{backend}: far rows differ by {error:.4} on average");
        assert!(error < 0.05, "{backend}: far rows differ by {error:.4}");
    }
}
