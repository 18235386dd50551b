//! The CPU interpreter of distance programs.
//!
//! A [`Tape`] is a program prepared for batch evaluation: instructions the requested outputs
//! do not need are dropped, chains of arithmetic that sum squares or products become one
//! step each (`fuse.rs`), and registers are packed into a few reusable slots. An
//! [`Evaluator`] runs a tape over batches of points given as separate x, y, z slices, read in
//! place: each step is one tight loop over the batch, so the cost of decoding it is shared
//! by the whole batch and the compiler can vectorise the loops.
//!
//! Everything is generic over [`Float`] (f32 or f64). [`eval_point`] is the one-point
//! reference evaluation used by tests.

mod fuse;
mod tape;
pub mod verify;
mod wide;

/// The evaluation types, at the path they had when they were defined here.
pub use crate::program::Float;

pub use tape::{Outputs, Tape};
pub use wide::wide;

use tape::{Guard, Sources, Step, INPUTS};

use crate::program::{Program, Reg};

/// The default number of points an evaluator processes per pass over the tape.
pub const DEFAULT_CHUNK: usize = 256;

/// Inside guarded blocks, steps run over a multiple of this many lanes (two vectors of
/// eight f32).
const BLOCK_LANES: usize = 16;

/// Evaluates a program at one point, instruction by instruction (the reference semantics):
/// a guarded block whose `bound >= best` is skipped, its results taking their values from
/// before it. The material id is the material register converted to an integer (negative and
/// NaN become 0).
pub fn eval_point<T: Float>(program: &Program, p: [T; 3]) -> (T, u32) {
    let regs = program.run(p, |_| {});
    let get = |i: Reg| regs.get(i.0 as usize).copied().unwrap_or_else(T::zero);
    (
        get(program.distance()),
        material_id(get(program.material())),
    )
}

/// A material register value as an id (saturating: negative and NaN give 0).
#[inline(always)]
pub fn material_id<T: Float>(m: T) -> u32 {
    let v = m.to_f64();
    if v >= 0.0 {
        v as u32
    } else {
        0
    }
}

/// Runs one tape over batches of points, with its own scratch registers.
#[derive(Debug)]
pub struct Evaluator<'t, T: Float> {
    tape: &'t Tape,
    /// `slot_count` slots of `chunk` values each, back to back.
    slots: Vec<T>,
    chunk: usize,
    /// Per open guarded block: the points (of the enclosing block's packing) where it runs,
    /// how many points the enclosing block had, and whether the block runs on all of them
    /// ([`DENSE`]).
    frames: Vec<(Vec<u32>, usize, bool)>,
}

impl<'t, T: Float> Evaluator<'t, T> {
    /// An evaluator for `tape` processing up to `chunk` points per pass (at least 1).
    pub fn new(tape: &'t Tape, chunk: usize) -> Self {
        let chunk = chunk.max(1);
        let mut slots = vec![T::zero(); chunk * tape.slot_count()];
        for &(slot, c) in tape.constants() {
            slots[(slot - INPUTS) as usize * chunk..][..chunk].fill(T::from_f64(c));
        }
        let frames = (0..tape.depth())
            .map(|_| (Vec::with_capacity(chunk), 0, false))
            .collect();
        Evaluator {
            tape,
            slots,
            chunk,
            frames,
        }
    }

    /// The bytes an evaluator of `tape` allocates for `chunk` points per pass (its slots and
    /// the point lists of its guarded blocks); evaluating allocates nothing more.
    pub fn heap_bytes(tape: &Tape, chunk: usize) -> usize {
        let chunk = chunk.max(1);
        let frame =
            chunk * std::mem::size_of::<u32>() + std::mem::size_of::<(Vec<u32>, usize, bool)>();
        chunk * tape.slot_count() * std::mem::size_of::<T>() + tape.depth() * frame
    }

    /// The tape this evaluator runs.
    pub fn tape(&self) -> &'t Tape {
        self.tape
    }

    /// Evaluates the distance at every point `(x[i], y[i], z[i])` into `d[i]`, and the
    /// material id into `m[i]` when asked for (and when the tape computes materials; 0
    /// otherwise). All slices must have the same length; extra elements are ignored.
    pub fn eval(&mut self, x: &[T], y: &[T], z: &[T], d: &mut [T], m: Option<&mut [u32]>) {
        wide(
            #[inline(always)]
            || self.eval_any(x, y, z, d, m),
        )
    }

    /// The body of [`Evaluator::eval`], inlined into both copies [`wide()`] makes of it.
    #[inline(always)]
    fn eval_any(&mut self, x: &[T], y: &[T], z: &[T], d: &mut [T], mut m: Option<&mut [u32]>) {
        let n = x.len().min(y.len()).min(z.len()).min(d.len());
        let mut start = 0;
        while start < n {
            let end = (start + self.chunk).min(n);
            let inputs = [&x[start..end], &y[start..end], &z[start..end]];
            let out = &mut d[start..end];
            self.run(inputs, out);
            if !self.tape.direct() {
                out.copy_from_slice(self.view(inputs, self.tape.distance_slot(), end - start));
            }
            if let Some(m) = m.as_deref_mut() {
                let stop = end.min(m.len());
                self.write_materials(inputs, &mut m[start.min(stop)..stop]);
            }
            start = end;
        }
    }

    fn write_materials(&self, inputs: [&[T]; 3], out: &mut [u32]) {
        match self.tape.material_slot() {
            Some(s) => {
                let n = out.len();
                for (o, &v) in out.iter_mut().zip(self.view(inputs, s, n)) {
                    *o = material_id(v);
                }
            }
            None => out.fill(0),
        }
    }

    /// The first `n` values of slot `s`: an input, or one of the scratch slots.
    #[inline(always)]
    fn view<'a>(&'a self, inputs: [&'a [T]; 3], s: u32, n: usize) -> &'a [T] {
        Sources::whole(inputs, &self.slots, self.chunk, n).get(s)
    }

    /// Copies the first `n` values of slot `from` to scratch slot `to`.
    #[inline(always)]
    fn copy(&mut self, inputs: [&[T]; 3], from: u32, to: u32, n: usize) {
        let c = self.chunk;
        let to = (to - INPUTS) as usize * c;
        match from.checked_sub(INPUTS) {
            None => self.slots[to..][..n].copy_from_slice(&inputs[from as usize][..n]),
            Some(from) => {
                let from = from as usize * c;
                self.slots.copy_within(from..from + n, to);
            }
        }
    }

    /// One pass over the tape for up to `chunk` points (the inputs' length); a tape whose
    /// last step computes the distance writes it into `out`.
    #[inline(always)]
    fn run(&mut self, inputs: [&[T]; 3], out: &mut [T]) {
        let mut n = inputs[0].len();
        let chunk = self.chunk;
        let tape = self.tape;
        let steps = tape.steps();
        let direct = tape.direct().then(|| steps.len() - 1);
        let data = (tape.meshes(), tape.outlines());
        let mut out = Some(out);
        let mut depth = 0;
        let mut s = 0;
        while s < steps.len() {
            match steps[s] {
                Step::Inst(inst) => {
                    let out = if direct == Some(s) { out.take() } else { None };
                    // Inside a block every operand is a scratch slot of `chunk` values, so a
                    // step may run over whole vectors: the lanes past `n` hold stale values
                    // that no result reads, and the loops skip their scalar tails.
                    let width = match depth {
                        0 => n,
                        _ => n.next_multiple_of(BLOCK_LANES).min(chunk),
                    };
                    inst.apply(data, &mut self.slots, out, inputs, chunk, width);
                }
                Step::Enter(g) => {
                    let guard = tape.guard(g);
                    match self.enter(inputs, guard, depth, n) {
                        Some(m) => {
                            depth += 1;
                            n = m;
                        }
                        None => {
                            s = guard.after;
                            continue;
                        }
                    }
                }
                Step::Leave(g) => {
                    depth -= 1;
                    n = self.leave(inputs, tape.guard(g), depth, n);
                }
            }
            s += 1;
        }
    }

    /// Starts a guarded block over `n` points: `None` when it runs nowhere (its results then
    /// hold their values from before), else the number of points it runs on, whose values
    /// from outside are gathered.
    #[inline(always)]
    fn enter(&mut self, inputs: [&[T]; 3], guard: &Guard, depth: usize, n: usize) -> Option<usize> {
        let c = self.chunk;
        let (mut idx, _, _) = std::mem::take(&mut self.frames[depth]);
        idx.resize(n, 0);
        let m = {
            let bound = self.view(inputs, guard.bound, n);
            let best = self.view(inputs, guard.best, n);
            compact(bound, best, &mut idx)
        };
        idx.truncate(m);
        let dense = m < n && m * DENSE.1 >= n * DENSE.0;
        if m == 0 {
            for &(dst, _, other) in &guard.phis {
                self.copy(inputs, other, dst, n);
            }
        } else if m == n || dense {
            for &(from, to) in &guard.gathers {
                self.copy(inputs, from, to, n);
            }
        } else {
            for &(from, to) in &guard.gathers {
                let to = (to - INPUTS) as usize * c;
                match from.checked_sub(INPUTS) {
                    None => {
                        let from = &inputs[from as usize][..n];
                        gather(&mut self.slots[to..][..m], from, &idx);
                    }
                    Some(from) => {
                        let from = from as usize * c;
                        let (dst, src) = two(&mut self.slots, to, m, from, n);
                        gather(dst, src, &idx);
                    }
                }
            }
        }
        self.frames[depth] = (idx, n, dense);
        (m > 0).then_some(if dense { n } else { m })
    }

    /// Ends a guarded block that ran on `m` points: scatters its results into the enclosing
    /// block's packing, whose number of points it returns.
    #[inline(always)]
    fn leave(&mut self, inputs: [&[T]; 3], guard: &Guard, depth: usize, m: usize) -> usize {
        let c = self.chunk;
        let (idx, n, dense) = std::mem::take(&mut self.frames[depth]);
        for &(dst, then, other) in &guard.phis {
            if dense {
                self.copy(inputs, other, dst, n);
                let (then, dst) = ((then - INPUTS) as usize * c, (dst - INPUTS) as usize * c);
                let (dst, src) = two(&mut self.slots, dst, n, then, n);
                for &i in &idx {
                    dst[i as usize] = src[i as usize];
                }
            } else if m == n {
                self.copy(inputs, then, dst, n);
            } else {
                self.copy(inputs, other, dst, n);
                let (then, dst) = ((then - INPUTS) as usize * c, (dst - INPUTS) as usize * c);
                let (dst, src) = two(&mut self.slots, dst, n, then, m);
                for (&i, &v) in idx.iter().zip(src) {
                    dst[i as usize] = v;
                }
            }
        }
        self.frames[depth] = (idx, n, dense);
        n
    }
}

/// A guarded block that runs on at least `DENSE.0 / DENSE.1` of its enclosing block's points
/// runs on all of them, its results kept where it runs: its values from outside are copied
/// whole instead of gathered point by point, for the little more work of the points where it
/// does not (whose guards inside it, testing boxes within its own, mostly fail too).
const DENSE: (usize, usize) = (3, 4);

/// Lists in `idx` the points where a guarded block runs, `!(bound >= best)`, and returns how
/// many there are; eight points are compared at a time, and a group where the block runs
/// everywhere or nowhere is written at once.
#[inline(always)]
fn compact<T: Float>(bound: &[T], best: &[T], idx: &mut [u32]) -> usize {
    let mut m = 0;
    let (whole, rest) = (bound.len() / 8 * 8, bound.len() % 8);
    for (g, (b, d)) in bound.chunks_exact(8).zip(best.chunks_exact(8)).enumerate() {
        let mut mask = 0u32;
        for (j, (b, d)) in b.iter().zip(d).enumerate() {
            mask |= u32::from(!(*b >= *d)) << j;
        }
        let base = (g * 8) as u32;
        if mask == 0xff {
            for (j, i) in idx[m..m + 8].iter_mut().enumerate() {
                *i = base + j as u32;
            }
            m += 8;
            continue;
        }
        while mask != 0 {
            idx[m] = base + mask.trailing_zeros();
            m += 1;
            mask &= mask - 1;
        }
    }
    for (j, (b, d)) in bound[whole..]
        .iter()
        .zip(&best[whole..])
        .enumerate()
        .take(rest)
    {
        idx[m] = (whole + j) as u32;
        m += usize::from(!(*b >= *d));
    }
    m
}

/// `dst[j] = src[idx[j]]` for every listed point.
#[inline(always)]
fn gather<T: Float>(dst: &mut [T], src: &[T], idx: &[u32]) {
    for (d, &i) in dst.iter_mut().zip(idx) {
        *d = src[i as usize];
    }
}

/// The `a_len` values from `a` (written) and the `b_len` values from `b` (read) of `slots`,
/// two ranges that do not overlap.
#[inline(always)]
fn two<T>(slots: &mut [T], a: usize, a_len: usize, b: usize, b_len: usize) -> (&mut [T], &[T]) {
    if a < b {
        let (lo, hi) = slots.split_at_mut(b);
        (&mut lo[a..][..a_len], &hi[..b_len])
    } else {
        let (lo, hi) = slots.split_at_mut(a);
        (&mut hi[..a_len], &lo[b..][..b_len])
    }
}
