//! The f32 instructions that WGSL's arithmetic becomes: the one place that chooses each
//! operation's PTX form (rounding, flushing, approximation), read by the operators, the
//! math functions and the library sequences alike.

// Every f32 instruction that rounds is written with `.ftz` (subnormal inputs and results
// flushed to sign-preserving zero), as WGSL allows (§ floating-point evaluation: an
// implementation may flush subnormals) and as NVIDIA's Vulkan driver runs shaders. For
// add, mul and fma it costs nothing either way; for the MUFU-based instructions (sqrt,
// rsqrt, rcp, lg2, division) the non-`.ftz` forms cost two to five extra instructions
// each (a compare and predicated rescaling around the MUFU), which made the PTX kernels
// 10–40 % slower than the same WGSL through Vulkan. Exact operations (abs, neg, min,
// max, comparisons, roundings) keep their plain forms: `abs.ftz` is a real instruction
// where `abs` folds into an operand.
//
// Products and sums carry no rounding modifier so that ptxas may contract them into
// FMAs, as NVIDIA's compilers do by default; explicit fused operations use `fma.rn`.

/// f32 addition, subtraction and multiplication (contractible).
pub(super) const ADD: &str = "add.ftz.f32";
pub(super) const SUB: &str = "sub.ftz.f32";
pub(super) const MUL: &str = "mul.ftz.f32";
/// A fused multiply-add.
pub(super) const FMA: &str = "fma.rn.ftz.f32";

/// f32 division `a / b`: `a · rcp(b)` (MUFU.RCP and a multiply), at most 2 ulp for |b| in
/// [2⁻¹²⁶, 2¹²⁶] (PTX ISA), which is the range where WGSL asks for 2.5 ulp; beyond it a
/// finite `a` gives 0 (and ∞ gives NaN). Bit for bit what NVIDIA's Vulkan driver gives
/// for the same WGSL (compared on 65 536 inputs: docs/ptx.md).
pub(super) const DIV: &str = "div.approx.ftz.f32";

/// f32 division over the full range (operands scaled when |b| > 2¹²⁶), 2 ulp everywhere:
/// for atan2, whose ratio min/max may have both terms beyond 2¹²⁶.
pub(super) const DIV_FULL: &str = "div.full.ftz.f32";

/// f32 square root: the hardware approximation, one MUFU.SQRT (under 1 ulp measured;
/// WGSL asks for the accuracy of 1/inverseSqrt, about 2.5 ulp), several times faster than
/// `sqrt.rn`; bit for bit the Vulkan driver's.
pub(super) const SQRT: &str = "sqrt.approx.ftz.f32";
/// 1/sqrt(x): one MUFU.RSQ.
pub(super) const RSQRT: &str = "rsqrt.approx.ftz.f32";
/// 2^x and log2(x): one MUFU.EX2 / MUFU.LG2 each.
pub(super) const EX2: &str = "ex2.approx.ftz.f32";
pub(super) const LG2: &str = "lg2.approx.ftz.f32";
/// sin and cos of an argument in [−π, π]: a multiply by 1/2π and one MUFU each.
pub(super) const SIN: &str = "sin.approx.ftz.f32";
pub(super) const COS: &str = "cos.approx.ftz.f32";
