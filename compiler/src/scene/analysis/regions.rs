//! The top-down pass of the analysis: what each node's field is read for, the band of level
//! sets an ancestor reads (its margin) and the region rays reach, carried from the root down
//! through each node's map of space.

use super::geometry::{invert, taper_floor, IDENTITY};
use super::{blend_reach, Aabb};
use crate::scene::bounds::{singular_range, Bounds};
use crate::scene::ir::{Light, Node, Scene, V3};
use crate::scene::NodeId;

/// The top-down facts: what each node's field is read for.
#[derive(Debug)]
pub(super) struct Usage {
    /// Highest level set of the node's field that an ancestor reads (offsets, shells, blends).
    pub(super) margin: Vec<f64>,
    /// Where (in the node's coordinates) rays can evaluate the field.
    pub(super) region: Vec<Aabb>,
    /// Whether the root reaches the node.
    pub(super) reachable: Vec<bool>,
}

impl Usage {
    pub(super) fn of(scene: &Scene) -> Usage {
        let n = scene.graph.len();
        let mut u = Usage {
            margin: vec![0.0; n],
            region: vec![Aabb::EMPTY; n],
            reachable: vec![false; n],
        };
        let Some(root) = scene.root else { return u };
        u.reachable[root.0 as usize] = true;
        u.region[root.0 as usize] = view_region(scene);
        for i in (0..n).rev() {
            if !u.reachable[i] {
                continue;
            }
            let node = scene.graph.node(NodeId(i as u32));
            for (child, margin, region) in down(node, u.margin[i], u.region[i]) {
                let c = child.0 as usize;
                u.reachable[c] = true;
                u.margin[c] = u.margin[c].max(margin);
                u.region[c] = u.region[c].union(region);
            }
        }
        u
    }
}

/// The region of each node, in its own coordinates, that the box `start` (in the root's
/// coordinates) reaches through the maps above the node (the union over the paths that reach
/// it; empty where none does), as the analysis carries the region rays reach. With `clip`,
/// each node's region is also cut to its own box (`scene/bounds.rs`) along the axes where
/// that is finite: the part of `start` around the node's shape.
pub(crate) fn regions(scene: &Scene, start: Aabb, clip: Option<&Bounds>) -> Vec<Aabb> {
    let n = scene.graph.len();
    let mut region = vec![Aabb::EMPTY; n];
    let Some(root) = scene.root else {
        return region;
    };
    let cut = |id: NodeId, r: Aabb| match clip.and_then(|b| b.get(id)) {
        Some(b) => r.intersect(Aabb {
            min: [0, 1, 2].map(|i| b.aabb.c[i] - b.aabb.h[i]),
            max: [0, 1, 2].map(|i| b.aabb.c[i] + b.aabb.h[i]),
        }),
        None => r,
    };
    region[root.0 as usize] = cut(root, start);
    for i in (0..n).rev() {
        if region[i].is_empty() {
            continue;
        }
        let node = scene.graph.node(NodeId(i as u32));
        for (child, _, r) in down(node, 0.0, region[i])
            .into_iter()
            .chain(profiles(node, region[i]))
        {
            let c = child.0 as usize;
            region[c] = region[c].union(cut(child, r));
        }
    }
    region
}

/// The region the profiles of a solid made of profiles are read in (their plane z = 0): an
/// extrusion's and a loft's at (x, y); a revolution's and a screw's at the distance from the
/// y axis (less the revolution's offset) and y.
fn profiles(node: &Node, r: Aabb) -> Vec<(NodeId, f64, Aabb)> {
    let flat = |r: Aabb| Aabb {
        min: [r.min[0], r.min[1], 0.0],
        max: [r.max[0], r.max[1], 0.0],
    };
    let around = |r: Aabb, offset: f64| Aabb {
        min: [-offset, r.min[1], 0.0],
        max: [r.radius(0, 2) - offset, r.max[1], 0.0],
    };
    if r.is_empty() {
        return Vec::new();
    }
    match node {
        Node::Extrude { child, .. } => vec![(*child, 0.0, flat(r))],
        Node::Loft { bottom, top, .. } => vec![(*bottom, 0.0, flat(r)), (*top, 0.0, flat(r))],
        Node::Revolve { offset, child } => vec![(*child, 0.0, around(r, *offset))],
        Node::Screw { child, .. } => vec![(*child, 0.0, around(r, 0.0))],
        // Within the farthest the region reaches from the path's box, either way.
        Node::Sweep { path, child, .. } => {
            let (lo, hi) = path.0.aabb();
            let m = [0, 1, 2]
                .map(|i| (r.max[i] - lo[i]).abs().max((hi[i] - r.min[i]).abs()))
                .iter()
                .map(|x| x * x)
                .sum::<f64>()
                .sqrt();
            vec![(
                *child,
                0.0,
                Aabb {
                    min: [-m, -m, 0.0],
                    max: [m, m, 0.0],
                },
            )]
        }
        _ => Vec::new(),
    }
}

/// Where rays can go: within `max_dist` of the camera for camera rays, of a hit for each
/// bounce and each shadow ray towards a directional light, and up to every point light.
fn view_region(scene: &Scene) -> Aabb {
    let s = &scene.settings;
    let secondary = scene
        .materials
        .iter()
        .any(|m| m.reflects() || m.transparency > 0.0);
    let legs = if secondary {
        s.max_depth as f64 + 2.0
    } else {
        2.0
    };
    let reach = s.max_dist.max(0.0) * legs;
    let mut region = Aabb::centred([reach; 3]).translate(scene.camera.position);
    for l in &scene.lights {
        if let Light::Point { position, .. } = l {
            region = region.union(Aabb {
                min: *position,
                max: *position,
            });
        }
    }
    region
}

/// The children of a node with the margin and region they are read with.
pub(super) fn down(node: &Node, m: f64, r: Aabb) -> Vec<(NodeId, f64, Aabb)> {
    match node {
        Node::Combine { children, .. } => children.iter().map(|&c| (c, m, r)).collect(),
        Node::SmoothCombine {
            k, variant, a, b, ..
        } => {
            // The blend reads each operand wherever it is within k of the other, and the
            // surface lies where the smaller one is below the reach.
            let m = m + k.max(0.0) + blend_reach(*k, *variant);
            vec![(*a, m, r), (*b, m, r)]
        }
        Node::Feature { op, a, b } => {
            // The feature is shaped by both fields up to its size from either surface.
            let m = m + op.reach();
            vec![(*a, m, r), (*b, m, r)]
        }
        Node::Translate { offset, child } => vec![(*child, m, r.translate(offset.map(|x| -x)))],
        Node::Rotate { matrix, child } => vec![(*child, m, r.transform(matrix, true))],
        Node::Scale { factor, child } => vec![(*child, m / factor, r.scale([1.0 / factor; 3]))],
        Node::ScaleXyz { factors, child } => {
            let smin = factors.iter().fold(f64::INFINITY, |a, f| a.min(f.abs()));
            vec![(*child, m / smin, r.scale(factors.map(|f| 1.0 / f)))]
        }
        Node::Repeat {
            period,
            count,
            child,
        } => vec![(*child, m, repeat_region(r, *period, *count))],
        Node::Mirror { axes, child } => vec![(*child, m, fold(r, *axes))],
        Node::Twist { child, .. } | Node::RepeatPolar { child, .. } => {
            vec![(*child, m, around(r, 1))]
        }
        Node::Wrap { radius, child } => vec![(*child, m, unwrap_region(r, *radius))],
        Node::Shear { matrix, child } => {
            let (smin, _) = singular_range(matrix);
            let inverse = invert(matrix).unwrap_or(IDENTITY);
            vec![(*child, m / smin.max(1e-12), r.transform(&inverse, false))]
        }
        Node::Taper { rate, child } => vec![(*child, m, untaper_region(r, *rate))],
        Node::Morph { a, b, .. } => vec![(*a, m, r), (*b, m, r)],
        Node::Bend { child, .. } => vec![(*child, m, around(r, 2))],
        Node::Round { radius, child } => vec![(*child, m + radius, r)],
        Node::Shell { half, child } => vec![(*child, m + half, r)],
        Node::Elongate { half, child } => vec![(
            *child,
            m,
            r.map(|i, lo, hi| (unstretch(lo, half[i]), unstretch(hi, half[i]))),
        )],
        Node::Paint { child, .. } => vec![(*child, m, r)],
        _ => Vec::new(),
    }
}

/// The region a wrap's child is read in: u = R·angle within ±π·R, y kept, w = R − ρ for ρ
/// from 0 to the region's farthest distance from the y axis.
fn unwrap_region(r: Aabb, radius: f64) -> Aabb {
    let rho = r.radius(0, 2);
    Aabb {
        min: [-std::f64::consts::PI * radius, r.min[1], radius - rho],
        max: [std::f64::consts::PI * radius, r.max[1], radius],
    }
}

/// The region a taper's child is read in: (x, z) divided by 1 + rate·y, which is at least
/// the smallest positive factor over the region's heights (clamped as the lowering clamps).
fn untaper_region(r: Aabb, rate: f64) -> Aabb {
    let s = taper_floor(rate, r.min[1], r.max[1]);
    r.map(|i, lo, hi| if i == 1 { (lo, hi) } else { (lo / s, hi / s) })
        .union(r)
}

/// x − clamp(x, −h, h): the coordinate an elongation reads its child at.
fn unstretch(x: f64, h: f64) -> f64 {
    x - x.clamp(-h, h)
}

/// The region a repetition's child is read in.
fn repeat_region(r: Aabb, period: V3, count: Option<V3>) -> Aabb {
    r.map(|i, lo, hi| {
        let s = period[i];
        if s == 0.0 {
            return (lo, hi);
        }
        let cell = (-s * 0.5, s * 0.5);
        match count {
            None => cell,
            Some(n) => {
                let reach = s * (n[i] - 1.0) * 0.5;
                (cell.0.min(lo + reach), cell.1.max(hi - reach))
            }
        }
    })
}

/// The region folded by a mirror.
fn fold(r: Aabb, axes: [bool; 3]) -> Aabb {
    r.map(|i, lo, hi| {
        if !axes[i] || lo >= 0.0 {
            (lo, hi)
        } else if hi <= 0.0 {
            (-hi, -lo)
        } else {
            (0.0, hi.max(-lo))
        }
    })
}

/// The region a rotation about axis `keep` can move `r` to: a square around that axis.
fn around(r: Aabb, keep: usize) -> Aabb {
    let (a, b) = match keep {
        1 => (0, 2),
        _ => (0, 1),
    };
    let rho = r.radius(a, b);
    r.map(|i, lo, hi| if i == keep { (lo, hi) } else { (-rho, rho) })
}
