//! One wave of rays: trace them, take the normal and material at each hit, light the hits
//! (Phong with shadow rays) and spawn the next wave of reflected and refracted rays.

use super::context::{Context, Lamp, Mat, Paint, Tint};
use super::lanes::{march, Launch};
use super::look;
use super::march::{Shadow, Shadowed, Status, Trace, Traced};
use super::pbr::{self, Surface};
use super::stats::Counters;
use super::vec::V3;
use super::wave::{Evaluators, Ray, Samples, Workspace};
use sdfc_compiler::Float;

/// A surface point reached by a ray of the wave.
#[derive(Debug, Clone, Copy)]
pub(super) struct Hit<T> {
    /// Index of the ray in the wave.
    pub ray: usize,
    pub p: V3<T>,
    /// Unit outward normal (gradient of f).
    pub n: V3<T>,
    /// Path length of the pixel's ray up to `p`.
    pub tt: T,
    /// Normal step h; offsets from the surface are 4h.
    pub h: T,
    pub mat: u32,
    /// A ray inside glass reached an opaque solid within it (not the glass's far side): the
    /// hit is lit and reflects as seen from outside, within the glass.
    pub solid: bool,
    /// For such a hit, the transparency of the glass around it (sphere tracing only: a traced
    /// shadow ray finds the glass it starts inside of).
    pub medium_tau: T,
    /// What fog left of the ray's segment (1 without fog, and inside solids).
    pub fade: T,
    /// On a checker of two materials whose cells the sample's footprint both covers, their
    /// blend ([`checkered`]); `mat` is then the checker's.
    pub blend: Option<Mat<T>>,
}

impl<T: Float> Hit<T> {
    /// Its material: the table's, or the blend of a checker's two.
    pub fn material<'a>(&'a self, ctx: &'a Context<T>) -> &'a Mat<T> {
        self.blend
            .as_ref()
            .unwrap_or_else(|| ctx.material(self.mat))
    }
}

/// Traces `wave`, adds what it sees to its samples, and returns the next wave. On return
/// `ws.traced[i]` still holds how ray `i` of `wave` ended (its first hit, for camera rays).
pub(super) fn bounce<T: Float>(
    ctx: &Context<T>,
    ws: &mut Workspace<'_, T>,
    wave: &[Ray<T>],
    samples: &mut Samples<T>,
    counters: &mut Counters,
) -> Vec<Ray<T>> {
    // Fog hides what lies beyond every surface: a miss outside solids is its colour.
    let seen = |ray: &Ray<T>| {
        if ctx.inv_fog > T::zero() && !ray.inside {
            ctx.fog_colour(ray.dir)
        } else {
            ctx.background(ray.dir)
        }
    };
    let hits = surfaces(ctx, ws, wave, samples, counters, &seen);
    light(ctx, ws, wave, &hits, samples, counters);
    let next = spawn(ctx, wave, &hits);
    counters.secondary_rays += next.len() as u64;
    next
}

/// Traces `wave` and finds the surface each ray reached: its point, normal and material
/// (with the fog over the ray's segment added to its sample). A ray that reached none adds
/// `seen(ray)` with its weight. On return `ws.traced[i]` holds how ray `i` ended.
pub(super) fn surfaces<T: Float>(
    ctx: &Context<T>,
    ws: &mut Workspace<'_, T>,
    wave: &[Ray<T>],
    samples: &mut Samples<T>,
    counters: &mut Counters,
    seen: &dyn Fn(&Ray<T>) -> V3<T>,
) -> Vec<Hit<T>> {
    trace(ctx, ws, wave, counters);
    let mut hits = Vec::new();
    for (i, (ray, tr)) in wave.iter().zip(&ws.traced).enumerate() {
        samples.steps[ray.sample as usize] += tr.steps;
        counters.steps += tr.steps as u64;
        // A camera ray glows with its marching steps: glow_color·Σ e^(−|dᵢ|/G).
        if ray.depth == 0 && ctx.inv_glow > T::zero() {
            let a = &mut samples.acc[ray.sample as usize];
            *a = *a + (ray.weight * tr.glow).mul_v(ctx.glow);
        }
        match tr.status {
            Status::Hit => {
                counters.hits += 1;
                let p = ray.origin + ray.dir * tr.t;
                let tt = ray.t0 + tr.t;
                let h = ctx.normal_step(tt, p);
                // Fog over the segment (none inside solids): what it hides is its colour.
                let fade = if ray.inside {
                    T::one()
                } else {
                    look::fade(ctx, tr.t)
                };
                if fade < T::one() {
                    let a = &mut samples.acc[ray.sample as usize];
                    *a = *a + (ray.weight * (T::one() - fade)).mul_v(ctx.fog_colour(ray.dir));
                }
                hits.push(Hit {
                    ray: i,
                    p,
                    n: V3::zero(),
                    tt,
                    h,
                    mat: 0,
                    solid: false,
                    medium_tau: T::zero(),
                    fade,
                    blend: None,
                });
                continue;
            }
            Status::Miss => counters.misses += 1,
            Status::Budget => counters.budget_misses += 1,
            Status::Nan => samples.met_nan(ray.sample),
        }
        let a = &mut samples.acc[ray.sample as usize];
        *a = *a + ray.weight.mul_v(seen(ray));
    }
    if ctx.analytic.is_some() {
        for hit in &mut hits {
            (hit.n, hit.mat) = ws.surfaces[hit.ray];
            // Glass overlaps no other glass in a traced scene, so an opaque primitive that a
            // ray inside glass meets lies within that glass. Its shadow rays need no
            // `medium_tau`: `Tracer::transmitted` applies the transparency of the glass they
            // start inside of.
            hit.solid = wave[hit.ray].inside && ctx.material(hit.mat).transparency <= T::zero();
        }
    } else {
        normals(ws, wave, &mut hits);
        materials(ctx, ws, &mut hits);
        solids(ctx, ws, wave, &mut hits);
    }
    checkered(ctx, wave, &mut hits);
    hits
}

/// A hit on a checker of two materials takes the material of the cell its sample sees
/// (the checker's parity at p − 2h·N, as a checker of colours), or, where the sample's
/// footprint covers both ([`look::checker_weight`] strictly between 0 and 1), their blend
/// by that weight, whose colour is their colours' blend (docs/rendering.md, "The checker's
/// footprint").
fn checkered<T: Float>(ctx: &Context<T>, wave: &[Ray<T>], hits: &mut [Hit<T>]) {
    for hit in hits.iter_mut() {
        let Paint::Materials {
            a,
            b,
            inv_size,
            shift,
        } = ctx.material(hit.mat).paint
        else {
            continue;
        };
        let dir = wave[hit.ray].dir;
        let q = (hit.p - hit.n * (T::from_f64(2.0) * hit.h)) * inv_size + shift;
        let wb = look::checker_weight(q, hit.n, dir, hit.tt * ctx.pitch * inv_size);
        if wb <= T::zero() {
            hit.mat = a;
        } else if wb >= T::one() {
            hit.mat = b;
        } else {
            let (ma, mb) = (ctx.material(a), ctx.material(b));
            let c = colour(ctx, ma, hit, dir) * (T::one() - wb) + colour(ctx, mb, hit, dir) * wb;
            hit.blend = Some(ma.blend(mb, wb, c));
        }
    }
}

/// The evaluators of a workspace that marches: every caller runs where the context has no
/// analytic tracer, and [`Workspace::new`] gives exactly those workspaces evaluators.
fn marching<'a, 't, T: Float>(
    evaluators: &'a mut Option<Evaluators<'t, T>>,
) -> &'a mut Evaluators<'t, T> {
    evaluators
        .as_mut()
        .expect("a marched scene's workspace has its evaluators")
}

/// Traces every ray of the wave into `ws.traced`: analytically (with each hit's normal and
/// material in `ws.surfaces`) or by sphere tracing.
fn trace<T: Float>(
    ctx: &Context<T>,
    ws: &mut Workspace<'_, T>,
    wave: &[Ray<T>],
    counters: &mut Counters,
) {
    if let Some(tracer) = &ctx.analytic {
        ws.traced.clear();
        ws.surfaces.clear();
        for ray in wave {
            // Inside glass, its far side counts the offset of secondary rays farther
            // (`Tracer::nearest`), with the normal step at the ray's origin, as on the GPU.
            let slack = if ray.inside {
                T::from_f64(4.0) * ctx.normal_step(ray.t0, ray.origin)
            } else {
                T::zero()
            };
            let clear = |m: u32| {
                if ctx.material(m).transparency > T::zero() {
                    slack
                } else {
                    T::zero()
                }
            };
            let (traced, surface) = match tracer.nearest(ray.origin, ray.dir, ctx.max_dist, clear) {
                Some(s) => (
                    Traced {
                        t: s.t,
                        status: Status::Hit,
                        steps: 0,
                        glow: T::zero(),
                    },
                    (s.normal, s.material),
                ),
                None => (
                    Traced {
                        t: ctx.max_dist,
                        status: Status::Miss,
                        steps: 0,
                        glow: T::zero(),
                    },
                    (V3::zero(), 0),
                ),
            };
            ws.traced.push(traced);
            ws.surfaces.push(surface);
        }
        return;
    }
    ws.traced.clear();
    ws.traced.resize(wave.len(), Traced::default());
    let ev = marching(&mut ws.marching);
    // Where the scene has media, rays inside glass march the medium instead of the scene.
    let passes: &[Option<bool>] = if ev.media.is_some() {
        &[Some(false), Some(true)]
    } else {
        &[None]
    };
    for &pass in passes {
        ws.launches.clear();
        ws.launches.extend(
            wave.iter()
                .enumerate()
                .filter(|(_, r)| pass.is_none_or(|inside| r.inside == inside))
                .map(|(i, r)| Launch {
                    id: i as u32,
                    origin: [r.origin.x, r.origin.y, r.origin.z],
                    dir: [r.dir.x, r.dir.y, r.dir.z],
                    t0: r.t0,
                    sign: if r.inside { -T::one() } else { T::one() },
                    tmax: ctx.max_dist,
                    k: T::zero(),
                    omega: ctx.relaxation,
                    through: T::one(),
                }),
        );
        if ws.launches.is_empty() {
            continue;
        }
        let mut rule = Trace {
            ctx,
            out: &mut ws.traced,
            counters: &mut *counters,
        };
        let dist = match (pass, ev.media.as_mut()) {
            (Some(true), Some(m)) => &mut m.medium,
            _ => &mut ev.dist,
        };
        march(&mut ws.lanes, dist, &mut ev.full, &ws.launches, &mut rule);
    }
}

/// The tetrahedron's corners k_i for the 4-tap gradient.
const TETRA: [[f64; 3]; 4] = [
    [1.0, -1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [-1.0, 1.0, -1.0],
    [1.0, 1.0, 1.0],
];

/// N = normalize(Σ k_i f(p + h·k_i)); a degenerate gradient gives -D.
fn normals<T: Float>(ws: &mut Workspace<'_, T>, wave: &[Ray<T>], hits: &mut [Hit<T>]) {
    let n = hits.len() * 4;
    for v in [&mut ws.x, &mut ws.y, &mut ws.z, &mut ws.d] {
        v.clear();
        v.resize(n, T::zero());
    }
    for (i, hit) in hits.iter().enumerate() {
        for (j, k) in TETRA.iter().enumerate() {
            let q = hit.p + V3::from_f64(*k) * hit.h;
            (ws.x[4 * i + j], ws.y[4 * i + j], ws.z[4 * i + j]) = (q.x, q.y, q.z);
        }
    }
    marching(&mut ws.marching)
        .dist
        .eval(&ws.x, &ws.y, &ws.z, &mut ws.d, None);
    for (i, hit) in hits.iter_mut().enumerate() {
        let g = TETRA.iter().enumerate().fold(V3::zero(), |g, (j, k)| {
            g + V3::from_f64(*k) * ws.d[4 * i + j]
        });
        let l = g.length();
        hit.n = if l > T::zero() && !l.is_nan() {
            g * (T::one() / l)
        } else {
            -wave[hit.ray].dir
        };
    }
}

/// The material id at each hit (all 0 when the scene has one material).
fn materials<T: Float>(ctx: &Context<T>, ws: &mut Workspace<'_, T>, hits: &mut [Hit<T>]) {
    if ctx.materials.len() <= 1 || hits.is_empty() {
        return;
    }
    let n = hits.len();
    for v in [&mut ws.x, &mut ws.y, &mut ws.z, &mut ws.d] {
        v.clear();
        v.resize(n, T::zero());
    }
    ws.m.clear();
    ws.m.resize(n, 0);
    for (i, hit) in hits.iter().enumerate() {
        (ws.x[i], ws.y[i], ws.z[i]) = (hit.p.x, hit.p.y, hit.p.z);
    }
    marching(&mut ws.marching)
        .full
        .eval(&ws.x, &ws.y, &ws.z, &mut ws.d, Some(&mut ws.m));
    for (hit, &m) in hits.iter_mut().zip(&ws.m) {
        hit.mat = m;
    }
}

/// Where the scene has media, the hits of rays inside glass that reached an opaque solid
/// rather than the glass's far side: the solids' field is below the normal step there. Such
/// a hit takes the solid's material and its normal (the solids' gradient), and keeps the
/// glass's transparency for its shadow rays.
fn solids<T: Float>(
    ctx: &Context<T>,
    ws: &mut Workspace<'_, T>,
    wave: &[Ray<T>],
    hits: &mut [Hit<T>],
) {
    let Some(media) = marching(&mut ws.marching).media.as_mut() else {
        return;
    };
    let inside: Vec<usize> = (0..hits.len())
        .filter(|&i| wave[hits[i].ray].inside)
        .collect();
    if inside.is_empty() {
        return;
    }
    let n = inside.len();
    for v in [&mut ws.x, &mut ws.y, &mut ws.z, &mut ws.d] {
        v.clear();
        v.resize(4 * n, T::zero());
    }
    ws.m.clear();
    ws.m.resize(n, 0);
    for (j, &i) in inside.iter().enumerate() {
        (ws.x[j], ws.y[j], ws.z[j]) = (hits[i].p.x, hits[i].p.y, hits[i].p.z);
    }
    media.solid_full.eval(
        &ws.x[..n],
        &ws.y[..n],
        &ws.z[..n],
        &mut ws.d[..n],
        Some(&mut ws.m[..n]),
    );
    let solid: Vec<(usize, u32)> = inside
        .iter()
        .enumerate()
        .filter(|&(j, &i)| ws.d[j] < hits[i].h)
        .map(|(j, &i)| (i, ws.m[j]))
        .collect();
    if solid.is_empty() {
        return;
    }
    let n = solid.len();
    for (j, &(i, _)) in solid.iter().enumerate() {
        for (c, k) in TETRA.iter().enumerate() {
            let q = hits[i].p + V3::from_f64(*k) * hits[i].h;
            (ws.x[4 * j + c], ws.y[4 * j + c], ws.z[4 * j + c]) = (q.x, q.y, q.z);
        }
    }
    media.solid.eval(
        &ws.x[..4 * n],
        &ws.y[..4 * n],
        &ws.z[..4 * n],
        &mut ws.d[..4 * n],
        None,
    );
    for (j, &(i, m)) in solid.iter().enumerate() {
        let g = TETRA.iter().enumerate().fold(V3::zero(), |g, (c, k)| {
            g + V3::from_f64(*k) * ws.d[4 * j + c]
        });
        let l = g.length();
        let hit = &mut hits[i];
        hit.medium_tau = ctx.material(hit.mat).transparency;
        hit.solid = true;
        hit.mat = m;
        hit.n = if l > T::zero() && !l.is_nan() {
            g * (T::one() / l)
        } else {
            -wave[hit.ray].dir
        };
    }
}

/// The colour of a material at p, seen along `dir`. A checker is the parity of
/// ⌊x/s⌋ + ⌊y/s⌋ + ⌊z/s⌋ (even: first colour), sampled at p - 2h·N, just inside the surface,
/// so that a face lying on a checker boundary does not flicker between the two colours, and
/// its two colours mixed over the sample's footprint ([`look::checker_weight`]); a colour
/// field is its value at p, where the unit normal is N.
pub(super) fn colour<T: Float>(ctx: &Context<T>, m: &Mat<T>, hit: &Hit<T>, dir: V3<T>) -> V3<T> {
    let tint = |t: Tint<T>| match t {
        Tint::Const(c) => c,
        Tint::Field(k) => {
            let [r, g, b] =
                ctx.colours[k].eval([hit.p.x, hit.p.y, hit.p.z], [hit.n.x, hit.n.y, hit.n.z]);
            V3::new(r, g, b)
        }
    };
    match m.paint {
        Paint::Solid(c) => tint(c),
        Paint::Checker {
            a,
            b,
            inv_size,
            shift,
        } => {
            let q = (hit.p - hit.n * (T::from_f64(2.0) * hit.h)) * inv_size + shift;
            let wb = look::checker_weight(q, hit.n, dir, hit.tt * ctx.pitch * inv_size);
            if wb >= T::one() {
                tint(b)
            } else if wb > T::zero() {
                tint(a) * (T::one() - wb) + tint(b) * wb
            } else {
                tint(a)
            }
        }
        // Resolved at the hit ([`checkered`]): never shaded as itself.
        Paint::Materials { .. } => V3::zero(),
    }
}

/// Direction to the light, its distance (max_dist for a directional light) and its
/// attenuation. Point lights fall off as (1 - (d/r)²)² clamped to [0, 1], reaching 0 at the
/// radius r (a radius ≤ 0 or infinite means no falloff).
pub(super) fn towards<T: Float>(ctx: &Context<T>, lamp: &Lamp<T>, p: V3<T>) -> (V3<T>, T, T) {
    match *lamp {
        Lamp::Point {
            position, radius, ..
        } => {
            let v = position - p;
            let d = v.length();
            let atten = if radius > T::zero() {
                let x = d / radius;
                let f = (T::one() - x * x).clamp(T::zero(), T::one());
                f * f
            } else {
                T::one()
            };
            (v * (T::one() / d), d, atten)
        }
        Lamp::Directional { to_light, .. } => (to_light, ctx.max_dist, T::one()),
    }
}

fn lamp_colour<T: Float>(lamp: &Lamp<T>) -> (V3<T>, T) {
    match *lamp {
        Lamp::Point {
            color, sharpness, ..
        }
        | Lamp::Directional {
            color, sharpness, ..
        } => (color, sharpness),
    }
}

/// The terms of one light at a hit, before its shadow: Phong's
/// atten·(k_d·(N·L)·C·I_l + k_s·max(R·V, 0)^α·I_l), or a `pbr` surface's
/// ([`pbr::lamp`]) times atten, and the shadow ray towards the light, or `None` when the
/// light cannot contribute (N·L ≤ 0 or atten = 0).
fn lamp_term<T: Float>(
    ctx: &Context<T>,
    lamp: &Lamp<T>,
    hit: &Hit<T>,
    m: &Mat<T>,
    c: V3<T>,
    dir: V3<T>,
    surface: Option<&Surface<T>>,
) -> Option<(V3<T>, Launch<T>)> {
    let (l, dist, atten) = towards(ctx, lamp, hit.p);
    let ndl = hit.n.dot(l);
    if ndl <= T::zero() || atten <= T::zero() {
        return None;
    }
    let (il, k) = lamp_colour(lamp);
    let contrib = match surface {
        Some(s) => pbr::lamp(s, hit.n, -dir, l, il) * atten,
        None => {
            let r = hit.n * (T::from_f64(2.0) * ndl) - l;
            let rv = r.dot(-dir).max(T::zero());
            let spec = m.specular * rv.powf(m.shininess);
            (c * (m.diffuse * ndl) + V3::splat(spec)).mul_v(il) * atten
        }
    };
    let off = T::from_f64(4.0) * hit.h;
    let o = hit.p + hit.n * off;
    let tmax = if matches!(lamp, Lamp::Point { .. }) {
        dist - off
    } else {
        dist
    };
    // From a solid inside glass, the shadow ray starts inside the glass: it marches −f to
    // the glass's far side, having let through the glass's transparency.
    let (sign, through) = if hit.solid {
        (-T::one(), hit.medium_tau)
    } else {
        (T::one(), T::one())
    };
    let launch = Launch {
        id: 0,
        origin: [o.x, o.y, o.z],
        dir: [l.x, l.y, l.z],
        t0: hit.tt,
        sign,
        tmax,
        k,
        omega: T::one(),
        through,
    };
    Some((contrib, launch))
}

/// Whether a material has a local colour: Phong's 1 − r − τ > 0 (before Fresnel), always
/// for `pbr` (whose terms weigh themselves).
fn has_local<T: Float>(m: &Mat<T>) -> bool {
    m.pbr.is_some() || T::one() - m.reflect - m.transparency > T::zero()
}

/// The light of every hit seen from outside, with one shadow ray per (hit, light) that can
/// contribute: Phong's I = k_a·C + Σ shadow·atten·(k_d·max(N·L, 0)·C·I_l + k_s·max(R·V,
/// 0)^α·I_l), or a `pbr` material's emission and terms ([`pbr`]), added to the sample with
/// the weight of the local colour ([`pbr::lobes`]).
fn light<T: Float>(
    ctx: &Context<T>,
    ws: &mut Workspace<'_, T>,
    wave: &[Ray<T>],
    hits: &[Hit<T>],
    samples: &mut Samples<T>,
    counters: &mut Counters,
) {
    let mut colour_at: Vec<V3<T>> = vec![V3::zero(); hits.len()];
    let mut pending: Vec<(usize, V3<T>)> = Vec::new();
    let lit = |hit: &Hit<T>| {
        let (ray, m) = (&wave[hit.ray], hit.material(ctx));
        (!ray.inside || hit.solid) && has_local(m)
    };
    let ao = occlusions(ctx, ws, hits, &lit);
    ws.launches.clear();
    for (hi, hit) in hits.iter().enumerate() {
        let (ray, m) = (&wave[hit.ray], hit.material(ctx));
        if !lit(hit) {
            continue;
        }
        let c = colour(ctx, m, hit, ray.dir);
        let surface = m.pbr.map(|p| pbr::surface(m, p, c, hit.n, -ray.dir));
        colour_at[hi] = match &surface {
            Some(s) => s.pbr.emission,
            None => c * (m.ambient * ao[hi]),
        };
        // Sky light: Phong's k_d·C·E(N)/π, or a `pbr` surface's ([`pbr::sky`]), times the
        // occlusion where it casts shadows.
        for sky in &ctx.skies {
            let seen = if sky.occluded { ao[hi] } else { T::one() };
            let term = match &surface {
                Some(s) => pbr::sky(s, sky, hit.n, -ray.dir),
                None => c.mul_v(sky.irradiance_at(hit.n.y)) * m.diffuse,
            };
            colour_at[hi] = colour_at[hi] + term * seen;
        }
        for lamp in &ctx.lamps {
            if let Some((contrib, launch)) =
                lamp_term(ctx, lamp, hit, m, c, ray.dir, surface.as_ref())
            {
                // k < 0: a light without shadows.
                if launch.k < T::zero() {
                    colour_at[hi] = colour_at[hi] + contrib;
                    continue;
                }
                ws.launches.push(Launch {
                    id: pending.len() as u32,
                    ..launch
                });
                pending.push((hi, contrib));
            }
        }
    }
    shadows(ctx, ws, counters);
    for (&(hi, contrib), s) in pending.iter().zip(&ws.shadowed) {
        colour_at[hi] = colour_at[hi] + contrib * s.light;
        let sample = wave[hits[hi].ray].sample;
        samples.steps[sample as usize] += s.steps;
        counters.steps += s.steps as u64;
        if s.nan {
            samples.met_nan(sample);
        }
    }
    for (hit, c) in hits.iter().zip(colour_at) {
        let (ray, m) = (&wave[hit.ray], hit.material(ctx));
        if lit(hit) {
            let w = pbr::local_weight(m, hit.n, ray.dir);
            let a = &mut samples.acc[ray.sample as usize];
            *a = *a + c.mul_v(ray.weight * hit.fade) * w;
        }
    }
}

/// The ambient occlusion at each hit (1 where the scene has none, at hits that are not lit,
/// and at a solid inside glass, whose surroundings the field does not describe).
fn occlusions<T: Float>(
    ctx: &Context<T>,
    ws: &mut Workspace<'_, T>,
    hits: &[Hit<T>],
    lit: &impl Fn(&Hit<T>) -> bool,
) -> Vec<T> {
    let mut ao = vec![T::one(); hits.len()];
    if ctx.occlusion <= T::zero() || ctx.analytic.is_some() {
        return ao;
    }
    let at: Vec<usize> = (0..hits.len())
        .filter(|&i| lit(&hits[i]) && !hits[i].solid)
        .collect();
    if at.is_empty() {
        return ao;
    }
    let points: Vec<(V3<T>, V3<T>)> = at.iter().map(|&i| (hits[i].p, hits[i].n)).collect();
    let buffers = [&mut ws.x, &mut ws.y, &mut ws.z, &mut ws.d];
    let found = look::occlusion(ctx, marching(&mut ws.marching), buffers, &points);
    for (&i, v) in at.iter().zip(found) {
        ao[i] = v;
    }
    ao
}

/// Marches the shadow rays of `ws.launches` into `ws.shadowed`.
pub(super) fn shadows<T: Float>(
    ctx: &Context<T>,
    ws: &mut Workspace<'_, T>,
    counters: &mut Counters,
) {
    counters.shadow_rays += ws.launches.len() as u64;
    ws.shadowed.clear();
    if let Some(tracer) = &ctx.analytic {
        for l in &ws.launches {
            let (o, d) = (
                V3::new(l.origin[0], l.origin[1], l.origin[2]),
                V3::new(l.dir[0], l.dir[1], l.dir[2]),
            );
            // Where shadow rays do not pass transparent surfaces (`Context::transparent`
            // is off: none is, or the path tracer's are opaque to them), all are opaque.
            let light = tracer.transmitted(o, d, l.tmax, |m| {
                if ctx.transparent {
                    ctx.material(m).transparency
                } else {
                    T::zero()
                }
            });
            ws.shadowed.push(Shadowed {
                light,
                steps: 0,
                nan: false,
            });
        }
        return;
    }
    ws.shadowed.resize(ws.launches.len(), Shadowed::default());
    let mut rule = Shadow {
        ctx,
        out: &mut ws.shadowed,
        counters,
    };
    let ev = marching(&mut ws.marching);
    march(
        &mut ws.lanes,
        &mut ev.dist,
        &mut ev.full,
        &ws.launches,
        &mut rule,
    );
}

/// The transmitted direction through a surface of normal `n` (facing the incoming ray) with
/// ratio of indices `eta`, or `None` on total internal reflection.
pub(super) fn refract<T: Float>(d: V3<T>, n: V3<T>, eta: T) -> Option<V3<T>> {
    let cosi = -d.dot(n);
    let k = T::one() - eta * eta * (T::one() - cosi * cosi);
    if k < T::zero() {
        None
    } else {
        Some((d * eta + n * (eta * cosi - k.sqrt())).normalize())
    }
}

/// The next wave. From outside: a reflection (weight r) and a refraction into the solid
/// (weight τ). From inside (an exit): the refraction out, or on total internal reflection
/// the reflection back inside, with the ray's whole weight. Only below `max_depth`.
fn spawn<T: Float>(ctx: &Context<T>, wave: &[Ray<T>], hits: &[Hit<T>]) -> Vec<Ray<T>> {
    // At most `branching` rays per hit below `max_depth`: the vector never grows past
    // this, and allocates nothing at `max_depth` (`super::memory` counts on both).
    let below = hits
        .iter()
        .filter(|h| wave[h.ray].depth < ctx.max_depth)
        .count();
    let mut next = Vec::with_capacity(below * ctx.branching);
    for hit in hits {
        let ray = &wave[hit.ray];
        if ray.depth >= ctx.max_depth {
            continue;
        }
        let m = hit.material(ctx);
        let off = hit.n * (T::from_f64(4.0) * hit.h);
        let weight = ray.weight * hit.fade;
        let child = |origin, dir, weight, inside| ray.child(hit.tt, origin, dir, weight, inside);
        if ray.inside && !hit.solid {
            match refract(ray.dir, -hit.n, m.ior) {
                Some(t) => next.push(child(hit.p + off, t, weight, false)),
                None => next.push(child(hit.p - off, ray.dir.reflect(hit.n), weight, true)),
            }
            continue;
        }
        // A solid's surface inside glass faces the glass: what leaves it stays inside.
        let within = hit.solid;
        let lobes = pbr::lobes(m, hit.n, ray.dir, || colour(ctx, m, hit, ray.dir));
        // A reflection of no weight (Fresnel's rim facing the camera) is not traced.
        if m.reflects && lobes.reflect.max_abs() > T::zero() {
            next.push(child(
                hit.p + off,
                ray.dir.reflect(hit.n),
                weight.mul_v(lobes.reflect),
                within,
            ));
        }
        if m.transparency > T::zero() {
            let weight = weight.mul_v(lobes.transmit);
            match refract(ray.dir, hit.n, T::one() / m.ior) {
                Some(t) => next.push(child(hit.p - off, t, weight, true)),
                None => next.push(child(hit.p + off, ray.dir.reflect(hit.n), weight, within)),
            }
        }
    }
    next
}
