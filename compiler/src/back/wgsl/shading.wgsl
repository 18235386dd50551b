//% The shading part of the renderer kernel template (appended to kernel.wgsl, expanded with
//% it: see template.rs): surface colours (the checker filtered over the sample's footprint),
//% ambient occlusion, Phong, fog and the pixel's exposure and tone curve, as docs/rendering.md
//% ("At a hit", "The look") states them. The CPU renderer's copy is runtime/src/cpu/shade.rs
//% and look.rs.

//#if COLOUR_FIELDS
{{COLOURS}}
//#endif
//#if CHECKER
// The checker's footprint: an axis narrower than FOOTPRINT_MIN cells is point sampled; a
// grazing ray's footprint stretches by 1/max(|N·D|, FOOTPRINT_COS).
const FOOTPRINT_MIN: f32 = {{FOOTPRINT_MIN}};
const FOOTPRINT_COS: f32 = {{FOOTPRINT_COS}};

// The mean over [u − w/2, u + w/2] of the checker's sign along one axis (+1 in even cells,
// −1 in odd ones), u and w in cells: 2·(T(f − w/2) − T(f + w/2))/w with T(x) = |fract(x/2) − ½|,
// f the offset of u in its cell, times the cell's sign.
fn checker_sign(u: f32, w: f32) -> f32 {
    let c = floor(u);
    let cell = 1.0 - 2.0 * (c - 2.0 * floor(c * 0.5));
    if w < FOOTPRINT_MIN {
        return cell;
    }
    let f = u - c;
    let x = (f - 0.5 * w) * 0.5;
    let y = (f + 0.5 * w) * 0.5;
    let a = abs(x - floor(x) - 0.5);
    let b = abs(y - floor(y) - 0.5);
    return cell * 2.0 * (a - b) / w;
}

// The weight of the checker's second colour at q (in cells) for a sample whose footprint at
// the hit is s cells wide, seen along d on a surface of normal n: the footprint's width along
// axis k is s·√max(1 − n_k² + ((d_k − (N·D)·n_k)/c)², 0), c = max(|N·D|, FOOTPRINT_COS), and
// the weight is ½ − ½·Π sign_k.
fn checker_weight(q: vec3<f32>, n: vec3<f32>, d: vec3<f32>, s: f32) -> f32 {
    let nd = dot(n, d);
    let c = max(abs(nd), FOOTPRINT_COS);
    let e = (d - n * nd) * (1.0 / c);
    let w = s * sqrt(max(vec3<f32>(1.0) - n * n + e * e, vec3<f32>(0.0)));
    return 0.5 - 0.5 * checker_sign(q.x, w.x) * checker_sign(q.y, w.y) * checker_sign(q.z, w.z);
}
//#endif

// The colour of material m at p (a checker: its two colours mixed over the sample's
// footprint, sampled just inside; a colour field: its value at p, where the normal is n). d:
// the ray's direction, tt: its path length.
fn surface_colour(m: Material, p: vec3<f32>, n: vec3<f32>, h: f32, d: vec3<f32>, tt: f32) -> vec3<f32> {
    var ca = m.color.xyz;
//#if COLOUR_FIELDS
    if m.optics.w > 0.0 {
        ca = colour_field(u32(m.optics.w) - 1u, p, n);
    }
//#endif
//#if CHECKER
    if m.color.w > 0.0 {
        let q = (p - n * (2.0 * h)) * m.color_b.w + m.shift.xyz;
        // The sample's footprint: the pixel's pitch at unit distance over aa, times tt.
        let pitch = 2.0 * params.view.y / (params.view.w * f32(params.counts.z));
        let wb = checker_weight(q, n, d, tt * pitch * m.color_b.w);
        var cb = m.color_b.xyz;
//#if COLOUR_FIELDS
        if m.shift.w > 0.0 && wb > 0.0 {
            cb = colour_field(u32(m.shift.w) - 1u, p, n);
        }
//#endif
        if wb >= 1.0 {
            return cb;
        }
        if wb > 0.0 {
            return ca * (1.0 - wb) + cb * wb;
        }
    }
//#endif
    return ca;
}
//#if MATERIAL_CHECKER

// A hit on a checker of two materials (color.w = 2, their ids in color.xy) takes the material
// of the cell its sample sees, or, where the footprint covers both (0 < wb < 1), their blend:
// every number x·(1 − wb) + y·wb, the colour their colours' blend (runtime/src/cpu/shade.rs,
// `checkered`; docs/rendering.md, "The checker's footprint").
fn checkered(m: Material, p: vec3<f32>, n: vec3<f32>, h: f32, d: vec3<f32>, tt: f32) -> Material {
    if m.color.w < 2.0 {
        return m;
    }
    let ma = params.materials[u32(m.color.x)];
    let mb = params.materials[u32(m.color.y)];
    let q = (p - n * (2.0 * h)) * m.color_b.w + m.shift.xyz;
    let pitch = 2.0 * params.view.y / (params.view.w * f32(params.counts.z));
    let wb = checker_weight(q, n, d, tt * pitch * m.color_b.w);
    if wb <= 0.0 {
        return ma;
    }
    if wb >= 1.0 {
        return mb;
    }
    let wa = 1.0 - wb;
    let c = surface_colour(ma, p, n, h, d, tt) * wa + surface_colour(mb, p, n, h, d, tt) * wb;
    return Material(
        vec4<f32>(c, 0.0),
        vec4<f32>(0.0),
        ma.phong * wa + mb.phong * wb,
        vec4<f32>(ma.optics.xyz * wa + mb.optics.xyz * wb, 0.0),
        vec4<f32>(0.0),
//#if FRESNEL
        ma.fresnel * wa + mb.fresnel * wb,
//#endif
//#if PBR
        ma.pbr * wa + mb.pbr * wb,
        ma.emission * wa + mb.emission * wb,
//#endif
    );
}
//#endif

//#if OCCLUSION
// Ambient occlusion at p on a surface of normal n: with R = look.x and n = OCCLUSION_SAMPLES,
// hᵢ = R·i/n, dᵢ = f(p + hᵢ·N)/L, ao = clamp(1 − (k/n)·Σ max(hᵢ − dᵢ, 0)/hᵢ, 0, 1).
const OCCLUSION_SAMPLES: u32 = {{OCCLUSION_SAMPLES}};
const OCCLUSION_STRENGTH: f32 = {{OCCLUSION_STRENGTH}};
fn occlusion(p: vec3<f32>, n: vec3<f32>) -> f32 {
    let r = params.look.x;
    var sum = 0.0;
    for (var i = 1u; i <= OCCLUSION_SAMPLES; i++) {
        let h = r * f32(i) / f32(OCCLUSION_SAMPLES);
        let d = sdf(p + n * h) * params.march.w;
        sum += max(h - d, 0.0) / h;
    }
    return clamp(1.0 - OCCLUSION_STRENGTH / f32(OCCLUSION_SAMPLES) * sum, 0.0, 1.0);
}
//#endif

//#if FRESNEL
// Schlick's (1 − c)⁵.
fn schlick(c: f32) -> f32 {
    let x = 1.0 - clamp(c, 0.0, 1.0);
    let x2 = x * x;
    return x2 * x2 * x;
}
//#endif
//#if PBR
// The physically based material (docs/rendering.md, "Physically based materials"; the
// formulas of compiler/src/scene/pbr.rs). The terms it shares at a hit of base colour c.
struct Surface {
    nv: f32,            // max(N·V, NV_MIN)
    f0: vec3<f32>,      // the reflectance at normal incidence
    albedo: vec3<f32>,  // the specular lobe's directional albedo E_s = clamp(F0·A + B, 0, 1)
}

fn pbr_surface(m: Material, c: vec3<f32>, n: vec3<f32>, v: vec3<f32>) -> Surface {
    let nv = max(dot(n, v), {{NV_MIN}});
    let f0 = vec3<f32>(m.fresnel.x * (1.0 - m.pbr.z)) + c * m.pbr.z;
    // Karis's fit of the split-sum environment BRDF: r = roughness·c0 + c1.
    let r = m.pbr.x * vec4<f32>({{ENV_C0}}) + vec4<f32>({{ENV_C1}});
    let a = min(r.x * r.x, exp2({{ENV_EXP}} * nv)) * r.x + r.y;
    let ab = vec2<f32>(-1.04, 1.04) * a + r.zw;
    return Surface(nv, f0, clamp(f0 * ab.x + vec3<f32>(ab.y), vec3<f32>(0.0), vec3<f32>(1.0)));
}

// A lamp's light on a pbr surface before attenuation and shadow, N·L > 0:
// (k_d·(1 − F)·C + π·D·Vis·F)·I_l·(N·L).
fn pbr_lamp(m: Material, s: Surface, c: vec3<f32>, n: vec3<f32>, v: vec3<f32>, l: vec3<f32>, il: vec3<f32>) -> vec3<f32> {
    let nl = dot(n, l);
    let hv = normalize(l + v);
    let nh = max(dot(n, hv), 0.0);
    let f = s.f0 + (vec3<f32>(1.0) - s.f0) * schlick(dot(v, hv));
    let a2 = m.pbr.y * m.pbr.y;
    let dd = nh * nh * (a2 - 1.0) + 1.0;
    let dist = a2 / ({{PI}} * dd * dd);
    let vis = 0.5 / (nl * sqrt(s.nv * s.nv * (1.0 - a2) + a2) + s.nv * sqrt(nl * nl * (1.0 - a2) + a2));
    let diffuse = (vec3<f32>(1.0) - f) * c * m.phong.y;
    return (diffuse + f * ({{PI}} * dist * vis)) * il * nl;
}
//#endif

//% The weights of a hit's local colour, reflected ray and refracted ray on m of normal n seen
//% along d: Phong's 1 − r − τ, r, τ (with Fresnel, moved towards the mirror at grazing
//% incidence); pbr's 1, E_s·g and τ·(1 − E_s)·C.
// The weights of a hit's local colour, reflected and refracted ray (docs/rendering.md).
struct Lobes { local: f32, reflect: vec3<f32>, transmit: vec3<f32> }
fn lobes(m: Material, p: vec3<f32>, n: vec3<f32>, d: vec3<f32>, tt: f32, h: f32) -> Lobes {
//#if PBR
    if m.fresnel.z > 0.0 {
        let c = surface_colour(m, p, n, h, d, tt);
        let s = pbr_surface(m, c, n, -d);
        return Lobes(1.0, s.albedo * m.pbr.w, (vec3<f32>(1.0) - s.albedo) * c * m.optics.y);
    }
//#endif
//#if FRESNEL
    let r = m.optics.x;
    let tau = m.optics.y;
    if m.fresnel.y > 0.0 {
        // w' = w·(1 − s), τ' = τ·(1 − R), r' = r + w·s + τ·R with s = (1 − |N·V|)⁵ and the
        // glass's R = F0 + (1 − F0)·s.
        let sg = schlick(abs(dot(n, d)));
        let w = 1.0 - r - tau;
        let big_r = m.fresnel.x + (1.0 - m.fresnel.x) * sg;
        return Lobes(w * (1.0 - sg), vec3<f32>(r + w * sg + tau * big_r), vec3<f32>(tau * (1.0 - big_r)));
    }
//#endif
    return Lobes(1.0 - m.optics.x - m.optics.y, vec3<f32>(m.optics.x), vec3<f32>(m.optics.y));
}

// One light's term at a hit, shadow included: Phong's, or a pbr surface's.
fn phong_term(c: vec3<f32>, m: Material, p: vec3<f32>, n: vec3<f32>, d: vec3<f32>, tt: f32, h: f32,
              l: vec3<f32>, dist: f32, atten: f32, il: vec3<f32>, k: f32, is_point: bool) -> vec3<f32> {
    let ndl = dot(n, l);
    if ndl <= 0.0 || atten <= 0.0 {
        return vec3<f32>(0.0);
    }
//#if PBR
    var contrib: vec3<f32>;
    if m.fresnel.z > 0.0 {
        contrib = pbr_lamp(m, pbr_surface(m, c, n, -d), c, n, -d, l, il) * atten;
    } else {
        let r = n * (2.0 * ndl) - l;
        let spec = m.phong.z * pow(max(dot(r, -d), 0.0), m.phong.w);
        contrib = (c * (m.phong.y * ndl) + vec3<f32>(spec)) * il * atten;
    }
//#else
    let r = n * (2.0 * ndl) - l;
    let rv = max(dot(r, -d), 0.0);
    let spec = m.phong.z * pow(rv, m.phong.w);
    let contrib = (c * (m.phong.y * ndl) + vec3<f32>(spec)) * il * atten;
//#endif
    // k < 0: a light without shadows.
    if k < 0.0 {
        return contrib;
    }
    let off = 4.0 * h;
    let tmax = select(dist, dist - off, is_point);
    return contrib * shadow(p + n * off, l, tt, tmax, k);
}

// What a ray that hits nothing sees: the skies that are the background, or the background.
fn background(d: vec3<f32>) -> vec3<f32> {
//#if SKY
    if params.background.w > 0.0 {
        var sum = vec3<f32>(0.0);
        for (var i = 0u; i < {{SKIES}}u; i++) {
            let sky = params.skies[i];
            var l = sky.ground.xyz;
            if d.y >= 0.0 {
                l = sky.horizon.xyz + (sky.zenith.xyz - sky.horizon.xyz) * d.y;
            }
            sum += l * sky.zenith.w;
        }
        return sum;
    }
//#endif
    return params.background.xyz;
}

// Ambient (times the occlusion ao) plus every light:
// I = ao·k_a·C + Σ shadow·atten·(k_d·max(N·L,0)·C·I_l + k_s·max(R·V,0)^α·I_l) (pbr: emission).
fn shade(m: Material, p: vec3<f32>, n: vec3<f32>, d: vec3<f32>, tt: f32, h: f32, ao: f32) -> vec3<f32> {
    let c = surface_colour(m, p, n, h, d, tt);
    var sum = c * (m.phong.x * ao);
//#if PBR
    let pbr = m.fresnel.z > 0.0;
    var es = vec3<f32>(0.0);
    if pbr {
        sum = m.emission.xyz;
        es = pbr_surface(m, c, n, -d).albedo;
    }
//#endif
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
        sum += phong_term(c, m, p, n, d, tt, h, v * (1.0 / dist), dist, atten, light.color.xyz, light.color.w, true);
    }
//#endif
//#if DIRECTIONAL
    for (var i = 0u; i < {{DIRS}}u; i++) {
        let light = params.dirs[i];
        sum += phong_term(c, m, p, n, d, tt, h, light.to_light.xyz, params.march.y, 1.0, light.color.xyz, light.color.w, false);
    }
//#endif
//#if SKY
    // Sky light: k_d·C·E(N)/π, times the occlusion where it casts shadows.
    for (var i = 0u; i < {{SKIES}}u; i++) {
        let sky = params.skies[i];
        let e = sky.c0.xyz + sky.c1.xyz * n.y + sky.c2.xyz * (3.0 * n.y * n.y - 1.0);
        var term = c * e * m.phong.y;
//#if PBR
        // pbr: k_d·(1 − E_s)·C·E(N)/π + E_s·(1 − g)·E(R)/π.
        if pbr {
            let ry = 2.0 * dot(n, -d) * n.y + d.y;
            let er = sky.c0.xyz + sky.c1.xyz * ry + sky.c2.xyz * (3.0 * ry * ry - 1.0);
            term = (vec3<f32>(1.0) - es) * term + es * er * (1.0 - m.pbr.w);
        }
//#endif
        sum += term * select(1.0, ao, sky.c0.w > 0.0);
    }
//#endif
    return sum;
}

//#if FOG
// What fog leaves of a ray segment of length t: e^(−t/D), with 1/D in look.y.
fn fade(t: f32) -> f32 {
    return exp(-t * params.look.y);
}

// The fog's colour along d: `fog_color`, or the background seen along d.
fn fog_colour(d: vec3<f32>) -> vec3<f32> {
    if params.fog.w > 0.0 {
        return params.fog.xyz;
    }
    return background(d);
}
//#endif

// A pixel's linear colour after the exposure (2^exposure in look.z) and the tone curve
// (look.w: 0 none, 1 filmic, 2 Reinhard).
fn grade(c: vec3<f32>) -> vec3<f32> {
//#if GRADE
    let x = c * params.look.z;
    if params.look.w == 1.0 {
        let num = x * ({{FILMIC_A}} * x + {{FILMIC_B}});
        let den = x * ({{FILMIC_C}} * x + {{FILMIC_D}}) + {{FILMIC_E}};
        return clamp(num / den, vec3<f32>(0.0), vec3<f32>(1.0));
    }
    if params.look.w == 2.0 {
        return x / (vec3<f32>(1.0) + x);
    }
    return x;
//#else
    return c;
//#endif
}
