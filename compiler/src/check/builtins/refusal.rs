//! Why a built-in refuses a call: one variant per reason, with its data. Its `Display` is the
//! message of the E0400 at the call; `OutOfRange`'s that of an argument outside its
//! parameter's range.

use crate::check::LoadError;
use crate::program::mesh::Invalid;
use crate::scene::dump_num;
use crate::scene::path::PathError;
use std::fmt;

/// Why a built-in refuses the arguments it was called with (all in range).
#[derive(Debug, thiserror::Error)]
pub enum Refusal {
    /// A primitive of the table refuses its arguments (its own check, `prim/`).
    #[error("{0}")]
    Primitive(String),
    /// The hull of these shapes has no exact distance here (`hull.rs`).
    #[error("{0}")]
    Hull(crate::check::hull::Refused),
    /// A path (`polyline`, `bezier`, `arc3`) cannot be built from these points.
    #[error(transparent)]
    Path(#[from] PathError),
    /// A file the call reads (a font) cannot be read.
    #[error(transparent)]
    File(#[from] LoadError),
    /// `mesh(path)` cannot make a shape of the file.
    #[error("cannot read the mesh `{path}`: {why}")]
    Mesh { path: String, why: MeshRefusal },
    /// `mesh(path)` of a file whose extension is not a mesh format's.
    #[error("`{path}` is not a mesh file: `mesh` reads .stl, .obj, .ply and .glb files")]
    NotMeshFile { path: String },
    /// `text` cannot lay its string out in the font.
    #[error("{}{error}", font.as_ref().map(|f| format!("`{f}`: ")).unwrap_or_default())]
    Font {
        /// The font file, `None` for the shipped one.
        font: Option<String>,
        error: crate::check::font::FontError,
    },
    /// A polygon of fewer than three points.
    #[error("a polygon needs at least 3 points, and this one has {points}")]
    FewPoints { points: usize },
    /// A polygon whose points are all on one line.
    #[error("the polygon's points lie on one line: it has no area")]
    Collinear,
    /// A polygon whose edges from points `a` and `b` cross.
    #[error("the polygon crosses itself: its edge from point {a} and its edge from point {b} meet (a polygon's edges may only meet at their shared ends)")]
    SelfCrossing { a: usize, b: usize },
    /// A profile that reaches infinity where a finite one is made solid (`what`: which).
    #[error("the {what} profile has no finite extent (it reaches infinity), so it cannot be made solid this way")]
    Unbounded { what: &'static str },
    /// A quadratic Bézier whose control point is the midpoint: a segment.
    #[error("the control point is the midpoint of `a` and `b`, so the curve is the straight segment: draw it with `segment2(a, b, radius)`")]
    StraightBezier,
    /// A screw's profile reaching the axis (`x` its least x).
    #[error("a screw's profile must lie at x > 0 (x is the distance from the axis), and this one reaches x = {}", dump_num(*x))]
    ScrewAxis { x: f64 },
    /// A screw's profile taller than one pitch.
    #[error("a screw's profile is one turn of the thread: it must lie within y = ±{} (half the pitch), and this one spans y from {} to {}", dump_num(*half), dump_num(*lo), dump_num(*hi))]
    ScrewTurn { half: f64, lo: f64, hi: f64 },
    /// `repeat_polar(…, mirror: true)` with an odd count.
    #[error("`mirror: true` alternates the copies, so `count` must be even, not {count}")]
    OddMirror { count: f64 },
    /// A combination (`name`) of an empty list.
    #[error("`{name}` of an empty list: there is no shape to combine")]
    EmptyList { name: &'static str },
    /// `round_box` rounded by more than a half-extent.
    #[error("the rounding radius {radius} is larger than a half-extent of the box")]
    BoxRounding { radius: f64 },
    /// An extrusion rounded by more than half its height.
    #[error("the rounding {round} is more than half the height {height}")]
    ExtrudeRounding { round: f64, height: f64 },
    /// `repeat(…, count)` with a count that is not whole.
    #[error("`count` must be whole numbers of copies")]
    FractionalCount,
    /// A shear whose matrix has no inverse.
    #[error("this shear is singular: it flattens space onto a plane or a line, so the shape has no volume")]
    SingularShear,
    /// `minkowski` with a second shape that is not a ball about the origin.
    #[error("`minkowski` takes a ball about the origin, `sphere(r)`, as its second shape: it is `shape.round(r)`; the sum with another shape has no exact distance here")]
    MinkowskiNotBall,
    /// `clamp(x, lo, hi)` with `lo` > `hi`.
    #[error("`lo` ({lo}) is greater than `hi` ({hi})")]
    ClampOrder { lo: f64, hi: f64 },
    /// `abs` of the least integer.
    #[error("integer overflow")]
    AbsOverflow,
    /// `div(a, 0)`.
    #[error("division by zero: `b` is 0")]
    DivisionByZero,
    /// `div(a, b)` past the integers' range.
    #[error("integer overflow in `div({a}, {b})`")]
    DivOverflow { a: i64, b: i64 },
    /// A per-point built-in (`noise`, `distance`, …) called with constants.
    #[error("this is evaluated per point: call it inside `field {{ … }}` with an argument that depends on `p`")]
    PerPoint,
    /// A built-in built on a primitive the table lacks (a mistake of the compiler's).
    #[error("the primitive `{name}` this builtin is built on is missing from the table")]
    NoPrimitive { name: &'static str },
}

/// Why `mesh(path)` cannot make a shape of a file it read.
#[derive(Debug, thiserror::Error)]
pub enum MeshRefusal {
    /// The file is not a mesh of its format.
    #[error("{0}")]
    Format(crate::check::meshfile::Error),
    /// Its triangles, with those of the meshes read before it, pass the `triangles` limit.
    #[error("{}the file has {triangles} triangles{}, more than the `triangles` limit of {max}; {raise}",
        at.as_ref().map(|p| format!("{p}: ")).unwrap_or_default(),
        if *others > 0 { format!(", and the scene's other meshes {others}") } else { String::new() })]
    Limit {
        /// Where the reader stopped.
        at: Option<crate::check::meshfile::Place>,
        triangles: u64,
        /// The triangles of the scene's other meshes.
        others: u64,
        max: u64,
        /// How to raise the limit (`Limits::raise_to`).
        raise: String,
    },
    /// The triangles are not a mesh (a vertex not finite, an index out of range, no area).
    #[error("{}", invalid(.0))]
    Invalid(Invalid),
    /// The scene's meshes take more GPU data than a 32-bit index reaches.
    #[error("the scene's meshes take more than 2^32 vectors of GPU data")]
    GpuData,
}

fn invalid(e: &Invalid) -> String {
    match e {
        Invalid::NotFinite(i) => format!(
            "vertex {i} (counting from 0 in the file's order) has a coordinate that is not a finite number"
        ),
        Invalid::Index(t, i) => format!("triangle {t} names vertex {i}, which does not exist"),
        Invalid::Empty => "every triangle has no area".to_string(),
    }
}

/// What a parameter's range asks of a value outside it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Expected {
    Positive,
    NonNegative,
    Unit,
    /// Between `lo` and `hi`, shown in degrees for an angle.
    Within {
        lo: f64,
        hi: f64,
        angle: bool,
    },
    NonZero,
    OneOf(&'static [&'static str]),
}

/// A value outside its parameter's range: what the range asks, of each component of a vector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutOfRange {
    pub expected: Expected,
    /// The value is a vector: every component must satisfy the range.
    pub vector: bool,
}

impl fmt::Display for OutOfRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let each = if self.vector { "every component " } else { "" };
        match self.expected {
            Expected::Positive => write!(f, "{each}must be greater than 0"),
            Expected::NonNegative => write!(f, "{each}must be 0 or more"),
            Expected::Unit => write!(f, "{each}must be between 0 and 1"),
            Expected::Within { lo, hi, angle } => {
                // Angles are shown in degrees, as they are usually written.
                let show = |x: f64| match angle {
                    true => format!("{}deg", dump_num(x.to_degrees())),
                    false => dump_num(x),
                };
                write!(f, "{each}must be between {} and {}", show(lo), show(hi))
            }
            Expected::NonZero => f.write_str("must not be the zero vector"),
            Expected::OneOf(opts) => {
                let quoted: Vec<String> = opts.iter().map(|o| format!("\"{o}\"")).collect();
                write!(f, "must be one of {}", quoted.join(", "))
            }
        }
    }
}
