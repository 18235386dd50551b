//! The memory `sdfc mesh` announces is an upper bound: a counting global allocator records
//! the peak of live heap bytes while the octree (`octree::bytes`) and then contouring
//! (`contour::candidate_bytes` and `BYTES_PER_SURFACE_CELL` per surface cell) run through the
//! library, for the benchmark scene, the bracket and a field without a proven bound.
//!
//! One test only: the counter sees every thread of the process, so nothing else may run.
#![allow(unsafe_code)] // A global allocator is an unsafe trait; it only forwards to `System`.

use sdfc_compiler::lower;
use sdfc_runtime::mesh::contour::{self, BYTES_PER_SURFACE_CELL};
use sdfc_runtime::mesh::{octree, Field, Grid, Settings};
use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

/// Counts live heap bytes and their peak.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grew(bytes: usize) {
    let now = LIVE.fetch_add(bytes, Ordering::SeqCst) + bytes;
    PEAK.fetch_max(now, Ordering::SeqCst);
}

// SAFETY: every call is forwarded to `System` with the same arguments; the counters are
// atomics and never allocate.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::SeqCst);
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            // Counted as the new block allocated before the old one is freed.
            grew(new_size);
            LIVE.fetch_sub(layout.size(), Ordering::SeqCst);
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Runs `f` and returns its result and the peak growth of live heap bytes while it ran.
fn peak_of<R>(f: impl FnOnce() -> R) -> (R, u64) {
    let base = LIVE.load(Ordering::SeqCst);
    PEAK.store(base, Ordering::SeqCst);
    let r = f();
    let peak = PEAK.load(Ordering::SeqCst);
    (r, peak.saturating_sub(base) as u64)
}

/// A grid as `sdfc mesh` lays it out over `[lo, hi]` with `n` cells along the longest side.
fn grid(lo: [f64; 3], hi: [f64; 3], n: u32) -> Grid {
    let offset = 0.381_966_011_250_105;
    let longest = (0..3).map(|i| hi[i] - lo[i]).fold(0.0, f64::max);
    let voxel = longest / n as f64;
    Grid {
        origin: lo.map(|x| x - (1.0 + offset) * voxel),
        voxel,
        cells: [0, 1, 2].map(|i| ((hi[i] - lo[i]) / voxel + 1.0 + offset).ceil() as u32 + 1),
    }
}

#[test]
fn meshing_stays_within_the_memory_it_announces() {
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
        let analysis = sdfc_compiler::scene::analysis::analyse(&scene);
        let proven = analysis.root().expect("objects").proven;
        let program = lower::lower(&scene);
        let field = Field::new(&program, proven, [lo, hi]);
        let g = grid(lo, hi, n);
        let max = 1 << 40;
        let (found, used) = peak_of(|| octree::candidates(&field, &g, max, &|_| {}));
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
}
