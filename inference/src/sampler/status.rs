//! Progress of a run, as a progress line sees it.

use serde::Serialize;

/// Where a run is.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Phase {
    /// Tuning cycle n (Metropolis) or tuning draws (NUTS).
    Tuning,
    /// Drawing the kept sample.
    Sampling,
}

/// Progress of a run (for a progress line).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Status {
    /// The phase.
    pub phase: Phase,
    /// Tuning cycle (Metropolis) or 0.
    pub cycle: usize,
    /// Kept draws per chain so far.
    pub draws: usize,
    /// Largest R-hat over the parameters (NaN before the first check).
    pub rhat_max: f64,
    /// Smallest bulk or tail ESS.
    pub ess_min: f64,
    /// Mean acceptance over the chains in the last batch (NUTS: mean acceptance statistic).
    pub acceptance: f64,
    /// Seconds since the start.
    pub seconds: f64,
}
