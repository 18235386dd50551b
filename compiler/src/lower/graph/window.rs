//! Repetitions whose copies reach out of their cells: the copies of the neighbouring cells
//! (or sectors, for a polar repetition) that the analysis's window names, and a lower bound
//! of the distance to the others.

use super::{rot2, rot2c, Field, Lowerer};
use crate::lower::shapes::cell_index;
use crate::lower::{Binary, Reg, Unary};
use crate::program::builder::P;
use crate::scene::analysis::Window;
use crate::scene::{NodeId, V3};

impl Lowerer<'_> {
    /// The neighbouring cells repetition `id` evaluates, if any.
    pub(super) fn window(&self, id: NodeId) -> Option<Window> {
        self.config.analysis.and_then(|a| a.window(id))
    }

    /// A repetition whose copies reach out of their cells: the minimum over the copies of the
    /// cells within `w.reach` of the point's own cell (clamped to those that exist), and
    /// `w.beyond`, a lower bound of the distance to the others.
    pub(super) fn windowed(
        &mut self,
        id: NodeId,
        child: NodeId,
        period: V3,
        count: Option<V3>,
        w: Window,
        p: P,
    ) -> Field {
        let b = &mut *self.b;
        // The own cell's index per axis, centred (−(n−1)/2 … (n−1)/2 for n copies).
        let cell: [Option<Reg>; 3] = [0, 1, 2].map(|i| {
            (period[i] != 0.0).then(|| cell_index(b, p[i], period[i], count.map(|n| n[i])))
        });
        let r = w.reach.map(|x| x as i64);
        let mut acc: Option<Field> = None;
        for i in -r[0]..=r[0] {
            for j in -r[1]..=r[1] {
                for k in -r[2]..=r[2] {
                    let offset = [i, j, k];
                    let b = &mut *self.b;
                    let q = b.map3(p, |b, x, a| {
                        let Some(c) = cell[a] else { return x };
                        let mut c = b.addc(c, offset[a] as f64);
                        if let Some(n) = count {
                            let half = (n[a] - 1.0) * 0.5;
                            c = b.clampc(c, -half, half);
                        }
                        let off = b.mulc(c, period[a]);
                        b.sub(x, off)
                    });
                    let f = self.node(child, q);
                    acc = Some(self.fold(acc, f));
                }
            }
        }
        self.resume(id, self.graph.node(id));
        let f = acc.expect("a window holds the own cell");
        if w.beyond.is_finite() {
            let cap = self.b.c(w.beyond);
            Field {
                d: self.b.min(f.d, cap),
                m: f.m,
            }
        } else {
            f
        }
    }

    /// A polar repetition about y: the copies of the sectors around the point's own, k + j
    /// for j in the window (`polar_window`, `scene/analysis/window.rs`), each the child at the
    /// point rotated back by (k + j)·360°/count (and mirrored across z = 0 for odd copies with
    /// `mirror`); where the window leaves copies out, the minimum with a lower bound of the
    /// distance to them: ρ·sin γ, and the distances to the node's bounding volumes, which hold
    /// every copy.
    pub(super) fn polar(
        &mut self,
        id: NodeId,
        count: u32,
        mirror: bool,
        child: NodeId,
        p: P,
    ) -> Field {
        if count <= 1 {
            return self.node(child, p);
        }
        let step = std::f64::consts::TAU / f64::from(count);
        let (below, above) = ((count as i64 - 1) / 2, count as i64 / 2);
        let (lo, hi, beyond) = match self.window(id) {
            Some(w) if w.beyond.is_finite() => {
                let r = i64::from(w.reach[0]);
                (-r, r, Some(w.beyond))
            }
            Some(_) => (-below, above, None),
            // No window: the analysis found none that bounds the field (reported), or there
            // is no analysis; the sector and its neighbours.
            None => (-below.min(1), above.min(1), None),
        };
        let b = &mut *self.b;
        let nz = b.neg(p[2]);
        let phi = b.bin(Binary::Atan2, nz, p[0]);
        let u = b.mulc(phi, 1.0 / step);
        let k = b.un(Unary::Round, u);
        // The point rotated into its own sector once (one cosine and one sine a point); the
        // other copies of the window are that point turned by constant rotations.
        let theta = b.mulc(k, step);
        let (c, s) = (b.un(Unary::Cos, theta), b.un(Unary::Sin, theta));
        let own = rot2(b, c, s, p[0], p[2]);
        let mut acc: Option<Field> = None;
        for j in lo..=hi {
            let b = &mut *self.b;
            let (x, mut z) = match j {
                0 => own,
                _ => {
                    let turn = j as f64 * step;
                    rot2c(b, turn.cos(), turn.sin(), own.0, own.1)
                }
            };
            if mirror {
                let kj = b.addc(k, j as f64);
                // The copy's parity: kj − 2·⌊kj/2⌋, with ⌊kj/2⌋ = round(kj/2 − 1/4).
                let half = b.mulc(kj, 0.5);
                let half = b.subc(half, 0.25);
                let floor = b.un(Unary::Round, half);
                let twice = b.mulc(floor, 2.0);
                let odd = b.sub(kj, twice);
                let sign = b.mulc(odd, -2.0);
                let sign = b.addc(sign, 1.0);
                z = b.mul(z, sign);
            }
            let f = self.node(child, [x, p[1], z]);
            acc = Some(self.fold(acc, f));
        }
        self.resume(id, self.graph.node(id));
        let f = acc.expect("a window holds the own sector");
        let Some(sin_gamma) = beyond else { return f };
        let b = &mut *self.b;
        let rho = b.len2(p[0], p[2]);
        let mut cap = b.mulc(rho, sin_gamma);
        if let Some(a) = self.config.analysis {
            // Every copy lies in the repetition's box, so the distance to the box is a lower
            // bound too, and the field stays above it as a bound's guarantee requires. The
            // box comes from the analysis, which every lowering has, so that the field does
            // not depend on whether culling volumes were computed.
            let bounds = a.node(id).bounds;
            let axes: Vec<usize> = (0..3)
                .filter(|&i| bounds.min[i].is_finite() && bounds.max[i].is_finite())
                .collect();
            if !axes.is_empty() {
                let extent = axes
                    .iter()
                    .map(|&i| bounds.min[i].abs().max(bounds.max[i].abs()))
                    .fold(0.0, f64::max);
                let b = &mut *self.b;
                let mut sum: Option<Reg> = None;
                for &i in &axes {
                    let above = b.subc(p[i], bounds.max[i]);
                    let below = b.subc(p[i], bounds.min[i]);
                    let below = b.neg(below);
                    let out = b.max(above, below);
                    let out = b.maxc(out, 0.0);
                    let sq = b.mul(out, out);
                    sum = Some(match sum {
                        Some(s) => b.add(s, sq),
                        None => sq,
                    });
                }
                let d = b.sqrt(sum.expect("an axis"));
                // A margin for the rounding of f32 evaluation.
                let d = b.subc(d, 1e-4 * (1.0 + extent));
                cap = b.max(cap, d);
            }
        }
        Field {
            d: self.b.min(f.d, cap),
            m: f.m,
        }
    }
}
