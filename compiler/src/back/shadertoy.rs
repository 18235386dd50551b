//! One GLSL ES page for Shadertoy (`sdfc compile --emit shadertoy`, docs/embedding.md): the
//! scene's distance function and material table ([`super::wgsl::part`], written by naga as
//! GLSL ES 3.00) and a `mainImage` that renders it with the scene's camera (its aspect taken
//! from the canvas), lights and materials: sphere tracing, tetrahedral normals, Phong with
//! point-light attenuation, hard or soft shadows, checker patterns, colour fields and the
//! glow of the marching steps as docs/rendering.md states them (the checker filtered over the
//! pixel's footprint; the march over-relaxed as the renderers' is, so that a glow sums the
//! same steps), for camera rays only. Reflection, refraction, transparency, antialiasing, sky
//! lights and the rest of the look (occlusion, fog, exposure and tone curves) are left out, so
//! a scene using them renders without them ([`left_out`] names those a scene uses, for the
//! warning `sdfc compile` prints).

use super::shader::{self, Error};
use super::wgsl::{self, float};
use crate::lower::Lowered;
use crate::scene::{look, Light, Scene};
use glam::DVec3;
use std::fmt::Write;

/// The name of the distance function in the page.
const NAME: &str = "sdfc_map";

/// The renderer, after the constants and the distance function.
const RENDERER: &str = r#"
// The distance along the ray to the first hit, or -1 (docs/rendering.md, "Marching"), with
// over-relaxation by SDFC_OMEGA; where the scene glows, glow gains e^(-|d|/G) at each
// evaluation (d = f/L there; docs/rendering.md, "The look"), as the renderers' march does.
float sdfc_march(vec3 o, vec3 d, inout float glow) {
    float t = 0.0;
    float omega = SDFC_OMEGA;
    float prev = 0.0;
    float stride = 0.0;
    for (int i = 0; i < SDFC_MAX_STEPS; i++) {
        vec3 p = o + d * t;
        float s = sdfc_map_distance(p) * SDFC_INV_L;
        if (s != s) break;
        float r = abs(s);
        if (SDFC_GLOWS) glow += exp(-r * SDFC_INV_GLOW);
        vec3 a = abs(p);
        float tol = max(SDFC_EPS * t, 8.0 * 1.1920929e-7 * max(a.x, max(a.y, a.z)));
        // A relaxed step whose spheres do not overlap is taken back, and ω drops to 1.
        bool fail = omega > 1.0 && r + prev < stride;
        if (fail) {
            stride = stride - omega * stride;
            omega = 1.0;
        } else {
            stride = s * omega;
        }
        prev = r;
        // A ray that starts inside a solid (or is stepped back to its start) has reached it.
        if (!fail && (r < tol || (t == 0.0 && s < -tol))) return t;
        bool gone = !fail && t + s > SDFC_MAX_DIST;
        t = max(t + stride, 0.0);
        if (gone) break;
    }
    return -1.0;
}

// The fraction of a light reaching o along d up to tmax; k > 0: soft, the least k·d/t
// searched for between the steps that bracket one (docs/rendering.md, "Shadows").
float sdfc_shadow(vec3 o, vec3 d, float tt, float tmax, float k) {
    float res = 1.0;
    float t = 0.0;
    float ta = 0.0, sa = 0.0, qa = 3.4e38, tm = 0.0, sm = 0.0, qm = 3.4e38;
    float ra = 0.0, rm = 0.0, rb = 0.0, rq = 0.0;
    int probes = 0;
    for (int i = 0; i < SDFC_MAX_STEPS; i++) {
        if (probes == 0 && t >= tmax) break;
        float s = sdfc_map_distance(o + d * t) * SDFC_INV_L;
        if (s < SDFC_EPS * (tt + t)) return 0.0;
        float q = (k > 0.0 && t > 0.0) ? k * s / t : 3.4e38;
        res = min(res, q);
        float next = t + s;
        if (probes > 0) {
            if (q < rq) {
                if (t < rm) rb = rm; else ra = rm;
                rm = t;
                rq = q;
            } else if (t < rm) ra = t; else rb = t;
            if (k * (rb - ra) <= SDFC_PENUMBRA_BRACKET * rm || probes >= SDFC_PENUMBRA_PROBES) {
                probes = 0;
                next = tm + sm;
            } else {
                probes++;
                next = rm - ra > rb - rm ? (ra + rm) * 0.5 : (rm + rb) * 0.5;
            }
        } else {
            float low = min(sa + sm - (tm - ta), sm + s - (t - tm)) * 0.5;
            if (qm < qa && q > qm && k * low < min(res, 1.0) * t && k * (t - ta) > SDFC_PENUMBRA_BRACKET * tm) {
                ra = ta; rm = tm; rb = t; rq = qm;
                probes = 1;
                next = rm - ra > rb - rm ? (ra + rm) * 0.5 : (rm + rb) * 0.5;
            }
            ta = tm; sa = sm; qa = qm;
            tm = t; sm = s; qm = q;
        }
        t = next;
    }
    return clamp(res, 0.0, 1.0);
}

// The checker filtered over the pixel's footprint (docs/rendering.md, "The look"): the mean
// of one axis's sign over [u - w/2, u + w/2] cells, and the second colour's weight at q for a
// footprint s cells wide seen along d on a surface of normal n.
float sdfc_checker_sign(float u, float w) {
    float c = floor(u);
    float cell = 1.0 - 2.0 * (c - 2.0 * floor(c * 0.5));
    if (w < SDFC_FOOTPRINT_MIN) return cell;
    float f = u - c;
    float x = (f - 0.5 * w) * 0.5;
    float y = (f + 0.5 * w) * 0.5;
    return cell * 2.0 * (abs(x - floor(x) - 0.5) - abs(y - floor(y) - 0.5)) / w;
}

float sdfc_checker_weight(vec3 q, vec3 n, vec3 d, float s) {
    float nd = dot(n, d);
    float c = max(abs(nd), SDFC_FOOTPRINT_COS);
    vec3 e = (d - n * nd) / c;
    vec3 w = s * sqrt(max(vec3(1.0) - n * n + e * e, vec3(0.0)));
    return 0.5 - 0.5 * sdfc_checker_sign(q.x, w.x) * sdfc_checker_sign(q.y, w.y) * sdfc_checker_sign(q.z, w.z);
}

// The second colour's weight of material m at p (0 for a plain colour); s: the footprint's
// width at the hit in scene units.
float sdfc_checker(sdfc_map_Material m, vec3 p, vec3 n, vec3 d, float s) {
    if (m.checker <= 0.0) return 0.0;
    return sdfc_checker_weight(p / m.checker + m.shift, n, d, s / m.checker);
}

// Phong for one light in direction l (towards it) with intensity il and attenuation atten.
vec3 sdfc_light(sdfc_map_Material m, vec3 c, vec3 p, vec3 n, vec3 v, float h, float tt,
                vec3 l, vec3 il, float atten, float tmax, float k) {
    float nl = dot(n, l);
    if (nl <= 0.0 || atten <= 0.0) return vec3(0.0);
    float sh = k < 0.0 ? 1.0 : sdfc_shadow(p + n * (4.0 * h), l, tt, tmax, k);
    vec3 r = 2.0 * nl * n - l;
    return sh * atten * (m.diffuse * nl * c * il + m.specular * pow(max(dot(r, v), 0.0), m.shininess) * il);
}

float sdfc_srgb(float c) {
    c = clamp(c, 0.0, 1.0);
    return c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

void mainImage(out vec4 fragColor, in vec2 fragCoord) {
    vec2 b = 2.0 * fragCoord / iResolution.xy - 1.0;
    float aspect = iResolution.x / iResolution.y;
    vec3 d = normalize(SDFC_CAM_W + b.x * SDFC_TAN * aspect * SDFC_CAM_U + b.y * SDFC_TAN * SDFC_CAM_V);
    vec3 col = SDFC_BACKGROUND;
    float glow = 0.0;
    float t = sdfc_march(SDFC_EYE, d, glow);
    if (t >= 0.0) {
        vec3 p = SDFC_EYE + d * t;
        vec3 a = abs(p);
        float h = max(SDFC_L * SDFC_EPS * t, 64.0 * 1.1920929e-7 * (1.0 + max(a.x, max(a.y, a.z))));
        vec3 k0 = vec3(1.0, -1.0, -1.0), k1 = vec3(-1.0, -1.0, 1.0), k2 = vec3(-1.0, 1.0, -1.0), k3 = vec3(1.0);
        vec3 g = k0 * sdfc_map_distance(p + h * k0) + k1 * sdfc_map_distance(p + h * k1)
               + k2 * sdfc_map_distance(p + h * k2) + k3 * sdfc_map_distance(p + h * k3);
        vec3 n = dot(g, g) > 0.0 ? normalize(g) : -d;
        int id = int(sdfc_map(p).y);
        sdfc_map_Material m = sdfc_map_MATERIALS[clamp(id, 0, int(sdfc_map_MATERIAL_COUNT) - 1)];
        float wb = sdfc_checker(m, p - n * (2.0 * h), n, d, t * 2.0 * SDFC_TAN / iResolution.y);
        vec3 c = mix(m.color, m.color_b, wb);
SDFC_FIELDS        vec3 v = -d;
        col = m.ambient * c;
SDFC_LIGHTS    }
    // The camera ray glows with its marching steps, on a surface or not.
    col += SDFC_GLOW_COLOR * glow;
    fragColor = vec4(sdfc_srgb(col.x), sdfc_srgb(col.y), sdfc_srgb(col.z), 1.0);
}
"#;

/// What `scene` asks for that the page does not render (the module's list), in words, for the
/// warning `sdfc compile --emit shadertoy` prints; empty where the page shows what the
/// renderers show.
pub fn left_out(scene: &Scene) -> Vec<&'static str> {
    let (m, s) = (&scene.materials, &scene.settings);
    let asked = [
        (m.iter().any(|m| m.reflect > 0.0), "reflection"),
        (
            m.iter().any(|m| m.transparency > 0.0),
            "refraction and transparency",
        ),
        (
            m.iter().any(|m| m.pbr.is_some()),
            "pbr materials (shaded as the nearest Phong)",
        ),
        (
            scene.lights.iter().any(|l| matches!(l, Light::Sky { .. })),
            "sky lights",
        ),
        (s.occlusion > 0.0, "occlusion"),
        (s.fog > 0.0, "fog"),
        (
            s.exposure != 0.0 || s.tonemap != look::Tonemap::None,
            "exposure and the tone curve",
        ),
        (s.aa > 1, "antialiasing"),
        (s.path, "path tracing (rendered by the Whitted model)"),
    ];
    asked
        .into_iter()
        .filter(|(used, _)| *used)
        .map(|(_, what)| what)
        .collect()
}

/// The page for `scene`, lowered as `lowered`.
pub fn write(scene: &Scene, lowered: &Lowered) -> Result<String, Error> {
    let part = wgsl::part::write(scene, lowered, NAME).map_err(|e| Error(e.to_string()))?;
    let functions = shader::write_part_es(&part)?;
    let cam = &scene.camera;
    let s = &scene.settings;
    let (w, u, v) = cam.basis();
    let l = lowered.program.lipschitz().max(1.0);
    let v3 = |x: [f64; 3]| format!("vec3({}, {}, {})", float(x[0]), float(x[1]), float(x[2]));
    let mut out = String::new();
    out.push_str(
        "// Generated by sdfc: a scene for Shadertoy (paste into a new shader's Image tab).\n\
         // Camera rays only: reflection, refraction, transparency and antialiasing are left out\n\
         // (docs/embedding.md). The canvas's aspect replaces the scene's image size.\n\n",
    );
    // The glow of the marching steps (`glow`, `glow_color`); none: no term at all.
    let glows = s.glows();
    let consts = [
        ("vec3", "EYE", v3(cam.position)),
        ("vec3", "CAM_W", v3(w)),
        ("vec3", "CAM_U", v3(u)),
        ("vec3", "CAM_V", v3(v)),
        ("float", "TAN", float((cam.fov * 0.5).tan())),
        ("float", "EPS", float(scene.epsilon())),
        ("float", "FOOTPRINT_MIN", float(look::FOOTPRINT_MIN)),
        ("float", "FOOTPRINT_COS", float(look::FOOTPRINT_COS)),
        ("float", "MAX_DIST", float(s.max_dist)),
        ("int", "MAX_STEPS", s.max_steps.max(1).to_string()),
        ("float", "L", float(l)),
        ("float", "INV_L", float(1.0 / l)),
        ("float", "PENUMBRA_BRACKET", float(Light::PENUMBRA_BRACKET)),
        ("int", "PENUMBRA_PROBES", Light::PENUMBRA_PROBES.to_string()),
        ("float", "OMEGA", float(s.relaxation.max(1.0))),
        ("bool", "GLOWS", glows.to_string()),
        (
            "float",
            "INV_GLOW",
            float(if glows { 1.0 / s.glow } else { 0.0 }),
        ),
        (
            "vec3",
            "GLOW_COLOR",
            v3(if glows { s.glow_color } else { [0.0; 3] }),
        ),
        ("vec3", "BACKGROUND", v3(s.background)),
    ];
    for (ty, name, value) in consts {
        let _ = writeln!(out, "const {ty} SDFC_{name} = {value};");
    }
    out.push('\n');
    out.push_str(&functions);
    let mut lights = String::new();
    for light in &scene.lights {
        // k < 0: a light without shadows.
        let k = float(if light.shadows() {
            light.sharpness()
        } else {
            -1.0
        });
        match light {
            Light::Point {
                position,
                color,
                intensity,
                radius,
                ..
            } => {
                let il = v3((DVec3::from(*color) * *intensity).into());
                let r = if radius.is_finite() { *radius } else { 0.0 };
                let _ = writeln!(
                    lights,
                    "        {{\n            vec3 to = {} - p;\n            float dist = length(to);\n            \
                     float q = {r} > 0.0 ? clamp(1.0 - (dist / {r}) * (dist / {r}), 0.0, 1.0) : 1.0;\n            \
                     col += sdfc_light(m, c, p, n, v, h, t, to / dist, {il}, q * q, dist - 4.0 * h, {k});\n        }}",
                    v3(*position),
                    r = float(r),
                );
            }
            Light::Directional {
                direction,
                color,
                intensity,
                ..
            } => {
                let il = v3((DVec3::from(*color) * *intensity).into());
                let to: [f64; 3] = (-DVec3::from(*direction)).normalize_or_zero().into();
                let _ = writeln!(
                    lights,
                    "        col += sdfc_light(m, c, p, n, v, h, t, {}, {il}, 1.0, SDFC_MAX_DIST, {k});",
                    v3(to)
                );
            }
            // Left out, as the module says.
            Light::Sky { .. } => {}
        }
    }
    // Colour fields: the material's colour at p (a checker's cell found as `sdfc_colour`
    // finds it).
    let mut fields = String::new();
    for (id, slots) in lowered.colours.fields.iter().enumerate() {
        let call = |k: Option<usize>, constant: &str| match k {
            Some(k) => format!("{NAME}_colour_field({k}u, p, n)"),
            None => constant.to_string(),
        };
        match slots {
            [None, None] => {}
            [a, None] if scene.materials[id].pattern.colours().len() == 1 => {
                let _ = writeln!(fields, "        if (id == {id}) c = {};", call(*a, "c"));
            }
            [a, b] => {
                let _ = writeln!(
                    fields,
                    "        if (id == {id}) c = mix({}, {}, wb);",
                    call(*a, "m.color"),
                    call(*b, "m.color_b")
                );
            }
        }
    }
    out.push_str(
        &RENDERER
            .replace("SDFC_LIGHTS", &lights)
            .replace("SDFC_FIELDS", &fields),
    );
    Ok(out)
}
