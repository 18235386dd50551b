//! Checker tests of materials and the look: a checker of two materials of one model, a glow
//! of marching steps, the newer look's tone curve.

use super::{check_str, codes, ok};

#[test]
fn a_checker_pairs_two_materials_of_one_model() {
    use crate::scene::{MaterialId, Pattern};
    let head = "material gold = pbr { base_color: (1, 0.8, 0.3), metallic: 1 };\n\
                material rubber = pbr { base_color: (0.1, 0.1, 0.1), roughness: 0.9 };\n\
                material glass = pbr { transmission: 1 };\n\
                material plastic = phong { color: (1, 0, 0) };\n\
                light point { position: (0, 5, 0) }\n";
    let scene = |m: &str| format!("{head}{m}\nscene {{ plane() @ tiles; }}");
    // Both materials, the second declared below the checker.
    let s = ok(&format!(
        "material tiles = checker {{ a: gold, b: later, size: 0.5 }};\n{}\nmaterial later = pbr {{ roughness: 0.3 }};",
        scene("")
    ));
    let tiles = s
        .materials
        .iter()
        .find(|m| m.name == "tiles")
        .expect("tiles");
    let id = |name: &str| s.materials.iter().position(|m| m.name == name).expect(name);
    let (gold, later) = (id("gold"), id("later"));
    assert_eq!(
        tiles.pattern,
        Pattern::Materials {
            a: MaterialId(gold as u32),
            b: MaterialId(later as u32),
            size: 0.5
        }
    );
    // A material and a colour, a transparent material, two models, a checker within a
    // checker (itself), and a property of its own are refused where they are written.
    for (tiles, code, at) in [
        ("checker { a: gold, b: (1, 0, 0) }", "E0300", "(1, 0, 0)"),
        ("checker { a: (1, 0, 0), b: gold }", "E0300", "(1, 0, 0)"),
        ("checker { a: gold }", "E0300", "checker"),
        ("checker { a: gold, b: glass }", "E0400", "glass"),
        ("checker { a: gold, b: plastic }", "E0400", "plastic"),
        ("checker { a: tiles, b: gold }", "E0400", "tiles"),
        (
            "checker { a: gold, b: rubber, specular: 0.5 }",
            "E0400",
            "specular",
        ),
    ] {
        let text = scene(&format!("material tiles = {tiles};"));
        let (_, diags, _) = check_str("t.sdf", &text);
        let errors: Vec<_> = diags.iter().filter(|d| d.is_error()).collect();
        assert_eq!(errors.len(), 1, "{tiles}: {errors:#?}");
        assert_eq!(errors[0].code, code, "{tiles}");
        let span = errors[0].labels[0].span;
        let line = text.lines().nth(5).expect("the checker's line");
        let offset = text.find(line).expect("line");
        assert_eq!(
            &text[span.start as usize..span.end as usize],
            at,
            "{tiles}: {} at {}",
            errors[0].message,
            span.start as usize - offset
        );
    }
    // A constant of a material's name is the constant: a checker of colours.
    let s = ok("let gold = (1, 0.8, 0.3);\nmaterial gold = phong {};\nmaterial tiles = checker { a: gold, b: (0, 0, 0) };\nlight point { position: (0, 5, 0) }\nscene { plane() @ tiles; }");
    let tiles = s
        .materials
        .iter()
        .find(|m| m.name == "tiles")
        .expect("tiles");
    assert!(matches!(tiles.pattern, Pattern::Checker { .. }));
}

#[test]
fn a_glow_of_marching_steps_is_marched_and_not_path_traced() {
    use crate::scene::analytic::{choose, Choice, Reason};
    let scene = |render: &str| format!("render {{ {render} }}\nscene {{ sphere(1); }}");
    // A sphere alone is traced analytically; with a glow it is marched, and says why.
    assert!(matches!(choose(&ok(&scene("width: 64"))), Choice::Trace(_)));
    let s = ok(&scene("glow: 0.1, glow_color: (0.1, 0.2, 0.3)"));
    assert_eq!(
        (s.settings.glow, s.settings.glow_color),
        (0.1, [0.1, 0.2, 0.3])
    );
    assert!(matches!(choose(&s), Choice::March(Reason::Glow)));
    assert_eq!(codes(&scene("glow: 0.1, method: \"trace\"")), ["E0405"]);
    assert_eq!(codes(&scene("glow: 0.1, method: \"path\"")), ["E0400"]);
    assert_eq!(codes(&scene("glow: -1")), ["E0400"]);
}

#[test]
fn a_scene_of_the_newer_look_is_filmic_unless_it_says_otherwise() {
    use crate::scene::{look, Tonemap};
    let pbr = "material m = pbr { roughness: 0.4 };\nscene { sphere(1) @ m; }";
    let s = ok(pbr);
    assert_eq!(s.settings.tonemap, Tonemap::Filmic);
    assert_eq!(s.settings.tonemap_why, Some("it has a `pbr` material"));
    for (text, why) in [
        (
            "light sky { }\nscene { sphere(1); }",
            "it is lit by a `light sky`",
        ),
        (
            "render { method: \"path\" }\nscene { sphere(1); }",
            "it is path traced (`method: \"path\"`)",
        ),
    ] {
        let s = ok(text);
        assert_eq!(
            (s.settings.tonemap, s.settings.tonemap_why),
            (Tonemap::Filmic, Some(why))
        );
    }
    // A path-traced scene of pbr materials under a sky is graded as any other (the viewer
    // grades the mean of its linear samples, as `sdfc render` does).
    let s = ok(&format!(
        "render {{ method: \"path\" }}\nlight sky {{ }}\n{pbr}"
    ));
    assert_eq!(s.settings.tonemap, Tonemap::Filmic);
    // A scene of the older look keeps `none`; a given curve is kept, and says so.
    let s = ok("light point { position: (0, 5, 0) }\nscene { sphere(1); }");
    assert_eq!(
        (s.settings.tonemap, s.settings.tonemap_why),
        (Tonemap::None, Some(look::OLDER_LOOK))
    );
    let s = ok(&format!("render {{ tonemap: \"none\" }}\n{pbr}"));
    assert_eq!(
        (s.settings.tonemap, s.settings.tonemap_why),
        (Tonemap::None, None)
    );
}
