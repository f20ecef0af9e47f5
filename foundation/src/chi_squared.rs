//! The chi-squared distribution's upper tail (statrs' regularised incomplete gamma).

use statrs::function::gamma::gamma_ur;

/// P(X >= x) for X ~ chi^2(ndf): Q(ndf / 2, x / 2), the upper regularised incomplete gamma
/// function. 1 for x <= 0; NaN for ndf = 0 or x NaN.
///
/// ```
/// use hpge_foundation::chi_squared_sf;
/// // chi^2(1) >= 3.841 is the two-sided 5% of a normal.
/// assert!((chi_squared_sf(1, 3.841_458_820_694_124) - 0.05).abs() < 1e-12);
/// // chi^2(2) is exponential with mean 2: P(X >= x) = exp(-x / 2).
/// assert!((chi_squared_sf(2, 3.0) - (-1.5f64).exp()).abs() < 1e-14);
/// assert_eq!(chi_squared_sf(5, 0.0), 1.0);
/// assert!(chi_squared_sf(0, 1.0).is_nan());
/// ```
pub fn chi_squared_sf(ndf: usize, x: f64) -> f64 {
    if ndf == 0 || x.is_nan() {
        return f64::NAN;
    }
    if x <= 0.0 {
        return 1.0;
    }
    if x.is_infinite() {
        return 0.0;
    }
    gamma_ur(ndf as f64 / 2.0, x / 2.0)
}
