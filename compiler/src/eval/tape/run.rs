//! The loop that runs each step of a tape over a batch of points: the operands' sources and
//! one loop per kind of instruction.

use super::{Code, Inst, INPUTS};
use crate::eval::fuse::{Finish, Kind};
use crate::eval::Float;
use crate::program::mesh::TriMesh;
use crate::program::outline::{self, Outline};
use crate::program::{scalar, Binary, Unary};
use std::sync::Arc;

impl Inst {
    /// Runs this step on the first `n` points: into `out` where given, else into its own
    /// slot of `slots` (scratch slots of `chunk` values, back to back), which is split off
    /// the buffer; operands are read from the rest of it, or from the inputs.
    #[inline(always)]
    pub(in crate::eval) fn apply<T: Float>(
        &self,
        (meshes, outlines): (&[Option<std::sync::Arc<TriMesh>>], &[Arc<Outline>]),
        slots: &mut [T],
        out: Option<&mut [T]>,
        inputs: [&[T]; 3],
        chunk: usize,
        n: usize,
    ) {
        let (d, sources) = match out {
            Some(out) => (out, Sources::whole(inputs, slots, chunk, n)),
            None => {
                let dst = (self.dst - INPUTS) as usize;
                let (lo, rest) = slots.split_at_mut(dst * chunk);
                let (d, hi) = rest.split_at_mut(chunk);
                let sources = Sources {
                    inputs,
                    lo,
                    hi,
                    dst,
                    chunk,
                    n,
                };
                (d, sources)
            }
        };
        let d = &mut d[..n];
        let k = T::from_f64(self.k);
        match self.code {
            Code::Unary(u) => unary_loop(u, d, sources.get(self.a)),
            Code::Binary(b) => binary_loop(b, d, sources.get(self.a), sources.get(self.b)),
            Code::BinaryK(b) => binary_k_loop(b, d, sources.get(self.a), k),
            Code::KBinary(b) => k_binary_loop(b, d, k, sources.get(self.a)),
            Code::Select => {
                let (c, x, y) = (
                    sources.get(self.a),
                    sources.get(self.b),
                    sources.get(self.c),
                );
                for (((o, &c), &p), &q) in d.iter_mut().zip(c).zip(x).zip(y) {
                    *o = scalar::select(c, p, q);
                }
            }
            Code::Fused(kind, terms, finish) => {
                let [k0, k1, k2] = self.ks;
                let ks = [T::from_f64(k0), T::from_f64(k1), T::from_f64(k2)];
                let x = [
                    sources.get(self.a),
                    sources.get(self.b),
                    sources.get(self.c),
                ];
                fused_loop(kind, terms, finish, d, x, ks, k);
            }
            Code::Mesh(m) => {
                let mesh = meshes[m as usize]
                    .as_deref()
                    .expect("a tape holds every mesh its program names");
                let (x, y, z) = (
                    sources.get(self.a),
                    sources.get(self.b),
                    sources.get(self.c),
                );
                // Each lane's walk starts bounded by the triangle nearest to the lane before
                // (neighbouring lanes are near points: the same results, fewer nodes).
                let mut hint = 0;
                map3(d, x, y, z, |x, y, z| {
                    mesh.distance_from([x, y, z], &mut hint)
                });
            }
            Code::Outline => {
                let o = &outlines[self.k as usize];
                let (x, y) = (sources.get(self.a), sources.get(self.b));
                for ((r, &x), &y) in d.iter_mut().zip(x).zip(y) {
                    *r = outline::distance(o, x, y);
                }
            }
        }
    }
}

/// Where an instruction's operands are read: the inputs, and the scratch slots below (`lo`)
/// and above (`hi`) its destination slot `dst` (all in `lo` when it writes elsewhere).
pub(in crate::eval) struct Sources<'a, T> {
    inputs: [&'a [T]; 3],
    lo: &'a [T],
    hi: &'a [T],
    dst: usize,
    chunk: usize,
    n: usize,
}

impl<'a, T> Sources<'a, T> {
    /// Every slot readable: the inputs and all of `slots`.
    #[inline(always)]
    pub(in crate::eval) fn whole(
        inputs: [&'a [T]; 3],
        slots: &'a [T],
        chunk: usize,
        n: usize,
    ) -> Self {
        Sources {
            inputs,
            lo: slots,
            hi: &[],
            dst: usize::MAX,
            chunk,
            n,
        }
    }

    /// The first `n` values of slot `s` (never the destination).
    #[inline(always)]
    pub(in crate::eval) fn get(&self, s: u32) -> &'a [T] {
        let Some(s) = s.checked_sub(INPUTS) else {
            return &self.inputs[s as usize][..self.n];
        };
        let s = s as usize;
        if s < self.dst {
            &self.lo[s * self.chunk..][..self.n]
        } else {
            &self.hi[(s - self.dst - 1) * self.chunk..][..self.n]
        }
    }
}

#[inline(always)]
fn map1<T: Float>(d: &mut [T], a: &[T], f: impl Fn(T) -> T) {
    for (o, &x) in d.iter_mut().zip(a) {
        *o = f(x);
    }
}

#[inline(always)]
fn map3<T: Float>(d: &mut [T], a: &[T], b: &[T], c: &[T], mut f: impl FnMut(T, T, T) -> T) {
    for (((o, &x), &y), &z) in d.iter_mut().zip(a).zip(b).zip(c) {
        *o = f(x, y, z);
    }
}

#[inline(always)]
fn map2<T: Float>(d: &mut [T], a: &[T], b: &[T], f: impl Fn(T, T) -> T) {
    for ((o, &x), &y) in d.iter_mut().zip(a).zip(b) {
        *o = f(x, y);
    }
}

/// One loop per operation, each specialised by `scalar::unary` with a constant operation;
/// sine and cosine as [`reduced_loop`]s.
#[inline(always)]
fn unary_loop<T: Float>(u: Unary, d: &mut [T], a: &[T]) {
    macro_rules! arms {
        ($($v:ident),*) => {
            match u {
                Unary::Sin => reduced_loop(d, a, T::sin_reduced, T::sin),
                Unary::Cos => reduced_loop(d, a, T::cos_reduced, T::cos),
                $(Unary::$v => map1(d, a, |x| scalar::unary(Unary::$v, x)),)*
            }
        };
    }
    arms!(Neg, Abs, Sqrt, Acos, Exp, Log, Floor, Round)
}

/// `f` over every lane (branch-free, so the loop vectorises), then, where some lane is not
/// [`Float::reduced`], `whole` over those lanes: `whole` at every lane.
#[inline(always)]
fn reduced_loop<T: Float>(d: &mut [T], a: &[T], f: impl Fn(T) -> T, whole: impl Fn(T) -> T) {
    map1(d, a, f);
    if a.iter().fold(false, |any, x| any | !x.reduced()) {
        for (o, &x) in d.iter_mut().zip(a) {
            if !x.reduced() {
                *o = whole(x);
            }
        }
    }
}

/// `$body` in one arm per binary operation, `$op` there a constant naming the arm's operation:
/// the loops of [`binary_loop`] and its kin, each specialised by its constant.
macro_rules! each_binary {
    ($b:expr, $op:ident => $body:expr) => {
        each_binary!(@arms $b, $op => $body; Add, Sub, Mul, Div, Min, Max, Pow, Atan2, Lt)
    };
    (@arms $b:expr, $op:ident => $body:expr; $($v:ident),*) => {
        match $b {
            $(Binary::$v => {
                const $op: Binary = Binary::$v;
                $body
            })*
        }
    };
}

/// One loop per operation, each specialised by `scalar::binary` with a constant operation.
#[inline(always)]
fn binary_loop<T: Float>(b: Binary, d: &mut [T], x: &[T], y: &[T]) {
    each_binary!(b, OP => map2(d, x, y, |p, q| scalar::binary(OP, p, q)))
}

/// `op(x, k)` for an immediate `k`.
#[inline(always)]
fn binary_k_loop<T: Float>(b: Binary, d: &mut [T], x: &[T], k: T) {
    each_binary!(b, OP => map1(d, x, |p| scalar::binary(OP, p, k)))
}

/// `op(k, y)` for an immediate `k`.
#[inline(always)]
fn k_binary_loop<T: Float>(b: Binary, d: &mut [T], k: T, y: &[T]) {
    each_binary!(b, OP => map1(d, y, |q| scalar::binary(OP, k, q)))
}

/// A fused step: `finish(Σ term(xᵢ, kᵢ))` over `terms` operands, summed left to right, the
/// operations those of the instructions it replaces (one loop per combination).
#[inline(always)]
fn fused_loop<T: Float>(
    kind: Kind,
    terms: u8,
    finish: Finish,
    d: &mut [T],
    x: [&[T]; 3],
    ks: [T; 3],
    k: T,
) {
    macro_rules! sum {
        ($term:expr, $fin:expr) => {{
            let (term, fin) = ($term, $fin);
            match terms {
                1 => map1(d, x[0], |a| fin(term(a, ks[0]))),
                2 => map2(d, x[0], x[1], |a, b| fin(term(a, ks[0]) + term(b, ks[1]))),
                _ => map3(d, x[0], x[1], x[2], |a, b, c| {
                    fin(term(a, ks[0]) + term(b, ks[1]) + term(c, ks[2]))
                }),
            }
        }};
    }
    macro_rules! finishes {
        ($term:expr) => {
            match finish {
                Finish::None => sum!($term, |s: T| s),
                Finish::Add => sum!($term, |s: T| s + k),
                Finish::Sqrt => sum!($term, |s: T| s.sqrt()),
                Finish::SqrtAdd => sum!($term, |s: T| s.sqrt() + k),
            }
        };
    }
    let square = |t: T| t * t;
    match kind {
        Kind::SquareAdd => finishes!(|v: T, k: T| square(v + k)),
        Kind::SquareMax => finishes!(|v: T, k: T| square(v.max(k))),
        Kind::Scale => finishes!(|v: T, k: T| v * k),
    }
}
