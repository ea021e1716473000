//! The one maximum of the figures: NaN wins.

/// max(a, b) that propagates NaN (`f64::max` ignores it): a non-finite estimate must not score
/// as a perfect one.
#[inline]
pub fn nan_max(a: f64, b: f64) -> f64 {
    // a when it is NaN or larger; else b, NaN when b is.
    if a > b || a.is_nan() { a } else { b }
}
