//! The sampling loop both samplers share: tune (sampler-specific), then draw batches on every
//! chain in parallel until the diagnostics reach their targets or a budget runs out.

use std::time::Instant;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::{LogDensity, metropolis, nuts};
use crate::{Diagnostics, Error, Result};

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
    /// Stop sampling (not tuning) after this many seconds.
    pub max_seconds: f64,
}

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
            chains: 4,
            seed: 0,
            rhat_max: 1.01,
            ess_min: 1000.0,
            cycle_draws: 1000,
            max_cycles: 40,
            acceptance: [0.15, 0.35],
            burnin_rhat: 1.1,
            mode_starts: 24,
            nuts_tune: 600,
            nuts_max_depth: 8,
            batch_draws: if metropolis { 2000 } else { 200 },
            thin: if metropolis { 4 } else { 1 },
            max_draws: 100_000,
            max_seconds: 600.0,
        }
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
pub enum StopReason {
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
    /// Acceptance over the sampling phase (NUTS: mean acceptance statistic).
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
    pub stop: StopReason,
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
        self.stop == StopReason::Converged
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

/// One draw of a chain engine.
pub(super) struct Draw {
    pub z: Vec<f64>,
    pub ln_density: f64,
    /// Accepted (Metropolis) or acceptance statistic (NUTS).
    pub accept: f64,
    pub divergent: bool,
}

/// A tuned chain that can draw.
pub(super) trait Engine: Send {
    fn draw(&mut self) -> Result<Draw>;
    fn evaluations(&self) -> u64;
    fn scale(&self) -> f64;
}

/// The result of a tuning phase.
pub(super) struct Tuned<'a> {
    pub engines: Vec<Box<dyn Engine + 'a>>,
    /// Modes the search found (empty when it did not run).
    pub modes: Vec<LocalMode>,
    pub tuned: bool,
    pub cycles: usize,
}

/// Samples `target` with `settings`; `progress` sees a [`Status`] after every cycle and batch.
pub fn sample(
    target: &dyn LogDensity,
    settings: &SampleSettings,
    progress: &(dyn Fn(&Status) + Sync),
) -> Result<Samples> {
    settings.validate()?;
    let start = Instant::now();
    match settings.sampler {
        SamplerKind::Metropolis => {
            let tuned = metropolis::tune(target, settings, start, progress)?;
            finish(target, settings, start, progress, tuned)
        }
        SamplerKind::Nuts => {
            if !target.has_gradient() {
                return Err(Error::Argument {
                    name: "--sampler".into(),
                    message:
                        "nuts needs the model's gradient; this model has none (use metropolis)"
                            .into(),
                });
            }
            nuts::run(target, settings, start, progress)
        }
    }
}

/// The sampling phase after tuning, common to both samplers.
pub(super) fn finish(
    target: &dyn LogDensity,
    settings: &SampleSettings,
    start: Instant,
    progress: &(dyn Fn(&Status) + Sync),
    tuned: Tuned<'_>,
) -> Result<Samples> {
    let tuning_seconds = start.elapsed().as_secs_f64();
    let Tuned {
        mut engines,
        tuned,
        cycles,
        modes,
    } = tuned;
    let d = target.dim();
    let m = engines.len();
    let mut chains: Vec<ChainDraws> = (0..m)
        .map(|_| ChainDraws {
            theta: Vec::new(),
            ln_posterior: Vec::new(),
            acceptance: 0.0,
            divergences: 0,
            evaluations: 0,
            scale: 0.0,
        })
        .collect();
    let mut accept_sum = vec![0.0; m];
    let mut steps = 0usize;
    let batch = settings.batch_draws;
    let (stop, diagnostics) = loop {
        let results: Vec<Result<(Vec<Draw>, f64)>> = engines
            .par_iter_mut()
            .map(|e| {
                let mut kept = Vec::with_capacity(batch);
                let mut acc = 0.0;
                for _ in 0..batch {
                    for _ in 0..settings.thin - 1 {
                        acc += e.draw()?.accept;
                    }
                    let dr = e.draw()?;
                    acc += dr.accept;
                    kept.push(dr);
                }
                Ok((kept, acc))
            })
            .collect();
        steps += batch * settings.thin;
        let mut batch_accept = 0.0;
        for (c, r) in results.into_iter().enumerate() {
            let (kept, acc) = r?;
            accept_sum[c] += acc;
            batch_accept += acc / (batch * settings.thin) as f64 / m as f64;
            for dr in kept {
                let (theta, lp) = target.output(&dr.z, dr.ln_density);
                chains[c].theta.push(theta);
                chains[c].ln_posterior.push(lp);
                chains[c].divergences += usize::from(dr.divergent);
            }
        }
        let diagnostics = diagnose(&chains, d);
        let rhat = diagnostics.iter().map(|x| x.rhat).fold(0.0, f64::max);
        let ess = diagnostics
            .iter()
            .map(|x| x.ess_bulk.min(x.ess_tail))
            .fold(f64::INFINITY, f64::min);
        let seconds = start.elapsed().as_secs_f64();
        let draws = chains[0].theta.len();
        progress(&Status {
            phase: Phase::Sampling,
            cycle: cycles,
            draws,
            rhat_max: rhat,
            ess_min: ess,
            acceptance: batch_accept,
            seconds,
        });
        if diagnostics
            .iter()
            .all(|x| x.converged(settings.rhat_max, settings.ess_min))
        {
            break (StopReason::Converged, diagnostics);
        }
        if draws + batch > settings.max_draws {
            break (StopReason::MaxDraws, diagnostics);
        }
        if seconds - tuning_seconds > settings.max_seconds {
            break (StopReason::MaxSeconds, diagnostics);
        }
    };
    for (c, e) in engines.iter().enumerate() {
        chains[c].acceptance = accept_sum[c] / steps as f64;
        chains[c].evaluations = e.evaluations();
        chains[c].scale = e.scale();
    }
    Ok(Samples {
        names: target.names(),
        settings: *settings,
        chains,
        diagnostics,
        stop,
        tuned,
        cycles,
        local_modes: modes,
        tuning_seconds,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Diagnostics per parameter of the kept draws.
fn diagnose(chains: &[ChainDraws], d: usize) -> Vec<Diagnostics> {
    (0..d)
        .into_par_iter()
        .map(|j| {
            let per: Vec<Vec<f64>> = chains
                .iter()
                .map(|c| c.theta.iter().map(|t| t[j]).collect())
                .collect();
            Diagnostics::of(&per)
        })
        .collect()
}
