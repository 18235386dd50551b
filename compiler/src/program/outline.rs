//! Outlines: the glyphs of a text as data (lines and quadratic curves, grouped by glyph, each
//! glyph with its box), the one definition of their signed distance ([`distance`]), which the
//! interpreter, the reference run and the Rust writer follow and the WGSL function of
//! `back/wgsl/outline.rs` mirrors step for step, and their words in `scene_data`
//! ([`Outline::words`]).
//!
//! The distance is the nearest of the curves (exact: the closest point of a quadratic curve is
//! a root of a cubic, solved in closed form as in Inigo Quilez's `sdBezier`, each root then
//! refined by one Newton step, the ends always candidates), negative where the winding number
//! of the curves about the point is not zero (TrueType's fill rule). The winding number is
//! counted along a ray towards +x: every curve is monotone in y (the font reader splits them at
//! their turning points), so it crosses the ray's line at most once, at the root of a quadratic
//! of one variable. The glyph whose box is nearest goes first, then the others in order, each
//! skipped where its box is farther than the best distance so far: its winding number about a
//! point outside its box is zero, so only the glyphs near the point cost anything.

use super::Float;

/// One piece of a glyph's outline, from `a` to `c`: a line (`b` unused) or the quadratic curve
/// with control point `b`, monotone in y. A curve is never a line: its `a - 2b + c` is not
/// zero (the font reader makes such curves lines).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    pub a: [f64; 2],
    pub b: [f64; 2],
    pub c: [f64; 2],
    pub line: bool,
}

/// The closed contours of one glyph, and the box of their points.
#[derive(Debug, Clone, PartialEq)]
pub struct Glyph {
    pub lo: [f64; 2],
    pub hi: [f64; 2],
    pub segments: Vec<Segment>,
}

/// The glyphs of a text, laid out in the plane: a profile given as data.
#[derive(Clone, PartialEq, Default)]
pub struct Outline {
    pub glyphs: Vec<Glyph>,
}

impl std::fmt::Debug for Outline {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Outline({} glyphs, {} segments)",
            self.glyphs.len(),
            self.segments()
        )
    }
}

/// The squared distances at or above this are "none yet" (a finite literal the WGSL function
/// can write too).
pub const FAR: f64 = 3.0e38;

impl Outline {
    /// The number of segments of every glyph.
    pub fn segments(&self) -> usize {
        self.glyphs.iter().map(|g| g.segments.len()).sum()
    }

    /// The box of every glyph: (low corner, high corner).
    pub fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for g in &self.glyphs {
            for i in 0..2 {
                lo[i] = lo[i].min(g.lo[i]);
                hi[i] = hi[i].max(g.hi[i]);
            }
        }
        (lo, hi)
    }

    /// The outline as `vec4<f32>` words of `scene_data`: `[0].x` the number of glyphs; per
    /// glyph its box (lo.x, lo.y, hi.x, hi.y), then its number of segments (in `.x`), then per
    /// segment `(a.x, a.y, b.x, b.y)` and `(c.x, c.y, 1 for a line else 0, 0)`. Counts are
    /// held as floats (exact below 2^24, which the checker's limits keep them under).
    pub fn words(&self) -> Vec<[f32; 4]> {
        let bits = |n: usize| n as f32;
        let mut out = vec![[bits(self.glyphs.len()), 0.0, 0.0, 0.0]];
        for g in &self.glyphs {
            out.push([g.lo[0], g.lo[1], g.hi[0], g.hi[1]].map(|v| v as f32));
            out.push([bits(g.segments.len()), 0.0, 0.0, 0.0]);
            for s in &g.segments {
                out.push([s.a[0], s.a[1], s.b[0], s.b[1]].map(|v| v as f32));
                let kind = if s.line { 1.0 } else { 0.0 };
                out.push([s.c[0] as f32, s.c[1] as f32, kind, 0.0]);
            }
        }
        out
    }

    /// The number of `vec4` words of [`Outline::words`].
    pub fn word_count(&self) -> usize {
        1 + self
            .glyphs
            .iter()
            .map(|g| 2 + 2 * g.segments.len())
            .sum::<usize>()
    }
}

/// The signed distance at (x, y) to the outline `o` (see the module doc).
pub fn distance<T: Float>(o: &Outline, x: T, y: T) -> T {
    let zero = T::zero();
    let mut best = T::from_f64(FAR);
    let mut wind: i32 = 0;
    let gap = |g: &Glyph| {
        let dx = (T::from_f64(g.lo[0]) - x)
            .max(x - T::from_f64(g.hi[0]))
            .max(zero);
        let dy = (T::from_f64(g.lo[1]) - y)
            .max(y - T::from_f64(g.hi[1]))
            .max(zero);
        dx * dx + dy * dy
    };
    // The glyph whose box is nearest first, so that the others are skipped sooner.
    let mut first = 0;
    let mut near = best;
    for (k, g) in o.glyphs.iter().enumerate() {
        let d = gap(g);
        if d < near {
            near = d;
            first = k;
        }
    }
    let order = std::iter::once(first).chain((0..o.glyphs.len()).filter(|&k| k != first));
    for g in order.map(|k| &o.glyphs[k]) {
        let gap = gap(g);
        // Outside the box and no nearer than the best: nothing of this glyph counts.
        if gap > zero && gap >= best {
            continue;
        }
        for s in &g.segments {
            let v = |p: [f64; 2]| (T::from_f64(p[0]), T::from_f64(p[1]));
            let (a, c) = (v(s.a), v(s.c));
            if s.line {
                let (d2, w) = line(a, c, x, y);
                if d2 < best {
                    best = d2;
                }
                wind += w;
            } else {
                let b = v(s.b);
                let lx = a.0.min(b.0).min(c.0);
                let hx = a.0.max(b.0).max(c.0);
                let ly = a.1.min(b.1).min(c.1);
                let hy = a.1.max(b.1).max(c.1);
                let gx = (lx - x).max(x - hx).max(zero);
                let gy = (ly - y).max(y - hy).max(zero);
                if gx * gx + gy * gy < best {
                    let d2 = quad(a, b, c, x, y);
                    if d2 < best {
                        best = d2;
                    }
                }
                wind += crossing(a, b, c, x, y);
            }
        }
    }
    let d = best.sqrt();
    if wind != 0 {
        -d
    } else {
        d
    }
}

/// The squared distance at (x, y) to the line from `a` to `c`, and its crossing of the ray
/// towards +x (+1 upwards, -1 downwards, 0; a line includes its lower end).
#[inline(always)]
fn line<T: Float>(a: (T, T), c: (T, T), x: T, y: T) -> (T, i32) {
    let (ex, ey) = (c.0 - a.0, c.1 - a.1);
    let (wx, wy) = (x - a.0, y - a.1);
    let t = ((wx * ex + wy * ey) / (ex * ex + ey * ey)).clamp(T::zero(), T::one());
    let (qx, qy) = (wx - ex * t, wy - ey * t);
    let cross = ex * wy - ey * wx;
    let mut w = 0;
    if a.1 <= y && y < c.1 && cross > T::zero() {
        w = 1;
    }
    if c.1 <= y && y < a.1 && cross < T::zero() {
        w = -1;
    }
    (qx * qx + qy * qy, w)
}

/// The crossing of the ray from (x, y) towards +x by the curve from `a` through `b` to `c`,
/// monotone in y (as [`line`]'s): where it meets the line of the ray, at the root in [0, 1] of
/// (a.y − 2b.y + c.y)t² + 2(b.y − a.y)t + a.y − y, taken in the form that does not cancel.
#[inline(always)]
fn crossing<T: Float>(a: (T, T), b: (T, T), c: (T, T), x: T, y: T) -> i32 {
    let up = a.1 <= y && y < c.1;
    let down = c.1 <= y && y < a.1;
    if !(up || down) {
        return 0;
    }
    let (zero, one, two) = (T::zero(), T::one(), T::from_f64(2.0));
    let s = if up { one } else { -one };
    let qa = a.1 - two * b.1 + c.1;
    let qb = two * (b.1 - a.1);
    let qc = a.1 - y;
    let disc = (qb * qb - T::from_f64(4.0) * qa * qc).max(zero);
    let q = T::from_f64(-0.5) * (qb + s * disc.sqrt());
    let t = if q != zero {
        (qc / q).clamp(zero, one)
    } else {
        zero
    };
    let u = one - t;
    let xt = a.0 * u * u + two * b.0 * t * u + c.0 * t * t;
    if xt > x {
        if up {
            1
        } else {
            -1
        }
    } else {
        0
    }
}

/// The squared distance at (x, y) to the quadratic curve from `a` through `b` to `c`: the
/// nearest of its ends and of the roots of the cubic (Quilez's `sdBezier`: Cardano's formula
/// where it has one real root, the trigonometric form where three, of which the middle one is
/// never the nearest), each root refined by a Newton step.
#[inline(always)]
fn quad<T: Float>(a: (T, T), b: (T, T), c: (T, T), x: T, y: T) -> T {
    let (zero, one, two, three) = (T::zero(), T::one(), T::from_f64(2.0), T::from_f64(3.0));
    let dot = |p: (T, T), q: (T, T)| p.0 * q.0 + p.1 * q.1;
    let ea = (b.0 - a.0, b.1 - a.1);
    let eb = (a.0 - two * b.0 + c.0, a.1 - two * b.1 + c.1);
    let ec = (two * ea.0, two * ea.1);
    let ed = (a.0 - x, a.1 - y);
    let kk = one / dot(eb, eb);
    let kx = kk * dot(ea, eb);
    let ky = kk * (two * dot(ea, ea) + dot(ed, eb)) / three;
    let kz = kk * dot(ed, ea);
    let p = ky - kx * kx;
    let q = kx * (two * kx * kx - three * ky) + kz;
    let h = q * q + T::from_f64(4.0) * p * p * p;
    let (t1, t2) = if h >= zero {
        let h = h.sqrt();
        let cbrt = |v: T| {
            let r = v.abs().powf(T::from_f64(1.0 / 3.0));
            if v < zero {
                -r
            } else {
                r
            }
        };
        let t = cbrt((h - q) / two) + cbrt((-h - q) / two) - kx;
        (t, t)
    } else {
        let z = (-p).sqrt();
        let v = (q / (p * z * two)).clamp(-one, one).acos() / three;
        let m = v.cos();
        let n = v.sin() * T::from_f64(1.732_050_808);
        ((m + m) * z - kx, (-n - m) * z - kx)
    };
    // The point of the curve at t, less (x, y): ed + (ec + eb·t)·t.
    let at = |t: T| (ed.0 + (ec.0 + eb.0 * t) * t, ed.1 + (ec.1 + eb.1 * t) * t);
    let newton = |t: T| {
        let t = t.clamp(zero, one);
        let f = at(t);
        let e = (ea.0 + eb.0 * t, ea.1 + eb.1 * t);
        let g = dot(f, e);
        let gp = two * dot(e, e) + dot(f, eb);
        if gp > zero {
            (t - g / gp).clamp(zero, one)
        } else {
            t
        }
    };
    let (f1, f2) = (at(newton(t1)), at(newton(t2)));
    let end = (c.0 - x, c.1 - y);
    dot(ed, ed)
        .min(dot(end, end))
        .min(dot(f1, f1))
        .min(dot(f2, f2))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square (lines) and a disc-like shape of four quarter curves.
    fn shapes() -> Outline {
        let l = |a: [f64; 2], c: [f64; 2]| Segment {
            a,
            b: a,
            c,
            line: true,
        };
        let square = Glyph {
            lo: [0.0, 0.0],
            hi: [1.0, 1.0],
            segments: vec![
                l([0.0, 0.0], [1.0, 0.0]),
                l([1.0, 0.0], [1.0, 1.0]),
                l([1.0, 1.0], [0.0, 1.0]),
                l([0.0, 1.0], [0.0, 0.0]),
            ],
        };
        Outline {
            glyphs: vec![square],
        }
    }

    #[test]
    fn a_square_of_lines_is_a_box() {
        let o = shapes();
        for &(x, y, want) in &[
            (0.5, 0.5, -0.5),
            (2.0, 0.5, 1.0),
            (0.5, -0.25, 0.25),
            (2.0, 2.0, 2f64.sqrt()),
            (0.9, 0.5, -0.1),
        ] {
            let d: f64 = distance(&o, x, y);
            assert!((d - want).abs() < 1e-12, "({x}, {y}): {d} != {want}");
        }
    }

    /// The curve (0,0) (1,1) (2,0) split at its top into two monotone halves, closed by a
    /// line: the points inside are those below the parabola y = x - x²/2 and above y = 0.
    #[test]
    fn a_parabola_closed_by_a_line_against_sampling() {
        let q = |a, b, c| Segment {
            a,
            b,
            c,
            line: false,
        };
        let g = Glyph {
            lo: [0.0, 0.0],
            hi: [2.0, 0.5],
            segments: vec![
                q([0.0, 0.0], [0.5, 0.5], [1.0, 0.5]),
                q([1.0, 0.5], [1.5, 0.5], [2.0, 0.0]),
                Segment {
                    a: [2.0, 0.0],
                    b: [2.0, 0.0],
                    c: [0.0, 0.0],
                    line: true,
                },
            ],
        };
        let o = Outline { glyphs: vec![g] };
        let mut rng = crate::rng::Rng::new(7);
        for _ in 0..500 {
            let (x, y) = (rng.range(-0.5, 2.5), rng.range(-0.5, 1.0));
            let d: f64 = distance(&o, x, y);
            // Brute force: the curve sampled finely, and the base.
            let mut best = f64::INFINITY;
            for i in 0..=20000 {
                let t = i as f64 / 20000.0;
                let (px, py) = (2.0 * t, 2.0 * t * (1.0 - t));
                best = best.min((px - x).hypot(py - y));
            }
            let bx = x.clamp(0.0, 2.0);
            best = best.min((bx - x).hypot(y));
            let inside = y > 0.0 && y < x - x * x / 2.0;
            let want = if inside { -best } else { best };
            assert!((d - want).abs() < 1e-6, "({x}, {y}): {d} != {want}");
        }
    }
}
