//! `hull(shapes…)` (issue 50, item 4): the shapes reduced to balls, or to cylinders, in the
//! scene's frame, and the node of their hull. Balls come from spheres, capsules, segments,
//! round cones and hulls of balls or of points with a radius (each the hull of balls), moved,
//! turned, scaled uniformly, rounded or united; their hull is `prim::HULL_BALLS`. Parallel
//! cylinders that span one stretch of their common axis hull to the extrusion of the 2D hull
//! of their circles (`prim::HULL_CIRCLES`), turned and moved into place. Both are exact; any
//! other mix is refused with the hulls there are.

use crate::prim::{ball_entries, Args, Ball, Kind, PrimRef, HULL_BALLS, HULL_CIRCLES};
use crate::scene::{Combine, Graph, Node, NodeId};
use crate::span::Span;
use glam::{DMat3, DVec3};

/// What a shape given to `hull` is made of.
#[derive(Debug, Clone, Copy)]
enum Piece {
    Ball(Ball),
    /// A capped cylinder: the centre, the unit axis, the radius and the half-height.
    Cylinder {
        c: DVec3,
        a: DVec3,
        r: f64,
        e: f64,
    },
}

/// Where a shape's own frame lies in the scene's: a point x of it is at t + s·m·x; and how
/// much it is rounded (in the scene's units).
#[derive(Debug, Clone, Copy)]
struct Place {
    m: DMat3,
    t: DVec3,
    s: f64,
    grow: f64,
}

impl Place {
    fn at(&self, x: DVec3) -> DVec3 {
        self.t + self.s * (self.m * x)
    }

    fn ball(&self, c: DVec3, r: f64) -> Piece {
        Piece::Ball(Ball {
            c: self.at(c),
            r: self.s * r + self.grow,
        })
    }
}

/// What `hull` accepts, for its messages.
const TAKES: &str = "`hull` takes balls (`sphere`, `capsule`, `segment`, `round_cone`, a `hull` of them or of points) or parallel `cylinder`s, moved, turned, scaled, rounded (balls) or united";

/// Why `hull` refuses its shapes.
#[derive(Debug)]
pub enum Refused {
    /// More balls and cylinders (`n`, saturating) than the limit `most`; `raise` says how
    /// to raise it.
    Many { n: u64, most: usize, raise: String },
    /// Shape `at` (from 1) of `of` is not one `hull` takes.
    Shape { at: usize, of: usize, what: Misfit },
    /// Balls and cylinders together.
    Mixed,
    /// Cylinder `at` (from 1) does not line up with the first.
    Cylinder { at: usize, how: Apart },
}

/// What a shape given to `hull` is that it does not take.
#[derive(Debug)]
pub enum Misfit {
    /// A shape of this kind.
    Kind(&'static str),
    Painted,
    RoundedCylinder,
}

/// How a cylinder differs from the first of a `hull`.
#[derive(Debug)]
pub enum Apart {
    Turned,
    Height,
    Moved,
}

impl std::fmt::Display for Refused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Refused::Many { n, most, raise } => write!(
                f,
                "this `hull` takes {n} balls and cylinders, more than the `hull_shapes` limit of {most}: its cost per point grows as the square of their number (hull fewer, or their centres with `hull([points…], radius)` where the radii are equal; or {raise})"
            ),
            Refused::Shape { at, of, what } => {
                write!(f, "shape {at} of {of} is ")?;
                match what {
                    Misfit::Kind(kind) => write!(f, "a `{kind}`: {TAKES} (for a polyhedron, hull its corners: `hull([points…], radius)`)"),
                    Misfit::Painted => write!(f, "painted: paint the hull instead, `hull(…) @ material`"),
                    Misfit::RoundedCylinder => write!(f, "a rounded cylinder: its hull with others has no exact distance here (hull the rounded cylinder's rims as balls, or round the hull: `hull(…).round(r)`)"),
                }
            }
            Refused::Mixed => write!(
                f,
                "a `hull` of balls and cylinders together has no exact distance here: hull balls alone (a cylinder with round ends is a `capsule`) or parallel cylinders alone ({TAKES})"
            ),
            Refused::Cylinder { at, how } => {
                let why = match how {
                    Apart::Turned => "turned from",
                    Apart::Height => "of another height than",
                    Apart::Moved => "moved along its axis from",
                };
                write!(f, "cylinder {at} is {why} the first: a `hull` of cylinders is exact where they are parallel and span the same stretch of their axis (then it is the extruded hull of their circles); for others hull balls (spheres, capsules) or points with `hull([points…], radius)`")
            }
        }
    }
}

/// The node of the hull of `shapes`, at most `most` balls and cylinders, added to `graph` at
/// `span`; or why there is none (`raise`: how to raise the limit to a count).
pub(super) fn hull(
    graph: &mut Graph,
    span: Span,
    shapes: &[NodeId],
    most: usize,
    raise: impl Fn(u64) -> String,
) -> Result<NodeId, Refused> {
    let mut seen = std::collections::HashMap::new();
    let n = shapes
        .iter()
        .fold(0u64, |n, &id| n.saturating_add(count(graph, id, &mut seen)));
    if n > most as u64 {
        return Err(Refused::Many {
            n,
            most,
            raise: raise(n),
        });
    }
    hull_of(graph, span, shapes)
}

/// How many balls and cylinders the shape `id` gives, each shared shape counted once per
/// use but walked once (`seen`); 0 for one that is refused, as [`collect`] says.
fn count(graph: &Graph, id: NodeId, seen: &mut std::collections::HashMap<NodeId, u64>) -> u64 {
    if let Some(&n) = seen.get(&id) {
        return n;
    }
    let n = match graph.node(id) {
        Node::Sphere { .. } | Node::Cylinder { .. } => 1,
        Node::Capsule { .. } => 2,
        Node::Prim { prim, args } => match prim.name {
            "cylinder" => 1,
            "segment" | "round_cone" => 2,
            "hull" if std::ptr::eq(prim.0, &HULL_BALLS) => args.list(0).len() as u64 / 2,
            "hull" => args.list(0).len() as u64,
            _ => 0,
        },
        Node::Translate { child, .. }
        | Node::Rotate { child, .. }
        | Node::Scale { child, .. }
        | Node::Round { child, .. }
        | Node::Extrude { child, .. } => count(graph, *child, seen),
        Node::Combine {
            op: Combine::Union,
            children,
        } => children
            .iter()
            .fold(0u64, |n, &c| n.saturating_add(count(graph, c, seen))),
        _ => 0,
    };
    seen.insert(id, n);
    n
}

/// The node of the hull of `shapes` (not more than the limit), added to `graph` at `span`.
fn hull_of(graph: &mut Graph, span: Span, shapes: &[NodeId]) -> Result<NodeId, Refused> {
    let mut pieces = Vec::new();
    for (k, &id) in shapes.iter().enumerate() {
        let place = Place {
            m: DMat3::IDENTITY,
            t: DVec3::ZERO,
            s: 1.0,
            grow: 0.0,
        };
        collect(graph, id, place, &mut pieces).map_err(|what| Refused::Shape {
            at: k + 1,
            of: shapes.len(),
            what,
        })?;
    }
    let balls: Vec<Ball> = pieces
        .iter()
        .filter_map(|p| match p {
            Piece::Ball(b) => Some(*b),
            Piece::Cylinder { .. } => None,
        })
        .collect();
    if balls.len() == pieces.len() {
        let args = Args::with_list(&[], 0, &ball_entries(&balls));
        return Ok(graph.add(
            Node::Prim {
                prim: PrimRef(&HULL_BALLS),
                args,
            },
            span,
        ));
    }
    if !balls.is_empty() {
        return Err(Refused::Mixed);
    }
    cylinders(graph, span, &pieces)
}

/// The hull of parallel cylinders that span one stretch of their axis: the 2D hull of their
/// circles, extruded, turned so that its z is the axis, and moved to their middle.
fn cylinders(graph: &mut Graph, span: Span, pieces: &[Piece]) -> Result<NodeId, Refused> {
    let cyls: Vec<(DVec3, DVec3, f64, f64)> = pieces
        .iter()
        .filter_map(|p| match *p {
            Piece::Cylinder { c, a, r, e } => Some((c, a, r, e)),
            Piece::Ball(_) => None,
        })
        .collect();
    let (c0, a, _, e) = cyls[0];
    let size = cyls
        .iter()
        .map(|(c, _, r, e)| c.distance(c0) + r + e)
        .fold(0.0, f64::max);
    let eps = 1e-9 * size;
    for (k, &(c, b, _, f)) in cyls.iter().enumerate().skip(1) {
        let how = if b.dot(a).abs() < 1.0 - 1e-9 {
            Apart::Turned
        } else if (f - e).abs() > eps {
            Apart::Height
        } else if (c - c0).dot(a).abs() > eps {
            Apart::Moved
        } else {
            continue;
        };
        return Err(Refused::Cylinder { at: k + 1, how });
    }
    let middle = cyls.iter().fold(DVec3::ZERO, |m, (c, ..)| m + *c) / cyls.len() as f64;
    let e1 = a.any_orthonormal_vector();
    let e2 = a.cross(e1);
    let circles: Vec<[f64; 3]> = cyls
        .iter()
        .map(|(c, _, r, _)| [(*c - middle).dot(e1), (*c - middle).dot(e2), *r])
        .collect();
    let profile = graph.add(
        Node::Prim {
            prim: PrimRef(&HULL_CIRCLES),
            args: Args::with_list(&[], 0, &circles),
        },
        span,
    );
    let solid = graph.add(
        Node::Extrude {
            half_height: e,
            round: 0.0,
            child: profile,
        },
        span,
    );
    // The frame (e1, e2, a) as the rotation's rows: a point x of the extrusion is at
    // x.x·e1 + x.y·e2 + x.z·a.
    let matrix = [0, 1, 2].map(|i| [e1[i], e2[i], a[i]]);
    let turned = graph.add(
        Node::Rotate {
            matrix,
            child: solid,
        },
        span,
    );
    Ok(graph.add(
        Node::Translate {
            offset: middle.to_array(),
            child: turned,
        },
        span,
    ))
}

/// The balls and cylinders the shape `id`, placed at `place`, is made of; or what it is that
/// `hull` does not take.
fn collect(graph: &Graph, id: NodeId, place: Place, out: &mut Vec<Piece>) -> Result<(), Misfit> {
    let y = |h: f64| DVec3::new(0.0, h, 0.0);
    match graph.node(id) {
        Node::Sphere { radius } => out.push(place.ball(DVec3::ZERO, *radius)),
        Node::Capsule {
            radius,
            half_height,
        } => {
            out.push(place.ball(y(-half_height), *radius));
            out.push(place.ball(y(*half_height), *radius));
        }
        Node::Cylinder {
            radius,
            half_height,
        } => out.push(cylinder(&place, y(-half_height), y(*half_height), *radius)?),
        Node::Prim { prim, args } => prim_pieces(*prim, args, &place, out)?,
        Node::Translate { offset, child } => {
            let t = place.at(DVec3::from(*offset));
            collect(graph, *child, Place { t, ..place }, out)?;
        }
        Node::Rotate { matrix, child } => {
            let m = place.m * DMat3::from_cols_array_2d(matrix).transpose();
            collect(graph, *child, Place { m, ..place }, out)?;
        }
        Node::Scale { factor, child } => {
            let s = place.s * factor;
            collect(graph, *child, Place { s, ..place }, out)?;
        }
        Node::Round { radius, child } => {
            let grow = place.grow + place.s * radius;
            collect(graph, *child, Place { grow, ..place }, out)?;
        }
        Node::Combine {
            op: Combine::Union,
            children,
        } => {
            for &c in children {
                collect(graph, c, place, out)?;
            }
        }
        Node::Paint { .. } => return Err(Misfit::Painted),
        Node::Extrude {
            half_height,
            round,
            child,
        } if *round == 0.0 => match graph.node(*child) {
            Node::Prim { prim, args } if std::ptr::eq(prim.0, &HULL_CIRCLES) => {
                for c in args.list(0) {
                    let (x, e) = (
                        DVec3::new(c[0], c[1], 0.0),
                        DVec3::new(0.0, 0.0, *half_height),
                    );
                    out.push(cylinder(&place, x - e, x + e, c[2])?);
                }
            }
            _ => return Err(Misfit::Kind("extrude")),
        },
        node => return Err(Misfit::Kind(node.kind())),
    }
    Ok(())
}

/// The pieces of a primitive of the table: those that are hulls of balls, and the cylinder
/// between two points.
fn prim_pieces(
    prim: PrimRef,
    args: &Args,
    place: &Place,
    out: &mut Vec<Piece>,
) -> Result<(), Misfit> {
    let v = |i: usize| DVec3::from(args.v3(i));
    let y = |h: f64| DVec3::new(0.0, h, 0.0);
    let along_y = prim.params[0].ty == Kind::Float;
    match prim.name {
        "segment" => {
            out.push(place.ball(v(0), args.f(2)));
            out.push(place.ball(v(1), args.f(2)));
        }
        "round_cone" if along_y => {
            let h = args.f(2) / 2.0;
            out.push(place.ball(y(-h), args.f(0)));
            out.push(place.ball(y(h), args.f(1)));
        }
        "round_cone" => {
            out.push(place.ball(v(0), args.f(2)));
            out.push(place.ball(v(1), args.f(3)));
        }
        "cylinder" => out.push(cylinder(place, v(0), v(1), args.f(2))?),
        "hull" if std::ptr::eq(prim.0, &HULL_BALLS) => {
            for e in args.list(0).chunks_exact(2) {
                out.push(place.ball(DVec3::from(e[0]), e[1][0]));
            }
        }
        "hull" if prim.params[0].ty == Kind::Points && prim.params.len() == 2 => {
            for q in args.list(0) {
                out.push(place.ball(DVec3::from(*q), args.f(1)));
            }
        }
        name => return Err(Misfit::Kind(name)),
    }
    Ok(())
}

/// The cylinder whose axis runs from `a` to `b` (in the shape's frame) of radius `r`.
fn cylinder(place: &Place, a: DVec3, b: DVec3, r: f64) -> Result<Piece, Misfit> {
    if place.grow > 0.0 {
        return Err(Misfit::RoundedCylinder);
    }
    let (a, b) = (place.at(a), place.at(b));
    Ok(Piece::Cylinder {
        c: (a + b) / 2.0,
        a: (b - a).normalize(),
        r: place.s * r,
        e: a.distance(b) / 2.0,
    })
}
