//! User fields (`field { … }`, docs/language.md "Fields", and `profile { … }`, a field of
//! the plane that reads x and y only): the expression of the point that a field shape
//! computes, as a flat list of scalar operations over the point's coordinates, constants,
//! other shapes' distances and noise. The checker builds it (vectors are split
//! into their components, constants folded); the lowering turns each operation into program
//! instructions (`lower/field.rs`); the analysis bounds its gradient (`analysis/field.rs`).

use super::NodeId;

/// Names an operation of a [`FieldFn`] by its index: the value it defines.
pub type Slot = u32;

/// One-operand operations of a field.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FUn {
    /// -a
    Neg,
    /// |a|
    Abs,
    /// √a
    Sqrt,
    /// sin a
    Sin,
    /// cos a
    Cos,
    /// tan a
    Tan,
    /// e^a
    Exp,
    /// ln a
    Log,
    /// ⌊a⌋
    Floor,
    /// The smoothstep polynomial s²(3 − 2s) of s = a clamped to [0, 1].
    Smooth,
}

/// Two-operand operations of a field.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FBin {
    /// a + b
    Add,
    /// a - b
    Sub,
    /// a * b
    Mul,
    /// a / b
    Div,
    /// min(a, b)
    Min,
    /// max(a, b)
    Max,
    /// a^b
    Pow,
    /// atan2(a, b): the angle of the vector (b, a)
    Atan2,
}

/// One operation; operands name earlier operations.
#[derive(Debug, Clone, PartialEq)]
pub enum FOp {
    /// A coordinate of the point (0: x, 1: y, 2: z; a profile's reads x and y only), or of the
    /// unit surface normal `n` (3, 4, 5: its x, y, z; a colour field's alone).
    Coord(u8),
    /// A constant.
    Const(f64),
    /// A one-operand operation.
    Un(FUn, Slot),
    /// A two-operand operation.
    Bin(FBin, Slot, Slot),
    /// The length of a vector of 2 or 3 components.
    Length(Vec<Slot>),
    /// The distance of another shape at a point.
    Distance(NodeId, [Slot; 3]),
    /// Gradient noise at a point of 2 or 3 coordinates, in [−√3/2, √3/2].
    Noise(Vec<Slot>),
    /// The distance from a point of 2 or 3 coordinates to the nearest of the feature points
    /// of the unit lattice (one per cell, jittered within the cell's middle 0.3…0.7).
    Voronoi(Vec<Slot>),
    /// The hash of the unit lattice cell holding a point of 1 to 3 coordinates, in (0, 1):
    /// constant within a cell, so a step at every cell's side.
    Hash(Vec<Slot>),
    /// mix(a, b, t) = a + (b − a)·t: between a and b where t is within [0, 1], which interval
    /// arithmetic over its three operations would not see.
    Mix(Slot, Slot, Slot),
}

impl FOp {
    /// The operations this one reads.
    pub fn operands(&self) -> Vec<Slot> {
        match self {
            FOp::Coord(_) | FOp::Const(_) => Vec::new(),
            FOp::Un(_, a) => vec![*a],
            FOp::Bin(_, a, b) => vec![*a, *b],
            FOp::Length(v) | FOp::Noise(v) | FOp::Voronoi(v) | FOp::Hash(v) => v.clone(),
            FOp::Distance(_, q) => q.to_vec(),
            FOp::Mix(a, b, t) => vec![*a, *b, *t],
        }
    }
}

/// The expression of a field: operations in order, and the ones that are its value (one
/// for a distance, three for a colour).
#[derive(Debug, Clone, PartialEq)]
pub struct FieldFn {
    /// The operations; operation `i` defines slot `i`.
    pub ops: Vec<FOp>,
    /// The slots of the value.
    pub out: Vec<Slot>,
}

impl FieldFn {
    /// The shapes whose distances the field reads, in order of use (with repeats).
    pub fn shapes(&self) -> Vec<NodeId> {
        self.ops
            .iter()
            .filter_map(|op| match op {
                FOp::Distance(id, _) => Some(*id),
                _ => None,
            })
            .collect()
    }

    /// The same expression reading the shapes `f` maps the current ones to.
    pub fn remap(&self, mut f: impl FnMut(NodeId) -> NodeId) -> FieldFn {
        FieldFn {
            ops: self
                .ops
                .iter()
                .map(|op| match op {
                    FOp::Distance(id, q) => FOp::Distance(f(*id), *q),
                    other => other.clone(),
                })
                .collect(),
            out: self.out.clone(),
        }
    }
}

/// The 289 gradient directions of the noise, by hash: points of a Fibonacci spiral on the
/// unit sphere, `z = 1 − (2h + 1)/289`, turning by the golden angle.
pub const NOISE_CELLS: f64 = 289.0;

/// The golden ratio's fractional part: the spiral's turn per gradient, in turns.
pub const GOLDEN_TURN: f64 = 0.618_033_988_749_894_9;

/// The Lipschitz constant of [`FOp::Noise`] (docs/analysis.md, "Noise"): 1 for the
/// gradients' own term, and √3 · 3.25 for the weights' (the largest of
/// fade'(t)·(√(t² + ½) + √((1 − t)² + ½)) is 1.875 · √3 ≈ 3.2476, at t = ½), rounded up.
pub const NOISE_LIPSCHITZ: f64 = 6.63;

/// The largest magnitude of [`FOp::Noise`]: √3 / 2.
pub const NOISE_RANGE: f64 = 0.866_025_404;

/// The jitter of the Voronoi feature points: each lies in `[LO, LO + SPAN)` of its cell per
/// axis, so that the nearest one is always among the 3×3(×3) cells around the point.
pub const VORONOI_LO: f64 = 0.3;
/// See [`VORONOI_LO`].
pub const VORONOI_SPAN: f64 = 0.4;

impl FieldFn {
    /// The instructions the expression costs per point, roughly (the shapes it reads are
    /// counted by the caller).
    pub fn cost(&self) -> f64 {
        self.ops
            .iter()
            .map(|op| match op {
                FOp::Coord(_) | FOp::Const(_) => 0.0,
                FOp::Un(FUn::Smooth, _) => 6.0,
                FOp::Un(FUn::Tan, _) => 3.0,
                FOp::Un(..) | FOp::Bin(..) => 1.0,
                FOp::Length(v) => 2.0 * v.len() as f64,
                FOp::Distance(..) => 0.0,
                FOp::Noise(v) if v.len() == 2 => 160.0,
                FOp::Noise(_) => 320.0,
                FOp::Voronoi(v) if v.len() == 2 => 9.0 * 40.0,
                FOp::Voronoi(_) => 27.0 * 50.0,
                FOp::Hash(v) => 20.0 * v.len() as f64,
                FOp::Mix(..) => 3.0,
            })
            .sum()
    }

    /// The expression as one line of text (`--emit ir`): `s3 = mul s1, s2; …; -> s7`.
    pub fn text(&self) -> String {
        let s = |x: &Slot| format!("s{x}");
        let list = |v: &[Slot]| v.iter().map(s).collect::<Vec<_>>().join(", ");
        let mut out: Vec<String> = self
            .ops
            .iter()
            .enumerate()
            .map(|(i, op)| {
                let rhs = match op {
                    FOp::Coord(a) => ["x", "y", "z", "nx", "ny", "nz"][*a as usize % 6].to_string(),
                    FOp::Const(c) => super::dump_num(*c),
                    FOp::Un(u, a) => format!("{} {}", un_name(*u), s(a)),
                    FOp::Bin(b, x, y) => format!("{} {}, {}", bin_name(*b), s(x), s(y)),
                    FOp::Length(v) => format!("length {}", list(v)),
                    FOp::Distance(id, q) => format!("distance %{} at {}", id.0, list(q)),
                    FOp::Noise(v) => format!("noise {}", list(v)),
                    FOp::Voronoi(v) => format!("voronoi {}", list(v)),
                    FOp::Hash(v) => format!("hash {}", list(v)),
                    FOp::Mix(a, b, t) => format!("mix {}, {}, {}", s(a), s(b), s(t)),
                };
                format!("s{i} = {rhs}")
            })
            .collect();
        out.push(format!("-> {}", list(&self.out)));
        out.join("; ")
    }
}

/// The name of a one-operand operation in text.
pub fn un_name(u: FUn) -> &'static str {
    match u {
        FUn::Neg => "neg",
        FUn::Abs => "abs",
        FUn::Sqrt => "sqrt",
        FUn::Sin => "sin",
        FUn::Cos => "cos",
        FUn::Tan => "tan",
        FUn::Exp => "exp",
        FUn::Log => "log",
        FUn::Floor => "floor",
        FUn::Smooth => "smooth",
    }
}

/// The name of a two-operand operation in text.
pub fn bin_name(b: FBin) -> &'static str {
    match b {
        FBin::Add => "add",
        FBin::Sub => "sub",
        FBin::Mul => "mul",
        FBin::Div => "div",
        FBin::Min => "min",
        FBin::Max => "max",
        FBin::Pow => "pow",
        FBin::Atan2 => "atan2",
    }
}
