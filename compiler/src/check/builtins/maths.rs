//! The table of value built-ins: lists, vectors, scalar maths and the per-point functions
//! (`noise`, `distance`, … inside `field { … }`); each entry its overloads and evaluation.

use super::*;

/// The built-in `name` of `f` over a number and over each component of a 2- or 3-vector;
/// `int`, where given, its evaluation over an integer (the first overload).
macro_rules! componentwise {
    ($name:literal, $f:expr $(, int: $int:expr)?) => {
        Builtin {
            name: $name,
            sigs: sigs![
                $([p("x", I, Req, Any)] -> I => $int;)?
                [p("x", F, Req, Any)] -> F => |_, a| f1(a, $f);
                [p("x", V2, Req, Any)] -> V2 => |_, a| Ok(vmap(&a[0], $f));
                [p("x", V, Req, Any)] -> V => |_, a| Ok(vmap(&a[0], $f));
            ],
        }
    };
}

/// The built-in `name` of `f` over an angle or a plain number (read as radians).
macro_rules! trig {
    ($name:literal, $f:expr) => {
        Builtin {
            name: $name,
            sigs: sigs![
                [p("x", A, Req, Any)] -> F => |_, a| f1(a, $f);
                [p("x", F, Req, Any)] -> F => |_, a| f1(a, $f);
            ],
        }
    };
}

/// The per-point function `name` of a point in space or in the plane (`at`): refused with
/// constants, evaluated at each point inside `field { … }`.
macro_rules! at_point {
    ($name:literal) => {
        Builtin {
            name: $name,
            sigs: sigs![
                [p("at", V, Req, Any)] -> F => |_, _| Err(Refusal::PerPoint);
                [p("at", V2, Req, Any)] -> F => |_, _| Err(Refusal::PerPoint);
            ],
        }
    };
}

/// The built-ins of lists, vectors, scalar maths and per-point functions.
pub(super) static MATHS: &[Builtin] = &[
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
    trig!("sin", f64::sin),
    trig!("cos", f64::cos),
    trig!("tan", f64::tan),
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
    componentwise!("abs", f64::abs, int: |_, a| match &a[0] {
        Value::Int(i) => i.checked_abs().map(Value::Int).ok_or(Refusal::AbsOverflow),
        _ => Ok(Value::Error),
    }),
    componentwise!("floor", f64::floor),
    componentwise!("ceil", f64::ceil),
    componentwise!("fract", |x| x - x.floor()),
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
    at_point!("noise"),
    Builtin {
        name: "fbm",
        sigs: sigs![
            [p("at", V, Req, Any), p("octaves", I, Int(4), Within(1.0, 12.0)), p("lacunarity", F, Num(2.0), Within(1.0, 8.0)), p("gain", F, Num(0.5), Within(0.0, 1.0))] -> F
                => |_, _| Err(Refusal::PerPoint);
            [p("at", V2, Req, Any), p("octaves", I, Int(4), Within(1.0, 12.0)), p("lacunarity", F, Num(2.0), Within(1.0, 8.0)), p("gain", F, Num(0.5), Within(0.0, 1.0))] -> F
                => |_, _| Err(Refusal::PerPoint);
        ],
    },
    at_point!("voronoi"),
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

/// The number of elements of a list of any type (`len` has a form for each element type but
/// `int`: a list of ints fits `[float]`).
fn len(a: &[Value]) -> Result<Value, Refusal> {
    match &a[0] {
        Value::List(_, items) => Ok(Value::Int(items.len() as i64)),
        _ => Ok(Value::Error),
    }
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
