//! Helpers shared by the integration tests of both crates: scenes built in code, random
//! scenes, a few reference formulas, the diagnostic codes the compiler's sources can emit and
//! the examples (the runtime's `tests/common` includes this file).
#![allow(dead_code)]

use sdfc_compiler::{
    Camera, Combine, FileId, Graph, Light, Material, MaterialId, Node, NodeId, Pattern, Rng, Scene,
    Settings, Smooth, Span,
};

/// A span for nodes made in code.
pub fn span() -> Span {
    Span::new(FileId(0), 0..0)
}

/// Fails, showing `text`, unless it contains every one of `needles`.
#[track_caller]
pub fn assert_has(text: &str, needles: &[&str]) {
    for needle in needles {
        assert!(text.contains(needle), "no `{needle}` in:\n{text}");
    }
}

/// A scene under construction.
#[derive(Debug, Default)]
pub struct Build {
    pub scene: Scene,
}

impl Build {
    /// An empty scene with the default material, camera and settings.
    pub fn new() -> Self {
        let scene = Scene {
            graph: Graph::default(),
            root: None,
            materials: vec![Material::default_material()],
            lights: Vec::new(),
            camera: Camera::default(),
            settings: Settings::default(),
            origin: [0.0; 3],
            ..Scene::default()
        };
        Build { scene }
    }

    /// Adds a node.
    pub fn add(&mut self, node: Node) -> NodeId {
        self.scene.graph.add(node, span())
    }

    /// Adds a solid-colour material and returns its id.
    pub fn material(&mut self, color: [f64; 3], reflect: f64, transparency: f64) -> MaterialId {
        let mut m = Material::default_material();
        m.name = format!("m{}", self.scene.materials.len());
        m.pattern = Pattern::Solid(color.into());
        m.reflect = reflect;
        m.transparency = transparency;
        self.scene.materials.push(m);
        MaterialId(self.scene.materials.len() as u32 - 1)
    }

    /// Paints a node.
    pub fn paint(&mut self, child: NodeId, m: MaterialId) -> NodeId {
        self.add(Node::Paint { material: m, child })
    }

    /// Translates a node.
    pub fn at(&mut self, child: NodeId, offset: [f64; 3]) -> NodeId {
        self.add(Node::Translate { offset, child })
    }

    /// Sets the root and returns the scene.
    pub fn finish(mut self, root: NodeId) -> Scene {
        self.scene.root = Some(root);
        self.scene
    }

    /// Adds a point light with a penumbra of `penumbra` radians (0: hard shadows).
    pub fn point_light(&mut self, position: [f64; 3], penumbra: f64) {
        self.scene.lights.push(Light::Point {
            position,
            color: [1.0; 3],
            intensity: 1.0,
            radius: 100.0,
            penumbra,
            shadows: true,
        });
    }
}

/// A scene of one node at the origin.
pub fn single(node: Node) -> Scene {
    let mut b = Build::new();
    let id = b.add(node);
    b.finish(id)
}

/// A random scene of `n` primitives under random transforms and combinations (random
/// structure for the fused steps' matcher and the interpreted GPU kernel to meet, and for the
/// evaluators of `distance_conformance.rs` to agree on).
pub fn random_scene(rng: &mut Rng, n: usize) -> Scene {
    let mut b = Build::new();
    let mut r = |lo: f64, hi: f64| rng.range(lo, hi);
    let mut kids = Vec::new();
    for _ in 0..n {
        let node = match (r(0.0, 9.0)) as u32 {
            0 => Node::Sphere {
                radius: r(0.1, 1.0),
            },
            1 => Node::Box {
                half: [r(0.1, 1.0), r(0.1, 1.0), r(0.1, 1.0)],
            },
            2 => Node::RoundBox {
                half: [r(0.2, 1.0), r(0.2, 1.0), r(0.2, 1.0)],
                radius: r(0.0, 0.2),
            },
            3 => Node::Torus {
                major: r(0.3, 1.0),
                minor: r(0.05, 0.3),
            },
            4 => Node::Cylinder {
                radius: r(0.1, 0.8),
                half_height: r(0.1, 1.0),
            },
            5 => Node::Capsule {
                radius: r(0.1, 0.5),
                half_height: r(0.1, 1.0),
            },
            6 => Node::Cone {
                radius: r(0.1, 0.8),
                half_height: r(0.1, 1.0),
            },
            7 => Node::Ellipsoid {
                radii: [r(0.2, 1.0), r(0.2, 1.0), r(0.2, 1.0)],
            },
            _ => Node::Plane {
                normal: {
                    let (t, p) = (r(0.0, 3.1), r(0.0, 6.2));
                    [t.sin() * p.cos(), t.cos(), t.sin() * p.sin()]
                },
                height: r(-2.0, 0.0),
            },
        };
        let mut id = b.add(node);
        for _ in 0..(r(0.0, 3.0) as u32) {
            let node = match r(0.0, 6.0) as u32 {
                0 => {
                    // A rotation about y, then about x.
                    let (a, e) = (r(0.0, 6.2), r(0.0, 6.2));
                    let (ca, sa, ce, se) = (a.cos(), a.sin(), e.cos(), e.sin());
                    Node::Rotate {
                        matrix: [
                            [ca, 0.0, sa],
                            [se * sa, ce, -se * ca],
                            [-ce * sa, se, ce * ca],
                        ],
                        child: id,
                    }
                }
                1 => Node::Scale {
                    factor: r(0.5, 2.0),
                    child: id,
                },
                2 => Node::Round {
                    radius: r(0.0, 0.1),
                    child: id,
                },
                3 => Node::Mirror {
                    axes: [true, false, r(0.0, 1.0) < 0.5],
                    child: id,
                },
                4 => Node::Repeat {
                    period: [r(2.0, 4.0), 0.0, r(2.0, 4.0)],
                    count: None,
                    child: id,
                },
                _ => Node::Shell {
                    half: r(0.02, 0.1),
                    child: id,
                },
            };
            id = b.add(node);
        }
        kids.push(b.at(id, [r(-3.0, 3.0), r(-1.0, 2.0), r(-3.0, 3.0)]));
    }
    while kids.len() > 1 {
        let (x, y) = (kids.pop().expect("two"), kids.pop().expect("two"));
        let op = [Combine::Union, Combine::Intersect, Combine::Subtract][r(0.0, 3.0) as usize % 3];
        let node = if r(0.0, 1.0) < 0.3 {
            Node::SmoothCombine {
                op,
                k: r(0.05, 0.5),
                variant: if r(0.0, 1.0) < 0.5 {
                    Smooth::Poly
                } else {
                    Smooth::Exp
                },
                a: x,
                b: y,
            }
        } else {
            Node::Combine {
                op,
                children: vec![x, y],
            }
        };
        kids.push(b.add(node));
    }
    let root = kids.pop().expect("at least one primitive");
    b.finish(root)
}

pub fn len3(p: [f64; 3]) -> f64 {
    (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt()
}

pub fn len2(a: f64, b: f64) -> f64 {
    (a * a + b * b).sqrt()
}

pub fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// The diagnostic codes (`"E0123"`, `"W0001"`) written as string literals in the Rust sources
/// under `dir`.
pub fn codes_in(dir: &std::path::Path, out: &mut std::collections::BTreeSet<String>) {
    for entry in std::fs::read_dir(dir).expect("readable").flatten() {
        let path = entry.path();
        if path.is_dir() {
            codes_in(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let text = std::fs::read_to_string(&path).expect("readable");
            for (i, _) in text.match_indices('"') {
                let code = text.get(i + 1..i + 6).unwrap_or("");
                let closed = text.get(i + 6..i + 7) == Some("\"");
                if closed
                    && (code.starts_with('E') || code.starts_with('W'))
                    && code[1..].chars().all(|c| c.is_ascii_digit())
                {
                    out.insert(code.to_string());
                }
            }
        }
    }
}

/// The example scenes (`examples/*.sdf`), sorted.
pub fn examples() -> Vec<std::path::PathBuf> {
    let mut files: Vec<std::path::PathBuf> = std::fs::read_dir("../examples")
        .expect("examples/")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "sdf"))
        .collect();
    files.sort();
    files
}

/// A scene file read and checked as `sdfc check` reads it: its imports and meshes from disk
/// relative to it, within the default limits, at t = 0.
#[derive(Debug)]
pub struct Loaded {
    /// The checked scene, when there were no errors.
    pub scene: Option<Scene>,
    /// Everything the compiler said.
    pub diagnostics: Vec<sdfc_compiler::Diagnostic>,
    /// The files read, for rendering diagnostics.
    pub sources: sdfc_compiler::SourceMap,
}

/// [`Loaded`] for the file at `path`; `Err` where the file cannot be read or is not UTF-8.
pub fn load(path: &std::path::Path) -> std::io::Result<Loaded> {
    use sdfc_compiler::files::{normalise, without_bom, FsLoader};
    let text = without_bom(std::fs::read_to_string(path)?);
    let mut sources = sdfc_compiler::SourceMap::new();
    let entry = sources.add(normalise(path), text);
    let limits = sdfc_compiler::Limits::default();
    let (scene, diagnostics) =
        sdfc_compiler::check_at(&mut sources, entry, &mut FsLoader::default(), &limits, 0.0);
    Ok(Loaded {
        scene,
        diagnostics,
        sources,
    })
}

/// The `.sdf` files directly inside `dir`, sorted.
pub fn sdf_files_in(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut files: Vec<std::path::PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "sdf"))
        .collect();
    files.sort();
    files
}

/// `program` run by the batch interpreter over `pts` in chunks of `chunk`: the distances (or
/// what `outputs` asks for) and the materials.
pub fn run_batch<T: sdfc_compiler::Float>(
    program: &sdfc_compiler::Program,
    outputs: sdfc_compiler::Outputs,
    chunk: usize,
    pts: &[[f64; 3]],
) -> (Vec<T>, Vec<u32>) {
    let tape = sdfc_compiler::Tape::new(program, outputs);
    let mut ev = sdfc_compiler::Evaluator::<T>::new(&tape, chunk);
    let c = |i: usize| pts.iter().map(|p| T::from_f64(p[i])).collect::<Vec<T>>();
    let mut d = vec![T::zero(); pts.len()];
    let mut m = vec![0u32; pts.len()];
    ev.eval(&c(0), &c(1), &c(2), &mut d, Some(&mut m));
    (d, m)
}
