//! Outlines: the glyphs of a text as data (lines and quadratic curves, grouped by glyph, each
//! glyph with its box) and a hierarchy of boxes over the glyphs, the one definition of their
//! signed distance ([`distance`]), which the interpreter, the reference run and the Rust writer
//! follow and the WGSL function of `back/wgsl/glyphs.rs` mirrors step for step, and their words
//! in `scene_data` ([`Outline::words`]).
//!
//! The distance is the nearest of the curves (exact: the closest point of a quadratic curve is
//! a root of a cubic, solved in closed form as in Inigo Quilez's `sdBezier`, each root then
//! refined by one Newton step, the ends always candidates), negative where the winding number
//! of the curves about the point is not zero (TrueType's fill rule). The winding number is
//! counted along a ray towards +x: every curve is monotone in y (the font reader splits them at
//! their turning points), so it crosses the ray's line at most once, at the root of a quadratic
//! of one variable.
//!
//! The glyphs are the leaves of a binary hierarchy of boxes: each group of glyphs is split
//! in two along x or y where the halves' boxes are smallest (at a word's gap, on a line of
//! text), each half holding between a third and two thirds of the group, so that it is at
//! most log₃⸝₂(glyphs) deep. The walk visits the nearer child first and skips a node whose box
//! the point is outside of and no nearer than the best distance so far: a box's distance
//! bounds its curves' from below, and the winding number of closed contours about a point
//! outside their box is zero. So the distance stays exact, and a point pays for the boxes on
//! its way down (about log(glyphs)) and the curves of the glyphs near it, not for every glyph.

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

/// A node of an outline's hierarchy: the box of the glyphs below it, and either one glyph (a
/// leaf) or two children, the nodes `first` and `first + 1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    pub lo: [f64; 2],
    pub hi: [f64; 2],
    /// The glyph of a leaf; `None` for a node with two children.
    pub glyph: Option<u32>,
    /// The first child of a node with children.
    pub first: u32,
}

/// The glyphs of a text, laid out in the plane, and the hierarchy over them: a profile given
/// as data.
#[derive(Clone, PartialEq)]
pub struct Outline {
    glyphs: Vec<Glyph>,
    nodes: Vec<Node>,
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

/// The entries a walk's stack holds at most: one per level of the hierarchy and one more. A
/// group's larger half holds at most two thirds of it, so the hierarchy over fewer than 2³²
/// glyphs is at most 55 levels deep.
pub const STACK: usize = 64;

impl Outline {
    /// The outline of `glyphs` (those without segments dropped: they draw nothing), with its
    /// hierarchy.
    pub fn new(glyphs: Vec<Glyph>) -> Outline {
        let glyphs: Vec<Glyph> = glyphs
            .into_iter()
            .filter(|g| !g.segments.is_empty())
            .collect();
        let nodes = hierarchy(&glyphs);
        Outline { glyphs, nodes }
    }

    /// The glyphs, in their order along the text.
    pub fn glyphs(&self) -> &[Glyph] {
        &self.glyphs
    }

    /// The hierarchy's nodes; the root is the first.
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// The number of segments of every glyph.
    pub fn segments(&self) -> usize {
        self.glyphs.iter().map(|g| g.segments.len()).sum()
    }

    /// The box of every glyph: (low corner, high corner).
    pub fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        (self.nodes[0].lo, self.nodes[0].hi)
    }

    /// The number of levels of the hierarchy (1 for a single glyph).
    pub fn depth(&self) -> usize {
        fn below(o: &Outline, n: usize) -> usize {
            let node = &o.nodes[n];
            match node.glyph {
                Some(_) => 1,
                None => {
                    let f = node.first as usize;
                    1 + below(o, f).max(below(o, f + 1))
                }
            }
        }
        below(self, 0)
    }

    /// The word (of [`Outline::words`]) where glyph `k`'s segments start, from the outline's
    /// first word.
    fn segment_words(&self) -> Vec<usize> {
        let mut at = 1 + 2 * self.nodes.len();
        self.glyphs
            .iter()
            .map(|g| {
                let here = at;
                at += 2 * g.segments.len();
                here
            })
            .collect()
    }

    /// The outline as `vec4<f32>` words of `scene_data`: `[0]` the number of nodes and of
    /// glyphs; per node its box (lo.x, lo.y, hi.x, hi.y) and then, for a leaf, the word its
    /// glyph's segments start at (from the outline's first word), their number and 1, or, for
    /// a node with children, its first child's index, 0 and 0; then per glyph, per segment
    /// `(a.x, a.y, b.x, b.y)` and `(c.x, c.y, 1 for a line else 0, 0)`. Counts and indices are
    /// held as floats (exact below 2^24, which the checker's limits keep them under).
    pub fn words(&self) -> Vec<[f32; 4]> {
        let bits = |n: usize| n as f32;
        let starts = self.segment_words();
        let mut out = vec![[bits(self.nodes.len()), bits(self.glyphs.len()), 0.0, 0.0]];
        for n in &self.nodes {
            out.push([n.lo[0], n.lo[1], n.hi[0], n.hi[1]].map(|v| v as f32));
            out.push(match n.glyph {
                Some(k) => {
                    let k = k as usize;
                    let count = self.glyphs.get(k).map_or(0, |g| g.segments.len());
                    [
                        bits(starts.get(k).copied().unwrap_or(0)),
                        bits(count),
                        1.0,
                        0.0,
                    ]
                }
                None => [bits(n.first as usize), 0.0, 0.0, 0.0],
            });
        }
        for g in &self.glyphs {
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
        1 + 2 * self.nodes.len() + 2 * self.segments()
    }
}

/// The hierarchy over `glyphs` (see the module doc), its root first; a single leaf of no
/// glyph's box where there is none.
fn hierarchy(glyphs: &[Glyph]) -> Vec<Node> {
    let empty = Node {
        lo: [0.0; 2],
        hi: [0.0; 2],
        glyph: None,
        first: 0,
    };
    if glyphs.is_empty() {
        return vec![Node {
            glyph: Some(0),
            ..empty
        }];
    }
    let centre = |g: &Glyph| [0.5 * (g.lo[0] + g.hi[0]), 0.5 * (g.lo[1] + g.hi[1])];
    let hull = |items: &[u32]| {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for &k in items {
            let g = &glyphs[k as usize];
            for i in 0..2 {
                lo[i] = lo[i].min(g.lo[i]);
                hi[i] = hi[i].max(g.hi[i]);
            }
        }
        (lo, hi)
    };
    let half_perimeter = |(lo, hi): ([f64; 2], [f64; 2])| (hi[0] - lo[0]) + (hi[1] - lo[1]);
    let mut nodes = vec![empty];
    let mut work: Vec<(usize, Vec<u32>)> = vec![(0, (0..glyphs.len() as u32).collect())];
    while let Some((at, mut items)) = work.pop() {
        let (lo, hi) = hull(&items);
        nodes[at].lo = lo;
        nodes[at].hi = hi;
        if items.len() == 1 {
            nodes[at].glyph = Some(items[0]);
            continue;
        }
        // The split of least cost (each half's half-perimeter times its glyphs) with each
        // half between a third and two thirds of the group; ties to x and the earlier split.
        let n = items.len();
        let (min_k, max_k) = (n.div_ceil(3).max(1), (2 * n / 3).max(1));
        let mut best: Option<(f64, usize, usize)> = None;
        for axis in 0..2 {
            sort_along(&mut items, glyphs, axis, &centre);
            let mut right = vec![0.0; n];
            let (mut rlo, mut rhi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for k in (1..n).rev() {
                let g = &glyphs[items[k] as usize];
                for i in 0..2 {
                    rlo[i] = rlo[i].min(g.lo[i]);
                    rhi[i] = rhi[i].max(g.hi[i]);
                }
                right[k] = half_perimeter((rlo, rhi));
            }
            let (mut llo, mut lhi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for k in 1..=max_k {
                let g = &glyphs[items[k - 1] as usize];
                for i in 0..2 {
                    llo[i] = llo[i].min(g.lo[i]);
                    lhi[i] = lhi[i].max(g.hi[i]);
                }
                if k < min_k {
                    continue;
                }
                let cost = half_perimeter((llo, lhi)) * k as f64 + right[k] * (n - k) as f64;
                if best.is_none_or(|b| cost < b.0) {
                    best = Some((cost, axis, k));
                }
            }
        }
        let (_, axis, k) = best.expect("a group of two or more has a split");
        sort_along(&mut items, glyphs, axis, &centre);
        let rest = items.split_off(k);
        let first = nodes.len();
        nodes.push(empty);
        nodes.push(empty);
        nodes[at].first = first as u32;
        work.push((first, items));
        work.push((first + 1, rest));
    }
    nodes
}

/// Sorts glyph indices by their boxes' centres along `axis`, then by index.
fn sort_along(
    items: &mut [u32],
    glyphs: &[Glyph],
    axis: usize,
    centre: &dyn Fn(&Glyph) -> [f64; 2],
) {
    items.sort_by(|&a, &b| {
        centre(&glyphs[a as usize])[axis]
            .total_cmp(&centre(&glyphs[b as usize])[axis])
            .then(a.cmp(&b))
    });
}

/// What one walk of [`distance_counted`] did: the nodes it took off its stack and the
/// segments it measured.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Work {
    pub nodes: usize,
    pub segments: usize,
}

/// The signed distance at (x, y) to the outline `o` (see the module doc).
#[inline]
pub fn distance<T: Float>(o: &Outline, x: T, y: T) -> T {
    distance_counted(o, x, y, &mut Work::default())
}

/// [`distance`], counting its work into `work`.
#[inline(always)]
pub fn distance_counted<T: Float>(o: &Outline, x: T, y: T, work: &mut Work) -> T {
    let zero = T::zero();
    let mut best = T::from_f64(FAR);
    let mut wind: i32 = 0;
    let gap = |n: &Node| {
        let dx = (T::from_f64(n.lo[0]) - x)
            .max(x - T::from_f64(n.hi[0]))
            .max(zero);
        let dy = (T::from_f64(n.lo[1]) - y)
            .max(y - T::from_f64(n.hi[1]))
            .max(zero);
        dx * dx + dy * dy
    };
    // Each entry: a node and its box's squared distance, tested again when it is taken
    // off (the best may have shrunk since).
    let mut stack = [(0u32, zero); STACK];
    stack[0] = (0, gap(&o.nodes[0]));
    let mut top = 1;
    while top > 0 {
        top -= 1;
        let (at, g) = stack[top];
        let n = &o.nodes[at as usize];
        work.nodes += 1;
        // Outside the box and no nearer than the best: nothing below counts.
        if g > zero && g >= best {
            continue;
        }
        let Some(k) = n.glyph else {
            // The nearer child on top, so that it is visited first.
            let (l, r) = (n.first, n.first + 1);
            let gl = gap(&o.nodes[l as usize]);
            let gr = gap(&o.nodes[r as usize]);
            let (near, far) = if gr < gl {
                ((r, gr), (l, gl))
            } else {
                ((l, gl), (r, gr))
            };
            if !(far.1 > zero && far.1 >= best) {
                stack[top] = far;
                top += 1;
            }
            if !(near.1 > zero && near.1 >= best) {
                stack[top] = near;
                top += 1;
            }
            continue;
        };
        let Some(glyph) = o.glyphs.get(k as usize) else {
            continue;
        };
        for s in &glyph.segments {
            let v = |p: [f64; 2]| (T::from_f64(p[0]), T::from_f64(p[1]));
            let (a, c) = (v(s.a), v(s.c));
            work.segments += 1;
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
        Outline::new(vec![square])
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
        let o = Outline::new(vec![g]);
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

    /// Every segment of every glyph, no box consulted: what the walk must give.
    fn flat<T: Float>(o: &Outline, x: T, y: T) -> T {
        let mut best = T::from_f64(FAR);
        let mut wind = 0;
        for g in o.glyphs() {
            for s in &g.segments {
                let v = |p: [f64; 2]| (T::from_f64(p[0]), T::from_f64(p[1]));
                let (a, b, c) = (v(s.a), v(s.b), v(s.c));
                if s.line {
                    let (d2, w) = line(a, c, x, y);
                    best = best.min(d2);
                    wind += w;
                } else {
                    best = best.min(quad(a, b, c, x, y));
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

    fn text(s: &str) -> Outline {
        crate::check::font::layout(crate::check::font::default_font(), s, 1.0).expect("laid out")
    }

    /// Points near a text's glyphs (where a ray marching at it spends its steps), and some
    /// farther out.
    fn near(o: &Outline, rng: &mut crate::rng::Rng, k: usize) -> (f64, f64) {
        let (lo, hi) = o.bounds();
        let pad = if k % 8 == 0 { 2.0 } else { 0.2 };
        (
            rng.range(lo[0] - pad, hi[0] + pad),
            rng.range(lo[1] - pad, hi[1] + pad),
        )
    }

    /// The walk skips glyphs by their boxes and their groups' boxes, nearest first: it gives
    /// what measuring every segment gives, in f64 and f32, on lines of text and a paragraph.
    #[test]
    fn the_hierarchy_keeps_the_distance() {
        let mut rng = crate::rng::Rng::new(52);
        for s in [
            "The quick brown fox jumps over a lazy do",
            "iiii il WWW\nSdfc 8g@ \u{00e9}t\u{00e9}\n  .,;: MM",
        ] {
            let o = text(s);
            for k in 0..3000 {
                let (x, y) = near(&o, &mut rng, k);
                let (d, want): (f64, f64) = (distance(&o, x, y), flat(&o, x, y));
                assert_eq!(
                    d.to_bits(),
                    want.to_bits(),
                    "{s:?} at ({x}, {y}): {d} != {want}"
                );
                let (x, y) = (x as f32, y as f32);
                let (d, want): (f32, f32) = (distance(&o, x, y), flat(&o, x, y));
                assert_eq!(
                    d.to_bits(),
                    want.to_bits(),
                    "{s:?} at ({x}, {y}): {d} != {want}"
                );
            }
        }
    }

    /// A point's work grows with log(glyphs) and the curves of the glyphs near it: four times
    /// the characters cost well under twice the boxes and curves per point (the walk before
    /// the hierarchy tested every glyph's box twice, four times as many).
    #[test]
    fn four_times_the_text_costs_a_point_little_more() {
        let line = "The quick brown fox jumps over a lazy do";
        let mean = |o: &Outline| {
            let mut rng = crate::rng::Rng::new(9);
            let mut sum = Work::default();
            let n = 4000;
            for k in 0..n {
                let (x, y) = near(o, &mut rng, k);
                let mut w = Work::default();
                let _: f32 = distance_counted(o, x as f32, y as f32, &mut w);
                sum.nodes += w.nodes;
                sum.segments += w.segments;
            }
            (sum.nodes as f64 / n as f64, sum.segments as f64 / n as f64)
        };
        let one = text(line);
        let four = text(&line.repeat(4));
        assert_eq!(one.glyphs().len(), 32);
        assert_eq!(four.glyphs().len(), 128);
        // At most log₃⸝₂ deep; a line of text splits near its middle.
        assert!(four.depth() <= 13, "{}", four.depth());
        let ((n1, s1), (n4, s4)) = (mean(&one), mean(&four));
        eprintln!("per point: 32 glyphs {n1:.1} nodes {s1:.1} segments, 128 glyphs {n4:.1} nodes {s4:.1} segments");
        assert!(n4 < 1.6 * n1, "nodes: {n1} then {n4}");
        assert!(s4 < 1.6 * s1, "segments: {s1} then {s4}");
        assert!(n4 < 0.25 * 2.0 * 128.0, "nodes: {n4} of 128 glyphs");
    }
}
