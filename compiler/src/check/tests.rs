//! Unit tests of constant evaluation and of the checker's diagnostics.

use super::check_str;
use crate::scene::{Light, Node};

fn ok(src: &str) -> crate::scene::Scene {
    let (scene, diags, _) = check_str("t.sdf", src);
    assert!(
        diags.iter().all(|d| !d.is_error()),
        "unexpected errors: {diags:#?}"
    );
    scene.expect("scene")
}

fn codes(src: &str) -> Vec<&'static str> {
    let (_, diags, _) = check_str("t.sdf", src);
    diags.iter().map(|d| d.code).collect()
}

#[test]
fn evaluates_constants_and_functions() {
    let s = ok("let r = 0.25 * 2 + 1;\nfn ball(x: float = r) -> shape { let k = x * 2; sphere(k) }\nscene { ball(); }");
    let root = s.root.expect("root");
    assert_eq!(s.graph.node(root), &Node::Sphere { radius: 3.0 });
}

#[test]
fn angles_and_vectors() {
    let s =
        ok("let a = 90deg / 2;\nlet v = (1, 2, 3) * 2 - vec3(1);\nscene { box(v).rotate_y(a); }");
    let root = s.root.expect("root");
    let Node::Rotate { matrix, child } = s.graph.node(root) else {
        panic!("not a rotation")
    };
    assert!((matrix[0][0] - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-12);
    assert_eq!(
        s.graph.node(*child),
        &Node::Box {
            half: [1.0, 3.0, 5.0]
        }
    );
}

#[test]
fn loops_if_and_hash() {
    let s = ok("scene { for i in 0..4 { sphere(if i % 2 == 0 { 0.5 } else { 0.25 }).translate(i, 0, 0); } }");
    let Node::Combine { children, .. } = s.graph.node(s.root.expect("root")) else {
        panic!()
    };
    assert_eq!(children.len(), 4);
}

#[test]
fn shared_shapes_are_one_node() {
    let s = ok("let b = sphere(1);\nscene { union(b.translate(1, 0, 0), b.translate(-1, 0, 0)); }");
    let spheres = s
        .graph
        .ids()
        .filter(|id| matches!(s.graph.node(*id), Node::Sphere { .. }))
        .count();
    assert_eq!(spheres, 1);
}

#[test]
fn lights_are_normalised() {
    let s = ok("light directional { direction: (0, -2, 0) }\nscene { sphere(); }");
    assert_eq!(
        s.lights[0],
        Light::Directional {
            direction: [0.0, -1.0, 0.0],
            color: [1.0; 3],
            intensity: 1.0,
            penumbra: 0.0
        }
    );
}

#[test]
fn reports_mistakes() {
    assert_eq!(codes("scene { spher(1); }"), ["E0201"]);
    assert_eq!(codes("scene { sphere(-1); }"), ["E0400"]);
    assert_eq!(codes("scene { sphere(radius: 1, radius: 2); }"), ["E0203"]);
    assert_eq!(codes("scene { torus(1, 0.2).rotate_x(90); }"), ["E0300"]);
    assert_eq!(codes("let x = 1 / 0;\nscene { sphere(); }"), ["E0401"]);
    assert_eq!(
        codes("fn f(a: float) -> shape { f(a) }\nscene { f(1); }"),
        ["E0502"]
    );
    assert_eq!(codes("let a = 1;"), ["E0503"]);
    assert_eq!(
        codes("let a = b;\nlet b = 1;\nscene { sphere(); }"),
        ["E0208"]
    );
    assert_eq!(
        codes("material m = phong { ior: 0.5 };\nscene { sphere() @ m; }"),
        ["E0400"]
    );
}

#[test]
fn function_bodies_are_checked_without_calls() {
    assert_eq!(
        codes("fn f(a: float) -> shape { a + true }\nscene { sphere(); }"),
        ["E0301"]
    );
    assert_eq!(
        codes("fn f(a: float) -> float { sphere(a) }\nscene { sphere(); }"),
        ["E0300"]
    );
}

/// Imports from a fixed set of texts.
struct Files(&'static [(&'static str, &'static str)]);

impl super::Loader for Files {
    fn load(&mut self, _from: &str, path: &str) -> Result<(String, String), String> {
        let (name, text) = self
            .0
            .iter()
            .find(|(n, _)| *n == path)
            .ok_or("no such file")?;
        Ok((name.to_string(), text.to_string()))
    }
}

/// Checks `src` (importing from `files`) within `limits`: the diagnostics.
fn within(
    src: &str,
    files: &'static [(&'static str, &'static str)],
    limits: &crate::Limits,
) -> Vec<crate::Diagnostic> {
    let mut sources = crate::SourceMap::new();
    let entry = sources.add("t.sdf", src);
    super::check_with(&mut sources, entry, &mut Files(files), limits).1
}

#[test]
fn every_compilation_limit_is_reported_with_the_flag_that_raises_it() {
    use crate::{Limit, Limits};
    const IMPORTS: &[(&str, &str)] = &[("a.sdf", "import \"b.sdf\";"), ("b.sdf", "let r = 1;")];
    let cases: [(Limit, u64, &str); 6] = [
        (Limit::Nesting, 5, "let x = abs(abs(abs(abs(abs(abs(1))))));\nscene { sphere(); }"),
        (Limit::Fuel, 100, "scene { for i in 0..50 { sphere(1).translate(i, 0, 0); } }"),
        (
            Limit::CallDepth,
            2,
            "fn a(x: float) -> float { x }\nfn b(x: float) -> float { a(x) }\nfn c(x: float) -> float { b(x) }\nlet y = c(1);\nscene { sphere(); }",
        ),
        (Limit::Nodes, 3, "scene { union(sphere(1), sphere(2), sphere(3), sphere(4)); }"),
        (Limit::Objects, 3, "scene { sphere(1); sphere(2); sphere(3); sphere(4); }"),
        (Limit::Files, 2, "import \"a.sdf\";\nscene { sphere(r); }"),
    ];
    for (limit, value, src) in cases {
        let mut low = Limits::default();
        low.set(limit, value).expect("valid");
        let diags = within(src, IMPORTS, &low);
        let flag = format!("`--limit {}={}`", limit.name(), 2 * value);
        assert!(
            diags
                .iter()
                .any(|d| d.code == "E0507" && d.notes.iter().any(|n| n.contains(&flag))),
            "{limit}: {diags:#?}"
        );
        let diags = within(src, IMPORTS, &Limits::default());
        assert!(diags.iter().all(|d| !d.is_error()), "{limit}: {diags:#?}");
    }
}
