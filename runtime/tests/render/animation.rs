//! Animation (docs/animation.md): the time `t` in every kind of field, what reads it and what
//! may not, and the limit on a sequence's frames. Sequences through the CLI are `sequence`'s,
//! their one kernel `animation_kernels`'s.

use sdfc_compiler::{
    check_at, Colour, Diagnostic, Light, Limits, NoImports, Node, Pattern, Scene, SourceMap,
};

/// Checks `text` at the time `t`.
fn at(text: &str, t: f64) -> (Option<Scene>, Vec<Diagnostic>) {
    let mut sources = SourceMap::new();
    let entry = sources.add("anim.sdf", text);
    check_at(&mut sources, entry, &mut NoImports, &Limits::default(), t)
}

/// The scene of `text` at `t`, which must check cleanly.
pub(crate) fn scene(text: &str, t: f64) -> Scene {
    let (s, d) = at(text, t);
    assert!(
        d.iter().all(|d| !d.is_error()),
        "{text} at t = {t}: {:?}",
        d.iter().map(|d| &d.message).collect::<Vec<_>>()
    );
    s.expect("scene")
}

pub(crate) const BASE: &str = "material m = phong { color: (0.8, 0.2, 0.2) };
light point { position: (2, 4, -3) }
";

/// Reads a number out of a checked scene.
type Read = fn(&Scene) -> f64;

#[test]
fn t_reaches_every_kind_of_field() {
    // Each case: a scene reading `t` in one place, and what it must read at t = 0.5.
    let cases: &[(&str, Read)] = &[
        ("scene { sphere(1 + t) @ m; }", |s| match s.graph.node(s.root.unwrap()) {
            Node::Paint { child, .. } => match s.graph.node(*child) {
                Node::Sphere { radius } => *radius,
                n => panic!("{n:?}"),
            },
            n => panic!("{n:?}"),
        }),
        (
            "camera { position: (0, 1, -5 - t), look_at: (0, 0, 0) } scene { sphere(1); }",
            |s| s.camera.position[2],
        ),
        (
            "camera { fov: degrees(40 + 20 * t) } scene { sphere(1); }",
            |s| s.camera.fov.to_degrees(),
        ),
        (
            "material n = phong { color: (t, 0.5, 0.5), reflect: t / 2 } scene { sphere(1) @ n; }",
            |s| s.materials[2].reflect + 10.0 * pattern_red(s),
        ),
        (
            "material n = checker { size: 1 + t } scene { sphere(1) @ n; }",
            |s| match s.materials[2].pattern {
                Pattern::Checker { size, .. } => size,
                _ => panic!("not a checker"),
            },
        ),
        (
            "light directional { direction: (0, -1, 0), intensity: t, penumbra: degrees(4 * t) } scene { sphere(1); }",
            |s| match s.lights[1] {
                Light::Directional {
                    intensity, penumbra, ..
                } => intensity + penumbra.to_degrees(),
                _ => panic!("not directional"),
            },
        ),
        (
            "render { max_steps: 100 + int(t * 100), epsilon: 0.001 * (1 + t), background: (t, t, t) } scene { sphere(1); }",
            |s| s.settings.max_steps as f64 + 1000.0 * s.settings.epsilon + s.settings.background[0],
        ),
        (
            "scene { for i in 0..int(4 * t) + 1 { sphere(0.2).translate(i, 0, 0); } }",
            |s| match s.graph.node(s.root.unwrap()) {
                Node::Combine { children, .. } => children.len() as f64,
                _ => 1.0,
            },
        ),
        (
            "scene { if t > 0.25 { box(1) } else { sphere(1) }; }",
            |s| match s.graph.node(s.root.unwrap()) {
                Node::Box { .. } => 1.0,
                _ => 0.0,
            },
        ),
        (
            "fn grow(r: float) -> shape { sphere(r + t + 1) } let size = 2 * t; scene { grow(size); grow(size); }",
            |s| match s.graph.node(s.root.unwrap()) {
                Node::Combine { children, .. } => match s.graph.node(children[0]) {
                    Node::Sphere { radius } => *radius,
                    n => panic!("{n:?}"),
                },
                // Both objects are the same sphere, hash-consed.
                Node::Sphere { radius } => *radius,
                n => panic!("{n:?}"),
            },
        ),
    ];
    let expected = [
        1.5,
        -5.5,
        50.0,
        5.0 + 0.25,
        1.5,
        0.5 + 2.0,
        150.0 + 1.5 + 0.5,
        3.0,
        1.0,
        2.5,
    ];
    for ((text, read), want) in cases.iter().zip(expected) {
        let text = format!("{BASE}{text}");
        let s = scene(&text, 0.5);
        assert!(s.animation.animated(), "{text} does not read t");
        assert_eq!(s.animation.time, 0.5);
        let got = read(&s);
        assert!((got - want).abs() < 1e-9, "{text}: {got}, expected {want}");
        // At another time the value differs: the scene was checked at that time.
        let other = read(&scene(&text, 0.0));
        assert!((other - want).abs() > 1e-6, "{text}: the same at t = 0");
    }
}

fn pattern_red(s: &Scene) -> f64 {
    match s.materials[2].pattern {
        Pattern::Solid(Colour::Const(c)) => c[0],
        _ => panic!("not solid"),
    }
}

#[test]
fn scenes_that_do_not_evaluate_t_are_stills() {
    for text in [
        "scene { sphere(1); }",
        // A constant, parameter or loop variable named `t` hides the time.
        "let t = 2; scene { sphere(t); }",
        "fn f(t: float) -> shape { sphere(t) } scene { f(1); }",
        "scene { for t in 1..3 { sphere(t); } }",
        // A function that reads `t` but is never called: checked, not evaluated.
        "fn pulse() -> shape { sphere(1 + t) } scene { sphere(1); }",
    ] {
        let s = scene(&format!("{BASE}{text}"), 1.0);
        assert!(!s.animation.animated(), "{text} is animated");
    }
    // A memoised call still reports that it reads the time, at every use.
    let s = scene(
        &format!("{BASE}fn f(r: float) -> float {{ r + t }} let a = f(1); let b = f(1); render {{ epsilon: 0.001 * b }} scene {{ sphere(1); }}"),
        0.5,
    );
    assert!(s.animation.animated());
    assert!((s.settings.epsilon - 0.0015).abs() < 1e-12);
}

#[test]
fn the_sequence_settings_cannot_read_t() {
    for (text, field) in [
        (
            "render { width: 100 + int(t) } scene { sphere(1); }",
            "width",
        ),
        ("render { fps: 30 + t } scene { sphere(1); }", "fps"),
        // Through a constant and through a function: the secondary label points at `t`.
        (
            "let d = 2 + t; render { duration: d } scene { sphere(1); }",
            "duration",
        ),
        (
            "fn h() -> int { int(t) + 50 } render { height: h() } scene { sphere(1); }",
            "height",
        ),
    ] {
        let text = format!("{BASE}{text}");
        let (s, d) = at(&text, 0.0);
        assert!(s.is_none(), "{text}");
        let e = d
            .iter()
            .find(|d| d.code == "E0406")
            .unwrap_or_else(|| panic!("{text}: {d:?}"));
        assert!(e.message.contains(field), "{}", e.message);
        let read = e.labels.get(1).expect("secondary label").span;
        assert_eq!(&text[read.start as usize..read.end as usize], "t", "{text}");
    }
    // `t` elsewhere in `render` is fine.
    let s = scene(
        &format!(
            "{BASE}render {{ max_depth: 2 + int(t), fps: 24, duration: 2 }} scene {{ sphere(1); }}"
        ),
        1.0,
    );
    assert_eq!(s.settings.max_depth, 3);
    assert_eq!(s.animation.frames(), 48);
}

#[test]
fn too_many_frames_is_a_limit() {
    let (s, d) = at(
        &format!("{BASE}render {{ fps: 1000, duration: 1e6 }} scene {{ sphere(1); }}"),
        0.0,
    );
    assert!(s.is_none());
    let e = d.iter().find(|d| d.code == "E0507").expect("E0507");
    assert!(
        e.notes.iter().any(|n| n.contains("--limit frames=")),
        "{e:?}"
    );
}
