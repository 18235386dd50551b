//! The physically based material (docs/rendering.md, "Physically based materials") on every
//! backend: the white furnace, a GGX highlight against the f64 formula as the roughness
//! changes, and Fresnel's brighter reflection at grazing angles.

use crate::common;

use common::{checked, render_everywhere};
use sdfc_compiler::Scene;

/// A sphere of the material `MAT` under a sky of radiance 1 all round, which is also the
/// background (so that the rays the sphere reflects see it), without occlusion.
const FURNACE: &str = "
material m = MAT;
camera { position: (0, 2, -4), look_at: (0, 0, 0), fov: 40deg }
light sky { color: (1, 1, 1) }
render { width: 40, height: 40, tonemap: \"none\" }
scene { sphere(1) @ m; }
";

/// The white furnace: a white diffuse `pbr` sphere (metallic 0, base colour 1) under a
/// uniform sky of 1 is 1 wherever it is seen, whatever its roughness (what its specular lobe
/// reflects, its diffuse part does not); a rough white metal is not above 1 and loses some
/// (the single-scattering lobe's energy), a mirror metal none. A grey sphere shows where the
/// sphere is.
/// The scene [`FURNACE`] with the material `material`, checked (the file `name`).
fn furnace(name: &str, material: &str) -> sdfc_compiler::Scene {
    checked(name, &FURNACE.replace("MAT", material))
}

#[test]
fn the_white_furnace_holds_for_pbr() {
    let grey = furnace("grey", "pbr { base_color: (0.5, 0.5, 0.5) }");
    let mut on_sphere = Vec::new();
    for (backend, image) in render_everywhere("grey", &grey) {
        let dark: Vec<(u32, u32)> = (0..40)
            .flat_map(|y| (0..40).map(move |x| (x, y)))
            .filter(|&(x, y)| image.pixel(x, y)[0] < 0.9)
            .collect();
        assert!(
            dark.len() > 300,
            "{backend}: the sphere covers {}",
            dark.len()
        );
        on_sphere = dark;
    }
    for roughness in [0.0, 0.3, 0.5, 1.0] {
        let white = furnace(
            "white",
            &format!("pbr {{ base_color: (1, 1, 1), roughness: {roughness} }}"),
        );
        for (backend, image) in render_everywhere("white furnace", &white) {
            let what = format!("{backend}: roughness {roughness}");
            common::assert_white(&image, 40, 2e-4, &what);
        }
    }
    for (roughness, least) in [(0.0, 0.999), (0.5, 0.6), (1.0, 0.35)] {
        let metal = furnace(
            "metal",
            &format!("pbr {{ base_color: (1, 1, 1), metallic: 1, roughness: {roughness} }}"),
        );
        for (backend, image) in render_everywhere("metal furnace", &metal) {
            let mut sum = 0.0;
            for &(x, y) in &on_sphere {
                let v = image.pixel(x, y)[1];
                assert!(
                    v <= 1.0 + 2e-4,
                    "{backend}: metal {roughness}: ({x}, {y}) is {v}"
                );
                sum += v as f64;
            }
            let mean = sum / on_sphere.len() as f64;
            println!("{backend}: metal of roughness {roughness}: mean {mean:.4}");
            assert!(mean >= least, "{backend}: metal {roughness}: mean {mean}");
            if roughness > 0.0 {
                assert!(
                    mean < 0.995,
                    "{backend}: metal {roughness} loses no energy: {mean}"
                );
            }
        }
    }
}

/// A grey `pbr` floor seen straight down from height 4, lit by a light straight above
/// (no shadows, no sky, a black background): a pixel is the formula's
/// `(k_d·(1 − F)·C + π·D·Vis·F)·(N·L)`, here written out in f64.
const FLOOR: &str = "
material m = pbr { base_color: (0.5, 0.5, 0.5), roughness: ROUGH };
camera { position: (0, 4, 0), look_at: (0, 0, 0), up: (0, 0, 1), fov: 30deg }
light directional { direction: (0, -1, 0), shadows: false }
render { width: 41, height: 41, background: (0, 0, 0), tonemap: \"none\" }
scene { plane() @ m; }
";

/// The f64 value of pixel column `x` of [`FLOOR`]'s middle row at `roughness`.
fn floor_pixel(scene: &Scene, x: u32, roughness: f64) -> f64 {
    let pi = std::f64::consts::PI;
    let w = scene.settings.width as f64;
    let tan = (scene.camera.fov * 0.5).tan();
    let bx = 2.0 * (x as f64 + 0.5) / w - 1.0;
    // The camera looks down −y with +z up in the image and −x to its right (u = (−1, 0, 0)).
    let d = [-bx * tan, -1.0, 0.0];
    let len = (d[0] * d[0] + d[1] * d[1]).sqrt();
    let v = [-d[0] / len, -d[1] / len, 0.0];
    // N = L = (0, 1, 0).
    let (nl, nv) = (1.0, v[1]);
    let hl = ((v[0]).powi(2) + (v[1] + 1.0).powi(2)).sqrt();
    let (nh, vh) = ((v[1] + 1.0) / hl, (v[0] * v[0] + v[1] * (v[1] + 1.0)) / hl);
    let a = (roughness * roughness).max(0.002);
    let a2 = a * a;
    let dist = a2 / (pi * (nh * nh * (a2 - 1.0) + 1.0).powi(2));
    let vis =
        0.5 / (nl * (nv * nv * (1.0 - a2) + a2).sqrt() + nv * (nl * nl * (1.0 - a2) + a2).sqrt());
    let f0 = 0.04;
    let f = f0 + (1.0 - f0) * (1.0 - vh).powi(5);
    ((1.0 - f) * 0.5 + pi * dist * vis * f) * nl
}

/// A GGX highlight's peak and width follow the formula as the roughness changes: every pixel
/// of the middle row is the f64 formula's, and a rougher floor's highlight is lower and
/// wider.
#[test]
fn a_ggx_highlight_follows_the_formula_as_the_roughness_changes() {
    let mut shapes = Vec::new();
    for roughness in [0.15, 0.3, 0.6] {
        let scene = checked("floor", &FLOOR.replace("ROUGH", &roughness.to_string()));
        let expected: Vec<f64> = (0..41).map(|x| floor_pixel(&scene, x, roughness)).collect();
        let peak = expected[20];
        let half = (expected[0] + peak) / 2.0;
        let width = expected.iter().filter(|&&e| e > half).count();
        for (backend, image) in render_everywhere("floor", &scene) {
            for (x, e) in expected.iter().enumerate() {
                let got = image.pixel(x as u32, 20)[0] as f64;
                assert!(
                    (got - e).abs() < 2e-3 * e.max(1.0),
                    "{backend}: roughness {roughness}: pixel {x} is {got:.5}, the formula {e:.5}"
                );
            }
        }
        println!("roughness {roughness}: peak {peak:.4}, {width} pixels above half");
        shapes.push((peak, width));
    }
    assert!(
        shapes[0].0 > shapes[1].0 && shapes[1].0 > shapes[2].0,
        "{shapes:?}"
    );
    assert!(
        shapes[0].1 < shapes[1].1 && shapes[1].1 < shapes[2].1,
        "{shapes:?}"
    );
}

/// Fresnel: a black smooth dielectric floor under a uniform sky of 1 reflects only the sky,
/// about 4 % of it seen from above and more towards grazing: the rows nearer the horizon
/// are brighter, on every backend.
#[test]
fn fresnel_brightens_a_pbr_floor_at_grazing_angles() {
    let scene = checked(
        "black floor",
        "
material m = pbr { base_color: (0, 0, 0), roughness: 0 };
camera { position: (0, 1, -4), look_at: (0, 0, 4), fov: 60deg }
light sky { color: (1, 1, 1) }
render { width: 16, height: 64, max_dist: 1000, tonemap: \"none\" }
scene { plane() @ m; }
",
    );
    for (backend, image) in render_everywhere("black floor", &scene) {
        let column: Vec<f32> = (0..64).map(|y| image.pixel(8, y)[0]).collect();
        let floor: Vec<f32> = column.iter().copied().filter(|&v| v < 0.999).collect();
        assert!(floor.len() > 30, "{backend}: {column:?}");
        // From the nearest row (the last) up towards the horizon: brighter and brighter.
        let near = *column.last().unwrap();
        brightens_towards_the_horizon(backend, (&floor, near), (0.035, 0.08), 0.3);
    }
}

/// Fails unless the `floor` rows of a column (from the horizon down) brighten towards the
/// horizon on `backend`: the nearest row's value `near` within `nearest` (open), every row at
/// least the one below it, and the row at the horizon above `horizon`.
#[track_caller]
fn brightens_towards_the_horizon(
    backend: &str,
    (floor, near): (&[f32], f32),
    nearest: (f32, f32),
    horizon: f32,
) {
    assert!(
        near > nearest.0 && near < nearest.1,
        "{backend}: the nearest row is {near}"
    );
    for w in floor.windows(2) {
        assert!(w[0] >= w[1] - 1e-6, "{backend}: {floor:?}");
    }
    assert!(
        floor[0] > horizon,
        "{backend}: towards the horizon {}",
        floor[0]
    );
}

/// A black floor of `MAT` under a uniform sky of 1 that is also the background, seen from a
/// little above: the column of pixel values from the horizon (row 0 of the floor) down.
fn floor_column(name: &str, material: &str) -> Vec<(&'static str, Vec<f32>)> {
    let scene = checked(
        name,
        &format!(
            "
material m = {material};
camera {{ position: (0, 1, -4), look_at: (0, 0, 4), fov: 60deg }}
light sky {{ color: (1, 1, 1) }}
render {{ width: 16, height: 64, max_dist: 1000, tonemap: \"none\" }}
scene {{ plane() @ m; }}
"
        ),
    );
    render_everywhere(name, &scene)
        .into_iter()
        .map(|(backend, image)| {
            let column: Vec<f32> = (0..64)
                .map(|y| image.pixel(8, y)[0])
                .filter(|&v| v < 0.999)
                .collect();
            (backend, column)
        })
        .collect()
}

/// `fresnel: true` on a Phong material: a black floor reflecting 10 % (`reflect: 0.1`)
/// reflects more of the sky towards the horizon, as `fresnel_weights` says
/// (r' = r + w·(1 − |N·V|)⁵, with the local colour black); without it every row reflects
/// 10 %, as before.
#[test]
fn fresnel_on_phong_brightens_grazing_angles_and_is_off_by_default() {
    let lit =
        "phong { color: (0, 0, 0), ambient: 0, diffuse: 0, specular: 0, reflect: 0.1 FRESNEL }";
    for (backend, column) in floor_column("plain", &lit.replace("FRESNEL", "")) {
        assert!(column.len() > 30, "{backend}: {column:?}");
        for v in &column {
            assert!((v - 0.1).abs() < 1e-5, "{backend}: {column:?}");
        }
    }
    for (backend, column) in floor_column("fresnel", &lit.replace("FRESNEL", ", fresnel: true")) {
        assert!(column.len() > 30, "{backend}: {column:?}");
        let near = *column.last().unwrap();
        // The nearest row: N·V ≈ sin 37°, s = (1 − 0.6)⁵ ≈ 0.01.
        brightens_towards_the_horizon(backend, (&column, near), (0.1, 0.13), 0.5);
    }
}
