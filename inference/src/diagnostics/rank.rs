//! Split chains, rank normalisation and folding (Vehtari et al. 2021, section 4).

use hpge_foundation::normal_quantile;
use hpge_foundation::quantile;

/// Each chain cut into its first and second half (an odd draw in the middle is dropped): 2M
/// chains of floor(N/2) draws, so that a trend within a chain shows up as between-chain
/// disagreement.
pub fn split_chains(chains: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let mut out = Vec::with_capacity(2 * chains.len());
    for c in chains {
        let half = c.len() / 2;
        out.push(c[..half].to_vec());
        out.push(c[c.len() - half..].to_vec());
    }
    out
}

/// Rank normalisation: over all draws pooled (S of them), z = Phi^-1((r - 3/8) / (S + 1/4)) with
/// r the rank (1-based; ties get their average rank). The chain structure is kept.
pub fn rank_normalise(chains: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let mut all: Vec<(f64, usize, usize)> = chains
        .iter()
        .enumerate()
        .flat_map(|(m, c)| c.iter().enumerate().map(move |(i, &x)| (x, m, i)))
        .collect();
    all.sort_by(|a, b| a.0.total_cmp(&b.0));
    let s = all.len() as f64;
    let mut out: Vec<Vec<f64>> = chains.iter().map(|c| vec![0.0; c.len()]).collect();
    let mut k = 0;
    while k < all.len() {
        let mut j = k;
        while j + 1 < all.len() && all[j + 1].0 == all[k].0 {
            j += 1;
        }
        let rank = (k + j) as f64 / 2.0 + 1.0;
        let z = normal_quantile((rank - 0.375) / (s + 0.25));
        for &(_, m, i) in &all[k..=j] {
            out[m][i] = z;
        }
        k = j + 1;
    }
    out
}

/// Folded draws |x - median| (median over all chains): R-hat of these detects chains that agree
/// in location but not in scale.
pub fn fold(chains: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let mut all: Vec<f64> = chains.iter().flatten().copied().collect();
    all.sort_by(f64::total_cmp);
    let median = if all.is_empty() {
        0.0
    } else {
        quantile(&all, 0.5)
    };
    chains
        .iter()
        .map(|c| c.iter().map(|x| (x - median).abs()).collect())
        .collect()
}
