//! The Rust back end: the text's shape and the glam version its header names. The text as a
//! user takes it away (`sdfc compile --emit rust` built in a scratch crate) is tested with
//! the command line (the runtime's `tests/cli/emit_rust.rs`); the generated code of every
//! scene of the distance conformance suite is compiled and compared with the interpreters
//! there (the runtime's `tests/render/distance_conformance.rs`).

use crate::common::*;
use sdfc_compiler::{lower, rust, Combine, Node, Scene, Smooth};

fn scene() -> Scene {
    let mut b = Build::new();
    let m = b.material([1.0, 0.0, 0.0], 0.0, 0.0);
    let s = b.add(Node::Sphere { radius: 0.8 });
    let s = b.paint(s, m);
    let t = b.add(Node::Torus {
        major: 1.0,
        minor: 0.2,
    });
    let t = b.add(Node::Repeat {
        period: [3.0, 0.0, 0.0],
        count: None,
        child: t,
    });
    let u = b.add(Node::SmoothCombine {
        op: Combine::Union,
        k: 0.2,
        variant: Smooth::Poly,
        a: s,
        b: t,
    });
    let bulb = Node::prim("mandelbulb", &[&[8.0], &[3.0]]);
    let bulb = b.add(bulb.expect("mandelbulb is a primitive of the table"));
    let bulb = b.at(bulb, [0.0, 3.0, 0.0]);
    let root = b.add(Node::Combine {
        op: Combine::Union,
        children: vec![u, bulb],
    });
    b.finish(root)
}

#[test]
fn text_has_both_functions_with_one_statement_per_instruction() {
    let program = lower(&scene());
    let text = rust::write(&program);
    assert_has(&text, &["pub fn map(p: glam::Vec3) -> (f32, u32) {"]);
    assert_has(&text, &["pub fn map_f64(p: glam::DVec3) -> (f64, u32) {"]);
    assert_eq!(text.matches("    let r").count(), 2 * program.len());
    assert!(text.contains(": f32 = p.x;") && text.contains(": f64 = p.z;"));
    assert_eq!(rust::write(&program), text, "output must be stable");
}

/// The header names the glam version the code is written against, and that version is the
/// workspace's own (one source: the workspace's Cargo.toml).
#[test]
fn header_names_the_glam_version_of_the_workspace() {
    let text = rust::write(&lower(&scene()));
    let header = text.lines().take(3).collect::<Vec<_>>().join("\n");
    let wanted = format!("`glam = \"{}\"`", rust::GLAM_VERSION);
    assert!(header.contains(&wanted), "{header}");
    let manifest = include_str!("../../../Cargo.toml");
    assert!(
        manifest.contains(&format!("glam = \"{}\"", rust::GLAM_VERSION)),
        "the workspace's glam is not {}",
        rust::GLAM_VERSION
    );
}
