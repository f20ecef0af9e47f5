//! Effective sample size of several chains: autocorrelations combined over chains through the
//! multi-chain variance estimate, summed with Geyer's initial monotone positive sequence
//! (Geyer 1992; the estimator of Stan and of Vehtari et al. 2021, section 3.2).

use super::rank::{rank_normalise, split_chains};
use super::rhat::mean_var;

/// Autocovariance of one chain at lag t (divided by N).
fn autocov(c: &[f64], mean: f64, t: usize) -> f64 {
    let n = c.len();
    (0..n - t)
        .map(|i| (c[i] - mean) * (c[i + t] - mean))
        .sum::<f64>()
        / n as f64
}

/// ESS of the chains as given (no splitting or normalisation):
/// rho_t = 1 - (W - mean_m acov_m(t)) / var+, tau = -1 + 2 sum_k (rho_2k + rho_2k+1) over the
/// initial positive and monotone sequence of pair sums, ESS = M N / tau (tau at least
/// 1 / log10(M N)). Autocovariances are computed lag by lag until the sequence ends (no FFT:
/// the sum stops after a few autocorrelation times).
pub fn ess(chains: &[Vec<f64>]) -> f64 {
    let m = chains.len();
    let n = chains.iter().map(Vec::len).min().unwrap_or(0);
    if m == 0 || n < 4 {
        return f64::NAN;
    }
    let chains: Vec<&[f64]> = chains.iter().map(|c| &c[..n]).collect();
    let stats: Vec<(f64, f64)> = chains.iter().map(|c| mean_var(c)).collect();
    let nf = n as f64;
    let w = stats.iter().map(|s| s.1).sum::<f64>() / m as f64;
    let mut var_plus = w * (nf - 1.0) / nf;
    if m > 1 {
        let grand = stats.iter().map(|s| s.0).sum::<f64>() / m as f64;
        var_plus += stats.iter().map(|s| (s.0 - grand).powi(2)).sum::<f64>() / (m as f64 - 1.0);
    }
    if var_plus.is_nan() || var_plus <= 0.0 {
        return f64::NAN;
    }
    let rho = |t: usize| -> f64 {
        let mean_acov = chains
            .iter()
            .zip(&stats)
            .map(|(c, s)| autocov(c, s.0, t))
            .sum::<f64>()
            / m as f64;
        1.0 - (w - mean_acov) / var_plus
    };
    // Pair sums P_k = rho_2k + rho_2k+1 while positive, made monotone non-increasing.
    let mut rhos = vec![1.0, rho(1)];
    let mut t = 1;
    let (mut even, mut odd) = (1.0, rhos[1]);
    while t + 2 < n - 3 && even + odd > 0.0 {
        even = rho(t + 1);
        odd = rho(t + 2);
        if even + odd >= 0.0 {
            rhos.push(even);
            rhos.push(odd);
        }
        t += 2;
    }
    let max_t = rhos.len() - 1;
    let mut tail = 0.0;
    if even > 0.0 && even + odd < 0.0 {
        tail = even;
    }
    let mut k = 1;
    while k + 2 <= max_t {
        let prev = rhos[k - 1] + rhos[k];
        if rhos[k + 1] + rhos[k + 2] > prev {
            rhos[k + 1] = prev / 2.0;
            rhos[k + 2] = prev / 2.0;
        }
        k += 2;
    }
    let total = m as f64 * nf;
    let tau = (-1.0 + 2.0 * rhos.iter().sum::<f64>() + tail).max(1.0 / total.log10());
    total / tau
}

/// Bulk ESS: [`ess`] of the rank-normalised split chains.
pub fn ess_bulk(chains: &[Vec<f64>]) -> f64 {
    ess(&rank_normalise(&split_chains(chains)))
}

/// Tail ESS: the smaller [`ess`] of the split chains' indicators I(x <= q_0.05) and
/// I(x <= q_0.95), q the pooled quantiles.
pub fn ess_tail(chains: &[Vec<f64>]) -> f64 {
    let split = split_chains(chains);
    let mut all: Vec<f64> = split.iter().flatten().copied().collect();
    all.sort_by(f64::total_cmp);
    let q = |p: f64| all[((all.len() - 1) as f64 * p).round() as usize];
    let indicator = |cut: f64| -> Vec<Vec<f64>> {
        split
            .iter()
            .map(|c| {
                c.iter()
                    .map(|&x| if x <= cut { 1.0 } else { 0.0 })
                    .collect()
            })
            .collect()
    };
    if all.is_empty() {
        return f64::NAN;
    }
    ess(&indicator(q(0.05))).min(ess(&indicator(q(0.95))))
}
