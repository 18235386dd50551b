//! Checks of the bounds the culling relies on: for every kind of node, alone and under other
//! nodes, the field the lowering computes is never below the guard distance of the node's
//! bound, at random points near and far (in f64 and in f32).

use super::graph::field_and_bound;
use crate::program::{Float, Program};
use crate::rng::Rng;
use crate::scene::bounds::Bounds;
use crate::scene::{Combine, Feature, Graph, MaterialId, Node, NodeId, Smooth};
use crate::{FileId, Span};

/// Evaluates the distance and the material register (the bound, here) of a program without
/// blocks.
fn eval<T: Float>(program: &Program, p: [T; 3]) -> (T, T) {
    let regs = program.run(p, |_| {});
    (
        regs[program.distance().0 as usize],
        regs[program.material().0 as usize],
    )
}

fn rotation(axis: [f64; 3], angle: f64) -> [[f64; 3]; 3] {
    let l = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    let [x, y, z] = axis.map(|a| a / l);
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ]
}

/// A primitive of the table (`prim/`).
fn prim(name: &str, args: &[&[f64]]) -> Node {
    Node::prim(name, args).expect("a primitive of the table")
}

/// Adds `n` to `g`, spanning nothing.
fn add(g: &mut Graph, n: Node) -> NodeId {
    g.add(n, Span::new(FileId(0), 0..0))
}

/// One of every primitive: those with nodes of their own, then the table's.
fn primitives() -> Vec<Node> {
    vec![
        Node::Sphere { radius: 0.7 },
        Node::Box {
            half: [0.5, 0.2, 0.9],
        },
        Node::RoundBox {
            half: [0.5, 0.4, 0.3],
            radius: 0.1,
        },
        Node::Torus {
            major: 0.8,
            minor: 0.2,
        },
        Node::Cylinder {
            radius: 0.3,
            half_height: 0.9,
        },
        Node::Capsule {
            radius: 0.25,
            half_height: 0.6,
        },
        Node::Cone {
            radius: 0.6,
            half_height: 0.5,
        },
        Node::Ellipsoid {
            radii: [0.3, 0.9, 0.5],
        },
        prim("mandelbulb", &[&[8.0], &[4.0]]),
        prim("mandelbulb", &[&[3.5], &[3.0]]),
        prim("capped_cone", &[&[1.2], &[0.5], &[0.2]]),
        prim("round_cone", &[&[0.4], &[0.2], &[1.0]]),
        prim("segment", &[&[0.3, -0.2, 0.5], &[-0.4, 0.6, 0.1], &[0.2]]),
        prim("rounded_cylinder", &[&[0.5], &[0.1], &[0.8]]),
        prim("hex_prism", &[&[0.4], &[1.0]]),
        prim("tri_prism", &[&[0.3], &[1.2]]),
        prim("octahedron", &[&[0.7]]),
        prim("pyramid", &[&[0.8], &[1.1]]),
        prim("box_frame", &[&[0.5, 0.4, 0.6], &[0.05]]),
        prim("link", &[&[0.6], &[0.4], &[0.1]]),
        prim("infinite_cylinder", &[&[0.3], &[0.0, 0.0, 1.0]]),
        prim("slab", &[&[0.4], &[0.0, 1.0, 0.0]]),
    ]
}

/// Every combination of `a` and `b`: plain and smooth (of every variant) unions,
/// intersections and subtractions, morphs and features.
fn combinations(a: NodeId, b: NodeId) -> Vec<Node> {
    let mut nodes = Vec::new();
    for op in [Combine::Union, Combine::Intersect, Combine::Subtract] {
        nodes.push(Node::Combine {
            op,
            children: vec![a, b],
        });
        for variant in [
            Smooth::Poly,
            Smooth::Exp,
            Smooth::Chamfer,
            Smooth::Round,
            Smooth::Stairs(3),
            Smooth::Columns(2),
        ] {
            nodes.push(Node::SmoothCombine {
                op,
                k: 0.5,
                variant,
                a,
                b,
            });
        }
    }
    for t in [0.3, 0.8] {
        nodes.push(Node::Morph { t, a, b });
    }
    for op in [
        Feature::Engrave { depth: 0.2 },
        Feature::Groove {
            width: 0.3,
            depth: 0.1,
        },
        Feature::Tongue {
            width: 0.3,
            height: 0.2,
        },
        Feature::Pipe { radius: 0.1 },
    ] {
        nodes.push(Node::Feature { op, a, b });
    }
    nodes
}

/// Every transform, paint and offset of `c`.
fn wrappers(c: NodeId) -> Vec<Node> {
    vec![
        Node::Translate {
            offset: [1.5, -0.5, 2.0],
            child: c,
        },
        Node::Rotate {
            matrix: rotation([1.0, 2.0, 0.5], 0.9),
            child: c,
        },
        Node::Scale {
            factor: 2.5,
            child: c,
        },
        Node::Scale {
            factor: 0.4,
            child: c,
        },
        Node::ScaleXyz {
            factors: [0.5, 2.0, 1.0],
            child: c,
        },
        Node::Repeat {
            period: [1.5, 0.0, 2.0],
            count: Some([3.0, 1.0, 2.0]),
            child: c,
        },
        Node::Repeat {
            period: [2.5, 0.0, 0.0],
            count: None,
            child: c,
        },
        Node::Mirror {
            axes: [true, false, true],
            child: c,
        },
        Node::Twist {
            rate: 1.3,
            child: c,
        },
        Node::RepeatPolar {
            count: 5,
            mirror: false,
            child: c,
        },
        Node::RepeatPolar {
            count: 6,
            mirror: true,
            child: c,
        },
        Node::Wrap {
            radius: 2.0,
            child: c,
        },
        Node::Shear {
            matrix: [[1.0, 0.5, 0.0], [0.0, 1.0, 0.3], [0.2, 0.0, 1.0]],
            child: c,
        },
        Node::Bend {
            rate: 0.7,
            child: c,
        },
        Node::Elongate {
            half: [0.3, 0.0, 0.5],
            child: c,
        },
        Node::Round {
            radius: 0.2,
            child: c,
        },
        Node::Shell {
            half: 0.1,
            child: c,
        },
        Node::Paint {
            material: MaterialId(1),
            child: c,
        },
    ]
}

/// A graph holding one of every kind of node, alone and nested: the primitives, their
/// combinations, each of those wrapped once (translated first), and a few shapes wrapped
/// twice.
fn zoo() -> (Graph, Vec<NodeId>) {
    let mut g = Graph::default();
    let prims: Vec<NodeId> = primitives().into_iter().map(|n| add(&mut g, n)).collect();
    let mut ids = prims.clone();
    let (a, b) = (prims[1], prims[7]);
    let moved = add(
        &mut g,
        Node::Translate {
            offset: [0.6, -0.2, 0.3],
            child: b,
        },
    );
    for n in combinations(a, moved) {
        ids.push(add(&mut g, n));
    }
    let bases: Vec<NodeId> = ids.clone();
    for &c in &bases {
        let shifted = add(
            &mut g,
            Node::Translate {
                offset: [0.4, 0.7, -0.3],
                child: c,
            },
        );
        for w in wrappers(shifted) {
            ids.push(add(&mut g, w));
        }
    }
    // Two levels of wrapping on a few shapes.
    for &c in &[prims[1], prims[3], prims[7]] {
        for w in wrappers(c) {
            let inner = add(&mut g, w);
            for w2 in wrappers(inner).into_iter().step_by(3) {
                ids.push(add(&mut g, w2));
            }
        }
    }
    (g, ids)
}

#[test]
fn every_bound_is_below_its_field() {
    let (graph, ids) = zoo();
    let bounds = Bounds::new(&graph);
    let mut rng = Rng::new(0x1234_5678_9ABC_DEF1);
    let mut checked = 0;
    for id in ids {
        let Some(program) = field_and_bound(&graph, &bounds, id) else {
            continue;
        };
        let b = bounds.get(id).expect("bounded");
        let reach = if b.finite() { b.sphere.r } else { 4.0 };
        let c = if b.finite() { b.sphere.c } else { [0.0; 3] };
        for k in 0..3000 {
            // Points from deep inside to far outside, denser near the volume.
            let scale = [0.3, 1.0, 1.5, 4.0][k % 4] * reach + 0.5;
            let p: [f64; 3] = [0, 1, 2].map(|i| c[i] + (2.0 * rng.uniform() - 1.0) * scale);
            let (f, beta) = eval::<f64>(&program, p);
            assert!(
                f.is_nan() || beta <= f,
                "node {:?}: bound {beta} above field {f} at {p:?}",
                graph.node(id)
            );
            let q = p.map(|v| v as f32);
            let (f, beta) = eval::<f32>(&program, q);
            assert!(
                f.is_nan() || beta <= f,
                "node {:?} (f32): bound {beta} above field {f} at {q:?}",
                graph.node(id)
            );
        }
        checked += 1;
    }
    assert!(checked > 300, "{checked} nodes checked");
}

/// issue 16, item 2: the builder counts the instructions it emits and stops at the `program`
/// limit. 2¹² distinct spheres lower to tens of thousands of instructions; capped at 1 000,
/// the lowering stops a node or so past the cap instead of lowering them all first.
#[test]
fn lowering_stops_at_the_program_limit() {
    let mut text = String::from("fn f0() -> shape { sphere(0.004) }\n");
    for i in 1..=12 {
        let (j, o) = (i - 1, f64::from(1u32 << i) * 1e-3);
        text.push_str(&format!(
            "fn f{i}() -> shape {{ union(f{j}().translate({o}, 0, 0), f{j}().translate(0, 0, {o})) }}\n"
        ));
    }
    text.push_str("scene { f12(); }");
    let (scene, diags, _) = crate::front::check_str("many.sdf", &text);
    let scene = scene.unwrap_or_else(|| panic!("{diags:?}"));
    let options = super::LowerOptions::default();
    let (whole, over, _) =
        super::lower_capped(&scene, &options, usize::MAX, &mut super::Phases::default());
    assert!(!over && whole.len() > 50_000, "{}", whole.len());
    let (part, over, _) =
        super::lower_capped(&scene, &options, 1_000, &mut super::Phases::default());
    assert!(over && part.len() < 2_000, "stopped at {}", part.len());
    let mut limits = crate::Limits::default();
    limits.set(crate::Limit::Program, 1_000).expect("valid");
    let err = super::lower_within(&scene, &options, &limits).expect_err("over the limit");
    assert!(
        err.notes.iter().any(|n| n.contains("--limit program=2000")),
        "{err:?}"
    );
    limits
        .set(crate::Limit::Program, whole.len() as u64 * 2)
        .expect("valid");
    let lowered = super::lower_within(&scene, &options, &limits).map(|l| l.program);
    assert_eq!(lowered, Ok(whole));
}

/// The GPU walk's shape functions are the lowering's own rules: for every kind of instance,
/// the program `shape_program` returns (the one the WGSL writer writes, each recorded
/// parameter read as `scale · s[slot]`) has the instructions of the primitive lowered with
/// its own constants, instruction for instruction, and each parameter's constant there is
/// `scale · slots[slot]` exactly, so that the shader computes what the program computes.
#[test]
fn the_walks_shape_programs_are_the_lowerings_rules() {
    use super::{shape_program, shapes};
    use crate::program::builder::Builder;
    use crate::program::Op;
    // Every kind of instance among the primitives.
    let shapes_of: Vec<Node> = primitives()
        .into_iter()
        .filter(|n| shapes::slots(n).is_some())
        .collect();
    assert_eq!(shapes_of.len(), 9);
    for node in &shapes_of {
        let slots = shapes::slots(node).expect("an instance kind");
        let shape = shape_program(node).expect("a shape program");
        let mut b = Builder::new(false);
        let p = b.input_point();
        let d = shapes::exact(&mut b, p, node, &slots).expect("exact");
        let m = b.c(0.0);
        let real = b.finish(d, m);
        let (a, r) = (shape.program.ops(), real.ops());
        assert_eq!(a.len(), r.len(), "{node:?}");
        assert!(!shape.params.is_empty(), "{node:?}");
        for (i, (x, y)) in a.iter().zip(r).enumerate() {
            match shape.params.iter().find(|q| q.reg.0 as usize == i) {
                Some(q) => {
                    assert_eq!(*y, Op::Const(q.scale * slots[q.slot]), "{node:?} at {i}");
                    assert!([1.0, -1.0, 2.0, -2.0].contains(&q.scale));
                }
                None => assert_eq!(x, y, "{node:?} at {i}"),
            }
        }
        assert_eq!(shape.program.distance(), real.distance());
    }
    assert!(shape_program(&Node::Ellipsoid {
        radii: [1.0, 2.0, 3.0]
    })
    .is_none());
}

/// The distance of a checked scene's program at `p`, in f64.
fn distance_of(src: &str) -> impl Fn([f64; 3]) -> f64 {
    let (scene, diags, _) = crate::front::check_str("t.sdf", src);
    assert!(diags.iter().all(|d| !d.is_error()), "{diags:#?}");
    let program = super::lower(&scene.expect("a scene"));
    move |p| eval::<f64>(&program, p).0
}

/// Random points around the y axis at distances `rho` from it.
fn around_axis(rng: &mut Rng, rho: (f64, f64)) -> [f64; 3] {
    let a = rng.uniform() * std::f64::consts::TAU;
    let r = rho.0 + (rho.1 - rho.0) * rng.uniform();
    [r * a.cos(), 2.0 * rng.uniform() - 1.0, r * a.sin()]
}

#[test]
fn polar_repetition_is_the_union_of_rotated_copies() {
    let mut rng = Rng::new(0x5EED_0F7A);
    // A shape inside its sector, one that reaches over its neighbours' (12 sectors of 30°,
    // a box 1.6 long at x = 2), three copies of it (every copy evaluated), one about a
    // tilted axis, and a mirrored set (the odd copies are the shape reflected across z = 0).
    let cases = [
        ("sphere(0.3).translate(2, 0, 0.2)", None, 8, [0.0, 1.0, 0.0]),
        (
            "box((0.3, 0.2, 0.8)).translate(2, 0, 0)",
            None,
            12,
            [0.0, 1.0, 0.0],
        ),
        (
            "box((0.3, 0.2, 0.8)).translate(2, 0, 0)",
            None,
            3,
            [0.0, 1.0, 0.0],
        ),
        (
            "capsule(0.2, 1).rotate_z(40deg).translate(2, 0, 0.1)",
            None,
            7,
            [1.0, 2.0, 0.5],
        ),
        (
            "box((0.3, 0.2, 0.4)).translate(2, 0, 0.3)",
            Some("box((0.3, 0.2, 0.4)).translate(2, 0, -0.3)"),
            10,
            [0.0, 1.0, 0.0],
        ),
    ];
    for (shape, reflected, n, axis) in cases {
        let a = format!("({}, {}, {})", axis[0], axis[1], axis[2]);
        let mirror = reflected.is_some();
        let polar = distance_of(&format!(
            "scene {{ repeat_polar({shape}, {n}, axis: {a}, mirror: {mirror}); }}"
        ));
        let copies: Vec<String> = (0..n)
            .map(|k| {
                let s = match reflected {
                    Some(r) if k % 2 == 1 => r,
                    _ => shape,
                };
                format!("rotate({s}, {a}, {}deg)", 360.0 * k as f64 / n as f64)
            })
            .collect();
        let explicit = distance_of(&format!("scene {{ union({}); }}", copies.join(", ")));
        // The turn taking y to the axis, to sample points around it.
        let l = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        let turn = if axis == [0.0, 1.0, 0.0] {
            rotation([1.0, 0.0, 0.0], 0.0)
        } else {
            rotation([axis[2], 0.0, -axis[0]], (axis[1] / l).acos())
        };
        let mut near = 0;
        for _ in 0..4000 {
            let q = around_axis(&mut rng, (0.0, 3.0));
            let p = [0, 1, 2].map(|i| (0..3).map(|j| turn[i][j] * q[j]).sum::<f64>());
            let (d, want) = (polar(p), explicit(p));
            // Everywhere a bound of the union, and the same distance near the surface.
            assert!(d <= want + 1e-12, "{shape} ×{n}: {d} above {want} at {p:?}");
            if want.abs() < 0.1 {
                near += 1;
                assert!(
                    (d - want).abs() <= 1e-12,
                    "{shape} ×{n}: {d} against {want} at {p:?}"
                );
            }
        }
        assert!(
            near > 20,
            "{shape} ×{n}: only {near} points near the surface"
        );
    }
}

#[test]
fn a_wrapped_bar_is_a_closed_ring() {
    // A bar of length 2πR along x, of square section 2h, wrapped around radius R: a ring of
    // square section centred on the circle of radius R about the y axis.
    let (r, h) = (2.0, 0.25);
    let wrapped = distance_of(&format!(
        "scene {{ wrap(box(({}, {h}, {h})), {r}); }}",
        std::f64::consts::PI * r
    ));
    let ring = |p: [f64; 3]| {
        // The square section's distance in the (ρ − R, y) plane: the ring's exact distance.
        let q = [(p[0].hypot(p[2]) - r).abs() - h, p[1].abs() - h];
        let outside = q[0].max(0.0).hypot(q[1].max(0.0));
        outside + q[0].max(q[1]).min(0.0)
    };
    let mut rng = Rng::new(0xB0A7_2417);
    // The wrap stretches arcs by up to R/(R − h) over the bar, and its field is divided by
    // that (docs/analysis.md): between the distance over that and the distance.
    let sigma = r / (r - h);
    let check = |p: [f64; 3]| {
        let (d, want) = (wrapped(p), ring(p));
        // Outside, a bound of the ring's exact distance; inside, a depth never below the
        // ring's (the bar's end faces meet at the seam, inside the solid), so the sign is the
        // ring's everywhere.
        if want > 0.0 {
            assert!(
                d <= want + 1e-9 && d >= want / sigma - 1e-9,
                "{d} against {want} at {p:?}"
            );
        } else {
            assert!(d >= want - 1e-9 && d <= 1e-9, "{d} against {want} at {p:?}");
        }
    };
    for _ in 0..4000 {
        let p = around_axis(&mut rng, (1.0, 3.0));
        check(p);
        // The ring is closed: no gap where the bar's ends meet (angle ±π, x = ±0, z > 0).
        let rho = p[0].hypot(p[2]);
        check([1e-9, p[1] * 0.5, rho]);
        check([-1e-9, p[1] * 0.5, rho]);
    }
}

#[test]
fn the_exponential_smooth_union_of_a_list_is_independent_of_its_order() {
    let parts = [
        "sphere(0.6)",
        "box(0.4).translate(0.7, 0.2, 0)",
        "torus(0.6, 0.15).translate(-0.3, 0.4, 0.2)",
    ];
    let field = |variant: &str, order: [usize; 3]| {
        let list: Vec<&str> = order.iter().map(|&i| parts[i]).collect();
        distance_of(&format!(
            "scene {{ smooth_union(0.4, [{}], variant: \"{variant}\"); }}",
            list.join(", ")
        ))
    };
    let (exp, exp_turned) = (field("exp", [0, 1, 2]), field("exp", [2, 0, 1]));
    let (poly, poly_turned) = (field("poly", [0, 1, 2]), field("poly", [2, 0, 1]));
    let mut rng = Rng::new(0x0DE2_1A57);
    let mut poly_differs = false;
    for _ in 0..2000 {
        let p = [0, 1, 2].map(|_| 3.0 * rng.uniform() - 1.5);
        let (a, b) = (exp(p), exp_turned(p));
        assert!(
            (a - b).abs() <= 1e-12 * (1.0 + a.abs()),
            "{a} against {b} at {p:?}"
        );
        poly_differs |= (poly(p) - poly_turned(p)).abs() > 1e-6;
    }
    assert!(
        poly_differs,
        "the polynomial blend of three should depend on the order"
    );
}

/// Where only its solid is read, an intersection leaves out the planes that cut nothing of
/// it (a box cut by one plane has the same program with two more that miss it); where its
/// field is read off the surface too (rounded), it keeps them.
#[test]
fn planes_that_cut_nothing_are_left_out_where_only_the_solid_counts() {
    let ops = |planes: &str, post: &str| {
        let src = format!(
            "scene {{ intersect([box((1, 1, 1)), plane((1, 0, 0), 0.5){planes}]){post}; }}"
        );
        let (scene, diags, _) = crate::front::check_str("t.sdf", &src);
        assert!(diags.iter().all(|d| !d.is_error()), "{diags:#?}");
        super::lower(&scene.expect("a scene")).ops.len()
    };
    let far = ", plane((0, 1, 0), 1.5), plane((0, 0, -1), 2)";
    assert_eq!(ops(far, ""), ops("", ""));
    assert!(ops(far, ".round(0.2)") > ops("", ".round(0.2)"));
}
