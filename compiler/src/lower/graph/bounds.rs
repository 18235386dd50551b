//! The distances to a node's bounding volumes in the program: the guard distance of a bound
//! (sphere, box, the slabs of its finite axes), a field raised to the distance to its box
//! where only its zero set is read, and a node's local bound `max(f / L, β)`.

use super::{Field, Lowerer, SHRINK};
use crate::lower::Reg;
use crate::program::builder::{Builder, P};
use crate::scene::bounds::{Aabb, Bound, Bounds};
use crate::scene::NodeId;
use glam::DVec3;

impl Lowerer<'_> {
    /// Where the field is read for its zero set alone, an intersection whose planes cut its
    /// box smaller (`Bounds::raised`) raised to the distance to that box, `max(f, β, β_box)`:
    /// both are distance bounds, so their maximum is one, with f's solid, and at least the
    /// distance to the box the unions around it guard it by (`Bounds::zero_set`).
    pub(super) fn raise(&mut self, id: NodeId, f: Field, p: P) -> Field {
        if !self.zero_set || self.b.parametric {
            return f;
        }
        let Some(bound) = self.config.bounds.and_then(|b| b.raised(id)) else {
            return f;
        };
        let text = format!(
            "node {} intersection: at least the distance to the box its planes cut",
            self.number(id)
        );
        self.b.note(text);
        let beta = bound_distance(self.b, &bound, p);
        let (slab, _) = slab_distance(self.b, &bound, None, p);
        let d = self.b.max(f.d, beta);
        let d = self.b.max(d, slab);
        Field { d, m: f.m }
    }

    /// Where the field is read for its zero set alone, the plane children of intersection
    /// `id` that cut nothing of its solid ([`Bounds::uncut`]), which it leaves out: the solid is
    /// the same, and so are its surface's field and material.
    pub(super) fn uncut(&mut self, id: NodeId) -> Vec<NodeId> {
        let uncut = match self.config.bounds {
            Some(bounds) if self.zero_set && !self.b.parametric && self.config.optimise => {
                bounds.uncut(id).to_vec()
            }
            _ => return Vec::new(),
        };
        if !uncut.is_empty() {
            let text = format!(
                "node {} intersection: {} planes that cut nothing left out",
                self.number(id),
                uncut.len()
            );
            self.b.note(text);
        }
        uncut
    }

    /// The bound a union's child is guarded by: where the child's field is read for its zero
    /// set alone, the one that counts its intersections raised ([`Lowerer::raise`]).
    pub(super) fn guard_bound(&self, bounds: &Bounds, c: NodeId) -> Option<Bound> {
        if self.zero_set && !self.b.parametric {
            bounds.zero_set(c)
        } else {
            bounds.get(c)
        }
    }

    /// `max(f / l, β)` for node `id`'s field `f` and β the distance to its bound; where not
    /// `used` (a parametric program's operand whose L is 1 in this frame), both and `f`
    /// chosen by a constant, so that the program has the shape of the frames that use it.
    pub(super) fn local_bound(&mut self, id: NodeId, l: f64, p: P, used: bool) -> Field {
        self.zero_set = false;
        let f = self.node(id, p);
        self.zero_set = true;
        // A parametric program's comments name no number: the kernel's text is a function of
        // the frame's structure.
        let l_text = if self.b.parametric {
            "L".to_string()
        } else {
            format!("L = {}", crate::scene::dump_num(l))
        };
        let text = format!(
            "node {} local bound: the field divided by its {l_text}, at least the distance to its bound",
            self.number(id),
        );
        self.b.note(text);
        let scaled = self.b.mulc(f.d, 1.0 / l);
        let d = match self.config.bounds.and_then(|b| b.get(id)) {
            Some(bound) => {
                // Both the guard distance of the node's own bound and that of its box: a
                // union's guards skip the node where either is not nearer than the best
                // distance (its own guard, and the boxes of the groups around it), and the
                // result must then not be nearer either, so that culling keeps the field.
                let beta = bound_distance(self.b, &bound, p);
                let (slab, _) = slab_distance(self.b, &bound, None, p);
                let d = self.b.max(scaled, beta);
                self.b.max(d, slab)
            }
            None => scaled,
        };
        if self.b.parametric {
            let c = self.b.c(if used { 1.0 } else { 0.0 });
            let d = self.b.select(c, d, f.d);
            return Field { d, m: f.m };
        }
        Field { d, m: f.m }
    }
}

/// A lower bound of the field of a node with bound `b` at `p`: the signed distance `s` to the
/// sphere, or a lower bound of it for the box (the largest of the per-axis distances, over
/// its finite axes), with the volume padded by 10⁻³ of its size plus 10⁻⁴·(1 + |centre|),
/// then `SHRINK·s` (scale 1) or `min(s, SHRINK·scale·s)`. The padding and the shrinking
/// cover the rounding of both this value and the field (`docs/optimisation.md`).
pub(super) fn bound_distance(b: &mut Builder, bound: &Bound, p: P) -> Reg {
    let (box_volume, sphere_volume) = bound.volumes();
    let sphere = |b: &mut Builder| {
        let sp = bound.sphere;
        let pad = 1e-3 * sp.r + 1e-4 * (1.0 + DVec3::from(sp.c).length());
        let q = b.sub3c(p, sp.c);
        let l = b.len3(q);
        let s = b.subc(l, sp.r + pad);
        shrink(b, s, bound.scale)
    };
    let axes: Vec<usize> = (0..3).filter(|&i| bound.aabb.h[i].is_finite()).collect();
    let use_sphere = bound.finite() && sphere_volume <= 1.5 * box_volume;
    if bound.finite() && b.parametric {
        // Which volume is the smaller is a matter of numbers: both, and the choice a
        // constant (the same distance as the usual program's).
        let s = sphere(b);
        let x = box_distance(b, bound, &axes, p);
        let c = b.c(if use_sphere { 1.0 } else { 0.0 });
        return b.select(c, s, x);
    }
    if use_sphere {
        return sphere(b);
    }
    box_distance(b, bound, &axes, p)
}

/// What the guards on the path to a hierarchy node have computed: the box they narrowed the
/// point to, and per axis the registers of the last per-axis distance computed (to a box
/// containing the node's, so a lower bound of the distance to the node's box along that
/// axis) and of its positive part squared.
#[derive(Debug, Clone, Copy)]
pub(super) struct Tested {
    region: Aabb,
    terms: [Option<(Reg, Reg)>; 3],
}

/// The bound distance of a hierarchy node: the distance to its box, `|max(q, 0)| +
/// min(max q_i, 0)` with `q_i` the per-axis distance, computed afresh along the axes where the
/// box is narrower than the region tested above (by a tenth) and taken from the guards above
/// along the others. The distance along an axis to a larger box is a lower bound of the one to
/// this box, and the formula grows with every `q_i`, so the result is a lower bound of the
/// distance to the box. Returns the distance and what the guards below will know.
pub(super) fn slab_distance(
    b: &mut Builder,
    bound: &Bound,
    tested: Option<&Tested>,
    p: P,
) -> (Reg, Tested) {
    let (c, h) = (bound.aabb.c, bound.aabb.h);
    let mut state = tested.copied().unwrap_or(Tested {
        region: bound.aabb,
        terms: [None; 3],
    });
    let parametric = b.parametric;
    let fresh = |i: usize| match tested {
        // Whether a box is narrower than the region tested is a matter of numbers: every
        // finite axis afresh (a distance to the node's own box is as low a bound).
        _ if parametric => h[i].is_finite(),
        None => h[i].is_finite(),
        Some(t) => {
            let margin = 0.1 * t.region.h[i];
            c[i] - h[i] > t.region.c[i] - t.region.h[i] + margin
                || c[i] + h[i] < t.region.c[i] + t.region.h[i] - margin
        }
    };
    let size = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
    let pad = 1e-3 * size + 1e-4 * (1.0 + DVec3::from(c).length());
    for i in (0..3).filter(|&i| fresh(i)) {
        let d = b.subc(p[i], c[i]);
        let d = b.abs(d);
        let q = b.subc(d, h[i] + pad);
        let o = b.maxc(q, 0.0);
        state.terms[i] = Some((q, b.mul(o, o)));
        state.region.c[i] = c[i];
        state.region.h[i] = h[i];
    }
    let terms: Vec<(Reg, Reg)> = state.terms.iter().flatten().copied().collect();
    let s = match terms.split_first() {
        None => b.c(f64::NEG_INFINITY),
        Some((&(q0, o0), rest)) => {
            let (q, o) = rest
                .iter()
                .fold((q0, o0), |(q, o), &(qi, oi)| (b.max(q, qi), b.add(o, oi)));
            let outside = b.sqrt(o);
            let inside = b.minc(q, 0.0);
            b.add(outside, inside)
        }
    };
    (shrink(b, s, bound.scale), state)
}

/// The largest per-axis distance to the box over `axes` (a lower bound of the distance to
/// the box), padded and shrunk.
fn box_distance(b: &mut Builder, bound: &Bound, axes: &[usize], p: P) -> Reg {
    let bx = bound.aabb;
    let size = axes.iter().map(|&i| bx.h[i] * bx.h[i]).sum::<f64>().sqrt();
    let centre = axes.iter().map(|&i| bx.c[i] * bx.c[i]).sum::<f64>().sqrt();
    let pad = 1e-3 * size + 1e-4 * (1.0 + centre);
    let per_axis: Vec<Reg> = axes
        .iter()
        .map(|&i| {
            let d = b.subc(p[i], bx.c[i]);
            let d = b.abs(d);
            b.subc(d, bx.h[i] + pad)
        })
        .collect();
    let s = per_axis
        .into_iter()
        .reduce(|x, y| b.max(x, y))
        .unwrap_or_else(|| b.c(f64::NEG_INFINITY));
    shrink(b, s, bound.scale)
}

/// `SHRINK·s` for a bound of scale 1, else `min(s, SHRINK·scale·s)`.
fn shrink(b: &mut Builder, s: Reg, scale: f64) -> Reg {
    if b.parametric {
        // Whether the scale is 1 is a matter of numbers: both, and the choice a constant.
        let one = b.mulc(s, SHRINK);
        let t = b.mulc(s, SHRINK * scale);
        let less = b.min(s, t);
        let c = b.c(if scale >= 1.0 { 1.0 } else { 0.0 });
        return b.select(c, one, less);
    }
    if scale >= 1.0 {
        b.mulc(s, SHRINK)
    } else {
        let t = b.mulc(s, SHRINK * scale);
        b.min(s, t)
    }
}
