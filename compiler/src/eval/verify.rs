//! Sampling the Lipschitz bound of every user field (`sdfc check --verify-bounds`): each field
//! is lowered alone, as written, and evaluated in f64 at pairs of nearby points around the
//! camera's target; a slope above the field's declared or derived L is a violation.

use super::eval_point;
use crate::lower::{lower_with, LowerOptions};
use crate::rng::Rng;
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

/// The fields of `scene` with a bound (declared or derived), sampled at `pairs` pairs of
/// points each within `reach` of the camera's target: the worst violation of each field
/// whose slope exceeds its L, if any.
pub fn verify_fields(scene: &Scene, pairs: usize, reach: f64) -> Vec<Violation> {
    let analysis = crate::scene::analysis::analyse(scene);
    let mut out = Vec::new();
    for id in scene.graph.ids() {
        let Node::Field { .. } = scene.graph.node(id) else {
            continue;
        };
        let d = analysis.node(id);
        if !d.proven {
            continue;
        }
        let bound = d.facts.lipschitz;
        let mut alone = scene.clone();
        alone.root = Some(id);
        let program = lower_with(&alone, &LowerOptions::level(0));
        let f = |p: V3| eval_point::<f64>(&program, p).0;
        let mut rng = Rng::new(u64::from(id.0) + 1);
        let centre = scene.camera.look_at;
        let mut worst: Option<Violation> = None;
        for i in 0..pairs {
            let o = rng.point(reach);
            let a: V3 = [0, 1, 2].map(|k| centre[k] + o[k]);
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
            if slope > bound * (1.0 + 1e-6) + slack
                && worst.as_ref().is_none_or(|w| slope > w.slope)
            {
                worst = Some(Violation {
                    node: id,
                    bound,
                    slope,
                    at: (a, b),
                });
            }
        }
        out.extend(worst);
    }
    out
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
        let leaf = |rng: &mut Rng| match rng.below(5) {
            0 => "p.x".to_string(),
            1 => "p.y".to_string(),
            2 => "p.z".to_string(),
            3 => "length(p)".to_string(),
            _ => format!("{:.2}", rng.range(-2.0, 2.0)),
        };
        if depth == 0 {
            return leaf(rng);
        }
        let mut e = || random_expr(rng, depth - 1);
        let (a, b) = (e(), e());
        match rng.below(14) {
            0 => format!("({a} + {b})"),
            1 => format!("({a} - {b})"),
            2 => format!("({a} * 0.7)"),
            3 => format!("sin({a})"),
            4 => format!("cos({a} * 2)"),
            5 => format!("abs({a})"),
            6 => format!("min({a}, {b})"),
            7 => format!("max({a}, {b})"),
            8 => format!("sqrt({a} * {a} + 1)"),
            9 => format!("smoothstep(-1, 1, {a})"),
            10 => format!("noise(vec3({a}, {b}, p.z))"),
            11 => format!("(sin({a}) * cos({b}))"),
            12 => format!("exp(-abs({a}))"),
            _ => format!("distance(torus(1, 0.3), vec3({a}, p.y, {b}))"),
        }
    }

    #[test]
    fn derived_bounds_are_never_below_sampled_slopes() {
        let mut rng = Rng::new(34);
        let mut proven = 0;
        for _ in 0..60 {
            let e = random_expr(&mut rng, 3);
            let s = scene(&format!("field {{ {e} }}"));
            let v = verify_fields(&s, 400, 3.0);
            assert!(v.is_empty(), "{e}: {v:?}");
            proven += usize::from(analyse(&s).root().is_some_and(|r| r.proven));
        }
        assert!(proven > 30, "only {proven} of 60 fields have a bound");
    }

    #[test]
    fn a_declared_bound_that_is_too_small_is_caught() {
        let s = scene("field(lipschitz: 1) { 3 * (length(p) - 1) }");
        let v = verify_fields(&s, 200, 2.0);
        assert_eq!(v.len(), 1);
        assert!(v[0].slope > 2.9 && v[0].bound == 1.0, "{v:?}");
        assert!(verify_fields(
            &scene("field(lipschitz: 3) { 3 * (length(p) - 1) }"),
            200,
            2.0
        )
        .is_empty());
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
