//! The PTX back end: WGSL compute shaders parsed and validated by naga, written as PTX,
//! and assembled by `ptxas` for sm_70, sm_80 and sm_90 (skipped, saying so, where no
//! `ptxas` is on PATH, unless SDFC_REQUIRE_DEVICES=1). Set SDFC_PTX_OUT to a folder
//! to keep the PTX files.

use naga::valid::{Capabilities, ModuleInfo, ValidationFlags, Validator};
use sdfc_compiler::ptx::{self, Error, Options};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// A sphere tracer shaped like the project's renderer kernel.
const SPHERE_TRACER: &str = r#"
struct Light { position: vec4<f32>, color: vec4<f32> }
struct Material { albedo: vec4<f32>, params: vec4<f32> }
struct Params {
    resolution: vec4<f32>,
    camera_pos: vec4<f32>,
    camera_target: vec4<f32>,
    settings: vec4<f32>,
    counts: vec4<u32>,
    lights: array<Light, 4>,
    materials: array<Material, 4>,
}
struct Ray { origin: vec3<f32>, weight: f32, dir: vec3<f32>, depth: u32 }

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read_write> image: array<u32>;
@group(0) @binding(2) var<storage, read_write> stats: array<vec4<f32>>;

var<private> stack: array<Ray, 8>;
var<private> sp: i32;

const PI: f32 = 3.14159265;

fn sd_box(p: vec3<f32>, b: vec3<f32>) -> f32 {
    let q = abs(p) - b;
    return length(max(q, vec3<f32>(0.0))) + min(max(q.x, max(q.y, q.z)), 0.0);
}

fn smin(a: f32, b: f32, k: f32) -> f32 {
    let h = clamp(0.5 + 0.5 * (b - a) / k, 0.0, 1.0);
    return mix(b, a, h) - k * h * (1.0 - h);
}

fn rotate_y(p: vec3<f32>, a: f32) -> vec3<f32> {
    let c = cos(a);
    let s = sin(a);
    return vec3<f32>(c * p.x + s * p.z, p.y, -s * p.x + c * p.z);
}

fn map(p: vec3<f32>) -> vec2<f32> {
    let sphere = length(p - vec3<f32>(0.0, 1.0, 0.0)) - 1.0;
    let q = rotate_y(p - vec3<f32>(1.5, 0.5, 0.0), p.y * 0.5);
    let bx = sd_box(q, vec3<f32>(0.5, 0.5, 0.5)) - 0.05;
    let tor = vec2<f32>(length(p.xz - vec2<f32>(-1.5, 0.0)) - 0.6, p.y - 0.3);
    let torus = length(tor) - 0.2 + 0.02 * sin(atan2(p.z, p.x + 1.5) * 8.0);
    let plane = p.y + 0.001 * fract(p.x * 4.0) * step(0.5, fract(p.z * 2.0));
    var d = smin(sphere, bx, 0.3);
    var m = 1.0;
    if torus < d { d = torus; m = 3.0; }
    if plane < d { d = plane; m = 2.0; }
    let wobble = pow(abs(p.x) + 1.0, 0.5) * exp(-abs(p.z)) * 0.0;
    return vec2<f32>(d + wobble, m);
}

fn normal(p: vec3<f32>, h: f32) -> vec3<f32> {
    let k = vec2<f32>(1.0, -1.0);
    return normalize(k.xyy * map(p + k.xyy * h).x + k.yyx * map(p + k.yyx * h).x
        + k.yxy * map(p + k.yxy * h).x + k.xxx * map(p + k.xxx * h).x);
}

fn trace(ro: vec3<f32>, rd: vec3<f32>) -> vec3<f32> {
    var t = 0.01;
    var m = -1.0;
    var i = 0u;
    loop {
        if i >= params.counts.x { break; }
        let r = map(ro + rd * t);
        if abs(r.x) < params.settings.y * t { m = r.y; break; }
        t += r.x / params.settings.w;
        if t > params.settings.z { break; }
        continuing { i += 1u; }
    }
    return vec3<f32>(t, m, f32(i));
}

fn soft_shadow(ro: vec3<f32>, rd: vec3<f32>, tmax: f32, k: f32) -> f32 {
    var res = 1.0;
    var t = 0.02;
    for (var i = 0; i < 64; i++) {
        let h = map(ro + rd * t).x;
        if h < 0.0001 { return 0.0; }
        res = min(res, k * h / t);
        t += clamp(h, 0.01, 0.5);
        if t > tmax { break; }
        if res < 0.001 { continue; }
    }
    return clamp(res, 0.0, 1.0);
}

fn shade(p: vec3<f32>, n: vec3<f32>, rd: vec3<f32>, mat: Material) -> vec3<f32> {
    var c = mat.albedo.xyz * 0.05;
    let n_lights = min(params.counts.y, 4u);
    for (var i = 0u; i < n_lights; i++) {
        let light = params.lights[i];
        let to_light = light.position.xyz - p;
        let dist = length(to_light);
        let l = to_light / dist;
        let atten = 1.0 - smoothstep(0.0, light.position.w, dist);
        let sh = soft_shadow(p + n * 0.002, l, dist, light.color.w);
        let diff = max(dot(n, l), 0.0);
        let r = reflect(-l, n);
        let spec = pow(max(dot(r, -rd), 0.0), mat.params.w);
        c += sh * atten * (mat.albedo.xyz * diff + vec3<f32>(spec)) * light.color.xyz;
    }
    return c;
}

fn push(r: Ray) {
    if sp < 8 {
        stack[sp] = r;
        sp += 1;
    }
}

fn pop() -> Ray {
    sp -= 1;
    return stack[sp];
}

fn srgb(x: f32) -> u32 {
    let c = clamp(x, 0.0, 1.0);
    let s = select(1.055 * pow(c, 1.0 / 2.4) - 0.055, 12.92 * c, c <= 0.0031308);
    return u32(round(s * 255.0));
}

fn camera_ray(uv: vec2<f32>) -> vec3<f32> {
    let w = normalize(params.camera_target.xyz - params.camera_pos.xyz);
    let u = normalize(cross(w, vec3<f32>(0.0, 1.0, 0.0)));
    let v = cross(u, w);
    let b = vec2<f32>(2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y);
    let t = tan(params.settings.x * 0.5);
    let aspect = params.resolution.x * params.resolution.w;
    return normalize(w + b.x * t * aspect * u + b.y * t * v);
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>,
        @builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let width = u32(params.resolution.x);
    let height = u32(params.resolution.y);
    if gid.x >= width || gid.y >= height { return; }
    let aa = max(params.counts.z, 1u);
    var color = vec3<f32>(0.0);
    var steps = 0.0;
    var hits = 0.0;
    for (var j = 0u; j < aa; j++) {
        for (var i = 0u; i < aa; i++) {
            let off = (vec2<f32>(f32(i), f32(j)) + 0.5) / f32(aa);
            let uv = (vec2<f32>(gid.xy) + off) * params.resolution.zw;
            sp = 0;
            push(Ray(params.camera_pos.xyz, 1.0, camera_ray(uv), 0u));
            loop {
                if sp <= 0 { break; }
                let ray = pop();
                let hit = trace(ray.origin, ray.dir);
                steps += hit.z;
                if hit.y < 0.0 {
                    let sky = mix(vec3<f32>(0.6, 0.7, 0.9), vec3<f32>(0.2, 0.3, 0.6), clamp(ray.dir.y, 0.0, 1.0));
                    color += ray.weight * sky;
                    continue;
                }
                hits += 1.0;
                let p = ray.origin + ray.dir * hit.x;
                let n = normal(p, 0.0005 * hit.x);
                let mat = params.materials[u32(hit.y) & 3u];
                color += ray.weight * shade(p, n, ray.dir, mat);
                let refl = mat.params.x;
                if refl > 0.0 && ray.depth < params.counts.w {
                    push(Ray(p + n * 0.002, ray.weight * refl, reflect(ray.dir, n), ray.depth + 1u));
                }
                let transparency = mat.params.y;
                if transparency > 0.0 && ray.depth < params.counts.w {
                    let inside = dot(ray.dir, n) > 0.0;
                    let nn = select(n, -n, inside);
                    let eta = select(1.0 / mat.params.z, mat.params.z, inside);
                    var dir = refract(ray.dir, nn, eta);
                    if all(dir == vec3<f32>(0.0)) { dir = reflect(ray.dir, nn); }
                    push(Ray(p - nn * 0.002, ray.weight * transparency, dir, ray.depth + 1u));
                }
            }
        }
    }
    color /= f32(aa * aa);
    let idx = gid.y * width + gid.x;
    let rgb = vec3<u32>(srgb(color.x), srgb(color.y), srgb(color.z));
    image[idx] = rgb.x | (rgb.y << 8u) | (rgb.z << 16u) | (255u << 24u);
    let misc = asin(0.5) + acos(0.5) + atan(1.0) + exp2(0.5) + log2(3.0) + log(2.0) + inverseSqrt(4.0)
        + floor(1.5) + ceil(1.5) + sign(-2.0) + fma(1.0, 2.0, 3.0) + sqrt(steps) + f32(lid.x + wid.y + nwg.z);
    stats[idx] = vec4<f32>(steps, hits, select(0.0, 1.0, any(color > vec3<f32>(1.0))), misc * 0.0);
}
"#;

/// Every math function, one output each, over inputs from a buffer (the GPU check
/// compares these with a double-precision reference).
const MATH: &str = r#"
@group(0) @binding(0) var<storage, read> input: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> output: array<f32>;

const N: u32 = 48u;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i >= 1048576u { return; }
    let v = input[i];
    let x = v.x;
    let y = v.y;
    let z = v.z;
    let o = i * N;
    output[o + 0u] = abs(x);
    output[o + 1u] = min(x, y);
    output[o + 2u] = max(x, y);
    output[o + 3u] = clamp(x, -0.5, 0.5);
    output[o + 4u] = floor(x);
    output[o + 5u] = ceil(x);
    output[o + 6u] = fract(x);
    output[o + 7u] = round(x);
    output[o + 8u] = sqrt(x);
    output[o + 9u] = inverseSqrt(x);
    output[o + 10u] = sin(x);
    output[o + 11u] = cos(x);
    output[o + 12u] = tan(x);
    output[o + 13u] = asin(x);
    output[o + 14u] = acos(x);
    output[o + 15u] = atan(x);
    output[o + 16u] = atan2(y, x);
    output[o + 17u] = exp(x);
    output[o + 18u] = exp2(x);
    output[o + 19u] = log(x);
    output[o + 20u] = log2(x);
    output[o + 21u] = pow(x, y);
    output[o + 22u] = dot(v.xyz, vec3<f32>(y, z, x));
    let c = cross(v.xyz, vec3<f32>(z, x, y));
    output[o + 23u] = c.x + 2.0 * c.y + 4.0 * c.z;
    output[o + 24u] = length(v.xyz);
    output[o + 25u] = normalize(v.xyz).x;
    let r = reflect(v.xyz, normalize(vec3<f32>(1.0, 2.0, 3.0)));
    output[o + 26u] = r.x + r.y + r.z;
    let rf = refract(normalize(v.xyz), vec3<f32>(0.0, 1.0, 0.0), 0.75);
    output[o + 27u] = rf.x + 2.0 * rf.y + 4.0 * rf.z;
    output[o + 28u] = mix(x, y, z);
    output[o + 29u] = step(y, x);
    output[o + 30u] = smoothstep(-1.0, 2.0, x);
    output[o + 31u] = sign(x);
    output[o + 32u] = fma(x, y, z);
    output[o + 33u] = x % y;
    output[o + 34u] = x / y;
    output[o + 35u] = f32(i32(x));
    output[o + 36u] = f32(u32(x));
    output[o + 37u] = sinh(x);
    output[o + 38u] = cosh(x);
    output[o + 39u] = tanh(x);
    output[o + 40u] = asinh(x);
    output[o + 41u] = acosh(x);
    output[o + 42u] = atanh(x);
    output[o + 43u] = trunc(x);
    output[o + 44u] = degrees(x);
    output[o + 45u] = radians(x);
    output[o + 46u] = saturate(x);
    output[o + 47u] = distance(v.xyz, vec3<f32>(z, y, x));
}
"#;

/// Integer semantics, conversions, switch, nested loops and matrices.
const INTEGERS: &str = r#"
@group(0) @binding(0) var<storage, read> input: array<vec4<i32>>;
@group(0) @binding(1) var<storage, read_write> output: array<i32>;

const N: u32 = 32u;

fn collatz(n0: u32) -> u32 {
    var n = n0;
    var steps = 0u;
    while n != 1u && steps < 1000u {
        if (n & 1u) == 0u { n = n / 2u; } else { n = 3u * n + 1u; }
        steps++;
    }
    return steps;
}

fn classify(x: i32) -> i32 {
    switch x & 7 {
        case 0: { return 10; }
        case 1, 2: { return 20; }
        case 3: { if x > 100 { return 31; } return 30; }
        default: { return -1; }
    }
}

@compute @workgroup_size(32, 2, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let i = gid.x + gid.y * 32u;
    let v = input[i];
    let a = v.x;
    let b = v.y;
    let ua = u32(a);
    let ub = u32(b);
    let o = i * N;
    output[o + 0u] = a / b;
    output[o + 1u] = a % b;
    output[o + 2u] = i32(ua / ub);
    output[o + 3u] = i32(ua % ub);
    output[o + 4u] = a << u32(b);
    output[o + 5u] = a >> u32(b);
    output[o + 6u] = i32(ua >> ub);
    output[o + 7u] = a * b;
    output[o + 8u] = a - b;
    output[o + 9u] = select(a, b, a < b);
    output[o + 10u] = i32(f32(a) * 1.5e9);
    output[o + 11u] = i32(u32(f32(a) * 1.5e9));
    output[o + 12u] = classify(a);
    output[o + 13u] = i32(collatz(u32(abs(a) % 1000 + 1)));
    output[o + 14u] = countOneBits(a) + 100 * countLeadingZeros(a);
    output[o + 15u] = i32(reverseBits(ua) >> 16u);
    output[o + 16u] = countTrailingZeros(a);
    output[o + 17u] = firstLeadingBit(a);
    output[o + 18u] = min(a, b) + 3 * max(a, b);
    output[o + 19u] = clamp(a, -5, 5);
    output[o + 20u] = abs(a);
    output[o + 21u] = sign(a);
    output[o + 22u] = ~a ^ b;
    output[o + 23u] = i32(!(a > b) || (a == 3));
    var acc = 0;
    for (var k = 0; k < 10; k++) {
        if k == 3 { continue; }
        for (var m = 0; m < k; m++) {
            if m * k > 20 { break; }
            acc += m ^ k;
        }
    }
    output[o + 24u] = acc;
    let m = mat3x3<f32>(vec3<f32>(1.0, 2.0, 3.0), vec3<f32>(4.0, 5.0, 6.0), vec3<f32>(7.0, 8.0, f32(a)));
    let p = m * vec3<f32>(1.0, f32(b), 2.0);
    let q = vec3<f32>(1.0, 0.5, 0.25) * m;
    let mm = transpose(m) * m;
    output[o + 25u] = i32(p.x + 10.0 * p.y + 100.0 * p.z);
    output[o + 26u] = i32(4.0 * (q.x + q.y + q.z));
    output[o + 27u] = i32(mm[2].z + mm[1][0]);
    var arr = array<i32, 8>(1, 2, 3, 4, 5, 6, 7, 8);
    arr[u32(a) & 7u] = b;
    output[o + 28u] = arr[u32(b) & 7u] + arr[3];
    var vv = vec4<i32>(a, b, 7, 9);
    vv[u32(b) & 3u] = 100;
    output[o + 29u] = vv[u32(a) & 3u] + vv.w;
    output[o + 30u] = i32(li);
    output[o + 31u] = i32(bool(a)) + 2 * i32(f32(b) != 0.0);
}
"#;

/// Shaders the back end must refuse with an error, not a panic.
const UNSUPPORTED: &[(&str, &str)] = &[
    (
        "texture sampling",
        r#"
@group(0) @binding(0) var tex: texture_2d<f32>;
@group(0) @binding(1) var samp: sampler;
@group(0) @binding(2) var<storage, read_write> out: array<vec4<f32>>;
@compute @workgroup_size(1)
fn main() { out[0] = textureSampleLevel(tex, samp, vec2<f32>(0.5), 0.0); }
"#,
    ),
    (
        "atomics",
        r#"
@group(0) @binding(0) var<storage, read_write> counter: atomic<u32>;
@compute @workgroup_size(1)
fn main() { atomicAdd(&counter, 1u); }
"#,
    ),
    (
        "arrayLength",
        r#"
@group(0) @binding(0) var<storage, read_write> data: array<f32>;
@compute @workgroup_size(1)
fn main() { data[0] = f32(arrayLength(&data)); }
"#,
    ),
    (
        "var<workgroup>",
        r#"
var<workgroup> tile: array<f32, 64>;
@group(0) @binding(0) var<storage, read_write> data: array<f32>;
@compute @workgroup_size(64)
fn main(@builtin(local_invocation_index) i: u32) { tile[i] = data[i]; workgroupBarrier(); data[i] = tile[63u - i]; }
"#,
    ),
    (
        "f16",
        r#"
enable f16;
@group(0) @binding(0) var<storage, read_write> data: array<f32>;
@compute @workgroup_size(1)
fn main() { let h = f16(data[0]); data[0] = f32(h * h); }
"#,
    ),
];

fn parse(src: &str) -> (naga::Module, ModuleInfo) {
    let module = match naga::front::wgsl::parse_str(src) {
        Ok(m) => m,
        Err(e) => panic!("{}", e.emit_to_string(src)),
    };
    let info = Validator::new(ValidationFlags::all(), Capabilities::all())
        .validate(&module)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(src)));
    (module, info)
}

fn parse_strict(src: &str) -> (naga::Module, ModuleInfo) {
    let module =
        naga::front::wgsl::parse_str(src).unwrap_or_else(|e| panic!("{}", e.emit_to_string(src)));
    let info = Validator::new(ValidationFlags::all(), Capabilities::empty())
        .validate(&module)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(src)));
    (module, info)
}

fn options(sm: u32) -> Options {
    Options {
        sm,
        entry_point: "main".into(),
    }
}

/// The `ptxas` on PATH, if any; a missing one fails the test under SDFC_REQUIRE_DEVICES=1.
fn ptxas() -> Option<PathBuf> {
    let found = std::env::var_os("PATH").and_then(|p| {
        std::env::split_paths(&p)
            .map(|d| d.join("ptxas"))
            .find(|p| p.is_file())
    });
    if found.is_none() {
        let required = std::env::var("SDFC_REQUIRE_DEVICES").is_ok_and(|v| v == "1");
        assert!(!required, "SDFC_REQUIRE_DEVICES=1 but no ptxas on PATH");
        println!("SKIPPED: no ptxas on PATH; the PTX was written but not assembled");
    }
    found
}

/// The folder SDFC_PTX_OUT names, where the test inputs and outputs are kept.
fn keep_dir() -> Option<PathBuf> {
    let dir = PathBuf::from(std::env::var_os("SDFC_PTX_OUT")?);
    std::fs::create_dir_all(&dir).unwrap();
    Some(dir)
}

/// Keeps a file in SDFC_PTX_OUT, if set.
fn keep(file: &str, bytes: &[u8]) {
    if let Some(dir) = keep_dir() {
        std::fs::write(dir.join(file), bytes).unwrap();
    }
}

/// Assembles `text` for `sm`; returns ptxas's `-v` report.
fn assemble(ptxas: &Path, text: &str, name: &str, sm: u32) -> String {
    let path = match keep_dir() {
        Some(dir) => dir.join(format!("{name}_sm{sm}.ptx")),
        None => std::env::temp_dir().join(format!("sdfc_{name}_sm{sm}_{}.ptx", std::process::id())),
    };
    std::fs::write(&path, text).unwrap();
    let out = Command::new(ptxas)
        .args([&format!("-arch=sm_{sm}"), "-v", "-o", "/dev/null"])
        .arg(&path)
        .output()
        .expect("ptxas runs");
    let report =
        String::from_utf8_lossy(&out.stderr).into_owned() + &String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "ptxas rejected {name} for sm_{sm} ({}):\n{report}",
        path.display()
    );
    if std::env::var_os("SDFC_PTX_OUT").is_none() {
        let _ = std::fs::remove_file(&path);
    }
    report
}

/// The kernel's registers, stack and spills from a ptxas report, then each `.func`'s
/// stack and spills where it has any.
fn summary(report: &str) -> String {
    let mut out = Vec::new();
    let mut function = String::new();
    for line in report.lines().map(str::trim) {
        if let Some(f) = line.split("Function properties for ").nth(1) {
            function = f.to_string();
        } else if line.contains("stack frame")
            && (function == "main"
                || !line
                    .starts_with("0 bytes stack frame, 0 bytes spill stores, 0 bytes spill loads"))
        {
            out.push(format!("{function}: {line}"));
        } else if let Some(used) = line
            .split("info    : ")
            .nth(1)
            .filter(|l| l.starts_with("Used"))
        {
            out.push(format!("{function}: {used}"));
        }
    }
    out.join("\n    ")
}

fn check(name: &str, src: &str) {
    keep(&format!("{name}.wgsl"), src.as_bytes());
    let (module, info) = parse_strict(src);
    let ptxas = ptxas();
    for sm in [70, 80, 90] {
        let start = Instant::now();
        let text = ptx::write(&module, &info, &options(sm))
            .unwrap_or_else(|e| panic!("{name}: {e}"))
            .text;
        let took = start.elapsed();
        assert!(text.contains(&format!(".target sm_{sm}")));
        assert_eq!(
            text,
            ptx::write(&module, &info, &options(sm)).unwrap().text,
            "{name}: output is not deterministic"
        );
        println!(
            "{name} sm_{sm}: {} lines of PTX in {took:.2?}",
            text.lines().count()
        );
        if let Some(p) = &ptxas {
            println!("    {}", summary(&assemble(p, &text, name, sm)));
        }
    }
}

#[test]
fn sphere_tracer_assembles() {
    check("sphere_tracer", SPHERE_TRACER);
}

#[test]
fn math_assembles() {
    check("math", MATH);
}

#[test]
fn integers_assemble() {
    check("integers", INTEGERS);
}

#[test]
fn sphere_tracer_shape() {
    let (module, info) = parse_strict(SPHERE_TRACER);
    let text = ptx::write(&module, &info, &options(90)).unwrap().text;
    assert!(text.contains(".version 7.8"));
    assert!(text.contains(".address_size 64"));
    assert!(text.contains("workgroup size (8, 8, 1)"));
    // Three buffers, in binding order; `push` (it uses the private stack) is inlined.
    assert!(
        text.contains("main_param_0")
            && text.contains("main_param_2")
            && !text.contains("main_param_3")
    );
    assert!(!text.contains("fn_push("));
    assert!(
        text.contains(".local .align 16 .b8"),
        "the private stack lives in local memory"
    );
    assert!(text.contains("__sdfc_trig_reduce"));
}

/// What makes the PTX as fast as the same WGSL through Vulkan: f32 arithmetic with
/// subnormals flushed (no rescaling around each MUFU instruction), division as a
/// reciprocal and a multiply, uniform loads out of innermost loops, and one argument
/// reduction shared by `sin(a)` and `cos(a)`.
#[test]
fn sphere_tracer_speed_shape() {
    let (module, info) = parse_strict(SPHERE_TRACER);
    let text = ptx::write(&module, &info, &options(90)).unwrap().text;
    let instructions: Vec<&str> = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.starts_with("//") && !l.starts_with('.') && !l.ends_with(':'))
        .collect();
    // Only the large-argument reduction (its own .func, f64 inside) has a plain f32 op.
    let kernel = &text[text.find(".visible .entry").unwrap()..];
    for op in [
        "add.f32",
        "sub.f32",
        "mul.f32",
        "fma.rn.f32",
        "div.full.f32",
        "div.rn.f32",
        "sqrt.approx.f32",
        "rsqrt.approx.f32",
        "lg2.approx.f32",
        "ex2.approx.f32",
        "sin.approx.f32",
        "cos.approx.f32",
    ] {
        assert!(!kernel.contains(&format!("{op} ")), "the kernel has `{op}`");
    }
    assert!(kernel.contains("div.approx.ftz.f32"));
    assert!(kernel.contains("sqrt.approx.ftz.f32"));
    // atan2 keeps the full-range division (its ratio's terms may both pass 2^126).
    assert!(kernel.contains("div.full.ftz.f32"));
    assert!(instructions.iter().any(|l| l.starts_with("fma.rn.ftz.f32")));
    // `params.counts.x` in the march loop's condition is loaded before the loop.
    let hoisted = kernel
        .find("uniform loads hoisted out of the loop")
        .expect("a hoisted uniform load");
    let rest = &kernel[hoisted..];
    let load = rest.find("ld.global.nc.u32").unwrap();
    let head = rest.find("_loop:").unwrap();
    assert!(load < head, "the hoisted load comes before the loop's head");
    // sin(a) and cos(a) of the rotation share one reduction; the torus's sin has its own.
    let calls = kernel.matches("call (retval0), __sdfc_trig_reduce").count();
    let sines =
        kernel.matches("sin.approx.ftz.f32").count() + kernel.matches("cos.approx.ftz.f32").count();
    assert!(
        calls < sines,
        "{calls} reductions for {sines} sines and cosines: sin(a) and cos(a) share one"
    );
}

#[test]
fn unsupported_constructs_are_errors() {
    for (what, src) in UNSUPPORTED {
        let (module, info) = parse(src);
        match ptx::write(&module, &info, &options(80)) {
            Err(Error::Unsupported(msg)) => println!("{what}: {msg}"),
            other => panic!("{what}: expected an Unsupported error, got {other:?}"),
        }
    }
}

#[test]
fn bad_options_are_errors() {
    let (module, info) = parse_strict(MATH);
    let missing = Options {
        sm: 80,
        entry_point: "nope".into(),
    };
    assert_eq!(
        ptx::write(&module, &info, &missing),
        Err(Error::NoEntryPoint("nope".into()))
    );
    assert_eq!(
        ptx::write(&module, &info, &options(42)),
        Err(Error::Target(42))
    );
}

mod scenes;
