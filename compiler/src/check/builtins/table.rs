//! The table of shape built-ins: primitives written here, profiles, combinators, transforms,
//! domain operations, hulls; each entry its overloads' signatures and evaluation.

use super::shapes::*;
use super::*;

/// The parameters of every smooth combination but the shapes: the radius `k`, the `variant`
/// and the `steps` of the stairs variants.
const SMOOTH_K: P = p("k", F, Req, NonNeg);
const SMOOTH_VARIANT: P = p("variant", Str, Text("poly"), OneOf(SMOOTH_VARIANTS));
const SMOOTH_STEPS: P = p("steps", I, Int(4), Within(1.0, 64.0));

/// The built-in of a smooth combination `op` named `name`: of two shapes or two profiles, and
/// where `fold` is given (`smooth_list`), of a list of profiles or of shapes folded by it.
macro_rules! smooth_builtin {
    ($name:literal, $op:expr $(, $fold:ident)?) => {
        Builtin {
            name: $name,
            sigs: sigs![
                [SMOOTH_K, shape("a"), shape("b"), SMOOTH_VARIANT, SMOOTH_STEPS] -> S
                    => |b, a| smooth(b, a, $op);
                [SMOOTH_K, prof("a"), prof("b"), SMOOTH_VARIANT, SMOOTH_STEPS] -> PR
                    => |b, a| flat(smooth(b, a, $op));
                $(
                    [SMOOTH_K, p("profiles", LP, Req, Any), SMOOTH_VARIANT, SMOOTH_STEPS] -> PR
                        => |b, a| flat($fold(b, a, $op, $name));
                    [SMOOTH_K, p("shapes", LS, Req, Any), SMOOTH_VARIANT, SMOOTH_STEPS] -> S
                        => |b, a| $fold(b, a, $op, $name);
                )?
            ],
        }
    };
}

/// The built-in `name` combining two or more shapes or profiles by `op`, or a list of them
/// (`union`, `intersect`).
macro_rules! combine_builtin {
    ($name:literal, $op:expr) => {
        Builtin {
            name: $name,
            sigs: sigs![
                [shape("a"), shape("b")] rest + -> S => |b, a| combine(b, a, $op);
                [p("shapes", LS, Req, Any)] -> S => |b, a| combine_list(b, a, $op, $name);
                [prof("a"), prof("b")] rest + -> PR => |b, a| flat(combine(b, a, $op));
                [p("profiles", LP, Req, Any)] -> PR => |b, a| flat(combine_list(b, a, $op, $name));
            ],
        }
    };
}

/// The built-ins of shapes, profiles and their operations.
pub(super) static SHAPES: &[Builtin] = &[
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
    combine_builtin!("union", Combine::Union),
    combine_builtin!("intersect", Combine::Intersect),
    Builtin {
        name: "subtract",
        sigs: sigs![
            [shape("a"), shape("b")] -> S => |b, a| combine(b, a, Combine::Subtract);
            [prof("a"), prof("b")] -> PR => |b, a| flat(combine(b, a, Combine::Subtract));
        ],
    },
    smooth_builtin!("smooth_union", Combine::Union, smooth_list),
    smooth_builtin!("smooth_intersect", Combine::Intersect, smooth_list),
    smooth_builtin!("smooth_subtract", Combine::Subtract),
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
];
