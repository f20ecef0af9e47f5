//! The potential scale reduction R-hat (Gelman and Rubin 1992; split and rank-normalised form of
//! Vehtari et al. 2021).

use super::rank::{fold, rank_normalise, split_chains};

/// Mean and unbiased variance of one chain.
pub(super) fn mean_var(c: &[f64]) -> (f64, f64) {
    let n = c.len() as f64;
    let mean = c.iter().sum::<f64>() / n;
    let var = c.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var)
}

/// R-hat of the chains as given: with W the mean within-chain variance and B/N the variance of
/// the chain means, var+ = (N-1)/N W + B/N and R-hat = sqrt(var+ / W). NaN for fewer than two
/// chains or two draws.
pub fn basic_rhat(chains: &[Vec<f64>]) -> f64 {
    let m = chains.len();
    let n = chains.iter().map(Vec::len).min().unwrap_or(0);
    if m < 2 || n < 2 {
        return f64::NAN;
    }
    let stats: Vec<(f64, f64)> = chains.iter().map(|c| mean_var(&c[..n])).collect();
    let w = stats.iter().map(|s| s.1).sum::<f64>() / m as f64;
    let grand = stats.iter().map(|s| s.0).sum::<f64>() / m as f64;
    let b_over_n = stats.iter().map(|s| (s.0 - grand).powi(2)).sum::<f64>() / (m as f64 - 1.0);
    let nf = n as f64;
    let var_plus = (nf - 1.0) / nf * w + b_over_n;
    if w == 0.0 {
        return if b_over_n == 0.0 { 1.0 } else { f64::INFINITY };
    }
    (var_plus / w).sqrt()
}

/// Split R-hat: `basic_rhat` of the split chains.
///
/// ```
/// use hpge_inference::diagnostics::split_rhat;
/// // Two chains that sample the same sequence agree (R-hat near 1); two stuck at different
/// // values do not.
/// let wave: Vec<f64> = (0..400).map(|i| (i as f64 * 0.7).sin()).collect();
/// let shifted: Vec<f64> = wave.iter().rev().cloned().collect();
/// assert!((split_rhat(&[wave.clone(), shifted]) - 1.0).abs() < 0.01);
/// let apart: Vec<f64> = wave.iter().map(|x| x + 5.0).collect();
/// assert!(split_rhat(&[wave, apart]) > 2.0);
/// ```
pub fn split_rhat(chains: &[Vec<f64>]) -> f64 {
    basic_rhat(&split_chains(chains))
}

/// The rank-normalised split R-hat of Vehtari et al. (2021), eq. 4.3: the larger of the split
/// R-hat of the rank-normalised draws (location) and of the rank-normalised folded draws (scale).
pub fn rank_rhat(chains: &[Vec<f64>]) -> f64 {
    let split = split_chains(chains);
    rank_rhat_of(&split, &rank_normalise(&split))
}

/// [`rank_rhat`] from the split chains and their rank-normalised draws (computed once for
/// R-hat and the bulk ESS by [`super::Diagnostics::of`]).
pub(crate) fn rank_rhat_of(split: &[Vec<f64>], normalised: &[Vec<f64>]) -> f64 {
    let bulk = basic_rhat(normalised);
    let tail = basic_rhat(&rank_normalise(&fold(split)));
    bulk.max(tail)
}
