//! Checker tests of parameters: values given from outside taken within what they accept,
//! offered values taken where accepted and passed over elsewhere.

use super::codes;
use crate::scene::Node;

#[test]
fn parameters_take_values_from_outside_within_what_they_accept() {
    use crate::scene::params::{Accepts, ParamValue};
    let src = "param width = 40.0 in 10..100 step 1 \"Box width (mm)\";\n\
               param holes = 3 in 1..8;\n\
               param rounded = true;\n\
               param style = \"round\" in [\"round\", \"square\"] \"Hole shape\";\n\
               light point { position: (0, 5, 0) }\n\
               scene { box((width / 2, 1, 1)).round(if rounded { 0.1 } else { 0 }); }";
    let run = |given: &[(&str, &str)]| {
        let mut limits = crate::Limits::default();
        for (n, v) in given {
            limits.set_param(n, v);
        }
        let mut sources = crate::SourceMap::new();
        let entry = sources.add("t.sdf", src);
        crate::front::check_with(&mut sources, entry, &mut crate::check::NoImports, &limits)
    };
    let (scene, diags) = run(&[]);
    assert!(diags.iter().all(|d| !d.is_error()), "{diags:#?}");
    let scene = scene.expect("scene");
    let names: Vec<&str> = scene.params.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["width", "holes", "rounded", "style"]);
    assert_eq!(
        scene.params[0].accepts,
        Accepts::Range {
            lo: 10.0,
            hi: 100.0,
            step: Some(1.0)
        }
    );
    assert_eq!(scene.params[0].doc, "Box width (mm)");
    // A value given from outside changes the scene and is listed beside the default.
    let (scene, _) = run(&[("width", "60"), ("style", "square"), ("rounded", "false")]);
    let scene = scene.expect("scene");
    assert_eq!(scene.params[0].value, ParamValue::Float(60.0));
    assert_eq!(scene.params[0].default, ParamValue::Float(40.0));
    assert_eq!(scene.params[3].value, ParamValue::Str("square".into()));
    let half: Vec<f64> = scene
        .graph
        .ids()
        .filter_map(|id| match scene.graph.node(id) {
            Node::Box { half } => Some(half[0]),
            _ => None,
        })
        .collect();
    assert_eq!(half, [30.0]);
    // Refused, each at its declaration: out of range, of the wrong type, not a choice, and
    // a name the file does not declare.
    for (given, code, line) in [
        (("width", "160"), "E0400", 1),
        (("holes", "2.5"), "E0300", 2),
        (("rounded", "yes"), "E0300", 3),
        (("style", "oval"), "E0400", 4),
        (("widht", "50"), "E0200", 1),
    ] {
        let (scene, diags) = run(&[given]);
        assert!(scene.is_none(), "{given:?}");
        let d = diags.iter().find(|d| d.is_error()).expect("an error");
        assert_eq!(d.code, code, "{given:?}: {d:#?}");
        assert!(
            d.message
                .contains(&format!("--param {}={}", given.0, given.1)),
            "{d:#?}"
        );
        let at = src[..d.span().start as usize].lines().count().max(1);
        assert_eq!(at, line, "{given:?}");
    }
    // A default outside its range, and a parameter that is not a number, bool or string.
    assert_eq!(
        codes("param w = 5 in 10..20;\nscene { sphere(1); }"),
        ["E0400"]
    );
    assert_eq!(codes("param s = sphere(1);\nscene { s; }"), ["E0300"]);
}

#[test]
fn offered_parameter_values_are_taken_where_accepted_and_passed_over_elsewhere() {
    use crate::scene::params::ParamValue;
    let src = "param width = 40.0 in 10..100 \"Box width (mm)\";\n\
               param holes = 3 in 1..8;\n\
               light point { position: (0, 5, 0) }\n\
               scene { box((width / 2, 1, 1)); }";
    let run = |given: &[(&str, &str)], offered: &[(&str, &str)]| {
        let mut limits = crate::Limits::default();
        for (n, v) in given {
            limits.set_param(n, v);
        }
        for (n, v) in offered {
            limits.offer_param(n, v);
        }
        let mut sources = crate::SourceMap::new();
        let entry = sources.add("t.sdf", src);
        let (scene, diags) =
            crate::front::check_with(&mut sources, entry, &mut crate::check::NoImports, &limits);
        assert!(diags.iter().all(|d| !d.is_error()), "{diags:#?}");
        let scene = scene.expect("scene");
        (scene.params[0].value.clone(), scene.params[1].value.clone())
    };
    // Taken, over a value given (the panel moved on from the command line's value); the last
    // offered counts.
    assert_eq!(
        run(&[("width", "60")], &[("width", "70"), ("width", "80")]),
        (ParamValue::Float(80.0), ParamValue::Int(3))
    );
    // Passed over in silence: out of range, of the wrong type, or a name the scene does not
    // declare (no E0200); the given value or the default stands.
    assert_eq!(
        run(
            &[("width", "60")],
            &[("width", "160"), ("holes", "2.5"), ("gone", "1")]
        ),
        (ParamValue::Float(60.0), ParamValue::Int(3))
    );
}
