//! Lowering of the scene IR to the distance program ([`crate::program`]).
//!
//! [`lower_with`] runs the optimisation passes of `docs/optimisation.md` at level 1 (the
//! default, [`lower`]): the scene is simplified (composed transforms, flattened unions,
//! primitives in their cheapest exact form), the builder folds constants, shares equal
//! instructions and drops dead ones, and unions are grouped into a bounding volume hierarchy
//! whose subtrees are skipped where they cannot be the nearest. Level 0 lowers the scene
//! literally.

mod blends;
mod bvh;
mod field;
mod graph;
mod instances;
mod media;
#[cfg(test)]
mod shape_tests;
mod shapes;
mod simplify;
mod sweep;
#[cfg(test)]
mod sweep_tests;
#[cfg(test)]
mod tests;

use crate::program::{Binary, Program, Reg, Unary};
pub(crate) use field::hash_of;
pub use field::{ColourProgram, Colours};
pub use instances::{shape_program, Instance, ShapeProgram, Split};
pub use media::{media, Media};
pub use shapes::slots;

use crate::diagnostics::Diagnostic;
use crate::limits::{Limit, Limits};
use crate::scene::analysis::{self, Analysis};
use crate::scene::analytic::{traceable, Choice, Traceable};
use crate::scene::bounds::Bounds;
use crate::scene::{Graph, NodeId, Scene, Settings};
use std::time::{Duration, Instant};

/// The distance a program reports for a scene with no objects: far beyond any `max_dist`.
pub const EMPTY_DISTANCE: f64 = 1e30;

/// How a scene is lowered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LowerOptions {
    /// Optimisation level: 0 lowers the scene literally (no folding, sharing, dead-code
    /// removal, scene simplification or culling); 1 runs every pass.
    pub level: u8,
    /// At level 1: whether unions get bounding-volume culling (guarded blocks). Turning it
    /// off keeps every other pass, and the same order of evaluation, so that the two
    /// programs compute bit-identical results.
    pub cull: bool,
    /// At level 1: local bounds. Each operand of the scene's unions, intersections and
    /// subtractions (and the root) whose L exceeds 1 is divided by its own L and raised to
    /// the distance to its bounding volume (`docs/analysis.md`, "Local bounds"), so that the
    /// program is a bound with L = 1 and only rays near such an operand step shorter. Off,
    /// the program is the field as written and renderers step by the scene's L everywhere.
    pub local: bool,
    /// At level 1: no rewrite that depends on the value of a number, only on the scene's
    /// structure: no identity removed (a translation by 0, `x · 1`), no subtraction of a
    /// negative constant written as an addition, no sharing of equal constants, no choice of
    /// a `Select` by its constant condition, no rotation absorbed by a box at a quarter turn
    /// or by a shape of revolution about its axis. The frames of an animation are lowered so
    /// (docs/animation.md), so that a number passing through 0 or 1 does not change the
    /// program's structure, and so the kernel. The program computes the same values.
    pub parametric: bool,
}

impl Default for LowerOptions {
    fn default() -> Self {
        LowerOptions::level(1)
    }
}

impl LowerOptions {
    /// The options of an optimisation level (culling on at level 1).
    pub fn level(level: u8) -> Self {
        LowerOptions {
            level,
            cull: level > 0,
            local: level > 0,
            parametric: false,
        }
    }

    /// The options the frames of an animation are lowered with: every pass, none that
    /// depends on a number's value ([`LowerOptions::parametric`]).
    pub fn parametric() -> Self {
        LowerOptions {
            parametric: true,
            ..LowerOptions::level(1)
        }
    }
}

/// A scene lowered for rendering, once: its distance program, what decides whether it is ray
/// traced analytically (the `method` setting picks, [`Lowered::choice`]), the programs rays
/// inside glass need, and the simplified scene the program came from, from which a back end
/// that walks the root union's instances as data splits them off ([`Lowered::instances`]).
#[derive(Debug, Clone)]
pub struct Lowered {
    /// The scene's distance program (a traced scene has one too: the placement warnings,
    /// statistics and the viewer read its field).
    pub program: Program,
    /// The scene's primitives, or why it cannot be traced analytically.
    pub traceable: Traceable,
    /// Where glass may overlap an opaque solid, the medium's and the solids' programs.
    pub media: Option<Media>,
    /// The colour fields of the materials.
    pub colours: Colours,
    /// At level 1, the simplified scene the program was lowered from.
    simplified: Option<Simplified>,
    /// The options the program was lowered with.
    options: LowerOptions,
    /// Where the lowering's time went.
    pub phases: Phases,
}

/// Where a lowering's time went, phase by phase (`sdfc render --stats`): each phase's name,
/// its time and what it did, in order.
#[derive(Debug, Clone)]
pub struct Phases {
    /// The phases that ended.
    pub list: Vec<(&'static str, Duration, &'static str)>,
    last: Instant,
}

impl Default for Phases {
    fn default() -> Self {
        Phases {
            list: Vec::new(),
            last: Instant::now(),
        }
    }
}

impl Phases {
    /// Ends a phase now.
    fn lap(&mut self, name: &'static str, what: &'static str) {
        let now = Instant::now();
        self.list.push((name, now - self.last, what));
        self.last = now;
    }
}

impl Lowered {
    /// Lowers a checked scene for rendering with every optimisation pass ([`lower_scene`]).
    pub fn new(scene: &Scene) -> Lowered {
        lower_scene(scene, &LowerOptions::default())
    }

    /// How the scene is rendered with `settings` (its `method`): the primitives to trace, or
    /// why it is marched.
    pub fn choice(&self, settings: &Settings) -> Choice {
        self.traceable.choose(settings.method)
    }

    /// The options the program was lowered with.
    pub fn options(&self) -> LowerOptions {
        self.options
    }

    /// The program without the root union's instances, and those instances, when there are
    /// more than `more_than` of them (and the program is optimised: level 0 keeps the scene as
    /// written). The rest is lowered from the simplified scene the program came from.
    pub fn instances(&self, more_than: usize) -> Option<Split> {
        instances::split(self.simplified.as_ref()?, &self.options, more_than)
    }
}

/// The simplified scene a level-1 lowering walked, with what it derived of it.
#[derive(Debug, Clone)]
struct Simplified {
    /// The simplified graph and its root, with the checked scene's materials, lights, camera
    /// and settings.
    scene: Scene,
    /// For every simplified node, the checked scene's node it comes from.
    origin: Vec<NodeId>,
    /// The analysis of `scene`.
    analysis: Analysis,
    /// The bounds of `scene`'s nodes.
    bounds: Bounds,
}

/// Lowers a checked scene for rendering ([`Lowered`]) with the given options.
pub fn lower_scene(scene: &Scene, options: &LowerOptions) -> Lowered {
    let mut phases = Phases::default();
    let (program, _, simplified) = lower_capped(scene, options, usize::MAX, &mut phases);
    lowered(scene, program, simplified, options, phases)
}

/// The [`Lowered`] of `scene` around its program.
fn lowered(
    scene: &Scene,
    program: Program,
    simplified: Option<Simplified>,
    options: &LowerOptions,
    mut phases: Phases,
) -> Lowered {
    let traceable = traceable(scene);
    phases.lap(
        "primitives",
        "the primitives to trace analytically, or why not",
    );
    let media = media(scene);
    phases.lap("media", "where glass may overlap a solid");
    Lowered {
        program,
        traceable,
        media,
        colours: Colours::new(scene),
        simplified,
        options: *options,
        phases,
    }
}

/// Lowers a checked scene to its distance program, with every optimisation pass.
pub fn lower(scene: &Scene) -> Program {
    lower_with(scene, &LowerOptions::default())
}

/// Lowers a checked scene within its limits: a scene over the `expansion` limit is refused
/// before any pass walks it, and the builder counts the instructions it emits and stops at
/// the `program` limit (an E0507 error at the scene's objects), so no program larger than
/// the limit is ever built. Run before any back end or render starts.
pub fn lower_within(
    scene: &Scene,
    options: &LowerOptions,
    limits: &Limits,
) -> Result<Lowered, Diagnostic> {
    let Some(root) = scene.root else {
        return Ok(lower_scene(scene, options));
    };
    let mut phases = Phases::default();
    let expansion = scene
        .graph
        .over_expanded(root, limits.get(Limit::Expansion));
    if let Some(e) = expansion {
        return Err(scene.graph.expansion_error(&e, limits));
    }
    phases.lap(
        "expansion",
        "shape nodes counted as a tree, within the limit",
    );
    let max = limits.get(Limit::Program);
    let cap = usize::try_from(max).unwrap_or(usize::MAX);
    let (program, over, simplified) = lower_capped(scene, options, cap, &mut phases);
    if !over && program.len() as u64 <= max {
        return Ok(lowered(scene, program, simplified, options, phases));
    }
    Err(Diagnostic::error(
        "E0507",
        format!("the distance program has more than {max} operations"),
        scene.graph.span(root),
    )
    .with_label("the scene's objects lower to it")
    .with_note(format!(
        "lowering stopped at the limit; this limit keeps compilation and rendering bounded; {}",
        limits.raise(Limit::Program)
    )))
}

/// Lowers a checked scene to its distance program with the given options.
pub fn lower_with(scene: &Scene, options: &LowerOptions) -> Program {
    lower_capped(scene, options, usize::MAX, &mut Phases::default()).0
}

/// [`lower_with`], stopping once more than `cap` instructions were emitted; the flag says
/// whether it stopped (the program is then incomplete). At level 1 the simplified scene
/// comes with it.
fn lower_capped(
    scene: &Scene,
    options: &LowerOptions,
    cap: usize,
    phases: &mut Phases,
) -> (Program, bool, Option<Simplified>) {
    match scene.root {
        _ if options.level == 0 => {
            let (program, over) = lower_literal(scene, cap);
            phases.lap("program", "the scene lowered as written");
            (program, over, None)
        }
        Some(root) => {
            let simple = simplify::simplify(&scene.graph, root, options.parametric);
            phases.lap("simplify", "transforms composed, unions flattened");
            lower_simple(
                scene,
                simple.graph,
                Some(simple.root),
                &simple.origin,
                options,
                (cap, phases),
            )
        }
        None => lower_simple(scene, Graph::default(), None, &[], options, (cap, phases)),
    }
}

/// Lowers the simplified graph `graph` below `root` (for the scene's camera and settings),
/// `origin` naming the original node of each simplified one; with a root, the simplified
/// scene comes with the program.
fn lower_simple(
    scene: &Scene,
    graph: Graph,
    root: Option<NodeId>,
    origin: &[NodeId],
    options: &LowerOptions,
    (cap, phases): (usize, &mut Phases),
) -> (Program, bool, Option<Simplified>) {
    let mut b = crate::program::builder::Builder::capped(true, cap);
    b.parametric = options.parametric;
    let p = b.input_point();
    let mut lipschitz = 1.0;
    let mut simplified = None;
    let (d, m) = match root {
        Some(root) => {
            // The analysis of the simplified graph, whose nodes the lowering walks.
            let simple_scene = Scene {
                graph,
                root: Some(root),
                ..scene_without_graph(scene)
            };
            let analysis = analysis::analyse(&simple_scene);
            if !options.local {
                lipschitz = analysis.step_lipschitz();
            }
            phases.lap("analysis", "exactness and Lipschitz bounds of every node");
            let bounds = Bounds::new(&simple_scene.graph);
            phases.lap("bounds", "the bounding volume of every node");
            let config = graph::Config {
                cull: options.cull,
                camera: scene.camera.position,
                origin: Some(origin),
                bounds: Some(&bounds),
                optimise: true,
                analysis: Some(&analysis),
                local: options.local,
            };
            let field = graph::Lowerer::new(&simple_scene.graph, &mut b, config).node(root, p);
            simplified = Some(Simplified {
                scene: simple_scene,
                origin: origin.to_vec(),
                analysis,
                bounds,
            });
            (field.d, field.m)
        }
        None => (b.c(EMPTY_DISTANCE), b.c(graph::UNPAINTED)),
    };
    let (program, over) = finish(b, d, m, lipschitz);
    phases.lap(
        "program",
        "the distance program built (hierarchies of bounds, culling blocks)",
    );
    (program, over, simplified)
}

/// Lowers the scene as written (level 0).
fn lower_literal(scene: &Scene, cap: usize) -> (Program, bool) {
    let mut b = crate::program::builder::Builder::capped(false, cap);
    let p = b.input_point();
    let mut lipschitz = 1.0;
    let (d, m) = match scene.root {
        Some(root) => {
            let analysis = analysis::analyse(scene);
            lipschitz = analysis.step_lipschitz();
            let config = graph::Config {
                cull: false,
                camera: scene.camera.position,
                origin: None,
                bounds: None,
                optimise: false,
                analysis: Some(&analysis),
                local: false,
            };
            let field = graph::Lowerer::new(&scene.graph, &mut b, config).node(root, p);
            (field.d, field.m)
        }
        None => (b.c(EMPTY_DISTANCE), b.c(graph::UNPAINTED)),
    };
    finish(b, d, m, lipschitz)
}

/// Paints what is unpainted with material 0 and ends the program.
fn finish(
    mut b: crate::program::builder::Builder,
    d: Reg,
    m: Reg,
    lipschitz: f64,
) -> (Program, bool) {
    b.note("result: unpainted shapes get the default material 0".into());
    let m = b.paint(m, 0.0);
    let over = b.over();
    let program = Program {
        lipschitz,
        ..b.finish(d, m)
    };
    (program, over)
}

/// Everything of a scene but its shapes (for analysing a rewritten graph).
fn scene_without_graph(scene: &Scene) -> Scene {
    Scene {
        graph: Graph::default(),
        root: None,
        materials: scene.materials.clone(),
        lights: scene.lights.clone(),
        camera: scene.camera.clone(),
        settings: scene.settings.clone(),
        origin: scene.origin,
        limits: scene.limits.clone(),
        animation: scene.animation,
        params: scene.params.clone(),
    }
}
