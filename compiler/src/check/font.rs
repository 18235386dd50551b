//! Text laid out from a font (`text(string, size)`): the glyphs' TrueType outlines read with
//! ttf-parser, placed along the line with the font's advances and its `kern` table, scaled so
//! that the em is `size`, and turned into an [`Outline`]: lines, and quadratic curves split
//! at their turning points in y (so that each crosses a horizontal line at most once).
//! The project ships DejaVu Sans (the `dejavu` crate's bytes), the font when none is named.

use crate::program::outline::{Glyph, Outline, Segment};

/// Why a text cannot be laid out in a font.
#[derive(Debug, thiserror::Error)]
pub enum FontError {
    #[error("the file is not a font that can be read ({0})")]
    NotAFont(ttf_parser::FaceParsingError),
    #[error("the text is empty")]
    Empty,
    #[error("the font has no glyph for {ch:?} (U+{:04X})", u32::from(*ch))]
    NoGlyph { ch: char },
    #[error("the font's outlines are cubic curves (a CFF font); only TrueType outlines, of lines and quadratic curves, are read")]
    Cubic,
    #[error("the text has no visible glyph (it is all spaces)")]
    NoInk,
}

/// The font `text` uses when no `font:` is given: DejaVu Sans.
pub fn default_font() -> &'static [u8] {
    dejavu::sans::regular()
}

/// A curve whose deviation from its chord is below this fraction of the em is a line: far
/// below any distance a scene resolves, and it keeps the closed-form solution of a curve
/// away from the division by a vanishing `a - 2b + c`.
const FLAT: f64 = 1e-6;

/// The outline of `text` in the font `bytes`, its em `size` high: each line of the text
/// (lines are separated by `\n`) centred on x = 0 by its advance width, running towards −x
/// (so that it reads from left to right looking along +z, as the default camera does); the
/// first line's capital letters and the last line's baseline centred on y = 0. `Err` says
/// why not.
pub fn layout(bytes: &[u8], text: &str, size: f64) -> Result<Outline, FontError> {
    let face = ttf_parser::Face::parse(bytes, 0).map_err(FontError::NotAFont)?;
    if text.is_empty() {
        return Err(FontError::Empty);
    }
    let upem = f64::from(face.units_per_em());
    let scale = size / upem;
    let line_height =
        f64::from(face.ascender()) - f64::from(face.descender()) + f64::from(face.line_gap());
    let kerning: Vec<_> = face
        .tables()
        .kern
        .iter()
        .flat_map(|k| k.subtables)
        .filter(|s| s.horizontal && !s.variable && !s.has_cross_stream)
        .collect();
    let mut glyphs: Vec<Glyph> = Vec::new();
    let mut lines: Vec<(usize, f64)> = Vec::new(); // (first glyph of the line, its width)
    let mut first = 0;
    let (mut pen, mut baseline) = (0.0f64, 0.0f64);
    let mut prev = None;
    for ch in text.chars() {
        if ch == '\n' {
            lines.push((first, pen));
            first = glyphs.len();
            pen = 0.0;
            baseline -= line_height;
            prev = None;
            continue;
        }
        let id = face
            .glyph_index(ch)
            .filter(|_| !ch.is_control())
            .ok_or(FontError::NoGlyph { ch })?;
        if let Some(p) = prev {
            let k: f64 = kerning
                .iter()
                .filter_map(|s| s.glyphs_kerning(p, id))
                .map(f64::from)
                .sum();
            pen += k;
        }
        let mut b = Builder {
            at: [pen, baseline],
            upem,
            ..Builder::default()
        };
        face.outline_glyph(id, &mut b);
        if b.cubic {
            return Err(FontError::Cubic);
        }
        b.close();
        if !b.segments.is_empty() {
            glyphs.push(glyph(b.segments));
        }
        pen += f64::from(face.glyph_hor_advance(id).unwrap_or(0));
        prev = Some(id);
    }
    lines.push((first, pen));
    if glyphs.is_empty() {
        return Err(FontError::NoInk);
    }
    let cap = face
        .capital_height()
        .map(f64::from)
        .filter(|&c| c > 0.0)
        .unwrap_or(f64::from(face.ascender()));
    let rise = (cap + baseline) / 2.0;
    // Place each line, in font units, then scale, moving the glyphs' segments in place (a
    // copy doubled what a long text holds).
    for (k, &(start, width)) in lines.iter().enumerate() {
        let end = lines.get(k + 1).map_or(glyphs.len(), |l| l.0);
        for g in &mut glyphs[start..end] {
            // Mirrored in x: the text reads from left to right seen looking along +z, as the
            // default camera looks (+x is on the picture's left).
            let shift = |p: [f64; 2]| [(width / 2.0 - p[0]) * scale, (p[1] - rise) * scale];
            let segments = std::mem::take(&mut g.segments)
                .into_iter()
                .map(|s| Segment {
                    a: shift(s.a),
                    b: shift(s.b),
                    c: shift(s.c),
                    line: s.line,
                })
                .collect();
            *g = glyph(segments);
        }
    }
    Ok(Outline::new(glyphs))
}

/// A glyph of `segments`, with the box of their points.
fn glyph(segments: Vec<Segment>) -> Glyph {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for s in &segments {
        let points = if s.line {
            &[s.a, s.c][..]
        } else {
            &[s.a, s.b, s.c]
        };
        for &p in points {
            for i in 0..2 {
                lo[i] = lo[i].min(p[i]);
                hi[i] = hi[i].max(p[i]);
            }
        }
    }
    Glyph { lo, hi, segments }
}

/// Collects one glyph's contours in font units, moved to the pen.
#[derive(Debug, Default)]
struct Builder {
    at: [f64; 2],
    start: [f64; 2],
    last: [f64; 2],
    open: bool,
    cubic: bool,
    upem: f64,
    segments: Vec<Segment>,
}

impl Builder {
    fn point(&self, x: f32, y: f32) -> [f64; 2] {
        [self.at[0] + f64::from(x), self.at[1] + f64::from(y)]
    }

    fn line(&mut self, c: [f64; 2]) {
        if c != self.last {
            self.segments.push(Segment {
                a: self.last,
                b: self.last,
                c,
                line: true,
            });
        }
        self.last = c;
    }

    /// A curve from the last point through `b` to `c`, split where it turns in y.
    fn quad(&mut self, b: [f64; 2], c: [f64; 2]) {
        let a = self.last;
        let den = a[1] - 2.0 * b[1] + c[1];
        let t = if den != 0.0 {
            (a[1] - b[1]) / den
        } else {
            -1.0
        };
        if t > 0.0 && t < 1.0 {
            let lerp =
                |p: [f64; 2], q: [f64; 2]| [p[0] + (q[0] - p[0]) * t, p[1] + (q[1] - p[1]) * t];
            let (ab, bc) = (lerp(a, b), lerp(b, c));
            let mid = lerp(ab, bc);
            // The turning point's y is the extreme of both halves: exactly that of `mid`.
            let ab = [ab[0], mid[1]];
            let bc = [bc[0], mid[1]];
            self.piece(ab, mid);
            self.piece(bc, c);
        } else {
            self.piece(b, c);
        }
    }

    /// A monotone curve from the last point through `b` to `c`, a line where it is flat.
    fn piece(&mut self, b: [f64; 2], c: [f64; 2]) {
        let a = self.last;
        let e = [a[0] - 2.0 * b[0] + c[0], a[1] - 2.0 * b[1] + c[1]];
        let flat = FLAT * if self.upem > 0.0 { self.upem } else { 2048.0 };
        if e[0].hypot(e[1]) / 4.0 <= flat {
            self.line(c);
            return;
        }
        self.segments.push(Segment {
            a,
            b,
            c,
            line: false,
        });
        self.last = c;
    }

    fn close(&mut self) {
        if self.open {
            let s = self.start;
            self.line(s);
            self.open = false;
        }
    }
}

impl ttf_parser::OutlineBuilder for Builder {
    fn move_to(&mut self, x: f32, y: f32) {
        self.close();
        let p = self.point(x, y);
        self.start = p;
        self.last = p;
        self.open = true;
    }

    fn line_to(&mut self, x: f32, y: f32) {
        let p = self.point(x, y);
        self.line(p);
    }

    fn quad_to(&mut self, x1: f32, y1: f32, x: f32, y: f32) {
        let (b, c) = (self.point(x1, y1), self.point(x, y));
        self.quad(b, c);
    }

    fn curve_to(&mut self, _: f32, _: f32, _: f32, _: f32, x: f32, y: f32) {
        self.cubic = true;
        let p = self.point(x, y);
        self.line(p);
    }

    fn close(&mut self) {
        Builder::close(self);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::program::outline::distance;

    /// A brute-force distance to the outline: every curve sampled at 1000 points, every line
    /// exactly; the sign from the winding number of the sampled polygon.
    fn brute(o: &Outline, x: f64, y: f64) -> f64 {
        let mut best = f64::INFINITY;
        let mut wind = 0i32;
        let seg = |a: [f64; 2], c: [f64; 2], best: &mut f64, wind: &mut i32| {
            let (ex, ey) = (c[0] - a[0], c[1] - a[1]);
            let (wx, wy) = (x - a[0], y - a[1]);
            let t = ((wx * ex + wy * ey) / (ex * ex + ey * ey)).clamp(0.0, 1.0);
            *best = best.min((wx - ex * t).hypot(wy - ey * t));
            let cross = ex * wy - ey * wx;
            if a[1] <= y && y < c[1] && cross > 0.0 {
                *wind += 1;
            } else if c[1] <= y && y < a[1] && cross < 0.0 {
                *wind -= 1;
            }
        };
        for g in o.glyphs() {
            for s in &g.segments {
                if s.line {
                    seg(s.a, s.c, &mut best, &mut wind);
                    continue;
                }
                let at = |t: f64| {
                    let u = 1.0 - t;
                    [
                        u * u * s.a[0] + 2.0 * t * u * s.b[0] + t * t * s.c[0],
                        u * u * s.a[1] + 2.0 * t * u * s.b[1] + t * t * s.c[1],
                    ]
                };
                let n = 1000;
                for i in 0..n {
                    let (p, q) = (at(i as f64 / n as f64), at((i + 1) as f64 / n as f64));
                    seg(p, q, &mut best, &mut wind);
                }
            }
        }
        if wind != 0 {
            -best
        } else {
            best
        }
    }

    #[test]
    fn a_string_against_brute_force() {
        let o = layout(default_font(), "Sdfc 8g@", 1.0).expect("laid out");
        let ((lx, ly), (hx, hy)) = {
            let (lo, hi) = o.bounds();
            ((lo[0], lo[1]), (hi[0], hi[1]))
        };
        let mut rng = crate::rng::Rng::new(35);
        let mut worst = 0.0f64;
        for k in 0..200 {
            // Mostly near the glyphs, some far.
            let pad = if k % 10 == 0 { 1.0 } else { 0.05 };
            let (x, y) = (rng.range(lx - pad, hx + pad), rng.range(ly - pad, hy + pad));
            let d: f64 = distance(&o, x, y);
            let want = brute(&o, x, y);
            // The sampled curves lie within 3e-7 of the true ones at this size.
            let err = (d - want).abs();
            worst = worst.max(err);
            assert!(
                err < 1e-6 || (d.abs() < 1e-6 && want.abs() < 1e-6),
                "({x}, {y}): {d} against {want}"
            );
            let d32: f32 = distance(&o, x as f32, y as f32);
            assert!(
                (f64::from(d32) - want).abs() < 2e-5,
                "f32 at ({x}, {y}): {d32} against {want}"
            );
        }
        assert!(worst < 1e-6, "{worst}");
    }

    #[test]
    fn every_printable_ascii_glyph_winds_consistently() {
        // Along lines across each glyph, the sign changes only where the distance is 0:
        // between neighbouring samples of opposite sign, the distances sum to at most the step.
        for ch in '!'..='~' {
            let o = layout(default_font(), &ch.to_string(), 1.0).expect("laid out");
            let (lo, hi) = o.bounds();
            let n = 300;
            for row in 0..25 {
                let y = lo[1] + (hi[1] - lo[1]) * (row as f64 + 0.5) / 25.0;
                let step = (hi[0] - lo[0] + 0.2) / n as f64;
                let mut last: Option<f32> = None;
                for i in 0..=n {
                    let x = lo[0] - 0.1 + step * i as f64;
                    let d: f32 = distance(&o, x as f32, y as f32);
                    if let Some(p) = last {
                        if (p < 0.0) != (d < 0.0) {
                            assert!(
                                f64::from(p.abs() + d.abs()) <= step * 1.001 + 1e-6,
                                "{ch:?}: the sign flips at x = {x}, y = {y} away from the outline ({p}, {d})"
                            );
                        }
                    }
                    last = Some(d);
                }
                assert!(last.is_some_and(|d| d > 0.0), "{ch:?}: outside is positive");
            }
            // Some point of every glyph is inside.
            let inside = (0..2000).any(|k| {
                let t = k as f64 / 2000.0;
                let (x, y) = (
                    lo[0] + (hi[0] - lo[0]) * t,
                    lo[1] + (hi[1] - lo[1]) * ((k * 7919) % 2000) as f64 / 2000.0,
                );
                distance::<f64>(&o, x, y) < 0.0
            });
            assert!(inside, "{ch:?} has no inside");
        }
    }

    #[test]
    fn kerning_comes_from_the_font() {
        // DejaVu Sans kerns "AV": the V's outline starts the A's advance plus the kerning
        // after the A's.
        let face = ttf_parser::Face::parse(default_font(), 0).expect("DejaVu Sans");
        let (a, v) = (
            face.glyph_index('A').unwrap(),
            face.glyph_index('V').unwrap(),
        );
        let kern: i16 = face
            .tables()
            .kern
            .iter()
            .flat_map(|k| k.subtables)
            .filter_map(|s| s.glyphs_kerning(a, v))
            .sum();
        assert!(kern < 0, "{kern}");
        let x_min = |g| f64::from(face.glyph_bounding_box(g).unwrap().x_min);
        let want =
            f64::from(face.glyph_hor_advance(a).unwrap()) + f64::from(kern) + x_min(v) - x_min(a);
        let o = layout(default_font(), "AV", 2048.0).expect("laid out");
        let upem = f64::from(face.units_per_em());
        // Mirrored: a glyph's left edge in the font is its box's high x.
        let got = (o.glyphs()[0].hi[0] - o.glyphs()[1].hi[0]) * upem / 2048.0;
        assert!((got - want).abs() < 1e-9, "{got} against {want}");
    }

    #[test]
    fn bad_text_and_fonts_say_why() {
        let fails = |font: &[u8], text| layout(font, text, 1.0).unwrap_err();
        assert!(matches!(fails(default_font(), ""), FontError::Empty));
        assert_eq!(fails(default_font(), "").to_string(), "the text is empty");
        assert!(matches!(fails(default_font(), "   "), FontError::NoInk));
        let e = fails(b"not a font at all", "A");
        assert!(matches!(e, FontError::NotAFont(_)));
        assert!(e.to_string().starts_with("the file is not a font"), "{e}");
        let e = fails(default_font(), "A\u{10FFFD}");
        assert!(matches!(e, FontError::NoGlyph { ch: '\u{10FFFD}' }));
        assert!(e.to_string().contains("U+10FFFD"), "{e}");
    }
}
