//! The Lipschitz bound of a user field, derived from its expression (docs/analysis.md,
//! "Fields"): every operation's value gets an interval, an interval per component of its
//! gradient, and a bound of its gradient's length; each rule bounds an operation's derivative
//! over its operands' intervals (the chain rule), and the field's L is the bound of its value.
//! An operation whose derivative is unbounded there (a division by a range holding 0, `floor`
//! across an integer, `sqrt` near 0) makes the bound infinite: nothing is proven. The same
//! intervals over half-spaces give the box of the field's solid (`solid_box`).

use crate::scene::field::{
    FBin, FOp, FUn, FieldFn, NOISE_LIPSCHITZ, NOISE_RANGE, VORONOI_LO, VORONOI_SPAN,
};
use crate::scene::NodeId;
use std::f64::consts::{FRAC_PI_2, PI};

/// A closed interval; infinite ends allowed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Iv {
    pub lo: f64,
    pub hi: f64,
}

impl Iv {
    const ALL: Iv = Iv {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    };
    const ZERO: Iv = Iv { lo: 0.0, hi: 0.0 };

    fn new(lo: f64, hi: f64) -> Iv {
        if lo.is_nan() || hi.is_nan() {
            Iv::ALL
        } else {
            Iv { lo, hi }
        }
    }
    fn point(x: f64) -> Iv {
        Iv::new(x, x)
    }
    fn sym(m: f64) -> Iv {
        Iv::new(-m, m)
    }
    /// The largest magnitude.
    fn mag(self) -> f64 {
        self.lo.abs().max(self.hi.abs())
    }
    fn add(self, o: Iv) -> Iv {
        Iv::new(self.lo + o.lo, self.hi + o.hi)
    }
    fn neg(self) -> Iv {
        Iv::new(-self.hi, -self.lo)
    }
    fn sub(self, o: Iv) -> Iv {
        self.add(o.neg())
    }
    fn mul(self, o: Iv) -> Iv {
        if self == Iv::ZERO || o == Iv::ZERO {
            return Iv::ZERO;
        }
        // 0 · ∞ is a product of a bounded factor with an unbounded one: 0 stands for it.
        let p = |a: f64, b: f64| {
            let x = a * b;
            if x.is_nan() {
                0.0
            } else {
                x
            }
        };
        let c = [
            p(self.lo, o.lo),
            p(self.lo, o.hi),
            p(self.hi, o.lo),
            p(self.hi, o.hi),
        ];
        Iv::new(
            c.iter().fold(f64::INFINITY, |a, &b| a.min(b)),
            c.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b)),
        )
    }
    fn hull(self, o: Iv) -> Iv {
        Iv::new(self.lo.min(o.lo), self.hi.max(o.hi))
    }
    fn contains(self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }
    /// The square: never negative.
    fn sqr(self) -> Iv {
        let m = self.mag();
        let lo = if self.contains(0.0) {
            0.0
        } else {
            self.lo.abs().min(self.hi.abs())
        };
        Iv::new(lo * lo, m * m)
    }
}

/// What is known of one value of the expression.
#[derive(Debug, Clone, Copy)]
struct Val {
    range: Iv,
    /// ∂/∂x, ∂/∂y, ∂/∂z.
    grad: [Iv; 3],
    /// A bound of the gradient's length.
    norm: f64,
}

impl Val {
    /// The best bound of the gradient's length: the norm bound, or the length of the
    /// gradient's component intervals.
    fn n(&self) -> f64 {
        let g = self
            .grad
            .iter()
            .map(|c| c.mag().powi(2))
            .sum::<f64>()
            .sqrt();
        let n = self.norm.min(g);
        if n.is_nan() {
            f64::INFINITY
        } else {
            n
        }
    }

    /// `φ(self)` where φ' lies in `d` over the operand's range.
    fn chain(&self, range: Iv, d: Iv) -> Val {
        Val {
            range,
            grad: self.grad.map(|g| d.mul(g)),
            norm: mul0(d.mag(), self.n()),
        }
    }
}

/// a · b with 0 · ∞ = 0 (a zero derivative of an unbounded operand).
fn mul0(a: f64, b: f64) -> f64 {
    if a == 0.0 || b == 0.0 {
        0.0
    } else {
        a * b
    }
}

/// A bound of the operator norm of the Jacobian whose rows are `rows`' gradients: the least
/// of the Frobenius norm of the magnitudes, √(‖·‖₁ ‖·‖∞) of them, and the rows' bounds'
/// root sum of squares.
fn jacobian_norm(rows: &[Val]) -> f64 {
    let m: Vec<[f64; 3]> = rows.iter().map(|r| r.grad.map(Iv::mag)).collect();
    let frob = m.iter().flatten().map(|x| x * x).sum::<f64>().sqrt();
    let row = m.iter().map(|r| r.iter().sum::<f64>()).fold(0.0, f64::max);
    let col = (0..3)
        .map(|j| m.iter().map(|r| r[j]).sum::<f64>())
        .fold(0.0, f64::max);
    let rss = rows.iter().map(|r| r.n().powi(2)).sum::<f64>().sqrt();
    let n = frob.min((row * col).sqrt()).min(rss);
    if n.is_nan() {
        f64::INFINITY
    } else {
        n
    }
}

/// An L-Lipschitz function of the vector `rows`: the gradient component j is at most L times
/// the length of column j of the Jacobian.
fn lipschitz_of(rows: &[Val], l: f64, range: Iv) -> Val {
    let grad = [0, 1, 2].map(|j| {
        let c = rows
            .iter()
            .map(|r| r.grad[j].mag().powi(2))
            .sum::<f64>()
            .sqrt();
        Iv::sym(mul0(l, c))
    });
    Val {
        range,
        grad,
        norm: mul0(l, jacobian_norm(rows)),
    }
}

/// The range of sin over `x`.
fn sin_range(x: Iv) -> Iv {
    if !(x.hi - x.lo < 2.0 * PI) {
        return Iv::new(-1.0, 1.0);
    }
    let mut r = Iv::point(x.lo.sin()).hull(Iv::point(x.hi.sin()));
    // The extremes at π/2 + kπ within the interval.
    let k0 = ((x.lo - FRAC_PI_2) / PI).ceil();
    let mut k = k0;
    while FRAC_PI_2 + k * PI <= x.hi {
        let v = if (k as i64).rem_euclid(2) == 0 {
            1.0
        } else {
            -1.0
        };
        r = r.hull(Iv::point(v));
        k += 1.0;
        if k - k0 > 3.0 {
            break;
        }
    }
    r
}

fn unary(u: FUn, a: &Val) -> Val {
    let r = a.range;
    let unbounded = |range: Iv| Val {
        range,
        grad: [Iv::ALL; 3],
        norm: f64::INFINITY,
    };
    match u {
        FUn::Neg => a.chain(r.neg(), Iv::point(-1.0)),
        FUn::Abs => {
            let range = if r.lo >= 0.0 {
                r
            } else if r.hi <= 0.0 {
                r.neg()
            } else {
                Iv::new(0.0, r.mag())
            };
            let d = if r.lo >= 0.0 {
                Iv::point(1.0)
            } else if r.hi <= 0.0 {
                Iv::point(-1.0)
            } else {
                Iv::new(-1.0, 1.0)
            };
            a.chain(range, d)
        }
        FUn::Sqrt => {
            let lo = r.lo.max(0.0);
            let range = Iv::new(lo.sqrt(), r.hi.max(0.0).sqrt());
            if lo > 0.0 {
                a.chain(range, Iv::new(0.5 / r.hi.sqrt(), 0.5 / lo.sqrt()))
            } else {
                unbounded(range)
            }
        }
        FUn::Sin => a.chain(
            sin_range(r),
            sin_range(Iv::new(r.lo + FRAC_PI_2, r.hi + FRAC_PI_2)),
        ),
        FUn::Cos => a.chain(
            sin_range(Iv::new(r.lo + FRAC_PI_2, r.hi + FRAC_PI_2)),
            sin_range(r).neg(),
        ),
        FUn::Tan => {
            // Within one branch (−π/2, π/2) + kπ, tan is increasing with tan' = 1 + tan².
            let k = (r.lo / PI + 0.5).floor();
            let (lo, hi) = (k * PI - FRAC_PI_2, k * PI + FRAC_PI_2);
            if r.lo > lo && r.hi < hi {
                let range = Iv::new(r.lo.tan(), r.hi.tan());
                a.chain(range, Iv::point(1.0).add(range.sqr()))
            } else {
                unbounded(Iv::ALL)
            }
        }
        FUn::Exp => {
            let range = Iv::new(r.lo.exp(), r.hi.exp());
            a.chain(range, range)
        }
        FUn::Log => {
            if r.lo > 0.0 {
                a.chain(
                    Iv::new(r.lo.ln(), r.hi.ln()),
                    Iv::new(1.0 / r.hi, 1.0 / r.lo),
                )
            } else {
                unbounded(Iv::new(f64::NEG_INFINITY, r.hi.max(0.0).ln()))
            }
        }
        FUn::Floor => {
            let range = Iv::new(r.lo.floor(), r.hi.floor());
            if range.lo == range.hi {
                a.chain(range, Iv::ZERO)
            } else {
                unbounded(range)
            }
        }
        FUn::Smooth => {
            let (lo, hi) = (r.lo.clamp(0.0, 1.0), r.hi.clamp(0.0, 1.0));
            let s = |t: f64| t * t * (3.0 - 2.0 * t);
            let ds = |t: f64| 6.0 * t * (1.0 - t);
            let top = if lo <= 0.5 && 0.5 <= hi {
                1.5
            } else {
                ds(lo).max(ds(hi))
            };
            a.chain(Iv::new(s(lo), s(hi)), Iv::new(0.0, top))
        }
    }
}

fn binary(op: FBin, a: &Val, b: &Val) -> Val {
    let unbounded = |range: Iv| Val {
        range,
        grad: [Iv::ALL; 3],
        norm: f64::INFINITY,
    };
    match op {
        FBin::Add | FBin::Sub => {
            let (range, grad) = if op == FBin::Add {
                (
                    a.range.add(b.range),
                    [0, 1, 2].map(|j| a.grad[j].add(b.grad[j])),
                )
            } else {
                (
                    a.range.sub(b.range),
                    [0, 1, 2].map(|j| a.grad[j].sub(b.grad[j])),
                )
            };
            Val {
                range,
                grad,
                norm: a.n() + b.n(),
            }
        }
        FBin::Mul => Val {
            range: a.range.mul(b.range),
            grad: [0, 1, 2].map(|j| a.range.mul(b.grad[j]).add(b.range.mul(a.grad[j]))),
            norm: mul0(a.range.mag(), b.n()) + mul0(b.range.mag(), a.n()),
        },
        FBin::Div => {
            if b.range.contains(0.0) {
                return unbounded(Iv::ALL);
            }
            // 1/b, whose derivative −1/b² lies in −[1/hi², 1/lo²] of |b|.
            let inv = Iv::new(1.0 / b.range.hi, 1.0 / b.range.lo);
            let recip = b.chain(inv, inv.sqr().neg());
            binary(FBin::Mul, a, &recip)
        }
        FBin::Min | FBin::Max => {
            let range = if op == FBin::Min {
                Iv::new(a.range.lo.min(b.range.lo), a.range.hi.min(b.range.hi))
            } else {
                Iv::new(a.range.lo.max(b.range.lo), a.range.hi.max(b.range.hi))
            };
            // Where one operand is always the result, its gradient is the result's.
            let (first, second) = if op == FBin::Min {
                (a.range.hi < b.range.lo, b.range.hi < a.range.lo)
            } else {
                (a.range.lo > b.range.hi, b.range.lo > a.range.hi)
            };
            if first {
                Val { range, ..*a }
            } else if second {
                Val { range, ..*b }
            } else {
                Val {
                    range,
                    grad: [0, 1, 2].map(|j| a.grad[j].hull(b.grad[j])),
                    norm: a.n().max(b.n()),
                }
            }
        }
        FBin::Pow => {
            let c = b.range;
            if c.lo != c.hi || b.n() != 0.0 {
                return unbounded(Iv::new(0.0, f64::INFINITY));
            }
            let c = c.lo;
            let lo = a.range.lo.max(0.0);
            let hi = a.range.hi.max(0.0);
            let range = Iv::new(lo.powf(c), hi.powf(c)).hull(Iv::new(hi.powf(c), lo.powf(c)));
            let range = Iv::new(range.lo.min(range.hi), range.hi.max(range.lo));
            if c == 0.0 {
                return a.chain(Iv::point(1.0), Iv::ZERO);
            }
            if c == 1.0 {
                return a.chain(range, Iv::point(1.0));
            }
            if c < 1.0 && lo == 0.0 {
                return unbounded(range);
            }
            let d1 = c * lo.powf(c - 1.0);
            let d2 = c * hi.powf(c - 1.0);
            a.chain(range, Iv::new(d1.min(d2), d1.max(d2)))
        }
        FBin::Atan2 => {
            // |∇atan2(y, x)| = |x∇y − y∇x| / r² ≤ √2 · max(|∇y|, |∇x|) / r.
            let gap = |r: Iv| {
                if r.contains(0.0) {
                    0.0
                } else {
                    r.lo.abs().min(r.hi.abs())
                }
            };
            let rmin = gap(a.range).hypot(gap(b.range));
            let range = Iv::new(-PI, PI);
            if rmin == 0.0 {
                return unbounded(range);
            }
            let n = std::f64::consts::SQRT_2 * a.n().max(b.n()) / rmin;
            Val {
                range,
                grad: [Iv::sym(n); 3],
                norm: n,
            }
        }
    }
}

/// The Lipschitz constant the expression's value `f.out[0]` is proven to have over all of
/// space, with `shape(id)` the L of a shape it reads; infinite where nothing is proven.
pub fn lipschitz(f: &FieldFn, shape: impl Fn(NodeId) -> f64) -> f64 {
    let vals = values(f, EVERYWHERE, shape, |_, _| f64::NEG_INFINITY);
    f.out.first().map_or(0.0, |&o| vals[o as usize].n())
}

/// Doublings of the search for a side of [`solid_box`] beyond which the solid is proven
/// absent (from 1 to 2⁶³), and halvings of the bisection that then narrows it.
const DOUBLINGS: i32 = 63;
const HALVINGS: u32 = 60;

/// A box around the solid of `f` (the points where its value is ≤ 0) that the expression
/// proves by interval arithmetic (docs/analysis.md, "Fields"): a side of the box is a plane
/// beyond which the value's interval over the half-space is above 0. Each of the six sides
/// is found by doubling until such a half-space is found (none within 2⁶³: the side is
/// infinite), then by bisection; then again with the other axes limited to the box found,
/// which tightens expressions that mix the coordinates (a length). `below(id, q)` is a lower
/// bound of the field of a shape the expression reads, over the box `q` of points it is read
/// at (−∞ when none is known). The box may be loose, never too small: it is widened by a
/// millionth of its size for the rounding of the interval bounds.
pub fn solid_box(f: &FieldFn, below: impl Fn(NodeId, Region) -> f64) -> ([f64; 3], [f64; 3]) {
    let Some(&out) = f.out.first() else {
        return ([f64::NEG_INFINITY; 3], [f64::INFINITY; 3]);
    };
    let empty = |r: Region| {
        let v = values(f, r, |_| f64::INFINITY, &below)[out as usize].range;
        v.lo > 0.0
    };
    let mut bounds = EVERYWHERE;
    for _pass in 0..2 {
        let within = bounds;
        for axis in 0..3 {
            for side in [1.0f64, -1.0] {
                // The half-space beyond `t` along the side's direction, within `within`.
                let beyond = |t: f64| {
                    let mut r = within;
                    r[axis] = if side > 0.0 {
                        [t, f64::INFINITY]
                    } else {
                        [f64::NEG_INFINITY, -t]
                    };
                    empty(r)
                };
                let Some(mut far) = (0..=DOUBLINGS).map(|k| 2f64.powi(k)).find(|&t| beyond(t))
                else {
                    continue;
                };
                let Some(mut near) = (0..=DOUBLINGS)
                    .map(|k| -(2f64.powi(k)))
                    .find(|&t| !beyond(t))
                else {
                    // Nothing anywhere along the axis: no solid.
                    return ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
                };
                for _ in 0..HALVINGS {
                    let mid = 0.5 * (near + far);
                    if beyond(mid) {
                        far = mid;
                    } else {
                        near = mid;
                    }
                }
                let k = if side > 0.0 { 1 } else { 0 };
                let t = side * far;
                bounds[axis][k] = if side > 0.0 {
                    t.min(bounds[axis][k])
                } else {
                    t.max(bounds[axis][k])
                };
            }
        }
    }
    let size = bounds
        .iter()
        .flatten()
        .filter(|x| x.is_finite())
        .fold(0.0f64, |m, x| m.max(x.abs()));
    let pad = 1e-6 * size + 1e-300;
    (bounds.map(|[a, _]| a - pad), bounds.map(|[_, b]| b + pad))
}

/// Where the point lies, for [`values`]: a box, infinite sides allowed.
type Region = [[f64; 2]; 3];

/// All of space.
const EVERYWHERE: Region = [[f64::NEG_INFINITY, f64::INFINITY]; 3];

/// What is known of every value of `f` for points in `region`, with `shape(id)` the L of a
/// shape the expression reads and `below(id, q)` a lower bound of that shape's field over
/// the box `q` of the points it is read at.
fn values(
    f: &FieldFn,
    region: Region,
    shape: impl Fn(NodeId) -> f64,
    below: impl Fn(NodeId, Region) -> f64,
) -> Vec<Val> {
    let mut vals: Vec<Val> = Vec::with_capacity(f.ops.len());
    for op in &f.ops {
        let get = |s: &u32| vals[*s as usize];
        let v = match op {
            FOp::Coord(axis) => {
                let mut grad = [Iv::ZERO; 3];
                grad[*axis as usize % 3] = Iv::point(1.0);
                let [lo, hi] = region[*axis as usize % 3];
                Val {
                    range: Iv::new(lo, hi),
                    grad,
                    norm: 1.0,
                }
            }
            FOp::Const(c) => Val {
                range: Iv::point(*c),
                grad: [Iv::ZERO; 3],
                norm: 0.0,
            },
            FOp::Un(u, a) => unary(*u, &get(a)),
            FOp::Bin(b, x, y) => binary(*b, &get(x), &get(y)),
            FOp::Length(v) => {
                let rows: Vec<Val> = v.iter().map(get).collect();
                let hi = rows.iter().map(|r| r.range.sqr().hi).sum::<f64>().sqrt();
                let lo = rows.iter().map(|r| r.range.sqr().lo).sum::<f64>().sqrt();
                lipschitz_of(&rows, 1.0, Iv::new(lo, hi))
            }
            FOp::Distance(id, q) => {
                let rows: Vec<Val> = q.iter().map(get).collect();
                let at = [0, 1, 2].map(|i| match rows.get(i) {
                    Some(r) => [r.range.lo, r.range.hi],
                    None => [0.0, 0.0],
                });
                let lo = below(*id, at);
                lipschitz_of(&rows, shape(*id), Iv::new(lo, f64::INFINITY))
            }
            FOp::Noise(v) => {
                let rows: Vec<Val> = v.iter().map(get).collect();
                lipschitz_of(&rows, NOISE_LIPSCHITZ, Iv::sym(NOISE_RANGE))
            }
            FOp::Voronoi(v) => {
                let rows: Vec<Val> = v.iter().map(get).collect();
                let far = (VORONOI_LO + VORONOI_SPAN) * (v.len() as f64).sqrt();
                lipschitz_of(&rows, 1.0, Iv::new(0.0, far))
            }
            FOp::Mix(a, b, t) => {
                let (a, b, t) = (get(a), get(b), get(t));
                let d = binary(FBin::Sub, &b, &a);
                let mut v = binary(FBin::Add, &a, &binary(FBin::Mul, &d, &t));
                // For t within [0, 1] the value lies between a's and b's.
                if t.range.lo >= 0.0 && t.range.hi <= 1.0 {
                    let lo = v.range.lo.max(a.range.lo.min(b.range.lo));
                    let hi = v.range.hi.min(a.range.hi.max(b.range.hi));
                    v.range = Iv::new(lo, hi);
                }
                v
            }
            // Constant within a lattice cell: a step wherever an input crosses a whole number,
            // so nothing is proven unless the inputs are constant.
            FOp::Hash(v) => {
                let rows: Vec<Val> = v.iter().map(get).collect();
                let range = Iv::new(0.0, 1.0);
                if rows.iter().all(|r| r.norm == 0.0) {
                    lipschitz_of(&rows, 0.0, range)
                } else {
                    Val {
                        range,
                        grad: [Iv::ALL; 3],
                        norm: f64::INFINITY,
                    }
                }
            }
        };
        vals.push(v);
    }
    vals
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field(ops: Vec<FOp>) -> FieldFn {
        let out = vec![ops.len() as u32 - 1];
        FieldFn { ops, out }
    }

    /// `length(p) − 1` is in the unit cube (within the millionth it is widened by); a
    /// constant above 0 has no solid; `sin x` (a slab of sheets) has no box along x; a `mix`
    /// of two bounded fields by a weight within [0, 1] is bounded by both.
    #[test]
    fn solid_boxes_come_from_the_intervals() {
        let none = |_: NodeId, _: Region| f64::NEG_INFINITY;
        let sphere = field(vec![
            FOp::Coord(0),
            FOp::Coord(1),
            FOp::Coord(2),
            FOp::Length(vec![0, 1, 2]),
            FOp::Const(1.0),
            FOp::Bin(FBin::Sub, 3, 4),
        ]);
        let (lo, hi) = solid_box(&sphere, none);
        for i in 0..3 {
            assert!((lo[i] + 1.0).abs() < 1e-5 && lo[i] <= -1.0, "{lo:?}");
            assert!((hi[i] - 1.0).abs() < 1e-5 && hi[i] >= 1.0, "{hi:?}");
        }
        let (lo, hi) = solid_box(&field(vec![FOp::Const(1.0)]), none);
        assert!((0..3).any(|i| lo[i] > hi[i]), "empty: {lo:?} {hi:?}");
        let sheets = field(vec![FOp::Coord(0), FOp::Un(FUn::Sin, 0)]);
        let (lo, hi) = solid_box(&sheets, none);
        assert_eq!((lo[0], hi[0]), (f64::NEG_INFINITY, f64::INFINITY));
        // A blend of two spheres' fields, of radius 1 about 0 and about x = 1, by a weight in
        // [0, 1] that varies with the point: inside both spheres' boxes together. Written as
        // its three operations the difference of the two would be unbounded and so the box.
        let mut ops = sphere.ops.clone();
        ops.extend([
            FOp::Const(1.0),
            FOp::Bin(FBin::Sub, 0, 6),
            FOp::Length(vec![7, 1, 2]),
            FOp::Bin(FBin::Sub, 8, 4),
            FOp::Un(FUn::Sin, 1),
            FOp::Const(0.5),
            FOp::Bin(FBin::Mul, 10, 11),
            FOp::Bin(FBin::Add, 12, 11),
            FOp::Mix(5, 9, 13),
        ]);
        let (lo, hi) = solid_box(&field(ops), none);
        assert!(lo[0] >= -1.0 - 1e-5 && hi[0] <= 2.0 + 1e-5, "{lo:?} {hi:?}");
        assert!(lo[1] >= -1.0 - 1e-5 && hi[1] <= 1.0 + 1e-5, "{lo:?} {hi:?}");
    }
}
