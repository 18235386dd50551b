//! `sdfc mesh` on printable parts (issue 51): flat faces stay flat (every vertex within 1 % of
//! a cell of the surface, by the f64 distance program, with corners and edges kept) on a
//! honeycomb panel, whose hexagonal cells' 120° edges and their corners on the plate's faces
//! fall anywhere in the grid, and on a box turned off the grid's axes; and walls and sheets
//! thinner than a cell kept (meshed again on a finer grid), where parts that touch a floor
//! are not taken for thin gaps.

use crate::common::assert_has;
use crate::meshes;

use meshes::*;

/// A panel 72 × 6 × 72 mm with hexagonal cells 7 mm across the flats and walls 1 mm thick
/// (two offset lattices of `hex_prism`), as a printer's honeycomb.
const HONEYCOMB: &str = "\
let cell = hex_prism(3.5, 20);
let a = repeat(cell, (13.856406, 0, 8), (5, 1, 9));
let b = repeat(cell, (13.856406, 0, 8), (4, 1, 8));
scene { box((36, 3, 36)).subtract(union(a, b)); }
";

/// The largest |f| at the mesh's vertices, as a fraction of a cell.
fn worst_vertex(scene: &std::path::Path, m: &Read, voxel: f64) -> f64 {
    let p = program(scene);
    m.positions
        .iter()
        .map(|&q| distance(&p, q).abs() / voxel)
        .fold(0.0, f64::max)
}

/// Every vertex of the honeycomb within 1 % of a cell of its faces at cells of 0.5625 mm
/// (resolution 128 over its 72 mm); before the QEF solution was kept inside its
/// cell and 120° edges were taken for features, vertices were up to 22 % of a cell off.
#[test]
fn honeycomb_vertices_lie_on_its_faces() {
    let (_, scene, out) = scene_in("honeycomb", "honeycomb.sdf", HONEYCOMB, "honeycomb.stl");
    mesh(&[s(&scene), "-o", s(&out), "--resolution", "128"]);
    let m = read_stl(&out);
    // 45 + 32 holes through it: genus 77.
    assert_eq!(manifold(&m, "honeycomb"), 2 - 2 * 77);
    let voxel = 72.0 / 128.0;
    let worst = worst_vertex(&scene, &m, voxel);
    assert!(
        worst <= 0.01,
        "a vertex is {:.2} % of a cell off",
        100.0 * worst
    );
}

/// A box turned about two axes: every vertex within 1 % of a cell of its faces (before the
/// QEF's options in the cell were chosen by the field, a corner's vertex clamped into its
/// cell was 1.9 % inside), and each corner with a vertex within 12 % of a cell of it: a
/// corner that pokes into a cell without a patch (no grid edge there crosses the surface) gets
/// the nearest point of an edge in the neighbouring cell, 7 to 10 % of a cell away here.
#[test]
fn a_turned_box_keeps_its_corners_and_flat_faces() {
    let body = "scene { box((0.5, 0.3, 0.4)).rotate_y(23deg).rotate_x(17deg); }\n";
    let (_, scene, out) = scene_in("turned-box", "box.sdf", body, "box.stl");
    let voxel = 0.021;
    mesh(&[s(&scene), "-o", s(&out), "--voxel", "0.021"]);
    let m = read_stl(&out);
    assert_eq!(manifold(&m, "turned box"), 2);
    let worst = worst_vertex(&scene, &m, voxel);
    assert!(
        worst <= 0.01,
        "a vertex is {:.2} % of a cell off",
        100.0 * worst
    );
    let (sy, cy) = 23f64.to_radians().sin_cos();
    let (sx, cx) = 17f64.to_radians().sin_cos();
    for k in 0..8 {
        let c = [0.5, 0.3, 0.4];
        let q = [
            if k & 1 == 0 { -c[0] } else { c[0] },
            if k & 2 == 0 { -c[1] } else { c[1] },
            if k & 4 == 0 { -c[2] } else { c[2] },
        ];
        // rotate_y then rotate_x, as the scene applies them to the shape.
        let q = [cy * q[0] + sy * q[2], q[1], -sy * q[0] + cy * q[2]];
        let q = [q[0], cx * q[1] - sx * q[2], sx * q[1] + cx * q[2]];
        let near = m
            .positions
            .iter()
            .map(|v| {
                (0..3)
                    .map(|i| (v[i] as f64 - q[i]).powi(2))
                    .sum::<f64>()
                    .sqrt()
            })
            .fold(f64::INFINITY, f64::min);
        assert!(near <= 0.12 * voxel, "corner {q:?}: nearest vertex {near}");
    }
}

/// A Gridfinity-style bin in millimetres, 100 × 40 × 60 outside with walls 0.475 thick and a
/// divider as thin, slanted to the grid, meshed at resolution 128 (cells of 0.78): the grid
/// misses the divider between its points, which fell into two pieces before; now the edges
/// that cross it twice are found and the bin is meshed again on cells of 0.39, one closed
/// piece of genus 0.
#[test]
fn a_bin_with_walls_thinner_than_a_cell_keeps_its_topology() {
    let (_, scene, out) = scene_in("bin", "bin.sdf", meshes::THIN_WALLED_BIN, "bin.stl");
    let err = mesh(&[s(&scene), "-o", s(&out), "--resolution", "128"]);
    assert_has(&err, &["meshing again with cells of 0.3906"]);
    assert!(!err.contains("warning"), "{err}");
    let m = read_stl(&out);
    assert_eq!(manifold(&m, "bin"), 2, "genus 0");
    assert_eq!(components(&m), 1);
}

/// A sheet 0.3 cells thick, slanted to the grid, stays one piece.
#[test]
fn a_sheet_of_a_third_of_a_cell_stays_one_piece() {
    let body = "scene { box((0.5, 0.006, 0.4)).rotate_x(11deg).rotate_z(7deg); }\n";
    let (_, scene, out) = scene_in("sheet", "sheet.sdf", body, "sheet.stl");
    let err = mesh(&[s(&scene), "-o", s(&out), "--voxel", "0.04"]);
    assert_has(&err, &["meshing again with cells of 0.01\n"]);
    let m = read_stl(&out);
    assert_eq!(manifold(&m, "sheet"), 2);
    assert_eq!(components(&m), 1);
}

/// A 3MF of two materials, one of them the thin sheet, touching a block: both parts are
/// meshed again on the one finer grid (each refined on its own left them on different grids,
/// whose shared faces no longer matched); `--set thin=off` keeps the cells asked for and
/// warns instead.
#[test]
fn every_part_of_a_3mf_is_refined_alike_and_thin_off_only_warns() {
    let body = "material a = phong { color: (1, 0, 0) };\nmaterial b = phong { color: (0, 0, 1) };\n\
         scene { box((0.5, 0.006, 0.4)).rotate_x(11deg).rotate_z(7deg) @ a; box(0.2).translate(0.6, 0, 0) @ b; }\n";
    let (d, scene, out) = scene_in("parts_thin", "two.sdf", body, "two.3mf");
    let stats = sdfc(&[
        "mesh",
        s(&scene),
        "-o",
        s(&out),
        "--voxel",
        "0.04",
        "--stats",
    ]);
    let text = String::from_utf8_lossy(&stats.stdout).into_owned();
    let err = String::from_utf8_lossy(&stats.stderr).into_owned();
    assert!(stats.status.success(), "{err}");
    let grids: Vec<&str> = text.lines().filter(|l| l.starts_with("grid")).collect();
    assert_eq!(grids.len(), 2, "{text}");
    assert_eq!(grids[0], grids[1], "{text}");
    assert!(grids[0].contains("refined from cells of 0.04"), "{text}");
    let err = mesh(&[
        s(&scene),
        "-o",
        s(&d.join("sheet.stl")),
        "--voxel",
        "0.04",
        "--set",
        "thin=off",
    ]);
    assert!(!err.contains("meshing again"), "{err}");
    assert_has(
        &err,
        &["warning: a wall or gap about", "--voxel 0.01 resolves it"],
    );
}

/// Where the memory limit leaves no room for the finer grid, the sheet is meshed on the
/// cells asked for, with a warning that names its place and the cell that resolves it.
#[test]
fn a_sheet_too_thin_for_the_memory_limit_is_warned_about() {
    let body = "scene { box((0.5, 0.0006, 0.4)).rotate_x(11deg).rotate_z(7deg); }\n";
    let (_, scene, out) = scene_in("sheet_limit", "sheet.sdf", body, "sheet.stl");
    let err = mesh(&[
        s(&scene),
        "-o",
        s(&out),
        "--voxel",
        "0.04",
        "--limit",
        "memory=64",
    ]);
    assert_has(
        &err,
        &[
            "warning: a wall or gap about 0.0012 thick at (",
            "more than the memory limit of 64 MiB",
            "--voxel 0.0011 resolves it",
        ],
    );
    assert!(!err.contains("meshing again"), "{err}");
}

/// A sphere resting on a floor, a cylinder lying on it and a spring's coil lifting off it
/// leave gaps that close where they touch: no finer grid resolves them, and they are
/// neither refined nor reported.
#[test]
fn parts_touching_a_floor_are_not_thin_gaps() {
    let body = "scene {
  box((2, 0.1, 2)).translate(0, -0.1, 0);
  sphere(0.5).translate(-1, 0.5, -1);
  cylinder(0.3, 0.6).rotate_x(90deg).translate(1, 0.3, 0.5);
  box((0.4, 0.1, 0.2)).rotate_z(4deg).translate(0, 0.1 + 0.4 * sin(4deg), -0.5);
}
";
    let (_, scene, out) = scene_in("touching", "touching.sdf", body, "touching.stl");
    let err = mesh(&[s(&scene), "-o", s(&out), "--resolution", "128"]);
    assert!(
        !err.contains("meshing again") && !err.contains("warning"),
        "{err}"
    );
}
