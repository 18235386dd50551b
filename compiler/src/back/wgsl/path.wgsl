//% The path tracer part of the kernel template (appended to kernel.wgsl and shading.wgsl,
//% expanded with them: see template.rs), kept only in kernels of the PATH feature: the
//% counter-based random stream, the sampling formulas and the path of one sample, as
//% docs/rendering.md ("Path tracing") states them. The CPU's copy is runtime/src/cpu/path.rs;
//% the stream and formulas are compiler/src/scene/sampling.rs, with the same integer arithmetic.
//#if PATH
const PATH_PI: f32 = {{PI}};
const PATH_INV_PI: f32 = {{INV_PI}};
const PATH_UNIT: f32 = {{UNIT}};
const ROULETTE_DEPTH: u32 = {{ROULETTE_DEPTH}};
const ROULETTE_MAX: f32 = {{ROULETTE_MAX}};
const DIM_LOBE: u32 = {{DIM_LOBE}};
const DIM_DIRECTION: u32 = {{DIM_DIRECTION}};
const DIM_SKY: u32 = {{DIM_SKY}};
const DIM_ROULETTE: u32 = {{DIM_ROULETTE}};
const DIM_LAMPS: u32 = {{DIM_LAMPS}};

// The PCG hash of one word (wrapping u32 arithmetic, as the host's `sampling::pcg`).
fn pcg(x: u32) -> u32 {
    let state = x * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// The stream's number in [0, 1) for (pixel, sample, bounce, dimension): the top 24 bits of
// pcg(pcg(pcg(pcg(pixel) + sample) + bounce) + dim) times 2⁻²⁴. The hash is taken in its
// steps, each once: a sample's key pcg(pcg(pixel) + sample) (`sample_key`), a bounce's
// pcg(sample key + bounce) (`bounce_key`), then one pcg for each number drawn at that bounce
// (`rnd`); the numbers are the host's (`sampling::uniform`), bit for bit.
fn sample_key(pixel: u32, sample: u32) -> u32 {
    return pcg(pcg(pixel) + sample);
}

fn bounce_key(sk: u32, bounce: u32) -> u32 {
    return pcg(sk + bounce);
}

fn rnd(key: u32, dim: u32) -> f32 {
    return f32(pcg(key + dim) >> 8u) * PATH_UNIT;
}

// The direction of local coordinates l about the unit vector n (Duff et al.'s basis).
fn from_tangent(l: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    let t = vec3<f32>(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    let bb = vec3<f32>(b, s + n.y * n.y * a, -n.y);
    return l.x * t + l.y * bb + l.z * n;
}

// A direction about local z of cosine c, turned by 2π·u.
fn about(c: f32, u: f32) -> vec3<f32> {
    let s = sqrt(max(1.0 - c * c, 0.0));
    let phi = (2.0 * PATH_PI) * u;
    return vec3<f32>(s * cos(phi), s * sin(phi), c);
}

// Cosine-distributed about local z (Malley): r = √u₁, φ = 2π·u₂.
fn cosine_dir(u1: f32, u2: f32) -> vec3<f32> {
    let r = sqrt(u1);
    let phi = (2.0 * PATH_PI) * u2;
    return vec3<f32>(r * cos(phi), r * sin(phi), sqrt(max(1.0 - u1, 0.0)));
}

// A GGX half vector about local z: cos²θ = (1 − u₁)/(1 + (α² − 1)·u₁).
fn ggx_half(u1: f32, u2: f32, alpha: f32) -> vec3<f32> {
    let a2 = alpha * alpha;
    let cos2 = (1.0 - u1) / (1.0 + (a2 - 1.0) * u1);
    return about(sqrt(max(cos2, 0.0)), u2);
}

// The density of a direction reflected about a GGX half vector: D(h)·(N·H)/(4·(V·H)).
fn ggx_pdf(nh: f32, vh: f32, alpha: f32) -> f32 {
    if vh <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let d = nh * nh * (a2 - 1.0) + 1.0;
    return a2 / (PATH_PI * d * d) * nh / (4.0 * vh);
}

// The power heuristic a²/(a² + b²) (0 where both are 0).
fn power_weight(a: f32, b: f32) -> f32 {
    let a2 = a * a;
    let b2 = b * b;
    if a2 + b2 > 0.0 {
        return a2 / (a2 + b2);
    }
    return 0.0;
}

fn mean3(v: vec3<f32>) -> f32 {
    return (v.x + v.y + v.z) / 3.0;
}

// The radiance of every sky along d (whether or not it is the background).
fn sky_radiance(d: vec3<f32>) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
//#if SKY
    for (var i = 0u; i < {{SKIES}}u; i++) {
        let sky = params.skies[i];
        var l = sky.ground.xyz;
        if d.y >= 0.0 {
            l = sky.horizon.xyz + (sky.zenith.xyz - sky.horizon.xyz) * d.y;
        }
        sum += l;
    }
//#endif
    return sum;
}

// A material at a hit as the path tracer sees it (runtime/src/cpu/path.rs, `Bsdf`).
struct Bsdf {
    n: vec3<f32>,
    v: vec3<f32>,
    pbr: u32,              // 1: pbr's diffuse and GGX lobes; 0: Lambert (and Phong's highlight for lamps)
    diffuse: vec3<f32>,    // Phong: w·k_d·C
    spec: f32,             // Phong: w·k_s
    shininess: f32,
    c: vec3<f32>,          // pbr: the base colour
    q: f32,                // pbr: the probability of the GGX lobe
    p: vec3<f32>,          // the probabilities of the scattering part, the mirror, the refraction
    reflect: vec3<f32>,
    transmit: vec3<f32>,
}

fn bsdf_new(m: Material, c: vec3<f32>, p: vec3<f32>, n: vec3<f32>, d: vec3<f32>, tt: f32, h: f32) -> Bsdf {
    var b: Bsdf;
    b.n = n;
    b.v = -d;
    b.pbr = 0u;
    b.c = c;
    b.q = 0.0;
    b.reflect = vec3<f32>(0.0);
    b.transmit = vec3<f32>(0.0);
    b.diffuse = vec3<f32>(0.0);
    b.spec = 0.0;
    b.shininess = m.phong.w;
    var a_s = 0.0;
//#if PBR
    if m.fresnel.z > 0.0 {
        let s = pbr_surface(m, c, n, -d);
        let spec = mean3(s.albedo);
        let diffuse = mean3((vec3<f32>(1.0) - s.albedo) * c) * m.phong.y;
        a_s = spec + diffuse;
        if a_s > 0.0 {
            b.q = spec / a_s;
        }
        b.pbr = 1u;
        b.transmit = (vec3<f32>(1.0) - s.albedo) * c * m.optics.y;
    } else {
//#endif
        let l = lobes(m, p, n, d, tt, h);
        b.diffuse = c * (l.local * m.phong.y);
        b.spec = l.local * m.phong.z;
        b.reflect = l.reflect;
        if m.optics.y > 0.0 {
            b.transmit = l.transmit;
        }
        a_s = max(mean3(b.diffuse), 0.0);
//#if PBR
    }
//#endif
    let a_r = max(mean3(b.reflect), 0.0);
    let a_t = max(mean3(b.transmit), 0.0);
    let total = a_s + a_r + a_t;
    b.p = vec3<f32>(0.0);
    if total > 0.0 {
        b.p = vec3<f32>(a_s / total, a_r / total, a_t / total);
    }
    return b;
}

// f(l)·(N·L) of the scattering part (0 below the surface).
fn bsdf_eval(m: Material, b: Bsdf, l: vec3<f32>) -> vec3<f32> {
    let nl = dot(b.n, l);
    if nl <= 0.0 {
        return vec3<f32>(0.0);
    }
//#if PBR
    if b.pbr != 0u {
        return pbr_lamp(m, pbr_surface(m, b.c, b.n, b.v), b.c, b.n, b.v, l, vec3<f32>(1.0)) * PATH_INV_PI;
    }
//#endif
    return b.diffuse * (nl / PATH_PI);
}

// The density with which the scattering part draws l.
fn bsdf_pdf(m: Material, b: Bsdf, l: vec3<f32>) -> f32 {
    let nl = dot(b.n, l);
    if nl <= 0.0 {
        return 0.0;
    }
    let cosine = nl / PATH_PI;
    var within = cosine;
//#if PBR
    if b.pbr != 0u {
        let hv = normalize(l + b.v);
        let ggx = ggx_pdf(dot(b.n, hv), dot(b.v, hv), m.pbr.y);
        within = b.q * ggx + (1.0 - b.q) * cosine;
    }
//#endif
    return b.p.x * within;
}

// A lamp's light of colour il from l (N·L > 0), before attenuation and shadow.
fn bsdf_lamp(m: Material, b: Bsdf, l: vec3<f32>, il: vec3<f32>) -> vec3<f32> {
    let nl = dot(b.n, l);
//#if PBR
    if b.pbr != 0u {
        return pbr_lamp(m, pbr_surface(m, b.c, b.n, b.v), b.c, b.n, b.v, l, il);
    }
//#endif
    let r = b.n * (2.0 * nl) - l;
    let rv = max(dot(r, b.v), 0.0);
    return (b.diffuse * nl + vec3<f32>(b.spec * pow(rv, b.shininess))) * il;
}

// The continued path's direction, the factor of its weight, the density for the sky's
// weight and its lobe (0: none, 1: scattered, 2: mirror, 3: refracted).
struct Drawn {
    dir: vec3<f32>,
    factor: vec3<f32>,
    pdf: f32,
    lobe: u32,
}

fn draw(m: Material, b: Bsdf, u0: f32, u1: f32, u2: f32) -> Drawn {
    var out = Drawn(vec3<f32>(0.0), vec3<f32>(0.0), 0.0, 0u);
    if u0 < b.p.x {
        var l = from_tangent(cosine_dir(u1, u2), b.n);
//#if PBR
        if b.pbr != 0u && u0 / b.p.x < b.q {
            let hv = from_tangent(ggx_half(u1, u2, m.pbr.y), b.n);
            l = hv * (2.0 * dot(b.v, hv)) - b.v;
        }
//#endif
        let pdf = bsdf_pdf(m, b, l);
        if pdf <= 0.0 {
            return out;
        }
        return Drawn(l, bsdf_eval(m, b, l) * (1.0 / pdf), pdf, 1u);
    }
    if u0 < b.p.x + b.p.y {
        return Drawn(reflect_dir(-b.v, b.n), b.reflect * (1.0 / b.p.y), 0.0, 2u);
    }
    if b.p.z > 0.0 {
        return Drawn(-b.v, b.transmit * (1.0 / b.p.z), 0.0, 3u);
    }
    return out;
}

// The next-event estimates at a hit seen from outside (runtime/src/cpu/path.rs, `estimates`):
// each lamp through a hard shadow ray (a directional light sampled as a disc of its penumbra's
// diameter, cos of its half angle in to_light.w), and the skies along a cosine-distributed
// direction, weighed against the BRDF's density where the path goes on.
fn estimates(m: Material, b: Bsdf, p: vec3<f32>, h: f32, tt: f32, weight: vec3<f32>, more: bool, key: u32) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    let n = b.n;
    let off = 4.0 * h;
    let o = p + n * off;
//#if POINT
    for (var i = 0u; i < {{POINTS}}u; i++) {
        let light = params.points[i];
        let v = light.position.xyz - p;
        let dist = length(v);
        var atten = 1.0;
        if light.position.w > 0.0 {
            let x = dist / light.position.w;
            let f = clamp(1.0 - x * x, 0.0, 1.0);
            atten = f * f;
        }
        let l = v * (1.0 / dist);
        if dot(n, l) <= 0.0 || atten <= 0.0 {
            continue;
        }
        var c = weight * bsdf_lamp(m, b, l, light.color.xyz) * atten;
        if light.color.w >= 0.0 {
            c = c * shadow(o, l, tt, dist - off, 0.0);
        }
        sum += c;
    }
//#endif
//#if DIRECTIONAL
    for (var j = 0u; j < {{DIRS}}u; j++) {
        let light = params.dirs[j];
        var l = light.to_light.xyz;
        if light.to_light.w < 1.0 {
            let k = DIM_LAMPS + 2u * j;
            let u1 = rnd(key, k);
            let u2 = rnd(key, k + 1u);
            l = from_tangent(about(1.0 - u1 * (1.0 - light.to_light.w), u2), light.to_light.xyz);
        }
        if dot(n, l) <= 0.0 {
            continue;
        }
        var c = weight * bsdf_lamp(m, b, l, light.color.xyz) * 1.0;
        if light.color.w >= 0.0 {
            c = c * shadow(o, l, tt, params.march.y, 0.0);
        }
        sum += c;
    }
//#endif
//#if SKY
    let l = from_tangent(cosine_dir(rnd(key, DIM_SKY), rnd(key, DIM_SKY + 1u)), n);
    let nl = dot(n, l);
    let f = bsdf_eval(m, b, l);
    if nl > 0.0 && max(max(abs(f.x), abs(f.y)), abs(f.z)) > 0.0 {
        let pdf = nl / PATH_PI;
        var w = 1.0;
        if more {
            w = power_weight(pdf, bsdf_pdf(m, b, l));
        }
        let c = weight * f * sky_radiance(l) * (w / pdf);
        sum += c * shadow(o, l, tt, params.march.y, 0.0);
    }
//#endif
    return sum;
}

// The direction through the point (x + jx, y + jy) of the image (docs/rendering.md, "Camera",
// with the path tracer's jitter in place of the grid).
fn camera_jittered(x: u32, y: u32, jx: f32, jy: f32) -> vec3<f32> {
    let ax = (f32(x) + jx) / params.view.z;
    let ay = (f32(y) + jy) / params.view.w;
    let bx = 2.0 * ax - 1.0;
    let by = 1.0 - 2.0 * ay;
    return normalize(params.cam_w.xyz + params.cam_u.xyz * (bx * params.view.x) + params.cam_v.xyz * (by * params.view.y));
}

// One sample of pixel (x, y): its path, and what it gathers.
fn path_radiance(x: u32, y: u32, sample: u32) -> vec3<f32> {
    let pixel = y * params.counts.x + x;
    let sk = sample_key(pixel, sample);
    let first = bounce_key(sk, 0u);
    let dir0 = camera_jittered(x, y, rnd(first, 0u), rnd(first, 1u));
    var ray = Ray(params.eye.xyz, 0.0, dir0, 0u, vec3<f32>(1.0), 0u);
    var pdf = 0.0;
    var sky_pdf = 0.0;
    var acc = vec3<f32>(0.0);
    loop {
        let inside = ray.inside != 0u;
        let hit = trace(ray.origin, ray.dir, ray.t0, select(1.0, -1.0, inside));
        if hit.status != STATUS_HIT {
            if hit.status == STATUS_MISS {
                counters.misses += 1u;
            } else if hit.status == STATUS_BUDGET {
                counters.budget += 1u;
            }
//#if FOG
            if !inside {
                acc += ray.weight * fog_colour(ray.dir);
                break;
            }
//#endif
            if ray.depth == 0u {
                acc += ray.weight * background(ray.dir);
                break;
            }
            var w = 1.0;
            if pdf > 0.0 {
                w = power_weight(pdf, sky_pdf);
            }
            var rest = params.background.xyz;
            if params.background.w > 0.0 {
                rest = vec3<f32>(0.0);
            }
            acc += ray.weight * (sky_radiance(ray.dir) * w + rest);
            break;
        }
        counters.hits += 1u;
        let p = ray.origin + ray.dir * hit.t;
        let tt = ray.t0 + hit.t;
        let h = normal_step(tt, p);
        var weight = ray.weight;
//#if FOG
        if !inside {
            let e = fade(hit.t);
            acc += weight * (1.0 - e) * fog_colour(ray.dir);
            weight = weight * e;
        }
//#endif
//#if ANALYTIC
        var n = hit.normal;
        var m = params.materials[hit.material];
        var solid = inside && m.optics.y <= 0.0;
//#else
        var n = normal(p, h, ray.dir);
//#if MATERIALS
        var m = params.materials[u32(map(p).y)];
//#else
        var m = params.materials[0];
//#endif
        var solid = false;
//#if MEDIA
        if inside {
            let found = map_solid(p);
            if found.x < h {
                // An opaque solid inside the glass (docs/rendering.md, "Inside glass").
                m = params.materials[u32(found.y)];
                n = normal_solid(p, h, ray.dir);
                solid = true;
            }
        }
//#endif
//#endif
//#if MATERIAL_CHECKER
        m = checkered(m, p, n, h, ray.dir, tt);
//#endif
        let more = ray.depth < params.depth.z;
        let bounce = ray.depth + 1u;
        let off = n * (4.0 * h);
        let key = bounce_key(sk, bounce);
        let u_roulette = rnd(key, DIM_ROULETTE);
        var next: Ray;
        if inside && !solid {
            if !more {
                break;
            }
            // Leaving the solid: refract out, or reflect back in on total internal reflection.
            let tr = refract_dir(ray.dir, -n, m.optics.z);
            if any(tr != vec3<f32>(0.0)) {
                next = Ray(p + off, tt, tr, bounce, weight, 0u);
            } else {
                next = Ray(p - off, tt, reflect_dir(ray.dir, n), bounce, weight, 1u);
            }
            pdf = 0.0;
        } else {
            let c = surface_colour(m, p, n, h, ray.dir, tt);
            let b = bsdf_new(m, c, p, n, ray.dir, tt, h);
//#if PBR
            if m.fresnel.z > 0.0 {
                acc += weight * m.emission.xyz;
            }
//#endif
            if !solid {
                acc += estimates(m, b, p, h, tt, weight, more, key);
            }
            if !more {
                break;
            }
            let d = draw(m, b, rnd(key, DIM_LOBE), rnd(key, DIM_DIRECTION), rnd(key, DIM_DIRECTION + 1u));
            if d.lobe == 0u {
                break;
            }
            let w = weight * d.factor;
            let within = u32(solid);
            pdf = select(d.pdf, 0.0, solid);
            if d.lobe == 3u {
                pdf = 0.0;
                let tr = refract_dir(ray.dir, n, 1.0 / m.optics.z);
                if any(tr != vec3<f32>(0.0)) {
                    next = Ray(p - off, tt, tr, bounce, w, 1u);
                } else {
                    next = Ray(p + off, tt, reflect_dir(ray.dir, n), bounce, w, within);
                }
            } else {
                next = Ray(p + off, tt, d.dir, bounce, w, within);
            }
        }
        sky_pdf = max(dot(n, next.dir), 0.0) / PATH_PI;
        // Russian roulette from ROULETTE_DEPTH on: go on with q = min(max(weight), ROULETTE_MAX).
        if next.depth >= ROULETTE_DEPTH {
            let q = min(max(max(next.weight.x, next.weight.y), next.weight.z), ROULETTE_MAX);
            if u_roulette >= q {
                break;
            }
            next.weight = next.weight * (1.0 / q);
        }
        counters.secondary += 1u;
        ray = next;
    }
    return acc;
}
//#endif
