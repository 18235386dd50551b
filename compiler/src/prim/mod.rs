//! The primitives' table: one entry per built-in shape or profile that is marched by its
//! formula, stating all that the stages read about it — its signature and the checks among
//! its arguments (the checker, the language server, the language reference), its distance
//! written over the program's operations (the lowering), whether that distance is exact, its
//! box and bounding sphere (the analysis and the culling bounds), its cost, and its doc line.
//!
//! An entry may share its name with another entry or with a built-in of the checker: it is
//! then one more overload of that name (`cylinder(a, b, radius)` beside `cylinder(radius,
//! height)`). Adding such a primitive is one [`Prim`] in one of the files below, its row in
//! docs/language.md (a test prints the row the table gives), its name in the editor grammar
//! (a test names what is missing) and a conformance line. The primitives that are also traced
//! analytically or walked as instances (sphere, box, torus, cylinder, capsule, cone, plane)
//! and those read from data (polygon, text, mesh) keep their own nodes. Two entries are out of
//! the table, since no call names them: the hulls of balls and of circles that the checker
//! builds for `hull(shapes…)` (`hull_balls.rs`).

mod between;
mod hull;
mod hull_balls;
mod mandelbulb;
mod polyhedra;
mod profiles;
mod solids;

use crate::limits::Limit;
use crate::program::builder::{Builder, Slots, P};
use crate::program::Reg;

pub(crate) use between::{placed, scaled, AlongY, Placed};
pub(crate) use hull_balls::{ball_entries, Ball, BALLS as HULL_BALLS, CIRCLES as HULL_CIRCLES};
pub(crate) use profiles::rect;
pub(crate) use solids::{box_from_q, cylinder, extrude, nearer_signed};

/// A parameter's default value.
#[derive(Debug, Clone, Copy)]
pub enum Def {
    /// The argument must be given.
    Req,
    Num(f64),
    Int(i64),
    Bool(bool),
    V3([f64; 3]),
    Text(&'static str),
    /// An angle in degrees.
    Deg(f64),
}

/// The values a numeric parameter accepts (checked per component for vectors).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Range {
    /// Any finite value.
    Any,
    /// > 0
    Pos,
    /// ≥ 0
    NonNeg,
    /// In [0, 1].
    Unit,
    /// In [lo, hi].
    Within(f64, f64),
    /// A vector that is not zero.
    NonZero,
    /// One of the listed strings.
    OneOf(&'static [&'static str]),
    /// In [lo, the value of a resource limit] (the render settings bounded by `--limit`).
    Limited(f64, Limit),
    /// A string whose characters, with those of every string passed so far to a parameter of
    /// this range, are at most the value of a resource limit (`text`'s string, bounded in
    /// all by `text_chars`; checked by the evaluator, which keeps the count).
    Chars(Limit),
}

/// What a primitive's parameter holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Float,
    Int,
    /// An angle, held in radians.
    Angle,
    Vec2,
    Vec3,
    /// A list of points (`[vec3]`); a primitive has at most one such parameter.
    Points,
}

/// One parameter of a primitive (`ty` its [`Kind`]), or of a built-in of the checker (its
/// type of value).
#[derive(Debug, Clone, Copy)]
pub struct Param<K = Kind> {
    pub name: &'static str,
    /// What it holds.
    pub ty: K,
    pub def: Def,
    pub range: Range,
}

pub(crate) const fn param<K>(name: &'static str, ty: K, def: Def, range: Range) -> Param<K> {
    Param {
        name,
        ty,
        def,
        range,
    }
}

/// The arguments of a primitive, in the order of its parameters, each as three numbers (a
/// float, an int or an angle in the first; a vec2 in the first two); a list of points as its
/// length in the first, its points after every parameter's.
#[derive(Debug, Clone, PartialEq)]
pub struct Args(pub Vec<[f64; 3]>);

impl Args {
    /// Arguments that are numbers alone (floats, ints or angles), one each.
    pub fn numbers(numbers: &[f64]) -> Args {
        Args(numbers.iter().map(|&x| [x, 0.0, 0.0]).collect())
    }

    /// The arguments `numbers` (one each) with the list `points` as parameter `at`.
    pub fn with_list(numbers: &[f64], at: usize, points: &[[f64; 3]]) -> Args {
        let mut v: Vec<[f64; 3]> = numbers.iter().map(|&x| [x, 0.0, 0.0]).collect();
        v.insert(at, [points.len() as f64, 0.0, 0.0]);
        v.extend_from_slice(points);
        Args(v)
    }

    /// The list of points argument `i`.
    pub fn list(&self, i: usize) -> &[[f64; 3]] {
        let n = self.0[i][0] as usize;
        &self.0[self.0.len() - n..]
    }

    /// The float, int (as a float) or angle (in radians) argument `i`.
    pub fn f(&self, i: usize) -> f64 {
        self.0[i][0]
    }

    pub fn v2(&self, i: usize) -> [f64; 2] {
        [self.0[i][0], self.0[i][1]]
    }

    pub fn v3(&self, i: usize) -> [f64; 3] {
        self.0[i]
    }
}

/// How a primitive's field relates to the distance to its surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Field {
    /// The exact signed distance.
    Exact,
    /// An estimate with no proven bound (a fractal's distance estimator).
    Unproven,
}

/// Where a primitive's solid lies: a box (unbounded along an axis where it is infinite), a
/// sphere about the box's centre that holds it, and the coordinate planes across which it is
/// symmetric. A profile's box and sphere are read in the xy plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extent {
    pub min: [f64; 3],
    pub max: [f64; 3],
    /// The radius of a sphere about the box's centre that holds the solid (∞ for an
    /// unbounded one).
    pub radius: f64,
    /// Across plane i (x = 0, y = 0, z = 0) the solid is its own mirror image.
    pub symmetric: [bool; 3],
}

impl Extent {
    /// The box of half-extents `half` about the origin, within `radius` of it.
    fn centred(half: [f64; 3], radius: f64, symmetric: [bool; 3]) -> Extent {
        Extent {
            min: half.map(|h| -h),
            max: half,
            radius,
            symmetric,
        }
    }
}

/// One built-in primitive: everything the stages read about it.
#[derive(Debug)]
pub struct Prim {
    /// The name users call it by.
    pub name: &'static str,
    /// A 2D profile in the xy plane (its distance reads x and y), or a solid.
    pub profile: bool,
    pub params: &'static [Param],
    /// The values accepted, in words, beyond what each parameter's range says: the
    /// language reference's second column.
    pub accepts: &'static str,
    /// What it is, for the language reference, hovers and completion.
    pub doc: &'static str,
    /// Checks among the arguments beyond each one's range: why they are refused.
    pub check: fn(&Args) -> Option<String>,
    pub field: Field,
    pub extent: fn(&Args) -> Extent,
    /// The instructions it costs per point, roughly.
    pub cost: fn(&Args) -> f64,
    /// Its distance at the point `p` (in its own frame), written over the program's
    /// operations.
    pub(crate) distance: fn(&mut Builder, P, &Args) -> Reg,
}

/// A primitive of the table as a node of the scene graph names it: shown by its name and
/// parameters (overloads share a name), equal when it is the same entry.
#[derive(Clone, Copy)]
pub struct PrimRef(pub &'static Prim);

impl PartialEq for PrimRef {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self.0, other.0)
    }
}

impl std::fmt::Debug for PrimRef {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        let params: Vec<&str> = self.0.params.iter().map(|p| p.name).collect();
        write!(f, "{}({})", self.0.name, params.join(", "))
    }
}

impl std::ops::Deref for PrimRef {
    type Target = Prim;
    fn deref(&self) -> &Prim {
        self.0
    }
}

/// Every entry, solids then profiles, in the order of the language reference.
pub fn all() -> impl Iterator<Item = &'static Prim> {
    [
        mandelbulb::PRIMS,
        solids::PRIMS,
        between::PRIMS,
        hull::PRIMS,
        polyhedra::PRIMS,
        profiles::PRIMS,
    ]
    .into_iter()
    .flatten()
}

/// The first entry of the primitive `name` (others of that name are its overloads).
pub fn find(name: &str) -> Option<&'static Prim> {
    all().find(|p| p.name == name)
}

/// The constants of an entry that a marched scene's instance may be, the capped and round
/// cones along y (`lower::slots`): what its distance reads through [`Builder::param`].
pub(crate) fn slots(prim: PrimRef, args: &Args) -> Option<Slots> {
    match (prim.name, prim.params[0].ty) {
        ("capped_cone", _) => Some(solids::capped_cone_slots(
            args.f(0) / 2.0,
            args.f(1),
            args.f(2),
        )),
        ("round_cone", Kind::Float) => Some(solids::round_cone_slots(
            args.f(0),
            args.f(1),
            args.f(2) / 2.0,
        )),
        _ => None,
    }
}

/// The distance of an entry [`slots`] knows at `p`, its constants `s` read through
/// [`Builder::param`]: the entry's own distance with `s` its slots.
pub(crate) fn exact(b: &mut Builder, p: P, prim: PrimRef, s: &Slots) -> Option<Reg> {
    match (prim.name, prim.params[0].ty) {
        ("capped_cone", _) => Some(solids::capped_cone(b, p, s)),
        ("round_cone", Kind::Float) => Some(solids::round_cone(b, p, s)),
        _ => None,
    }
}

/// No check among the arguments.
fn any(_: &Args) -> Option<String> {
    None
}

/// The unit vector along `v` (not zero: its range says so).
fn unit(v: [f64; 3]) -> [f64; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|x| x / l)
}

/// The refusal of a `what` of size `x` larger than one of the half-extents `half` of the
/// `shape`; none where it fits within each.
fn within_halves(half: &[f64], x: f64, what: &str, shape: &str) -> Option<String> {
    half.iter().any(|&h| h < x).then(|| {
        format!(
            "the {what} {} is larger than a half-extent of the {shape}",
            num(x)
        )
    })
}

/// A number for a message.
fn num(x: f64) -> String {
    crate::diagnostics::number(x, 6)
}
