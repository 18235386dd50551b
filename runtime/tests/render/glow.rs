//! The glow of the marching steps (docs/rendering.md, "The look"), on every backend: a camera
//! ray that misses a sphere glows by the documented sum over its march's evaluations.

use crate::common;

use common::{checked, render_everywhere};
use sdfc_compiler::Scene;

/// A unit sphere seen from (0, 0, −5) on black, no lights, no relaxation (a step is the
/// distance): the glow of G and colour (0.01, 0.02, 0.04).
const BLOB: &str = "
camera { position: (0, 0, -5), look_at: (0, 0, 0), fov: 40deg }
render { width: 64, height: 48, background: (0, 0, 0), relaxation: 1, max_dist: 20 GLOW }
scene { sphere(1); }
";

/// The glow the documentation gives for the camera ray of pixel (x, y) that misses the
/// sphere: Σ e^(−dᵢ/G) over the march t ← t + dᵢ, dᵢ = |o + t·D| − 1, until t passes
/// max_dist (in f64).
fn expected(scene: &Scene, x: u32, y: u32, g: f64) -> Option<f64> {
    let (w, h) = (scene.settings.width as f64, scene.settings.height as f64);
    let tan = (scene.camera.fov * 0.5).tan();
    let (bx, by) = (
        2.0 * (x as f64 + 0.5) / w - 1.0,
        1.0 - 2.0 * (y as f64 + 0.5) / h,
    );
    // w = +z, u = −x, v = +y for this camera.
    let d = [-bx * tan * w / h, by * tan, 1.0];
    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let d = d.map(|c| c / len);
    let (mut t, mut sum) = (0.0, 0.0);
    for _ in 0..scene.settings.max_steps {
        let p = [d[0] * t, d[1] * t, -5.0 + d[2] * t];
        let f = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - 1.0;
        sum += (-f.abs() / g).exp();
        if f < 1e-3 {
            return None; // near or on the sphere: not a clean miss
        }
        if t + f > scene.settings.max_dist {
            return Some(sum);
        }
        t += f;
    }
    None
}

/// Pixels whose rays miss the sphere are the documented glow (to 0.5 %), brighter near the
/// sphere's outline than in the corners; without `glow` they are black; every backend agrees.
#[test]
fn a_missing_ray_glows_by_the_sum_over_its_steps() {
    let g = 0.3;
    let colour = [0.01, 0.02, 0.04];
    let scene = checked(
        "glow",
        &BLOB.replace(
            "GLOW",
            &format!(
                ", glow: {g}, glow_color: ({}, {}, {})",
                colour[0], colour[1], colour[2]
            ),
        ),
    );
    let plain = checked("no glow", &BLOB.replace("GLOW", ""));
    for (backend, image) in render_everywhere("no glow", &plain) {
        assert_eq!(image.pixel(0, 0), [0.0; 3], "{backend}");
    }
    for (backend, image) in render_everywhere("glow", &scene) {
        let (mut checked_px, mut brightest, mut corner) = (0, 0.0f64, f64::MAX);
        let y = scene.settings.height / 2;
        for x in 0..scene.settings.width {
            let Some(sum) = expected(&scene, x, y, g) else {
                continue;
            };
            let got = image.pixel(x, y);
            for c in 0..3 {
                let want = colour[c] * sum;
                assert!(
                    (got[c] as f64 - want).abs() <= 0.005 * want + 1e-6,
                    "{backend}: pixel ({x}, {y}) channel {c}: {} against {want}",
                    got[c]
                );
            }
            brightest = brightest.max(got[2] as f64);
            corner = corner.min(got[2] as f64);
            checked_px += 1;
        }
        println!("{backend}: {checked_px} pixels, glow from {corner:.4} to {brightest:.4}");
        assert!(checked_px >= 20, "{backend}: {checked_px} missing pixels");
        assert!(
            brightest > 2.0 * corner,
            "{backend}: {corner} to {brightest}"
        );
    }
}
