//! The FP32 floor of a GPU render: the arithmetic a frame needs (operations of the distance
//! program per evaluation, times the evaluations counted in its statistics) over the device's
//! peak FP32 rate, from a table of peaks by device name. `docs/accuracy.md` documents the
//! weights and the sources of the peaks.

use crate::cpu::Counters;
use sdfc_compiler::{Binary, Op, Program, Unary};

/// Operations counted for one special-function instruction (sqrt, exp, log, sin, cos): an
/// SM of the Hopper and Ampere data-centre GPUs issues 16 of them per clock against 128 FP32
/// operations, so each takes the place of 8.
pub const TRANSCENDENTAL: f64 = 8.0;

/// Operations counted for the inverse trigonometric functions (acos, atan2), which have no
/// hardware instruction and are evaluated as a polynomial with a square root or reciprocal.
pub const INVERSE_TRIG: f64 = 16.0;

/// Operations one instruction of a distance program counts for.
pub fn op_cost(op: &Op) -> f64 {
    match op {
        Op::Const(_) | Op::Input(_) => 0.0,
        Op::Unary(u, _) => unary_cost(*u),
        Op::Binary(b, _, _) => binary_cost(*b),
        // A text's outline: a loop over its data, counted as one glyph's worth of curves.
        Op::Outline(..) => 40.0 * (INVERSE_TRIG + 3.0 * TRANSCENDENTAL),
        _ => 1.0,
    }
}

fn unary_cost(u: Unary) -> f64 {
    match u {
        Unary::Sqrt | Unary::Sin | Unary::Cos | Unary::Exp | Unary::Log => TRANSCENDENTAL,
        Unary::Acos => INVERSE_TRIG,
        Unary::Round => 2.0,
        _ => 1.0,
    }
}

fn binary_cost(b: Binary) -> f64 {
    match b {
        Binary::Div => 2.0,
        Binary::Pow => 2.0 * TRANSCENDENTAL + 1.0,
        Binary::Atan2 => INVERSE_TRIG,
        _ => 1.0,
    }
}

/// Operations of one evaluation of the distance: the instructions the distance register
/// depends on (the material's are left out, as the march does not compute them), weighted
/// by [`op_cost`]. Every guarded block is counted, though an evaluation runs only the blocks
/// whose bounds are near it: for a program with blocks this is an upper bound of the work.
pub fn distance_ops(program: &Program) -> f64 {
    let ops = program.ops();
    let mut live = vec![false; ops.len()];
    if let Some(l) = live.get_mut(program.distance().0 as usize) {
        *l = true;
    }
    let mut total = 0.0;
    for i in (0..ops.len()).rev() {
        if !live[i] {
            continue;
        }
        total += op_cost(&ops[i]);
        for r in ops[i].operands() {
            if let Some(l) = live.get_mut(r.0 as usize) {
                *l = true;
            }
        }
    }
    total
}

/// Evaluations of the distance in a frame: every marching step of every ray, and the four
/// taps of the normal at every hit.
pub fn evaluations(c: &Counters) -> u64 {
    c.steps + 4 * c.hits
}

/// Peak FP32 rates in TFLOP/s (a fused multiply-add counted as two operations, boost clock,
/// no tensor cores), from NVIDIA's data sheets. Matched in order against the lower-cased
/// device name, so the more specific names come first.
pub const PEAKS: &[(&str, f64)] = &[
    ("h100 pcie", 51.0),
    ("h100 nvl", 60.0),
    ("h100", 67.0),
    ("h200 nvl", 60.0),
    ("h200", 67.0),
    ("gh200", 67.0),
    ("a100", 19.5),
    ("l40s", 91.6),
    ("l40", 90.5),
    ("l4", 30.3),
    ("a10", 31.2),
    ("rtx 4090", 82.6),
    ("rtx 3090", 35.6),
    ("v100 pcie", 14.0),
    ("v100", 15.7),
    ("t4", 8.1),
];

/// The peak FP32 rate of a device in FLOP/s, from its name; `None` for a device not in
/// [`PEAKS`].
pub fn peak_flops(device: &str) -> Option<f64> {
    let name = device.to_lowercase();
    PEAKS
        .iter()
        .find(|(key, _)| contains_word(&name, key))
        .map(|&(_, tflops)| tflops * 1e12)
}

/// Whether `key` occurs in `name` not followed by a letter or digit ("l4" is not "l40s").
fn contains_word(name: &str, key: &str) -> bool {
    name.match_indices(key).any(|(at, _)| {
        let before = name[..at].chars().next_back();
        let after = name[at + key.len()..].chars().next();
        !before.is_some_and(|c| c.is_ascii_alphanumeric())
            && !after.is_some_and(|c| c.is_ascii_alphanumeric())
    })
}

/// The fraction of the peak FP32 rate a frame achieved: `ops_per_eval · evaluations` over
/// `seconds · peak`. `None` where the quotient exceeds 1 (or is not a number): the count is
/// then not what ran, and no fraction of peak above 1 is ever reported.
pub fn fraction(ops_per_eval: f64, evaluations: u64, seconds: f64, peak: f64) -> Option<f64> {
    let f = ops_per_eval * evaluations as f64 / (seconds * peak);
    (f.is_finite() && (0.0..=1.0).contains(&f)).then_some(f)
}

/// The fraction of the peak FP32 rate a frame of `program` achieved, where the operations
/// that ran are known: every evaluation of a program without guarded blocks runs all of
/// [`distance_ops`]. `None` for a program with guarded blocks: an evaluation runs only the
/// blocks whose bounds are near, which the statistics do not count, and counting every block
/// reports more than the peak (several times it for `examples/scaling/compound_1000.sdf`).
pub fn fraction_of_peak(
    program: &Program,
    evaluations: u64,
    seconds: f64,
    peak: f64,
) -> Option<f64> {
    if !program.blocks().is_empty() {
        return None;
    }
    fraction(distance_ops(program), evaluations, seconds, peak)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn device_names() {
        assert_eq!(peak_flops("NVIDIA H100 80GB HBM3 (sm_90)"), Some(67.0e12));
        assert_eq!(peak_flops("NVIDIA H100 PCIe (sm_90)"), Some(51.0e12));
        assert_eq!(peak_flops("NVIDIA H200 (sm_90)"), Some(67.0e12));
        assert_eq!(peak_flops("NVIDIA L40S"), Some(91.6e12));
        assert_eq!(peak_flops("NVIDIA L4"), Some(30.3e12));
        assert_eq!(peak_flops("NVIDIA A100-SXM4-80GB"), Some(19.5e12));
        assert_eq!(peak_flops("llvmpipe (LLVM 15.0.6, 256 bits)"), None);
    }
}
