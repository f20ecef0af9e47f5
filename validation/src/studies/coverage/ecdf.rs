//! The ECDF of the truths' ranks against the uniform one, with simultaneous bands (Säilynoja,
//! Bürkner and Vehtari, "Graphical test for discrete uniformity and its applications in
//! goodness-of-fit evaluation and multiple sample comparison", Statistics and Computing 32, 32
//! (2022)): a calibrated fit's ECDF stays inside the band at every evaluation point at once
//! with the band's probability, so that a figure tests something where a rank histogram with a
//! per-bin band does not.
//!
//! With n truths ranked among L draws, a rank is uniform on 0..=L under calibration. At each
//! threshold j = 1..=L the count c_j = #{rank < j} is Binomial(n, z_j) with z_j = j / (L + 1),
//! exactly (no continuity correction: the ranks' own lattice is used). A sample's pointwise
//! two-sided tail probability at j is p_j = min(1, 2 min(P(C <= c_j), P(C >= c_j))); the band
//! of probability 1 - alpha holds at every j the counts whose p_j >= gamma, where gamma is the
//! alpha-quantile of min_j p_j over samples of uniform ranks (the paper's simulation method,
//! section 2.2; 10 000 samples from a fixed seed).

use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use statrs::distribution::{Binomial, DiscreteCDF};

/// Samples of uniform ranks behind a band's gamma.
pub const BAND_SAMPLES: usize = 10_000;
/// The seed of those samples (the figures are reproducible).
pub const BAND_SEED: u64 = 20_220_302;

/// A simultaneous band of the ECDF difference F(z_j) - z_j of n uniform ranks on 0..=L.
#[derive(Debug, Clone, PartialEq)]
pub struct EcdfBand {
    /// Its probability (e.g. 0.99).
    pub mass: f64,
    /// The pointwise level gamma that gives it simultaneously.
    pub gamma: f64,
    /// The evaluation points z_j = j / (L + 1), j = 1..=L.
    pub z: Vec<f64>,
    /// The band's lower edge of F - z at each z.
    pub lower: Vec<f64>,
    /// Its upper edge.
    pub upper: Vec<f64>,
}

/// P(C <= c) and P(C >= c) of C ~ Binomial(n, z) for c = 0..=n, per threshold j = 1..=L.
struct Tails {
    below: Vec<Vec<f64>>,
    above: Vec<Vec<f64>>,
}

impl Tails {
    fn new(n: usize, l: usize) -> Self {
        let (mut below, mut above) = (Vec::with_capacity(l), Vec::with_capacity(l));
        for j in 1..=l {
            let z = j as f64 / (l + 1) as f64;
            let b = Binomial::new(z, n as u64).expect("0 < z < 1");
            let cdf: Vec<f64> = (0..=n as u64).map(|c| b.cdf(c)).collect();
            let sf: Vec<f64> = (0..=n)
                .map(|c| if c == 0 { 1.0 } else { 1.0 - cdf[c - 1] })
                .collect();
            below.push(cdf);
            above.push(sf);
        }
        Self { below, above }
    }

    /// p_j of count c at threshold index i (j = i + 1).
    fn p(&self, i: usize, c: usize) -> f64 {
        (2.0 * self.below[i][c].min(self.above[i][c])).min(1.0)
    }
}

/// The counts c_j = #{rank < j}, j = 1..=L, of `ranks` on 0..=l.
pub fn counts_below(ranks: &[usize], l: usize) -> Vec<usize> {
    let mut hist = vec![0usize; l + 1];
    for &r in ranks {
        hist[r.min(l)] += 1;
    }
    let mut out = Vec::with_capacity(l);
    let mut acc = 0;
    for h in hist.iter().take(l) {
        acc += h;
        out.push(acc);
    }
    out
}

/// The simultaneous band of probability `mass` for n ranks on 0..=l (n, l >= 1).
pub fn ecdf_band(n: usize, l: usize, mass: f64) -> EcdfBand {
    let tails = Tails::new(n, l);
    let mut rng = StdRng::seed_from_u64(BAND_SEED ^ ((n as u64) << 32) ^ l as u64);
    let mut minima: Vec<f64> = (0..BAND_SAMPLES)
        .map(|_| {
            let ranks: Vec<usize> = (0..n)
                .map(|_| ((rng.random::<f64>() * (l + 1) as f64) as usize).min(l))
                .collect();
            counts_below(&ranks, l)
                .iter()
                .enumerate()
                .map(|(i, &c)| tails.p(i, c))
                .fold(1.0, f64::min)
        })
        .collect();
    minima.sort_by(f64::total_cmp);
    let gamma = hpge_foundation::quantile(&minima, 1.0 - mass);
    let z: Vec<f64> = (1..=l).map(|j| j as f64 / (l + 1) as f64).collect();
    let (mut lower, mut upper) = (Vec::with_capacity(l), Vec::with_capacity(l));
    for (i, &zj) in z.iter().enumerate() {
        let inside: Vec<usize> = (0..=n).filter(|&c| tails.p(i, c) >= gamma).collect();
        let (lo, hi) = (
            inside.first().copied().unwrap_or(0),
            inside.last().copied().unwrap_or(n),
        );
        lower.push(lo as f64 / n as f64 - zj);
        upper.push(hi as f64 / n as f64 - zj);
    }
    EcdfBand {
        mass,
        gamma,
        z,
        lower,
        upper,
    }
}

/// The ECDF difference F(z_j) - z_j of `ranks` on 0..=l at the band's points.
pub fn ecdf_difference(ranks: &[usize], l: usize) -> Vec<f64> {
    let n = ranks.len().max(1) as f64;
    counts_below(ranks, l)
        .iter()
        .enumerate()
        .map(|(i, &c)| c as f64 / n - (i + 1) as f64 / (l + 1) as f64)
        .collect()
}

/// Whether `ranks`' ECDF difference stays inside `band` at every point.
pub fn inside_band(ranks: &[usize], l: usize, band: &EcdfBand) -> bool {
    ecdf_difference(ranks, l)
        .iter()
        .zip(band.lower.iter().zip(&band.upper))
        .all(|(d, (lo, hi))| *d >= lo - 1e-12 && *d <= hi + 1e-12)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_below_each_threshold() {
        assert_eq!(counts_below(&[0, 0, 2, 3], 3), [2, 2, 3]);
        let d = ecdf_difference(&[0, 1, 2, 3], 3);
        assert!(d.iter().all(|x| x.abs() < 1e-15), "{d:?}");
    }

    #[test]
    fn the_band_holds_its_probability_simultaneously() {
        // Fresh uniform samples (another seed than the band's) leave the 95% band in about 5%
        // of cases: simultaneous, not pointwise (a pointwise 95% band over 49 points would be
        // left by most samples).
        let (n, l) = (100, 49);
        let band = ecdf_band(n, l, 0.95);
        assert!(band.gamma < 0.05 && band.gamma > 1e-4, "{}", band.gamma);
        let mut rng = StdRng::seed_from_u64(7);
        let trials = 2000;
        let outside = (0..trials)
            .filter(|_| {
                let ranks: Vec<usize> = (0..n)
                    .map(|_| ((rng.random::<f64>() * (l + 1) as f64) as usize).min(l))
                    .collect();
                !inside_band(&ranks, l, &band)
            })
            .count() as f64
            / trials as f64;
        // Binomial sd of a 5% rate over 2000 trials is 0.5%; the discreteness of the counts
        // makes the band a little conservative.
        assert!((0.025..=0.065).contains(&outside), "{outside}");
        for (lo, hi) in band.lower.iter().zip(&band.upper) {
            assert!(lo < &0.0 && hi > &0.0);
        }
    }

    #[test]
    fn ranks_of_an_overconfident_fit_leave_the_band() {
        // Truths at the ends of too narrow posteriors: ranks 0 and L only.
        let l = 99;
        let ranks: Vec<usize> = (0..200).map(|i| if i % 2 == 0 { 0 } else { l }).collect();
        assert!(!inside_band(&ranks, l, &ecdf_band(200, l, 0.99)));
    }
}
