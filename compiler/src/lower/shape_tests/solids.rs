//! The solids of `shapes.rs` with nodes of their own: cones, segments, prisms, polyhedra,
//! frames and links are exact and equal the shapes they generalise; `reflect`; the shapes
//! between two points.

use super::{exact, f, len, program, same};
use glam::DVec3;

const S3: f64 = 1.732_050_807_568_877_2;

#[test]
fn capped_cone_is_exact_and_generalises_cylinder_and_cone() {
    exact("capped_cone(1.2, 0.7, 0.3)", |p| {
        let r = 0.5 - p[1] / 1.2 * 0.4;
        p[1].abs() < 0.6 && p[0].hypot(p[2]) < r
    });
    exact("capped_cone(1, 0.2, 0.9)", |p| {
        let r = 0.55 + p[1] * 0.7;
        p[1].abs() < 0.5 && p[0].hypot(p[2]) < r
    });
    same("capped_cone(1.4, 0.6, 0.6)", "cylinder(0.6, 1.4)");
    same("capped_cone(1.4, 0.6, 0)", "cone(0.6, 1.4)");
}

#[test]
fn round_cone_is_exact() {
    exact("round_cone(0.5, 0.2, 1)", |p| {
        // Inside the hull of the two spheres: within the radius interpolated along the
        // tangent cone, or inside either sphere.
        let (r1, r2, h) = (0.5, 0.2, 1.0);
        let q = (p[0].hypot(p[2]), p[1] + 0.5);
        let s = (r1 - r2) / h;
        let c = (1.0f64 - s * s).sqrt();
        let k = -s * q.0 + c * q.1;
        let side = q.0 * c + q.1 * s - r1;
        q.0.hypot(q.1) < r1 || q.0.hypot(q.1 - h) < r2 || (k >= 0.0 && k <= c * h && side < 0.0)
    });
    same("round_cone(0.4, 0.4, 1.2)", "capsule(0.4, 1.2)");
}

#[test]
fn segment_is_a_capsule_between_two_points() {
    same(
        "segment((0, -0.6, 0), (0, 0.6, 0), 0.3)",
        "capsule(0.3, 1.2)",
    );
    same(
        "segment((0.2, -0.1, 0.4), (0.2, 0.9, 0.4), 0.25)",
        "capsule(0.25, 1).translate(0.2, 0.4, 0.4)",
    );
    same(
        "segment((0.3, 0, 0), (0.3, 0, 0), 0.5)",
        "sphere(0.5).translate(0.3, 0, 0)",
    );
    exact("segment((-0.5, -0.3, 0.2), (0.6, 0.4, -0.1), 0.3)", |p| {
        let (a, b) = (DVec3::new(-0.5, -0.3, 0.2), DVec3::new(0.6, 0.4, -0.1));
        let (ba, pa) = (b - a, DVec3::from(p) - a);
        let t = (pa.dot(ba) / ba.length_squared()).clamp(0.0, 1.0);
        (pa - ba * t).length() < 0.3
    });
}

#[test]
fn rounded_cylinder_is_a_rounded_smaller_cylinder() {
    same("rounded_cylinder(0.6, 0, 1.2)", "cylinder(0.6, 1.2)");
    same(
        "rounded_cylinder(0.6, 0.15, 1.2)",
        "cylinder(0.45, 0.9).round(0.15)",
    );
    exact("rounded_cylinder(0.7, 0.2, 1)", |p| {
        let (x, y) = (p[0].hypot(p[2]) - 0.5, p[1].abs() - 0.3);
        let d = x.max(y).min(0.0) + x.max(0.0).hypot(y.max(0.0));
        d < 0.2
    });
}

#[test]
fn prisms_are_exact() {
    exact("hex_prism(0.6, 1.4)", |p| {
        let (x, z) = (p[0].abs(), p[2].abs());
        p[1].abs() < 0.7 && z < 0.6 && z * 0.5 + x * S3 * 0.5 < 0.6
    });
    exact("tri_prism(0.4, 1)", |p| {
        // Sides 0.4 from the axis: z > -0.4 and the two sides through the corner (0, 0.8).
        let (x, z) = (p[0].abs(), p[2]);
        p[1].abs() < 0.5 && z > -0.4 && x * S3 * 0.5 + z * 0.5 < 0.4
    });
}

#[test]
fn octahedron_pyramid_frame_and_link_are_exact() {
    exact("octahedron(1.1)", |p| {
        p[0].abs() + p[1].abs() + p[2].abs() < 1.1
    });
    exact("pyramid(1.2, 1.5)", |p| {
        // Base y = -0.75 of half-side 0.6, apex at y = 0.75.
        let t = (p[1] + 0.75) / 1.5;
        (0.0..1.0).contains(&t) && p[0].abs().max(p[2].abs()) < 0.6 * (1.0 - t)
    });
    exact("box_frame((0.8, 0.6, 0.5), 0.1)", |p| {
        let q = [p[0].abs(), p[1].abs(), p[2].abs()];
        let h = [0.8, 0.6, 0.5];
        let inside = (0..3).all(|i| q[i] < h[i]);
        let near = (0..3).filter(|&i| q[i] > h[i] - 0.2).count();
        inside && near >= 2
    });
    exact("link(0.6, 0.5, 0.15)", |p| {
        let y = (p[1].abs() - 0.3).max(0.0);
        (p[0].hypot(y) - 0.5).hypot(p[2]) < 0.15
    });
}

#[test]
fn infinite_shapes_equal_huge_finite_ones_near_the_origin() {
    same("slab(0.5)", "box((1e6, 0.25, 1e6))");
    same("slab(0.5, (0, 0, 2))", "box((1e6, 1e6, 0.25))");
    same("infinite_cylinder(0.4)", "cylinder(0.4, 2e6)");
    same(
        "infinite_cylinder(0.4, (1, 0, 0))",
        "cylinder(0.4, 2e6).rotate_z(90deg)",
    );
    exact("infinite_cylinder(0.3, (1, 1, 0))", |p| {
        let t = (p[0] + p[1]) * 0.5;
        len([p[0] - t, p[1] - t, p[2]]) < 0.3
    });
    exact("slab(0.6, (1, 2, -1))", |p| {
        (p[0] + 2.0 * p[1] - p[2]).abs() / 6f64.sqrt() < 0.3
    });
}

#[test]
fn reflect_is_one_mirror_image_where_mirror_folds() {
    // A sphere at +x reflected across x = 0 is the sphere at -x, and only that one; `mirror`
    // keeps both.
    same(
        "sphere(0.5).translate(1, 0.2, 0).reflect((1, 0, 0))",
        "sphere(0.5).translate(-1, 0.2, 0)",
    );
    let (folded, _) = program("sphere(0.5).translate(1, 0.2, 0).mirror()");
    let (reflected, l) = program("sphere(0.5).translate(1, 0.2, 0).reflect((2, 0, 0))");
    assert_eq!(l, 1.0);
    assert!(f(&folded, [1.0, 0.2, 0.0]) < 0.0 && f(&folded, [-1.0, 0.2, 0.0]) < 0.0);
    assert!(f(&reflected, [1.0, 0.2, 0.0]) > 0.0 && f(&reflected, [-1.0, 0.2, 0.0]) < 0.0);
    // Any plane through the origin: a point goes to p − 2(p·n)n.
    same(
        "box((0.2, 0.3, 0.4)).translate(0.5, 0.1, 0).reflect((1, 1, 0))",
        "box((0.3, 0.2, 0.4)).translate(-0.1, -0.5, 0)",
    );
    exact(
        "box((0.3, 0.2, 0.1)).translate(0.4, 0, 0).reflect((0, 0, 1))",
        |x| (x[0] - 0.4).abs() < 0.3 && x[1].abs() < 0.2 && x[2].abs() < 0.1,
    );
    // Profiles reflect across a line of the plane.
    same(
        "extrude(circle(0.3).translate(0.5, 0.2).reflect((0, 1)), 0.4)",
        "extrude(circle(0.3).translate(0.5, -0.2), 0.4)",
    );
}

/// The frame of the segment from `a` to `b` at `p`: (the distance from the axis, the
/// distance along it from `a`), and the segment's length.
fn along(a: [f64; 3], b: [f64; 3], p: [f64; 3]) -> ((f64, f64), f64) {
    let ab = [0, 1, 2].map(|i| b[i] - a[i]);
    let l = len(ab);
    let u = ab.map(|x| x / l);
    let ap = [0, 1, 2].map(|i| p[i] - a[i]);
    let t = (0..3).map(|i| ap[i] * u[i]).sum::<f64>();
    let radial = len([0, 1, 2].map(|i| ap[i] - t * u[i]));
    ((radial, t), l)
}

#[test]
fn shapes_between_two_points_are_exact_and_their_y_aligned_shapes_moved() {
    same(
        "cylinder((0, -0.7, 0), (0, 0.7, 0), 0.5)",
        "cylinder(0.5, 1.4)",
    );
    same("cone((0, -0.6, 0), (0, 0.6, 0), 0.6, 0)", "cone(0.6, 1.2)");
    same(
        "round_cone((0, -0.5, 0), (0, 0.5, 0), 0.5, 0.2)",
        "round_cone(0.5, 0.2, 1)",
    );
    // Turned: b → a along y is the same solid as a → b upside down.
    same(
        "cone((0, 0.6, 0), (0, -0.6, 0), 0.2, 0.5)",
        "capped_cone(1.2, 0.5, 0.2)",
    );
    let (a, b) = ([-0.5, -0.4, 0.3], [0.6, 0.5, -0.2]);
    exact("cylinder((-0.5, -0.4, 0.3), (0.6, 0.5, -0.2), 0.35)", |p| {
        let ((r, t), l) = along(a, b, p);
        t > 0.0 && t < l && r < 0.35
    });
    exact("cone((-0.5, -0.4, 0.3), (0.6, 0.5, -0.2), 0.5, 0.1)", |p| {
        let ((r, t), l) = along(a, b, p);
        t > 0.0 && t < l && r < 0.5 + (0.1 - 0.5) * t / l
    });
    exact(
        "round_cone((-0.5, -0.4, 0.3), (0.6, 0.5, -0.2), 0.45, 0.2)",
        |p| {
            // As round_cone_is_exact, in the segment's frame.
            let ((r, t), h) = along(a, b, p);
            let (r1, r2) = (0.45, 0.2);
            let s = (r1 - r2) / h;
            let c = (1.0f64 - s * s).sqrt();
            let k = -s * r + c * t;
            let side = r * c + t * s - r1;
            r.hypot(t) < r1 || r.hypot(t - h) < r2 || (k >= 0.0 && k <= c * h && side < 0.0)
        },
    );
}
