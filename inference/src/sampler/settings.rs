//! What a sampling run is asked to do: the sampler, chains, seed, convergence targets and
//! budgets.

use serde::{Deserialize, Serialize};

use crate::{Error, Result};

/// Which sampler (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum SamplerKind {
    /// Adaptive Metropolis (BAT.jl's default): multivariate-normal proposals whose covariance
    /// and scale are tuned in cycles.
    #[default]
    Metropolis,
    /// The No-U-Turn sampler (nuts-rs) with the model's gradient.
    Nuts,
}

impl SamplerKind {
    /// Parses `metropolis` (or `mh`) or `nuts`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "metropolis" | "mh" | "am" => Some(SamplerKind::Metropolis),
            "nuts" => Some(SamplerKind::Nuts),
            _ => None,
        }
    }

    /// The name.
    pub fn as_str(&self) -> &'static str {
        match self {
            SamplerKind::Metropolis => "metropolis",
            SamplerKind::Nuts => "nuts",
        }
    }
}

/// Chains of a run: 4, as in the paper's BAT.jl fits (at least 2 are needed for R-hat).
pub const DEFAULT_CHAINS: usize = 4;
/// Seed of a run that is not given one.
pub const DEFAULT_SEED: u64 = 0;
/// Target R-hat (rank-normalised, split) of a whole run: 1.01, Vehtari et al. (2021).
pub const DEFAULT_RHAT_MAX: f64 = 1.01;
/// Target bulk and tail ESS of every parameter: 1000, Vehtari et al. (2021).
pub const DEFAULT_ESS_MIN: f64 = 1000.0;
/// Nelder-Mead starts of the mode search before tuning (0: no search).
pub const DEFAULT_MODE_STARTS: usize = 24;
/// Sampling budget (s) of a run that nobody limits otherwise (library callers such as the
/// benches): 10 minutes, generous, since a run normally stops at its R-hat and ESS targets first.
/// The command line's fits stop earlier ([`crate::fit::FIT_MAX_SECONDS`]), and so do the many
/// fits of the validation studies (their own budgets).
pub const DEFAULT_MAX_SECONDS: f64 = 600.0;

/// Sampling settings. Defaults: 4 chains (the paper's BAT.jl run), BAT.jl's acceptance window
/// [0.15, 0.35] and burn-in criterion R-hat <= 1.1, then sampling on to the stricter R-hat <= 1.01
/// and ESS >= 1000 of Vehtari et al. (2021).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SampleSettings {
    /// The sampler.
    pub sampler: SamplerKind,
    /// Chains (>= 2), run in parallel.
    pub chains: usize,
    /// Seed of everything random.
    pub seed: u64,
    /// Target R-hat for the whole run.
    pub rhat_max: f64,
    /// Target bulk and tail ESS (each parameter).
    pub ess_min: f64,
    /// Metropolis: draws per chain per tuning cycle.
    pub cycle_draws: usize,
    /// Metropolis: most tuning cycles.
    pub max_cycles: usize,
    /// Metropolis: the acceptance window of the tuning (BAT.jl: [0.15, 0.35]).
    pub acceptance: [f64; 2],
    /// Metropolis: burn-in ends when R-hat over the last two cycles is below this (BAT.jl: 1.1).
    pub burnin_rhat: f64,
    /// Nelder-Mead starts of the mode search before tuning (0: no search; chains then start at
    /// dispersed prior draws). Metropolis starts chains in the modes found and jumps between
    /// them; NUTS starts chains in the modes of weight >= 1%.
    pub mode_starts: usize,
    /// NUTS: tuning draws per chain.
    pub nuts_tune: usize,
    /// NUTS: maximum tree depth.
    pub nuts_max_depth: u64,
    /// Draws per chain between convergence checks.
    pub batch_draws: usize,
    /// Keep every `thin`-th draw.
    pub thin: usize,
    /// Most kept draws per chain.
    pub max_draws: usize,
    /// The run's time budget (s): the mode search, the tuning and the sampling stop when it is
    /// spent (the sampling keeps [`MIN_DRAWS_AT_BUDGET`] draws per chain at least).
    pub max_seconds: f64,
}

/// Draws per chain the sampling phase keeps even when the time budget ran out before (so that
/// a run cut short still has draws to summarise, however slow one evaluation is).
pub const MIN_DRAWS_AT_BUDGET: usize = 20;

impl Default for SampleSettings {
    fn default() -> Self {
        Self::for_sampler(SamplerKind::Metropolis)
    }
}

impl SampleSettings {
    /// The defaults of one sampler.
    pub fn for_sampler(sampler: SamplerKind) -> Self {
        let metropolis = sampler == SamplerKind::Metropolis;
        Self {
            sampler,
            chains: DEFAULT_CHAINS,
            seed: DEFAULT_SEED,
            rhat_max: DEFAULT_RHAT_MAX,
            ess_min: DEFAULT_ESS_MIN,
            cycle_draws: 1000,
            max_cycles: 40,
            acceptance: [0.15, 0.35],
            burnin_rhat: 1.1,
            mode_starts: DEFAULT_MODE_STARTS,
            nuts_tune: 600,
            nuts_max_depth: 8,
            batch_draws: if metropolis { 2000 } else { 200 },
            thin: if metropolis { 4 } else { 1 },
            max_draws: 100_000,
            max_seconds: DEFAULT_MAX_SECONDS,
        }
    }

    /// When a run started at `start` has spent its time budget (`max_seconds`).
    pub fn deadline(&self, start: std::time::Instant) -> std::time::Instant {
        std::time::Duration::try_from_secs_f64(self.max_seconds)
            .ok()
            .and_then(|d| start.checked_add(d))
            .or_else(|| start.checked_add(std::time::Duration::from_secs(1 << 32)))
            .unwrap_or(start)
    }

    /// Checks the values.
    pub fn validate(&self) -> Result<()> {
        let bad = |name: &str, message: String| {
            Err(Error::Argument {
                name: name.into(),
                message,
            })
        };
        if self.chains < 2 {
            return bad(
                "chains",
                format!("need at least 2 chains for R-hat, got {}", self.chains),
            );
        }
        if !(self.ess_min.is_finite() && self.ess_min > 0.0) {
            return bad(
                "ess_min",
                format!("the ESS target must be positive, got {}", self.ess_min),
            );
        }
        if self.max_seconds.is_nan() || self.max_seconds <= 0.0 {
            return bad(
                "max_seconds",
                format!("the time budget must be positive, got {}", self.max_seconds),
            );
        }
        if !(self.rhat_max > 1.0 && self.burnin_rhat > 1.0) {
            return bad("rhat_max", "R-hat targets must exceed 1".into());
        }
        if !(self.acceptance[0] > 0.0
            && self.acceptance[0] < self.acceptance[1]
            && self.acceptance[1] < 1.0)
        {
            return bad(
                "acceptance",
                format!("need 0 < lo < hi < 1, got {:?}", self.acceptance),
            );
        }
        if self.cycle_draws < 20 || self.batch_draws < 10 || self.thin == 0 || self.max_draws < 10 {
            return bad(
                "draws",
                "cycle_draws >= 20, batch_draws >= 10, thin >= 1, max_draws >= 10".into(),
            );
        }
        Ok(())
    }
}
