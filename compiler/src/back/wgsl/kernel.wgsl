//% sdfc renderer kernel template: docs/rendering.md as a WGSL compute shader, one invocation per
//% pixel. `//#if FEATURE` blocks are kept only when the scene uses the feature, a
//% double-brace placeholder is replaced by a value, and `//%` lines (these) are dropped (see
//% template.rs). The CPU renderer (runtime/src/cpu) implements the same algorithm;
//% docs/rendering.md fixes the constants.
{{HEADER}}

//#if POINT
struct PointLight {
    position: vec4<f32>, // xyz, w: radius (0: no falloff)
    color: vec4<f32>,    // rgb = colour × intensity, w: softness k (0: hard shadows)
}
//#endif
//#if DIRECTIONAL
struct DirLight {
    to_light: vec4<f32>, // unit vector towards the light
    color: vec4<f32>,    // rgb = colour × intensity, w: softness k
}
//#endif
//#if SKY
struct SkyLight {
    c0: vec4<f32>,      // irradiance over π: c0 + c1·N_y + c2·(3N_y² − 1), times the intensity;
    c1: vec4<f32>,      // c0.w: 1 when the occlusion scales it
    c2: vec4<f32>,
    zenith: vec4<f32>,  // radiance, times the intensity; w: 1 when it is the background
    horizon: vec4<f32>,
    ground: vec4<f32>,
}
//#endif
struct Material {
    color: vec4<f32>,   // rgb, w: 1 for a checker pattern
    color_b: vec4<f32>, // checker's second colour, w: 1 / checker size
    phong: vec4<f32>,   // ambient, diffuse, specular, shininess
    optics: vec4<f32>,  // reflect, transparency, ior, colour field of color (k + 1; 0: none)
    shift: vec4<f32>,   // checker: the pattern's offset at the scene's origin, in cells; w: colour field of color_b
//#if FRESNEL
    fresnel: vec4<f32>, // F0 of a dielectric of its ior, 1 for Phong with Fresnel, 1 for pbr
//#endif
//#if PBR
    pbr: vec4<f32>,      // roughness, GGX α, metallic, mirror weight g = (1 − roughness)²
    emission: vec4<f32>, // rgb
//#endif
}
struct Params {
    eye: vec4<f32>,        // camera position
    cam_w: vec4<f32>,      // forward
    cam_u: vec4<f32>,      // right
    cam_v: vec4<f32>,      // up
    view: vec4<f32>,       // tan(fov/2)·aspect, tan(fov/2), width, height
    march: vec4<f32>,      // epsilon, max_dist, relaxation ω, 1/L
    // background.w: 1 when rays that hit nothing show the skies instead.
    background: vec4<f32>,
    look: vec4<f32>,       // occlusion radius R, 1/fog distance, 2^exposure, tone curve
    fog: vec4<f32>,        // the fog's colour; w: 0 where it is the background seen along the ray
    counts: vec4<u32>,     // width, height, aa, max_steps
    //% depth.yzw: the path tracer's samples, bounces and first sample (path.wgsl).
    depth: vec4<u32>,      // max_depth
//#if GLOW
    glow: vec4<f32>,       // the glow's colour, 1/G
//#endif
//#if POINT
    points: array<PointLight, {{POINTS}}>,
//#endif
//#if DIRECTIONAL
    dirs: array<DirLight, {{DIRS}}>,
//#endif
//#if SKY
    skies: array<SkyLight, {{SKIES}}>,
//#endif
    materials: array<Material, {{MATERIALS}}>,
    srgb: array<vec4<f32>, 64>, // the least linear value of each 8-bit sRGB code (srgb.rs)
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<uniform> tile: vec4<u32>; // x0, y0, width, height
@group(0) @binding(2) var<storage, read_write> image: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> stats: array<u32>;
// The finished pixels: RGBA8, sRGB-encoded, red in the low byte.
@group(0) @binding(5) var<storage, read_write> pixels: array<u32>;
//#if SCENE_DATA
// The primitives and hierarchy of a large analytically traced scene, the instances of a large
// marched one (layouts: compiler/src/back/wgsl/buffer.rs, march.rs), or the constants of the
// distance program of a kernel shared by the frames of an animation (map.rs, `Params`).
@group(0) @binding(4) var<storage, read> scene_data: array<vec4<f32>>;
//#endif

// Per-pixel statistics, written to `stats` (8 words per pixel).
struct Counters {
    steps: u32,
    hits: u32,
    misses: u32,
    budget: u32,
    overshoots: u32,
    nans: u32,
    secondary: u32,
    shadow: u32,
    // Marching loops a software adapter ended early (docs/rendering.md, "Software
    // adapters"): never on a GPU.
    cut: u32,
}
var<private> counters: Counters;

const STATUS_HIT: u32 = 0u;
const STATUS_MISS: u32 = 1u;
const STATUS_BUDGET: u32 = 2u;
const STATUS_NAN: u32 = 3u;
// The tetrahedron's corners for the 4-tap gradient.
const TETRA = array<vec3<f32>, 4>(vec3<f32>(1.0, -1.0, -1.0), vec3<f32>(-1.0, -1.0, 1.0), vec3<f32>(-1.0, 1.0, -1.0), vec3<f32>(1.0, 1.0, 1.0));

{{MAP}}

fn is_nan(x: f32) -> bool {
    // NaN is the only value not equal to itself; the bit test keeps drivers from folding it.
    let b = bitcast<u32>(x);
    return (b & 0x7f800000u) == 0x7f800000u && (b & 0x007fffffu) != 0u;
}

struct Traced {
    t: f32,
    status: u32,
//#if ANALYTIC
    normal: vec3<f32>, // unit outward normal at the hit
    material: u32,
    limit: f32, // t, plus the slack of `nearest` for a surface of glass seen from inside
//#endif
}

//#if ANALYTIC
// Analytic ray tracing (docs/rendering.md, "Analytic ray tracing"). Every primitive is convex (a plane
// bounds a half-space), so a ray meets it in one interval [near, far], near > far for a miss,
// with the outward normals in the primitive's frame at both ends. BIG stands for infinity.
const BIG: f32 = 3.0e38;
struct Interval {
    near: f32,
    far: f32,
    n_near: vec3<f32>,
    n_far: vec3<f32>,
}

fn missed() -> Interval {
    return Interval(BIG, -BIG, vec3<f32>(0.0), vec3<f32>(0.0));
}

// The nearer of best and the first end of s beyond the ray's origin, by their distances with
// `slack` added (to a transparent surface's inside glass, so that an opaque surface that
// coincides with the glass's far side is the one met).
fn nearest(best: Traced, s: Interval, material: u32, slack: f32) -> Traced {
    if !(s.near <= s.far) {
        return best;
    }
    var t = s.far;
    var n = s.n_far;
    if s.near > 0.0 {
        t = s.near;
        n = s.n_near;
    }
    let limit = t + slack;
    if t > 0.0 && limit < best.limit {
        return Traced(t, STATUS_HIT, normalize(n), material, limit);
    }
    return best;
}

// A shadow ray's light after one primitive: blocked by an opaque one in (0, tmax), reduced
// by the transparency of a transparent one whose surface it crosses (one it enters, or the
// glass it starts inside of, from an opaque surface within it).
fn occlude(through: f32, s: Interval, tmax: f32, tau: f32) -> f32 {
    if !(s.near <= s.far) || s.far <= 0.0 || s.near >= tmax {
        return through;
    }
//#if PATH
    // The path tracer's shadow rays are stopped by every surface.
    return 0.0;
//#endif
    if tau <= 0.0 {
        return 0.0;
    }
    return through * tau;
}

{{ANALYTIC}}
//#else
//#if GLOW
// The glow of the last march: Σ e^(−|dᵢ|/G) over its evaluations (docs/rendering.md, "The look").
var<private> glow: f32;
//#endif
// Sphere tracing (docs/rendering.md, "Marching"), with over-relaxation when ω > 1.
fn trace(o: vec3<f32>, d: vec3<f32>, t0: f32, sign: f32) -> Traced {
//#if GLOW
    glow = 0.0;
//#endif
    let eps = params.march.x;
    let max_dist = params.march.y;
    let inv_l = params.march.w;
    var t = 0.0;
    var steps = 0u;
//#if RELAX
    var omega = params.march.z;
    var prev = 0.0;
    var step = 0.0;
//#endif
    loop {
        let p = o + d * t;
//#if MEDIA
        // Inside glass (sign < 0) the ray marches the medium: glass less the solids in it.
        var f: f32;
        if sign < 0.0 {
            f = sdf_medium(p);
        } else {
            f = sdf(p);
        }
//#else
        let f = sdf(p);
//#endif
        steps += 1u;
        counters.steps += 1u;
        if is_nan(f) {
            counters.nans += 1u;
            return Traced(t, STATUS_NAN);
        }
        let signed = sign * f * inv_l;
        let r = abs(signed);
//#if GLOW
        glow += exp(-r * params.glow.w);
//#endif
        let tol = tolerance(eps * (t0 + t), p);
        if signed < -tol {
            counters.overshoots += 1u;
        }
//#if RELAX
        let fail = omega > 1.0 && r + prev < step;
        if fail {
            step = step - omega * step;
            omega = 1.0;
        } else {
            step = signed * omega;
        }
        prev = r;
        // Inside a solid at t = 0: reached there (docs/rendering.md, "Marching").
        if !fail && (r < tol || (t == 0.0 && signed < -tol)) {
            return Traced(t, STATUS_HIT);
        }
        let next = max(t + step, 0.0);
        // A miss needs the verified reach t + f/L (this point's empty sphere) past
        // max_dist: a relaxed step that crosses it is checked at the next point first.
        let gone = !fail && t + signed > max_dist;
//#else
        if r < tol || (t == 0.0 && signed < -tol) {
            return Traced(t, STATUS_HIT);
        }
        let next = max(t + signed, 0.0);
        let gone = next > max_dist;
//#endif
        t = next;
        if gone {
            return Traced(next, STATUS_MISS);
        }
        if steps >= params.counts.w {
            break;
        }
    }
    // The loop ends on the step budget, or, on a software adapter (Mesa's llvmpipe), where
    // every loop of a shader stops once they have run 65 535 iterations together, before
    // it: the distances were wrong from there on, and the frame is refused.
    if steps < params.counts.w {
        counters.cut += 1u;
    }
    return Traced(t, STATUS_BUDGET);
}
//#endif

// The normal step h = max(L·ε·t, 64·ε_f32·(1 + |p|∞)) (a hit may lie up to L·ε·t away).
fn normal_step(tt: f32, p: vec3<f32>) -> f32 {
    let a = abs(p);
    let floor_h = 64.0 * 1.1920929e-7 * (1.0 + max(a.x, max(a.y, a.z)));
    return max(params.march.x * tt / params.march.w, floor_h);
}

//#if !ANALYTIC
// The hit tolerance: the pixel cone, but never below 8 ulps of the point's coordinates.
fn tolerance(cone: f32, p: vec3<f32>) -> f32 {
    let a = abs(p);
    return max(cone, 8.0 * 1.1920929e-7 * max(a.x, max(a.y, a.z)));
}

// N = normalize(Σ k_i f(p + h·k_i)); a degenerate gradient gives -D.
fn normal(p: vec3<f32>, h: f32, d: vec3<f32>) -> vec3<f32> {
    var g = vec3<f32>(0.0);
    for (var i = 0u; i < 4u; i++) {
        let k = TETRA[i];
        g += k * sdf(p + k * h);
    }
    let l = length(g);
    if l > 0.0 && !is_nan(l) {
        return g * (1.0 / l);
    }
    return -d;
}
//#if MEDIA

// The normal of the solids inside glass (the gradient of their own field), as `normal`.
fn normal_solid(p: vec3<f32>, h: f32, d: vec3<f32>) -> vec3<f32> {
    var g = vec3<f32>(0.0);
    for (var i = 0u; i < 4u; i++) {
        let k = TETRA[i];
        g += k * sdf_solid(p + k * h);
    }
    let l = length(g);
    if l > 0.0 && !is_nan(l) {
        return g * (1.0 / l);
    }
    return -d;
}

// While a solid inside glass is shaded: the glass's transparency, which its shadow rays
// start inside of (0 otherwise).
var<private> medium_tau: f32 = 0.0;
//#endif
//#endif

//#if !ANALYTIC
//#if SOFT
// A penumbra term where there is none (transparent, inside a solid, t = 0).
const NO_PENUMBRA: f32 = 3.4e38;
// The search around a least k·d/t ends when its bracket is narrower than this fraction of
// the penumbra cone's width, or after this many probes (docs/rendering.md, "Shadows").
const PENUMBRA_BRACKET: f32 = {{PENUMBRA_BRACKET}};
const PENUMBRA_PROBES: u32 = {{PENUMBRA_PROBES}};

// The next probe of the bracket (a, m, b): the middle of its longer half.
fn probe(a: f32, m: f32, b: f32) -> f32 {
    return select((m + b) * 0.5, (a + m) * 0.5, m - a > b - m);
}

//#endif
// A shadow ray towards a light at distance tmax: the fraction of light that arrives.
// Soft (k > 0): res = min(res, k·d/t), the least found by a search wherever the steps
// bracket one. A transparent occluder passes its transparency and the ray goes on through
// it; an opaque one blocks the light.
fn shadow(o: vec3<f32>, d: vec3<f32>, t0: f32, tmax: f32, k: f32) -> f32 {
    counters.shadow += 1u;
    let eps = params.march.x;
    let inv_l = params.march.w;
    var t = 0.0;
    var steps = 0u;
    var res = 1.0;
    var through = 1.0;
    var sign = 1.0;
//#if SOFT
    // The last two samples of the march (t, d/L, penumbra term): a, then m.
    var ta = 0.0;
    var sa = 0.0;
    var qa = NO_PENUMBRA;
    var tm = 0.0;
    var sm = 0.0;
    var qm = NO_PENUMBRA;
    // A search's bracket ra < rm < rb, rq the term at rm, and its probes (0: marching).
    var ra = 0.0;
    var rm = 0.0;
    var rb = 0.0;
    var rq = 0.0;
    var probes = 0u;
//#endif
//#if MEDIA
    if medium_tau > 0.0 {
        through = medium_tau;
        sign = -1.0;
    }
//#endif
    loop {
        let p = o + d * t;
//#if TRANSPARENT
        let fm = map(p);
        let f = fm.x;
        let tau = params.materials[u32(fm.y)].optics.y;
//#else
        let f = sdf(p);
        let tau = 0.0;
//#endif
        steps += 1u;
        counters.steps += 1u;
        if is_nan(f) {
            counters.nans += 1u;
            return through * res;
        }
        let signed = sign * f * inv_l;
        let tt = t0 + t;
        let tol = tolerance(eps * tt, p);
        if signed < -tol {
            counters.overshoots += 1u;
        }
        let outside = sign > 0.0;
//#if SOFT
        var q = NO_PENUMBRA;
        if outside && k > 0.0 && t > 0.0 && tau <= 0.0 {
            q = k * signed / t;
            res = min(res, q);
        }
//#endif
        var next = t + signed;
        // Below −tol: inside a solid (a start lifted into a neighbour), as if reached.
        let reached = signed < tol;
        if reached && tau <= 0.0 {
            return 0.0;
        }
//#if SOFT
        if probes > 0u {
            // A probe: the bracket closes in on the least term; a transparent surface within
            // it is not crossed (the march crosses it when it gets there).
            if q < rq {
                if t < rm {
                    rb = rm;
                } else {
                    ra = rm;
                }
                rm = t;
                rq = q;
            } else if t < rm {
                ra = t;
            } else {
                rb = t;
            }
            if k * (rb - ra) <= PENUMBRA_BRACKET * rm || probes >= PENUMBRA_PROBES {
                probes = 0u;
                next = tm + sm;
            } else {
                probes += 1u;
                next = probe(ra, rm, rb);
            }
        } else if reached {
//#else
        if reached {
//#endif
            if outside {
                through = through * tau;
            }
            sign = -sign;
            next = t + 4.0 * normal_step(tt, p);
//#if SOFT
            ta = tm;
            sa = sm;
            qa = qm;
            tm = t;
            sm = signed;
            qm = NO_PENUMBRA;
        } else {
            // The term fell at m and rose again: search (a, b) where its Lipschitz bound
            // allows a term below res and 1 there, unless the bracket is narrow already.
            let low = min(sa + sm - (tm - ta), sm + signed - (t - tm)) * 0.5;
            if qm < qa && q > qm && k * low < min(res, 1.0) * t
                && k * (t - ta) > PENUMBRA_BRACKET * tm {
                ra = ta;
                rm = tm;
                rb = t;
                rq = qm;
                probes = 1u;
                next = probe(ra, rm, rb);
            }
            ta = tm;
            sa = sm;
            qa = qm;
            tm = t;
            sm = signed;
            qm = q;
//#endif
        }
        t = max(next, 0.0);
//#if SOFT
        if probes > 0u {
            if steps >= params.counts.w {
                break;
            }
            continue;
        }
//#endif
        if t >= tmax || steps >= params.counts.w {
            break;
        }
    }
    // Ended by neither: a software adapter cut the loop (see `trace`).
    if t < tmax && steps < params.counts.w {
        counters.cut += 1u;
    }
    return through * clamp(res, 0.0, 1.0);
}
//#endif

// A ray to trace, with the weight its colour is added with.
struct Ray {
    origin: vec3<f32>,
    t0: f32, // path length of the pixel's ray before this segment
    dir: vec3<f32>,
    depth: u32,
    weight: vec3<f32>,
    inside: u32, // 1 while travelling inside a solid (marching -f)
}

//#if SECONDARY
// The transmitted direction through a surface of normal n (facing the ray) with index
// ratio eta; a zero vector on total internal reflection.
fn refract_dir(d: vec3<f32>, n: vec3<f32>, eta: f32) -> vec3<f32> {
    let cosi = -dot(d, n);
    let k = 1.0 - eta * eta * (1.0 - cosi * cosi);
    if k < 0.0 {
        return vec3<f32>(0.0);
    }
    return normalize(d * eta + n * (eta * cosi - sqrt(k)));
}

fn reflect_dir(d: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    return d - n * (2.0 * dot(d, n));
}
//#endif

// The colour seen along one camera ray, with all its secondary rays.
fn radiance(eye: vec3<f32>, dir: vec3<f32>) -> vec3<f32> {
    var acc = vec3<f32>(0.0);
    let first = Ray(eye, 0.0, dir, 0u, vec3<f32>(1.0), 0u);
//#if SECONDARY
    // Pending rays on an explicit stack: each hit pushes at most two, one of which is
    // popped next, so max_depth + 2 entries suffice.
    var stack: array<Ray, {{STACK}}>;
    var top = 1u;
    stack[0] = first;
    while top > 0u {
        top -= 1u;
        let ray = stack[top];
//#else
    for (var once = 0u; once < 1u; once++) {
        let ray = first;
//#endif
//#if REFRACTION
        let inside = ray.inside != 0u;
        let hit = trace(ray.origin, ray.dir, ray.t0, select(1.0, -1.0, inside));
//#else
        let inside = false;
        let hit = trace(ray.origin, ray.dir, ray.t0, 1.0);
//#endif
//#if GLOW
        // A camera ray glows with its marching steps.
        if ray.depth == 0u {
            acc += params.glow.xyz * glow;
        }
//#endif
        if hit.status != STATUS_HIT {
            if hit.status == STATUS_MISS {
                counters.misses += 1u;
            } else if hit.status == STATUS_BUDGET {
                counters.budget += 1u;
            }
//#if FOG
            // Fog hides what lies beyond every surface: a miss outside solids is its colour.
            if !inside {
                acc += ray.weight * fog_colour(ray.dir);
                continue;
            }
//#endif
            acc += ray.weight * background(ray.dir);
            continue;
        }
        counters.hits += 1u;
        let p = ray.origin + ray.dir * hit.t;
        let tt = ray.t0 + hit.t;
        let h = normal_step(tt, p);
        // Fog over the segment (none inside solids): what it hides is the fog's colour.
        var weight = ray.weight;
//#if FOG
        if !inside {
            let e = fade(hit.t);
            acc += weight * (1.0 - e) * fog_colour(ray.dir);
            weight = weight * e;
        }
//#endif
//#if MEDIA
        if inside {
            let solid = map_solid(p);
            if solid.x < h {
                // An opaque solid inside the glass: lit and reflecting as seen from outside,
                // within the glass (docs/rendering.md, "Inside glass").
                let ns = normal_solid(p, h, ray.dir);
//#if MATERIAL_CHECKER
                let ms = checkered(params.materials[u32(solid.y)], p, ns, h, ray.dir, tt);
//#else
                let ms = params.materials[u32(solid.y)];
//#endif
                let ls = lobes(ms, p, ns, ray.dir, tt, h);
                if ls.local > 0.0 {
                    medium_tau = params.materials[u32(map(p).y)].optics.y;
                    acc += shade(ms, p, ns, ray.dir, tt, h, 1.0) * weight * ls.local;
                    medium_tau = 0.0;
                }
                if ray.depth < params.depth.x && any(ls.reflect > vec3<f32>(0.0)) {
                    stack[top] = Ray(p + ns * (4.0 * h), tt, reflect_dir(ray.dir, ns), ray.depth + 1u, weight * ls.reflect, 1u);
                    top += 1u;
                    counters.secondary += 1u;
                }
                continue;
            }
        }
//#endif
//#if ANALYTIC
        let n = hit.normal;
//#if MATERIAL_CHECKER
        let m = checkered(params.materials[hit.material], p, n, h, ray.dir, tt);
//#else
        let m = params.materials[hit.material];
//#endif
        // Inside glass, an opaque primitive (glass overlaps no other glass in a traced scene):
        // lit and reflecting as seen from outside, within the glass (docs/rendering.md,
        // "Inside glass"); its shadow rays start inside the glass, whose transparency
        // `occlude` applies.
        let solid = inside && m.optics.y <= 0.0;
//#else
        let n = normal(p, h, ray.dir);
//#if MATERIALS
//#if MATERIAL_CHECKER
        let m = checkered(params.materials[u32(map(p).y)], p, n, h, ray.dir, tt);
//#else
        let m = params.materials[u32(map(p).y)];
//#endif
//#else
        let m = params.materials[0];
//#endif
        let solid = false;
//#endif
        let lb = lobes(m, p, n, ray.dir, tt, h);
        if (!inside || solid) && lb.local > 0.0 {
            var ao = 1.0;
//#if OCCLUSION
            if !solid {
                ao = occlusion(p, n);
            }
//#endif
            acc += shade(m, p, n, ray.dir, tt, h, ao) * weight * lb.local;
        }
//#if SECONDARY
        if ray.depth >= params.depth.x {
            continue;
        }
        let off = n * (4.0 * h);
//#if REFRACTION
        if inside && !solid {
            // Leaving the solid: refract out, or reflect back in on total internal reflection.
            let tr = refract_dir(ray.dir, -n, m.optics.z);
            if any(tr != vec3<f32>(0.0)) {
                stack[top] = Ray(p + off, tt, tr, ray.depth + 1u, weight, 0u);
            } else {
                stack[top] = Ray(p - off, tt, reflect_dir(ray.dir, n), ray.depth + 1u, weight, 1u);
            }
            top += 1u;
            counters.secondary += 1u;
            continue;
        }
//#endif
        if any(lb.reflect > vec3<f32>(0.0)) {
            // From a solid within glass the reflection stays inside the glass.
            stack[top] = Ray(p + off, tt, reflect_dir(ray.dir, n), ray.depth + 1u, weight * lb.reflect, u32(solid));
            top += 1u;
            counters.secondary += 1u;
        }
//#if REFRACTION
        if m.optics.y > 0.0 {
            let tr = refract_dir(ray.dir, n, 1.0 / m.optics.z);
            if any(tr != vec3<f32>(0.0)) {
                stack[top] = Ray(p - off, tt, tr, ray.depth + 1u, weight * lb.transmit, 1u);
            } else {
                stack[top] = Ray(p + off, tt, reflect_dir(ray.dir, n), ray.depth + 1u, weight * lb.transmit, 0u);
            }
            top += 1u;
            counters.secondary += 1u;
        }
//#endif
//#endif
    }
    return acc;
}

// The direction of sample (i, j) of pixel (x, y) (docs/rendering.md, "Camera").
fn camera_dir(x: u32, y: u32, i: u32, j: u32) -> vec3<f32> {
    let n = f32(params.counts.z);
    let ax = (f32(x) + (f32(i) + 0.5) / n) / params.view.z;
    let ay = (f32(y) + (f32(j) + 0.5) / n) / params.view.w;
    let bx = 2.0 * ax - 1.0;
    let by = 1.0 - 2.0 * ay;
    return normalize(params.cam_w.xyz + params.cam_u.xyz * (bx * params.view.x) + params.cam_v.xyz * (by * params.view.y));
}

// Threshold `k` of the sRGB encoding (`params.srgb`, four to a vector).
fn srgb_threshold(k: u32) -> f32 {
    let q = params.srgb[k >> 2u];
    let m = k & 3u;
    return select(select(q.x, q.y, m == 1u), select(q.z, q.w, m == 3u), m >= 2u);
}

// A linear value clamped to [0, 1] (NaN as 0) and sRGB-encoded to 8 bits, bit for bit the
// host's (srgb.rs): the number of thresholds at or below it, by binary search. A NaN or a
// value below the first threshold compares false at every step.
fn srgb_code(c: f32) -> u32 {
    var v = select(0u, 128u, c >= srgb_threshold(128u));
    v += select(0u, 64u, c >= srgb_threshold(v + 64u));
    v += select(0u, 32u, c >= srgb_threshold(v + 32u));
    v += select(0u, 16u, c >= srgb_threshold(v + 16u));
    v += select(0u, 8u, c >= srgb_threshold(v + 8u));
    v += select(0u, 4u, c >= srgb_threshold(v + 4u));
    v += select(0u, 2u, c >= srgb_threshold(v + 2u));
    v += select(0u, 1u, c >= srgb_threshold(v + 1u));
    return v;
}

@compute @workgroup_size({{WORKGROUP}}, {{WORKGROUP}}, 1)
fn {{ENTRY}}(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= tile.z || gid.y >= tile.w {
        return;
    }
    let x = tile.x + gid.x;
    let y = tile.y + gid.y;
//#if PATH
    // Path traced (path.wgsl): the mean of `samples` paths (depth.y), numbered from the first
    // sample (depth.w).
    let samples = params.depth.y;
    var sum = vec3<f32>(0.0);
    for (var s = 0u; s < samples; s++) {
        sum += path_radiance(x, y, params.depth.w + s);
    }
    let pixel = y * params.counts.x + x;
    var colour = grade(sum / f32(samples));
//#else
    let aa = params.counts.z;
    var sum = vec3<f32>(0.0);
    for (var j = 0u; j < aa; j++) {
        for (var i = 0u; i < aa; i++) {
            sum += radiance(params.eye.xyz, camera_dir(x, y, i, j));
        }
    }
    let pixel = y * params.counts.x + x;
    var colour = grade(sum / f32(aa * aa));
//#endif
//#if DEBUG_NAN
    // --debug-nan: a pixel any of whose rays met a NaN is magenta.
    if counters.nans > 0u {
        colour = vec3<f32>(1.0, 0.0, 1.0);
    }
//#endif
    image[pixel] = vec4<f32>(colour, 1.0);
    pixels[pixel] = srgb_code(colour.x) | (srgb_code(colour.y) << 8u) | (srgb_code(colour.z) << 16u) | (255u << 24u);
    let s = pixel * 9u;
    stats[s] = counters.steps;
    stats[s + 1u] = counters.hits;
    stats[s + 2u] = counters.misses;
    stats[s + 3u] = counters.budget;
    stats[s + 4u] = counters.overshoots;
    stats[s + 5u] = counters.nans;
    stats[s + 6u] = counters.secondary;
    stats[s + 7u] = counters.shadow;
    stats[s + 8u] = counters.cut;
}
