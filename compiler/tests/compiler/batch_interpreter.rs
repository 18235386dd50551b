//! The batch interpreter: f32 against f64, the batch path against the one-point reference
//! path (bit for bit, fused steps included, at special values too), batches of every length
//! around the chunk size, and what a tape keeps.

use crate::common::*;
use sdfc_compiler::{
    eval_point, lower, lower_with, Combine, Float, LowerOptions, Node, Outputs, Program, Rng,
    Scene, Smooth, Tape,
};

/// A scene that uses most operations: smooth blends, repetition, twist, bend, rotation,
/// painting.
fn busy_scene() -> Scene {
    let mut b = Build::new();
    let (m1, m2) = (
        b.material([1.0, 0.2, 0.2], 0.0, 0.0),
        b.material([0.2, 0.2, 1.0], 0.3, 0.0),
    );
    let t = b.add(Node::Torus {
        major: 1.0,
        minor: 0.3,
    });
    let t = b.add(Node::Twist {
        rate: 0.5,
        child: t,
    });
    let t = b.paint(t, m1);
    let bx = b.add(Node::RoundBox {
        half: [0.6, 0.4, 0.5],
        radius: 0.1,
    });
    let bx = b.add(Node::Bend {
        rate: 0.3,
        child: bx,
    });
    let bx = b.at(bx, [0.7, 0.2, 0.0]);
    let blend = b.add(Node::SmoothCombine {
        op: Combine::Union,
        k: 0.3,
        variant: Smooth::Exp,
        a: t,
        b: bx,
    });
    let c = b.add(Node::Cone {
        radius: 0.4,
        half_height: 0.5,
    });
    let th: f64 = 0.4;
    let c = b.add(Node::Rotate {
        matrix: [
            [1.0, 0.0, 0.0],
            [0.0, th.cos(), -th.sin()],
            [0.0, th.sin(), th.cos()],
        ],
        child: c,
    });
    let c = b.add(Node::Repeat {
        period: [3.0, 0.0, 3.0],
        count: Some([4.0, 1.0, 4.0]),
        child: c,
    });
    let c = b.paint(c, m2);
    let e = b.add(Node::Ellipsoid {
        radii: [0.3, 0.6, 0.4],
    });
    let e = b.add(Node::Shell {
        half: 0.05,
        child: e,
    });
    let e = b.at(e, [-2.0, 0.0, 1.0]);
    let floor = b.add(Node::Plane {
        normal: [0.0, 1.0, 0.0],
        height: -1.0,
    });
    let root = b.add(Node::Combine {
        op: Combine::Union,
        children: vec![blend, c, e, floor],
    });
    b.finish(root)
}

fn points(n: usize) -> Vec<[f64; 3]> {
    let mut rng = Rng::new(42);
    (0..n).map(|_| rng.point(4.0)).collect()
}

#[test]
fn f32_agrees_with_f64() {
    let program = lower(&busy_scene());
    let pts = points(2000);
    let (d32, m32) = run_batch::<f32>(&program, Outputs::DistanceAndMaterial, 256, &pts);
    let (d64, m64) = run_batch::<f64>(&program, Outputs::DistanceAndMaterial, 256, &pts);
    let mut material_mismatch = 0;
    for i in 0..pts.len() {
        let tol = 2e-5 * (1.0 + d64[i].abs() + len3(pts[i]));
        assert!(
            (d32[i] as f64 - d64[i]).abs() <= tol,
            "at {:?}: {} vs {}",
            pts[i],
            d32[i],
            d64[i]
        );
        material_mismatch += (m32[i] != m64[i]) as usize;
    }
    // Materials may differ only where two children are equally near (none at random points).
    assert_eq!(material_mismatch, 0);
}

fn batch_matches_reference<T: Float>() {
    let program = lower(&busy_scene());
    let pts = points(300);
    for chunk in [1, 7, 64] {
        for n in [0, 1, 63, 64, 65, 128, 300] {
            as_reference::<T>(&program, &pts[..n], chunk, &format!("n {n}"));
        }
    }
}

/// Asserts that a batch run of `program` at `chunk` points per pass gives the reference
/// path's distances and materials, bit for bit.
fn as_reference<T: Float>(program: &Program, pts: &[[f64; 3]], chunk: usize, what: &str) {
    let (d, m) = run_batch::<T>(program, Outputs::DistanceAndMaterial, chunk, pts);
    for (i, p) in pts.iter().enumerate() {
        let (rd, rm) = eval_point::<T>(program, p.map(T::from_f64));
        assert!(
            rd.to_f64().to_bits() == d[i].to_f64().to_bits() && rm == m[i],
            "{what}, chunk {chunk}, point {i}"
        );
    }
}

#[test]
fn batch_matches_the_reference_path_bit_for_bit() {
    batch_matches_reference::<f32>();
    batch_matches_reference::<f64>();
}

/// A row of spheres, each painted, as one union: a hierarchy of guarded groups.
fn row_scene() -> Scene {
    let mut b = Build::new();
    let ms = [
        b.material([1.0, 0.2, 0.2], 0.0, 0.0),
        b.material([0.2, 0.2, 1.0], 0.0, 0.0),
    ];
    let children = (0..24)
        .map(|i| {
            let s = b.add(Node::Sphere { radius: 0.3 });
            let s = b.at(s, [2.0 * i as f64, 0.0, 0.0]);
            b.paint(s, ms[i % 2])
        })
        .collect();
    let root = b.add(Node::Combine {
        op: Combine::Union,
        children,
    });
    b.finish(root)
}

/// Batches where most points are near one end of the row and a few near the other, so that
/// guarded blocks run on all, most (the interpreter then runs them on every point and keeps
/// the results where they run) and few of a batch's points: bit for bit the reference.
fn dense_and_sparse_blocks<T: Float>() {
    let program = lower(&row_scene());
    let mut rng = Rng::new(7);
    let pts: Vec<[f64; 3]> = (0..256)
        .map(|i| {
            let x = if i % 8 == 7 { 46.0 } else { 0.0 };
            let q = rng.point(1.5);
            [x + q[0], q[1], q[2]]
        })
        .collect();
    for chunk in [8, 16, 64, 256] {
        as_reference::<T>(&program, &pts, chunk, "a row of spheres");
    }
}

#[test]
fn blocks_run_on_most_or_few_points_as_the_reference() {
    dense_and_sparse_blocks::<f32>();
    dense_and_sparse_blocks::<f64>();
}

#[test]
fn distance_tape_drops_material_code() {
    let program = lower(&busy_scene());
    let full = Tape::new(&program, Outputs::DistanceAndMaterial);
    let dist = Tape::new(&program, Outputs::Distance);
    assert!(dist.len() < full.len(), "{} vs {}", dist.len(), full.len());
    let pts = points(100);
    let (a, _) = run_batch::<f32>(&program, Outputs::Distance, 32, &pts);
    let (b, _) = run_batch::<f32>(&program, Outputs::DistanceAndMaterial, 32, &pts);
    assert_eq!(a, b);
}

#[test]
fn slots_are_reused() {
    // A long chain of unions needs few live registers at a time.
    let mut b = Build::new();
    let kids: Vec<_> = (0..50)
        .map(|i| {
            let s = b.add(Node::Sphere { radius: 0.1 });
            b.at(s, [i as f64, 0.0, 0.0])
        })
        .collect();
    let root = b.add(Node::Combine {
        op: Combine::Union,
        children: kids,
    });
    let program = lower(&b.finish(root));
    let tape = Tape::new(&program, Outputs::Distance);
    assert!(
        tape.slot_count() < program.len() / 2,
        "{} slots for {} instructions",
        tape.slot_count(),
        program.len()
    );
}

/// One of each primitive, each moved off the origin (so that its length chains carry
/// offsets), some rounded, blended, repeated or rotated, and a tilted plane.
fn primitives_scene() -> Scene {
    let mut b = Build::new();
    let nodes = [
        Node::Sphere { radius: 0.5 },
        Node::Box {
            half: [0.4, 0.3, 0.5],
        },
        Node::RoundBox {
            half: [0.4, 0.3, 0.5],
            radius: 0.1,
        },
        Node::Torus {
            major: 0.6,
            minor: 0.2,
        },
        Node::Cylinder {
            radius: 0.3,
            half_height: 0.5,
        },
        Node::Capsule {
            radius: 0.3,
            half_height: 0.5,
        },
        Node::Cone {
            radius: 0.4,
            half_height: 0.5,
        },
        Node::Ellipsoid {
            radii: [0.3, 0.6, 0.4],
        },
    ];
    let mut kids = Vec::new();
    for (i, node) in nodes.into_iter().enumerate() {
        let n = b.add(node);
        let n = if i % 3 == 1 {
            b.add(Node::Round {
                radius: 0.05,
                child: n,
            })
        } else {
            n
        };
        kids.push(b.at(n, [i as f64 - 3.5, 0.25 * i as f64, -0.5]));
    }
    let blend = b.add(Node::SmoothCombine {
        op: Combine::Union,
        k: 0.3,
        variant: Smooth::Exp,
        a: kids[0],
        b: kids[1],
    });
    kids.push(blend);
    let s = b.add(Node::Sphere { radius: 0.3 });
    let rep = b.add(Node::Repeat {
        period: [2.0, 0.0, 2.0],
        count: None,
        child: s,
    });
    kids.push(rep);
    let (c, s) = (0.3f64.cos(), 0.3f64.sin());
    let t = b.add(Node::Torus {
        major: 0.5,
        minor: 0.1,
    });
    let t = b.add(Node::Rotate {
        matrix: [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
        child: t,
    });
    kids.push(b.at(t, [0.0, 1.5, 0.5]));
    kids.push(b.add(Node::Plane {
        normal: [0.6, 0.8, 0.0],
        height: -2.0,
    }));
    let root = b.add(Node::Combine {
        op: Combine::Union,
        children: kids,
    });
    b.finish(root)
}

/// Points with coordinates where fused and unfused arithmetic could part if they did not
/// perform the same operations: zeros of both signs, infinities, NaN, a subnormal, huge
/// values, the offsets of the scene itself; every combination of three.
fn special_points() -> Vec<[f64; 3]> {
    let values = [
        0.0,
        -0.0,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
        1e-40,
        -3e38,
        0.5,
        -3.5,
        -0.5,
    ];
    let mut pts = Vec::new();
    for &x in &values {
        for &y in &values {
            for &z in &values {
                pts.push([x, y, z]);
            }
        }
    }
    pts
}

fn same_bits<T: Float>(a: T, b: T) -> bool {
    a.to_f64().to_bits() == b.to_f64().to_bits() || (a.is_nan() && b.is_nan())
}

fn fused_matches_reference<T: Float>(program: &Program, pts: &[[f64; 3]], what: &str) {
    for outputs in [Outputs::Distance, Outputs::DistanceAndMaterial] {
        for chunk in [1, 64, 256] {
            let (d, m) = run_batch::<T>(program, outputs, chunk, pts);
            for (i, p) in pts.iter().enumerate() {
                let (rd, rm) = eval_point::<T>(program, p.map(T::from_f64));
                assert!(
                    same_bits(rd, d[i]),
                    "{what}, {outputs:?}, chunk {chunk}, point {p:?}: {} vs {}",
                    rd.to_f64(),
                    d[i].to_f64()
                );
                if outputs == Outputs::DistanceAndMaterial {
                    assert_eq!(rm, m[i], "{what}, chunk {chunk}, point {p:?}");
                }
            }
        }
    }
}

#[test]
fn fused_steps_match_the_reference_bit_for_bit() {
    let mut pts = special_points();
    pts.extend(points(500));
    for (what, scene) in [("primitives", primitives_scene()), ("busy", busy_scene())] {
        for level in [0, 1] {
            let program = lower_with(&scene, &LowerOptions::level(level));
            let what = format!("{what} at level {level}");
            fused_matches_reference::<f32>(&program, &pts, &what);
            fused_matches_reference::<f64>(&program, &pts, &what);
        }
    }
}

#[test]
fn the_sums_of_distance_programs_are_one_step_each() {
    let steps = |scene: Scene| Tape::new(&lower(&scene), Outputs::Distance).len();
    // `length(p - c) - r`: three offsets, three squares, two sums, a root and the radius.
    let mut b = Build::new();
    let s = b.add(Node::Sphere { radius: 0.5 });
    let root = b.at(s, [1.0, -2.0, 0.5]);
    let scene = b.finish(root);
    assert!(lower(&scene).len() > 10, "{}", lower(&scene).len());
    assert_eq!(steps(scene), 1);
    // A torus is two lengths, the second of the first minus the major radius.
    let mut b = Build::new();
    let t = b.add(Node::Torus {
        major: 1.0,
        minor: 0.25,
    });
    let root = b.at(t, [0.5, 0.0, 0.0]);
    assert_eq!(steps(b.finish(root)), 2);
    // A tilted plane is `n·p - h`: products with constants, a sum and an offset.
    assert_eq!(
        steps(single(Node::Plane {
            normal: [0.6, 0.8, 0.0],
            height: 0.5,
        })),
        1
    );
}

#[test]
fn random_scenes_run_bit_for_bit_as_the_reference() {
    let mut rng = Rng::new(2026);
    let mut pts = special_points();
    pts.extend(points(200));
    for case in 0..40 {
        let scene = random_scene(&mut rng, 1 + case % 6);
        for level in [0, 1] {
            let program = lower_with(&scene, &LowerOptions::level(level));
            let what = format!("random scene {case} at level {level}");
            fused_matches_reference::<f32>(&program, &pts, &what);
            fused_matches_reference::<f64>(&program, &pts, &what);
        }
    }
}
