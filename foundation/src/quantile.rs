//! Quantiles of a sorted sample.

/// Quantile q of sorted values: linear interpolation between order statistics,
/// x_(i) + (pos - i) (x_(i+1) - x_(i)) with pos = q (n - 1), q clamped to [0, 1]; NaN when empty.
///
/// ```
/// use hpge_foundation::quantile;
/// let v = [1.0, 2.0, 3.0, 4.0, 5.0];
/// assert_eq!(quantile(&v, 0.5), 3.0);
/// assert_eq!(quantile(&v, 0.9), 4.6);
/// assert_eq!(quantile(&v, 1.5), 5.0);
/// assert!(quantile(&[], 0.5).is_nan());
/// ```
pub fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let pos = q.clamp(0.0, 1.0) * (sorted.len() - 1) as f64;
    let i = pos.floor() as usize;
    let j = (i + 1).min(sorted.len() - 1);
    sorted[i] + (pos - i as f64) * (sorted[j] - sorted[i])
}
