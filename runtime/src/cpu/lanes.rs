//! Lanes: the rays being marched together, in separate arrays per field so that the point
//! computation and the distance evaluation run over contiguous slices.
//!
//! A march keeps up to `capacity` rays in flight: finished rays leave (the last lane moves
//! into the hole) and queued rays refill the free lanes, so batches stay full until the
//! queue runs dry. A ray's result depends only on its own lane, never on its position, so
//! the output is the same whatever the order.

use sdfc_compiler::{wide, Evaluator, Float};

/// The state of one ray entering a march.
#[derive(Debug, Clone, Copy)]
pub(super) struct Launch<T> {
    /// Index of the ray in the caller's list (results are written there).
    pub id: u32,
    pub origin: [T; 3],
    pub dir: [T; 3],
    /// Path length before this segment (for the pixel-cone tolerance ε·t).
    pub t0: T,
    /// +1 to march outside solids, -1 inside (with -f).
    pub sign: T,
    /// Shadow rays: the distance to the light; trace rays: unused.
    pub tmax: T,
    /// Shadow rays: the softness k (0 for hard shadows).
    pub k: T,
    /// Over-relaxation factor ω at the start.
    pub omega: T,
    /// Shadow rays: the light let through so far (1, or the transparency of the glass a ray
    /// starts inside).
    pub through: T,
}

macro_rules! lanes {
    (state { $($f:ident: $t:ty),* $(,)? } scratch { $($g:ident: $u:ty),* $(,)? }) => {
        /// Per-lane state, one array per field; lane `k` is valid for `k < len`. The
        /// scratch arrays are rewritten at every step and do not move with their lane.
        #[derive(Debug, Default)]
        pub(super) struct Lanes<T> {
            pub len: usize,
            /// Lanes finished in the last step, in increasing order.
            pub finished: Vec<usize>,
            $(pub $f: Vec<$t>,)*
            $(pub $g: Vec<$u>,)*
        }

        impl<T: Float> Lanes<T> {
            /// Room for `capacity` lanes.
            pub fn new(capacity: usize) -> Self {
                Lanes { len: 0, finished: Vec::with_capacity(capacity), $($f: vec![Default::default(); capacity],)* $($g: vec![Default::default(); capacity],)* }
            }

            /// The bytes [`Lanes::new`] allocates for `capacity` lanes (they never grow).
            pub fn heap_bytes(capacity: usize) -> usize {
                capacity * (std::mem::size_of::<usize>() $(+ std::mem::size_of::<$t>())* $(+ std::mem::size_of::<$u>())*)
            }

            /// Moves lane `from` into lane `to`.
            #[inline(always)]
            fn move_lane(&mut self, from: usize, to: usize) {
                $(self.$f[to] = self.$f[from];)*
            }
        }
    };
}

lanes! {
    state {
        id: u32, steps: u32,
        ox: T, oy: T, oz: T, dx: T, dy: T, dz: T,
        t: T, t0: T, sign: T, tmax: T, k: T,
        omega: T, prev: T, step: T, res: T, through: T,
        // Camera rays: the glow of the steps so far (`march::Trace`).
        glow: T,
        // Soft shadow rays: the last two samples (t, d/L, penumbra term) and a search's
        // bracket (docs/rendering.md, "Shadows"; `march::Shadow`).
        ta: T, sa: T, qa: T, tm: T, sm: T, qm: T,
        ra: T, rm: T, rb: T, rq: T, probes: u32,
    }
    scratch {
        mat: u32, flags: u32,
        px: T, py: T, pz: T, dist: T,
    }
}

impl<T: Float> Lanes<T> {
    /// Number of lanes.
    pub fn capacity(&self) -> usize {
        self.id.len()
    }

    /// Starts a ray in the next free lane (the caller checks there is one).
    #[inline(always)]
    pub fn push(&mut self, l: &Launch<T>) {
        let k = self.len;
        self.len += 1;
        self.id[k] = l.id;
        self.steps[k] = 0;
        [self.ox[k], self.oy[k], self.oz[k]] = l.origin;
        [self.dx[k], self.dy[k], self.dz[k]] = l.dir;
        self.t[k] = T::zero();
        self.t0[k] = l.t0;
        self.sign[k] = l.sign;
        self.tmax[k] = l.tmax;
        self.k[k] = l.k;
        self.omega[k] = l.omega;
        self.prev[k] = T::zero();
        self.step[k] = T::zero();
        self.res[k] = T::one();
        self.through[k] = l.through;
        self.glow[k] = T::zero();
        let none = T::from_f64(f64::INFINITY);
        (self.ta[k], self.sa[k], self.qa[k]) = (T::zero(), T::zero(), none);
        (self.tm[k], self.sm[k], self.qm[k]) = (T::zero(), T::zero(), none);
        self.probes[k] = 0;
    }

    /// p = o + t·d for every lane.
    #[inline(always)]
    pub fn points(&mut self) {
        let n = self.len;
        for (axis, (o, d)) in [
            (&self.ox, &self.dx),
            (&self.oy, &self.dy),
            (&self.oz, &self.dz),
        ]
        .into_iter()
        .enumerate()
        {
            let p = match axis {
                0 => &mut self.px,
                1 => &mut self.py,
                _ => &mut self.pz,
            };
            for (((p, &o), &d), &t) in p[..n]
                .iter_mut()
                .zip(&o[..n])
                .zip(&d[..n])
                .zip(&self.t[..n])
            {
                *p = o + t * d;
            }
        }
    }

    /// Evaluates the field (and the materials, with `full`) at the lanes' points.
    #[inline(always)]
    pub fn evaluate(&mut self, dist: &mut Evaluator<'_, T>, full: Option<&mut Evaluator<'_, T>>) {
        let n = self.len;
        match full {
            Some(ev) => ev.eval(
                &self.px[..n],
                &self.py[..n],
                &self.pz[..n],
                &mut self.dist[..n],
                Some(&mut self.mat[..n]),
            ),
            None => dist.eval(
                &self.px[..n],
                &self.py[..n],
                &self.pz[..n],
                &mut self.dist[..n],
                None,
            ),
        }
    }

    /// Removes the lanes listed in `finished`, from the last one down, each replaced by the
    /// current last lane.
    #[inline(always)]
    pub fn remove_finished(&mut self) {
        while let Some(k) = self.finished.pop() {
            let last = self.len - 1;
            if k != last {
                self.move_lane(last, k);
            }
            self.len -= 1;
        }
    }
}

/// What a march does with the lanes after an evaluation.
pub(super) trait Rule<T: Float> {
    /// Advances every lane by one step, given their fresh distances, and lists in
    /// `finished` the lanes whose ray is finished (after writing its result).
    fn advance(&mut self, lanes: &mut Lanes<T>);
    /// Whether the rule needs material ids at every step.
    fn needs_materials(&self) -> bool {
        false
    }
}

/// Marches every ray of `queue` to completion under `rule`, with the lane loops compiled for
/// the widest vector unit the processor has ([`wide`]).
pub(super) fn march<T: Float, R: Rule<T>>(
    lanes: &mut Lanes<T>,
    dist: &mut Evaluator<'_, T>,
    full: &mut Evaluator<'_, T>,
    queue: &[Launch<T>],
    rule: &mut R,
) {
    wide(
        #[inline(always)]
        || march_lanes(lanes, dist, full, queue, rule),
    )
}

/// The body of [`march`], inlined into both copies [`wide`] makes of it.
#[inline(always)]
fn march_lanes<T: Float, R: Rule<T>>(
    lanes: &mut Lanes<T>,
    dist: &mut Evaluator<'_, T>,
    full: &mut Evaluator<'_, T>,
    queue: &[Launch<T>],
    rule: &mut R,
) {
    let mut next = 0;
    lanes.len = 0;
    loop {
        while lanes.len < lanes.capacity() && next < queue.len() {
            lanes.push(&queue[next]);
            next += 1;
        }
        if lanes.len == 0 {
            return;
        }
        lanes.points();
        lanes.evaluate(
            dist,
            if rule.needs_materials() {
                Some(&mut *full)
            } else {
                None
            },
        );
        rule.advance(lanes);
        lanes.remove_finished();
    }
}
