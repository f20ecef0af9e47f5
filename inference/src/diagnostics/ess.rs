//! Effective sample size of several chains: autocorrelations combined over chains through the
//! multi-chain variance estimate, summed with Geyer's initial monotone positive sequence
//! (Geyer 1992; the estimator of Stan and of Vehtari et al. 2021, section 3.2).

use rustfft::FftPlanner;
use rustfft::num_complex::Complex;

use super::rank::{rank_normalise, split_chains};
use super::rhat::mean_var;

/// Autocovariance of one chain at lag t (divided by N), summed directly: the reference of the
/// FFT path's tests.
#[cfg(test)]
pub(crate) fn autocov(c: &[f64], mean: f64, t: usize) -> f64 {
    let n = c.len();
    (0..n - t)
        .map(|i| (c[i] - mean) * (c[i + t] - mean))
        .sum::<f64>()
        / n as f64
}

/// Autocovariances of one chain at every lag t < N,
///   acov(t) = 1/N sum_{i < N - t} (c_i - mean) (c_{i+t} - mean),
/// as the inverse FFT of |FFT(c - mean)|^2 (Wiener-Khinchin), the chain zero-padded to a power
/// of two of at least 2N so that the circular correlation is the linear one. O(N log N) for
/// all lags; a Metropolis chain's sum runs to hundreds of lags, which summed lag by lag cost
/// O(N) each (5.7% of the main job's CPU time, `perf`, 2026-11-28).
pub(crate) fn autocovariances(c: &[f64], mean: f64, planner: &mut FftPlanner<f64>) -> Vec<f64> {
    let n = c.len();
    let len = (2 * n).next_power_of_two();
    let mut buf: Vec<Complex<f64>> = c
        .iter()
        .map(|x| Complex::new(x - mean, 0.0))
        .chain(std::iter::repeat(Complex::new(0.0, 0.0)))
        .take(len)
        .collect();
    planner.plan_fft_forward(len).process(&mut buf);
    for z in buf.iter_mut() {
        *z = Complex::new(z.norm_sqr(), 0.0);
    }
    planner.plan_fft_inverse(len).process(&mut buf);
    // rustfft's transforms are unnormalised: forward then inverse multiplies by len.
    let scale = 1.0 / (len as f64 * n as f64);
    buf[..n].iter().map(|z| z.re * scale).collect()
}

/// ESS of the chains as given (no splitting or normalisation):
/// rho_t = 1 - (W - mean_m acov_m(t)) / var+, tau = -1 + 2 sum_k (rho_2k + rho_2k+1) over the
/// initial positive and monotone sequence of pair sums, ESS = M N / tau (tau at least
/// 1 / log10(M N)). The autocovariances of every lag come from one FFT per chain
/// (`autocovariances`).
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
    let mut planner = FftPlanner::new();
    let acov: Vec<Vec<f64>> = chains
        .iter()
        .zip(&stats)
        .map(|(c, s)| autocovariances(c, s.0, &mut planner))
        .collect();
    let rho = |t: usize| -> f64 {
        let mean_acov = acov.iter().map(|a| a[t]).sum::<f64>() / m as f64;
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
///
/// ```
/// use hpge_inference::diagnostics::ess_bulk;
/// // Independent draws (a Weyl sequence, well mixed) give about their number; a chain that
/// // repeats each value 10 times gives about a tenth.
/// let iid: Vec<Vec<f64>> = (0..4)
///     .map(|c| (0..1000).map(|i| ((i * 4 + c) as f64 * 0.618_033_988_75).fract()).collect())
///     .collect();
/// assert!(ess_bulk(&iid) > 2000.0);
/// let sticky: Vec<Vec<f64>> = iid
///     .iter()
///     .map(|ch| ch.iter().step_by(10).flat_map(|&x| [x; 10]).collect())
///     .collect();
/// assert!(ess_bulk(&sticky) < 0.2 * ess_bulk(&iid));
/// ```
pub fn ess_bulk(chains: &[Vec<f64>]) -> f64 {
    ess(&rank_normalise(&split_chains(chains)))
}

/// Tail ESS: the smaller [`ess`] of the split chains' indicators I(x <= q_0.05) and
/// I(x <= q_0.95), q the pooled quantiles.
pub fn ess_tail(chains: &[Vec<f64>]) -> f64 {
    ess_tail_of(&split_chains(chains))
}

/// [`ess_tail`] of chains already split.
pub(crate) fn ess_tail_of(split: &[Vec<f64>]) -> f64 {
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
