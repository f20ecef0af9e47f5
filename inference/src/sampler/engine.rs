//! The sampling phase both samplers share: tuned chain engines draw batches in parallel until
//! the diagnostics reach their targets or a budget runs out.

use std::time::Instant;

use rayon::prelude::*;

use super::samples::{ChainDraws, LocalMode, SamplerStop, Samples};
use super::settings::{MIN_DRAWS_AT_BUDGET, SampleSettings};
use super::status::{Phase, Status};
use super::target::LogDensity;
use crate::Result;
use crate::diagnostics::Diagnostics;

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
    // The budget covers the whole run (mode search and tuning included, issue 66): a batch
    // ends early when it is spent, once every chain has its minimum of draws.
    let deadline = settings.deadline(start);
    let (stop, diagnostics) = loop {
        let have = chains[0].theta.len();
        let results: Vec<Result<(Vec<Draw>, f64)>> = engines
            .par_iter_mut()
            .map(|e| {
                let mut kept = Vec::with_capacity(batch);
                let mut acc = 0.0;
                for _ in 0..batch {
                    if have + kept.len() >= MIN_DRAWS_AT_BUDGET && Instant::now() >= deadline {
                        break;
                    }
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
        let mut results = results.into_iter().collect::<Result<Vec<_>>>()?;
        // Chains of equal length: the draws beyond the shortest chain's are dropped.
        let taken = results.iter().map(|r| r.0.len()).min().unwrap_or(0);
        for r in &mut results {
            r.0.truncate(taken);
        }
        steps += taken * settings.thin;
        let mut batch_accept = 0.0;
        for (c, (kept, acc)) in results.into_iter().enumerate() {
            accept_sum[c] += acc;
            batch_accept += acc / (taken.max(1) * settings.thin) as f64 / m as f64;
            for dr in kept {
                let (theta, lp) = target.output(&dr.z, dr.ln_density);
                chains[c].theta.push(theta);
                chains[c].ln_posterior.push(lp);
                chains[c].divergences += usize::from(dr.divergent);
            }
        }
        let diagnostics = diagnose(&chains, d);
        let (rhat, ess) = Diagnostics::worst(&diagnostics);
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
            break (SamplerStop::Converged, diagnostics);
        }
        if draws + batch > settings.max_draws {
            break (SamplerStop::MaxDraws, diagnostics);
        }
        if Instant::now() >= deadline {
            break (SamplerStop::MaxSeconds, diagnostics);
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
