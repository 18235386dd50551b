//! Lowering of the operations of a user field (`scene::field`) to program instructions, of
//! the colour fields of materials to programs of their own ([`Colours`]), and of noise: gradient noise and the Voronoi distance over a lattice hashed by the
//! permutation polynomial (34x² + x) mod 289 (Gustavson and McEwan's webgl-noise), computed
//! on whole numbers below 2²⁴ so that every evaluator, f32 or f64, finds the same cell hashes
//! exactly (docs/language.md, "Noise").

use super::{Reg, Unary};
use crate::program::builder::{Builder, P};
use crate::program::{Binary, Float, Program};
use crate::scene::field::{
    FBin, FOp, FUn, FieldFn, GOLDEN_TURN, NOISE_CELLS, VORONOI_LO, VORONOI_SPAN,
};
use crate::scene::frame::Frame;
use crate::scene::{Colour, Scene, V3};
use std::f64::consts::TAU;

/// A colour field lowered: a program of the point and the unit surface normal there whose
/// registers `rgb` are the colour's red, green and blue, each at least 0. Its input is the
/// point in the program's coordinates; the scene's [`Scene::origin`] is added first, so that
/// the colour keeps its place in the world, then its material's frames map the point and the
/// normal to the painted shape's coordinates ([`Material::frame`](crate::scene::Material)).
#[derive(Debug, Clone, PartialEq)]
pub struct ColourProgram {
    /// The program (its distance and material registers are red and green; read `rgb`).
    pub program: Program,
    /// The registers of red, green and blue.
    pub rgb: [Reg; 3],
}

impl ColourProgram {
    /// Lowers the expression `f` (three values) for a scene moved by `origin`, in the
    /// coordinates the maps `frames` lead to from the world's.
    pub fn new(f: &FieldFn, origin: V3, frames: &[Frame]) -> ColourProgram {
        let mut b = Builder::new(true);
        let q = b.input_point();
        let mut p = [0, 1, 2].map(|i| b.addc(q[i], origin[i]));
        let mut n = b.input_normal();
        for frame in frames {
            (p, n) = place(&mut b, frame, p, n);
        }
        let mut regs: Vec<Reg> = Vec::with_capacity(f.ops.len());
        for o in &f.ops {
            let r = match o {
                FOp::Coord(a @ 3..) => n[*a as usize % 3],
                o => op(&mut b, o, p, &regs),
            };
            regs.push(r);
        }
        let rgb = [0, 1, 2].map(|i| {
            let r = f.out.get(i).map_or_else(|| b.c(0.0), |s| regs[*s as usize]);
            b.maxc(r, 0.0)
        });
        let (program, roots) = b.finish_roots(&rgb);
        ColourProgram {
            program,
            rgb: [roots[0], roots[1], roots[2]],
        }
    }

    /// The colour at `p` where the unit surface normal is `n` (the program's reference run,
    /// [`Program::run_with_normal`]).
    pub fn eval<T: Float>(&self, p: [T; 3], n: [T; 3]) -> [T; 3] {
        let regs = self.program.run_with_normal::<T>(p, n, |_| {});
        self.rgb.map(|r| regs[r.0 as usize])
    }
}

/// The colour fields of a scene's materials, each lowered once: every back end reads them
/// here.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Colours {
    /// The programs, in the order of the materials and, in a checker, `a` before `b`.
    pub programs: Vec<ColourProgram>,
    /// For each material, the index in `programs` of its colour's field (a checker's `a`)
    /// and of a checker's `b`, where they are fields.
    pub fields: Vec<[Option<usize>; 2]>,
}

impl Colours {
    /// The colour fields of `scene`'s materials.
    pub fn new(scene: &Scene) -> Colours {
        let mut programs = Vec::new();
        for m in &scene.materials {
            for c in m.pattern.colours() {
                if let Colour::Field(f) = c {
                    programs.push(ColourProgram::new(f, scene.origin, &m.frame));
                }
            }
        }
        Colours {
            programs,
            fields: Colours::numbers(scene),
        }
    }

    /// [`Colours::fields`] of `scene`, without lowering the fields.
    pub fn numbers(scene: &Scene) -> Vec<[Option<usize>; 2]> {
        let mut next = 0;
        scene
            .materials
            .iter()
            .map(|m| {
                let mut slots = [None, None];
                for (k, c) in m.pattern.colours().into_iter().enumerate() {
                    if let Colour::Field(_) = c {
                        slots[k] = Some(next);
                        next += 1;
                    }
                }
                slots
            })
            .collect()
    }

    /// Whether no material has a colour field.
    pub fn is_empty(&self) -> bool {
        self.programs.is_empty()
    }
}

/// The point `p` and unit normal `n` through one map of a colour's frame: the point as the
/// distance maps it (`shapes.rs`), the normal as the map turns the surface, `(A⁻¹)ᵀn`
/// normalised for a linear part `A`, flipped with the coordinates a mirror folds.
fn place(b: &mut Builder, frame: &Frame, p: P, n: P) -> (P, P) {
    match frame {
        Frame::Affine { matrix, offset } => {
            // rotate(p, M) is Mᵀp: (Aᵀ)ᵀp = Ap, and ((A⁻¹)ᵀ)ᵀ = A⁻¹.
            let t = [0, 1, 2].map(|i| [0, 1, 2].map(|j| matrix[j][i]));
            let q = super::shapes::rotate(b, p, &t);
            let q = [0, 1, 2].map(|i| b.addc(q[i], offset[i]));
            let inverse = crate::scene::analysis::invert(matrix).unwrap_or(*matrix);
            let m = super::shapes::rotate(b, n, &inverse);
            let len = b.len3(m);
            (q, b.map3(m, |b, x, _| b.div(x, len)))
        }
        Frame::Mirror(axes) => {
            let zero = b.c(0.0);
            let (minus, plus) = (b.c(-1.0), b.c(1.0));
            let mut q = p;
            let mut m = n;
            for i in 0..3 {
                if axes[i] {
                    q[i] = b.abs(p[i]);
                    let below = b.lt(p[i], zero);
                    let sign = b.select(below, minus, plus);
                    m[i] = b.mul(n[i], sign);
                }
            }
            (q, m)
        }
        Frame::Repeat { period, count } => (super::shapes::repeat(b, p, *period, *count), n),
    }
}

/// The instructions of one operation other than [`FOp::Distance`] (which the caller lowers
/// as a shape), given the registers of the earlier ones.
pub(super) fn op(b: &mut Builder, op: &FOp, p: P, regs: &[Reg]) -> Reg {
    let r = |s: &u32| regs[*s as usize];
    match op {
        FOp::Coord(a) => p[*a as usize % 3],
        FOp::Const(c) => b.c(*c),
        FOp::Un(u, a) => unary(b, *u, r(a)),
        FOp::Bin(o, x, y) => {
            let (x, y) = (r(x), r(y));
            let o = match o {
                FBin::Add => Binary::Add,
                FBin::Sub => Binary::Sub,
                FBin::Mul => Binary::Mul,
                FBin::Div => Binary::Div,
                FBin::Min => Binary::Min,
                FBin::Max => Binary::Max,
                FBin::Pow => Binary::Pow,
                FBin::Atan2 => Binary::Atan2,
            };
            b.bin(o, x, y)
        }
        FOp::Length(v) => {
            let mut acc: Option<Reg> = None;
            for s in v {
                let x = r(s);
                let sq = b.mul(x, x);
                acc = Some(match acc {
                    None => sq,
                    Some(a) => b.add(a, sq),
                });
            }
            let sum = acc.unwrap_or_else(|| b.c(0.0));
            b.sqrt(sum)
        }
        FOp::Noise(v) => {
            let q: Vec<Reg> = v.iter().map(r).collect();
            noise(b, &q)
        }
        FOp::Voronoi(v) => {
            let q: Vec<Reg> = v.iter().map(r).collect();
            voronoi(b, &q)
        }
        FOp::Hash(v) => {
            let q: Vec<Reg> = v.iter().map(r).collect();
            lattice_hash(b, &q)
        }
        FOp::Mix(x, y, t) => {
            let (x, y, t) = (r(x), r(y), r(t));
            let d = b.sub(y, x);
            let m = b.mul(d, t);
            b.add(x, m)
        }
        FOp::Distance(..) => b.c(0.0),
    }
}

fn unary(b: &mut Builder, u: FUn, a: Reg) -> Reg {
    match u {
        FUn::Neg => b.neg(a),
        FUn::Abs => b.abs(a),
        FUn::Sqrt => b.sqrt(a),
        FUn::Sin => b.un(Unary::Sin, a),
        FUn::Cos => b.un(Unary::Cos, a),
        FUn::Tan => {
            let s = b.un(Unary::Sin, a);
            let c = b.un(Unary::Cos, a);
            b.div(s, c)
        }
        FUn::Exp => b.un(Unary::Exp, a),
        FUn::Log => b.un(Unary::Log, a),
        FUn::Floor => b.un(Unary::Floor, a),
        FUn::Smooth => {
            let t = b.clampc(a, 0.0, 1.0);
            let t2 = b.mul(t, t);
            let twice = b.mulc(t, 2.0);
            let three = b.c(3.0);
            let k = b.sub(three, twice);
            b.mul(t2, k)
        }
    }
}

/// x mod 289 for a whole number x (|x| < 2²³): x − ⌊(x + ½)/289⌋·289, the half keeping the
/// quotient's rounding away from whole numbers.
fn mod289(b: &mut Builder, x: Reg) -> Reg {
    let h = b.addc(x, 0.5);
    let q = b.mulc(h, 1.0 / NOISE_CELLS);
    let f = b.un(Unary::Floor, q);
    let m = b.mulc(f, NOISE_CELLS);
    b.sub(x, m)
}

/// The permutation (34x² + x) mod 289 of a whole number 0 ≤ x ≤ 289 (products below 2²²).
fn perm(b: &mut Builder, x: Reg) -> Reg {
    let k = b.mulc(x, 34.0);
    let k = b.addc(k, 1.0);
    let y = b.mul(k, x);
    mod289(b, y)
}

/// The hash of the lattice cell whose reduced coordinates are `a` (each in [−1, 289]).
fn cell_hash(b: &mut Builder, a: &[Reg]) -> Reg {
    let mut h = perm(b, a[0]);
    for &x in &a[1..] {
        let s = b.add(h, x);
        let s = mod289(b, s);
        h = perm(b, s);
    }
    h
}

/// fract(h·k) for a whole number h: its product never comes near a whole number for the
/// irrational k used here (h < 289), so every evaluator takes the same branch.
fn fract_of(b: &mut Builder, h: Reg, k: f64) -> Reg {
    let x = b.mulc(h, k);
    let f = b.un(Unary::Floor, x);
    b.sub(x, f)
}

/// The unit gradient of hash `h`: on the unit circle in 2D, on a Fibonacci spiral over the
/// sphere in 3D.
fn gradient(b: &mut Builder, h: Reg, dims: usize) -> Vec<Reg> {
    let turn = fract_of(b, h, GOLDEN_TURN);
    let phi = b.mulc(turn, TAU);
    let c = b.un(Unary::Cos, phi);
    let s = b.un(Unary::Sin, phi);
    if dims == 2 {
        return vec![c, s];
    }
    // z = 1 − (2h + 1)/289, r = √(1 − z²).
    let z = b.mulc(h, -2.0 / NOISE_CELLS);
    let z = b.addc(z, 1.0 - 1.0 / NOISE_CELLS);
    let z2 = b.mul(z, z);
    let one = b.c(1.0);
    let r2 = b.sub(one, z2);
    let r2 = b.maxc(r2, 0.0);
    let r = b.sqrt(r2);
    vec![b.mul(r, c), b.mul(r, s), z]
}

/// The quintic fade t³(t(6t − 15) + 10).
fn fade(b: &mut Builder, t: Reg) -> Reg {
    let a = b.mulc(t, 6.0);
    let a = b.subc(a, 15.0);
    let a = b.mul(a, t);
    let a = b.addc(a, 10.0);
    let t2 = b.mul(t, t);
    let t3 = b.mul(t2, t);
    b.mul(t3, a)
}

/// a + (c − a)·s.
fn lerp(b: &mut Builder, a: Reg, c: Reg, s: Reg) -> Reg {
    let d = b.sub(c, a);
    let m = b.mul(d, s);
    b.add(a, m)
}

/// The hash of the unit lattice cell holding `q` (1 to 3 coordinates), in (0, 1): two cell
/// hashes `h₁`, `h₂` (the second of `h₁` and the cell's coordinates, last first, times 2, 3
/// and 4) as the whole number 289·h₁ + h₂, scaled into the unit interval at the middle of its
/// step; no two cells of one 289 × 289 period of the plane share it. Every step is on
/// whole numbers below 2²⁴, so f32 and f64 find the same cell; the lattice repeats every 289
/// cells along each axis (docs/language.md, "Noise").
pub(super) fn lattice_hash(b: &mut Builder, q: &[Reg]) -> Reg {
    let a: Vec<Reg> = q
        .iter()
        .map(|&x| {
            let i = b.un(Unary::Floor, x);
            mod289(b, i)
        })
        .collect();
    let h1 = cell_hash(b, &a);
    // The permutation keeps x mod 17, so a second hash of the same sums would repeat h₁'s
    // residue: the coordinates enter it with factors 2, 3, 4 instead.
    let mut second = vec![h1];
    for (k, &x) in a.iter().rev().enumerate() {
        let y = b.mulc(x, k as f64 + 2.0);
        second.push(mod289(b, y));
    }
    let h2 = cell_hash(b, &second);
    let n = b.mulc(h1, NOISE_CELLS);
    let n = b.add(n, h2);
    let n = b.addc(n, 0.5);
    b.mulc(n, 1.0 / (NOISE_CELLS * NOISE_CELLS))
}

/// [`lattice_hash`] of a constant cell (1 to 3 coordinates), computed in f64 by the very
/// instructions a field runs: `hash(x)` of a number known when the scene is checked.
pub(crate) fn hash_of(cell: &[f64]) -> f64 {
    let mut b = Builder::new(false);
    let p = b.input_point();
    let h = lattice_hash(&mut b, &p[..cell.len().min(3)]);
    let (program, roots) = b.finish_roots(&[h]);
    let mut at = [0.0; 3];
    for (a, c) in at.iter_mut().zip(cell) {
        *a = *c;
    }
    program.run::<f64>(at, |_| {})[roots[0].0 as usize]
}

/// The lattice cell of `q`, axis by axis: the fractional coordinates, and what `cell` makes of
/// the integer part (mod 289).
fn lattice<T>(
    b: &mut Builder,
    q: &[Reg],
    mut cell: impl FnMut(&mut Builder, Reg) -> T,
) -> (Vec<Reg>, Vec<T>) {
    let mut f = Vec::with_capacity(q.len());
    let mut a = Vec::with_capacity(q.len());
    for &x in q {
        let i = b.un(Unary::Floor, x);
        f.push(b.sub(x, i));
        let r = mod289(b, i);
        a.push(cell(b, r));
    }
    (f, a)
}

/// Gradient noise at `q` (2 or 3 coordinates): the lattice cell's corners each contribute
/// the dot product of their gradient with the offset from the corner, blended by the quintic
/// fade of the fractional coordinates (Perlin 2002).
pub(super) fn noise(b: &mut Builder, q: &[Reg]) -> Reg {
    let dims = q.len();
    let (f, a) = lattice(b, q, |b, r| [r, b.addc(r, 1.0)]);
    let s: Vec<Reg> = f.iter().map(|&t| fade(b, t)).collect();
    // Each corner's contribution, corners numbered with bit k for axis k.
    let corners = 1usize << dims;
    let mut v: Vec<Reg> = (0..corners)
        .map(|c| {
            let cell: Vec<Reg> = (0..dims).map(|k| a[k][(c >> k) & 1]).collect();
            let h = cell_hash(b, &cell);
            let g = gradient(b, h, dims);
            let mut dot: Option<Reg> = None;
            for k in 0..dims {
                let off = if (c >> k) & 1 == 1 {
                    b.subc(f[k], 1.0)
                } else {
                    f[k]
                };
                let t = b.mul(g[k], off);
                dot = Some(match dot {
                    None => t,
                    Some(d) => b.add(d, t),
                });
            }
            dot.expect("two or three axes")
        })
        .collect();
    // Blend along x, then y, then z.
    for &sk in &s {
        v = v
            .chunks(2)
            .map(|pair| lerp(b, pair[0], pair[1], sk))
            .collect();
    }
    v[0]
}

/// The distance from `q` to the nearest feature point of the lattice: one per cell, at
/// `VORONOI_LO + VORONOI_SPAN · (fract(h·k₁), …)` within it, so that the nearest lies in the
/// 3 (×3 ×3) cells around the point's own.
pub(super) fn voronoi(b: &mut Builder, q: &[Reg]) -> Reg {
    const TURNS: [f64; 3] = [
        GOLDEN_TURN,
        std::f64::consts::SQRT_2 - 1.0,
        1.732_050_807_568_877_2 - 1.0,
    ];
    let dims = q.len();
    let (f, a) = lattice(b, q, |_, r| r);
    let cells = 3usize.pow(dims as u32);
    let mut best: Option<Reg> = None;
    for c in 0..cells {
        let offset: Vec<i32> = (0..dims)
            .map(|k| (c / 3usize.pow(k as u32) % 3) as i32 - 1)
            .collect();
        let cell: Vec<Reg> = (0..dims).map(|k| b.addc(a[k], offset[k] as f64)).collect();
        let h = cell_hash(b, &cell);
        let mut d2: Option<Reg> = None;
        for k in 0..dims {
            let j = fract_of(b, h, TURNS[k]);
            let j = b.mulc(j, VORONOI_SPAN);
            let feature = b.addc(j, f64::from(offset[k]) + VORONOI_LO);
            let d = b.sub(feature, f[k]);
            let sq = b.mul(d, d);
            d2 = Some(match d2 {
                None => sq,
                Some(s) => b.add(s, sq),
            });
        }
        let d2 = d2.expect("two or three axes");
        best = Some(match best {
            None => d2,
            Some(m) => b.min(m, d2),
        });
    }
    let best = best.expect("cells");
    b.sqrt(best)
}
