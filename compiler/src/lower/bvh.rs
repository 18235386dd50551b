//! The bounding volume hierarchy of a union's bounded children, split by the surface area
//! heuristic until splitting no longer pays, each half's bound the hull of its children's. The
//! half nearer the camera comes first, so that the best distance shrinks early for the points
//! nearest the eye. For the frames of a sequence ([`Shape::Fixed`]) the hierarchy is a
//! function of the children's order and costs alone, so that moving shapes and a moving camera
//! keep one program (their bounds are its constants).

use crate::scene::bounds::{hull, Bound};
use crate::scene::{NodeId, V3};

/// Instructions a union spends per child after evaluating it (min, lt, select).
pub(super) const FOLD_COST: f64 = 3.0;

/// A child of a union with a finite bound.
#[derive(Debug, Clone, Copy)]
pub(super) struct Item {
    pub id: NodeId,
    pub bound: Bound,
    pub cost: f64,
    /// Position among the union's children (leaves keep this order).
    pub index: usize,
}

/// A node of the hierarchy: a group of children, or two halves.
#[derive(Debug, Clone)]
pub(super) struct Tree {
    pub bound: Bound,
    /// Estimated instructions per point of everything below.
    pub cost: f64,
    pub kind: Kind,
}

/// What a [`Tree`] node holds.
#[derive(Debug, Clone)]
pub(super) enum Kind {
    /// Children evaluated one after the other.
    Leaf(Vec<Item>),
    /// Two halves, the first nearer the camera.
    Split(Box<Tree>, Box<Tree>, Plane),
}

/// The plane between the two halves of a split: the children of the `low` half have their
/// centres below `at` along `axis`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Plane {
    pub axis: usize,
    pub at: f64,
    /// Whether the first half is the low one.
    pub first_low: bool,
}

/// How a hierarchy is shaped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Shape {
    /// By the surface area heuristic over where the children are, the half nearer `eye`
    /// first.
    Sah { eye: V3 },
    /// By the children's order: each group of more than one child costing more than
    /// [`MIN_SPLIT_COST`] is halved, the first half first, its plane across the axis of the
    /// group's depth (x, y, z, x, …); no choice reads a number.
    Fixed,
}

/// Builds the hierarchy of a non-empty list of children.
pub(super) fn build(items: Vec<Item>, shape: Shape) -> Tree {
    build_at(items, shape, 0)
}

fn build_at(mut items: Vec<Item>, shape: Shape, depth: usize) -> Tree {
    let bound = items
        .iter()
        .map(|i| i.bound)
        .reduce(|a, b| hull(&a, &b))
        .expect("a non-empty group");
    let cost: f64 = items.iter().map(|i| i.cost + FOLD_COST).sum();
    let split = if items.len() < 2 || cost <= MIN_SPLIT_COST {
        None
    } else if let Shape::Sah { .. } = shape {
        best_split(&mut items, area(&bound), cost)
    } else {
        items.sort_by_key(|i| i.index);
        Some((depth % 3, items.len() / 2))
    };
    let Some(split) = split else {
        items.sort_by_key(|i| i.index);
        return Tree {
            bound,
            cost,
            kind: Kind::Leaf(items),
        };
    };
    let (axis, k) = split;
    let at = (items[k - 1].bound.aabb.c[axis] + items[k].bound.aabb.c[axis]) * 0.5;
    let rest = items.split_off(k);
    let (a, b) = (
        build_at(items, shape, depth + 1),
        build_at(rest, shape, depth + 1),
    );
    let swap = match shape {
        Shape::Sah { eye } => distance(&b.bound, eye) < distance(&a.bound, eye),
        Shape::Fixed => false,
    };
    let plane = Plane {
        axis,
        at,
        first_low: !swap,
    };
    let (first, second) = if swap { (b, a) } else { (a, b) };
    Tree {
        bound,
        cost,
        kind: Kind::Split(Box::new(first), Box::new(second), plane),
    }
}

/// A group costing less than this is never split.
const MIN_SPLIT_COST: f64 = 48.0;

/// The cost of a guard (its bound and bookkeeping), in instructions.
const GUARD: f64 = 48.0;

/// The surface area heuristic: sorts the items along the best axis and returns where to
/// split them, or `None` when splitting costs more than evaluating the group as it is. A
/// split costs two guards plus each half's cost weighted by its share of the surface area
/// (the chance that a point must evaluate it).
fn best_split(items: &mut [Item], total_area: f64, cost: f64) -> Option<(usize, usize)> {
    let mut best: Option<(f64, usize, usize)> = None;
    for axis in 0..3 {
        sort_along(items, axis);
        let n = items.len();
        let mut right = vec![(0.0, 0.0); n];
        let mut acc: Option<Bound> = None;
        let mut c = 0.0;
        for k in (1..n).rev() {
            acc = Some(acc.map_or(items[k].bound, |a| hull(&a, &items[k].bound)));
            c += items[k].cost + FOLD_COST;
            right[k] = (area(acc.as_ref().expect("set")), c);
        }
        let mut acc: Option<Bound> = None;
        let mut c = 0.0;
        for k in 0..n - 1 {
            acc = Some(acc.map_or(items[k].bound, |a| hull(&a, &items[k].bound)));
            c += items[k].cost + FOLD_COST;
            let (ra, rc) = right[k + 1];
            let a = area(acc.as_ref().expect("set"));
            let split = 2.0 * GUARD + (a * c + ra * rc) / total_area.max(1e-300);
            if best.is_none_or(|b| split < b.0) {
                best = Some((split, axis, k + 1));
            }
        }
    }
    let (split, axis, at) = best?;
    if split >= cost {
        return None;
    }
    sort_along(items, axis);
    Some((axis, at))
}

fn sort_along(items: &mut [Item], axis: usize) {
    items.sort_by(|a, b| {
        a.bound.aabb.c[axis]
            .total_cmp(&b.bound.aabb.c[axis])
            .then(a.index.cmp(&b.index))
    });
}

/// Half the surface area of a bound's box.
fn area(b: &Bound) -> f64 {
    let h = b.aabb.h;
    4.0 * (h[0] * h[1] + h[1] * h[2] + h[2] * h[0])
}

/// How far the eye is from a bound (0 inside), then from its centre, for ordering halves.
fn distance(b: &Bound, eye: V3) -> (f64, f64) {
    let c = b.sphere.c;
    let d = ((eye[0] - c[0]).powi(2) + (eye[1] - c[1]).powi(2) + (eye[2] - c[2]).powi(2)).sqrt();
    ((d - b.sphere.r).max(0.0), d)
}
