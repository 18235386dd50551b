//! Helpers shared by the integration tests: scenes built in code, random points, a few
//! reference formulas, and the diagnostic codes the compiler's sources can emit.
#![allow(dead_code)]

use sdfc_compiler::scene::{
    Camera, Graph, Light, Material, MaterialId, Node, NodeId, Pattern, Scene, Settings,
};
use sdfc_compiler::{FileId, Span};

/// A span for nodes made in code.
pub fn span() -> Span {
    Span::new(FileId(0), 0..0)
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
        m.pattern = Pattern::Solid(color);
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
        });
    }
}

/// A scene of one node at the origin.
pub fn single(node: Node) -> Scene {
    let mut b = Build::new();
    let id = b.add(node);
    b.finish(id)
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
