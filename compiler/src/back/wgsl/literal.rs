//! Numbers as WGSL literals: f32 values written so that naga and Tint read them alike.

/// A WGSL float literal for `x` rounded to f32 (finite values only reach here; others are
/// clamped to the largest f32 so that the module stays valid).
///
/// WGSL reads a literal without suffix as an abstract float (an f64) and converts that to
/// f32: Tint rejects an f64 beyond the largest f32, naga rounds to the nearest. The shortest
/// text of an f32 is used when its f64 lies within f32's range and rounds to the same f32;
/// otherwise (the shortest text of `f32::MAX`, 3.4028235e38, lies above it) the shortest text
/// of the f32 as an f64, which is the f32 exactly.
pub fn float(x: f64) -> String {
    let f = (x as f32).clamp(-f32::MAX, f32::MAX);
    let short = format!("{f:?}");
    let read = short.parse::<f64>().unwrap_or(f64::INFINITY);
    let s = if read.abs() <= f64::from(f32::MAX) && read as f32 == f {
        short
    } else {
        format!("{:?}", f64::from(f))
    };
    if s.contains('.') || s.contains('e') {
        s
    } else {
        format!("{s}.0")
    }
}
