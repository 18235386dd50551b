//! The two marches of docs/rendering.md: sphere tracing to the nearest surface (camera and
//! secondary rays, with optional over-relaxation) and shadow rays (hard or soft, through
//! transparent occluders).

use super::context::Context;
use super::lanes::{Lanes, Rule};
use super::stats::Counters;
use sdfc_compiler::{Float, Light};

/// How a traced ray ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(super) enum Status {
    /// |d| < ε·t at t.
    #[default]
    Hit,
    /// t went past `max_dist`.
    Miss,
    /// The step budget ran out.
    Budget,
    /// The field was NaN.
    Nan,
}

/// The result of tracing one ray.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Traced<T> {
    /// Distance along the ray of the hit (or where the march stopped).
    pub t: T,
    pub status: Status,
    pub steps: u32,
    /// Σ e^(−|dᵢ|/G) over the evaluations of its march, where the render has a glow
    /// (docs/rendering.md, "The look"); else 0.
    pub glow: T,
}

/// Sphere tracing with Keinert et al.'s over-relaxation: step ω·d, and when the new
/// unbounding sphere does not overlap the previous one (|d| + |d_prev| < step), step back
/// and continue with ω = 1.
#[derive(Debug)]
pub(super) struct Trace<'a, T: Float> {
    pub ctx: &'a Context<T>,
    pub out: &'a mut [Traced<T>],
    pub counters: &'a mut Counters,
}

// Flag bits an advance sets per lane, read back by its scan.
const HIT: u32 = 2;
const MISS: u32 = 4;
const BUDGET: u32 = 8;
const NAN: u32 = 16;
const OVERSHOOT: u32 = 32;
/// Shadow rays: a soft shadow's search around a least `k·d/t` goes on or may start.
const SEARCH: u32 = 64;

/// The first lane from `from` on with a flag set: eight clear lanes are skipped at a time
/// (most lanes go on after most steps).
#[inline(always)]
fn next_flagged(flags: &[u32], mut from: usize) -> Option<usize> {
    while let Some(group) = flags.get(from..from + 8) {
        if group.iter().fold(0, |a, &f| a | f) != 0 {
            break;
        }
        from += 8;
    }
    let rest = flags.get(from..)?;
    rest.iter().position(|&f| f != 0).map(|i| from + i)
}

/// `flag` when `b` holds, else 0 (branch-free).
#[inline(always)]
fn bit(b: bool, flag: u32) -> u32 {
    (b as u32) * flag
}

impl<T: Float> Rule<T> for Trace<'_, T> {
    /// One branch-free pass over the lanes, then a scan of the flags for finished rays.
    #[inline(always)]
    fn advance(&mut self, l: &mut Lanes<T>) {
        let n = l.len;
        let c = self.ctx;
        let (one, zero) = (T::one(), T::zero());
        let (inv_l, eps, max_dist, max_steps) =
            (c.inv_lipschitz, c.epsilon, c.max_dist, c.max_steps);
        let (dist, sign, t0) = (&l.dist[..n], &l.sign[..n], &l.t0[..n]);
        let (px, py, pz) = (&l.px[..n], &l.py[..n], &l.pz[..n]);
        let (t, steps, flags) = (&mut l.t[..n], &mut l.steps[..n], &mut l.flags[..n]);
        let (omega, prev, step) = (&mut l.omega[..n], &mut l.prev[..n], &mut l.step[..n]);
        let mut any = 0;
        for k in 0..n {
            let f = dist[k];
            let s = sign[k] * f * inv_l;
            let r = s.abs();
            let tol = c.tolerance(eps * (t0[k] + t[k]), px[k], py[k], pz[k]);
            let om = omega[k];
            let fail = (om > one) & (r + prev[k] < step[k]);
            let st = if fail { step[k] - om * step[k] } else { s * om };
            step[k] = st;
            omega[k] = if fail { one } else { om };
            prev[k] = r;
            // A ray that starts inside a solid, or is stepped back to its start, has
            // reached it there (as the kernel's `trace`).
            let hit = !fail & ((r < tol) | ((t[k] == zero) & (s < -tol)));
            // A miss needs the verified reach t + f/L past max_dist, not a relaxed step's.
            let gone = !fail & (t[k] + s > max_dist);
            let count = steps[k] + 1;
            steps[k] = count;
            // A hit stays where it is. Written as a step of zero rather than as a store
            // that keeps the old value, which compiles to a masked store, slow on some
            // processors; t is never negative nor NaN, so `(t + 0).max(0)` is t exactly.
            t[k] = (t[k] + if hit { zero } else { st }).max(zero);
            let fl = bit(hit, HIT)
                | bit(gone, MISS)
                | bit(count >= max_steps, BUDGET)
                | bit(f.is_nan(), NAN)
                | bit(s < -tol, OVERSHOOT);
            flags[k] = fl;
            any |= fl;
        }
        // The glow: each evaluation adds e^(−|d|/G) (|d| is `prev` now).
        if c.inv_glow > zero {
            let (prev, glow) = (&l.prev[..n], &mut l.glow[..n]);
            for k in 0..n {
                glow[k] = glow[k] + (-(prev[k] * c.inv_glow)).exp();
            }
        }
        if any == 0 {
            return;
        }
        let mut next = 0;
        while let Some(k) = next_flagged(&l.flags[..n], next) {
            next = k + 1;
            let fl = l.flags[k];
            self.counters.overshoots += (fl & OVERSHOOT != 0) as u64;
            let status = if fl & NAN != 0 {
                self.counters.nans += 1;
                Status::Nan
            } else if fl & HIT != 0 {
                Status::Hit
            } else if fl & MISS != 0 {
                Status::Miss
            } else if fl & BUDGET != 0 {
                Status::Budget
            } else {
                continue;
            };
            self.out[l.id[k] as usize] = Traced {
                t: l.t[k],
                status,
                steps: l.steps[k],
                glow: l.glow[k],
            };
            l.finished.push(k);
        }
    }
}

/// The result of one shadow ray: the fraction of the light that arrives, in [0, 1].
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Shadowed<T> {
    pub light: T,
    pub steps: u32,
    /// Whether the ray stopped at a NaN.
    pub nan: bool,
}

/// Shadow rays towards a light at distance `tmax`. Soft (k > 0): res = min(res, k·d/t) along
/// the ray, searched for between the steps wherever three of them bracket a least term
/// ([`Shadow::search`]). Reaching a surface: an opaque one blocks the light; a transparent
/// one multiplies what passes by its transparency, and the ray goes on through the solid
/// (marching -f) and out of it. Transparent solids cast no penumbra. Running out of steps
/// counts as lit.
#[derive(Debug)]
pub(super) struct Shadow<'a, T: Float> {
    pub ctx: &'a Context<T>,
    pub out: &'a mut [Shadowed<T>],
    pub counters: &'a mut Counters,
}

impl<T: Float> Shadow<'_, T> {
    fn finish(&mut self, l: &mut Lanes<T>, k: usize, light: T) {
        self.out[l.id[k] as usize] = Shadowed {
            light,
            steps: l.steps[k],
            nan: false,
        };
        l.finished.push(k);
    }

    /// Finishes lane `k` at a NaN: counted, and the light that arrived so far is kept.
    fn finish_nan(&mut self, l: &mut Lanes<T>, k: usize) {
        self.counters.nans += 1;
        self.finish(l, k, Self::arrived(l, k));
        self.out[l.id[k] as usize].nan = true;
    }

    /// The light arriving at the end of lane `k`'s march.
    fn arrived(l: &Lanes<T>, k: usize) -> T {
        l.through[k] * l.res[k].clamp(T::zero(), T::one())
    }

    /// Where lane `k` evaluates next after a sample at `l.t[k]` (`s` the distance over L,
    /// `q` its penumbra term, +∞ where there is none, already in `res`) that reached no
    /// surface. A march sample steps on by `s`; where the term fell at the sample before and
    /// rose again, the least lies between the samples around it, where sphere tracing's steps
    /// can miss it by much (a boolean's kink along the ray has no flat bottom): if the
    /// Lipschitz bound (`s` is 1-Lipschitz in t) allows a term below `min(res, 1)` there, a
    /// search probes the middle of the bracket's longer half, keeps the least and the points
    /// either side of it, and ends when the bracket is narrower than
    /// [`Light::PENUMBRA_BRACKET`] of the penumbra cone's width or after
    /// [`Light::PENUMBRA_PROBES`] probes; the march then goes on from where it was.
    /// docs/rendering.md, "Shadows"; the kernel's `shadow` does the same.
    fn search(l: &mut Lanes<T>, k: usize, s: T, q: T) -> T {
        let half = T::from_f64(0.5);
        let bracket = T::from_f64(Light::PENUMBRA_BRACKET);
        let probe = |a: T, m: T, b: T| {
            if m - a > b - m {
                (a + m) * half
            } else {
                (m + b) * half
            }
        };
        let (t, kk) = (l.t[k], l.k[k]);
        if l.probes[k] > 0 {
            let (mut a, mut m, mut b) = (l.ra[k], l.rm[k], l.rb[k]);
            if q < l.rq[k] {
                if t < m {
                    b = m;
                } else {
                    a = m;
                }
                m = t;
                l.rq[k] = q;
            } else if t < m {
                a = t;
            } else {
                b = t;
            }
            (l.ra[k], l.rm[k], l.rb[k]) = (a, m, b);
            if kk * (b - a) <= bracket * m || l.probes[k] >= Light::PENUMBRA_PROBES {
                l.probes[k] = 0;
                return (l.tm[k] + l.sm[k]).max(T::zero());
            }
            l.probes[k] += 1;
            return probe(a, m, b);
        }
        let (ta, sa, qa, tm, sm, qm) = (l.ta[k], l.sa[k], l.qa[k], l.tm[k], l.sm[k], l.qm[k]);
        let mut next = t + s;
        let low = (sa + sm - (tm - ta)).min(sm + s - (t - tm)) * half;
        if qm < qa
            && q > qm
            && kk * low < l.res[k].min(T::one()) * t
            && kk * (t - ta) > bracket * tm
        {
            (l.ra[k], l.rm[k], l.rb[k], l.rq[k]) = (ta, tm, t, qm);
            l.probes[k] = 1;
            next = probe(ta, tm, t);
        }
        Self::remember(l, k, s, q);
        next.max(T::zero())
    }

    /// Shifts lane `k`'s sample at `l.t[k]` into its last two.
    #[inline(always)]
    fn remember(l: &mut Lanes<T>, k: usize, s: T, q: T) {
        (l.ta[k], l.sa[k], l.qa[k]) = (l.tm[k], l.sm[k], l.qm[k]);
        (l.tm[k], l.sm[k], l.qm[k]) = (l.t[k], s, q);
    }

    /// Opaque scenes: one branch-free pass, then a scan for finished rays.
    #[inline(always)]
    fn advance_opaque(&mut self, l: &mut Lanes<T>) {
        let n = l.len;
        let c = self.ctx;
        let (zero, one, half) = (T::zero(), T::one(), T::from_f64(0.5));
        let bracket = T::from_f64(Light::PENUMBRA_BRACKET);
        let (inv_l, eps, max_steps) = (c.inv_lipschitz, c.epsilon, c.max_steps);
        let (dist, t0, kk, tmax) = (&l.dist[..n], &l.t0[..n], &l.k[..n], &l.tmax[..n]);
        let (px, py, pz) = (&l.px[..n], &l.py[..n], &l.pz[..n]);
        let probes = &l.probes[..n];
        let (t, steps, flags, res) = (
            &mut l.t[..n],
            &mut l.steps[..n],
            &mut l.flags[..n],
            &mut l.res[..n],
        );
        let (ta, sa, qa) = (&mut l.ta[..n], &mut l.sa[..n], &mut l.qa[..n]);
        let (tm, sm, qm) = (&mut l.tm[..n], &mut l.sm[..n], &mut l.qm[..n]);
        let mut any = 0;
        for k in 0..n {
            let f = dist[k];
            let s = f * inv_l;
            let tol = c.tolerance(eps * (t0[k] + t[k]), px[k], py[k], pz[k]);
            let q = penumbra(kk[k], s, t[k]);
            res[k] = res[k].min(q);
            // Below −tol: inside the solid (a start lifted into a neighbouring one), blocked.
            let blocked = s < tol;
            // A search goes on, or starts: the scan below moves such a lane
            // ([`Shadow::search`], whose test this repeats); the others step on here and
            // shift their sample into their last two.
            let low = (sa[k] + sm[k] - (tm[k] - ta[k])).min(sm[k] + s - (t[k] - tm[k])) * half;
            let start = (qm[k] < qa[k])
                & (q > qm[k])
                & (kk[k] * low < res[k].min(one) * t[k])
                & (kk[k] * (t[k] - ta[k]) > bracket * tm[k]);
            let search = (probes[k] > 0) | start;
            let next = (t[k] + s).max(zero);
            let on = !search;
            (ta[k], sa[k], qa[k]) = if on {
                (tm[k], sm[k], qm[k])
            } else {
                (ta[k], sa[k], qa[k])
            };
            (tm[k], sm[k], qm[k]) = if on {
                (t[k], s, q)
            } else {
                (tm[k], sm[k], qm[k])
            };
            t[k] = if on { next } else { t[k] };
            let count = steps[k] + 1;
            steps[k] = count;
            let fl = bit(blocked, HIT)
                | bit(on & (next >= tmax[k]), MISS)
                | bit(count >= max_steps, BUDGET)
                | bit(f.is_nan(), NAN)
                | bit(s < -tol, OVERSHOOT)
                | bit(search, SEARCH);
            flags[k] = fl;
            any |= fl;
        }
        if any == 0 {
            return;
        }
        let mut next = 0;
        while let Some(k) = next_flagged(&l.flags[..n], next) {
            next = k + 1;
            let fl = l.flags[k];
            self.counters.overshoots += (fl & OVERSHOOT != 0) as u64;
            if fl & NAN != 0 {
                self.finish_nan(l, k);
            } else if fl & HIT != 0 {
                self.finish(l, k, T::zero());
            } else {
                let mut miss = fl & MISS != 0;
                if fl & SEARCH != 0 {
                    let s = l.dist[k] * inv_l;
                    let at = Self::search(l, k, s, penumbra(l.k[k], s, l.t[k]));
                    l.t[k] = at;
                    miss = l.probes[k] == 0 && at >= l.tmax[k];
                }
                if miss || fl & BUDGET != 0 {
                    self.finish(l, k, Self::arrived(l, k));
                }
            }
        }
    }

    /// Scenes with transparent materials: lane by lane, looking at the nearest material.
    fn step_transparent(&mut self, l: &mut Lanes<T>, k: usize) {
        let c = self.ctx;
        let f = l.dist[k];
        let t = l.t[k];
        l.steps[k] += 1;
        if f.is_nan() {
            return self.finish_nan(l, k);
        }
        let signed = l.sign[k] * f * c.inv_lipschitz;
        let tt = l.t0[k] + t;
        let tol = c.tolerance(c.epsilon * tt, l.px[k], l.py[k], l.pz[k]);
        if signed < -tol {
            self.counters.overshoots += 1;
        }
        let tau = c.material(l.mat[k]).transparency;
        let outside = l.sign[k] > T::zero();
        let q = if outside && tau <= T::zero() {
            penumbra(l.k[k], signed, t)
        } else {
            T::from_f64(f64::INFINITY)
        };
        l.res[k] = l.res[k].min(q);
        let reached = signed < tol;
        if reached && tau <= T::zero() {
            return self.finish(l, k, T::zero());
        }
        // A probe does not cross a transparent surface; the march crosses it when it gets there.
        let next = if reached && l.probes[k] == 0 {
            if outside {
                l.through[k] = l.through[k] * tau;
            }
            l.sign[k] = -l.sign[k];
            let p = super::vec::V3::new(l.px[k], l.py[k], l.pz[k]);
            Self::remember(l, k, signed, T::from_f64(f64::INFINITY));
            (t + T::from_f64(4.0) * c.normal_step(tt, p)).max(T::zero())
        } else {
            Self::search(l, k, signed, q)
        };
        l.t[k] = next;
        let marching = l.probes[k] == 0;
        if (marching && next >= l.tmax[k]) || l.steps[k] >= c.max_steps {
            self.finish(l, k, Self::arrived(l, k));
        }
    }
}

/// The penumbra term `k·s/t` of a sample (`s` the distance over L), +∞ where there is none:
/// hard shadows (k = 0) and the ray's origin (t = 0). Written as a select rather than a store
/// that keeps the old value (a slow masked store). It is never NaN: a NaN needs a NaN
/// distance, which finishes the lane in the step that produces it, or a softness that
/// overflows to +∞ (above 3.4e38 in f32).
#[inline(always)]
fn penumbra<T: Float>(k: T, s: T, t: T) -> T {
    if (k > T::zero()) & (t > T::zero()) {
        k * s / t
    } else {
        T::from_f64(f64::INFINITY)
    }
}

impl<T: Float> Rule<T> for Shadow<'_, T> {
    fn needs_materials(&self) -> bool {
        self.ctx.transparent
    }

    #[inline(always)]
    fn advance(&mut self, l: &mut Lanes<T>) {
        if self.ctx.transparent {
            for k in 0..l.len {
                self.step_transparent(l, k);
            }
        } else {
            self.advance_opaque(l);
        }
    }
}
