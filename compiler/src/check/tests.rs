//! Unit tests of constant evaluation and of the checker's diagnostics.

use crate::front::check_str;
use crate::scene::{Light, Node};

fn ok(src: &str) -> crate::scene::Scene {
    let (scene, diags, _) = check_str("t.sdf", src);
    assert!(
        diags.iter().all(|d| !d.is_error()),
        "unexpected errors: {diags:#?}"
    );
    scene.expect("scene")
}

/// The root node of a scene.
fn root(s: &crate::scene::Scene) -> &Node {
    s.graph.node(s.root.expect("root"))
}

/// The help of the first diagnostic `code` of `src`, if any.
fn help_of(src: &str, code: &str) -> Option<String> {
    let (_, diags, _) = check_str("t.sdf", src);
    diags
        .iter()
        .find(|d| d.code == code)
        .and_then(|d| d.help.clone())
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
    let Node::Combine { children, .. } = root(&s) else {
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

/// A white directional light of intensity 1 shining straight down.
fn downwards(penumbra: f64, shadows: bool) -> Light {
    Light::Directional {
        direction: [0.0, -1.0, 0.0],
        color: [1.0; 3],
        intensity: 1.0,
        penumbra,
        shadows,
    }
}

#[test]
fn lights_are_normalised() {
    let s = ok("light directional { direction: (0, -2, 0) }\nscene { sphere(); }");
    assert_eq!(s.lights[0], downwards(0.0, true));
}

/// `sun` is a directional light whose penumbra is its angle (the real sun's by default);
/// `sky`'s `color` gives the parts not given beside it; `shadows: false` reaches the IR.
#[test]
fn suns_and_skies() {
    let s = ok("light sun { direction: (0, -2, 0), shadows: false }\n\
                light sky { color: (0.5, 0.5, 0.5), ground: (0.1, 0.1, 0.1), background: false }\n\
                scene { sphere(); }");
    assert_eq!(s.lights[0], downwards(0.53f64.to_radians(), false));
    assert_eq!(
        s.lights[1],
        Light::Sky {
            zenith: [0.5; 3],
            horizon: [0.5; 3],
            ground: [0.1; 3],
            intensity: 1.0,
            shadows: true,
            background: false,
        }
    );
    assert_eq!(codes("light sun { }\nscene { sphere(); }"), ["E0204"]);
    assert_eq!(
        codes("light sun { direction: (0, -1, 0), angle: 95deg }\nscene { sphere(); }"),
        ["E0400"]
    );
    assert_eq!(codes("light lamp { }\nscene { sphere(); }"), ["E0211"]);
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
        ["E0507"]
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
    fn load(&mut self, _from: &str, path: &str) -> Result<(String, String), super::LoadError> {
        let missing = || super::LoadError::Read {
            path: path.into(),
            source: std::sync::Arc::new(std::io::Error::from(std::io::ErrorKind::NotFound).into()),
        };
        let (name, text) = self
            .0
            .iter()
            .find(|(n, _)| *n == path)
            .ok_or_else(missing)?;
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
    crate::front::check_with(&mut sources, entry, &mut Files(files), limits).1
}

#[test]
fn every_compilation_limit_is_reported_with_the_flag_that_raises_it() {
    use crate::{Limit, Limits};
    const IMPORTS: &[(&str, &str)] = &[("a.sdf", "import \"b.sdf\";"), ("b.sdf", "let r = 1;")];
    let cases: [(Limit, u64, &str); 7] = [
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
        // One sphere shared five times: two nodes in the graph, six as a tree.
        (Limit::Expansion, 3, "scene { union(sphere(1), sphere(1), sphere(1), sphere(1), sphere(1)); }"),
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

#[test]
fn a_material_can_be_used_above_its_declaration() {
    // A global `let` painting with a material declared below it (issue 24, item 10).
    let s =
        ok("let s = sphere(1) @ blue;\nmaterial blue = phong { color: (0, 0, 1) };\nscene { s; }");
    assert_eq!(s.materials[1].name, "blue");
    assert_eq!(
        s.materials[1].pattern,
        crate::scene::Pattern::Solid([0.0, 0.0, 1.0].into())
    );
    let Node::Paint { material, .. } = root(&s) else {
        panic!("not painted")
    };
    assert_eq!(material.0, 1);
    assert_eq!(
        codes("material m = phong {};\nmaterial m = phong {};\nscene { sphere() @ m; }"),
        ["E0207"]
    );
}

#[test]
fn suggestions_skip_the_parameters_already_given() {
    let help = |src: &str| help_of(src, "E0202");
    let f = "fn f(a: float, b: float = 1, c: float = 2) -> shape { sphere(a + b + c) }\n";
    // `d` is one edit from a, b and c; a and c are given.
    assert_eq!(
        help(&format!("{f}scene {{ f(1, c: 3, d: 4); }}")).as_deref(),
        Some("did you mean `b`?")
    );
    assert_eq!(
        help(&format!("{f}scene {{ f(1, b: 2, c: 3, d: 4); }}")),
        None
    );
    // The same for the fields of a record.
    assert_eq!(
        help("material m = phong { color: (1, 1, 1), colr: (1, 0, 0) };\nscene { sphere(); }"),
        None
    );
}

#[test]
fn function_bodies_see_the_global_constants() {
    // docs/language.md §5: a body sees its parameters, its `let`s and the global constants.
    let s = ok("let k = 2;\nfn ball() -> shape { sphere(k) }\nscene { ball(); }");
    assert_eq!(root(&s), &Node::Sphere { radius: 2.0 });
    // ... and a call from a constant above the one the body uses is E0208.
    assert_eq!(
        codes("let b = ball();\nlet k = 2;\nfn ball() -> shape { sphere(k) }\nscene { b; }"),
        ["E0208"]
    );
}

#[test]
fn rotations_follow_the_right_hand_rule() {
    // README and docs/language.md §8: rotate_y(90deg) turns +x into −z, rotate_z(90deg) +x
    // into +y, rotate_x(90deg) +y into +z.
    for (shape, at) in [
        ("translate(1, 0, 0).rotate_y(90deg)", [0.0, 0.0, -1.0]),
        ("translate(1, 0, 0).rotate_z(90deg)", [0.0, 1.0, 0.0]),
        ("translate(0, 1, 0).rotate_x(90deg)", [0.0, 0.0, 1.0]),
    ] {
        let s = ok(&format!("scene {{ sphere(0.1).{shape}; }}"));
        let program = crate::lower::lower(&s);
        let (d, _) = crate::eval::eval_point::<f64>(&program, at);
        assert!(d < 0.0, "{shape}: {d} at {at:?}");
    }
}

#[test]
fn an_error_in_a_body_shows_its_calls_up_to_four() {
    // f0 fails for a negative radius; f1 … f5 each call the one below, so the chain has five
    // calls: four are shown, and a note says there are more.
    let mut src = String::from("fn f0(r: float) -> shape { sphere(r) }\n");
    for i in 1..6 {
        src.push_str(&format!(
            "fn f{i}(r: float) -> shape {{ f{}(r - 1) }}\n",
            i - 1
        ));
    }
    src.push_str("scene { f5(3); }");
    let (_, diags, _) = check_str("t.sdf", &src);
    let d = diags.iter().find(|d| d.code == "E0400").expect("E0400");
    let calls: Vec<&str> = d.labels[1..].iter().map(|l| l.message.as_str()).collect();
    assert_eq!(
        calls,
        [
            "called here with r = -2",
            "called here with r = -1",
            "called here with r = 0",
            "called here with r = 1"
        ]
    );
    assert!(d.notes.iter().any(|n| n.contains("further functions")));
}

#[test]
fn a_list_union_is_the_union_of_its_shapes() {
    let given = ok("scene { union(sphere(1), box(0.5).translate(1, 0, 0), torus(1, 0.2)); }");
    let listed = ok("scene { union([sphere(1), box(0.5).translate(1, 0, 0), torus(1, 0.2)]); }");
    let built = ok(
        "fn parts() -> [shape] { [sphere(1), box(0.5).translate(1, 0, 0), torus(1, 0.2)] }\nscene { union(parts()); }",
    );
    let shown = |s: &crate::scene::Scene| crate::scene::dump(s);
    assert_eq!(shown(&given), shown(&listed));
    assert_eq!(shown(&given), shown(&built));
}

#[test]
fn comprehensions_in_function_bodies() {
    let s = ok("fn hoop(n: int, r: float) -> shape {\n  union([for i in 0..n { sphere(0.1).translate(r, 0, 0).rotate_y(360deg * i / n) }])\n}\nscene { hoop(6, 2); }");
    let Node::Combine { children, .. } = root(&s) else {
        panic!("not a union")
    };
    assert_eq!(children.len(), 6);
    // The same with a loop of the scene.
    let looped = ok("scene { union([for i in 0..6 { sphere(0.1).translate(2, 0, 0).rotate_y(360deg * i / 6) }]); }");
    assert_eq!(crate::scene::dump(&s), crate::scene::dump(&looped));
}

#[test]
fn list_values_len_and_index() {
    let s = ok("let xs = [1, 2.5, 3];\nlet n = len(xs);\nlet sq: [float] = [for i in 0..n { xs[i] * xs[i] }];\nscene { sphere(sq[1] + n); }");
    assert_eq!(root(&s), &Node::Sphere { radius: 9.25 });
    // A list parameter, with a comprehension over its length.
    let s = ok("fn sum(xs: [float], i: int = 0) -> float { if i >= len(xs) { 0 } else { xs[i] + sum2(xs, i + 1) } }\nfn sum2(xs: [float], i: int) -> float { if i >= len(xs) { 0 } else { xs[i] } }\nscene { sphere(sum([1, 2])); }");
    assert_eq!(root(&s), &Node::Sphere { radius: 3.0 });
}

#[test]
fn list_mistakes_are_reported_where_they_are() {
    let (_, diags, _) = check_str("t.sdf", "let xs = [1, 2, 3];\nscene { sphere(xs[3]); }");
    let d = diags.iter().find(|d| d.code == "E0407").expect("E0407");
    assert_eq!(
        d.span().start as usize,
        "let xs = [1, 2, 3];\nscene { sphere(xs[".len()
    );
    assert_eq!(
        codes("let xs = [1, 2];\nscene { sphere(xs[-1]); }"),
        ["E0407"]
    );
    assert_eq!(codes("scene { sphere([1, true][0]); }"), ["E0300"]);
    assert_eq!(codes("let xs = [];\nscene { sphere(1); }"), ["E0300"]);
    assert_eq!(
        codes("let v = (1, 2, 3);\nscene { sphere(v[0]); }"),
        ["E0300"]
    );
    assert_eq!(
        codes("let xs = [1, 2];\nscene { sphere(xs[0.5]); }"),
        ["E0300"]
    );
    assert_eq!(
        codes("fn f(xs: [[shape]]) -> shape { xs }\nscene { sphere(1); }"),
        ["E0209"]
    );
    assert_eq!(
        codes("scene { union([for i in 0..0 { sphere(1) }]); }"),
        ["E0400"]
    );
    // An error inside a comprehension's body is reported once, not once per element.
    assert_eq!(
        codes("scene { union([for i in 0..9 { sphere(-1) }]); }"),
        ["E0400"]
    );
    assert_eq!(
        codes("let xs = [1, 2] == [1, 2];\nscene { sphere(1); }"),
        ["E0301"]
    );
}

#[test]
fn lists_are_bounded_by_the_objects_limit() {
    use crate::limits::{Limit, Limits};
    let mut limits = Limits::default();
    limits.set(Limit::Objects, 10).expect("a valid limit");
    let src = "scene { union([for i in 0..11 { sphere(1).translate(i, 0, 0) }]); }";
    let mut sources = crate::span::SourceMap::new();
    let entry = sources.add("t.sdf", src);
    let (_, diags) = crate::front::check_with(&mut sources, entry, &mut super::NoImports, &limits);
    assert!(diags.iter().any(|d| d.code == "E0507"), "{diags:#?}");
}

#[test]
fn smooth_lists_fold_from_the_left() {
    let listed =
        ok("scene { smooth_union(0.2, [sphere(1), box(0.5), torus(1, 0.2)], variant: \"exp\"); }");
    let nested = ok("scene { smooth_union(0.2, smooth_union(0.2, sphere(1), box(0.5), variant: \"exp\"), torus(1, 0.2), variant: \"exp\"); }");
    // The nodes are made in another order, so they are numbered differently; the programs
    // are the same but for the node numbers in their comments.
    let program = |s: &crate::scene::Scene| {
        let text = crate::lower::lower(s).dump();
        text.lines()
            .filter(|l| !l.starts_with(';'))
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert_eq!(program(&listed), program(&nested));
    let one = ok("scene { smooth_intersect(0.2, [sphere(1)]); }");
    assert_eq!(root(&one), &Node::Sphere { radius: 1.0 });
}

#[test]
fn pi_and_tau_are_constants_a_name_of_the_file_hides() {
    let s = ok("scene { sphere(pi / 4 + tau); }");
    let want = std::f64::consts::PI / 4.0 + std::f64::consts::TAU;
    assert_eq!(root(&s), &Node::Sphere { radius: want });
    let s = ok("let pi = 3;\nfn r(tau: float) -> float { tau }\nscene { sphere(pi + r(1)); }");
    assert_eq!(root(&s), &Node::Sphere { radius: 4.0 });
}

#[test]
fn a_wrap_folds_only_a_shape_longer_than_its_circle() {
    let light = "light directional { direction: (-1, -1, 1) }\n";
    // Exactly the circle's length closes, also with a rounding above the wrap.
    let closed = format!("{light}scene {{ wrap(box((pi * 1.5, 0.2, 0.2)), 1.5).round(0.05); }}");
    assert_eq!(codes(&closed), Vec::<&str>::new());
    assert_eq!(
        codes(&format!(
            "{light}scene {{ wrap(box((5, 0.2, 0.2)), 1.5); }}"
        )),
        ["W0014"]
    );
    // Reaching the axis folds too, as does a taper whose factor reaches 0 over the shape.
    assert_eq!(
        codes(&format!("{light}scene {{ wrap(box((1, 0.2, 2)), 1.5); }}")),
        ["W0014"]
    );
    assert_eq!(
        codes(&format!(
            "{light}scene {{ taper(box((0.5, 1, 0.5)), 1.5); }}"
        )),
        ["W0014"]
    );
}

#[test]
fn a_list_of_shapes_as_a_scene_statement_suggests_union() {
    let (_, diags, _) = check_str("t.sdf", "scene { [sphere(1), box(0.5)]; }");
    let d = diags.iter().find(|d| d.code == "E0300").expect("E0300");
    assert!(d.help.iter().any(|h| h.contains("union(...)")), "{d:?}");
}

/// Brackets count towards the `nesting` limit in the parser: a million nested parentheses
/// are one E0507 at the first past the limit, before any recursion; a flat sum of 1 001
/// terms and a chain of 1 001 method calls are not nesting.
#[test]
fn nesting_counts_brackets_and_not_flat_chains() {
    // A thousand levels fit the test thread's 2 MiB in a release build, not in a debug build
    // (unoptimised frames are several times larger): the body runs on a thread whose stack
    // fits either. runtime/tests' robustness suite holds release builds to 2 MiB.
    std::thread::Builder::new()
        .stack_size(64 << 20)
        .spawn(nesting_counts_brackets_and_not_flat_chains_body)
        .expect("a test thread")
        .join()
        .expect("the test passes");
}

fn nesting_counts_brackets_and_not_flat_chains_body() {
    use crate::Limits;
    let n = 1_000_000;
    let src = format!(
        "let x = {}1{};\nscene {{ sphere(x); }}",
        "(".repeat(n),
        ")".repeat(n)
    );
    let diags = within(&src, &[], &Limits::default());
    let e: Vec<_> = diags.iter().filter(|d| d.is_error()).collect();
    assert_eq!(e.len(), 1, "{e:#?}");
    assert_eq!(e[0].code, "E0507");
    assert!(e[0].message.contains("more than 1000 levels"), "{:?}", e[0]);
    assert!(e[0]
        .notes
        .iter()
        .any(|n| n.contains("`--limit nesting=2000`")));
    assert_eq!(e[0].span().start, 8 + 1000);
    let terms = vec!["1"; 1001].join(" + ");
    ok(&format!("let x = {terms};\nscene {{ sphere(x / 1000); }}"));
    ok(&format!(
        "scene {{ sphere(1){}; }}",
        ".translate(0, 0, 0)".repeat(1001)
    ));
    // 1 000 levels of brackets are accepted (with the scene's own two), 1 001 are not.
    let deep = |k: usize| {
        format!(
            "let x = {}1{};\nscene {{ sphere(x); }}",
            "(".repeat(k),
            ")".repeat(k)
        )
    };
    ok(&deep(1000));
    assert!(codes(&deep(1001)).contains(&"E0507"));
}

#[test]
fn constants_are_returned_with_their_values_even_beside_errors() {
    let mut sources = crate::span::SourceMap::new();
    let text = "let r = 2 * 3;\nlet f = 1.5 / 3;\nlet a = 45deg;\nlet v = (1, 2.5, 0);\n\
                let s = \"po\\\"ly\";\nlet l = [for i in 0..20 { i * i }];\nlet b = sphere(1);\n\
                let ok = r > 5;\nscene { sphre(r); }";
    let entry = sources.add("t.sdf", text);
    let (scene, diags, constants) = crate::front::check_with_constants(
        &mut sources,
        entry,
        &mut super::NoImports,
        &crate::limits::Limits::default(),
    );
    assert!(scene.is_none() && diags.iter().any(|d| d.code == "E0201"));
    let shown: Vec<(&str, &str, &str)> = constants
        .iter()
        .map(|c| (&text[c.at.range()], c.value.as_str(), c.ty.as_str()))
        .collect();
    assert_eq!(
        shown,
        [
            ("r", "6", "int"),
            ("f", "0.5", "float"),
            ("a", "45deg", "angle"),
            ("v", "(1, 2.5, 0)", "vec3"),
            ("s", "\"po\\\"ly\"", "string"),
            (
                "l",
                "[0, 1, 4, 9, 16, 25, 36, 49, 64, 81, 100, 121, 144, 169, 196, 225, … 20 in all]",
                "[int]"
            ),
            ("ok", "true", "bool"),
        ]
    );
}

/// A material's colour and a checker's colours may be colour fields (a `field` of a vec3),
/// returned by functions too; their expressions reach the scene IR, and a colour field of
/// constants is lowered to a program of constants.
#[test]
fn colour_fields_reach_the_materials() {
    use crate::scene::{Colour, Pattern};
    let s = ok("fn bands(n: float) -> color_field { field { vec3(0.5 + 0.5 * sin(n * p.y), 0.2, 0.2) } }\n\
         material m = phong { color: bands(8) };\n\
         material c = checker { a: field { (0.3, 0.3, 0.3) }, b: (0.1, 0.1, 0.1) };\n\
         scene { sphere(1) @ m; box(0.5) @ c; }");
    let Pattern::Solid(Colour::Field(f)) = &s.materials[1].pattern else {
        panic!("{:?}", s.materials[1].pattern)
    };
    assert_eq!(f.out.len(), 3);
    assert!(f.text().contains("sin"), "{}", f.text());
    let Pattern::Checker {
        a: Colour::Field(a),
        b: Colour::Const(b),
        ..
    } = &s.materials[2].pattern
    else {
        panic!("{:?}", s.materials[2].pattern)
    };
    assert_eq!(*b, [0.1; 3]);
    let lowered = crate::lower::Lowered::new(&s);
    let colours = &lowered.colours;
    assert_eq!(colours.fields[1..], [[Some(0), None], [Some(1), None]]);
    // 0.5 + 0.5 sin(8y) at y = 0.1.
    let [r, g, _] = colours.programs[0].eval([0.0f64, 0.1, 0.0], [0.0; 3]);
    assert!((r - (0.5 + 0.5 * 0.8f64.sin())).abs() < 1e-12 && g == 0.2);
    let constant = &colours.programs[1].program;
    assert!(
        constant.ops().iter().all(|op| matches!(
            op,
            crate::program::Op::Const(_) | crate::program::Op::Input(_)
        )),
        "{a:?}"
    );
    assert_eq!(
        colours.programs[1].eval([5.0f64, -2.0, 1.0], [0.0; 3]),
        [0.3; 3]
    );
}

#[test]
fn an_unknown_name_in_a_field_suggests_the_nearest_binding() {
    let help = |src: &str| help_of(src, "E0200");
    // `q` is one edit from both `a` and `p`: the field's point is the nearer binding.
    assert_eq!(
        help("let a = 1;\nscene { field { length(q) - a }; }").as_deref(),
        Some("did you mean `p`?")
    );
    assert_eq!(
        help("fn f(a: float) -> shape { field { length(q) - a } }\nscene { f(1); }").as_deref(),
        Some("did you mean `p`?")
    );
    // Outside a field the global is the only one-letter name in scope.
    assert_eq!(
        help("let a = 1;\nscene { sphere(q); }").as_deref(),
        Some("did you mean `a`?")
    );
}

/// A wrong argument of `field` or `profile` is labelled where it is written: a name other
/// than `lipschitz`, a second `lipschitz`, a second argument; a colour field's `lipschitz`
/// is labelled as a whole.
#[test]
fn a_wrong_argument_of_a_field_is_labelled_where_it_is() {
    let first = |src: &str| {
        let (_, diags, _) = check_str("t.sdf", src);
        let d = diags.iter().find(|d| d.is_error()).expect("an error");
        let span = d.labels[0].span;
        (
            d.code,
            src[span.range()].to_string(),
            d.labels[0].message.clone(),
        )
    };
    for word in ["field", "profile"] {
        let solid = if word == "field" { "" } else { "extrude(" };
        let close = if word == "field" { "" } else { ", 1)" };
        let at = |args: &str| {
            first(&format!(
                "scene {{ {solid}{word}({args}) {{ length(p) - 1 }}{close}; }}"
            ))
        };
        let (code, text, label) = at("lipschitz: 1, x: 2");
        assert_eq!((code, text.as_str()), ("E0202", "x: 2"), "{word}: {label}");
        assert_eq!(label, "not `lipschitz`");
        let (code, text, _) = at("x: 2, lipschitz: 1");
        assert_eq!((code, text.as_str()), ("E0202", "x: 2"), "{word}");
        let (code, text, _) = at("lipschitz: 1, lipschitz: 3");
        assert_eq!((code, text.as_str()), ("E0203", "lipschitz: 3"), "{word}");
        let (code, text, _) = at("1, 3");
        assert_eq!((code, text.as_str()), ("E0205", "3"), "{word}");
    }
    let (code, text, _) = first(
        "material m = phong { color: field(lipschitz: 2) { vec3(p.x, 0, 0) } };\nscene { sphere(1) @ m; }",
    );
    assert_eq!((code, text.as_str()), ("E0202", "lipschitz: 2"));
}

/// A profile is called a profile: in the IR printout (`--emit ir`), as the node that leaves
/// a bound unproven, and in the messages about its body.
#[test]
fn a_profile_is_called_a_profile() {
    let s = ok("scene { revolve(profile { floor(p.x) + length(p) - 1 }); field(lipschitz: 2) { length(p) - 1 }; }");
    let ir = crate::dump_ir(&s);
    assert!(ir.contains("= profile { "), "{ir}");
    assert!(ir.contains("= field lipschitz=2 { "), "{ir}");
    let s = ok("scene { revolve(profile(lipschitz: 3) { length(p) - 1 }); }");
    let ir = crate::dump_ir(&s);
    assert!(ir.contains("= profile lipschitz=3 { "), "{ir}");
    assert!(!ir.contains("field"), "{ir}");
    let s = ok("scene { revolve(profile { floor(p.x) + length(p) - 1 }); }");
    let analysis = crate::scene::analysis::analyse(&s);
    let cause = analysis.root().and_then(|r| r.cause).expect("a cause");
    assert_eq!(crate::scene::analysis::kind(s.graph.node(cause)), "profile");
    let (_, diags, _) = check_str(
        "t.sdf",
        "scene { revolve(profile { if p.x > 0 { 1 } else { 0 } }); }",
    );
    let d = diags.iter().find(|d| d.code == "E0410").expect("E0410");
    assert!(d.message.contains("a profile's value"), "{d:?}");
    assert!(
        d.notes.iter().any(|n| n.contains("inside `profile { … }`")),
        "{d:?}"
    );
    assert!(
        d.help
            .as_deref()
            .is_some_and(|h| h.starts_with("a profile is")),
        "{d:?}"
    );
    // A field's messages are unchanged.
    let (_, diags, _) = check_str("t.sdf", "scene { field { if p.x > 0 { 1 } else { 0 } }; }");
    let d = diags.iter().find(|d| d.code == "E0410").expect("E0410");
    assert!(d.message.contains("a field's value"), "{d:?}");
    assert!(
        d.notes.iter().any(|n| n.contains("inside `field { … }`")),
        "{d:?}"
    );
}

mod hulls;
mod language;
mod limits;
mod looks;
mod params;
mod sweeps;
