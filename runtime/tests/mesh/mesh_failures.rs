//! `sdfc mesh`'s failure paths (docs/failures.md): unbounded scenes, limits and bad arguments,
//! a killed mesh, a read-only output, missing files, empty meshes and tiny cells, a grid too fine.

use crate::common::assert_has;
use crate::meshes;
use meshes::*;
use std::process::Command;

/// An unbounded scene needs --bounds, and the error says so; with it, the plane is cut to the
/// box and the cut closed.
#[test]
fn an_unbounded_scene_needs_bounds_and_is_closed_at_them() {
    let body = "scene { plane(); sphere(0.5).translate(0, 0.4, 0); }\n";
    let (_, scene, out) = scene_in("unbounded", "floor.sdf", body, "floor.stl");
    let o = sdfc(&["mesh", s(&scene), "-o", s(&out)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_has(&err, &["unbounded", "`--bounds X0,Y0,Z0,X1,Y1,Z1`"]);
    assert!(!out.exists());
    mesh(&[
        s(&scene),
        "-o",
        s(&out),
        "--bounds=-1,-0.5,-1,1,1,1",
        "--resolution",
        "40",
    ]);
    // The slab and the sphere sunk into it are one surface of genus 0.
    assert_eq!(manifold(&read_stl(&out), "floor"), 2);
}

/// The cell limit, the memory limit and bad arguments stop before any file is written, with
/// the flag to change named.
#[test]
fn limits_and_bad_arguments_are_reported() {
    let d = dir("limits");
    let scene = root().join("examples/mesh/parts.sdf");
    let out = d.join("p.stl");
    let run = |extra: &[&str]| {
        let mut a = vec!["mesh", s(&scene), "-o", s(&out)];
        a.extend_from_slice(extra);
        let o = sdfc(&a);
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let (code, err) = run(&["--limit", "cells=1000"]);
    assert_eq!(code, Some(1), "{err}");
    assert_has(&err, &["cells limit of 1000", "--limit cells="]);
    let (code, err) = run(&["--limit", "memory=1", "--resolution", "200"]);
    assert_eq!(code, Some(1), "{err}");
    assert_has(&err, &["allocating at most", "--limit memory="]);
    let (code, err) = run(&["--set", "sharp=maybe"]);
    assert_eq!(code, Some(2), "{err}");
    assert_has(&err, &["sharp must be on or off"]);
    let (code, err) = run(&["--bounds=1,0,0,0,1,1"]);
    assert_eq!(code, Some(2), "{err}");
    assert_has(&err, &["X0 < X1"]);
    // More workers than the `threads` limit (10 000 never finished): refused, naming the
    // range and the value that would do.
    let (code, err) = run(&["--threads", "10000"]);
    assert_eq!(code, Some(2), "{err}");
    assert_has(&err, &["from 1 to 1024", "`--limit threads=10000`"]);
    assert!(!out.exists());
    let o = sdfc(&["mesh", s(&scene), "-o", s(&d.join("p.xyz"))]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains(".stl, .obj, .ply, .glb or .3mf"));
}

/// Whether `bytes` are a whole binary STL: the header's triangle count matches the length.
fn whole_binary_stl(bytes: &[u8]) -> bool {
    bytes.len() >= 84 && {
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        bytes.len() == 84 + 50 * count
    }
}

/// A `sdfc mesh` killed (SIGKILL) while it writes leaves the previous file as it was or the
/// complete new one, never a part of it: the process is killed as soon as the output changes
/// or its temporary file appears.
#[test]
fn a_killed_mesh_leaves_the_old_file_or_a_whole_new_one() {
    let d = dir("killed");
    let out = d.join("m.stl");
    let old = b"the previous mesh".to_vec();
    std::fs::write(&out, &old).expect("old file");
    let scene = root().join("examples/mesh/bracket.sdf");
    let mut child = Command::new(env!("CARGO_BIN_EXE_sdfc"))
        .args(["mesh", s(&scene), "--resolution", "400", "-o", s(&out)])
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("run sdfc");
    let started = std::time::Instant::now();
    loop {
        let temporary = std::fs::read_dir(&d)
            .expect("dir")
            .flatten()
            .any(|e| e.file_name().to_string_lossy().ends_with(".tmp"));
        let changed = std::fs::read(&out).map_or(true, |b| b != old);
        if let Some(status) = child.try_wait().expect("wait") {
            assert!(status.success(), "sdfc mesh failed: {status}");
            break;
        }
        if temporary || changed {
            break;
        }
        assert!(started.elapsed().as_secs() < 120, "sdfc mesh never wrote");
        std::thread::sleep(std::time::Duration::from_micros(200));
    }
    let _ = child.kill();
    let _ = child.wait();
    let now = std::fs::read(&out).expect("the output is still there");
    assert!(
        now == old || whole_binary_stl(&now),
        "a partial mesh of {} bytes replaced the old file",
        now.len()
    );
}

/// A read-only output file is refused before the mesh is made, and stays as it was.
#[test]
fn a_read_only_output_is_refused_and_left_unchanged() {
    use std::os::unix::fs::PermissionsExt;
    let d = dir("read-only");
    let out = d.join("m.stl");
    std::fs::write(&out, b"keep me").expect("old file");
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o444)).expect("chmod");
    let scene = root().join("examples/mesh/parts.sdf");
    let err = exits(&["mesh", s(&scene), "--resolution", "16", "-o", s(&out)], 2);
    assert_has(&err, &["read-only"]);
    assert_eq!(std::fs::read(&out).expect("kept"), b"keep me");
}

/// A file that cannot be read exits 2, as for `check` and `render`; a grid that finds no
/// surface (bounds away from the shape, or cells too coarse) is an error, exit 1, with
/// nothing written; a tiny cell is named in scientific notation, not as `0`.
#[test]
fn missing_files_empty_meshes_and_tiny_cells_are_reported() {
    let (d, scene, out) = scene_in("empty", "ball.sdf", "scene { sphere(0.5); }\n", "ball.stl");
    let o = sdfc(&["mesh", s(&d.join("nope.sdf")), "-o", s(&out)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot read"));
    // Bounds away from the shape's box say where it is; bounds in its box's corner, that they
    // hold none of the surface.
    let err = exits(
        &["mesh", s(&scene), "-o", s(&out), "--bounds=2,2,2,3,3,3"],
        1,
    );
    assert_has(&err, &["--bounds does not reach the scene's solid, which lies within `--bounds=-0.5,-0.5,-0.5,0.5,0.5,0.5`"]);
    assert!(!out.exists());
    let err = exits(
        &[
            "mesh",
            s(&scene),
            "-o",
            s(&out),
            "--bounds=0.4,0.4,0.4,0.5,0.5,0.5",
        ],
        1,
    );
    assert_has(&err, &["no triangles", "--bounds"]);
    assert!(!out.exists());
    // A solid known to be empty says so, with no advice on cells or bounds (it was told to
    // raise the resolution, or that it was unbounded).
    for empty in [
        "intersect(sphere(1), sphere(1).translate(5, 0, 0))",
        "extrude(intersect(circle(1), circle(1).translate(5, 0)), 1)",
    ] {
        let e = write_scene(&d, "e.sdf", &format!("scene {{ {empty}; }}\n"));
        let o = sdfc(&["mesh", s(&e), "-o", s(&out)]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{empty}: {err}");
        assert!(
            err.contains("the scene's solid is empty")
                && !err.contains("resolution")
                && !err.contains("unbounded"),
            "{empty}: {err}"
        );
    }
    // A sphere of radius 0.001 at --resolution 100: cells of 2e-5, cheap to mesh.
    let tiny = write_scene(&d, "tiny.sdf", "scene { sphere(0.001); }\n");
    let o = sdfc(&["mesh", s(&tiny), "-o", s(&out), "--resolution", "100"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !err.contains("of 0 ") && !err.contains("of 0:") && err.contains("e-5"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// A grid far too fine for the limits is refused from the octree's first levels, which prove
/// enough surface through the balls about their centres inside the solid, before the large
/// levels are evaluated: by the cells limit (resolution 100 000) or by the candidates the
/// memory limit lets contouring hold (resolution 2000). The proof is a lower bound: with the
/// true number of candidates as the most allowed, the octree finishes.
#[test]
fn a_grid_too_fine_is_refused_from_the_first_levels() {
    use sdfc_runtime::mesh::{octree, Field, Grid};
    let bracket = program(&root().join("examples/mesh/bracket.sdf"));
    let (lo, hi) = ([-0.9, -0.5, -0.6], [0.9, 0.4, 0.6]);
    let field = Field::new(&bracket, true, [lo, hi]);
    let fine = Grid::over(&[lo, hi], 1.8 / 100_000.0);
    let refused = octree::candidates(&field, &fine, 50_000_000, u64::MAX, &|_| {});
    assert!(
        matches!(refused, Err(octree::Refused::Cells(n)) if n > 50_000_000),
        "{refused:?}"
    );
    assert!(field.evaluated() < 100_000, "{}", field.evaluated());
    let field = Field::new(&bracket, true, [lo, hi]);
    let grid = Grid::over(&[lo, hi], 1.8 / 2000.0);
    let refused = octree::candidates(&field, &grid, 50_000_000, 40_000, &|_| {});
    assert!(
        matches!(refused, Err(octree::Refused::Candidates(n)) if n > 40_000),
        "{refused:?}"
    );
    assert!(field.evaluated() < 100_000, "{}", field.evaluated());
    // Never more than the octree finds.
    let cases = [
        ("examples/mesh/bracket.sdf", lo, hi, 160),
        ("examples/mesh/parts.sdf", [-1.0; 3], [1.0; 3], 160),
    ];
    for (file, lo, hi, n) in cases {
        let p = program(&root().join(file));
        let field = Field::new(&p, true, [lo, hi]);
        let longest = (0..3).map(|i| hi[i] - lo[i]).fold(0.0, f64::max);
        let grid = Grid::over(&[lo, hi], longest / n as f64);
        let all = octree::candidates(&field, &grid, 1 << 40, u64::MAX, &|_| {}).expect("all");
        let found = all.cells.len() as u64;
        let again = octree::candidates(&field, &grid, 1 << 40, found, &|_| {});
        assert_eq!(
            again.as_ref().map(|c| c.cells.len() as u64),
            Ok(found),
            "{file}"
        );
        // Fewer allowed: refused by a number of candidates between the most and the truth.
        let mut refused = 0;
        for most in [found / 4, found / 16, found / 64, 10] {
            match octree::candidates(&field, &grid, 1 << 40, most, &|_| {}) {
                Err(octree::Refused::Candidates(k)) => {
                    assert!(k > most && k <= found, "{file}: {k} of {found}");
                    refused += 1;
                }
                Ok(c) => assert_eq!(c.cells.len() as u64, found, "{file}"),
                Err(other) => panic!("{file}: {other:?}"),
            }
        }
        assert!(refused > 0, "{file}: never refused");
    }
}
