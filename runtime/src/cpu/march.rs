//! The two marches of docs/rendering.md: sphere tracing to the nearest surface (camera and
//! secondary rays, with optional over-relaxation) and shadow rays (hard or soft, through
//! transparent occluders).

use super::context::Context;
use super::lanes::{Lanes, Rule};
use super::stats::Counters;
use sdfc_compiler::Float;

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
            let hit = !fail & (r < tol);
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
/// the ray. Reaching a surface: an opaque one blocks the light; a transparent one multiplies
/// what passes by its transparency, and the ray goes on through the solid (marching -f) and
/// out of it. Transparent solids cast no penumbra. Running out of steps counts as lit.
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

    /// Opaque scenes: one branch-free pass, then a scan for finished rays.
    #[inline(always)]
    fn advance_opaque(&mut self, l: &mut Lanes<T>) {
        let n = l.len;
        let c = self.ctx;
        let zero = T::zero();
        let (inv_l, eps, max_steps) = (c.inv_lipschitz, c.epsilon, c.max_steps);
        let (dist, t0, kk, tmax) = (&l.dist[..n], &l.t0[..n], &l.k[..n], &l.tmax[..n]);
        let (px, py, pz) = (&l.px[..n], &l.py[..n], &l.pz[..n]);
        let (t, steps, flags, res) = (
            &mut l.t[..n],
            &mut l.steps[..n],
            &mut l.flags[..n],
            &mut l.res[..n],
        );
        let mut any = 0;
        for k in 0..n {
            let f = dist[k];
            let s = f * inv_l;
            let tol = c.tolerance(eps * (t0[k] + t[k]), px[k], py[k], pz[k]);
            let soft = (kk[k] > zero) & (t[k] > zero);
            // Without a penumbra term res stays: min with +∞ rather than a store keeping the
            // old value (a slow masked store). res is never NaN here: it starts at 1, and a
            // NaN penumbra term needs a NaN distance, which finishes the lane in the step
            // that produces it, or a softness that overflows to +∞ (above 3.4e38 in f32).
            let penumbra = if soft {
                kk[k] * s / t[k]
            } else {
                T::from_f64(f64::INFINITY)
            };
            res[k] = res[k].min(penumbra);
            let blocked = s.abs() < tol;
            let next = (t[k] + s).max(zero);
            t[k] = next;
            let count = steps[k] + 1;
            steps[k] = count;
            let fl = bit(blocked, HIT)
                | bit(next >= tmax[k], MISS)
                | bit(count >= max_steps, BUDGET)
                | bit(f.is_nan(), NAN)
                | bit(s < -tol, OVERSHOOT);
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
            } else if fl & (MISS | BUDGET) != 0 {
                self.finish(l, k, Self::arrived(l, k));
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
        if outside && l.k[k] > T::zero() && t > T::zero() && tau <= T::zero() {
            l.res[k] = l.res[k].min(l.k[k] * signed / t);
        }
        let mut next = t + signed;
        if signed.abs() < tol {
            if tau <= T::zero() {
                return self.finish(l, k, T::zero());
            }
            if outside {
                l.through[k] = l.through[k] * tau;
            }
            l.sign[k] = -l.sign[k];
            let p = super::vec::V3::new(l.px[k], l.py[k], l.pz[k]);
            next = t + T::from_f64(4.0) * c.normal_step(tt, p);
        }
        l.t[k] = next.max(T::zero());
        if l.t[k] >= l.tmax[k] || l.steps[k] >= c.max_steps {
            self.finish(l, k, Self::arrived(l, k));
        }
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
