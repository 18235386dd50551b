//! Text in a kernel: the outlines a distance program reads ([`Op::Outline`]) appended to
//! `scene_data` as data, and the WGSL function that walks them, `text_outline`, which follows
//! `program/outline.rs` step for step. A paragraph is more data, not more code: the kernel's
//! text grows by one constant per outline.
//!
//! [`Op::Outline`]: crate::program::Op::Outline

use crate::program::outline::Outline;
use crate::program::Program;
use std::fmt::Write;
use std::sync::Arc;

/// The name of the constant holding the index in `scene_data` of the outline's first word:
/// named by its contents, so that every program of a kernel (and the cut of one into its
/// rest and instances) names one outline alike.
pub fn name(o: &Outline) -> String {
    // FNV-1a over the bits of the words.
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for w in o.words() {
        for v in w {
            for b in v.to_bits().to_le_bytes() {
                h ^= u64::from(b);
                h = h.wrapping_mul(0x0100_0000_01b3);
            }
        }
    }
    format!("GLYPHS_{h:016x}")
}

/// The distinct outlines of `programs`, by [`name`], in order of first use.
pub fn collect(programs: &[&Program]) -> Vec<(String, Arc<Outline>)> {
    let mut out: Vec<(String, Arc<Outline>)> = Vec::new();
    for p in programs {
        for o in p.outlines() {
            let n = name(o);
            if !out.iter().any(|(m, _)| *m == n) {
                out.push((n, o.clone()));
            }
        }
    }
    out
}

/// Appends the outlines of `programs` to the bytes of `scene_data` (made where there are
/// none) and returns the WGSL that reads them (their constants and `text_outline`), or
/// nothing where the programs read none.
pub(super) fn append(programs: &[&Program], data: &mut Option<Vec<u8>>) -> String {
    let outlines = collect(programs);
    if outlines.is_empty() {
        return String::new();
    }
    let bytes = data.get_or_insert_with(Vec::new);
    bytes.resize(bytes.len().div_ceil(16) * 16, 0);
    let mut text = String::from(
        "// The outlines of text, read from scene_data (layout: compiler/src/program/outline.rs).\n",
    );
    for (n, o) in &outlines {
        let _ = writeln!(text, "const {n}: u32 = {}u;", bytes.len() / 16);
        for w in o.words() {
            for v in w {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    text.push('\n');
    text.push_str(&functions("", "scene_data"));
    text
}

/// The outlines of `program` for a part (`--part map`) named `name`: their constants, the
/// words as a private array `{name}_glyphs` (a part has no buffers), and the functions, every
/// name starting with `name`; nothing where the program reads no outline.
pub fn part(program: &Program, name: &str) -> String {
    let outlines = collect(&[program]);
    if outlines.is_empty() {
        return String::new();
    }
    let mut text =
        String::from("// The outlines of text (layout: compiler/src/program/outline.rs).\n");
    let mut words: Vec<[f32; 4]> = Vec::new();
    for (n, o) in &outlines {
        let _ = writeln!(text, "const {name}_{n}: u32 = {}u;", words.len());
        words.extend(o.words());
    }
    let _ = writeln!(
        text,
        "var<private> {name}_glyphs: array<vec4<f32>, {}> = array<vec4<f32>, {}>(",
        words.len(),
        words.len()
    );
    for w in &words {
        let v: Vec<String> = w
            .iter()
            .map(|&x| super::literal::float(f64::from(x)))
            .collect();
        let _ = writeln!(text, "    vec4<f32>({}),", v.join(", "));
    }
    text.push_str(");\n\n");
    text.push_str(&functions(&format!("{name}_"), &format!("{name}_glyphs")));
    text
}

/// The calls of a program's WGSL (map.rs) made to read a part's outlines: its functions and
/// constants prefixed by `name`.
pub fn rename_calls(map: &str, name: &str) -> String {
    map.replace(
        "text_outline(GLYPHS_",
        &format!("{name}_text_outline({name}_GLYPHS_"),
    )
}

/// [`FUNCTIONS`] with their names prefixed by `prefix` and reading the words from `data`.
pub(super) fn functions(prefix: &str, data: &str) -> String {
    FUNCTIONS
        .replace("STACKu", &format!("{}u", crate::program::outline::STACK))
        .replace("text_", &format!("{prefix}text_"))
        .replace("scene_data[", &format!("{data}["))
}

/// `text_outline` and its parts: `program/outline.rs`'s `distance`, `line`, `crossing` and
/// `quad` in WGSL, operation for operation.
const FUNCTIONS: &str = r#"// The squared distance to the line from a to c, and its crossing of the ray from q towards +x.
fn text_line(a: vec2<f32>, c: vec2<f32>, q: vec2<f32>) -> vec2<f32> {
    let e = c - a;
    let w = q - a;
    let t = clamp((w.x * e.x + w.y * e.y) / (e.x * e.x + e.y * e.y), 0.0, 1.0);
    let d = w - e * t;
    let cross = e.x * w.y - e.y * w.x;
    var k = 0.0;
    if a.y <= q.y && q.y < c.y && cross > 0.0 {
        k = 1.0;
    }
    if c.y <= q.y && q.y < a.y && cross < 0.0 {
        k = -1.0;
    }
    return vec2<f32>(d.x * d.x + d.y * d.y, k);
}

// The crossing of the ray from q towards +x by the curve a, b, c (monotone in y).
fn text_crossing(a: vec2<f32>, b: vec2<f32>, c: vec2<f32>, q: vec2<f32>) -> i32 {
    let up = a.y <= q.y && q.y < c.y;
    let down = c.y <= q.y && q.y < a.y;
    if !(up || down) {
        return 0i;
    }
    let s = select(-1.0, 1.0, up);
    let qa = a.y - 2.0 * b.y + c.y;
    let qb = 2.0 * (b.y - a.y);
    let qc = a.y - q.y;
    let disc = max(qb * qb - 4.0 * qa * qc, 0.0);
    let r = -0.5 * (qb + s * sqrt(disc));
    var t = 0.0;
    if r != 0.0 {
        t = clamp(qc / r, 0.0, 1.0);
    }
    let u = 1.0 - t;
    let xt = a.x * u * u + 2.0 * b.x * t * u + c.x * t * t;
    if xt > q.x {
        return select(-1i, 1i, up);
    }
    return 0i;
}

fn text_cbrt(v: f32) -> f32 {
    let r = pow(abs(v), 0.3333333333333333);
    return select(r, -r, v < 0.0);
}

// The squared distance to the curve a, b, c (Quilez's sdBezier, each root refined by a
// Newton step, the ends candidates too).
fn text_quad(a: vec2<f32>, b: vec2<f32>, c: vec2<f32>, q: vec2<f32>) -> f32 {
    let ea = b - a;
    let eb = vec2<f32>(a.x - 2.0 * b.x + c.x, a.y - 2.0 * b.y + c.y);
    let ec = 2.0 * ea;
    let ed = a - q;
    let kk = 1.0 / (eb.x * eb.x + eb.y * eb.y);
    let kx = kk * (ea.x * eb.x + ea.y * eb.y);
    let ky = kk * (2.0 * (ea.x * ea.x + ea.y * ea.y) + (ed.x * eb.x + ed.y * eb.y)) / 3.0;
    let kz = kk * (ed.x * ea.x + ed.y * ea.y);
    let p = ky - kx * kx;
    let r = kx * (2.0 * kx * kx - 3.0 * ky) + kz;
    let h = r * r + 4.0 * p * p * p;
    var t1: f32;
    var t2: f32;
    if h >= 0.0 {
        let hs = sqrt(h);
        t1 = text_cbrt((hs - r) / 2.0) + text_cbrt((-hs - r) / 2.0) - kx;
        t2 = t1;
    } else {
        let z = sqrt(-p);
        let v = acos(clamp(r / (p * z * 2.0), -1.0, 1.0)) / 3.0;
        let m = cos(v);
        let n = sin(v) * 1.732050808;
        t1 = (m + m) * z - kx;
        t2 = (-n - m) * z - kx;
    }
    let f1 = text_at(ea, eb, ec, ed, text_newton(ea, eb, ec, ed, t1));
    let f2 = text_at(ea, eb, ec, ed, text_newton(ea, eb, ec, ed, t2));
    let end = c - q;
    return min(min(min(ed.x * ed.x + ed.y * ed.y, end.x * end.x + end.y * end.y),
        f1.x * f1.x + f1.y * f1.y), f2.x * f2.x + f2.y * f2.y);
}

// The point of the curve at t, less the point.
fn text_at(ea: vec2<f32>, eb: vec2<f32>, ec: vec2<f32>, ed: vec2<f32>, t: f32) -> vec2<f32> {
    return vec2<f32>(ed.x + (ec.x + eb.x * t) * t, ed.y + (ec.y + eb.y * t) * t);
}

fn text_newton(ea: vec2<f32>, eb: vec2<f32>, ec: vec2<f32>, ed: vec2<f32>, t0: f32) -> f32 {
    let t = clamp(t0, 0.0, 1.0);
    let f = text_at(ea, eb, ec, ed, t);
    let e = vec2<f32>(ea.x + eb.x * t, ea.y + eb.y * t);
    let g = f.x * e.x + f.y * e.y;
    let gp = 2.0 * (e.x * e.x + e.y * e.y) + (f.x * eb.x + f.y * eb.y);
    if gp > 0.0 {
        return clamp(t - g / gp, 0.0, 1.0);
    }
    return t;
}

// The squared distance to the box (lo.x, lo.y, hi.x, hi.y) of a node, 0 inside it.
fn text_gap(bx: vec4<f32>, q: vec2<f32>) -> f32 {
    let dx = max(max(bx.x - q.x, q.x - bx.z), 0.0);
    let dy = max(max(bx.y - q.y, q.y - bx.w), 0.0);
    return dx * dx + dy * dy;
}

// The signed distance at q to the outline whose words start at scene_data[base]: the
// nearest of its curves, negative where their winding number is not zero, found through the
// hierarchy of its glyphs' boxes, the nearer child first; a node outside whose box the point
// is, no nearer than the best so far, is skipped.
fn text_outline(base: u32, q: vec2<f32>) -> f32 {
    var best = 3e38;
    var wind = 0i;
    // Each entry: a node and its box's squared distance, tested again when it is taken off.
    var stack: array<u32, STACKu>;
    var gaps: array<f32, STACKu>;
    stack[0] = 0u;
    gaps[0] = text_gap(scene_data[base + 1u], q);
    var top = 1u;
    while top > 0u {
        top -= 1u;
        let n = base + 1u + 2u * stack[top];
        let gap = gaps[top];
        if gap > 0.0 && gap >= best {
            continue;
        }
        let link = scene_data[n + 1u];
        if link.z == 0.0 {
            // The nearer child on top, so that it is visited first.
            let l = u32(link.x);
            let gl = text_gap(scene_data[base + 1u + 2u * l], q);
            let gr = text_gap(scene_data[base + 3u + 2u * l], q);
            let right = gr < gl;
            let gn = select(gl, gr, right);
            let gf = select(gr, gl, right);
            if !(gf > 0.0 && gf >= best) {
                stack[top] = select(l + 1u, l, right);
                gaps[top] = gf;
                top += 1u;
            }
            if !(gn > 0.0 && gn >= best) {
                stack[top] = select(l, l + 1u, right);
                gaps[top] = gn;
                top += 1u;
            }
            continue;
        }
        let first = base + u32(link.x);
        let next = first + 2u * u32(link.y);
        for (var s = first; s < next; s += 2u) {
            let w0 = scene_data[s];
            let w1 = scene_data[s + 1u];
            let a = w0.xy;
            let c = w1.xy;
            if w1.z != 0.0 {
                let l = text_line(a, c, q);
                best = select(best, l.x, l.x < best);
                wind += i32(l.y);
            } else {
                let b = w0.zw;
                let lx = min(min(a.x, b.x), c.x);
                let hx = max(max(a.x, b.x), c.x);
                let ly = min(min(a.y, b.y), c.y);
                let hy = max(max(a.y, b.y), c.y);
                let gx = max(max(lx - q.x, q.x - hx), 0.0);
                let gy = max(max(ly - q.y, q.y - hy), 0.0);
                if gx * gx + gy * gy < best {
                    let d2 = text_quad(a, b, c, q);
                    best = select(best, d2, d2 < best);
                }
                wind += text_crossing(a, b, c, q);
            }
        }
    }
    let d = sqrt(best);
    return select(d, -d, wind != 0i);
}
"#;
