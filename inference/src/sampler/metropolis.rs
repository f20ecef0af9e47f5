//! Adaptive Metropolis in the way of BAT.jl's default sampler (Haario et al. 2001, as tuned by
//! BAT.jl's `AdaptiveMHTuning`): multivariate-normal random-walk proposals z' = z + sqrt(c) L e,
//! e ~ N(0, I), L L^T = Sigma. In tuning cycles of `cycle_draws` steps per chain,
//!   Sigma <- (1 - a) Sigma + a S,  a = (n + 1)^-1/2 for cycle n (S the cycle's pooled draw
//!   covariance), and per chain c <- c * 1.25 when the cycle's acceptance is above the window,
//!   c / 1.25 below it,
//! until every chain's acceptance lies in the window and the rank-normalised R-hat of the cycle's
//! draws is below `burnin_rhat` (BAT.jl: 1.1). The starting scale is Gelman et al.'s
//! c = 2.38^2 / d.

use std::time::Instant;

use std::sync::Arc;

use rand::RngExt;
use rand::rngs::StdRng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;

use super::engine::{Draw, Engine, Tuned};
use super::modes::{Modes, search};
use super::settings::SampleSettings;
use super::start::{chain_rng, start_point};
use super::status::{Phase, Status};
use super::target::LogDensity;
use crate::Result;
use crate::diagnostics::rank_rhat;
use crate::numerics::Cholesky;
use crate::rejection::density_or_rejected;

/// Factor of the scale update per cycle.
const SCALE_STEP: f64 = 1.25;
/// Probability of a mode-jump proposal per step (when several modes were found).
const JUMP_PROBABILITY: f64 = 0.1;

struct Chain<'a> {
    target: &'a dyn LogDensity,
    /// Mode-jump proposals (when the search found several modes).
    jumps: Option<Arc<Modes>>,
    /// Random-walk proposals and acceptances since the last reset (the tuning's acceptance).
    rw_tried: u64,
    rw_accepted: u64,
    z: Vec<f64>,
    ln_p: f64,
    /// Cholesky factor of Sigma.
    l: Cholesky,
    /// c.
    scale: f64,
    rng: StdRng,
    evaluations: u64,
}

impl Chain<'_> {
    /// One step: a mode jump or a random-walk proposal. A recoverable model error rejects the
    /// proposal; any other error is returned.
    fn step(&mut self) -> Result<Draw> {
        if let Some(m) = &self.jumps
            && self.rng.random::<f64>() < JUMP_PROBABILITY
        {
            let proposal = m.sample(&mut self.rng);
            self.evaluations += 1;
            let ln_q = density_or_rejected(self.target.ln_density(&proposal, None))?;
            let ln_a = ln_q - self.ln_p + m.ln_q(&self.z) - m.ln_q(&proposal);
            let u: f64 = self.rng.random();
            let accepted = ln_q.is_finite() && u.ln() < ln_a;
            if accepted {
                self.z = proposal;
                self.ln_p = ln_q;
            }
            return Ok(Draw {
                z: self.z.clone(),
                ln_density: self.ln_p,
                accept: f64::from(u8::from(accepted)),
                divergent: false,
            });
        }
        let d = self.z.len();
        let e: Vec<f64> = (0..d)
            .map(|_| StandardNormal.sample(&mut self.rng))
            .collect();
        let s = self.scale.sqrt();
        let step = self.l.mul_lower(&e);
        let proposal: Vec<f64> = (0..d).map(|i| self.z[i] + s * step[i]).collect();
        self.evaluations += 1;
        let ln_q = density_or_rejected(self.target.ln_density(&proposal, None))?;
        let u: f64 = self.rng.random();
        let accepted = ln_q.is_finite() && u.ln() < ln_q - self.ln_p;
        self.rw_tried += 1;
        if accepted {
            self.rw_accepted += 1;
            self.z = proposal;
            self.ln_p = ln_q;
        }
        Ok(Draw {
            z: self.z.clone(),
            ln_density: self.ln_p,
            accept: f64::from(u8::from(accepted)),
            divergent: false,
        })
    }
}

impl Engine for Chain<'_> {
    fn draw(&mut self) -> Result<Draw> {
        self.step()
    }

    fn evaluations(&self) -> u64 {
        self.evaluations
    }

    fn scale(&self) -> f64 {
        self.scale
    }
}

/// Burn-in and tuning.
pub(super) fn tune<'a>(
    target: &'a dyn LogDensity,
    s: &SampleSettings,
    start: Instant,
    progress: &(dyn Fn(&Status) + Sync),
) -> Result<Tuned<'a>> {
    let d = target.dim();
    let modes = if s.mode_starts > 0 {
        search(target, s.mode_starts, s.seed, s.deadline(start))?
    } else {
        Modes {
            modes: Vec::new(),
            evaluations: 0,
        }
    };
    // Sigma_0: the best mode's Laplace covariance, or the prior's spread in z scaled down by 10.
    let mut sigma = vec![0.0; d * d];
    if let Some(m) = modes.modes.first() {
        sigma.copy_from_slice(&m.cov);
    } else {
        let mut rng = chain_rng(s.seed, usize::MAX);
        let probe: Vec<Vec<f64>> = (0..200).map(|_| target.initial(&mut rng)).collect();
        for j in 0..d {
            let m = probe.iter().map(|p| p[j]).sum::<f64>() / probe.len() as f64;
            let v = probe.iter().map(|p| (p[j] - m).powi(2)).sum::<f64>() / probe.len() as f64;
            sigma[j * d + j] = (0.01 * v).max(1e-8);
        }
    }
    let l0 = factor(&sigma, d);
    let several = modes.modes.len() > 1;
    let jumps = several.then(|| Arc::new(modes.clone()));
    let mut chains: Vec<Chain<'a>> = (0..s.chains)
        .map(|c| {
            let mut rng = chain_rng(s.seed, c);
            // Several modes: chains start in them in turn; otherwise from dispersed prior draws.
            let (z, ln_p) = if several {
                let m = &modes.modes[c % modes.modes.len()];
                (m.z.clone(), m.ln_p)
            } else {
                start_point(target, &mut rng)?
            };
            Ok(Chain {
                target,
                jumps: jumps.clone(),
                rw_tried: 0,
                rw_accepted: 0,
                z,
                ln_p,
                l: l0.clone(),
                scale: 2.38 * 2.38 / d as f64,
                rng,
                evaluations: 1,
            })
        })
        .collect::<Result<_>>()?;
    chains[0].evaluations += modes.evaluations;
    let mut tuned = false;
    let mut cycle = 0;
    let mut previous: Vec<Vec<Vec<f64>>> = vec![Vec::new(); s.chains];
    // Tuning ends at the run's time budget too (untuned: the sampling phase then stops at once
    // with the draws it must keep).
    let deadline = s.deadline(start);
    while cycle < s.max_cycles && Instant::now() < deadline {
        cycle += 1;
        let runs: Vec<(Vec<Vec<f64>>, f64)> = chains
            .par_iter_mut()
            .map(|ch| {
                let mut zs = Vec::with_capacity(s.cycle_draws);
                let mut acc = 0.0;
                for _ in 0..s.cycle_draws {
                    // A cycle ends early at the time budget (two draws for a covariance).
                    if zs.len() >= 2 && Instant::now() >= deadline {
                        break;
                    }
                    let dr = ch.step()?;
                    acc += dr.accept;
                    zs.push(dr.z);
                }
                let n = zs.len().max(1) as f64;
                Ok((zs, acc / n))
            })
            .collect::<Result<_>>()?;
        // Pooled covariance of the cycle's draws.
        let all: Vec<&Vec<f64>> = runs.iter().flat_map(|r| r.0.iter()).collect();
        let n = all.len() as f64;
        let mean: Vec<f64> = (0..d)
            .map(|j| all.iter().map(|z| z[j]).sum::<f64>() / n)
            .collect();
        let mut cov = vec![0.0; d * d];
        for z in &all {
            for i in 0..d {
                for j in 0..=i {
                    cov[i * d + j] += (z[i] - mean[i]) * (z[j] - mean[j]) / (n - 1.0);
                }
            }
        }
        let a = 1.0 / ((cycle + 1) as f64).sqrt();
        for i in 0..d {
            for j in 0..=i {
                let v = (1.0 - a) * sigma[i * d + j] + a * cov[i * d + j];
                sigma[i * d + j] = v;
                sigma[j * d + i] = v;
            }
            sigma[i * d + i] = sigma[i * d + i].max(1e-12);
        }
        let l = factor(&sigma, d);
        let mut in_window = true;
        let mut mean_acc = 0.0;
        for (ch, run) in chains.iter_mut().zip(&runs) {
            let acc = run.1;
            mean_acc += acc / s.chains as f64;
            if acc > s.acceptance[1] {
                ch.scale *= SCALE_STEP;
                in_window = false;
            } else if acc < s.acceptance[0] {
                ch.scale /= SCALE_STEP;
                in_window = false;
            }
            ch.l = l.clone();
        }
        // R-hat over this cycle and the previous one.
        let rhat = (0..d)
            .map(|j| {
                let per: Vec<Vec<f64>> = runs
                    .iter()
                    .zip(&previous)
                    .map(|(r, p)| p.iter().chain(&r.0).map(|z| z[j]).collect())
                    .collect();
                rank_rhat(&per)
            })
            .fold(0.0, f64::max);
        previous = runs.into_iter().map(|r| r.0).collect();
        progress(&Status {
            phase: Phase::Tuning,
            cycle,
            draws: 0,
            rhat_max: rhat,
            ess_min: f64::NAN,
            acceptance: mean_acc,
            seconds: start.elapsed().as_secs_f64(),
        });
        if in_window && rhat <= s.burnin_rhat {
            tuned = true;
            break;
        }
    }
    Ok(Tuned {
        modes: modes.local_modes(target),
        engines: chains
            .into_iter()
            .map(|c| Box::new(c) as Box<dyn Engine + 'a>)
            .collect(),
        tuned,
        cycles: cycle,
    })
}

/// Cholesky factor of a covariance, with growing diagonal jitter if it is not positive definite.
fn factor(sigma: &[f64], d: usize) -> Cholesky {
    let mut a = sigma.to_vec();
    let mut jitter = 1e-12;
    loop {
        if let Some(c) = Cholesky::new(&a, d) {
            return c;
        }
        for i in 0..d {
            a[i * d + i] += jitter * (1.0 + sigma[i * d + i]);
        }
        jitter *= 10.0;
    }
}
