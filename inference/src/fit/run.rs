//! A fit from start to summary.

use std::collections::BTreeMap;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::predictive::{Predictive, predictive, thin_indices};
use super::summary::{FitSummary, LEVELS, ModeSummary, ParameterSummary};
use crate::Result;
use crate::numerics::nelder_mead_until;
use crate::posterior::{NoiseSettings, Posterior};
use crate::rejection::Latch;
use crate::sampler::{LogDensity, SampleSettings, Samples, Status, sample};
use crate::summary::{bound_flags, find_modes, marginal_mode, smallest_intervals};

/// Settings of a fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitSettings {
    /// Sampling.
    pub sample: SampleSettings,
    /// The likelihood's noise model.
    pub noise: NoiseSettings,
    /// Histogram bins over each parameter's support (marginal modes, smallest intervals; BAT.jl
    /// plots use 200, 100 suffices for intervals at 1e4+ draws).
    pub bins: usize,
    /// Draws for the posterior predictive.
    pub predictive_draws: usize,
    /// Most modes to look for (Gaussian mixtures with 1..=max_modes components).
    pub max_modes: usize,
    /// Draws the mixture is fitted to (thinned).
    pub mode_draws: usize,
}

impl Default for FitSettings {
    fn default() -> Self {
        Self {
            sample: SampleSettings::default(),
            noise: NoiseSettings::default(),
            bins: 100,
            predictive_draws: 1000,
            max_modes: 3,
            mode_draws: 4000,
        }
    }
}

/// A finished fit.
#[derive(Debug, Clone)]
pub struct Fit {
    /// The draws.
    pub samples: Samples,
    /// The summary (`summary.json`).
    pub summary: FitSummary,
    /// The posterior predictive.
    pub predictive: Predictive,
    /// theta at the global mode.
    pub mode: Vec<f64>,
}

/// The histogram range of a marginal: the draws' [min, max] (inside the support). Binning the
/// whole support instead makes a posterior narrower than a bin look one bin wide, and its smallest
/// intervals over-cover (seen in the B_Z coverage study: y_top's 68.3% intervals covered 82.5%).
pub fn draw_range(draws: &[f64], support: [f64; 2]) -> [f64; 2] {
    let lo = draws
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min)
        .max(support[0]);
    let hi = draws
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max)
        .min(support[1]);
    if lo < hi { [lo, hi] } else { support }
}

/// Joins neighbouring intervals separated by at most `gap` (histogram noise splits a smooth
/// marginal's smallest interval at single empty-looking bins; two bins is the tolerance).
fn close_gaps(v: Vec<[f64; 2]>, gap: f64) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = Vec::with_capacity(v.len());
    for iv in v {
        match out.last_mut() {
            Some(last) if iv[0] - last[1] <= gap * (1.0 + 1e-9) => last[1] = last[1].max(iv[1]),
            _ => out.push(iv),
        }
    }
    out
}

/// Samples the posterior and summarises it. `inputs` (file names and hashes) go into the
/// summary as given.
pub fn fit(
    posterior: &Posterior,
    settings: &FitSettings,
    inputs: BTreeMap<String, String>,
    progress: &(dyn Fn(&Status) + Sync),
) -> Result<Fit> {
    let start = Instant::now();
    let samples = sample(posterior, &settings.sample, progress)?;
    let prior = posterior.prior;
    let d = prior.dim();
    // Global mode: the best draw, refined by Nelder-Mead in the unconstrained coordinates.
    let (best, _) = samples.best();
    let mut z0 = vec![0.0; d];
    prior.to_unconstrained(&best, &mut z0);
    // A recoverable model error is a point of zero density; any other ends the fit.
    let latch = Latch::default();
    let f = |z: &[f64]| {
        latch.value(|| {
            posterior
                .ln_density_z(z, None)
                .map(|(l, _)| posterior.output(z, l).1)
        })
    };
    // Within the run's time budget too (a run cut short keeps its best draw, refined so far).
    let deadline = settings.sample.deadline(start);
    let (z_mode, _) = nelder_mead_until(&f, &z0, 0.05, 200 * d + 400, 1e-10, &|| {
        Instant::now() >= deadline
    });
    latch.check()?;
    let mut mode = vec![0.0; d];
    prior.from_unconstrained(&z_mode, &mut mode);
    let at_mode = posterior.evaluate(&mode)?;
    let chi2 = posterior
        .likelihood
        .chi2_var(&at_mode.c_p, &at_mode.var_rel);
    let max_abs_pull = posterior
        .likelihood
        .pulls_var(&at_mode.c_p, &at_mode.var_rel)
        .iter()
        .fold(0.0f64, |m, p| m.max(p.abs()));
    let mut parameters = Vec::with_capacity(d);
    for (j, p) in prior.parameters.iter().enumerate() {
        let per = samples.parameter(j);
        let all: Vec<f64> = per.iter().flatten().copied().collect();
        let n = all.len() as f64;
        let mean = all.iter().sum::<f64>() / n;
        let std = (all.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let range = draw_range(&all, p.support);
        let dg = samples.diagnostics[j];
        // The histogram's counting noise is that of the chains' effective draws.
        let ess = dg.ess_min();
        let si = smallest_intervals(&all, None, Some(ess), range, settings.bins, &LEVELS);
        let width = (range[1] - range[0]) / settings.bins as f64;
        let si: Vec<Vec<[f64; 2]>> = si.into_iter().map(|v| close_gaps(v, 2.0 * width)).collect();
        let marginal = marginal_mode(&all, None, range, settings.bins);
        let at_prior_bound = bound_flags(
            &[("global mode", mode[j]), ("marginal mode", marginal)],
            &si[0],
            p.support,
        );
        parameters.push(ParameterSummary {
            name: p.name.clone(),
            mean,
            std,
            global_mode: mode[j],
            marginal_mode: marginal,
            smallest_intervals: LEVELS
                .iter()
                .zip(si)
                .map(|(l, v)| (format!("{l}"), v))
                .collect(),
            rhat: dg.rhat,
            ess_bulk: dg.ess_bulk,
            ess_tail: dg.ess_tail,
            unit: p.unit.clone(),
            prior: p.distribution,
            support: p.support,
            at_prior_bound,
        });
    }
    let all = samples.all();
    let points: Vec<Vec<f64>> = thin_indices(all.len(), settings.mode_draws)
        .into_iter()
        .map(|i| all[i].to_vec())
        .collect();
    let mixture = find_modes(&points, settings.max_modes, settings.sample.seed);
    let modes = mixture
        .components
        .iter()
        .map(|c| ModeSummary {
            weight: c.weight,
            location: c.mean.clone(),
            std: (0..d).map(|j| c.cov[j * d + j].max(0.0).sqrt()).collect(),
            physics: super::summary::mode_physics(&prior.names(), &c.mean),
        })
        .collect();
    let predictive = predictive(
        posterior,
        &samples,
        settings.predictive_draws,
        &at_mode,
        &LEVELS,
    )?;
    let summary = FitSummary {
        converged: samples.converged(),
        seconds: start.elapsed().as_secs_f64(),
        chi2,
        ndf: posterior.likelihood.len().saturating_sub(d),
        posterior_predictive_p: predictive.ppp,
        calibration_factor: predictive.calibration,
        parameters,
        modes,
        local_modes: samples.local_modes.clone(),
        exact_check: None,
        exact_check_skipped: None,
        refinement: None,
        posterior_outside_support: None,
        made: Some(hpge_solver::made()),
        program_version: env!("CARGO_PKG_VERSION").into(),
        inputs,
        likelihood: posterior.likelihood.noise,
        settings: settings.sample,
        stop: samples.stop,
        tuned: samples.tuned,
        tuning_cycles: samples.cycles,
        tuning_seconds: samples.tuning_seconds,
        draws_per_chain: samples.chains[0].theta.len(),
        acceptance: samples.chains.iter().map(|c| c.acceptance).collect(),
        divergences: samples.chains.iter().map(|c| c.divergences).sum(),
        evaluations: samples.evaluations(),
        ess_bulk_per_second: samples.ess_per_second(),
        ln_posterior_at_mode: at_mode.ln_posterior,
        max_abs_pull,
    };
    Ok(Fit {
        samples,
        summary,
        predictive,
        mode,
    })
}
