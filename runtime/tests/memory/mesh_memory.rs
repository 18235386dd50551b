//! The memory `sdfc mesh` announces is an upper bound: a counting global allocator records
//! the peak of live heap bytes while the octree (`octree::bytes`) and then contouring
//! (`contour::candidate_bytes` and `BYTES_PER_SURFACE_CELL` per surface cell) run through the
//! library, for the benchmark scene, the bracket and a field without a proven bound, and the
//! octree refused by the cells limit.
//!
//! The counter sees every thread of the process, so the test measures alone
//! ([`counting::alone`]).

use sdfc_compiler::lower;
use sdfc_runtime::mesh::contour::{self, BYTES_PER_SURFACE_CELL};
use sdfc_runtime::mesh::{octree, Field, Grid, Settings};
use std::path::Path;

use crate::counting;
use counting::peak_of;
use std::sync::atomic::{AtomicU64, Ordering};

/// The grid `sdfc mesh` lays over `[lo, hi]` with `n` cells along the longest side.
fn grid(lo: [f64; 3], hi: [f64; 3], n: u32) -> Grid {
    let longest = (0..3).map(|i| hi[i] - lo[i]).fold(0.0, f64::max);
    Grid::over(&[lo, hi], longest / n as f64)
}

#[test]
fn meshing_stays_within_the_memory_it_announces() {
    let _alone = counting::alone();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let cases: [(&str, [f64; 3], [f64; 3], u32); 5] = [
        ("examples/mesh/parts.sdf", [-1.0; 3], [1.0; 3], 48),
        ("examples/mesh/parts.sdf", [-1.0; 3], [1.0; 3], 128),
        (
            "examples/mesh/bracket.sdf",
            [-0.9, -0.5, -0.6],
            [0.9, 0.4, 0.6],
            96,
        ),
        (
            "examples/seed6.sdf",
            [-1.3, -1.3, -1.3],
            [1.3, 1.3, 1.3],
            40,
        ),
        ("examples/mesh/parts.sdf", [-1.0; 3], [1.0; 3], 16),
    ];
    for (k, (file, lo, hi, n)) in cases.into_iter().enumerate() {
        let loaded = sdfc_runtime::frontend::load(&root.join(file)).expect("load");
        let scene = loaded.scene.expect("checks");
        let analysis = sdfc_compiler::analysis::analyse(&scene);
        let proven = analysis.root().expect("objects").proven;
        let program = lower(&scene);
        let field = Field::new(&program, proven, [lo, hi]);
        let g = grid(lo, hi, n);
        let max = 1 << 40;
        let (found, used) = peak_of(|| octree::candidates(&field, &g, max, u64::MAX, &|_| {}));
        let found = found.expect("within the cells limit");
        let bound = octree::bytes(&g, proven, max);
        // The first case warms up rayon's pool and the evaluators' code paths.
        if k > 0 {
            assert!(
                used <= bound,
                "{file} at {n}: octree used {used} B, announced {bound}"
            );
        }
        let candidates = contour::candidate_bytes(&g, found.cells.len() as u64);
        let surface = AtomicU64::new(0);
        let check = |cells: u64| {
            surface.store(cells, Ordering::SeqCst);
            Ok(())
        };
        let settings = Settings::default();
        let (mesh, used) =
            peak_of(|| contour::contour(&field, &g, found.cells, &settings, max, &check, &|_| {}));
        let (mesh, _) = mesh.expect("contoured");
        let bound = candidates + surface.load(Ordering::SeqCst) * BYTES_PER_SURFACE_CELL;
        assert!(!mesh.triangles.is_empty(), "{file}");
        if k > 0 {
            assert!(
                used <= bound,
                "{file} at {n}: contouring used {used} B, announced {bound}"
            );
        }
        eprintln!("{file} at {n}: contouring peak {used} B of {bound} announced");
    }
    // An octree refused by the cells limit stays within the same announcement: the level
    // that would pass the limit is counted, not stored. The limit is set just above what the
    // octree evaluates before its last level, so that the last level (about four times the one
    // before) is refused.
    let loaded =
        sdfc_runtime::frontend::load(&root.join("examples/mesh/bracket.sdf")).expect("load");
    let scene = loaded.scene.expect("checks");
    let program = lower(&scene);
    let (lo, hi) = ([-0.9, -0.5, -0.6], [0.9, 0.4, 0.6]);
    let field = Field::new(&program, true, [lo, hi]);
    let g = grid(lo, hi, 200);
    let all =
        octree::candidates(&field, &g, 1 << 40, u64::MAX, &|_| {}).expect("within the cells limit");
    let max = all.evaluated + all.evaluated / 20;
    let (refused, used) = peak_of(|| octree::candidates(&field, &g, max, u64::MAX, &|_| {}));
    // Refused at the last level, or before it by the surface an earlier one proves (a lower
    // bound of what the octree would reach).
    match refused {
        Err(octree::Refused::Cells(n)) => assert!(
            n > max && n <= all.evaluated + all.cells.len() as u64,
            "{n} of {max}"
        ),
        other => panic!("{other:?}"),
    }
    let bound = octree::bytes(&g, true, max);
    assert!(
        used <= bound,
        "refused octree used {used} B, announced {bound}"
    );
    eprintln!(
        "refused at {} cells of {max}: octree peak {used} B of {bound} announced",
        all.evaluated + all.cells.len() as u64
    );
}
