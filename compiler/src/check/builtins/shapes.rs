//! The built-ins that build shapes and profiles from their checked arguments: polygons, text,
//! curves, lofts, screws, sweeps, polar repetition, combinations and hulls (the table's entries
//! in `table.rs` call them).

use super::*;

/// `polygon(points)`: three or more points, not all on a line, no two edges crossing.
pub(super) fn polygon(b: &mut Build, a: &[Value]) -> Result<Value, Refusal> {
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
pub(super) fn text(b: &mut Build, a: &[Value]) -> Result<Value, Refusal> {
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
pub(super) fn outline_of(
    b: &mut Build,
    string: &str,
    size: f64,
    font: &str,
) -> Result<crate::program::outline::Outline, Refusal> {
    if font.is_empty() {
        crate::check::font::layout(crate::check::font::default_font(), string, size)
            .map_err(|error| Refusal::Font { font: None, error })
    } else {
        let (_, bytes) = b.read_bytes(font)?;
        crate::check::font::layout(&bytes, string, size).map_err(|error| Refusal::Font {
            font: Some(font.into()),
            error,
        })
    }
}

/// `text_size`: the width and height of the box around the ink of what `text` draws with
/// the same arguments.
pub(super) fn text_size(b: &mut Build, a: &[Value]) -> Result<Value, Refusal> {
    let (Value::Str(string), Value::Str(font)) = (&a[0], &a[2]) else {
        return Ok(Value::Error);
    };
    let (lo, hi) = outline_of(b, string, a[1].num(), font)?.bounds();
    Ok(Value::Vec2([hi[0] - lo[0], hi[1] - lo[1]]))
}

pub(super) fn polygon_of(b: &mut Build, points: Vec<[f64; 2]>) -> Result<Value, Refusal> {
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
    let crossing = crate::check::polygon::crossing(&points, b.fuel_left, &mut b.steps);
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
pub(super) fn rect_of(
    b: &Build,
    v: &Value,
    what: &'static str,
) -> Result<([f64; 2], [f64; 2], f64), Refusal> {
    crate::scene::bounds::profile_rect(b.graph, sh(v)).ok_or(Refusal::Unbounded { what })
}

/// `bezier(a, control, b, radius)`: the curve is a parabola's arc only where the control
/// point is off the midpoint of `a` and `b` (at the midpoint it is the segment, which
/// `segment2` draws).
pub(super) fn bezier(b: &mut Build, a: &[Value]) -> Result<Value, Refusal> {
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
pub(super) fn loft(b: &mut Build, a: &[Value]) -> Result<Value, Refusal> {
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
pub(super) fn screw(b: &mut Build, a: &[Value]) -> Result<Value, Refusal> {
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
pub(super) fn points3(v: &Value) -> Vec<V3> {
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
pub(super) fn sweep(b: &mut Build, a: &[Value]) -> Result<Value, Refusal> {
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
pub(super) fn householder(n: V3) -> [V3; 3] {
    let nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| f64::from(u8::from(i == j)) - 2.0 * n[i] * n[j] / nn))
}

/// The points of a regular polygon of `sides` with its corners `radius` from the centre,
/// the first on +y, turning counter-clockwise.
pub(super) fn regular(sides: usize, radius: f64, phase: f64) -> Vec<[f64; 2]> {
    (0..sides)
        .map(|i| {
            let t = std::f64::consts::FRAC_PI_2
                + phase
                + std::f64::consts::TAU * i as f64 / sides as f64;
            [radius * t.cos(), radius * t.sin()]
        })
        .collect()
}

pub(super) const HANDS: &[&str] = &["right", "left"];

pub(super) const SMOOTH_VARIANTS: &[&str] =
    &["poly", "exp", "chamfer", "round", "stairs", "columns"];

pub(super) fn smooth(b: &mut Build, a: &[Value], op: Combine) -> Result<Value, Refusal> {
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

pub(super) fn feature(b: &mut Build, a: &[Value], op: Feature) -> Result<Value, Refusal> {
    b.node(Node::Feature {
        op,
        a: sh(&a[0]),
        b: sh(&a[1]),
    })
}

pub(super) fn rotation(axis: V3, angle: f64) -> [V3; 3] {
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
pub(super) fn repeat_polar(b: &mut Build, a: &[Value]) -> Result<Value, Refusal> {
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

pub(super) fn rotate(b: &mut Build, child: &Value, axis: V3, angle: f64) -> Result<Value, Refusal> {
    b.node(Node::Rotate {
        matrix: rotation(axis, angle),
        child: sh(child),
    })
}

/// The shapes of a list argument; an empty list is an error (nothing to combine).
pub(super) fn shapes(list: &Value, name: &'static str) -> Result<Vec<Value>, Refusal> {
    match list {
        Value::List(_, items) if items.is_empty() => Err(Refusal::EmptyList { name }),
        Value::List(_, items) => Ok(items.to_vec()),
        _ => Ok(Vec::new()),
    }
}

/// `union(shapes)`, `intersect(shapes)`: the same node as the shapes given one by one.
pub(super) fn combine_list(
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
pub(super) fn smooth_list(
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
pub(super) fn hull(b: &mut Build, a: &[Value]) -> Result<Value, Refusal> {
    let ids: Vec<NodeId> = a.iter().map(sh).collect();
    let (limits, most) = (b.limits, b.limits.count(Limit::HullShapes));
    let raise = |n| limits.raise_to(Limit::HullShapes, n);
    crate::check::hull::hull(b.graph, b.span, &ids, most, raise)
        .map(Value::Shape)
        .map_err(Refusal::Hull)
}

pub(super) fn combine(b: &mut Build, a: &[Value], op: Combine) -> Result<Value, Refusal> {
    b.node(Node::Combine {
        op,
        children: a.iter().map(sh).collect(),
    })
}
