//! Sampling the Lipschitz bound of every user field (`sdfc check --verify-bounds`): each field
//! is lowered alone, as written, and evaluated in f64 at pairs of nearby points over the
//! scene's bounded region and over the field's own region, both carried into the field's
//! coordinates; a slope above the field's declared or derived L is a violation. Sampling
//! proves nothing: the result says where, and with how many pairs, no steeper slope was found.

use super::eval_point;
use crate::lower::{lower_with, LowerOptions};
use crate::rng::Rng;
use crate::scene::analysis::{regions, Aabb};
use crate::scene::bounds::Bounds;
use crate::scene::{Node, NodeId, Scene, V3};

/// A pair of points where a field changes faster than its bound allows.
#[derive(Debug, Clone, PartialEq)]
pub struct Violation {
    /// The field.
    pub node: NodeId,
    /// Its L (declared, or derived from the expression).
    pub bound: f64,
    /// The largest slope sampled, |f(a) − f(b)| / |a − b|.
    pub slope: f64,
    /// Where: the two points.
    pub at: (V3, V3),
}

/// A box: its lower and upper corners.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Region {
    pub min: V3,
    pub max: V3,
}

/// The scene's bounded region, in the scene's coordinates: the root's box (`scene/bounds.rs`),
/// clipped along the axes where it is unbounded (a plane, a field, an infinite repetition) to
/// within `max_dist` of the camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scope {
    pub region: Region,
    /// The axes clipped to within `max_dist` of the camera.
    pub clipped: [bool; 3],
}

/// Which region a field was sampled over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Over {
    /// The scene's bounded region ([`Scope`]), carried into the field's coordinates.
    Scene,
    /// The same cut, at each node above the field, to that node's box: the part around the
    /// shape the field is in.
    Own,
}

/// What was sampled of one field, and the steepest slope above its bound, if any.
#[derive(Debug, Clone, PartialEq)]
pub struct Sampled {
    /// The field.
    pub node: NodeId,
    /// Its L (declared, or derived from the expression).
    pub bound: f64,
    /// The boxes sampled, in the field's coordinates, with the pairs of points in each.
    pub regions: Vec<(Over, Region, usize)>,
    /// The steepest slope above the bound found there.
    pub violation: Option<Violation>,
}

/// A field that was not sampled, and why.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unsampled {
    /// No bound is declared or proven: there is nothing to check.
    NoBound,
    /// No ray reaches it within the scene's region (a part outside it).
    Unreached,
}

/// The result of [`verify_fields`].
#[derive(Debug, Clone, PartialEq)]
pub struct Verification {
    /// The scene's bounded region.
    pub scope: Scope,
    /// Each field with a bound that the region reaches.
    pub sampled: Vec<Sampled>,
    /// The others.
    pub unsampled: Vec<(NodeId, Unsampled)>,
}

/// The scene's bounded region ([`Scope`]).
pub fn scope(scene: &Scene) -> Scope {
    let reach = scene.settings.max_dist.max(0.0);
    let eye = scene.camera.position;
    let bound = scene.root.and_then(|r| Bounds::new(&scene.graph).get(r));
    let mut out = Scope {
        region: Region {
            min: [0.0; 3],
            max: [0.0; 3],
        },
        clipped: [false; 3],
    };
    for (i, e) in eye.iter().enumerate() {
        let (lo, hi) = match bound {
            Some(b) if b.aabb.h[i].is_finite() => {
                (b.aabb.c[i] - b.aabb.h[i], b.aabb.c[i] + b.aabb.h[i])
            }
            _ => {
                out.clipped[i] = true;
                (e - reach, e + reach)
            }
        };
        out.region.min[i] = lo;
        out.region.max[i] = hi;
    }
    out
}

/// The fields of `scene` with a bound (declared or derived), each sampled at `pairs` pairs of
/// points over the scene's bounded region and, where it is smaller, at as many over the
/// field's own region (both in the field's coordinates): the steepest slope of each field
/// above its L, if any.
pub fn verify_fields(scene: &Scene, pairs: usize) -> Verification {
    let analysis = crate::scene::analysis::analyse(scene);
    let scope = scope(scene);
    let start = Aabb {
        min: scope.region.min,
        max: scope.region.max,
    };
    let bounds = Bounds::new(&scene.graph);
    let wide = regions(scene, start, None);
    let own = regions(scene, start, Some(&bounds));
    let mut out = Verification {
        scope,
        sampled: Vec::new(),
        unsampled: Vec::new(),
    };
    for id in scene.graph.ids() {
        let Node::Field { .. } = scene.graph.node(id) else {
            continue;
        };
        let i = id.0 as usize;
        let d = analysis.node(id);
        if !d.proven {
            out.unsampled.push((id, Unsampled::NoBound));
            continue;
        }
        // A region the maps above made unbounded is clipped to the reach around the origin.
        let finite = |r: Aabb| {
            let reach = scene.settings.max_dist.max(0.0);
            Region {
                min: r.min.map(|x| if x.is_finite() { x } else { -reach }),
                max: r.max.map(|x| if x.is_finite() { x } else { reach }),
            }
        };
        if wide[i].is_empty() {
            out.unsampled.push((id, Unsampled::Unreached));
            continue;
        }
        let mut list = vec![(Over::Scene, finite(wide[i]), pairs)];
        if !own[i].is_empty() && own[i] != wide[i] {
            list.push((Over::Own, finite(own[i]), pairs));
        }
        let bound = d.facts.lipschitz;
        let violation = list
            .iter()
            .enumerate()
            .filter_map(|(k, (_, r, n))| sample_field(scene, id, bound, *r, *n, k as u64))
            .max_by(|a, b| a.slope.total_cmp(&b.slope));
        out.sampled.push(Sampled {
            node: id,
            bound,
            regions: list,
            violation,
        });
    }
    out
}

/// Field `id` of `scene`, lowered alone, sampled at `pairs` pairs of points in `region` (its
/// coordinates), a step of 10⁻³ or 0.05 apart: the steepest slope above `bound`, if any.
/// `stream` varies the points drawn for the same field.
pub fn sample_field(
    scene: &Scene,
    id: NodeId,
    bound: f64,
    region: Region,
    pairs: usize,
    stream: u64,
) -> Option<Violation> {
    let mut alone = scene.clone();
    alone.root = Some(id);
    let program = lower_with(&alone, &LowerOptions::level(0));
    let f = |p: V3| eval_point::<f64>(&program, p).0;
    let mut rng = Rng::new((u64::from(id.0) + 1) ^ (stream << 32));
    let mut worst: Option<Violation> = None;
    for i in 0..pairs {
        let a: V3 = [0, 1, 2].map(|k| rng.range(region.min[k], region.max[k]));
        let h = if i % 2 == 0 { 1e-3 } else { 0.05 };
        let dir = rng.point(1.0);
        let len = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
        if len < 1e-3 {
            continue;
        }
        let b: V3 = [0, 1, 2].map(|k| a[k] + dir[k] / len * h);
        let (fa, fb) = (f(a), f(b));
        if !(fa.is_finite() && fb.is_finite()) {
            continue;
        }
        let slope = (fa - fb).abs() / h;
        // Rounding of the two values, relative to the step.
        let slack = 1e-9 * (1.0 + fa.abs().max(fb.abs())) / h;
        if slope > bound * (1.0 + 1e-6) + slack && worst.as_ref().is_none_or(|w| slope > w.slope) {
            worst = Some(Violation {
                node: id,
                bound,
                slope,
                at: (a, b),
            });
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::front::check_str;
    use crate::lower::lower;
    use crate::scene::analysis::analyse;

    fn scene(body: &str) -> Scene {
        let text =
            format!("camera {{ position: (0, 0, -5), look_at: (0, 0, 0) }}\nscene {{ {body}; }}");
        let (s, diags, _) = check_str("field.sdf", &text);
        s.unwrap_or_else(|| panic!("{body}: {diags:?}"))
    }

    /// The largest difference between two scenes' distances at random points.
    fn difference(a: &str, b: &str) -> f64 {
        let (pa, pb) = (lower(&scene(a)), lower(&scene(b)));
        let mut rng = Rng::new(7);
        let mut worst = 0f64;
        for _ in 0..500 {
            let p = rng.point(3.0);
            let (x, y) = (eval_point::<f64>(&pa, p).0, eval_point::<f64>(&pb, p).0);
            worst = worst.max((x - y).abs());
            let q = p.map(|c| c as f32);
            let (x, y) = (eval_point::<f32>(&pa, q).0, eval_point::<f32>(&pb, q).0);
            worst = worst.max(f64::from((x - y).abs()) * 1e-3);
        }
        worst
    }

    #[test]
    fn fields_equal_the_builtin_shapes_they_spell() {
        assert!(difference("field { length(p) - 1 }", "sphere(1)") < 1e-12);
        assert!(
            difference(
                "field { distance(box(0.7), p) - 0.1 }",
                "box(0.7).round(0.1)"
            ) < 1e-12
        );
        assert!(
            difference(
                "field { distance(sphere(1), p) + 0 * noise(p * 4) }",
                "sphere(1)"
            ) < 1e-12
        );
        // Transforms apply to a field as to any shape.
        assert!(
            difference(
                "field { length(p.xz) - 0.5 }.translate(1, 0, 0).rotate_y(30deg)",
                "field { length(vec2(p.x, p.z)) - 0.5 }.translate(1, 0, 0).rotate_y(30deg)"
            ) < 1e-12
        );
    }

    /// A field spelling a built-in shape lowers to the built-in's instructions: the field
    /// path costs nothing per step on any back end.
    #[test]
    fn fields_lower_to_the_programs_of_the_builtins_they_spell() {
        for (field, builtin) in [
            ("field { length(p) - 1 }", "sphere(1)"),
            (
                "field { distance(box(0.7), p) - 0.1 }",
                "box(0.7).round(0.1)",
            ),
        ] {
            let (a, b) = (lower(&scene(field)), lower(&scene(builtin)));
            assert_eq!(a.ops(), b.ops(), "{field} and {builtin}");
        }
    }

    fn derived(body: &str) -> (f64, bool) {
        let s = scene(body);
        let a = analyse(&s);
        let root = a.root().expect("root");
        (root.facts.lipschitz, root.proven)
    }

    #[test]
    fn bounds_are_derived_from_the_expression() {
        assert_eq!(derived("field { length(p) - 1 }"), (1.0, true));
        assert_eq!(derived("field { 2 * (length(p) - 1) }"), (2.0, true));
        assert_eq!(
            derived("field { distance(box(0.7), p) - 0.1 }"),
            (1.0, true)
        );
        assert_eq!(derived("field(lipschitz: 3) { p.x * p.y }"), (3.0, true));
        // A product of unbounded coordinates, a floor across integers: nothing proven.
        assert!(!derived("field { p.x * p.y }").1);
        assert!(!derived("field { floor(p.x) }").1);
        let (l, proven) =
            derived("field { sin(p.x) * cos(p.y) + sin(p.y) * cos(p.z) + sin(p.z) * cos(p.x) }");
        assert!(proven && l <= 3.5, "gyroid L = {l}");
    }

    /// A random field expression of the point, from the operations the bound analysis rules.
    fn random_expr(rng: &mut Rng, depth: u32) -> String {
        let leaves = ["p.x", "p.y", "p.z", "length(p)"];
        let forms = [
            "({a} + {b})",
            "({a} - {b})",
            "({a} * 0.7)",
            "sin({a})",
            "cos({a} * 2)",
            "abs({a})",
            "min({a}, {b})",
            "max({a}, {b})",
            "sqrt({a} * {a} + 1)",
            "smoothstep(-1, 1, {a})",
            "noise(vec3({a}, {b}, p.z))",
            "(sin({a}) * cos({b}))",
            "exp(-abs({a}))",
            "distance(torus(1, 0.3), vec3({a}, p.y, {b}))",
        ];
        rng.formula(depth, &leaves, &forms)
    }

    #[test]
    fn derived_bounds_are_never_below_sampled_slopes() {
        let mut rng = Rng::new(34);
        let mut proven = 0;
        for _ in 0..60 {
            let e = random_expr(&mut rng, 3);
            let s = scene(&format!("field {{ {e} }}"));
            let v = verify_fields(&s, 400);
            assert!(
                v.sampled.iter().all(|f| f.violation.is_none()),
                "{e}: {v:?}"
            );
            // Denser near the origin, where the expressions vary most.
            if let Some(root) = s.root.filter(|&r| analyse(&s).node(r).proven) {
                let bound = analyse(&s).node(root).facts.lipschitz;
                let v = sample_field(&s, root, bound, near(3.0), 400, 0);
                assert!(v.is_none(), "{e}: {v:?}");
            }
            proven += usize::from(analyse(&s).root().is_some_and(|r| r.proven));
        }
        assert!(proven > 30, "only {proven} of 60 fields have a bound");
    }

    /// The box `[-r, r]³`.
    fn near(r: f64) -> Region {
        Region {
            min: [-r; 3],
            max: [r; 3],
        }
    }

    fn violations(v: &Verification) -> Vec<&Violation> {
        v.sampled
            .iter()
            .filter_map(|f| f.violation.as_ref())
            .collect()
    }

    #[test]
    fn a_declared_bound_that_is_too_small_is_caught() {
        let s = scene("field(lipschitz: 1) { 3 * (length(p) - 1) }");
        let v = verify_fields(&s, 200);
        let found = violations(&v);
        assert_eq!(found.len(), 1);
        assert!(found[0].slope > 2.9 && found[0].bound == 1.0, "{v:?}");
        assert!(violations(&verify_fields(
            &scene("field(lipschitz: 3) { 3 * (length(p) - 1) }"),
            200
        ))
        .is_empty());
    }

    /// A field steeper than its bound only far from the camera's target, inside the box of
    /// the shape it is cut to: sampled over that box, in the field's coordinates (moved and
    /// turned), it is caught; a field the box cuts nothing from is sampled over the scene's
    /// region, clipped to within `max_dist` of the camera where the scene is unbounded.
    #[test]
    fn fields_are_sampled_over_the_scene_and_their_own_boxes() {
        let s = scene(
            "intersect(field(lipschitz: 1) { length(p) - 1 + 0.5 * max(p.x - 6, 0) }, box(9)).rotate_y(90deg).translate(20, 0, 0)",
        );
        let v = verify_fields(&s, 2000);
        assert_eq!(v.sampled.len(), 1, "{v:?}");
        let f = &v.sampled[0];
        let w = f.violation.as_ref().expect("caught");
        assert!(w.slope > 1.2 && w.at.0[0] > 6.0, "{w:?}");
        // The scene's box is the box(9) moved; the field's own box is box(9) itself.
        assert_eq!(v.scope.clipped, [false; 3]);
        assert!((v.scope.region.min[0] - 11.0).abs() < 0.1, "{:?}", v.scope);
        let (over, r, n) = f.regions[0];
        assert_eq!((over, n), (Over::Scene, 2000));
        assert!(
            (r.min[0] + 9.0).abs() < 0.1 && (r.max[2] - 9.0).abs() < 0.1,
            "{r:?}"
        );
        // Unbounded: the camera's reach.
        let s = scene("field(lipschitz: 1) { length(p) - 1 }; plane((0, 1, 0), -2)");
        let v = verify_fields(&s, 100);
        assert_eq!(v.scope.clipped, [true; 3]);
        assert_eq!(v.scope.region.min[2], -105.0);
        assert!(violations(&v).is_empty());
        // A field with no bound is not sampled, and said so.
        let v = verify_fields(&scene("field { p.x * p.y }"), 100);
        assert!(v.sampled.is_empty());
        assert_eq!(v.unsampled.len(), 1);
        assert_eq!(v.unsampled[0].1, Unsampled::NoBound);
    }

    #[test]
    fn noise_stays_within_its_range_and_bound() {
        use crate::scene::field::{NOISE_LIPSCHITZ, NOISE_RANGE};
        for body in [
            "field { noise(p) }",
            "field { noise(p.xz) }",
            "field { voronoi(p) }",
            "field { voronoi(p.xy) }",
        ] {
            let program = lower_with(&scene(body), &LowerOptions::level(0));
            let mut rng = Rng::new(3);
            let voronoi = body.contains("voronoi");
            let (mut lo, mut hi, mut slope) = (f64::MAX, f64::MIN, 0f64);
            for _ in 0..4000 {
                let a = rng.point(20.0);
                let dir = rng.point(1.0);
                let b = [0, 1, 2].map(|k| a[k] + dir[k] * 1e-4);
                let len = (0..3).map(|k| (b[k] - a[k]).powi(2)).sum::<f64>().sqrt();
                let (fa, fb) = (
                    eval_point::<f64>(&program, a).0,
                    eval_point::<f64>(&program, b).0,
                );
                lo = lo.min(fa);
                hi = hi.max(fa);
                slope = slope.max((fa - fb).abs() / len);
                // f32 agrees with f64: the lattice hashes are exact in both.
                let g = eval_point::<f32>(&program, a.map(|c| c as f32)).0;
                assert!(
                    (f64::from(g) - fa).abs() < 1e-3,
                    "{body} at {a:?}: {g} and {fa}"
                );
            }
            if voronoi {
                assert!(
                    lo >= 0.0 && hi <= 0.7 * 3f64.sqrt() && slope <= 1.0 + 1e-6,
                    "{body}: [{lo}, {hi}], slope {slope}"
                );
            } else {
                assert!(
                    lo >= -NOISE_RANGE && hi <= NOISE_RANGE,
                    "{body}: [{lo}, {hi}]"
                );
                assert!(hi - lo > 0.6, "{body}: [{lo}, {hi}] is flat");
                assert!(slope <= NOISE_LIPSCHITZ, "{body}: slope {slope}");
            }
        }
    }
}
