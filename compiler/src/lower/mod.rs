//! Lowering of the scene IR to the distance program ([`crate::program`]).
//!
//! [`lower_with`] runs the optimisation passes of `docs/optimisation.md` at level 1 (the
//! default, [`lower`]): the scene is simplified (composed transforms, flattened unions,
//! primitives in their cheapest exact form), the builder folds constants, shares equal
//! instructions and drops dead ones, and unions are grouped into a bounding volume hierarchy
//! whose subtrees are skipped where they cannot be the nearest. Level 0 lowers the scene
//! literally.

mod bounds;
mod builder;
mod bvh;
mod graph;
mod instances;
mod media;
mod shapes;
mod simplify;
#[cfg(test)]
mod tests;

/// The program's types, at the path they had when they were defined here.
pub use crate::program::{
    axis_name, binary_name, op_text, unary_name, Axis, Binary, Block, Item, LowerOptions, Note, Op,
    Program, Reg, Unary,
};
pub use instances::{split, Instance, Split};
pub use media::{media, Media};

use crate::diagnostics::Diagnostic;
use crate::limits::{Limit, Limits};
use crate::scene::{analysis, Graph, NodeId, Scene};

/// The distance a program reports for a scene with no objects: far beyond any `max_dist`.
pub const EMPTY_DISTANCE: f64 = 1e30;

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
) -> Result<Program, Diagnostic> {
    let Some(root) = scene.root else {
        return Ok(lower_with(scene, options));
    };
    let expansion = scene
        .graph
        .over_expanded(root, limits.get(Limit::Expansion));
    if let Some(e) = expansion {
        return Err(scene.graph.expansion_error(&e, limits));
    }
    let max = limits.get(Limit::Program);
    let cap = usize::try_from(max).unwrap_or(usize::MAX);
    let (program, over) = lower_capped(scene, options, cap);
    if !over && program.len() as u64 <= max {
        return Ok(program);
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
    lower_capped(scene, options, usize::MAX).0
}

/// [`lower_with`], stopping once more than `cap` instructions were emitted; the flag says
/// whether it stopped (the program is then incomplete).
fn lower_capped(scene: &Scene, options: &LowerOptions, cap: usize) -> (Program, bool) {
    match scene.root {
        _ if options.level == 0 => lower_literal(scene, options, cap),
        Some(root) => {
            let simple = simplify::simplify(&scene.graph, root);
            lower_simple(
                scene,
                simple.graph,
                Some(simple.root),
                &simple.origin,
                options,
                cap,
            )
        }
        None => lower_simple(scene, Graph::default(), None, &[], options, cap),
    }
}

/// Lowers the simplified graph `graph` below `root` (for the scene's camera and settings),
/// `origin` naming the original node of each simplified one.
fn lower_simple(
    scene: &Scene,
    graph: Graph,
    root: Option<NodeId>,
    origin: &[NodeId],
    options: &LowerOptions,
    cap: usize,
) -> (Program, bool) {
    let mut b = builder::Builder::capped(true, cap);
    let p = b.input_point();
    let mut lipschitz = 1.0;
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
            let bounds = bounds::Bounds::new(&simple_scene.graph);
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
            (field.d, field.m)
        }
        None => (b.c(EMPTY_DISTANCE), b.c(graph::UNPAINTED)),
    };
    finish(b, d, m, lipschitz, options)
}

/// Lowers the scene as written (level 0).
fn lower_literal(scene: &Scene, options: &LowerOptions, cap: usize) -> (Program, bool) {
    let mut b = builder::Builder::capped(false, cap);
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
    finish(b, d, m, lipschitz, options)
}

/// Paints what is unpainted with material 0 and ends the program.
fn finish(
    mut b: builder::Builder,
    d: Reg,
    m: Reg,
    lipschitz: f64,
    options: &LowerOptions,
) -> (Program, bool) {
    b.note("result: unpainted shapes get the default material 0".into());
    let m = b.paint(m, 0.0);
    let over = b.over();
    let program = Program {
        lipschitz,
        options: *options,
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
    }
}
