//! The Rust back end: the text's shape, and (when `rustc` is on the PATH) the generated code
//! compiled against a stand-in for glam's vector types and run, giving the interpreter's
//! results bit for bit.

mod common;

use common::*;
use sdfc_compiler::back::rust;
use sdfc_compiler::eval::eval_point;
use sdfc_compiler::lower::lower;
use sdfc_compiler::program::Program;
use sdfc_compiler::scene::{Combine, Node, Scene, Smooth};
use std::fmt::Write;
use std::process::Command;

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
    let bulb = b.add(Node::Mandelbulb {
        power: 8.0,
        iterations: 3,
    });
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
    assert!(
        text.contains("pub fn map(p: glam::Vec3) -> (f32, u32) {"),
        "{text}"
    );
    assert!(
        text.contains("pub fn map_f64(p: glam::DVec3) -> (f64, u32) {"),
        "{text}"
    );
    assert_eq!(text.matches("    let r").count(), 2 * program.len());
    assert!(text.contains(": f32 = p.x;") && text.contains(": f64 = p.z;"));
    assert_eq!(rust::write(&program), text, "output must be stable");
}

/// The generated functions plus a main that prints the results at `points` as bits.
fn harness(program: &Program, points: &[[f64; 3]]) -> String {
    let mut s = String::from(
        "#![allow(dead_code)]\nmod glam {\n    #[derive(Clone, Copy)]\n    pub struct Vec3 { pub x: f32, pub y: f32, pub z: f32 }\n    #[derive(Clone, Copy)]\n    pub struct DVec3 { pub x: f64, pub y: f64, pub z: f64 }\n}\n",
    );
    s.push_str(&rust::write(program));
    s.push_str("fn main() {\n");
    for p in points {
        let _ = writeln!(
            s,
            "    let (a, m) = map(glam::Vec3 {{ x: {:?}f32, y: {:?}f32, z: {:?}f32 }}); println!(\"{{}} {{}}\", a.to_bits(), m);",
            p[0] as f32, p[1] as f32, p[2] as f32
        );
        let _ = writeln!(
            s,
            "    let (a, m) = map_f64(glam::DVec3 {{ x: {:?}f64, y: {:?}f64, z: {:?}f64 }}); println!(\"{{}} {{}}\", a.to_bits(), m);",
            p[0], p[1], p[2]
        );
    }
    s.push_str("}\n");
    s
}

#[test]
fn generated_code_compiles_and_agrees_with_the_interpreter() {
    let program = lower(&scene());
    let mut rng = Rng::new(5);
    let points: Vec<[f64; 3]> = (0..20).map(|_| rng.point(3.0)).collect();
    let dir = std::env::temp_dir().join(format!("sdfc-emit-rust-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    let src = dir.join("gen.rs");
    let exe = dir.join("gen");
    std::fs::write(&src, harness(&program, &points)).expect("write source");
    let compiled = Command::new("rustc")
        .args(["--edition", "2021", "-o"])
        .arg(&exe)
        .arg(&src)
        .output();
    let compiled = match compiled {
        Ok(o) => o,
        Err(e) => {
            eprintln!("skipped: no rustc on the PATH ({e})");
            return;
        }
    };
    assert!(
        compiled.status.success(),
        "{}",
        String::from_utf8_lossy(&compiled.stderr)
    );
    let out = Command::new(&exe)
        .output()
        .expect("run the generated program");
    let _ = std::fs::remove_dir_all(&dir);
    let text = String::from_utf8_lossy(&out.stdout);
    let mut lines = text.lines();
    for p in &points {
        let (d32, m32) = eval_point::<f32>(&program, p.map(|v| v as f32));
        let (d64, m64) = eval_point::<f64>(&program, *p);
        assert_eq!(
            lines.next(),
            Some(format!("{} {}", d32.to_bits(), m32).as_str()),
            "f32 at {p:?}"
        );
        assert_eq!(
            lines.next(),
            Some(format!("{} {}", d64.to_bits(), m64).as_str()),
            "f64 at {p:?}"
        );
    }
}
