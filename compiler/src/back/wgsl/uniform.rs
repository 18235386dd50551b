//! The bytes of the scene uniform `Params` (binding 0) that a render uploads: every member the
//! template declares, written by name at the offsets naga laid it out at ([`Uniform`]):
//! camera, settings, the look, lights (skies' irradiance coefficients computed here once, in
//! f64), materials and the sRGB thresholds.

use super::contract::{Mismatch, Uniform, UniformWriter};
use super::srgb;
use crate::scene::{Colour, Light, Pattern, Scene};
use glam::DVec3;

/// The bytes of the scene uniform (binding 0) of a kernel whose uniform is laid out as
/// `layout` ([`Contract::uniform`], naga's layout of `Params`), each member written by name at
/// naga's offset. `Err` when a member named here is missing from the layout or of another
/// type, when the scene has more lights or materials than the kernel's arrays hold, or when a
/// member of the layout is written by nothing (the kernel is another scene's, or this writer
/// lags the template).
pub fn uniforms(layout: &Uniform, scene: &Scene, lipschitz: f64) -> Result<Vec<u8>, Mismatch> {
    let mut w = layout.writer();
    view(&mut w, scene, lipschitz)?;
    lights(&mut w, scene)?;
    materials(&mut w, scene)?;
    for (k, t) in srgb::thresholds().chunks_exact(4).enumerate() {
        let t: Vec<f64> = t.iter().map(|&x| f64::from(x)).collect();
        w.floats(&format!("srgb[{k}]"), &t)?;
    }
    w.finish()
}

/// A vec3 and a w.
fn v4(v: [f64; 3], w: f64) -> [f64; 4] {
    [v[0], v[1], v[2], w]
}

/// The camera, the march, the look, the counts, the glow and the background.
fn view(w: &mut UniformWriter, scene: &Scene, lipschitz: f64) -> Result<(), Mismatch> {
    let cam = &scene.camera;
    let s = &scene.settings;
    let (fwd, u, v) = cam.basis();
    let tan = (cam.fov * 0.5).tan();
    let aspect = s.width.max(1) as f64 / s.height.max(1) as f64;
    w.floats("eye", &v4(cam.position, 0.0))?;
    w.floats("cam_w", &v4(fwd, 0.0))?;
    w.floats("cam_u", &v4(u, 0.0))?;
    w.floats("cam_v", &v4(v, 0.0))?;
    w.floats(
        "view",
        &[tan * aspect, tan, s.width as f64, s.height as f64],
    )?;
    w.floats(
        "march",
        &[
            scene.epsilon(),
            s.max_dist,
            s.relaxation.max(1.0),
            1.0 / lipschitz.max(1.0),
        ],
    )?;
    let inv_fog = if s.fog > 0.0 { 1.0 / s.fog } else { 0.0 };
    w.floats(
        "look",
        &[
            s.occlusion,
            inv_fog,
            s.exposure.exp2(),
            s.tonemap.index() as f64,
        ],
    )?;
    // w: 1 where `fog_color` is given; else the fog is the background seen along the ray.
    w.floats(
        "fog",
        &v4(
            s.fog_colour(),
            if s.fog_color.is_some() { 1.0 } else { 0.0 },
        ),
    )?;
    // The path tracer's samples spread over the whole pixel: its checker's footprint is the
    // pixel's (aa counts as 1).
    let aa = if s.path { 1 } else { s.aa.max(1) };
    w.uints("counts", &[s.width, s.height, aa, s.max_steps.max(1)])?;
    w.uints(
        "depth",
        &[s.max_depth, s.samples.max(1), s.bounces, s.first_sample],
    )?;
    // The kernels of the feature GLOW have it: the glow's colour, 1/G.
    if s.glows() {
        w.floats("glow", &v4(s.glow_color, 1.0 / s.glow))?;
    }
    // Whether a sky is the background (`background.w`): rays that hit nothing show the skies
    // that are.
    let sky_background = scene.lights.iter().any(|l| {
        matches!(
            l,
            Light::Sky {
                background: true,
                ..
            }
        )
    });
    w.floats(
        "background",
        &v4(s.background, if sky_background { 1.0 } else { 0.0 }),
    )
}

/// The lights: point, directional and sky lights in their arrays, in the scene's order.
fn lights(w: &mut UniformWriter, scene: &Scene) -> Result<(), Mismatch> {
    let (mut points, mut dirs, mut skies) = (0, 0, 0);
    for l in &scene.lights {
        // w: the shadows' sharpness k (0: hard), or −1 for a light without shadows.
        let k = if l.shadows() { l.sharpness() } else { -1.0 };
        let colour = |c: [f64; 3], i: f64| v4((DVec3::from(c) * i).into(), k);
        match l {
            Light::Point {
                position,
                color,
                intensity,
                radius,
                ..
            } => {
                let r = if radius.is_finite() { *radius } else { 0.0 };
                w.floats(&format!("points[{points}].position"), &v4(*position, r))?;
                w.floats(
                    &format!("points[{points}].color"),
                    &colour(*color, *intensity),
                )?;
                points += 1;
            }
            Light::Directional {
                direction,
                color,
                intensity,
                penumbra,
                ..
            } => {
                let to = (-DVec3::from(*direction)).normalize_or_zero().into();
                // w: the cosine of half the penumbra angle (the path tracer's disc).
                w.floats(
                    &format!("dirs[{dirs}].to_light"),
                    &v4(to, (penumbra * 0.5).cos()),
                )?;
                w.floats(&format!("dirs[{dirs}].color"), &colour(*color, *intensity))?;
                dirs += 1;
            }
            Light::Sky {
                zenith,
                horizon,
                ground,
                intensity,
                shadows,
                background,
            } => {
                let c = crate::scene::look::sky_irradiance(*zenith, *horizon, *ground);
                let at = |name: &str| format!("skies[{skies}].{name}");
                let flag = |on: bool| if on { 1.0 } else { 0.0 };
                let scaled = |c: [f64; 3]| -> [f64; 3] { (DVec3::from(c) * *intensity).into() };
                w.floats(&at("c0"), &v4(scaled(c[0]), flag(*shadows)))?;
                w.floats(&at("c1"), &v4(scaled(c[1]), 0.0))?;
                w.floats(&at("c2"), &v4(scaled(c[2]), 0.0))?;
                w.floats(&at("zenith"), &v4(scaled(*zenith), flag(*background)))?;
                w.floats(&at("horizon"), &v4(scaled(*horizon), 0.0))?;
                w.floats(&at("ground"), &v4(scaled(*ground), 0.0))?;
                skies += 1;
            }
        }
    }
    Ok(())
}

/// The materials: colours or checkers, Phong's terms, optics, colour fields, and the Fresnel
/// and physically based members of the kernels that have them.
fn materials(w: &mut UniformWriter, scene: &Scene) -> Result<(), Mismatch> {
    let colours = crate::lower::Colours::numbers(scene);
    for (k, m) in scene.materials.iter().enumerate() {
        // A colour field's colour is its program's (the constant is unused).
        let v = |c: &Colour| c.constant().unwrap_or([0.0; 3]);
        let (a, b, checker, inv, shift) = match &m.pattern {
            Pattern::Solid(c) => (v(c), [0.0; 3], 0.0, 0.0, [0.0; 3]),
            Pattern::Checker { a, b, size } => {
                (v(a), v(b), 1.0, 1.0 / size, scene.checker_shift(*size))
            }
            // A checker of two materials: their ids in `color`, whose w is 2
            // (`checkered` in shading.wgsl).
            Pattern::Materials { a, b, size } => (
                [a.0 as f64, b.0 as f64, 0.0],
                [0.0; 3],
                2.0,
                1.0 / size,
                scene.checker_shift(*size),
            ),
        };
        // The colour fields' numbers, plus 1 (0: none).
        let field = |slot: usize| {
            colours
                .get(k)
                .and_then(|f| f[slot])
                .map_or(0.0, |i| i as f64 + 1.0)
        };
        let at = |member: &str| format!("materials[{k}].{member}");
        w.floats(&at("color"), &v4(a, checker))?;
        w.floats(&at("color_b"), &v4(b, inv))?;
        w.floats(
            &at("phong"),
            &[m.ambient, m.diffuse, m.specular, m.shininess],
        )?;
        w.floats(
            &at("optics"),
            &[m.reflect, m.transparency, m.ior.max(1e-6), field(0)],
        )?;
        w.floats(&at("shift"), &v4(shift, field(1)))?;
        // The members of the kernels that have them (the scene's features FRESNEL and PBR).
        if scene.materials.iter().any(|m| m.fresnel) {
            let flag = |on: bool| if on { 1.0 } else { 0.0 };
            w.floats(
                &at("fresnel"),
                &[
                    crate::scene::pbr::f0(m.ior),
                    flag(m.fresnel && m.pbr.is_none()),
                    flag(m.pbr.is_some()),
                    0.0,
                ],
            )?;
        }
        if scene.materials.iter().any(|m| m.pbr.is_some()) {
            let p = m.pbr.unwrap_or(crate::scene::Pbr {
                roughness: 1.0,
                metallic: 0.0,
                emission: [0.0; 3],
                transmission: 0.0,
            });
            w.floats(
                &at("pbr"),
                &[p.roughness, p.alpha(), p.metallic, p.mirror()],
            )?;
            w.floats(&at("emission"), &v4(p.emission, 0.0))?;
        }
    }
    Ok(())
}
