//! Loops compiled for the widest vector unit the processor has: [`wide`] runs a closure
//! inside a function compiled with AVX2 where the processor supports it (checked once and
//! cached by the standard library), and compiled as usual elsewhere. The interpreter's
//! instruction loops and the renderer's lane loops go through it.
//!
//! What `f` inlines is compiled for AVX2 (eight f32 or four f64 per operation instead of four
//! or two); what it calls without inlining is not, so the loops that matter are marked
//! `#[inline(always)]` on the way down, the closure passed in included: its body holds the
//! whole inlined loop nest, too large for LLVM to inline on its own (without the attribute
//! the interpreter's loops ran as a separate, baseline-compiled closure). Results do not change: rustc never lets LLVM contract
//! or reorder floating-point operations, so the vector code performs the same IEEE operations
//! in the same order. That holds for f32 sine, cosine and arc tangent too, polynomials of
//! plain operations (`program/trig.rs`) that vectorise like the rest; the other
//! transcendental functions (and sine and cosine of arguments beyond 2²⁰) are the same library
//! calls either way.

/// Runs `f`, compiled for AVX2 where the processor has it.
#[inline(always)]
pub fn wide<R>(f: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor has AVX2, as just checked.
        #[allow(unsafe_code)]
        return unsafe { avx2(f) };
    }
    f()
}

/// Calls `f` in a function compiled with AVX2.
///
/// # Safety
/// The processor must support AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[allow(unsafe_code)] // Only called where AVX2 was detected.
unsafe fn avx2<R>(f: impl FnOnce() -> R) -> R {
    f()
}
