//! The Rust back end as a user takes it away: `sdfc compile --emit rust` of an example built
//! in a scratch crate that depends on the glam version its header names, giving the
//! interpreter's results bit for bit.

use crate::common::run_ok;
use sdfc_compiler::{eval_point, rust, Rng};
use std::fmt::Write;
use std::process::Command;

/// `sdfc compile --emit rust` of an example, put in a new crate whose only dependency is the
/// glam its header names, builds (offline, from the workspace's lock file) and gives the
/// interpreter's distances and materials bit for bit.
#[test]
fn emitted_rust_builds_in_a_scratch_crate_with_glam() {
    let scene_path = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/seed1.sdf");
    let root = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("emit-rust-crate");
    std::fs::create_dir_all(root.join("src")).expect("scratch crate");
    run_ok(
        Command::new(env!("CARGO_BIN_EXE_sdfc"))
            .args(["compile", scene_path, "--emit", "rust", "-o"])
            .arg(root.join("src/scene.rs")),
        "run sdfc",
    );
    std::fs::write(
        root.join("Cargo.toml"),
        format!(
            "[package]\nname = \"sdfc-emit-rust-user\"\nversion = \"0.0.0\"\nedition = \"2021\"\npublish = false\n\n[dependencies]\nglam = \"{}\"\n\n[workspace]\n",
            rust::GLAM_VERSION
        ),
    )
    .expect("manifest");
    std::fs::copy(
        concat!(env!("CARGO_MANIFEST_DIR"), "/../Cargo.lock"),
        root.join("Cargo.lock"),
    )
    .expect("lock file");
    let mut rng = Rng::new(11);
    let points: Vec<[f64; 3]> = (0..32).map(|_| rng.point(4.0)).collect();
    let mut main = String::from("mod scene;\n\nfn main() {\n");
    for p in &points {
        let _ = writeln!(
            main,
            "    let (d, m) = scene::map(glam::Vec3::new({:?}, {:?}, {:?})); println!(\"{{}} {{}}\", d.to_bits(), m);",
            p[0] as f32, p[1] as f32, p[2] as f32
        );
    }
    main.push_str("}\n");
    std::fs::write(root.join("src/main.rs"), main).expect("main");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let run = run_ok(
        Command::new(cargo)
            .current_dir(&root)
            .args(["run", "--quiet", "--offline"])
            .env_remove("RUSTFLAGS"),
        "run cargo",
    );
    let text = std::fs::read_to_string(scene_path).expect("scene");
    let (checked, diags, _) = sdfc_compiler::check_str("seed1.sdf", &text);
    let checked = checked.unwrap_or_else(|| panic!("{diags:?}"));
    let program =
        sdfc_compiler::lower_scene(&checked, &sdfc_compiler::LowerOptions::level(1)).program;
    let out = String::from_utf8_lossy(&run.stdout);
    let mut lines = out.lines();
    for p in &points {
        let (d, m) = eval_point::<f32>(&program, p.map(|v| v as f32));
        assert_eq!(
            lines.next(),
            Some(format!("{} {}", d.to_bits(), m).as_str()),
            "at {p:?}"
        );
    }
}
