//! A model's accuracy by band of the bias voltage, as `hpge-cv evaluate` reports it beside the
//! whole set's figures: where along a C-V curve the surrogate can be trusted, and whether its
//! calibrated uncertainty sigma_s(p, U_B) follows its error there.
//!
//! On a uniform bias the whole set's figures are dominated by the rows above a few hundred
//! volts; c12 changes fastest at low bias (c12 ~ U_B^-1/2 while the depletion grows), where few
//! rows lie and the error is largest. The bands are therefore finer at the low end.

use serde::Serialize;

use crate::model::{DataSet, Surrogate, coverage_of, dimension_from_unit, gaussian_fit, quantile};
use crate::space::Target;

/// Band edges in the bias input's unit coordinate u: 1%, 3%, 10%, 20%, ... of its range (for
/// the paper's 10-3000 V: 10, 40, 100, 309, 608, 1206, 1804, 2402, 3000 V).
pub const BIAS_BAND_EDGES_U: [f64; 9] = [0.0, 0.01, 0.03, 0.1, 0.2, 0.4, 0.6, 0.8, 1.0];

/// The accuracy of the rows in one band of the bias.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BiasBand {
    /// The band [lo, hi] (V); rows with lo <= U_B < hi (the last band includes hi).
    pub range_v: [f64; 2],
    /// Rows in the band.
    pub n: usize,
    /// Gaussian sigma of the relative error (c_p - c_s)/c_s (the fit of
    /// [`gaussian_fit`]; its robust sigma 1.4826 MAD with few rows); NaN without rows.
    pub rel_sigma: f64,
    /// Median of |relative error|.
    pub abs_rel_q50: f64,
    /// 90% quantile of |relative error|.
    pub abs_rel_q90: f64,
    /// 99% quantile of |relative error|.
    pub abs_rel_q99: f64,
    /// Fraction of the band's rows within 2 predicted sigma (the calibrated sigma_s, or the
    /// constant sigma_p): near 0.95 where the error model follows the error.
    pub coverage_2sigma: f64,
}

/// The bands of [`BIAS_BAND_EDGES_U`] for `data` with relative errors `rel` and predicted
/// relative sigmas `sigma` (one per row); empty when the model's space has no bias input.
pub fn bias_bands(model: &Surrogate, data: &DataSet, rel: &[f64], sigma: &[f64]) -> Vec<BiasBand> {
    let space = &model.info.space;
    let order = crate::model::network_order(space).unwrap_or_default();
    let targets = space.targets();
    let Some(k) = order.iter().position(|&j| targets[j] == Target::Bias) else {
        return Vec::new();
    };
    let dim = &space.dimensions[order[k]];
    let last = BIAS_BAND_EDGES_U.len() - 2;
    BIAS_BAND_EDGES_U
        .windows(2)
        .enumerate()
        .map(|(b, e)| {
            let inside = |u: f64| u >= e[0] && (u < e[1] || (b == last && u <= e[1]));
            let rows: Vec<usize> = (0..data.len())
                .filter(|&i| inside(data.unit_row(i)[k]))
                .collect();
            band(
                [
                    dimension_from_unit(dim, e[0]),
                    dimension_from_unit(dim, e[1]),
                ],
                &rows.iter().map(|&i| rel[i]).collect::<Vec<_>>(),
                &rows.iter().map(|&i| sigma[i]).collect::<Vec<_>>(),
            )
        })
        .collect()
}

/// The figures of one band's relative errors `rel` with predicted sigmas `sigma`.
pub(crate) fn band(range_v: [f64; 2], rel: &[f64], sigma: &[f64]) -> BiasBand {
    let n = rel.len();
    let mut abs: Vec<f64> = rel.iter().map(|r| r.abs()).collect();
    abs.sort_by(f64::total_cmp);
    BiasBand {
        range_v,
        n,
        rel_sigma: if n == 0 {
            f64::NAN
        } else {
            gaussian_fit(rel).1
        },
        abs_rel_q50: quantile(&abs, 0.5),
        abs_rel_q90: quantile(&abs, 0.9),
        abs_rel_q99: quantile(&abs, 0.99),
        coverage_2sigma: coverage_of(rel, sigma.iter().copied()).1,
    }
}

#[cfg(test)]
mod tests {
    use super::band;

    #[test]
    fn a_band_counts_its_rows_within_two_sigma_and_takes_quantiles_of_the_absolute_error() {
        let rel = [0.01, -0.02, 0.03, -0.05];
        let sigma = [0.01, 0.01, 0.01, 0.03];
        let b = band([10.0, 40.0], &rel, &sigma);
        assert_eq!(b.n, 4);
        // |0.01| <= 0.02, |-0.02| <= 0.02, |0.03| > 0.02, |-0.05| <= 0.06.
        assert_eq!(b.coverage_2sigma, 0.75);
        assert!((b.abs_rel_q50 - 0.025).abs() < 1e-15);
        assert!(b.rel_sigma.is_finite() && b.rel_sigma > 0.0);
        let empty = band([40.0, 100.0], &[], &[]);
        assert_eq!(empty.n, 0);
        assert!(empty.rel_sigma.is_nan() && empty.coverage_2sigma.is_nan());
    }
}
