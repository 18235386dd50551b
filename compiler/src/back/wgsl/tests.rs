//! Tests of the kernel's contract: the scene uniform's bytes follow the template's layout, and
//! the contract names every feature and refuses other scenes.

use super::*;

fn scene(text: &str) -> Scene {
    let (scene, diags, _) = crate::front::check_str("contract.sdf", text);
    assert!(!crate::diagnostics::has_errors(&diags), "{diags:?}");
    scene.expect("checks")
}

const LIT: &str = "material red = phong { color: (0.9, 0.2, 0.2), reflect: 0.3 };\n\
    material floor = checker { a: (0.9, 0.9, 0.9), b: (0.1, 0.1, 0.1), size: 1 };\n\
    light point { position: (4, 6, -4), radius: 30 }\n\
    light directional { direction: (-1, -1, 0.5) }\n\
    render { relaxation: 1.3 }\n\
    scene { plane((0, 1, 0), 0) @ floor; torus(1, 0.3) @ red; }";

/// The members of `layout` at `paths`, read from `bytes` at naga's offsets, as words.
fn read(layout: &Uniform, bytes: &[u8], paths: &[String]) -> Vec<Vec<u32>> {
    paths
        .iter()
        .map(|p| {
            let mut w = layout.writer();
            // The offset of `p`: write a marker there and find it.
            w.uints(p, &[u32::MAX; 4])
                .or_else(|_| w.floats(p, &[f64::from(f32::from_bits(0x7f80_0001)); 4]))
                .expect("a member");
            let marked = w.finish_unchecked();
            let at = marked
                .chunks_exact(4)
                .position(|c| c != [0; 4])
                .expect("marked")
                * 4;
            bytes[at..at + 16]
                .chunks_exact(4)
                .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect()
        })
        .collect()
}

/// `Params` with its members reordered and `background` moved first: the uniform is
/// written at the new offsets naga reports, and every member reads back the same; a
/// member added to the template is refused until something writes it, and a member the
/// writer names and the template lacks is refused.
#[test]
fn the_uniform_follows_the_templates_layout() {
    let scene = scene(LIT);
    let lowered = Lowered::new(&scene);
    let options = Options::default();
    let kernel = write_from(TEMPLATE, &scene, &lowered, &options).expect("kernel");
    let bytes = uniforms(&kernel.contract.uniform, &scene, 2.0).expect("uniform");
    assert_eq!(bytes.len() as u32, kernel.contract.uniform.size);

    let background = "    background: vec4<f32>,\n";
    let depth = "    depth: vec4<u32>,      // max_depth\n";
    assert!(TEMPLATE.contains(background) && TEMPLATE.contains(depth));
    let reordered = TEMPLATE.replace(background, "").replace(
        "struct Params {\n",
        &format!("struct Params {{\n{depth}{background}"),
    );
    let reordered = reordered.replacen(depth, "", 2).replacen(
        "struct Params {\n",
        &format!("struct Params {{\n{depth}"),
        1,
    );
    let moved = write_from(&reordered, &scene, &lowered, &options).expect("kernel");
    let (a, b) = (&kernel.contract.uniform, &moved.contract.uniform);
    let offset =
        |u: &Uniform, name: &str| u.members.iter().find(|m| m.name == name).map(|m| m.offset);
    assert_ne!(offset(a, "background"), offset(b, "background"));
    assert_ne!(offset(a, "depth"), offset(b, "depth"));
    let moved_bytes = uniforms(b, &scene, 2.0).expect("uniform");
    let paths: Vec<String> = [
        "eye",
        "cam_w",
        "view",
        "march",
        "background",
        "counts",
        "depth",
        "points[0].position",
        "points[0].color",
        "dirs[0].to_light",
        "materials[1].optics",
        "materials[1].shift",
    ]
    .map(String::from)
    .to_vec();
    assert_eq!(read(a, &bytes, &paths), read(b, &moved_bytes, &paths));

    let added = TEMPLATE.replace(
        "struct Params {\n",
        "struct Params {\n    exposure: vec4<f32>,\n",
    );
    let grown = write_from(&added, &scene, &lowered, &options).expect("kernel");
    let e = uniforms(&grown.contract.uniform, &scene, 2.0).expect_err("unwritten");
    assert!(e.0.contains("`exposure`"), "{e}");

    let shrunk = write_from(&TEMPLATE.replace(depth, ""), &scene, &lowered, &options);
    // The template reads `params.depth`, so naga refuses it first; a writer naming a
    // member the layout lacks is refused by name.
    assert!(shrunk.is_err());
    let mut w = a.writer();
    let e = w.floats("exposure", &[0.0; 4]).expect_err("no such member");
    assert!(e.0.contains("no member `exposure`"), "{e}");
    let e = w.floats("counts", &[0.0; 4]).expect_err("u32s");
    assert!(e.0.contains("holds 4 u32"), "{e}");
    let e = w
        .floats("points[1].color", &[0.0; 4])
        .expect_err("one light");
    assert!(e.0.contains("holds 1"), "{e}");
}

/// The contract lists every feature of the template (and PARAMS), and a render of a scene that needs
/// another feature (a soft light where the kernel has hard shadows) or other settings is
/// refused, naming the difference.
#[test]
fn the_contract_names_every_feature_and_refuses_other_scenes() {
    let scene = scene(LIT);
    let lowered = Lowered::new(&scene);
    let kernel = write(&scene, &lowered).expect("kernel");
    let flags: std::collections::BTreeSet<&str> = TEMPLATE
        .lines()
        .filter_map(|l| l.trim().strip_prefix("//#if "))
        .map(|f| f.trim().trim_start_matches('!'))
        .collect();
    let mut named: std::collections::BTreeSet<&str> =
        kernel.contract.features.iter().map(|(n, _)| *n).collect();
    // PARAMS and INTERPRETED change the distance program's text, not the template.
    assert!(named.remove("PARAMS"));
    assert!(named.remove("INTERPRETED"));
    assert_eq!(flags, named);
    let contract = &kernel.contract;
    assert!(contract.has("RELAX") && contract.has("POINT") && !contract.has("SOFT"));
    contract.check(&scene, false).expect("its own scene");

    let soft = self::scene(&LIT.replace("radius: 30", "radius: 30, penumbra: 4deg"));
    let e = contract.check(&soft, false).expect_err("soft shadows");
    assert!(e.0.contains("SOFT is off in the kernel and on"), "{e}");
    let mut plain = scene.clone();
    plain.settings.relaxation = 1.0;
    let e = contract.check(&plain, false).expect_err("no relaxation");
    assert!(e.0.contains("no over-relaxation"), "{e}");
    assert!(e.0.contains("RELAX is on in the kernel and off"), "{e}");
}
