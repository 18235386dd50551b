//! The arena of nodes ([`Graph`]): hash-consed, children before parents, with spans; the
//! facts computed per node ([`Facts`], [`Exactness`]); how far a DAG would expand as a tree.

use super::{Node, NodeId};
use crate::diagnostics::Diagnostic;
use crate::limits::{Limit, Limits};
use crate::span::Span;
use std::collections::HashMap;

/// Facts an analysis computed for a node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Facts {
    /// Whether the field is an exact distance, a bound, or neither.
    pub exactness: Exactness,
    /// The step divisor L: marching by f / L never crosses the surface. For a field with a
    /// proven gradient bound it is that bound; for a bound such as the ellipsoid it is 1
    /// (a lower bound on the distance is safe to step by, however steep the field).
    pub lipschitz: f64,
}

/// How a field relates to the true distance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exactness {
    /// The exact Euclidean distance (signed).
    Exact,
    /// Never above the true distance (safe for sphere tracing).
    Bound,
    /// May overstate the distance.
    Approximate,
}

/// An arena of hash-consed nodes, with the span each node came from.
#[derive(Debug, Default, Clone)]
pub struct Graph {
    nodes: Vec<Node>,
    spans: Vec<Span>,
    dedup: HashMap<String, NodeId>,
}

impl Graph {
    /// Adds a node, or returns the id of an equal node added before.
    pub fn add(&mut self, node: Node, span: Span) -> NodeId {
        let key = node.key();
        if let Some(&id) = self.dedup.get(&key) {
            return id;
        }
        let id = NodeId(self.nodes.len() as u32);
        self.nodes.push(node);
        self.spans.push(span);
        self.dedup.insert(key, id);
        id
    }

    /// The node behind an id.
    pub fn node(&self, id: NodeId) -> &Node {
        &self.nodes[id.0 as usize]
    }

    /// The span of the expression that first built this node.
    pub fn span(&self, id: NodeId) -> Span {
        self.spans[id.0 as usize]
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// True when there are no nodes.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// All ids in creation order (children before parents).
    pub fn ids(&self) -> impl Iterator<Item = NodeId> {
        (0..self.nodes.len() as u32).map(NodeId)
    }

    /// The size of every node as a tree: the node and, for each child it names, the child's
    /// size (a shared sub-shape counts once per use). One pass in creation order, memoised
    /// per node and saturating, so it takes time linear in the graph, however large the
    /// tree: the bound on the passes that walk the scene as a tree (`Limit::Expansion`).
    pub fn tree_sizes(&self) -> Vec<u64> {
        let mut sizes: Vec<u64> = Vec::with_capacity(self.nodes.len());
        for node in &self.nodes {
            let size = node
                .children()
                .iter()
                .fold(1u64, |acc, c| acc.saturating_add(sizes[c.0 as usize]));
            sizes.push(size);
        }
        sizes
    }

    /// When the tree below `root` has more than `max` nodes: the deepest node of it whose
    /// own tree still has more (where the expansion crosses the limit), with the size of
    /// that node's tree and of the root's.
    pub fn over_expanded(&self, root: NodeId, max: u64) -> Option<Expansion> {
        let sizes = self.tree_sizes();
        let total = sizes[root.0 as usize];
        if total <= max {
            return None;
        }
        let mut at = root;
        while let Some(big) = self
            .node(at)
            .children()
            .into_iter()
            .find(|c| sizes[c.0 as usize] > max)
        {
            at = big;
        }
        Some(Expansion {
            at,
            size: sizes[at.0 as usize],
            total,
        })
    }

    /// The E0507 error of a tree over the `expansion` limit of `limits`, at the shape where
    /// the expansion crosses the limit.
    pub fn expansion_error(&self, e: &Expansion, limits: &Limits) -> Diagnostic {
        let max = limits.get(Limit::Expansion);
        Diagnostic::error(
            "E0507",
            format!("the scene's shapes expand to more than {max} nodes"),
            self.span(e.at),
        )
        .with_label(format!(
            "this shape alone expands to {} nodes when its shared sub-shapes are counted once per use",
            e.size
        ))
        .with_note(format!(
            "passes over the scene visit a shape once per use; this limit keeps them bounded; {}",
            limits.raise_to(Limit::Expansion, e.total)
        ))
    }
}

/// A scene whose tree is over the `expansion` limit ([`Graph::over_expanded`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Expansion {
    /// The deepest node whose tree is over the limit.
    pub at: NodeId,
    /// The size of its tree.
    pub size: u64,
    /// The size of the whole scene's tree (saturated at `u64::MAX`).
    pub total: u64,
}
