//! Loops compiled for the widest vector unit the processor has: [`wide`] runs a closure
//! inside a function compiled with AVX2 where the processor supports it (checked once and
//! cached by the standard library), and as it is elsewhere. The interpreter's instruction
//! loops and the renderer's lane loops go through it.
//!
//! What `f` inlines is compiled for AVX2 (eight f32 or four f64 per operation instead of four
//! or two); what it calls without inlining is not, so the loops that matter are marked
//! `#[inline(always)]` on the way down. The same IEEE operations run in the same order
//! either way (no fused multiply-add is enabled), so results are bit for bit the same.

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
