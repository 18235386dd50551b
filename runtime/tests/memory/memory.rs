//! The memory a render announces is an upper bound: a counting global allocator records the
//! peak of live heap bytes while CPU renders run through the library, which must stay
//! within `cpu::memory` (the render) and `memory::render` (the render, the frame held and
//! its outputs written, as `sdfc render` does), for several sizes, supersampling and
//! precisions, on a scene whose glass spawns two rays per hit.
//!
//! The counter sees every thread of the process, so the test measures alone
//! ([`counting::alone`]).

use sdfc_compiler::{check_str, Lowered, Scene};
use sdfc_runtime::backend::{Backend, Prepared, Setup};
use sdfc_runtime::cpu::{self, Options, Precision, Tapes};
use sdfc_runtime::memory;

use crate::counting;
use counting::peak_of;

const SCENE: &str = "
material glass = phong { color: (1, 1, 1), reflect: 0.1, transparency: 0.85, ior: 1.5 };
material mirror = phong { color: (0.9, 0.9, 0.9), reflect: 0.6 };
material floor = checker { a: (0.9, 0.9, 0.9), b: (0.1, 0.1, 0.1), size: 1 };
camera { position: (0, 2, -6), look_at: (0, 0.5, 0), fov: 60deg }
light point { position: (4, 6, -4), intensity: 1, radius: 30, penumbra: 3.5763deg }
light directional { direction: (-1, -1, 0.5), color: (0.4, 0.4, 0.4) }
render { width: 64, height: 48, max_depth: 8 }
scene {
  plane((0, 1, 0), 0) @ floor;
  sphere(1).translate(0, 1, 0) @ glass;
  sphere(0.6).translate(1.6, 0.6, 0.5) @ mirror;
  for i in 0..5 { box((0.2, 0.5, 0.2)).translate(i - 2, 0.5, 2) @ glass; }
}
";

/// The same kind of scene within what analytic tracing takes: hard lights, glass that touches
/// nothing.
const TRACED: &str = "
material glass = phong { color: (1, 1, 1), reflect: 0.1, transparency: 0.85, ior: 1.5 };
material mirror = phong { color: (0.9, 0.9, 0.9), reflect: 0.6 };
material floor = checker { a: (0.9, 0.9, 0.9), b: (0.1, 0.1, 0.1), size: 1 };
camera { position: (0, 2, -6), look_at: (0, 0.5, 0), fov: 60deg }
light point { position: (4, 6, -4), intensity: 1, radius: 30 }
light directional { direction: (-1, -1, 0.5), color: (0.4, 0.4, 0.4) }
render { width: 64, height: 48, max_depth: 8 }
scene {
  plane((0, 1, 0), 0) @ floor;
  sphere(1).translate(0, 1.2, 0) @ glass;
  sphere(0.6).translate(1.8, 0.6, 0.5) @ mirror;
  for i in 0..5 { box((0.2, 0.5, 0.2)).translate(i - 2, 0.5, 2) @ mirror; }
}
";

fn scene(width: u32, height: u32, aa: u32) -> Scene {
    scene_of(SCENE, width, height, aa)
}

fn scene_of(text: &str, width: u32, height: u32, aa: u32) -> Scene {
    let (scene, diags, _) = check_str("memory.sdf", text);
    let mut scene = scene.unwrap_or_else(|| panic!("{diags:?}"));
    scene.settings.width = width;
    scene.settings.height = height;
    scene.settings.aa = aa;
    scene
}

#[test]
fn renders_stay_within_the_memory_they_announce() {
    let _alone = counting::alone();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .expect("thread pool");
    // Warm the pool and its thread-local state before measuring.
    let warm = scene(16, 16, 1);
    pool.install(|| cpu::render(&warm, &Lowered::new(&warm), &Options::default(), &|| {}));
    for (text, width, height, aa, precision) in [
        (SCENE, 64, 48, 1, Precision::F32),
        (SCENE, 120, 90, 3, Precision::F32),
        (SCENE, 80, 60, 2, Precision::F64),
        (SCENE, 300, 200, 1, Precision::F32),
        (TRACED, 120, 90, 3, Precision::F32),
        (TRACED, 300, 200, 1, Precision::F64),
    ] {
        let scene = scene_of(text, width, height, aa);
        let traced = sdfc_compiler::analytic::choose(&scene)
            .primitives()
            .is_some();
        assert_eq!(traced, text == TRACED);
        let lowered = Lowered::new(&scene);
        let tapes = Tapes::new(&lowered);
        let options = Options {
            precision,
            ..Options::default()
        };
        let bound = pool.install(|| cpu::memory(&scene, &tapes, &options, 3));
        let (render, peak) =
            peak_of(|| pool.install(|| cpu::render_tapes(&scene, &tapes, &options, &|| {})));
        let case = format!("{width}x{height}, aa {aa}, {precision:?}, traced {traced}");
        println!(
            "{case}: render peak {peak} bytes, bound {bound} ({:.1}x)",
            bound as f64 / peak as f64
        );
        assert!(render.stats.counters.secondary_rays > 0, "{case}: no glass");
        let image = 12 * (width * height) as u64;
        assert!(peak >= image, "{case}: the counter missed the image");
        assert!(peak <= bound, "{case}: peak {peak} > bound {bound}");
        // A sanity check that the bound says something: within an order of magnitude.
        assert!(
            bound <= 12 * peak,
            "{case}: bound {bound} is far above {peak}"
        );

        // The whole of `sdfc render`: prepare, render, hold the frame, write PNG and sidecar.
        let setup = Setup {
            precision,
            debug_nan: false,
            parameters: false,
            kernel: Default::default(),
            image_only: false,
            finished: false,
            software: false,
        };
        let prepared = pool.install(|| {
            Prepared::from_program(Backend::Cpu, &scene, lowered.clone(), &setup).expect("cpu")
        });
        let announced = pool.install(|| memory::render(&prepared, &scene, false, true));
        assert_eq!(announced.device, 0);
        let (bytes, peak) = peak_of(|| {
            let frame = pool
                .install(|| prepared.render(&scene, &|_| {}))
                .expect("render");
            let png = frame.render.image.encode_png().expect("png");
            let aux = frame.render.depth.as_ref().expect("depth").encode();
            png.len() + aux.len()
        });
        println!(
            "{case}: render and outputs peak {peak} bytes, announced {}",
            announced.host
        );
        assert!(bytes > 0);
        assert!(
            peak <= announced.host,
            "{case}: peak {peak} > announced {}",
            announced.host
        );
    }
}
