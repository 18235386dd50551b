//! Checker tests of what users of other tools write: division, names that hide built-ins,
//! web colours, angles, `max_dist`, `len`, `text_size`, recursion, comprehensions, hashes of
//! lattice cells, lists joined with `+` and a number broadcast over a vector (hulls,
//! parameters and the look in `hulls.rs`, `params.rs`, `looks.rs`).

use super::{check_str, codes, ok, root};
use crate::scene::{Node, Scene};

/// Fails unless the root of `s` is a box of half-size `half`.
#[track_caller]
fn assert_box(s: &Scene, half: [f64; 3]) {
    assert_eq!(root(s), &Node::Box { half });
}

#[test]
fn division_gives_what_users_of_other_tools_expect() {
    // `5 / 2` is 2.5: a box 5 wide, not 4.
    let s = ok("let w = 5;\nscene { box((w / 2, 0.5, 0.5)); }");
    assert_box(&s, [2.5, 0.5, 0.5]);
    // Whole numbers divide with `div`, rounded down as Python's `//`.
    let s =
        ok("scene { for i in 0..1 { sphere(1).translate(div(7, 2), div(-7, 2), div(7, -2)); } }");
    let Node::Translate { offset, .. } = root(&s) else {
        panic!("not a translation")
    };
    assert_eq!(offset, &[3.0, -4.0, -4.0]);
    assert_eq!(codes("let x = div(1, 0);\nscene { sphere(); }"), ["E0400"]);
    assert_eq!(codes("let x = 1.5 / 0;\nscene { sphere(); }"), ["E0401"]);
    // A float where an int is needed says why and what to write.
    for src in [
        "let n = 5;\nscene { for i in 0..n / 2 { sphere(); } }",
        "let xs = [1, 2, 3];\nlet x = xs[4 / 2];\nscene { sphere(x); }",
        "let n = 6;\nscene { repeat_polar(sphere(0.2), n / 2); }",
    ] {
        let (_, diags, _) = check_str("t.sdf", src);
        let d = diags.iter().find(|d| d.is_error()).expect("an error");
        assert_eq!(d.code, "E0300", "{src}");
        assert!(
            d.help.iter().any(|h| h.contains("div(a, b)")),
            "{src}: {d:#?}"
        );
    }
}

#[test]
fn a_function_named_like_a_built_in_hides_it_with_a_warning() {
    let src = "fn ring(r: float) -> shape { torus(r, 0.1) }\n\
               fn offset(s: shape, d: vec3) -> shape { s.translate(d) }\n\
               light point { position: (0, 5, 0) }\n\
               scene { ring(1).offset((0, 2, 0)); }";
    let (scene, diags, _) = check_str("t.sdf", src);
    let codes: Vec<_> = diags.iter().map(|d| d.code).collect();
    assert_eq!(codes, ["W0016", "W0016"], "{diags:#?}");
    assert!(
        diags[0].message.contains("`ring`"),
        "{:?}",
        diags[0].message
    );
    assert!(
        diags[0].notes.iter().any(|n| n.contains("ring(")),
        "the built-in's signature: {:?}",
        diags[0].notes
    );
    // The calls are the user's: a torus moved up, not a profile.
    let s = scene.expect("scene");
    let Node::Translate { offset, child } = root(&s) else {
        panic!("not a translation")
    };
    assert_eq!(offset, &[0.0, 2.0, 0.0]);
    assert!(matches!(s.graph.node(*child), Node::Torus { .. }));
}

#[test]
fn web_colours_are_srgb_made_linear() {
    let s = ok("material m = phong { color: #ff8000 };\n\
                light point { position: (0, 5, 0), color: #FFFFFF }\n\
                render { background: #000000 }\n\
                scene { sphere(1) @ m; }");
    let crate::scene::Pattern::Solid(crate::scene::Colour::Const(c)) = s.materials[1].pattern
    else {
        panic!("{:?}", s.materials[1].pattern)
    };
    assert_eq!(c[0], 1.0);
    // sRGB 0x80 = 128/255 is linear 0.2158 (IEC 61966-2-1).
    assert!((c[1] - 0.215_860_5).abs() < 1e-6, "{c:?}");
    assert_eq!(c[2], 0.0);
    assert_eq!(s.settings.background, [0.0; 3]);
    // Not six hex digits: a lexical error.
    let (_, diags, _) = check_str("t.sdf", "let c = #ff80;\nscene { sphere(); }");
    assert_eq!(diags[0].code, "E0001");
    assert!(
        diags[0]
            .help
            .as_deref()
            .is_some_and(|h| h.contains("six hex digits")),
        "{diags:#?}"
    );
}

#[test]
fn radians_is_refused_with_the_spelling_that_works_and_degrees_reads_both_ways() {
    let (_, diags, _) = check_str("t.sdf", "scene { box(1).rotate_y(radians(30)); }");
    let d = diags.iter().find(|d| d.is_error()).expect("an error");
    assert_eq!(d.code, "E0201");
    let help = d.help.as_deref().unwrap_or("");
    assert!(help.contains("30deg") && help.contains("1rad"), "{help}");
    // `degrees` of a number is that many degrees; of an angle, its number of degrees.
    let s = ok(
        "let a = degrees(90);\nlet n = degrees(a) + degrees(0.5rad);\nscene { sphere(n / 100); }",
    );
    let Node::Sphere { radius } = root(&s) else {
        panic!("not a sphere")
    };
    assert!((radius - (90.0 + 0.5f64.to_degrees()) / 100.0).abs() < 1e-12);
}

#[test]
fn max_dist_covers_the_bounded_parts_unless_set_and_then_says_what_it_cuts() {
    // Not set: it reaches past the far side of a sphere 150 units away (a floor plane, which
    // is unbounded, does not stretch it).
    let s = ok("camera { position: (0, 0, -150), look_at: (0, 0, 0) }\n\
                light point { position: (0, 10, -10) }\n\
                scene { sphere(1); plane((0, 1, 0), -5); }");
    assert!(s.settings.max_dist >= 151.0, "{}", s.settings.max_dist);
    // A near scene keeps the default of 100.
    let s = ok("light point { position: (0, 10, -10) }\nscene { sphere(1); }");
    assert_eq!(s.settings.max_dist, 100.0);
    // Set short: a warning at the part, naming the setting.
    let (scene, diags, _) = check_str(
        "t.sdf",
        "camera { position: (0, 0, -30), look_at: (0, 0, 0) }\n\
         light point { position: (0, 10, -10) }\n\
         render { max_dist: 30 }\n\
         scene { sphere(2); sphere(1).translate(0, 0, 40); }",
    );
    let far: Vec<_> = diags.iter().filter(|d| d.code == "W0017").collect();
    assert_eq!(far.len(), 2, "{diags:#?}");
    assert!(
        far.iter().any(|d| d.message.contains("not seen")),
        "{far:#?}"
    );
    assert_eq!(scene.expect("scene").settings.max_dist, 30.0);
}

#[test]
fn len_takes_a_list_of_profiles() {
    let s = ok("let n = len([circle(1), rect(1)]);\nlight point { position: (0, 5, 0) }\nscene { sphere(n); }");
    assert_eq!(root(&s), &Node::Sphere { radius: 2.0 });
}

/// `text_size` is the size of the box around the ink `text` draws: a plate fits the text
/// it measures (issue 50, item 7).
#[test]
fn text_size_measures_the_ink_of_text() {
    let outline = crate::check::font::layout(crate::check::font::default_font(), "HELLO", 2.0)
        .expect("laid out");
    let (lo, hi) = outline.bounds();
    let s = ok("let s = text_size(\"HELLO\", 2);\nscene { box((s.x, s.y, 1)); }");
    let Node::Box { half } = root(&s) else {
        panic!("not a box")
    };
    assert_eq!(half[0], hi[0] - lo[0]);
    assert_eq!(half[1], hi[1] - lo[1]);
    assert!(half[0] > 4.0 * half[1], "HELLO is wide: {half:?}");
    // Twice the size, twice the box; the text's mistakes are text's.
    let t = ok("let s = text_size(\"HELLO\", 4);\nscene { box((s.x, s.y, 1)); }");
    let Node::Box { half: twice } = root(&t) else {
        panic!("not a box")
    };
    assert!((twice[0] - 2.0 * half[0]).abs() < 1e-9 * half[0]);
    assert_eq!(
        codes("let s = text_size(\"\");\nscene { sphere(); }"),
        ["E0400"]
    );
}

/// A list of a `field` of a vec3 says it holds a colour field, not that lists do not nest
/// (the message it gave), and how a field makes a shape.
#[test]
fn a_list_of_a_colour_field_says_what_it_holds() {
    let (_, diags, _) = check_str("t.sdf", "scene { union([field { vec3(1, 0, 0) }]); }");
    assert_eq!(diags.len(), 1, "{diags:#?}");
    assert_eq!(diags[0].code, "E0300");
    assert_eq!(
        diags[0].message,
        "a colour field cannot be a list's element"
    );
    assert_eq!(diags[0].span().start, 15);
    assert!(diags[0]
        .help
        .as_deref()
        .is_some_and(|h| h.contains("field { length(p) - 1 }")));
    // A list of lists keeps its message.
    let (_, diags, _) = check_str("t.sdf", "let xs = [[1], [2]];\nscene { sphere(1); }");
    assert_eq!(
        diags[0].message, "a list's elements cannot be lists",
        "{diags:#?}"
    );
}

/// Functions may call themselves, directly or through others (issue 50, item 5): a tree of
/// 2 to 4 children a branch chosen by a hash is one short function; each distinct call is
/// evaluated once; without a stopping case the call depth is met and the note names the
/// function.
#[test]
fn functions_may_call_themselves() {
    let src = "fn branch(level: int, seed: int) -> shape {
  let stem = cylinder((0, 0, 0), (0, 1, 0), 0.06);
  if level == 0 { stem } else {
    let n = 2 + int(hash(seed) * 3);
    union(stem, union([for i in 0..n { branch(level - 1, seed * 4 + i + 1).scale(0.7).translate(0, 1, 0) }]))
  }
}
scene { branch(4, 1); }";
    let s = ok(src);
    // Every level adds its stems: the leaves are as many as the hash chose.
    let stems = s
        .graph
        .ids()
        .filter(
            |&id| matches!(s.graph.node(id), Node::Prim { prim, .. } if prim.name == "cylinder"),
        )
        .count();
    assert_eq!(stems, 1, "one stem node, shared");
    let scales = s
        .graph
        .ids()
        .filter(|&id| matches!(s.graph.node(id), Node::Scale { .. }))
        .count();
    assert!(scales >= 4, "the branches of four levels: {scales}");
    // Mutual recursion with stopping cases.
    let s = ok(
        "fn even(n: int) -> bool { if n == 0 { true } else { odd(n - 1) } }
fn odd(n: int) -> bool { if n == 0 { false } else { even(n - 1) } }
scene { sphere(if even(10) { 1 } else { 2 }); }",
    );
    assert_eq!(root(&s), &Node::Sphere { radius: 1.0 });
    // Without a stopping case: E0507 at `call_depth`, naming the function.
    let (_, diags, _) = check_str(
        "t.sdf",
        "fn f(n: int) -> shape { f(n + 1) }\nscene { f(0); }",
    );
    assert_eq!(diags.len(), 1, "{diags:#?}");
    assert_eq!(diags[0].code, "E0507");
    assert!(
        diags[0].notes.iter().any(|n| n.starts_with(
            "`f` calls itself, directly or through other functions, and had done so 256 times"
        )),
        "{:?}",
        diags[0].notes
    );
}

/// A comprehension keeps the elements whose condition holds (issue 50, item 5):
/// `[for i in 0..n if c { … }]`; a condition that is not a bool is E0303.
#[test]
fn comprehensions_keep_what_their_condition_allows() {
    let s = ok(
        "let xs = [for i in 0..10 if i % 3 == 0 { i * 2 }];\nscene { sphere(len(xs) + xs[3]); }",
    );
    // 0, 3, 6, 9 kept: four elements, the last 18.
    assert_eq!(root(&s), &Node::Sphere { radius: 22.0 });
    // Inside a function, with a hash choosing what stays.
    let s = ok("fn some(n: int) -> shape { union([for i in 0..n if hash(i) < 2 { sphere(0.1).translate(i, 0, 0) }]) }\nscene { some(3); }");
    assert!(matches!(
        root(&s),
        Node::Combine { children, .. } if children.len() == 3
    ));
    assert_eq!(
        codes("let xs = [for i in 0..3 if i { i }];\nscene { sphere(); }"),
        ["E0303"]
    );
}

#[test]
fn hashes_of_lattice_cells_agree_in_the_checker_and_in_fields_of_either_precision() {
    use crate::eval::eval_point;
    // A field reads `p` through `hash`: the distance at a point of cell (i, j) is that cell's
    // hash minus 2, the same as `hash` of a constant in the cell, in f64 and in f32.
    let field = ok("scene { field(lipschitz: 1) { hash(p.xy) - 2 }; }");
    let program = crate::lower::lower(&field);
    let mut seen = std::collections::BTreeSet::new();
    for i in -32..32 {
        for j in -32..32 {
            let at = [i as f64 + 0.37, j as f64 + 0.81, 0.0];
            let constant = ok(&format!(
                "let h = hash(vec2({}, {}));\nscene {{ sphere(h); }}",
                at[0], at[1]
            ));
            let Node::Sphere { radius } = root(&constant) else {
                panic!("not a sphere")
            };
            assert!(*radius > 0.0 && *radius < 1.0, "{radius}");
            let (d64, _) = eval_point::<f64>(&program, at);
            assert!(
                (d64 + 2.0 - radius).abs() < 1e-12,
                "cell ({i}, {j}): {d64} {radius}"
            );
            let (d32, _) = eval_point::<f32>(&program, at.map(|x| x as f32));
            assert!(
                (d32 as f64 - d64).abs() < 1e-6,
                "cell ({i}, {j}): {d32} {d64}"
            );
            // Constant within the cell.
            let (corner, _) = eval_point::<f64>(&program, [i as f64 + 0.999, j as f64, 0.0]);
            assert_eq!(corner, d64, "cell ({i}, {j})");
            seen.insert((*radius * 1e9) as i64);
        }
    }
    // 4096 cells, nearly all different (the hash has 289² values).
    assert!(seen.len() > 4000, "{} distinct hashes", seen.len());
    // A step at every cell's side: the field is a bound of unknown slope unless declared.
    let s = ok("scene { field { p.y - hash(floor(p.x * 4)) }; }");
    let analysis = crate::scene::analysis::analyse(&s);
    let cause = analysis
        .root()
        .and_then(|r| r.cause)
        .expect("no bound proven");
    assert_eq!(crate::scene::analysis::kind(s.graph.node(cause)), "field");
    // An int seed keeps its own hash, known when the scene is checked.
    assert_eq!(
        codes("let h = hash(3) + hash(3.5) + hash((1, 2, 3));\nlight point { position: (0, 5, 0) }\nscene { sphere(h); }"),
        Vec::<&str>::new()
    );
}

#[test]
fn lists_concatenate_with_plus() {
    let s = ok("let xs = [1, 2] + [3.5];\n\
                fn twigs(n: int) -> [shape] { if n == 0 { [sphere(0.1)] } else { twigs(n - 1) + [sphere(0.1).translate(n, 0, 0)] } }\n\
                light point { position: (0, 5, 0) }\n\
                scene { union(twigs(3)).translate(xs[2], 0, 0); }");
    let mut spheres = 0;
    let mut moved = Vec::new();
    for id in s.graph.ids() {
        match s.graph.node(id) {
            Node::Sphere { .. } => spheres += 1,
            Node::Translate { offset, .. } => moved.push(offset[0]),
            _ => {}
        }
    }
    assert_eq!(spheres, 1, "one sphere, shared");
    moved.sort_by(f64::total_cmp);
    assert_eq!(moved, [1.0, 2.0, 3.0, 3.5]);
    // Lists of different element types do not concatenate.
    assert_eq!(
        codes("let xs = [1] + [sphere(1)];\nscene { sphere(1); }"),
        ["E0301"]
    );
    // Growing a list spends fuel by its elements: a list doubled 40 times stops at a limit.
    let src =
        "fn grow(n: int) -> [float] { if n == 0 { [1.0] } else { let h = grow(n - 1); h + h } }\n\
               let xs = grow(40);\nscene { sphere(xs[0]); }";
    let (_, diags, _) = check_str("t.sdf", src);
    assert!(
        diags
            .iter()
            .any(|d| d.code == "E0507" && d.message.contains("elements")),
        "{diags:#?}"
    );
}

#[test]
fn a_number_broadcasts_over_a_vector_in_constants_and_fields() {
    use crate::eval::eval_point;
    // Constants: `1 + v / 2` is `vec3(1) + v / 2`, and `1 / v` divides per component.
    let s = ok("let v = (2, 4, 6);\nscene { box(1 + v / 2 - 1 / (1, 2, 4)); }");
    assert_box(&s, [1.0, 2.5, 3.75]);
    assert_eq!(
        codes("let v = 1 / (1, 0, 1);\nscene { sphere(); }"),
        ["E0401"]
    );
    // Fields: each form with a number is the same field as with the number made a vector.
    for (scalar, vector) in [
        ("length(1 + p) - 1", "length(vec3(1) + p) - 1"),
        ("length(1 - p) - 1", "length(vec3(1) - p) - 1"),
        (
            "length(p.xz + 0.5) - 1",
            "length(p.xz + vec2(0.5, 0.5)) - 1",
        ),
        (
            "length(2 / (p + 3)) - 1",
            "length(vec3(2) / (p + vec3(3))) - 1",
        ),
    ] {
        let a = crate::lower::lower(&ok(&format!("scene {{ field {{ {scalar} }}; }}")));
        let b = crate::lower::lower(&ok(&format!("scene {{ field {{ {vector} }}; }}")));
        for at in [[0.3, -0.2, 0.7], [1.5, 2.0, -0.4], [-0.9, 0.1, 0.0]] {
            assert_eq!(
                eval_point::<f64>(&a, at).0,
                eval_point::<f64>(&b, at).0,
                "{scalar}"
            );
        }
    }
    // A colour field of a number and a vector (GLSL's `0.5 + 0.5 * n`).
    assert_eq!(
        codes("material m = phong { color: field { 0.5 + 0.5 * n } };\nlight point { position: (0, 5, 0) }\nscene { sphere(1) @ m; }"),
        Vec::<&str>::new()
    );
    // Vectors of two sizes, and angles with vectors, are still refused.
    assert_eq!(
        codes("let v = (1, 2) + (1, 2, 3);\nscene { sphere(); }"),
        ["E0301"]
    );
    assert_eq!(
        codes("let v = 1deg + (1, 2);\nscene { sphere(); }"),
        ["E0301"]
    );
}
