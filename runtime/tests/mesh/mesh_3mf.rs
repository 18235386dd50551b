//! `sdfc mesh -o FILE.3mf` (issue 51 item 6), read back with independent readers (`zip`,
//! `quick-xml`): the package's three parts, millimetres, one object per material with its
//! colour, each object a closed oriented 2-manifold, a one-material part the same mesh as
//! its STL, a colour field's colours per vertex, and z up (`--up`). `python/tests/test_mesh_files.py`
//! reads the same files with lib3mf and checks them with manifold3d.

use crate::common::assert_has;
use crate::meshes;

use meshes::*;
use quick_xml::events::Event;
use std::collections::HashMap;
use std::io::Read as _;
use std::path::Path;

/// One `<object>` as read back.
#[derive(Debug, Default)]
struct Object {
    attributes: HashMap<String, String>,
    mesh: Read,
    /// Each triangle's attributes beyond v1, v2, v3 (pid, p1, p2, p3), as written.
    properties: Vec<HashMap<String, String>>,
}

/// A 3MF package as read back.
#[derive(Debug, Default)]
struct Package {
    entries: Vec<String>,
    model: HashMap<String, String>,
    /// `(name, displaycolor)` of each `base`.
    bases: Vec<(String, String)>,
    /// The `m:color`s of each colour group, by id.
    groups: HashMap<String, Vec<String>>,
    objects: Vec<Object>,
    build: Vec<String>,
}

fn attributes(e: &quick_xml::events::BytesStart) -> HashMap<String, String> {
    e.attributes()
        .map(|a| {
            let a = a.expect("attribute");
            (
                String::from_utf8(a.key.as_ref().to_vec()).expect("utf-8"),
                a.normalized_value(quick_xml::XmlVersion::Explicit1_0)
                    .expect("value")
                    .into_owned(),
            )
        })
        .collect()
}

fn read_3mf(path: &Path) -> Package {
    let file = std::fs::File::open(path).expect("open 3mf");
    let mut zip = zip::ZipArchive::new(file).expect("a ZIP archive");
    let mut p = Package {
        entries: (0..zip.len())
            .map(|i| zip.by_index(i).expect("entry").name().to_string())
            .collect(),
        ..Package::default()
    };
    let mut text = String::new();
    for name in ["[Content_Types].xml", "_rels/.rels"] {
        let mut s = String::new();
        zip.by_name(name)
            .expect("entry")
            .read_to_string(&mut s)
            .expect("utf-8");
        assert!(s.contains("3dmanufacturing"), "{name}: {s}");
    }
    zip.by_name("3D/3dmodel.model")
        .expect("the model")
        .read_to_string(&mut text)
        .expect("utf-8");
    let mut reader = quick_xml::Reader::from_str(&text);
    let mut group: Option<String> = None;
    loop {
        let (e, empty) = match reader.read_event().expect("well-formed XML") {
            Event::Eof => break,
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::End(e) => {
                if e.name().as_ref() == b"m:colorgroup" {
                    group = None;
                }
                continue;
            }
            _ => continue,
        };
        let a = attributes(&e);
        match e.name().as_ref() {
            b"model" => p.model = a,
            b"base" => p.bases.push((a["name"].clone(), a["displaycolor"].clone())),
            b"m:colorgroup" if !empty => {
                group = Some(a["id"].clone());
                p.groups.insert(a["id"].clone(), Vec::new());
            }
            b"m:color" => p
                .groups
                .get_mut(group.as_ref().expect("in a group"))
                .expect("group")
                .push(a["color"].clone()),
            b"object" => p.objects.push(Object {
                attributes: a,
                ..Object::default()
            }),
            b"vertex" => {
                let o = p.objects.last_mut().expect("in an object");
                let c = ["x", "y", "z"].map(|k| a[k].parse::<f32>().expect("a number"));
                o.mesh.positions.push(c);
            }
            b"triangle" => {
                let o = p.objects.last_mut().expect("in an object");
                let v = ["v1", "v2", "v3"].map(|k| a[k].parse::<usize>().expect("an index"));
                o.mesh.triangles.push(v);
                let mut rest = a;
                for k in ["v1", "v2", "v3"] {
                    rest.remove(k);
                }
                o.properties.push(rest);
            }
            b"item" => p.build.push(a["objectid"].clone()),
            _ => {}
        }
    }
    p
}

/// `#RRGGBB` of a linear colour, as the writer encodes it.
fn hex(c: [f32; 3]) -> String {
    let [r, g, b] = c.map(sdfc_runtime::image::srgb_encode);
    format!("#{r:02X}{g:02X}{b:02X}")
}

/// The parts scene: four materials, four objects, each closed, in millimetres, coloured by
/// its material, their triangles adding up to about the whole scene's.
#[test]
fn the_parts_scene_is_an_object_per_material() {
    let d = dir("3mf-parts");
    let scene = root().join("examples/mesh/parts.sdf");
    let out = d.join("parts.3mf");
    let err = mesh(&[s(&scene), "-o", s(&out), "--resolution", "48"]);
    assert_has(&err, &["4 objects"]);
    let p = read_3mf(&out);
    assert_eq!(
        p.entries,
        ["[Content_Types].xml", "_rels/.rels", "3D/3dmodel.model"]
    );
    assert_eq!(p.model["unit"], "millimeter");
    // Every scene material, the default first, in its colour (sRGB).
    let names: Vec<&str> = p.bases.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["default", "clay", "steel", "teal", "slate"]);
    assert_eq!(p.bases[1].1, hex([0.85, 0.45, 0.25]));
    assert_eq!(p.bases[4].1, hex([0.3, 0.32, 0.36]));
    let objects: Vec<(&str, &str)> = p
        .objects
        .iter()
        .map(|o| {
            (
                o.attributes["name"].as_str(),
                o.attributes["pindex"].as_str(),
            )
        })
        .collect();
    assert_eq!(
        objects,
        [("clay", "1"), ("steel", "2"), ("teal", "3"), ("slate", "4")]
    );
    let ids: Vec<&String> = p.objects.iter().map(|o| &o.attributes["id"]).collect();
    assert_eq!(p.build.iter().collect::<Vec<_>>(), ids);
    // The sphere and the torus overlap: the torus's object is the torus less the sphere
    // (genus 1 still); the box and the plate are boxes.
    let whole = d.join("parts.stl");
    mesh(&[s(&scene), "-o", s(&whole), "--resolution", "48"]);
    let all = read_stl(&whole).triangles.len();
    let mut sum = 0;
    for (o, chi) in p.objects.iter().zip([2, 2, 0, 2]) {
        let name = &o.attributes["name"];
        assert_eq!(manifold(&o.mesh, name), chi, "{name}: Euler characteristic");
        assert!(
            o.properties.iter().all(|t| t.is_empty()),
            "{name}: one material"
        );
        sum += o.mesh.triangles.len();
    }
    // The objects hold the scene's surface and, where sphere and torus meet, the sphere's
    // surface inside the torus twice (once on each side): more triangles, not many more.
    assert!(sum > all && sum < all + all / 4, "{sum} against {all}");
}

/// A one-material part is one object, the same mesh as its STL: as many triangles, and as
/// many vertices as an STL reader finds by position.
#[test]
fn a_one_material_part_is_its_stl_mesh() {
    let d = dir("3mf-bracket");
    let scene = root().join("examples/mesh/bracket.sdf");
    let (stl, tmf) = (d.join("bracket.stl"), d.join("bracket.3mf"));
    mesh(&[s(&scene), "-o", s(&stl), "--resolution", "64"]);
    mesh(&[s(&scene), "-o", s(&tmf), "--resolution", "64"]);
    let a = read_stl(&stl);
    let p = read_3mf(&tmf);
    assert_eq!(p.objects.len(), 1);
    let o = &p.objects[0];
    assert_eq!(o.attributes["name"], "steel");
    assert_eq!(o.mesh.triangles.len(), a.triangles.len());
    assert_eq!(o.mesh.positions.len(), a.positions.len());
    // Genus 3: χ = −4.
    assert_eq!(manifold(&o.mesh, "bracket"), -4);
}

/// A colour field's material: its triangles take a colour per vertex from a colour group
/// (the Materials extension, declared required), the field's colour at the vertex.
#[test]
fn a_colour_field_is_a_colour_per_vertex() {
    let body =
        "material g = phong { color: field { vec3(0.5 + 0.5 * p.y, 0.25, 0.5 - 0.5 * p.y) } };\n\
         material red = phong { color: (0.9, 0.1, 0.1) };\n\
         scene { sphere(1) @ g; box(0.5).translate(2, 0, 0) @ red; }\n";
    let (_, scene, out) = scene_in("3mf-field", "two.sdf", body, "two.3mf");
    mesh(&[s(&scene), "-o", s(&out), "--resolution", "32"]);
    let p = read_3mf(&out);
    assert_eq!(p.model["requiredextensions"], "m");
    assert_eq!(p.objects.len(), 2);
    let sphere = &p.objects[0];
    let id = &sphere.attributes["id"];
    let group = p.groups.values().next().expect("a colour group");
    assert_eq!(p.groups.len(), 1);
    assert_eq!(group.len(), sphere.mesh.positions.len());
    assert!(id.parse::<u32>().unwrap() > 1);
    for (t, props) in sphere.mesh.triangles.iter().zip(&sphere.properties) {
        for (k, v) in ["p1", "p2", "p3"].iter().zip(t) {
            assert_eq!(props[*k], v.to_string());
        }
    }
    for (q, c) in sphere.mesh.positions.iter().zip(group) {
        // The package has z up: the scene's y is the file's z.
        let y = q[2];
        let want = [0.5 + 0.5 * y, 0.25, (0.5 - 0.5 * y).max(0.0)];
        let got = u32::from_str_radix(&c[1..], 16).expect("hex");
        let want = u32::from_str_radix(&hex(want)[1..], 16).unwrap();
        for shift in [0, 8, 16] {
            let (a, b) = ((got >> shift) & 255, (want >> shift) & 255);
            assert!(a.abs_diff(b) <= 1, "vertex {q:?}: {c}");
        }
    }
    let cube = &p.objects[1];
    assert_eq!(cube.attributes["name"], "red");
    assert_eq!(manifold(&cube.mesh, "cube"), 2);
}

/// A region that leaves a part out writes the others, and a 3MF with no part in its region
/// is refused like any mesh with no triangles.
#[test]
fn a_part_outside_the_region_is_left_out() {
    let d = dir("3mf-region");
    let scene = root().join("examples/mesh/parts.sdf");
    let out = d.join("left.3mf");
    // x below -0.6: the sphere and the plate's left end (the torus reaches to -0.47, the
    // box to 0.15).
    let err = mesh(&[
        s(&scene),
        "-o",
        s(&out),
        "--bounds=-1,-0.7,-1,-0.6,0.7,1",
        "--resolution",
        "32",
    ]);
    assert_has(&err, &["`steel` lies outside the region"]);
    let p = read_3mf(&out);
    let names: Vec<&str> = p
        .objects
        .iter()
        .map(|o| o.attributes["name"].as_str())
        .collect();
    assert_eq!(names, ["clay", "slate"]);
    for o in &p.objects {
        manifold(&o.mesh, &o.attributes["name"]);
    }
}

/// The signed volume of a closed mesh (positive when its triangles wind counter-clockwise
/// seen from outside).
fn volume(m: &Read) -> f64 {
    m.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| m.positions[i].map(f64::from));
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum()
}

/// The smallest and largest coordinate along each axis.
fn extent(m: &Read) -> [[f32; 2]; 3] {
    [0, 1, 2].map(|i| {
        let (lo, hi) = m
            .positions
            .iter()
            .fold((f32::MAX, f32::MIN), |(lo, hi), p| {
                (lo.min(p[i]), hi.max(p[i]))
            });
        [lo, hi]
    })
}

/// A 3MF stands on the build plate: the scene's up (+y) is the file's +z unless `--up y`
/// keeps the scene's axes; `--up z` turns an STL the same way. A quarter turn about x, so
/// the triangles keep their winding (the volume stays positive) and the mesh its shape.
#[test]
fn a_3mf_has_z_up_and_up_turns_any_format() {
    let d = dir("3mf-up");
    // 1 wide (x), 3 tall (y, from 0 to 3), half deep (z, towards -z from 0).
    let body = "scene { box((0.5, 1.5, 0.25)).translate(0, 1.5, -0.25); }\n";
    let scene = write_scene(&d, "post.sdf", body);
    let near = |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).abs() < 0.05 && (a[1] - b[1]).abs() < 0.05;
    let file = |name: &str, up: Option<&str>| {
        let out = d.join(name);
        let mut args = vec![s(&scene), "-o", s(&out), "--resolution", "32"];
        if let Some(up) = up {
            args.extend(["--up", up]);
        }
        mesh(&args);
        out
    };
    let tall = read_3mf(&file("tall.3mf", None)).objects.remove(0).mesh;
    let e = extent(&tall);
    assert!(near(e[2], [0.0, 3.0]), "z: {e:?}");
    assert!(near(e[1], [0.0, 0.5]), "y (the scene's -z): {e:?}");
    assert!(near(e[0], [-0.5, 0.5]), "x: {e:?}");
    assert!(volume(&tall) > 1.4, "{}", volume(&tall));
    let y = read_3mf(&file("y.3mf", Some("y"))).objects.remove(0).mesh;
    assert!(near(extent(&y)[1], [0.0, 3.0]), "{:?}", extent(&y));
    // STL keeps the scene's axes unless asked; with --up z it is the 3MF's placement.
    let stl = read_stl(&file("plain.stl", None));
    assert!(near(extent(&stl)[1], [0.0, 3.0]), "{:?}", extent(&stl));
    let turned = read_stl(&file("z.stl", Some("z")));
    assert_eq!(turned.triangles.len(), stl.triangles.len());
    for (t, u) in stl.triangles.iter().zip(&turned.triangles) {
        for (&i, &j) in t.iter().zip(u) {
            let [x, y, z] = stl.positions[i];
            assert_eq!(turned.positions[j], [x, -z, y]);
        }
    }
    for m in [&y, &stl, &turned] {
        assert!(
            (volume(m) - volume(&tall)).abs() < 1e-3,
            "{} {}",
            volume(m),
            volume(&tall)
        );
    }
    // A wrong axis is refused by name.
    let o = sdfc(&["mesh", s(&scene), "-o", s(&d.join("x.stl")), "--up", "x"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("possible values: y, z"));
}
