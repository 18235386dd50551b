//! The built-in functions and record schemas: signatures (types, defaults, valid ranges) and
//! their constant evaluation. Shape builtins add nodes to the scene graph.

mod refusal;

use super::types::{Type, Value};
use super::LoadError;
use crate::limits::{Limit, Limits};
use crate::lower::hash_of;
use crate::prim::{Args, Kind, Prim, PrimRef};
pub use crate::prim::{Def, Range};
use crate::scene::{
    Camera, Combine, Feature, Graph, Material, Node, NodeId, Path, Pbr, Settings, Smooth, V3,
};
use crate::span::Span;
pub use refusal::{Expected, MeshRefusal, OutOfRange, Refusal};

impl Def {
    /// The default as a value; `None` for a required parameter.
    pub fn value(self) -> Option<Value> {
        Some(match self {
            Def::Req => return None,
            Def::Num(f) => Value::Float(f),
            Def::Int(i) => Value::Int(i),
            Def::Bool(b) => Value::Bool(b),
            Def::V3(v) => Value::Vec3(v),
            Def::Text(s) => Value::Str(s.into()),
            Def::Deg(d) => Value::Angle(d.to_radians()),
        })
    }
}

impl Range {
    /// The range with its resource limit, if any, replaced by the limit's value.
    pub fn resolve(self, limits: &Limits) -> Range {
        match self {
            Range::Limited(lo, l) => Range::Within(lo, limits.get(l) as f64),
            other => other,
        }
    }

    /// The resource limit a value beyond the top of this range exceeds.
    pub fn limit(self, v: &Value, limits: &Limits) -> Option<Limit> {
        match self {
            Range::Limited(_, l) => {
                let top = limits.get(l) as f64;
                v.components().iter().any(|&x| x > top).then_some(l)
            }
            _ => None,
        }
    }

    /// Checks a concrete value; says what was expected when it is out of range.
    pub fn check(self, v: &Value, limits: &Limits) -> Result<(), OutOfRange> {
        let range = self.resolve(limits);
        let c = v.components();
        let expected = match range {
            Range::Any | Range::Limited(..) | Range::Chars(_) => return Ok(()),
            Range::Pos if c.iter().all(|&x| x > 0.0) => return Ok(()),
            Range::NonNeg if c.iter().all(|&x| x >= 0.0) => return Ok(()),
            Range::Unit if c.iter().all(|&x| (0.0..=1.0).contains(&x)) => return Ok(()),
            Range::Within(lo, hi) if c.iter().all(|&x| x >= lo && x <= hi) => return Ok(()),
            Range::NonZero if c.iter().any(|&x| x != 0.0) => return Ok(()),
            Range::OneOf(opts) => match v {
                Value::Str(s) if !opts.contains(&&**s) => Expected::OneOf(opts),
                _ => return Ok(()),
            },
            Range::Pos => Expected::Positive,
            Range::NonNeg => Expected::NonNegative,
            Range::Unit => Expected::Unit,
            Range::Within(lo, hi) => Expected::Within {
                lo,
                hi,
                angle: matches!(v, Value::Angle(_)),
            },
            Range::NonZero => Expected::NonZero,
        };
        Err(OutOfRange {
            expected,
            vector: matches!(v, Value::Vec2(_) | Value::Vec3(_)),
        })
    }
}

/// One parameter of a builtin or record.
#[derive(Debug, Clone, Copy)]
pub struct P {
    pub name: &'static str,
    pub ty: Type,
    pub def: Def,
    pub range: Range,
}

const fn p(name: &'static str, ty: Type, def: Def, range: Range) -> P {
    P {
        name,
        ty,
        def,
        range,
    }
}

const fn shape(name: &'static str) -> P {
    p(name, Type::Shape, Def::Req, Range::Any)
}

/// The evaluation of one overload on bound, in-range, concrete arguments.
#[derive(Clone, Copy)]
pub enum Imp {
    /// A function of the arguments.
    Fn(fn(&mut Build<'_, '_>, &[Value]) -> Result<Value, Refusal>),
    /// A primitive of the table: its node, once its checks pass.
    Prim(&'static Prim),
}

impl std::fmt::Debug for Imp {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            Imp::Fn(_) => f.write_str("Fn"),
            Imp::Prim(p) => write!(f, "Prim({})", p.name),
        }
    }
}

impl Imp {
    /// Evaluates the overload on its arguments.
    pub fn call(self, b: &mut Build<'_, '_>, a: &[Value]) -> Result<Value, Refusal> {
        match self {
            Imp::Fn(f) => f(b, a),
            Imp::Prim(prim) => {
                let three = |v: &Value| {
                    let c = v.components();
                    [0, 1, 2].map(|i| c.get(i).copied().unwrap_or(0.0))
                };
                let mut args = Args(a.iter().map(three).collect());
                for (i, v) in a.iter().enumerate() {
                    if let Value::List(_, items) = v {
                        args.0[i] = [items.len() as f64, 0.0, 0.0];
                        args.0.extend(items.iter().map(three));
                    }
                }
                if let Some(why) = (prim.check)(&args) {
                    return Err(Refusal::Primitive(why));
                }
                let node = Node::Prim {
                    prim: PrimRef(prim),
                    args,
                };
                if prim.profile {
                    b.profile(node)
                } else {
                    b.node(node)
                }
            }
        }
    }
}

/// One overload.
#[derive(Debug, Clone)]
pub struct Sig {
    pub params: &'static [P],
    /// The last parameter may be repeated (variadic).
    pub rest: bool,
    pub ret: Type,
    pub imp: Imp,
}

/// A builtin function with its overloads, tried in order.
#[derive(Debug, Clone, Copy)]
pub struct Builtin {
    pub name: &'static str,
    pub sigs: &'static [Sig],
}

/// What a builtin may touch: the scene graph, the span of the call for the nodes it adds,
/// the files `mesh` reads, the limits, and the warnings it gives.
#[derive(Debug)]
pub struct Build<'a, 'l> {
    pub graph: &'a mut Graph,
    pub span: Span,
    /// The files `mesh(path)` reads (none: no file can be read).
    pub files: Option<&'a mut super::Files<'l>>,
    pub limits: &'a Limits,
    pub warnings: Vec<crate::diagnostics::Diagnostic>,
    /// Evaluation steps the `fuel` limit leaves, and those the call has taken (spent by the
    /// evaluator after it: more than were left reports the limit at the call).
    pub fuel_left: u64,
    pub steps: u64,
}

impl Build<'_, '_> {
    /// The bytes of the file `path` (relative to the calling file), read through the
    /// caller's loader.
    fn read_bytes(&mut self, path: &str) -> Result<Vec<u8>, LoadError> {
        let no_files = || LoadError::NoFiles { path: path.into() };
        let files = self.files.as_deref_mut().ok_or_else(no_files)?;
        let from = files
            .names
            .get(self.span.file.0 as usize)
            .cloned()
            .unwrap_or_default();
        let loader = files.loader.as_deref_mut().ok_or_else(no_files)?;
        loader.load_bytes(&from, path).map(|(_, bytes)| bytes)
    }

    /// The shape of the triangle mesh in the file `path` (relative to the calling file),
    /// scaled by `scale`: read once per file and scale, with a warning where it is open.
    fn mesh(&mut self, path: &str, scale: f64) -> Result<Value, Refusal> {
        use super::meshfile::{read, Error, Format};
        use crate::program::mesh::TriMesh;
        let format = Format::of(path).ok_or_else(|| Refusal::NotMeshFile { path: path.into() })?;
        let refused = |why| Refusal::Mesh {
            path: path.into(),
            why,
        };
        let no_files = || Refusal::File(LoadError::NoFiles { path: path.into() });
        let files = self.files.as_deref_mut().ok_or_else(no_files)?;
        let from = files
            .names
            .get(self.span.file.0 as usize)
            .cloned()
            .unwrap_or_default();
        let loader = files.loader.as_deref_mut().ok_or_else(no_files)?;
        let (name, bytes) = loader.load_bytes(&from, path)?;
        let key = (name.clone(), scale.to_bits());
        if let Some(m) = files.meshes.get(&key) {
            let node = Node::Mesh {
                mesh: crate::scene::MeshRef(std::sync::Arc::clone(m)),
            };
            return self.node(node);
        }
        let max = self.limits.get(Limit::Triangles);
        let used = files.triangles;
        let read = read(format, &bytes, max.saturating_sub(used)).map_err(|e| {
            refused(match e {
                // The limit is for all the scene's meshes: the value that would do is this
                // file's triangles and those read before it.
                Error::Limit { triangles, at, .. } => MeshRefusal::Limit {
                    at,
                    triangles,
                    others: used,
                    max,
                    raise: self
                        .limits
                        .raise_to(Limit::Triangles, triangles.saturating_add(used)),
                },
                e => MeshRefusal::Format(e),
            })
        })?;
        let mut mesh = TriMesh::new(path, &read.positions, &read.faces, scale)
            .map_err(|e| refused(MeshRefusal::Invalid(e)))?;
        mesh.id = files.next_id;
        mesh.base = u32::try_from(files.next_base).map_err(|_| refused(MeshRefusal::GpuData))?;
        files.next_id += 1;
        files.next_base += mesh.vectors();
        files.triangles += mesh.triangles().len() as u64;
        let r = mesh.report;
        if r.open_edges > 0 || r.non_manifold_edges > 0 {
            let mut what = Vec::new();
            if r.open_edges > 0 {
                what.push(format!("{} open edges (the rims of holes)", r.open_edges));
            }
            if r.non_manifold_edges > 0 {
                what.push(format!(
                    "{} edges shared by more than two triangles",
                    r.non_manifold_edges
                ));
            }
            self.warnings.push(
                crate::diagnostics::Diagnostic::warning(
                    "W0015",
                    format!("the mesh `{path}` is not closed: it has {}", what.join(" and ")),
                    self.span,
                )
                .with_label("this mesh")
                .with_note(
                    "the distance is exact, but the inside is decided by the nearest triangle's side: right away from the holes, while points that see a hole may take the wrong side, which shows as a seam or a sheet across it",
                ),
            );
        }
        let mesh = std::sync::Arc::new(mesh);
        files.meshes.insert(key, std::sync::Arc::clone(&mesh));
        self.node(Node::Mesh {
            mesh: crate::scene::MeshRef(mesh),
        })
    }

    fn node(&mut self, node: Node) -> Result<Value, Refusal> {
        Ok(Value::Shape(self.graph.add(node, self.span)))
    }

    /// Adds a node of a profile (whose distance reads only x and y).
    fn profile(&mut self, node: Node) -> Result<Value, Refusal> {
        Ok(Value::Profile(self.graph.add(node, self.span)))
    }
}

/// The result of a builder of shapes as a profile: the 2D operations add the same nodes as
/// the 3D ones, in the plane z = 0.
fn flat(v: Result<Value, Refusal>) -> Result<Value, Refusal> {
    Ok(match v? {
        Value::Shape(id) => Value::Profile(id),
        other => other,
    })
}

const fn prof(name: &'static str) -> P {
    p(name, Type::Profile, Def::Req, Range::Any)
}

fn sh(v: &Value) -> NodeId {
    match v {
        Value::Shape(id) | Value::Profile(id) => *id,
        _ => NodeId(0),
    }
}

/// Renders a signature for notes: `sphere(radius: float = 1) -> shape`.
pub fn signature(name: &str, sig: &Sig) -> String {
    let params: Vec<String> = sig
        .params
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let rest = if sig.rest && i + 1 == sig.params.len() {
                "..."
            } else {
                ""
            };
            match p.def.value() {
                Some(v) => format!("{}{rest}: {} = {v}", p.name, p.ty),
                None => format!("{}{rest}: {}", p.name, p.ty),
            }
        })
        .collect();
    format!("{name}({}) -> {}", params.join(", "), sig.ret)
}

use Def::*;
use Range::*;
use Type::{Angle as A, Bool as B, Float as F, Int as I, Shape as S, Str, Vec2 as V2, Vec3 as V};

/// A list of shapes, `[shape]`.
const LS: Type = Type::List(&Type::Shape);
/// A list of profiles, `[profile]`.
const LP: Type = Type::List(&Type::Profile);
/// A profile.
const PR: Type = Type::Profile;

/// `polygon(points)`: three or more points, not all on a line, no two edges crossing.
fn polygon(b: &mut Build, a: &[Value]) -> Result<Value, Refusal> {
    let Value::List(_, items) = &a[0] else {
        return Ok(Value::Error);
    };
    let points: Vec<[f64; 2]> = items
        .iter()
        .map(|v| match v {
            Value::Vec2(q) => *q,
            _ => [0.0; 2],
        })
        .collect();
    polygon_of(b, points)
}

/// `text(string, size, font)`: the glyphs of `string` in the font (the shipped DejaVu Sans
/// when `font` is empty), laid out by `check/font.rs`.
fn text(b: &mut Build, a: &[Value]) -> Result<Value, Refusal> {
    let (Value::Str(string), Value::Str(font)) = (&a[0], &a[2]) else {
        return Ok(Value::Error);
    };
    let size = a[1].num();
    let outline = outline_of(b, string, size, font)?;
    b.profile(Node::Text {
        text: string.to_string(),
        size,
        font: font.to_string(),
        outline: std::sync::Arc::new(outline),
    })
}

/// The glyphs of `string` in the font file `font` (empty: the shipped DejaVu Sans), the em
/// `size` high, laid out as `text` lays them out.
fn outline_of(
    b: &mut Build,
    string: &str,
    size: f64,
    font: &str,
) -> Result<crate::program::outline::Outline, Refusal> {
    if font.is_empty() {
        super::font::layout(super::font::default_font(), string, size)
            .map_err(|error| Refusal::Font { font: None, error })
    } else {
        let bytes = b.read_bytes(font)?;
        super::font::layout(&bytes, string, size).map_err(|error| Refusal::Font {
            font: Some(font.into()),
            error,
        })
    }
}

/// `text_size`: the width and height of the box around the ink of what `text` draws with
/// the same arguments.
fn text_size(b: &mut Build, a: &[Value]) -> Result<Value, Refusal> {
    let (Value::Str(string), Value::Str(font)) = (&a[0], &a[2]) else {
        return Ok(Value::Error);
    };
    let (lo, hi) = outline_of(b, string, a[1].num(), font)?.bounds();
    Ok(Value::Vec2([hi[0] - lo[0], hi[1] - lo[1]]))
}

fn polygon_of(b: &mut Build, points: Vec<[f64; 2]>) -> Result<Value, Refusal> {
    let n = points.len();
    if n < 3 {
        return Err(Refusal::FewPoints { points: n });
    }
    // Every point on the line through the first and some other point.
    let o = points[0];
    let on_line = points.iter().find(|q| **q != o).is_none_or(|e| {
        points
            .iter()
            .all(|q| (e[0] - o[0]) * (q[1] - o[1]) == (e[1] - o[1]) * (q[0] - o[0]))
    });
    if on_line {
        return Err(Refusal::Collinear);
    }
    let crossing = super::polygon::crossing(&points, b.fuel_left, &mut b.steps);
    let Ok(crossing) = crossing else {
        // Out of steps: the evaluator reports the `fuel` limit at the call.
        return Ok(Value::Error);
    };
    if let Some((a, b)) = crossing {
        return Err(Refusal::SelfCrossing { a, b });
    }
    b.profile(Node::Polygon { points })
}

/// The rectangle of a profile argument and its bound's scale (`scene::bounds::profile_rect`),
/// or why it has none.
fn rect_of(b: &Build, v: &Value, what: &'static str) -> Result<([f64; 2], [f64; 2], f64), Refusal> {
    crate::scene::bounds::profile_rect(b.graph, sh(v)).ok_or(Refusal::Unbounded { what })
}

/// `bezier(a, control, b, radius)`: the curve is a parabola's arc only where the control
/// point is off the midpoint of `a` and `b` (at the midpoint it is the segment, which
/// `segment2` draws).
fn bezier(b: &mut Build, a: &[Value]) -> Result<Value, Refusal> {
    let [x, c, y] = [0, 1, 2].map(|i| {
        let v = a[i].components();
        [v[0], v[1]]
    });
    let bend = [x[0] - 2.0 * c[0] + y[0], x[1] - 2.0 * c[1] + y[1]];
    let span = (y[0] - x[0])
        .hypot(y[1] - x[1])
        .max((c[0] - x[0]).hypot(c[1] - x[1]));
    if bend[0].hypot(bend[1]) <= 1e-6 * span.max(1e-300) {
        return Err(Refusal::StraightBezier);
    }
    b.profile(Node::Bezier {
        a: x,
        control: c,
        b: y,
        radius: a[3].num(),
    })
}

/// `loft(bottom, top, height)`: the spread bounds |b - a| for exact profiles, from the
/// circles around their rectangles (docs/analysis.md, "Loft").
/// Where one profile is an `offset` of the other, their fields differ by its amount
/// everywhere, and that is the spread.
fn loft(b: &mut Build, a: &[Value]) -> Result<Value, Refusal> {
    let (ca, ha, _) = rect_of(b, &a[0], "bottom")?;
    let (cb, hb, _) = rect_of(b, &a[1], "top")?;
    let (x, y) = (sh(&a[0]), sh(&a[1]));
    let offset = |from: NodeId, to: NodeId| match b.graph.node(to) {
        Node::Round { radius, child } if *child == from => Some(radius.abs()),
        _ => None,
    };
    let spread = offset(x, y).or_else(|| offset(y, x)).unwrap_or_else(|| {
        (ca[0] - cb[0]).hypot(ca[1] - cb[1]) + ha[0].hypot(ha[1]) + hb[0].hypot(hb[1])
    });
    b.node(Node::Loft {
        half_height: a[2].num() / 2.0,
        spread,
        bottom: sh(&a[0]),
        top: sh(&a[1]),
    })
}

/// `screw(profile, pitch, height)`: the profile, one turn's cross-section, must lie at
/// x > 0 (x is the distance from the axis) and within one pitch about y = 0.
fn screw(b: &mut Build, a: &[Value]) -> Result<Value, Refusal> {
    let (c, h, scale) = rect_of(b, &a[0], "screw's")?;
    let (pitch, height) = (a[1].num(), a[2].num());
    let inner = c[0] - h[0];
    if inner <= 0.0 {
        return Err(Refusal::ScrewAxis { x: inner });
    }
    let (lo, hi) = (c[1] - h[1], c[1] + h[1]);
    let half = pitch / 2.0;
    if lo < -half - 1e-9 * pitch || hi > half + 1e-9 * pitch {
        return Err(Refusal::ScrewTurn { half, lo, hi });
    }
    let thread = b.node(Node::Screw {
        pitch,
        half_height: height / 2.0,
        inner,
        floor: scale.min(1.0),
        child: sh(&a[0]),
    })?;
    match &a[3] {
        // A left-handed thread is the right-handed one's mirror image: reflected across x = 0,
        // which keeps the axis and the profile's half-plane.
        Value::Str(hand) if &**hand == "left" => b.node(Node::Rotate {
            matrix: householder([1.0, 0.0, 0.0]),
            child: sh(&thread),
        }),
        _ => Ok(thread),
    }
}

/// The points of a list of vec3.
fn points3(v: &Value) -> Vec<V3> {
    match v {
        Value::List(_, items) => items
            .iter()
            .map(|x| {
                let c = x.components();
                [0, 1, 2].map(|i| c.get(i).copied().unwrap_or(0.0))
            })
            .collect(),
        _ => Vec::new(),
    }
}

/// `sweep(profile, path)`: the profile's reach from its origin against the path's reach; a
/// profile that reaches past it (but a disc, whose sweep is a union of balls) is W0018.
fn sweep(b: &mut Build, a: &[Value]) -> Result<Value, Refusal> {
    let Value::Path(path) = &a[1] else {
        return Ok(Value::Error);
    };
    let (c, h, _) = rect_of(b, &a[0], "swept")?;
    let extent = (c[0].abs() + h[0]).hypot(c[1].abs() + h[1]);
    let child = sh(&a[0]);
    let (reach, at, why) = path.reach();
    let round = crate::scene::path::round_profile(b.graph, child);
    let folds = !round && extent >= reach;
    if folds {
        let show = |x: f64| crate::diagnostics::number(x, 4);
        let how = if why == "curvature" {
            format!("bends with a radius of {}", show(reach))
        } else {
            format!("comes within {} of itself", show(2.0 * reach))
        };
        b.warnings.push(
            crate::diagnostics::Diagnostic::warning(
                "W0018",
                format!(
                    "the profile reaches {} from the path, but the path {how} at ({}, {}, {}): the sweep folds over itself there",
                    show(extent),
                    show(at.x),
                    show(at.y),
                    show(at.z)
                ),
                b.span,
            )
            .with_label("this sweep")
            .with_note(format!(
                "a profile swept along a path must stay within the path's reach ({} here) of its origin, or its planes cross and the field is wrong there (not proven a bound); make the profile smaller or the path gentler",
                show(reach)
            )),
        );
    }
    let inner = if round || folds {
        f64::INFINITY
    } else {
        reach - extent
    };
    b.node(Node::Sweep {
        path: crate::scene::PathRef(std::sync::Arc::clone(path)),
        inner,
        extent,
        folds,
        child,
    })
}

/// The reflection across the plane through the origin with normal `n` (not zero):
/// I − 2·n·nᵀ/|n|², orthogonal, symmetric and its own inverse.
fn householder(n: V3) -> [V3; 3] {
    let nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| f64::from(u8::from(i == j)) - 2.0 * n[i] * n[j] / nn))
}

/// The points of a regular polygon of `sides` with its corners `radius` from the centre,
/// the first on +y, turning counter-clockwise.
fn regular(sides: usize, radius: f64, phase: f64) -> Vec<[f64; 2]> {
    (0..sides)
        .map(|i| {
            let t = std::f64::consts::FRAC_PI_2
                + phase
                + std::f64::consts::TAU * i as f64 / sides as f64;
            [radius * t.cos(), radius * t.sin()]
        })
        .collect()
}

/// The number of elements of a list of any type (`len` has a form for each element type but
/// `int`: a list of ints fits `[float]`).
fn len(a: &[Value]) -> Result<Value, Refusal> {
    match &a[0] {
        Value::List(_, items) => Ok(Value::Int(items.len() as i64)),
        _ => Ok(Value::Error),
    }
}

const HANDS: &[&str] = &["right", "left"];

const SMOOTH_VARIANTS: &[&str] = &["poly", "exp", "chamfer", "round", "stairs", "columns"];

fn smooth(b: &mut Build, a: &[Value], op: Combine) -> Result<Value, Refusal> {
    let steps = a[4].num() as u32;
    let variant = match &a[3] {
        Value::Str(s) => match &**s {
            "exp" => Smooth::Exp,
            "chamfer" => Smooth::Chamfer,
            "round" => Smooth::Round,
            "stairs" => Smooth::Stairs(steps),
            "columns" => Smooth::Columns(steps),
            _ => Smooth::Poly,
        },
        _ => Smooth::Poly,
    };
    b.node(Node::SmoothCombine {
        op,
        k: a[0].num(),
        variant,
        a: sh(&a[1]),
        b: sh(&a[2]),
    })
}

fn feature(b: &mut Build, a: &[Value], op: Feature) -> Result<Value, Refusal> {
    b.node(Node::Feature {
        op,
        a: sh(&a[0]),
        b: sh(&a[1]),
    })
}

fn rotation(axis: V3, angle: f64) -> [V3; 3] {
    let len = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    let [x, y, z] = [axis[0] / len, axis[1] / len, axis[2] / len];
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    // Rodrigues' rotation matrix (rows), rotating the shape by `angle` about `axis`.
    let m = [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ];
    // Snap round-off (cos 90° = 6e-17) so that quarter turns are exact permutations.
    m.map(|row| {
        row.map(|v| {
            if v.abs() < 1e-15 {
                0.0
            } else if (v.abs() - 1.0).abs() < 1e-15 {
                v.signum()
            } else {
                v
            }
        })
    })
}

/// `repeat_polar(shape, count, axis, mirror)`: the node about y, between rotations that take
/// y to `axis` and back for any other axis.
fn repeat_polar(b: &mut Build, a: &[Value]) -> Result<Value, Refusal> {
    let count = a[1].num();
    let mirror = a[3] == Value::Bool(true);
    if mirror && count % 2.0 != 0.0 {
        return Err(Refusal::OddMirror { count });
    }
    let n = a[2].v3();
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let axis = n.map(|x| x / len);
    // The rotation taking y to the axis: about y × axis by the angle between them.
    let turn = if (axis[1] - 1.0).abs() < 1e-15 {
        None
    } else if (axis[1] + 1.0).abs() < 1e-15 {
        Some(rotation([1.0, 0.0, 0.0], std::f64::consts::PI))
    } else {
        Some(rotation(
            [axis[2], 0.0, -axis[0]],
            axis[1].clamp(-1.0, 1.0).acos(),
        ))
    };
    let mut child = sh(&a[0]);
    if let Some(m) = turn {
        let back = [0, 1, 2].map(|i| [0, 1, 2].map(|j| m[j][i]));
        child = b.graph.add(
            Node::Rotate {
                matrix: back,
                child,
            },
            b.span,
        );
    }
    let polar = b.graph.add(
        Node::RepeatPolar {
            count: count as u32,
            mirror,
            child,
        },
        b.span,
    );
    match turn {
        Some(matrix) => b.node(Node::Rotate {
            matrix,
            child: polar,
        }),
        None => Ok(Value::Shape(polar)),
    }
}

fn rotate(b: &mut Build, child: &Value, axis: V3, angle: f64) -> Result<Value, Refusal> {
    b.node(Node::Rotate {
        matrix: rotation(axis, angle),
        child: sh(child),
    })
}

/// The shapes of a list argument; an empty list is an error (nothing to combine).
fn shapes(list: &Value, name: &'static str) -> Result<Vec<Value>, Refusal> {
    match list {
        Value::List(_, items) if items.is_empty() => Err(Refusal::EmptyList { name }),
        Value::List(_, items) => Ok(items.to_vec()),
        _ => Ok(Vec::new()),
    }
}

/// `union(shapes)`, `intersect(shapes)`: the same node as the shapes given one by one.
fn combine_list(
    b: &mut Build,
    a: &[Value],
    op: Combine,
    name: &'static str,
) -> Result<Value, Refusal> {
    let items = shapes(&a[0], name)?;
    match items.as_slice() {
        [one] => Ok(one.clone()),
        _ => combine(b, &items, op),
    }
}

/// `smooth_union(k, shapes, …)`: the left fold of the binary form,
/// `smooth_union(k, smooth_union(k, a, b), c)`; its other arguments as the binary form's.
fn smooth_list(
    b: &mut Build,
    a: &[Value],
    op: Combine,
    name: &'static str,
) -> Result<Value, Refusal> {
    let items = shapes(&a[1], name)?;
    let mut acc = items[0].clone();
    for x in &items[1..] {
        let mut args = vec![a[0].clone(), acc, x.clone()];
        args.extend_from_slice(&a[2..]);
        acc = smooth(b, &args, op)?;
    }
    Ok(acc)
}

/// `hull(shapes…)` (`hull.rs`): its node, or why there is none.
fn hull(b: &mut Build, a: &[Value]) -> Result<Value, Refusal> {
    let ids: Vec<NodeId> = a.iter().map(sh).collect();
    let (limits, most) = (b.limits, b.limits.count(Limit::HullShapes));
    let raise = |n| limits.raise_to(Limit::HullShapes, n);
    super::hull::hull(b.graph, b.span, &ids, most, raise)
        .map(Value::Shape)
        .map_err(Refusal::Hull)
}

fn combine(b: &mut Build, a: &[Value], op: Combine) -> Result<Value, Refusal> {
    b.node(Node::Combine {
        op,
        children: a.iter().map(sh).collect(),
    })
}

fn f1(a: &[Value], f: fn(f64) -> f64) -> Result<Value, Refusal> {
    Ok(Value::Float(f(a[0].num())))
}

fn hash(i: i64) -> f64 {
    // A 64-bit integer mix (splitmix64's finaliser); the top 53 bits as a float in [0, 1).
    let mut z = (i as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

fn vmap(v: &Value, f: impl Fn(f64) -> f64) -> Value {
    match v {
        Value::Vec2(a) => Value::Vec2([f(a[0]), f(a[1])]),
        Value::Vec3(a) => Value::Vec3([f(a[0]), f(a[1]), f(a[2])]),
        other => Value::Float(f(other.num())),
    }
}

macro_rules! sigs {
    ($([$($p:expr),*] $(rest $rest:tt)? -> $ret:expr => $imp:expr;)*) => {
        &[$(Sig { params: &[$($p),*], rest: sigs!(@rest $($rest)?), ret: $ret, imp: Imp::Fn($imp) }),*]
    };
    (@rest) => { false };
    (@rest $t:tt) => { true };
}

/// The name of the time, in seconds, that every expression may read (docs/animation.md): a
/// constant, parameter or loop variable of that name hides it.
pub const TIME: &str = "t";

/// The name of the unit surface normal at the hit that a colour field's body may read beside
/// its point `p` (docs/language.md, "Colour fields"); a name of the program hides it.
pub const NORMAL: &str = "n";

/// The built-in constants, read like `t`: a constant, parameter or loop variable of the
/// same name hides them.
pub const CONSTANTS: &[(&str, f64)] =
    &[("pi", std::f64::consts::PI), ("tau", std::f64::consts::TAU)];

/// The value of the built-in constant `name`, if it is one.
pub fn constant(name: &str) -> Option<f64> {
    CONSTANTS.iter().find(|(n, _)| *n == name).map(|(_, v)| *v)
}

/// Every builtin function: those written here and the primitives of the table (`prim/`).
pub static BUILTINS: std::sync::LazyLock<Vec<Builtin>> = std::sync::LazyLock::new(|| {
    let prims = crate::prim::all().map(|prim| {
        let params: Vec<P> = prim
            .params
            .iter()
            .map(|q| p(q.name, kind_type(q.kind), q.def, q.range))
            .collect();
        let sig = Sig {
            params: Vec::leak(params),
            rest: false,
            ret: if prim.profile {
                Type::Profile
            } else {
                Type::Shape
            },
            imp: Imp::Prim(prim),
        };
        Builtin {
            name: prim.name,
            sigs: Vec::leak(vec![sig]),
        }
    });
    // An entry named like a builtin before it is one more overload of that builtin.
    let mut all: Vec<Builtin> = FUNCTIONS.to_vec();
    for prim in prims {
        match all.iter_mut().find(|b| b.name == prim.name) {
            Some(b) => b.sigs = Vec::leak([b.sigs, prim.sigs].concat()),
            None => all.push(prim),
        }
    }
    all
});

/// The type of a primitive's parameter.
fn kind_type(k: Kind) -> Type {
    match k {
        Kind::Float => Type::Float,
        Kind::Int => Type::Int,
        Kind::Angle => Type::Angle,
        Kind::Vec2 => Type::Vec2,
        Kind::Vec3 => Type::Vec3,
        Kind::Points => Type::List(&Type::Vec3),
    }
}

/// The builtin functions written here.
static FUNCTIONS: &[Builtin] = &[
    // Primitives.
    Builtin {
        name: "sphere",
        sigs: sigs![
            [p("radius", F, Num(1.0), Pos)] -> S => |b, a| b.node(Node::Sphere { radius: a[0].num() });
        ],
    },
    Builtin {
        name: "box",
        sigs: sigs![
            [p("half", V, Req, Pos)] -> S => |b, a| b.node(Node::Box { half: a[0].v3() });
            [p("half", F, Num(0.5), Pos)] -> S => |b, a| { let h = a[0].num(); b.node(Node::Box { half: [h; 3] }) };
        ],
    },
    Builtin {
        name: "round_box",
        sigs: sigs![
            [p("half", V, Req, Pos), p("radius", F, Num(0.05), NonNeg)] -> S => |b, a| {
                let (half, radius) = (a[0].v3(), a[1].num());
                if half.iter().any(|&h| h < radius) {
                    return Err(Refusal::BoxRounding { radius });
                }
                b.node(Node::RoundBox { half, radius })
            };
        ],
    },
    Builtin {
        name: "plane",
        sigs: sigs![
            [p("normal", V, V3([0.0, 1.0, 0.0]), NonZero), p("height", F, Num(0.0), Any)] -> S => |b, a| {
                let n = a[0].v3();
                let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                b.node(Node::Plane { normal: [n[0] / len, n[1] / len, n[2] / len], height: a[1].num() })
            };
        ],
    },
    Builtin {
        name: "torus",
        sigs: sigs![
            [p("major", F, Num(1.0), Pos), p("minor", F, Num(0.25), Pos)] -> S => |b, a| {
                b.node(Node::Torus { major: a[0].num(), minor: a[1].num() })
            };
        ],
    },
    Builtin {
        name: "cylinder",
        sigs: sigs![
            [p("radius", F, Num(0.5), Pos), p("height", F, Num(1.0), Pos)] -> S => |b, a| {
                b.node(Node::Cylinder { radius: a[0].num(), half_height: a[1].num() / 2.0 })
            };
        ],
    },
    Builtin {
        name: "capsule",
        sigs: sigs![
            [p("radius", F, Num(0.25), Pos), p("height", F, Num(1.0), NonNeg)] -> S => |b, a| {
                b.node(Node::Capsule { radius: a[0].num(), half_height: a[1].num() / 2.0 })
            };
        ],
    },
    Builtin {
        name: "cone",
        sigs: sigs![
            [p("radius", F, Num(0.5), Pos), p("height", F, Num(1.0), Pos)] -> S => |b, a| {
                b.node(Node::Cone { radius: a[0].num(), half_height: a[1].num() / 2.0 })
            };
        ],
    },
    Builtin {
        name: "ellipsoid",
        sigs: sigs![
            [p("radii", V, Req, Pos)] -> S => |b, a| b.node(Node::Ellipsoid { radii: a[0].v3() });
        ],
    },
    Builtin {
        name: "mesh",
        sigs: sigs![
            [p("path", Str, Req, Any), p("scale", F, Num(1.0), Pos)] -> S => |b, a| {
                let Value::Str(path) = &a[0] else {
                    return Ok(Value::Error);
                };
                b.mesh(path, a[1].num())
            };
        ],
    },
    // Profiles (2D, in the xy plane).
    Builtin {
        name: "rect",
        sigs: sigs![
            [p("half", V2, Req, Pos)] -> PR => |b, a| {
                let c = a[0].components();
                b.profile(Node::Rect { half: [c[0], c[1]] })
            };
            [p("half", F, Num(0.5), Pos)] -> PR => |b, a| b.profile(Node::Rect { half: [a[0].num(); 2] });
        ],
    },
    Builtin {
        name: "polygon",
        sigs: sigs![
            [p("points", Type::List(&V2), Req, Any)] -> PR => polygon;
        ],
    },
    Builtin {
        name: "text",
        sigs: sigs![
            [p("string", Str, Req, Chars(Limit::TextChars)), p("size", F, Num(1.0), Pos), p("font", Str, Text(""), Any)] -> PR => text;
        ],
    },
    Builtin {
        name: "text_size",
        sigs: sigs![
            [p("string", Str, Req, Chars(Limit::TextChars)), p("size", F, Num(1.0), Pos), p("font", Str, Text(""), Any)] -> V2 => text_size;
        ],
    },
    Builtin {
        name: "regular_polygon",
        sigs: sigs![
            [p("sides", I, Req, Within(3.0, 1e4)), p("radius", F, Num(0.5), Pos)] -> PR => |b, a| {
                polygon_of(b, regular(a[0].num() as usize, a[1].num(), 0.0))
            };
        ],
    },
    Builtin {
        name: "star",
        sigs: sigs![
            [p("points", I, Req, Within(2.0, 1e4)), p("outer", F, Num(0.5), Pos), p("inner", F, Num(0.25), Pos)] -> PR => |b, a| {
                let (n, outer, inner) = (a[0].num() as usize, a[1].num(), a[2].num());
                let tips = regular(n, outer, 0.0);
                let dents = regular(n, inner, std::f64::consts::PI / n as f64);
                let points = tips.into_iter().zip(dents).flat_map(|(t, d)| [t, d]).collect();
                polygon_of(b, points)
            };
        ],
    },
    Builtin {
        name: "ring",
        sigs: sigs![
            [p("radius", F, Num(0.5), Pos), p("thickness", F, Num(0.1), Pos)] -> PR => |b, a| {
                let circle = Node::prim("circle", &[&[a[0].num()]]).ok_or(Refusal::NoPrimitive { name: "circle" })?;
                let circle = b.graph.add(circle, b.span);
                b.profile(Node::Shell { half: a[1].num() / 2.0, child: circle })
            };
        ],
    },
    Builtin {
        name: "segment2",
        sigs: sigs![
            [p("a", V2, Req, Any), p("b", V2, Req, Any), p("radius", F, Num(0.1), Pos)] -> PR => |b, a| {
                let (x, y) = (a[0].components(), a[1].components());
                // The capsule of space about the segment, read in its plane z = 0.
                let segment = Node::prim("segment", &[&[x[0], x[1], 0.0], &[y[0], y[1], 0.0], &[a[2].num()]]);
                b.profile(segment.ok_or(Refusal::NoPrimitive { name: "segment" })?)
            };
        ],
    },
    Builtin {
        name: "extrude",
        sigs: sigs![
            [prof("profile"), p("height", F, Req, Pos), p("round", F, Num(0.0), NonNeg)] -> S => |b, a| {
                let (height, round) = (a[1].num(), a[2].num());
                if 2.0 * round > height {
                    return Err(Refusal::ExtrudeRounding { round, height });
                }
                b.node(Node::Extrude { half_height: height / 2.0, round, child: sh(&a[0]) })
            };
        ],
    },
    Builtin {
        name: "revolve",
        sigs: sigs![
            [prof("profile"), p("offset", F, Num(0.0), Any)] -> S => |b, a| {
                b.node(Node::Revolve { offset: a[1].num(), child: sh(&a[0]) })
            };
        ],
    },
    Builtin {
        name: "bezier",
        sigs: sigs![
            [p("a", V2, Req, Any), p("control", V2, Req, Any), p("b", V2, Req, Any), p("radius", F, Num(0.05), Pos)] -> PR => bezier;
            [p("points", Type::List(&V), Req, Any)] -> Type::Path => |_, a| {
                Ok(Value::Path(std::sync::Arc::new(Path::bezier(&points3(&a[0]))?)))
            };
        ],
    },
    Builtin {
        name: "sweep",
        sigs: sigs![
            [prof("profile"), p("path", Type::Path, Req, Any)] -> S => sweep;
        ],
    },
    Builtin {
        name: "polyline",
        sigs: sigs![
            [p("points", Type::List(&V), Req, Any)] -> Type::Path => |_, a| {
                Ok(Value::Path(std::sync::Arc::new(Path::polyline(&points3(&a[0]))?)))
            };
        ],
    },
    Builtin {
        name: "helix",
        sigs: sigs![
            [p("radius", F, Req, Pos), p("pitch", F, Req, Pos), p("turns", F, Req, Pos)] -> Type::Path => |_, a| {
                Ok(Value::Path(std::sync::Arc::new(Path::helix(a[0].num(), a[1].num(), a[2].num()))))
            };
        ],
    },
    Builtin {
        name: "arc3",
        sigs: sigs![
            [p("start", V, Req, Any), p("through", V, Req, Any), p("end", V, Req, Any)] -> Type::Path => |_, a| {
                let [x, y, z] = [0, 1, 2].map(|i| {
                    let c = a[i].components();
                    [c[0], c[1], c[2]]
                });
                Ok(Value::Path(std::sync::Arc::new(Path::arc3(x, y, z)?)))
            };
        ],
    },
    Builtin {
        name: "loft",
        sigs: sigs![
            [prof("bottom"), prof("top"), p("height", F, Req, Pos)] -> S => loft;
        ],
    },
    Builtin {
        name: "screw",
        sigs: sigs![
            [prof("profile"), p("pitch", F, Req, Pos), p("height", F, Req, Pos), p("hand", Str, Text("right"), OneOf(HANDS))] -> S => screw;
        ],
    },
    Builtin {
        name: "offset",
        sigs: sigs![
            [prof("profile"), p("amount", F, Req, Any)] -> PR => |b, a| b.profile(Node::Round { radius: a[1].num(), child: sh(&a[0]) });
        ],
    },
    // Combinators.
    Builtin {
        name: "union",
        sigs: sigs![
            [shape("a"), shape("b")] rest + -> S => |b, a| combine(b, a, Combine::Union);
            [p("shapes", LS, Req, Any)] -> S => |b, a| combine_list(b, a, Combine::Union, "union");
            [prof("a"), prof("b")] rest + -> PR => |b, a| flat(combine(b, a, Combine::Union));
            [p("profiles", LP, Req, Any)] -> PR => |b, a| flat(combine_list(b, a, Combine::Union, "union"));
        ],
    },
    Builtin {
        name: "intersect",
        sigs: sigs![
            [shape("a"), shape("b")] rest + -> S => |b, a| combine(b, a, Combine::Intersect);
            [p("shapes", LS, Req, Any)] -> S => |b, a| combine_list(b, a, Combine::Intersect, "intersect");
            [prof("a"), prof("b")] rest + -> PR => |b, a| flat(combine(b, a, Combine::Intersect));
            [p("profiles", LP, Req, Any)] -> PR => |b, a| flat(combine_list(b, a, Combine::Intersect, "intersect"));
        ],
    },
    Builtin {
        name: "subtract",
        sigs: sigs![
            [shape("a"), shape("b")] -> S => |b, a| combine(b, a, Combine::Subtract);
            [prof("a"), prof("b")] -> PR => |b, a| flat(combine(b, a, Combine::Subtract));
        ],
    },
    Builtin {
        name: "smooth_union",
        sigs: sigs![
            [p("k", F, Req, NonNeg), shape("a"), shape("b"), p("variant", Str, Text("poly"), OneOf(SMOOTH_VARIANTS)), p("steps", I, Int(4), Within(1.0, 64.0))] -> S
                => |b, a| smooth(b, a, Combine::Union);
            [p("k", F, Req, NonNeg), prof("a"), prof("b"), p("variant", Str, Text("poly"), OneOf(SMOOTH_VARIANTS)), p("steps", I, Int(4), Within(1.0, 64.0))] -> PR
                => |b, a| flat(smooth(b, a, Combine::Union));
            [p("k", F, Req, NonNeg), p("profiles", LP, Req, Any), p("variant", Str, Text("poly"), OneOf(SMOOTH_VARIANTS)), p("steps", I, Int(4), Within(1.0, 64.0))] -> PR
                => |b, a| flat(smooth_list(b, a, Combine::Union, "smooth_union"));
            [p("k", F, Req, NonNeg), p("shapes", LS, Req, Any), p("variant", Str, Text("poly"), OneOf(SMOOTH_VARIANTS)), p("steps", I, Int(4), Within(1.0, 64.0))] -> S
                => |b, a| smooth_list(b, a, Combine::Union, "smooth_union");
        ],
    },
    Builtin {
        name: "smooth_intersect",
        sigs: sigs![
            [p("k", F, Req, NonNeg), shape("a"), shape("b"), p("variant", Str, Text("poly"), OneOf(SMOOTH_VARIANTS)), p("steps", I, Int(4), Within(1.0, 64.0))] -> S
                => |b, a| smooth(b, a, Combine::Intersect);
            [p("k", F, Req, NonNeg), prof("a"), prof("b"), p("variant", Str, Text("poly"), OneOf(SMOOTH_VARIANTS)), p("steps", I, Int(4), Within(1.0, 64.0))] -> PR
                => |b, a| flat(smooth(b, a, Combine::Intersect));
            [p("k", F, Req, NonNeg), p("profiles", LP, Req, Any), p("variant", Str, Text("poly"), OneOf(SMOOTH_VARIANTS)), p("steps", I, Int(4), Within(1.0, 64.0))] -> PR
                => |b, a| flat(smooth_list(b, a, Combine::Intersect, "smooth_intersect"));
            [p("k", F, Req, NonNeg), p("shapes", LS, Req, Any), p("variant", Str, Text("poly"), OneOf(SMOOTH_VARIANTS)), p("steps", I, Int(4), Within(1.0, 64.0))] -> S
                => |b, a| smooth_list(b, a, Combine::Intersect, "smooth_intersect");
        ],
    },
    Builtin {
        name: "smooth_subtract",
        sigs: sigs![
            [p("k", F, Req, NonNeg), shape("a"), shape("b"), p("variant", Str, Text("poly"), OneOf(SMOOTH_VARIANTS)), p("steps", I, Int(4), Within(1.0, 64.0))] -> S
                => |b, a| smooth(b, a, Combine::Subtract);
            [p("k", F, Req, NonNeg), prof("a"), prof("b"), p("variant", Str, Text("poly"), OneOf(SMOOTH_VARIANTS)), p("steps", I, Int(4), Within(1.0, 64.0))] -> PR
                => |b, a| flat(smooth(b, a, Combine::Subtract));
        ],
    },
    Builtin {
        name: "engrave",
        sigs: sigs![
            [shape("a"), shape("b"), p("depth", F, Req, Pos)] -> S
                => |b, a| feature(b, a, Feature::Engrave { depth: a[2].num() });
        ],
    },
    Builtin {
        name: "groove",
        sigs: sigs![
            [shape("a"), shape("b"), p("width", F, Req, Pos), p("depth", F, Req, Pos)] -> S
                => |b, a| feature(b, a, Feature::Groove { width: a[2].num(), depth: a[3].num() });
        ],
    },
    Builtin {
        name: "tongue",
        sigs: sigs![
            [shape("a"), shape("b"), p("width", F, Req, Pos), p("height", F, Req, Pos)] -> S
                => |b, a| feature(b, a, Feature::Tongue { width: a[2].num(), height: a[3].num() });
        ],
    },
    Builtin {
        name: "pipe",
        sigs: sigs![
            [shape("a"), shape("b"), p("radius", F, Req, Pos)] -> S
                => |b, a| feature(b, a, Feature::Pipe { radius: a[2].num() });
        ],
    },
    // Transforms.
    Builtin {
        name: "translate",
        sigs: sigs![
            [shape("shape"), p("offset", V, Req, Any)] -> S => |b, a| b.node(Node::Translate { offset: a[1].v3(), child: sh(&a[0]) });
            [shape("shape"), p("x", F, Req, Any), p("y", F, Num(0.0), Any), p("z", F, Num(0.0), Any)] -> S => |b, a| {
                b.node(Node::Translate { offset: [a[1].num(), a[2].num(), a[3].num()], child: sh(&a[0]) })
            };
            [prof("profile"), p("offset", V2, Req, Any)] -> PR => |b, a| {
                let c = a[1].components();
                b.profile(Node::Translate { offset: [c[0], c[1], 0.0], child: sh(&a[0]) })
            };
            [prof("profile"), p("x", F, Req, Any), p("y", F, Num(0.0), Any)] -> PR => |b, a| {
                b.profile(Node::Translate { offset: [a[1].num(), a[2].num(), 0.0], child: sh(&a[0]) })
            };
        ],
    },
    Builtin {
        name: "rotate_x",
        sigs: sigs![
            [shape("shape"), p("angle", A, Req, Any)] -> S => |b, a| rotate(b, &a[0], [1.0, 0.0, 0.0], a[1].num());
        ],
    },
    Builtin {
        name: "rotate_y",
        sigs: sigs![
            [shape("shape"), p("angle", A, Req, Any)] -> S => |b, a| rotate(b, &a[0], [0.0, 1.0, 0.0], a[1].num());
        ],
    },
    Builtin {
        name: "rotate_z",
        sigs: sigs![
            [shape("shape"), p("angle", A, Req, Any)] -> S => |b, a| rotate(b, &a[0], [0.0, 0.0, 1.0], a[1].num());
        ],
    },
    Builtin {
        name: "rotate",
        sigs: sigs![
            [shape("shape"), p("axis", V, Req, NonZero), p("angle", A, Req, Any)] -> S => |b, a| rotate(b, &a[0], a[1].v3(), a[2].num());
            [prof("profile"), p("angle", A, Req, Any)] -> PR => |b, a| flat(rotate(b, &a[0], [0.0, 0.0, 1.0], a[1].num()));
        ],
    },
    Builtin {
        name: "scale",
        sigs: sigs![
            [shape("shape"), p("factor", F, Req, Pos)] -> S => |b, a| b.node(Node::Scale { factor: a[1].num(), child: sh(&a[0]) });
            [prof("profile"), p("factor", F, Req, Pos)] -> PR => |b, a| b.profile(Node::Scale { factor: a[1].num(), child: sh(&a[0]) });
            [shape("shape"), p("factors", V, Req, Pos)] -> S => |b, a| b.node(Node::ScaleXyz { factors: a[1].v3(), child: sh(&a[0]) });
        ],
    },
    // Domain and shape operations.
    Builtin {
        name: "repeat",
        sigs: sigs![
            [shape("shape"), p("period", V, Req, NonNeg)] -> S => |b, a| {
                b.node(Node::Repeat { period: a[1].v3(), count: None, child: sh(&a[0]) })
            };
            [shape("shape"), p("period", V, Req, NonNeg), p("count", V, Req, Within(1.0, 1e6))] -> S => |b, a| {
                let count = a[2].v3();
                if count.iter().any(|c| c.fract() != 0.0) {
                    return Err(Refusal::FractionalCount);
                }
                b.node(Node::Repeat { period: a[1].v3(), count: Some(count), child: sh(&a[0]) })
            };
        ],
    },
    Builtin {
        name: "mirror",
        sigs: sigs![
            [shape("shape"), p("x", B, Bool(true), Any), p("y", B, Bool(false), Any), p("z", B, Bool(false), Any)] -> S => |b, a| {
                let axes = [a[1] == Value::Bool(true), a[2] == Value::Bool(true), a[3] == Value::Bool(true)];
                b.node(Node::Mirror { axes, child: sh(&a[0]) })
            };
            [prof("profile"), p("x", B, Bool(true), Any), p("y", B, Bool(false), Any)] -> PR => |b, a| {
                let axes = [a[1] == Value::Bool(true), a[2] == Value::Bool(true), false];
                b.profile(Node::Mirror { axes, child: sh(&a[0]) })
            };
        ],
    },
    Builtin {
        name: "reflect",
        sigs: sigs![
            [shape("shape"), p("normal", V, Req, NonZero)] -> S => |b, a| {
                b.node(Node::Rotate { matrix: householder(a[1].v3()), child: sh(&a[0]) })
            };
            [prof("profile"), p("normal", V2, Req, NonZero)] -> PR => |b, a| {
                let n = a[1].components();
                flat(b.node(Node::Rotate { matrix: householder([n[0], n[1], 0.0]), child: sh(&a[0]) }))
            };
        ],
    },
    Builtin {
        name: "twist",
        sigs: sigs![
            [shape("shape"), p("rate", F, Req, Any)] -> S => |b, a| b.node(Node::Twist { rate: a[1].num(), child: sh(&a[0]) });
        ],
    },
    Builtin {
        name: "bend",
        sigs: sigs![
            [shape("shape"), p("rate", F, Req, Any)] -> S => |b, a| b.node(Node::Bend { rate: a[1].num(), child: sh(&a[0]) });
        ],
    },
    Builtin {
        name: "repeat_polar",
        sigs: sigs![
            [shape("shape"), p("count", I, Req, Within(1.0, 1e6)), p("axis", V, V3([0.0, 1.0, 0.0]), NonZero), p("mirror", B, Bool(false), Any)] -> S
                => repeat_polar;
            [prof("profile"), p("count", I, Req, Within(1.0, 1e6)), p("mirror", B, Bool(false), Any)] -> PR => |b, a| {
                // About the origin of the plane: the z axis of the profile's prism.
                flat(repeat_polar(b, &[a[0].clone(), a[1].clone(), Value::Vec3([0.0, 0.0, 1.0]), a[2].clone()]))
            };
        ],
    },
    Builtin {
        name: "wrap",
        sigs: sigs![
            [shape("shape"), p("radius", F, Req, Pos)] -> S => |b, a| b.node(Node::Wrap { radius: a[1].num(), child: sh(&a[0]) });
        ],
    },
    Builtin {
        name: "shear",
        sigs: sigs![
            [shape("shape"), p("xy", F, Num(0.0), Any), p("xz", F, Num(0.0), Any), p("yx", F, Num(0.0), Any), p("yz", F, Num(0.0), Any), p("zx", F, Num(0.0), Any), p("zy", F, Num(0.0), Any)] -> S => |b, a| {
                let k = |i: usize| a[i].num();
                let matrix = [[1.0, k(1), k(2)], [k(3), 1.0, k(4)], [k(5), k(6), 1.0]];
                if crate::scene::analysis::invert(&matrix).is_none() {
                    return Err(Refusal::SingularShear);
                }
                b.node(Node::Shear { matrix, child: sh(&a[0]) })
            };
        ],
    },
    Builtin {
        name: "taper",
        sigs: sigs![
            [shape("shape"), p("rate", F, Req, Any)] -> S => |b, a| b.node(Node::Taper { rate: a[1].num(), child: sh(&a[0]) });
        ],
    },
    Builtin {
        name: "morph",
        sigs: sigs![
            [shape("a"), shape("b"), p("t", F, Req, Unit)] -> S => |b, a| b.node(Node::Morph { t: a[2].num(), a: sh(&a[0]), b: sh(&a[1]) });
        ],
    },
    Builtin {
        name: "round",
        sigs: sigs![
            [shape("shape"), p("radius", F, Req, NonNeg)] -> S => |b, a| b.node(Node::Round { radius: a[1].num(), child: sh(&a[0]) });
        ],
    },
    // The hull of balls or of parallel cylinders (`hull.rs`); of points, an entry of the table.
    Builtin {
        name: "hull",
        sigs: sigs![
            [shape("shapes")] rest + -> S => hull;
            [p("shapes", LS, Req, Any)] -> S => |b, a| hull(b, &shapes(&a[0], "hull")?);
        ],
    },
    // OpenSCAD's `minkowski` with a ball is a rounding: the distance less the radius.
    Builtin {
        name: "minkowski",
        sigs: sigs![
            [shape("shape"), shape("ball")] -> S => |b, a| match *b.graph.node(sh(&a[1])) {
                Node::Sphere { radius } => b.node(Node::Round { radius, child: sh(&a[0]) }),
                _ => Err(Refusal::MinkowskiNotBall),
            };
        ],
    },
    Builtin {
        name: "shell",
        sigs: sigs![
            [shape("shape"), p("thickness", F, Req, Pos)] -> S => |b, a| b.node(Node::Shell { half: a[1].num() / 2.0, child: sh(&a[0]) });
        ],
    },
    Builtin {
        name: "elongate",
        sigs: sigs![
            [shape("shape"), p("half", V, Req, NonNeg)] -> S => |b, a| b.node(Node::Elongate { half: a[1].v3(), child: sh(&a[0]) });
        ],
    },
    // Lists.
    Builtin {
        name: "len",
        sigs: sigs![
            [p("xs", LS, Req, Any)] -> I => |_, a| len(a);
            [p("xs", LP, Req, Any)] -> I => |_, a| len(a);
            [p("xs", Type::List(&F), Req, Any)] -> I => |_, a| len(a);
            [p("xs", Type::List(&V), Req, Any)] -> I => |_, a| len(a);
            [p("xs", Type::List(&V2), Req, Any)] -> I => |_, a| len(a);
            [p("xs", Type::List(&A), Req, Any)] -> I => |_, a| len(a);
            [p("xs", Type::List(&B), Req, Any)] -> I => |_, a| len(a);
            [p("xs", Type::List(&Str), Req, Any)] -> I => |_, a| len(a);
            [p("xs", Type::List(&Type::Path), Req, Any)] -> I => |_, a| len(a);
        ],
    },
    // Vectors.
    Builtin {
        name: "vec2",
        sigs: sigs![
            [p("x", F, Req, Any), p("y", F, Req, Any)] -> V2 => |_, a| Ok(Value::Vec2([a[0].num(), a[1].num()]));
        ],
    },
    Builtin {
        name: "vec3",
        sigs: sigs![
            [p("x", F, Req, Any), p("y", F, Req, Any), p("z", F, Req, Any)] -> V => |_, a| Ok(Value::Vec3([a[0].num(), a[1].num(), a[2].num()]));
            [p("all", F, Req, Any)] -> V => |_, a| Ok(Value::Vec3([a[0].num(); 3]));
        ],
    },
    Builtin {
        name: "length",
        sigs: sigs![
            [p("v", V, Req, Any)] -> F => |_, a| { let v = a[0].v3(); Ok(Value::Float((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt())) };
            [p("v", V2, Req, Any)] -> F => |_, a| { let c = a[0].components(); Ok(Value::Float(c[0].hypot(c[1]))) };
        ],
    },
    Builtin {
        name: "normalize",
        sigs: sigs![
            [p("v", V, Req, NonZero)] -> V => |_, a| {
                let v = a[0].v3();
                let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                Ok(Value::Vec3([v[0] / l, v[1] / l, v[2] / l]))
            };
        ],
    },
    Builtin {
        name: "dot",
        sigs: sigs![
            [p("a", V, Req, Any), p("b", V, Req, Any)] -> F => |_, a| {
                let (x, y) = (a[0].v3(), a[1].v3());
                Ok(Value::Float(x[0] * y[0] + x[1] * y[1] + x[2] * y[2]))
            };
        ],
    },
    Builtin {
        name: "cross",
        sigs: sigs![
            [p("a", V, Req, Any), p("b", V, Req, Any)] -> V => |_, a| {
                let (x, y) = (a[0].v3(), a[1].v3());
                Ok(Value::Vec3([x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]]))
            };
        ],
    },
    Builtin {
        name: "mix",
        sigs: sigs![
            [p("a", F, Req, Any), p("b", F, Req, Any), p("t", F, Req, Any)] -> F => |_, a| {
                Ok(Value::Float(a[0].num() + (a[1].num() - a[0].num()) * a[2].num()))
            };
            [p("a", V, Req, Any), p("b", V, Req, Any), p("t", F, Req, Any)] -> V => |_, a| {
                let (x, y, t) = (a[0].v3(), a[1].v3(), a[2].num());
                Ok(Value::Vec3([x[0] + (y[0] - x[0]) * t, x[1] + (y[1] - x[1]) * t, x[2] + (y[2] - x[2]) * t]))
            };
        ],
    },
    // Scalar maths.
    Builtin {
        name: "sin",
        sigs: sigs![
            [p("x", A, Req, Any)] -> F => |_, a| f1(a, f64::sin);
            [p("x", F, Req, Any)] -> F => |_, a| f1(a, f64::sin);
        ],
    },
    Builtin {
        name: "cos",
        sigs: sigs![
            [p("x", A, Req, Any)] -> F => |_, a| f1(a, f64::cos);
            [p("x", F, Req, Any)] -> F => |_, a| f1(a, f64::cos);
        ],
    },
    Builtin {
        name: "tan",
        sigs: sigs![
            [p("x", A, Req, Any)] -> F => |_, a| f1(a, f64::tan);
            [p("x", F, Req, Any)] -> F => |_, a| f1(a, f64::tan);
        ],
    },
    Builtin {
        name: "asin",
        sigs: sigs![
            [p("x", F, Req, Within(-1.0, 1.0))] -> A => |_, a| Ok(Value::Angle(a[0].num().asin()));
        ],
    },
    Builtin {
        name: "acos",
        sigs: sigs![
            [p("x", F, Req, Within(-1.0, 1.0))] -> A => |_, a| Ok(Value::Angle(a[0].num().acos()));
        ],
    },
    Builtin {
        name: "atan",
        sigs: sigs![
            [p("x", F, Req, Any)] -> A => |_, a| Ok(Value::Angle(a[0].num().atan()));
        ],
    },
    Builtin {
        name: "atan2",
        sigs: sigs![
            [p("y", F, Req, Any), p("x", F, Req, Any)] -> A => |_, a| Ok(Value::Angle(a[0].num().atan2(a[1].num())));
        ],
    },
    Builtin {
        name: "sqrt",
        sigs: sigs![
            [p("x", F, Req, NonNeg)] -> F => |_, a| f1(a, f64::sqrt);
        ],
    },
    Builtin {
        name: "exp",
        sigs: sigs![
            [p("x", F, Req, Any)] -> F => |_, a| f1(a, f64::exp);
        ],
    },
    Builtin {
        name: "log",
        sigs: sigs![
            [p("x", F, Req, Pos)] -> F => |_, a| f1(a, f64::ln);
        ],
    },
    Builtin {
        name: "pow",
        sigs: sigs![
            [p("base", F, Req, Any), p("exponent", F, Req, Any)] -> F => |_, a| Ok(Value::Float(a[0].num().powf(a[1].num())));
        ],
    },
    Builtin {
        name: "abs",
        sigs: sigs![
            [p("x", I, Req, Any)] -> I => |_, a| match &a[0] { Value::Int(i) => i.checked_abs().map(Value::Int).ok_or(Refusal::AbsOverflow), _ => Ok(Value::Error) };
            [p("x", F, Req, Any)] -> F => |_, a| f1(a, f64::abs);
            [p("x", V2, Req, Any)] -> V2 => |_, a| Ok(vmap(&a[0], f64::abs));
            [p("x", V, Req, Any)] -> V => |_, a| Ok(vmap(&a[0], f64::abs));
        ],
    },
    Builtin {
        name: "floor",
        sigs: sigs![
            [p("x", F, Req, Any)] -> F => |_, a| f1(a, f64::floor);
            [p("x", V2, Req, Any)] -> V2 => |_, a| Ok(vmap(&a[0], f64::floor));
            [p("x", V, Req, Any)] -> V => |_, a| Ok(vmap(&a[0], f64::floor));
        ],
    },
    Builtin {
        name: "ceil",
        sigs: sigs![
            [p("x", F, Req, Any)] -> F => |_, a| f1(a, f64::ceil);
            [p("x", V2, Req, Any)] -> V2 => |_, a| Ok(vmap(&a[0], f64::ceil));
            [p("x", V, Req, Any)] -> V => |_, a| Ok(vmap(&a[0], f64::ceil));
        ],
    },
    Builtin {
        name: "fract",
        sigs: sigs![
            [p("x", F, Req, Any)] -> F => |_, a| f1(a, |x| x - x.floor());
            [p("x", V2, Req, Any)] -> V2 => |_, a| Ok(vmap(&a[0], |x| x - x.floor()));
            [p("x", V, Req, Any)] -> V => |_, a| Ok(vmap(&a[0], |x| x - x.floor()));
        ],
    },
    Builtin {
        name: "mod",
        sigs: sigs![
            [p("a", F, Req, Any), p("b", F, Req, Any)] -> F => |_, a| {
                let (x, y) = (a[0].num(), a[1].num());
                Ok(Value::Float(x - y * (x / y).floor()))
            };
            [p("a", V, Req, Any), p("b", F, Req, Any)] -> V => |_, a| {
                let y = a[1].num();
                Ok(vmap(&a[0], |x| x - y * (x / y).floor()))
            };
        ],
    },
    Builtin {
        name: "smoothstep",
        sigs: sigs![
            [p("edge0", F, Req, Any), p("edge1", F, Req, Any), p("x", F, Req, Any)] -> F => |_, a| {
                let t = ((a[2].num() - a[0].num()) / (a[1].num() - a[0].num())).clamp(0.0, 1.0);
                Ok(Value::Float(t * t * (3.0 - 2.0 * t)))
            };
        ],
    },
    // Per point (inside `field { … }`): with constant arguments they are errors.
    Builtin {
        name: "distance",
        sigs: sigs![
            [shape("shape"), p("at", V, Req, Any)] -> F => |_, _| Err(Refusal::PerPoint);
            [prof("profile"), p("at", V2, Req, Any)] -> F => |_, _| Err(Refusal::PerPoint);
        ],
    },
    Builtin {
        name: "noise",
        sigs: sigs![
            [p("at", V, Req, Any)] -> F => |_, _| Err(Refusal::PerPoint);
            [p("at", V2, Req, Any)] -> F => |_, _| Err(Refusal::PerPoint);
        ],
    },
    Builtin {
        name: "fbm",
        sigs: sigs![
            [p("at", V, Req, Any), p("octaves", I, Int(4), Within(1.0, 12.0)), p("lacunarity", F, Num(2.0), Within(1.0, 8.0)), p("gain", F, Num(0.5), Within(0.0, 1.0))] -> F
                => |_, _| Err(Refusal::PerPoint);
            [p("at", V2, Req, Any), p("octaves", I, Int(4), Within(1.0, 12.0)), p("lacunarity", F, Num(2.0), Within(1.0, 8.0)), p("gain", F, Num(0.5), Within(0.0, 1.0))] -> F
                => |_, _| Err(Refusal::PerPoint);
        ],
    },
    Builtin {
        name: "voronoi",
        sigs: sigs![
            [p("at", V, Req, Any)] -> F => |_, _| Err(Refusal::PerPoint);
            [p("at", V2, Req, Any)] -> F => |_, _| Err(Refusal::PerPoint);
        ],
    },
    Builtin {
        name: "min",
        sigs: sigs![
            [p("a", I, Req, Any), p("b", I, Req, Any)] -> I => |_, a| Ok(Value::Int(a[0].num().min(a[1].num()) as i64));
            [p("a", F, Req, Any), p("b", F, Req, Any)] -> F => |_, a| Ok(Value::Float(a[0].num().min(a[1].num())));
        ],
    },
    Builtin {
        name: "max",
        sigs: sigs![
            [p("a", I, Req, Any), p("b", I, Req, Any)] -> I => |_, a| Ok(Value::Int(a[0].num().max(a[1].num()) as i64));
            [p("a", F, Req, Any), p("b", F, Req, Any)] -> F => |_, a| Ok(Value::Float(a[0].num().max(a[1].num())));
        ],
    },
    Builtin {
        name: "clamp",
        sigs: sigs![
            [p("x", F, Req, Any), p("lo", F, Req, Any), p("hi", F, Req, Any)] -> F => |_, a| {
                let (x, lo, hi) = (a[0].num(), a[1].num(), a[2].num());
                if lo > hi {
                    return Err(Refusal::ClampOrder { lo, hi });
                }
                Ok(Value::Float(x.clamp(lo, hi)))
            };
        ],
    },
    // No `radians`: GLSL's turns degrees into radians, the opposite of "x radians", so the
    // name is refused with the spelling that works (`suggest::ported`).
    Builtin {
        name: "degrees",
        sigs: sigs![
            [p("x", F, Req, Any)] -> A => |_, a| Ok(Value::Angle(a[0].num().to_radians()));
            [p("x", A, Req, Any)] -> F => |_, a| Ok(Value::Float(a[0].num().to_degrees()));
        ],
    },
    Builtin {
        name: "hash",
        sigs: sigs![
            [p("seed", I, Req, Any)] -> F => |_, a| match &a[0] { Value::Int(i) => Ok(Value::Float(hash(*i))), _ => Ok(Value::Error) };
            [p("cell", F, Req, Any)] -> F => |_, a| Ok(Value::Float(hash_of(&[a[0].num()])));
            [p("cell", V2, Req, Any)] -> F => |_, a| match &a[0] { Value::Vec2(v) => Ok(Value::Float(hash_of(v))), _ => Ok(Value::Error) };
            [p("cell", V, Req, Any)] -> F => |_, a| match &a[0] { Value::Vec3(v) => Ok(Value::Float(hash_of(v))), _ => Ok(Value::Error) };
        ],
    },
    Builtin {
        name: "float",
        sigs: sigs![
            [p("x", F, Req, Any)] -> F => |_, a| Ok(Value::Float(a[0].num()));
            [p("x", A, Req, Any)] -> F => |_, a| Ok(Value::Float(a[0].num()));
        ],
    },
    Builtin {
        name: "int",
        sigs: sigs![
            [p("x", F, Req, Within(-9.0e15, 9.0e15))] -> I => |_, a| Ok(Value::Int(a[0].num().floor() as i64));
        ],
    },
    Builtin {
        name: "div",
        sigs: sigs![
            [p("a", I, Req, Any), p("b", I, Req, Any)] -> I => |_, a| match (&a[0], &a[1]) {
                (Value::Int(_), Value::Int(0)) => Err(Refusal::DivisionByZero),
                (Value::Int(x), Value::Int(y)) => floor_div(*x, *y)
                    .map(Value::Int)
                    .ok_or(Refusal::DivOverflow { a: *x, b: *y }),
                _ => Ok(Value::Error),
            };
        ],
    },
];

/// `a / b` rounded down (towards −∞, as Python's `//`), or `None` on overflow; `b` ≠ 0.
fn floor_div(a: i64, b: i64) -> Option<i64> {
    let q = a.checked_div(b)?;
    Some(if a % b != 0 && (a < 0) != (b < 0) {
        q - 1
    } else {
        q
    })
}

/// Looks a builtin up by name.
pub fn builtin(name: &str) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name)
}

/// The schema of a record: a material kind, a light kind, `camera` or `render`.
#[derive(Debug)]
pub struct Record {
    pub name: &'static str,
    pub fields: &'static [P],
    /// Fields whose value must not depend on the time `t` (E0406): what every frame of a
    /// sequence shares.
    pub timeless: &'static [&'static str],
    /// Fields that take a colour field (`field { … }` of a vec3) as well as a vec3.
    pub painted: &'static [&'static str],
    /// The help of a field's E0400 (its value out of range): how to give a valid one.
    pub help: &'static [(&'static str, &'static str)],
}

const SURFACE: [P; 9] = [
    p("ambient", F, Num(Material::AMBIENT), Unit),
    p("diffuse", F, Num(Material::DIFFUSE), NonNeg),
    p("specular", F, Num(Material::SPECULAR), NonNeg),
    p(
        "shininess",
        F,
        Num(Material::SHININESS),
        Within(1.0, 10000.0),
    ),
    p("reflect", F, Num(Material::REFLECT), Unit),
    p("transparency", F, Num(Material::TRANSPARENCY), Unit),
    p("ior", F, Num(Material::IOR), Within(1.0, 10.0)),
    p("color", V, V3(Material::COLOR), NonNeg),
    // Schlick's Fresnel term on the reflected and refracted rays (docs/rendering.md,
    // "Secondary rays"): off, so that the scenes written before it keep their look.
    p("fresnel", B, Bool(false), Any),
];

const fn concat<const N: usize, const M: usize, const T: usize>(a: [P; N], b: [P; M]) -> [P; T] {
    let mut out = [p("", F, Req, Any); T];
    let mut i = 0;
    while i < N {
        out[i] = a[i];
        i += 1;
    }
    while i < T {
        out[i] = b[i - N];
        i += 1;
    }
    out
}

const CHECKER: [P; 11] = concat(
    [
        SURFACE[0], SURFACE[1], SURFACE[2], SURFACE[3], SURFACE[4], SURFACE[5], SURFACE[6],
        SURFACE[8],
    ],
    [
        p("a", V, V3([0.9, 0.9, 0.9]), NonNeg),
        p("b", V, V3([0.1, 0.1, 0.1]), NonNeg),
        p("size", F, Num(1.0), Pos),
    ],
);

/// `pbr`: the physically based material (docs/rendering.md, "Physically based materials").
const PBR: [P; 6] = [
    p("base_color", V, V3(Material::COLOR), NonNeg),
    p("roughness", F, Num(Pbr::ROUGHNESS), Unit),
    p("metallic", F, Num(Pbr::METALLIC), Unit),
    p("emission", V, V3([0.0; 3]), NonNeg),
    p("transmission", F, Num(Pbr::TRANSMISSION), Unit),
    SURFACE[6],
];

/// Material kinds.
pub static MATERIALS: &[Record] = &[
    Record {
        name: "phong",
        timeless: &[],
        painted: &["color"],
        help: &[],
        fields: &SURFACE,
    },
    Record {
        name: "checker",
        timeless: &[],
        painted: &["a", "b"],
        help: &[],
        fields: &CHECKER,
    },
    Record {
        name: "pbr",
        timeless: &[],
        painted: &["base_color"],
        help: &[
            ("roughness", "write a roughness from 0 (a mirror) to 1 (fully rough): `roughness: 0.5`"),
            ("metallic", "write a metallic from 0 (plastic, stone, glass) to 1 (a metal): `metallic: 1`"),
            ("transmission", "write a transmission from 0 (opaque) to 1 (clear glass): `transmission: 1`"),
            ("ior", "write an index of refraction from 1 to 10 (air 1, water 1.33, glass 1.5, diamond 2.42): `ior: 1.5`"),
        ],
        fields: &PBR,
    },
];

const LIGHT_COMMON: [P; 5] = [
    p("color", V, V3([1.0, 1.0, 1.0]), NonNeg),
    p("intensity", F, Num(1.0), NonNeg),
    p(
        "penumbra",
        A,
        Deg(0.0),
        Within(0.0, 89.0 * std::f64::consts::PI / 180.0),
    ),
    // The sharpness k = 1/tan(penumbra) of the old files; W0012 says what to write instead.
    p("softness", F, Num(0.0), NonNeg),
    p("shadows", B, Bool(true), Any),
];

const POINT: [P; 7] = concat(
    [p("position", V, Req, Any), p("radius", F, Num(100.0), Pos)],
    LIGHT_COMMON,
);
const DIRECTIONAL: [P; 6] = concat([p("direction", V, Req, NonZero)], LIGHT_COMMON);

/// `light sun`: a directional light whose shadows soften over its angular size.
const SUN: [P; 5] = [
    p("direction", V, Req, NonZero),
    LIGHT_COMMON[0],
    LIGHT_COMMON[1],
    p(
        "angle",
        A,
        Deg(0.53),
        Within(0.0, 89.0 * std::f64::consts::PI / 180.0),
    ),
    LIGHT_COMMON[4],
];

/// `light sky`: light from the whole sky, a gradient or one colour.
const SKY: [P; 7] = [
    p("color", V, V3([1.0, 1.0, 1.0]), NonNeg),
    p("zenith", V, V3(crate::scene::look::SKY_ZENITH), NonNeg),
    p("horizon", V, V3(crate::scene::look::SKY_HORIZON), NonNeg),
    p("ground", V, V3(crate::scene::look::SKY_GROUND), NonNeg),
    LIGHT_COMMON[1],
    LIGHT_COMMON[4],
    p("background", B, Bool(true), Any),
];

/// Light kinds.
pub static LIGHTS: &[Record] = &[
    Record {
        name: "point",
        timeless: &[],
        painted: &[],
        help: &[],
        fields: &POINT,
    },
    Record {
        name: "directional",
        timeless: &[],
        painted: &[],
        help: &[],
        fields: &DIRECTIONAL,
    },
    Record {
        name: "sun",
        timeless: &[],
        painted: &[],
        help: &[],
        fields: &SUN,
    },
    Record {
        name: "sky",
        timeless: &[],
        painted: &[],
        help: &[],
        fields: &SKY,
    },
];

/// `camera { ... }`
pub static CAMERA: Record = Record {
    name: "camera",
    timeless: &[],
    painted: &[],
    help: &[],
    fields: &[
        p("position", V, V3(Camera::DEFAULT.position), Any),
        p("look_at", V, V3(Camera::DEFAULT.look_at), Any),
        p("up", V, V3(Camera::DEFAULT.up), NonZero),
        p(
            "fov",
            A,
            Deg(Camera::FOV_DEGREES),
            Within(
                0.1f64 * std::f64::consts::PI / 180.0,
                179.0 * std::f64::consts::PI / 180.0,
            ),
        ),
    ],
};

/// The defaults of `render`'s fields.
const DEFAULT: Settings = Settings::DEFAULT;

/// `render { ... }`; the same keys are accepted by `sdfc render --set`.
pub static RENDER: Record = Record {
    name: "render",
    // The sequence's frames and their size: an animated PNG or a video has one size.
    timeless: &["width", "height", "fps", "duration"],
    painted: &[],
    help: &[],
    fields: &[
        p(
            "width",
            I,
            Int(DEFAULT.width as i64),
            Limited(1.0, Limit::Edge),
        ),
        p(
            "height",
            I,
            Int(DEFAULT.height as i64),
            Limited(1.0, Limit::Edge),
        ),
        p("aa", I, Int(DEFAULT.aa as i64), Limited(1.0, Limit::Aa)),
        p(
            "max_steps",
            I,
            Int(DEFAULT.max_steps as i64),
            Limited(1.0, Limit::MaxSteps),
        ),
        p("epsilon", F, Num(DEFAULT.epsilon), Within(1e-9, 0.5)),
        p(
            "max_depth",
            I,
            Int(DEFAULT.max_depth as i64),
            Limited(0.0, Limit::MaxDepth),
        ),
        p("max_dist", F, Num(DEFAULT.max_dist), Within(1e-6, 1e9)),
        p("relaxation", F, Num(DEFAULT.relaxation), Within(1.0, 1.99)),
        p("background", V, V3(DEFAULT.background), NonNeg),
        p(
            "method",
            Str,
            Text(DEFAULT.method.name()),
            OneOf(Settings::METHODS),
        ),
        p(
            "samples",
            I,
            Int(DEFAULT.samples as i64),
            Limited(1.0, Limit::Samples),
        ),
        p(
            "bounces",
            I,
            Int(DEFAULT.bounces as i64),
            Limited(0.0, Limit::Bounces),
        ),
        p("fps", F, Num(30.0), Within(0.01, 1000.0)),
        p("duration", F, Num(0.0), Within(0.0, 1e7)),
        p("occlusion", F, Num(DEFAULT.occlusion), Within(0.0, 1e9)),
        p("fog", F, Num(DEFAULT.fog), Within(0.0, 1e9)),
        p("fog_color", V, V3(DEFAULT.background), NonNeg),
        p("glow", F, Num(DEFAULT.glow), Within(0.0, 1e9)),
        p("glow_color", V, V3(DEFAULT.glow_color), NonNeg),
        p("exposure", F, Num(DEFAULT.exposure), Within(-20.0, 20.0)),
        p(
            "tonemap",
            Str,
            Text(DEFAULT.tonemap.name()),
            OneOf(crate::scene::Tonemap::NAMES),
        ),
    ],
};
