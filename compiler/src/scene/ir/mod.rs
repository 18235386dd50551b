//! The scene IR: a hash-consed DAG of shape nodes plus materials, lights, camera and settings.
//!
//! Everything in it is constant: the checker has evaluated every expression. Nodes live in an
//! arena ([`Graph`]) and are named by [`NodeId`]; structurally equal nodes are stored once, so
//! a sub-shape used twice is one node. Computed facts (bounds, Lipschitz bound, exactness) are
//! kept in side tables keyed by `NodeId` ([`Facts`]), next to the spans.

use super::NodeId;
use crate::diagnostics::Diagnostic;
use crate::limits::{Limit, Limits};

mod graph;
mod material;
mod node;
mod settings;
mod view;

pub use graph::{Exactness, Expansion, Facts, Graph};
pub use material::{Colour, Material, Pattern};
pub use node::{Combine, Feature, MeshRef, Node, PathRef, Smooth};
pub use settings::{Method, Settings};
pub use view::{penumbra_of_sharpness, Camera, Light};

/// A 3-vector of f64.
pub type V3 = [f64; 3];

/// The product of the matrix `m` (rows) and `v`.
pub fn mat_vec(m: &[V3; 3], v: V3) -> V3 {
    [0, 1, 2].map(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
}

/// Names a material of a [`Scene`]; 0 is the default material.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MaterialId(pub u32);

/// A checked scene: everything a back end needs, nothing from the AST.
#[derive(Debug, Clone, Default)]
pub struct Scene {
    /// The shape arena.
    pub graph: Graph,
    /// The union of all scene objects; `None` for a scene with no objects.
    pub root: Option<NodeId>,
    /// Materials; index 0 is the default material.
    pub materials: Vec<Material>,
    /// Lights in declaration order.
    pub lights: Vec<Light>,
    /// The camera.
    pub camera: Camera,
    /// Render settings.
    pub settings: Settings,
    /// Where the scene's origin lies in the coordinates it was written in: zero, unless the
    /// scene was moved to put a far camera at the origin ([`super::recentre`]). Patterns are
    /// laid out in the written coordinates, at p + origin.
    pub origin: V3,
    /// The limits the scene was checked within: the passes after the checker (the choice of
    /// method, the kernel's data) read theirs from here.
    pub limits: Limits,
    /// The animation the `render` block states, the time the scene was checked at, and
    /// whether anything in it read the time `t`.
    pub animation: Animation,
    /// The parameters (`param`), in the order of the source, with the values checked.
    pub params: Vec<super::params::Parameter>,
}

/// A scene's animation (docs/animation.md): frame `k` is the scene checked at the time
/// `k / fps` seconds. A scene that never reads `t` is a still: every frame is the same.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Animation {
    /// Frames per second (`render { fps }`).
    pub fps: f64,
    /// Length of the sequence in seconds (`render { duration }`); 0 for none.
    pub duration: f64,
    /// The time `t` the scene was checked at, in seconds.
    pub time: f64,
    /// Where the checker first read `t` (outside function bodies checked on their own);
    /// `None` when nothing did: the scene is a still.
    pub reads_time: Option<crate::span::Span>,
}

impl Default for Animation {
    fn default() -> Self {
        Animation {
            fps: 30.0,
            duration: 0.0,
            time: 0.0,
            reads_time: None,
        }
    }
}

impl Animation {
    /// The number of frames the `render` block states: `fps × duration`, rounded.
    pub fn frames(&self) -> u64 {
        (self.fps * self.duration).round() as u64
    }

    /// The time of frame `k`, in seconds.
    pub fn time_of(fps: f64, k: u64) -> f64 {
        k as f64 / fps
    }

    /// Whether the scene reads `t` (otherwise every frame is the same).
    pub fn animated(&self) -> bool {
        self.reads_time.is_some()
    }
}

impl Scene {
    /// The ε rays are marched with ([`Settings::hit_epsilon`] for this scene's camera).
    pub fn epsilon(&self) -> f64 {
        self.settings.hit_epsilon(self.camera.fov)
    }

    /// Where a checker of cells of edge `size` starts at the scene's origin, in cells: the
    /// written pattern at p + origin is the pattern at p / size + shift. The origin is
    /// reduced modulo two cells (which keeps the parity) so that the shift stays small and
    /// exact in f32.
    pub fn checker_shift(&self, size: f64) -> V3 {
        self.origin.map(|o| o.rem_euclid(2.0 * size) / size)
    }

    /// The material behind an id.
    pub fn material(&self, id: MaterialId) -> &Material {
        &self.materials[id.0 as usize]
    }

    /// The scene's objects as a tree, when they have more nodes than its `expansion` limit.
    pub fn over_expanded(&self) -> Option<Expansion> {
        let root = self.root?;
        self.graph
            .over_expanded(root, self.limits.get(Limit::Expansion))
    }

    /// The E0507 error of a scene over its `expansion` limit.
    pub fn expansion_error(&self, e: &Expansion) -> Diagnostic {
        self.graph.expansion_error(e, &self.limits)
    }
}
