//! The path tracer (docs/rendering.md, "Path tracing"): `samples` paths a pixel, each a camera
//! ray through a jittered point of the pixel continued by one ray a hit, drawn from the
//! material's BRDF, for up to `bounces` bounces, with next-event estimates of the lamps and
//! the skies at every hit, the skies' weighed against the BRDF's by multiple importance
//! sampling, and Russian roulette. Every number comes from the counter-based stream of
//! `sdfc_compiler::sampling`, so the kernel draws the same ones.
//!
//! Surfaces are found as the Whitted renderer finds them (`shade::surfaces`: analytic
//! tracing or sphere tracing), one wave of rays a bounce; a tile renders its pixels' paths one
//! sample at a time, so a wave holds at most a ray a pixel.

use super::context::{Context, Lamp, Mat};
use super::lanes::Launch;
use super::pbr::{self, Surface};
use super::shade::{self, Hit};
use super::stats::Counters;
use super::tile::{Rect, TileOut};
use super::vec::V3;
use super::wave::{Ray, Samples, Workspace};
use sdfc_compiler::sampling::{self, dim};
use sdfc_compiler::Float;

const PI: f64 = std::f64::consts::PI;

/// Renders one tile by path tracing.
pub(super) fn render<T: Float>(ctx: &Context<T>, ws: &mut Workspace<'_, T>, rect: Rect) -> TileOut {
    let n = (rect.w * rect.h) as usize;
    let mut sum = vec![V3::<T>::zero(); n];
    let mut steps = vec![0u32; n];
    let mut nan = vec![false; n];
    let mut first = vec![(T::zero(), 0u32); n];
    let mut counters = Counters::default();
    for k in 0..ctx.samples {
        let sample = ctx.first_sample.wrapping_add(k);
        let mut samples = Samples::new(n, ctx.debug_nan);
        let camera = camera_rays(ctx, rect, sample);
        counters.camera_rays += n as u64;
        let mut wave = step(ctx, ws, &camera, rect, sample, &mut samples, &mut counters);
        for (f, tr) in first.iter_mut().zip(&ws.traced) {
            if tr.status == super::march::Status::Hit {
                *f = (f.0 + tr.t, f.1 + 1);
            }
        }
        while !wave.is_empty() {
            wave = step(ctx, ws, &wave, rect, sample, &mut samples, &mut counters);
        }
        for i in 0..n {
            sum[i] = sum[i] + samples.acc[i];
            steps[i] += samples.steps[i];
            nan[i] |= samples.nan.get(i).copied().unwrap_or(false);
        }
    }
    let scale = T::one() / T::from_f64(ctx.samples as f64);
    let pixels = sum
        .iter()
        .zip(&nan)
        .map(|(&c, &met)| {
            if met {
                return super::NAN_COLOUR;
            }
            let c = super::look::grade(ctx, c * scale);
            [
                c.x.to_f64() as f32,
                c.y.to_f64() as f32,
                c.z.to_f64() as f32,
            ]
        })
        .collect();
    let (distance, coverage) = first
        .iter()
        .map(|&(t, hits)| {
            let d = if hits == 0 {
                f32::NAN
            } else {
                (t / T::from_f64(hits as f64)).to_f64() as f32
            };
            (d, hits as f32 / ctx.samples as f32)
        })
        .unzip();
    TileOut {
        pixels,
        steps,
        distance,
        coverage,
        counters,
    }
}

/// The number of the pixel of index `i` within the tile in the image, `y·width + x`.
fn pixel_of(rect: Rect, width: u32, i: u32) -> u32 {
    (rect.y + i / rect.w) * width + rect.x + i % rect.w
}

/// The camera rays of one sample of every pixel of the tile, through the point of the pixel
/// the stream's first two numbers pick.
fn camera_rays<T: Float>(ctx: &Context<T>, rect: Rect, sample: u32) -> Vec<Ray<T>> {
    (0..rect.w * rect.h)
        .map(|i| {
            let pixel = pixel_of(rect, ctx.width, i);
            let u = |d: u32| sampling::uniform::<T>(pixel, sample, sampling::CAMERA, d);
            let (x, y) = (rect.x + i % rect.w, rect.y + i / rect.w);
            Ray {
                origin: ctx.camera.origin(),
                dir: ctx
                    .camera
                    .jittered(x, y, u(dim::JITTER[0]), u(dim::JITTER[1])),
                t0: T::zero(),
                weight: V3::splat(T::one()),
                sample: i,
                depth: 0,
                inside: false,
                pdf: T::zero(),
                sky_pdf: T::zero(),
            }
        })
        .collect()
}

fn from<T: Float>(v: [T; 3]) -> V3<T> {
    V3::new(v[0], v[1], v[2])
}

fn mean<T: Float>(v: V3<T>) -> T {
    (v.x + v.y + v.z) / T::from_f64(3.0)
}

/// A material at a hit as the path tracer sees it: the part that scatters over directions
/// (Lambert's diffuse for Phong, with its highlight for lamps alone; diffuse and GGX for
/// `pbr`), a mirror and a refraction, each picked with a probability in proportion to its
/// mean weight.
struct Bsdf<T> {
    n: V3<T>,
    v: V3<T>,
    kind: Kind<T>,
    /// The probabilities of the scattering part, the mirror and the refraction (summing to
    /// 1, or all 0 where the material reflects nothing).
    p: [T; 3],
    /// The weights of the mirror and of the refraction.
    reflect: V3<T>,
    transmit: V3<T>,
}

enum Kind<T> {
    /// Lambert's `diffuse/π` (`diffuse` = `w·k_d·C`, `w` the local weight), and for lamps
    /// Phong's highlight `spec·max(R·V, 0)^shininess` as the Whitted renderer adds it.
    Phong {
        diffuse: V3<T>,
        spec: T,
        shininess: T,
    },
    /// `pbr`'s diffuse and GGX lobes ([`pbr::lamp`] over π), the GGX lobe drawn with
    /// probability `q`, the diffuse one otherwise.
    Pbr { s: Surface<T>, q: T },
}

impl<T: Float> Bsdf<T> {
    fn new(m: &Mat<T>, c: V3<T>, n: V3<T>, d: V3<T>) -> Self {
        let v = -d;
        let (kind, a_s, reflect, transmit) = match m.pbr {
            Some(p) => {
                let s = pbr::surface(m, p, c, n, v);
                let one = V3::splat(T::one());
                let spec = mean(s.albedo);
                let diffuse = mean((one - s.albedo).mul_v(c)) * s.kd;
                let a = spec + diffuse;
                let q = if a > T::zero() { spec / a } else { T::zero() };
                let transmit = (one - s.albedo).mul_v(c) * m.transparency;
                (Kind::Pbr { s, q }, a, V3::zero(), transmit)
            }
            None => {
                let l = pbr::lobes(m, n, d, V3::zero);
                let diffuse = c * (l.local * m.diffuse);
                let reflect = if m.reflects { l.reflect } else { V3::zero() };
                let transmit = if m.transparency > T::zero() {
                    l.transmit
                } else {
                    V3::zero()
                };
                let kind = Kind::Phong {
                    diffuse,
                    spec: l.local * m.specular,
                    shininess: m.shininess,
                };
                (kind, mean(diffuse).max(T::zero()), reflect, transmit)
            }
        };
        let (a_r, a_t) = (mean(reflect).max(T::zero()), mean(transmit).max(T::zero()));
        let total = a_s + a_r + a_t;
        let p = if total > T::zero() {
            [a_s / total, a_r / total, a_t / total]
        } else {
            [T::zero(); 3]
        };
        Bsdf {
            n,
            v,
            kind,
            p,
            reflect,
            transmit,
        }
    }

    /// `f(l)·(N·L)` of the scattering part (0 below the surface).
    fn eval(&self, l: V3<T>) -> V3<T> {
        let nl = self.n.dot(l);
        if nl <= T::zero() {
            return V3::zero();
        }
        match &self.kind {
            Kind::Phong { diffuse, .. } => *diffuse * (nl / T::from_f64(PI)),
            Kind::Pbr { s, .. } => {
                pbr::lamp(s, self.n, self.v, l, V3::splat(T::one())) * T::from_f64(1.0 / PI)
            }
        }
    }

    /// The density with which [`draw`] draws `l` (its scattering part's; 0 below
    /// the surface).
    fn pdf(&self, l: V3<T>) -> T {
        let nl = self.n.dot(l);
        if nl <= T::zero() {
            return T::zero();
        }
        let cosine = nl / T::from_f64(PI);
        let within = match &self.kind {
            Kind::Phong { .. } => cosine,
            Kind::Pbr { s, q } => {
                let h = (l + self.v).normalize();
                let ggx = sampling::ggx_pdf(self.n.dot(h), self.v.dot(h), s.pbr.alpha);
                *q * ggx + (T::one() - *q) * cosine
            }
        };
        self.p[0] * within
    }

    /// A lamp's light of colour `il` from `l`, before attenuation and shadow, where `N·L > 0`:
    /// the Whitted renderer's term (Phong's diffuse and highlight times the local weight, or
    /// [`pbr::lamp`]).
    fn lamp(&self, l: V3<T>, il: V3<T>) -> V3<T> {
        let nl = self.n.dot(l);
        match &self.kind {
            Kind::Phong {
                diffuse,
                spec,
                shininess,
            } => {
                let r = self.n * (T::from_f64(2.0) * nl) - l;
                let rv = r.dot(self.v).max(T::zero());
                (*diffuse * nl + V3::splat(*spec * rv.powf(*shininess))).mul_v(il)
            }
            Kind::Pbr { s, .. } => pbr::lamp(s, self.n, self.v, l, il),
        }
    }
}

/// How a continued path leaves a hit.
enum Lobe {
    Scatter,
    Mirror,
    Refract,
}

/// Draws the continued path's lobe and direction from `u` (the hit's numbers of
/// [`dim::LOBE`] and [`dim::DIRECTION`]): the direction, the factor its weight takes
/// (`f·cos/pdf`, or a delta lobe's weight over its probability), the density for the
/// sky's weight (0 for a delta lobe) and the lobe.
fn draw<T: Float>(b: &Bsdf<T>, u: [T; 3]) -> Option<(V3<T>, V3<T>, T, Lobe)> {
    let [p_s, p_r, p_t] = b.p;
    if u[0] < p_s {
        let l = match &b.kind {
            Kind::Pbr { s, q } if u[0] / p_s < *q => {
                let h = from(sampling::to_world(
                    sampling::ggx_half(u[1], u[2], s.pbr.alpha),
                    [b.n.x, b.n.y, b.n.z],
                ));
                h * (T::from_f64(2.0) * b.v.dot(h)) - b.v
            }
            _ => from(sampling::to_world(
                sampling::cosine(u[1], u[2]),
                [b.n.x, b.n.y, b.n.z],
            )),
        };
        let pdf = b.pdf(l);
        if pdf <= T::zero() {
            return None;
        }
        return Some((l, b.eval(l) * (T::one() / pdf), pdf, Lobe::Scatter));
    }
    if u[0] < p_s + p_r {
        let d = -b.v;
        return Some((
            d.reflect(b.n),
            b.reflect * (T::one() / p_r),
            T::zero(),
            Lobe::Mirror,
        ));
    }
    if p_t > T::zero() {
        return Some((
            -b.v,
            b.transmit * (T::one() / p_t),
            T::zero(),
            Lobe::Refract,
        ));
    }
    None
}

/// Traces one wave of the sample's paths: adds what each ray sees (a miss: the sky, weighed
/// against the sky's estimate at the ray's origin; a hit: its emission and the estimates of
/// the lamps and skies, through hard shadow rays) and returns the rays that continue them.
fn step<T: Float>(
    ctx: &Context<T>,
    ws: &mut Workspace<'_, T>,
    wave: &[Ray<T>],
    rect: Rect,
    sample: u32,
    samples: &mut Samples<T>,
    counters: &mut Counters,
) -> Vec<Ray<T>> {
    let seen = |ray: &Ray<T>| {
        // Fog hides what lies beyond every surface: a miss outside solids is its colour.
        if ctx.inv_fog > T::zero() && !ray.inside {
            return ctx.fog_colour(ray.dir);
        }
        if ray.depth == 0 {
            return ctx.background(ray.dir);
        }
        let w = if ray.pdf > T::zero() {
            sampling::power(ray.pdf, ray.sky_pdf)
        } else {
            T::one()
        };
        let rest = if ctx.sky_background {
            V3::zero()
        } else {
            ctx.background
        };
        ctx.sky_radiance(ray.dir) * w + rest
    };
    let hits = shade::surfaces(ctx, ws, wave, samples, counters, &seen);
    ws.launches.clear();
    // Each estimate: its sample, its light and whether a shadow ray (the next launch) decides it.
    let mut pending: Vec<(u32, V3<T>, bool)> = Vec::new();
    let mut next = Vec::with_capacity(hits.len());
    for hit in &hits {
        let ray = &wave[hit.ray];
        let pixel = pixel_of(rect, ctx.width, ray.sample);
        let u = |d: u32| sampling::uniform::<T>(pixel, sample, ray.depth + 1, d);
        let weight = ray.weight * hit.fade;
        let m = hit.material(ctx);
        let more = ray.depth < ctx.bounces;
        let off = hit.n * (T::from_f64(4.0) * hit.h);
        let child = |origin: V3<T>, dir: V3<T>, weight: V3<T>, inside: bool, pdf: T| Ray {
            pdf,
            sky_pdf: hit.n.dot(dir).max(T::zero()) / T::from_f64(PI),
            ..ray.child(hit.tt, origin, dir, weight, inside)
        };
        if ray.inside && !hit.solid {
            // Leaving the solid: refract out, or reflect back in on total internal reflection.
            if more {
                let out = match shade::refract(ray.dir, -hit.n, m.ior) {
                    Some(t) => child(hit.p + off, t, weight, false, T::zero()),
                    None => child(hit.p - off, ray.dir.reflect(hit.n), weight, true, T::zero()),
                };
                next.extend(roulette(out, u(dim::ROULETTE)));
            }
            continue;
        }
        let b = Bsdf::new(m, shade::colour(ctx, m, hit, ray.dir), hit.n, ray.dir);
        if let Some(p) = m.pbr {
            let a = &mut samples.acc[ray.sample as usize];
            *a = *a + weight.mul_v(p.emission);
        }
        // A solid inside glass gets its light through the glass, along the paths alone.
        if !hit.solid {
            estimates(ctx, ws, hit, &b, weight, more, &u, ray.sample, &mut pending);
        }
        if !more {
            continue;
        }
        let drawn = [u(dim::LOBE), u(dim::DIRECTION[0]), u(dim::DIRECTION[1])];
        let Some((dir, factor, pdf, lobe)) = draw(&b, drawn) else {
            continue;
        };
        let weight = weight.mul_v(factor);
        // From a solid within glass what leaves stays inside the glass, and the sky it may
        // reach had no estimate there.
        let within = hit.solid;
        let pdf = if within { T::zero() } else { pdf };
        let ray = match lobe {
            Lobe::Scatter | Lobe::Mirror => child(hit.p + off, dir, weight, within, pdf),
            Lobe::Refract => match shade::refract(ray.dir, hit.n, T::one() / m.ior) {
                Some(t) => child(hit.p - off, t, weight, true, T::zero()),
                None => child(
                    hit.p + off,
                    ray.dir.reflect(hit.n),
                    weight,
                    within,
                    T::zero(),
                ),
            },
        };
        next.extend(roulette(ray, u(dim::ROULETTE)));
    }
    shade::shadows(ctx, ws, counters);
    let mut shadowed = ws.shadowed.iter();
    for &(s, contrib, decided) in &pending {
        let a = &mut samples.acc[s as usize];
        if !decided {
            *a = *a + contrib;
            continue;
        }
        let shadowed = shadowed
            .next()
            .expect("a shadow ray for each decided estimate");
        *a = *a + contrib * shadowed.light;
        samples.steps[s as usize] += shadowed.steps;
        counters.steps += shadowed.steps as u64;
        if shadowed.nan {
            samples.met_nan(s);
        }
    }
    counters.secondary_rays += next.len() as u64;
    next
}

/// Russian roulette for a ray of depth at least [`sampling::ROULETTE_DEPTH`]: it goes on
/// with probability `q = min(max(weight), ROULETTE_MAX)`, its weight divided by `q`.
fn roulette<T: Float>(mut ray: Ray<T>, u: T) -> Option<Ray<T>> {
    if ray.depth < sampling::ROULETTE_DEPTH {
        return Some(ray);
    }
    let w = ray.weight;
    let q =
        w.x.max(w.y)
            .max(w.z)
            .min(T::from_f64(sampling::ROULETTE_MAX));
    if u >= q {
        return None;
    }
    ray.weight = w * (T::one() / q);
    Some(ray)
}

/// The next-event estimates at a hit seen from outside: each lamp (a point; a directional
/// light, a disc of its penumbra's diameter about its direction) and the skies (a
/// cosine-distributed direction, weighed by the power heuristic against the BRDF's density
/// where the path goes on), each queued with its hard shadow ray, or added at once for a lamp
/// without shadows.
#[allow(clippy::too_many_arguments)]
fn estimates<T: Float>(
    ctx: &Context<T>,
    ws: &mut Workspace<'_, T>,
    hit: &Hit<T>,
    b: &Bsdf<T>,
    weight: V3<T>,
    more: bool,
    u: &dyn Fn(u32) -> T,
    sample: u32,
    pending: &mut Vec<(u32, V3<T>, bool)>,
) {
    let off = T::from_f64(4.0) * hit.h;
    let o = hit.p + hit.n * off;
    let mut queue = |dir: V3<T>, tmax: T, contrib: V3<T>, shadows: bool| {
        if shadows {
            ws.launches.push(Launch {
                id: ws.launches.len() as u32,
                origin: [o.x, o.y, o.z],
                dir: [dir.x, dir.y, dir.z],
                t0: hit.tt,
                sign: T::one(),
                tmax,
                k: T::zero(),
                omega: T::one(),
                through: T::one(),
            });
        }
        pending.push((sample, contrib, shadows));
    };
    let mut directional = 0u32;
    for lamp in &ctx.lamps {
        let (l, tmax, atten, il, k) = match *lamp {
            Lamp::Point {
                color, sharpness, ..
            } => {
                let (l, d, atten) = shade::towards(ctx, lamp, hit.p);
                (l, d - off, atten, color, sharpness)
            }
            Lamp::Directional {
                to_light,
                color,
                sharpness,
                cos_disc,
            } => {
                let j = dim::LAMPS + 2 * directional;
                directional += 1;
                let l = if cos_disc < T::one() {
                    let local = sampling::cone(u(j), u(j + 1), cos_disc);
                    from(sampling::to_world(
                        local,
                        [to_light.x, to_light.y, to_light.z],
                    ))
                } else {
                    to_light
                };
                (l, ctx.max_dist, T::one(), color, sharpness)
            }
        };
        if hit.n.dot(l) <= T::zero() || atten <= T::zero() {
            continue;
        }
        queue(l, tmax, weight.mul_v(b.lamp(l, il)) * atten, k >= T::zero());
    }
    if ctx.skies.is_empty() {
        return;
    }
    let local = sampling::cosine(u(dim::SKY[0]), u(dim::SKY[1]));
    let l = from(sampling::to_world(local, [hit.n.x, hit.n.y, hit.n.z]));
    let nl = hit.n.dot(l);
    let f = b.eval(l);
    if nl <= T::zero() || f.max_abs() <= T::zero() {
        return;
    }
    let pdf = nl / T::from_f64(PI);
    let w = if more {
        sampling::power(pdf, b.pdf(l))
    } else {
        T::one()
    };
    let contrib = weight.mul_v(f).mul_v(ctx.sky_radiance(l)) * (w / pdf);
    queue(l, ctx.max_dist, contrib, true);
}
