//! What a finished run hands back: the kept draws per chain, their diagnostics, why the run
//! stopped, and the local modes found before sampling.

use serde::{Deserialize, Serialize};

use super::settings::SampleSettings;
use crate::diagnostics::Diagnostics;

/// A local maximum of the posterior found before sampling.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LocalMode {
    /// Laplace weight: p(z_k) sqrt(det Sigma_k), normalised over the modes found.
    pub weight: f64,
    /// Location (parameters).
    pub theta: Vec<f64>,
    /// ln p(theta | data) there (up to the evidence).
    pub ln_posterior: f64,
}

/// Why sampling stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SamplerStop {
    /// R-hat and ESS reached their targets.
    Converged,
    /// `max_draws` reached first.
    MaxDraws,
    /// `max_seconds` reached first.
    MaxSeconds,
}

/// One chain's kept draws.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChainDraws {
    /// theta per kept draw.
    pub theta: Vec<Vec<f64>>,
    /// ln p(theta | data) per kept draw (up to a constant).
    pub ln_posterior: Vec<f64>,
    /// Acceptance over the sampling phase (NUTS: the fraction of non-divergent transitions;
    /// nuts-rs's draw does not return its mean acceptance statistic).
    pub acceptance: f64,
    /// Divergent transitions (NUTS) in the sampling phase.
    pub divergences: usize,
    /// Log-density evaluations (gradients for NUTS), tuning included.
    pub evaluations: u64,
    /// Final proposal scale (Metropolis) or step size (NUTS).
    pub scale: f64,
}

/// A finished run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Samples {
    /// Parameter names.
    pub names: Vec<String>,
    /// The settings used.
    pub settings: SampleSettings,
    /// The chains.
    pub chains: Vec<ChainDraws>,
    /// Per parameter: R-hat, bulk and tail ESS of the kept draws.
    pub diagnostics: Vec<Diagnostics>,
    /// Why it stopped.
    pub stop: SamplerStop,
    /// Whether the tuning phase met its criterion (Metropolis: acceptance in the window and
    /// R-hat <= burnin_rhat within max_cycles).
    pub tuned: bool,
    /// Tuning cycles run (Metropolis), 0 for NUTS.
    pub cycles: usize,
    /// The local maxima the pre-tuning search found, with their Laplace weights (Metropolis;
    /// empty when it did not run).
    pub local_modes: Vec<LocalMode>,
    /// Wall time of the tuning, s.
    pub tuning_seconds: f64,
    /// Wall time in all, s.
    pub seconds: f64,
}

impl Samples {
    /// R-hat and ESS targets reached.
    pub fn converged(&self) -> bool {
        self.stop == SamplerStop::Converged
    }

    /// Draws of parameter j per chain.
    pub fn parameter(&self, j: usize) -> Vec<Vec<f64>> {
        self.chains
            .iter()
            .map(|c| c.theta.iter().map(|t| t[j]).collect())
            .collect()
    }

    /// All kept draws, chain after chain.
    pub fn all(&self) -> Vec<&[f64]> {
        self.chains
            .iter()
            .flat_map(|c| c.theta.iter().map(Vec::as_slice))
            .collect()
    }

    /// The kept draw with the highest posterior density (and that density).
    pub fn best(&self) -> (Vec<f64>, f64) {
        let mut best = (Vec::new(), f64::NEG_INFINITY);
        for c in &self.chains {
            for (t, &l) in c.theta.iter().zip(&c.ln_posterior) {
                if l > best.1 {
                    best = (t.clone(), l);
                }
            }
        }
        best
    }

    /// Total evaluations of the log density.
    pub fn evaluations(&self) -> u64 {
        self.chains.iter().map(|c| c.evaluations).sum()
    }

    /// The smallest bulk ESS over the parameters per second of the whole run.
    pub fn ess_per_second(&self) -> f64 {
        let ess = self
            .diagnostics
            .iter()
            .map(|d| d.ess_bulk)
            .fold(f64::INFINITY, f64::min);
        ess / self.seconds
    }
}
