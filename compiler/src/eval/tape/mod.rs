//! Tapes: distance programs prepared for batch evaluation (dead instructions dropped,
//! constant operands of two-operand instructions made immediate, fused steps where
//! [`fuse`] finds them, registers packed into reusable slots; the inputs are slots 0 to 2,
//! read in place), and the loop that runs each step.
//!
//! A guarded block becomes an `Enter` step, the block's steps and a `Leave` step. `Enter`
//! finds the points of the batch where the block runs; where none does, it sets the block's
//! results to their values from before and jumps past `Leave`. Otherwise it gathers the
//! values the block reads from outside into slots of its own, packed for the running points
//! only, so that the block's steps run over those points alone; `Leave` scatters the
//! results back. Blocks nest, each packing relative to the one around it. A block that runs on
//! most of the points around it copies its values whole instead and runs on all of them,
//! `Leave` keeping its results where it runs (the evaluator's `DENSE`).

use super::fuse::{Finish, Kind};
use crate::program::mesh::TriMesh;
use crate::program::outline::Outline;
use crate::program::{Binary, Unary};
use std::sync::Arc;

mod compile;
mod run;

pub(super) use run::Sources;

/// Which results a tape computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outputs {
    /// The distance only (sphere tracing, shadows, normals).
    Distance,
    /// The distance and the material id (shading).
    DistanceAndMaterial,
}

/// The operation of one instruction step.
#[derive(Debug, Clone, Copy)]
enum Code {
    /// `op(a)`
    Unary(Unary),
    /// `op(a, b)`
    Binary(Binary),
    /// `op(a, k)`
    BinaryK(Binary),
    /// `op(k, a)`
    KBinary(Binary),
    /// `select(a, b, c)`
    Select,
    /// A fused sum of 1 to 3 terms over `a`, `b`, `c` (see [`fuse`]).
    Fused(Kind, u8, Finish),
    /// The distance to the tape's mesh of this id at the point (`a`, `b`, `c`).
    Mesh(u32),
    /// The signed distance at (`a`, `b`) to the tape's outline number `k`.
    Outline,
}

/// One instruction over slots: `dst = code(a, b, c)` with the immediate `k` (and, for a
/// fused step, its terms' constants `ks`). `dst` never equals an operand.
#[derive(Debug, Clone, Copy)]
pub(super) struct Inst {
    code: Code,
    pub(super) dst: u32,
    a: u32,
    b: u32,
    c: u32,
    k: f64,
    ks: [f64; 3],
}

/// A step of a tape.
#[derive(Debug, Clone, Copy)]
pub(super) enum Step {
    /// An instruction.
    Inst(Inst),
    /// The start of a guarded block (index into the guards).
    Enter(u32),
    /// The end of a guarded block.
    Leave(u32),
}

/// The slots of a guarded block.
#[derive(Debug, Clone)]
pub(super) struct Guard {
    /// The block runs where `!(bound >= best)`.
    pub bound: u32,
    pub best: u32,
    /// (outside slot, inside slot) of each value the block reads from outside.
    pub gathers: Vec<(u32, u32)>,
    /// (result slot outside, value inside, value from before) of each result.
    pub phis: Vec<(u32, u32, u32)>,
    /// The index of the step after the block's `Leave`.
    pub after: usize,
}

/// Slot numbers below this one are the inputs x, y and z, read in place from the caller's
/// slices; scratch slot `s` (from `INPUTS` up) is the evaluator's `s - INPUTS`th chunk.
pub(super) const INPUTS: u32 = 3;

/// A program prepared for an [`super::Evaluator`].
#[derive(Debug, Clone)]
pub struct Tape {
    steps: Vec<Step>,
    guards: Vec<Guard>,
    constants: Vec<(u32, f64)>,
    slots: usize,
    depth: usize,
    instructions: usize,
    distance: u32,
    material: Option<u32>,
    /// Whether the last step computes the distance at the top level, and so can write it
    /// straight into the caller's output.
    direct: bool,
    /// The program's meshes, by id.
    meshes: Vec<Option<std::sync::Arc<TriMesh>>>,
    /// The program's outlines ([`Op::Outline`]).
    outlines: Vec<Arc<Outline>>,
}

impl Tape {
    /// The meshes its steps read, by id.
    #[inline]
    pub(super) fn meshes(&self) -> &[Option<std::sync::Arc<TriMesh>>] {
        &self.meshes
    }

    /// Number of instructions run per point (when every guarded block runs).
    #[inline]
    pub fn len(&self) -> usize {
        self.instructions
    }

    /// True when the tape runs no instruction (the result is a constant or an input).
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.instructions == 0
    }

    /// Number of scratch slots (of one chunk each) an evaluator needs (inputs not counted).
    #[inline]
    pub fn slot_count(&self) -> usize {
        self.slots
    }

    /// The deepest nesting of guarded blocks.
    #[inline]
    pub fn depth(&self) -> usize {
        self.depth
    }

    #[inline]
    pub(super) fn outlines(&self) -> &[Arc<Outline>] {
        &self.outlines
    }

    #[inline]
    pub(super) fn steps(&self) -> &[Step] {
        &self.steps
    }

    #[inline]
    pub(super) fn guard(&self, g: u32) -> &Guard {
        &self.guards[g as usize]
    }

    #[inline]
    pub(super) fn constants(&self) -> &[(u32, f64)] {
        &self.constants
    }

    #[inline]
    pub(super) fn distance_slot(&self) -> u32 {
        self.distance
    }

    #[inline]
    pub(super) fn material_slot(&self) -> Option<u32> {
        self.material
    }

    /// Whether the last step computes the distance at the top level, and so can write it
    /// straight into the caller's output instead of its slot.
    #[inline]
    pub(super) fn direct(&self) -> bool {
        self.direct
    }
}
