//! Accuracy figures of a surrogate against solver values: the paper's Gaussian fit of the relative
//! errors (section 7, its sigma becomes sigma_p) and quantiles of |relative error|.

use serde::{Deserialize, Serialize};

/// Error figures on one data set. Relative values are fractions (0.01 = 1%).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Figures {
    /// Samples.
    pub n: usize,
    /// Sigma of a Gaussian fitted to the histogram of (c_p - c_s)/c_s.
    pub rel_sigma: f64,
    /// Its mean.
    pub rel_mean: f64,
    /// Root mean square of the relative error (tails included).
    pub rel_rms: f64,
    /// Median of |relative error|.
    pub abs_rel_q50: f64,
    /// 90% quantile of |relative error|.
    pub abs_rel_q90: f64,
    /// 99% quantile of |relative error|.
    pub abs_rel_q99: f64,
    /// 99.9% quantile of |relative error|.
    pub abs_rel_q999: f64,
    /// Largest |relative error|.
    pub abs_rel_max: f64,
    /// Root mean square of c_p - c_s (pF).
    pub abs_rms_pf: f64,
}

pub use hpge_foundation::quantile;

/// Gaussian fit to a sample's histogram: the counts n_b of 60 bins spanning median +- 3 s
/// (s = 1.4826 MAD, the robust sigma) are fitted by ln n_b = a + b x + c x^2 in weighted least
/// squares (weights n_b, the inverse variance of ln n_b), using bins with n_b >= 3:
/// sigma = sqrt(-1 / 2c), mean = -b / 2c. Returns (mean, sigma); falls back to the median and the
/// robust sigma when too few bins are filled.
pub fn gaussian_fit(values: &[f64]) -> (f64, f64) {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    v.sort_by(f64::total_cmp);
    let med = quantile(&v, 0.5);
    let mut dev: Vec<f64> = v.iter().map(|x| (x - med).abs()).collect();
    dev.sort_by(f64::total_cmp);
    let s = 1.4826 * quantile(&dev, 0.5);
    if s.is_nan() || s <= 0.0 {
        return (med, s);
    }
    let bins = 60;
    let (lo, width) = (med - 3.0 * s, 6.0 * s / bins as f64);
    let mut counts = vec![0.0; bins];
    for &x in &v {
        let k = ((x - lo) / width).floor();
        if k >= 0.0 && (k as usize) < bins {
            counts[k as usize] += 1.0;
        }
    }
    // Normal equations of the weighted fit in t = (x - med)/s.
    let mut m = [[0.0; 3]; 3];
    let mut r = [0.0; 3];
    let mut used = 0;
    for (k, &n) in counts.iter().enumerate() {
        if n < 3.0 {
            continue;
        }
        used += 1;
        let t = (lo + (k as f64 + 0.5) * width - med) / s;
        let f = [1.0, t, t * t];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += n * f[i] * f[j];
            }
            r[i] += n * f[i] * n.ln();
        }
    }
    let Some([_, b, c]) = solve3(m, r).filter(|_| used >= 5) else {
        return (med, s);
    };
    if c >= 0.0 {
        return (med, s);
    }
    (med + s * (-b / (2.0 * c)), s * (-1.0 / (2.0 * c)).sqrt())
}

/// Solves a 3x3 system by Cramer's rule.
fn solve3(m: [[f64; 3]; 3], r: [f64; 3]) -> Option<[f64; 3]> {
    let det = |a: [[f64; 3]; 3]| {
        a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
            - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
    };
    let d = det(m);
    if d.abs() < 1e-300 {
        return None;
    }
    let mut x = [0.0; 3];
    for (k, xk) in x.iter_mut().enumerate() {
        let mut a = m;
        for i in 0..3 {
            a[i][k] = r[i];
        }
        *xk = det(a) / d;
    }
    Some(x)
}

impl Figures {
    /// Figures of predictions `pred` against solver values `truth` (pF).
    pub fn of(pred: &[f64], truth: &[f64]) -> Figures {
        let rel: Vec<f64> = pred.iter().zip(truth).map(|(p, t)| (p - t) / t).collect();
        let n = rel.len();
        let (rel_mean, rel_sigma) = gaussian_fit(&rel);
        let mut abs: Vec<f64> = rel.iter().map(|r| r.abs()).collect();
        abs.sort_by(f64::total_cmp);
        let abs_rms = (pred
            .iter()
            .zip(truth)
            .map(|(p, t)| (p - t).powi(2))
            .sum::<f64>()
            / n.max(1) as f64)
            .sqrt();
        Figures {
            n,
            rel_sigma,
            rel_mean,
            rel_rms: (rel.iter().map(|r| r * r).sum::<f64>() / n.max(1) as f64).sqrt(),
            abs_rel_q50: quantile(&abs, 0.5),
            abs_rel_q90: quantile(&abs, 0.9),
            abs_rel_q99: quantile(&abs, 0.99),
            abs_rel_q999: quantile(&abs, 0.999),
            abs_rel_max: abs.last().copied().unwrap_or(f64::NAN),
            abs_rms_pf: abs_rms,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{SeedableRng, rngs::StdRng};
    use rand_distr::{Distribution, Normal};

    #[test]
    fn gaussian_fit_recovers_a_normal_sample_with_outliers() {
        let mut rng = StdRng::seed_from_u64(7);
        let g = Normal::new(0.002, 0.015).unwrap();
        let mut v: Vec<f64> = (0..20000).map(|_| g.sample(&mut rng)).collect();
        v.extend((0..400).map(|k| 0.2 + k as f64 * 1e-3)); // a 2% tail far out
        let (mean, sigma) = gaussian_fit(&v);
        assert!((mean - 0.002).abs() < 5e-4, "mean {mean}");
        assert!((sigma / 0.015 - 1.0).abs() < 0.03, "sigma {sigma}");
    }

    #[test]
    fn quantiles_interpolate_order_statistics() {
        let v: Vec<f64> = (0..=100).map(f64::from).collect();
        assert_eq!(quantile(&v, 0.5), 50.0);
        assert_eq!(quantile(&v, 0.99), 99.0);
        assert!((quantile(&v, 0.999) - 99.9).abs() < 1e-12);
    }
}
