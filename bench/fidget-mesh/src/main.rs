//! fidget 0.5.1's Manifold Dual Contouring on sdfc's meshing benchmark scene (examples/mesh/parts.sdf),
//! over [-1, 1]³ at a given depth, with the VM or the JIT; prints the median time of N runs, the
//! triangles, the zero-area triangles, the vertices and the distinct vertex positions.
use fidget_core::context::Tree;
use fidget::mesh::{Octree, Settings};
use std::time::Instant;

fn length3(x: Tree, y: Tree, z: Tree) -> Tree {
    (x.square() + y.square() + z.square()).sqrt()
}

fn boxed(c: [f32; 3], h: [f32; 3]) -> Tree {
    let q = [
        (Tree::x() - c[0]).abs() - h[0],
        (Tree::y() - c[1]).abs() - h[1],
        (Tree::z() - c[2]).abs() - h[2],
    ];
    let out = length3(q[0].clone().max(0.0), q[1].clone().max(0.0), q[2].clone().max(0.0));
    let inside = q[0].clone().max(q[1].clone()).max(q[2].clone()).min(0.0);
    out + inside
}

fn scene() -> Tree {
    let sphere = length3(Tree::x() + 0.5, Tree::y(), Tree::z()) - 0.5;
    let cube = boxed([0.5, 0.0, 0.0], [0.35, 0.35, 0.35]);
    let ring = (Tree::x().square() + Tree::z().square()).sqrt() - 0.35;
    let torus = (ring.square() + (Tree::y() - 0.5).square()).sqrt() - 0.12;
    let plate = boxed([0.0, -0.575, 0.0], [0.9, 0.025, 0.9]);
    sphere.min(cube).min(torus).min(plate)
}

fn run<F>(shape: fidget_core::shape::Shape<F>, depth: u8, runs: usize, stl: Option<&str>)
where
    F: fidget_core::eval::Function + fidget_core::render::RenderHints + Clone,
{
    let bound: fidget_core::shape::BoundShape<F, f32> =
        shape.try_into().expect("no variables");
    let settings = Settings { depth, ..Default::default() };
    let mut times = Vec::new();
    let mut mesh = None;
    for _ in 0..runs {
        let t = Instant::now();
        let o = Octree::build(&bound, &settings).expect("built");
        let m = o.walk_dual();
        times.push(t.elapsed().as_secs_f64());
        mesh = Some(m);
    }
    times.sort_by(f64::total_cmp);
    let m = mesh.expect("a run");
    let zero = m
        .triangles
        .iter()
        .filter(|t| {
            let [a, b, c] = [t.x, t.y, t.z].map(|i| m.vertices[i].cast::<f64>());
            (b - a).cross(&(c - a)).norm() == 0.0
        })
        .count();
    let mut pos: Vec<[u32; 3]> = m
        .vertices
        .iter()
        .map(|v| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()])
        .collect();
    pos.sort_unstable();
    pos.dedup();
    println!(
        "depth {depth}: median {:.3} s of {runs} (min {:.3}), {} triangles, {zero} of zero area, {} vertices at {} distinct positions",
        times[runs / 2],
        times[0],
        m.triangles.len(),
        m.vertices.len(),
        pos.len()
    );
    if let Some(path) = stl {
        let mut f = std::fs::File::create(path).expect("create");
        m.write_stl(&mut f).expect("write");
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let which = args.get(1).map(String::as_str).unwrap_or("jit");
    let depth: u8 = args.get(2).and_then(|d| d.parse().ok()).unwrap_or(8);
    let runs: usize = args.get(3).and_then(|d| d.parse().ok()).unwrap_or(5);
    let stl = args.get(4).map(String::as_str);
    print!("{which} ");
    match which {
        "vm" => run(fidget_core::vm::VmShape::from(scene()), depth, runs, stl),
        _ => run(fidget::jit::JitShape::from(scene()), depth, runs, stl),
    }
}
