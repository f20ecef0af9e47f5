//! The workflow: fit the start model, locate its disagreement with the data, score every
//! catalogue entry, fit the best, and measure how much of the gap it closes.

use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::Instant;

use hpge_surrogate::ExactSolver;
use rand::{SeedableRng, rngs::StdRng};
use rand_distr::{Distribution, StandardNormal};
use serde::Serialize;

use super::catalogue::{Baseline, Candidate, Predictor, catalogue};
use super::checks::{
    Elpd, PredictiveDraws, ResidualCheck, delta_elpd, leave_window_out, residual_check,
};
use super::laplace::{LaplaceFit, LaplaceSettings, laplace_fit};
use super::region::probed_region;
use super::summary::{CandidateScore, Disagreement, DiscoverySummary, Gap, NotApplicable};
use crate::fit::thin_indices;
use crate::posterior::Cholesky;
use crate::prior::PriorDistribution;
use crate::{
    CvModel, ExactModel, Fit, FitSettings, Likelihood, Posterior, Prior, PriorSpec, Result, Status,
    fit,
};

/// Settings of the workflow.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DiscoverSettings {
    /// The start model's and the chosen extension's MCMC fits.
    pub fit: FitSettings,
    /// The quick fits.
    pub laplace: LaplaceSettings,
    /// Shortest run of same-sign residuals that counts as a window.
    pub min_run: usize,
    /// A window is reported as disagreement when its (look-elsewhere corrected) p-value is below
    /// this.
    pub window_p: f64,
    /// Smallest Laplace ln Bayes factor for an extension to be chosen: 3 is "strong" evidence
    /// on Kass & Raftery's (1995) scale (2 ln B > 6).
    pub min_ln_bayes: f64,
    /// Blocks of the leave-window-out elpd (contiguous voltage windows).
    pub elpd_blocks: usize,
    /// Posterior draws for the residual check and the elpd.
    pub draws: usize,
    /// Run the quick fits, the residual check and the full fit of an extension on the exact
    /// solver (Laplace), the surrogate only seeding the start model's mode. Off: everything
    /// on the surrogate where it can (MCMC), the exact solver only for entries outside its
    /// space. On by default: the surrogate is up to 27% off the exact solver on z-only
    /// profiles at 25 V (a corner of its space), enough to fake any effect.
    pub exact: bool,
    /// Catalogue entries to try (empty: all).
    pub only: Vec<String>,
    /// Seed of every random step.
    pub seed: u64,
}

impl Default for DiscoverSettings {
    fn default() -> Self {
        Self {
            fit: FitSettings::default(),
            laplace: LaplaceSettings::default(),
            min_run: 3,
            window_p: 0.01,
            min_ln_bayes: 3.0,
            elpd_blocks: 10,
            draws: 1000,
            exact: true,
            only: Vec::new(),
            seed: 1,
        }
    }
}

impl DiscoverSettings {
    /// Checks the values (the message names the field).
    pub fn validate(&self) -> std::result::Result<(), String> {
        if self.min_run < 2 {
            return Err(format!("min_run: {} < 2", self.min_run));
        }
        if !(self.window_p > 0.0 && self.window_p < 1.0) {
            return Err(format!("window_p: {} is not in (0, 1)", self.window_p));
        }
        if self.elpd_blocks < 2 {
            return Err(format!("elpd_blocks: {} < 2", self.elpd_blocks));
        }
        if self.draws < 100 {
            return Err(format!("draws: {} < 100", self.draws));
        }
        Ok(())
    }
}

/// What the workflow starts from.
pub struct DiscoverInputs<'a> {
    /// The surrogate bound to the data's voltages.
    pub surrogate: Arc<dyn CvModel>,
    /// The exact solver on the surrogate's space and the detector.
    pub exact: &'a ExactSolver,
    /// The start model's prior.
    pub start: &'a PriorSpec,
    /// The likelihood of the data (its sigma_p is the surrogate's; used for every predictor so
    /// that scores compare alike).
    pub likelihood: &'a Likelihood,
    /// Input files and hashes for the summary.
    pub inputs: BTreeMap<String, String>,
}

/// One model's fit, as the workflow keeps it.
#[derive(Debug, Clone)]
pub struct ModelFit {
    /// The model's prior name.
    pub model: String,
    /// Parameter names.
    pub names: Vec<String>,
    /// The MCMC fit (None for a Laplace fit).
    pub mcmc: Option<Fit>,
    /// The Laplace fit (None for an MCMC fit).
    pub laplace: Option<LaplaceFit>,
    /// Its residual check.
    pub check: ResidualCheck,
    /// Its leave-window-out elpd.
    pub elpd: Elpd,
    /// c_p at the mode, pF.
    pub c_mode: Vec<f64>,
    /// sigma at the mode, pF.
    pub sigma_mode: Vec<f64>,
}

/// Everything the workflow found.
#[derive(Debug, Clone)]
pub struct Discovery {
    /// The summary (JSON).
    pub summary: DiscoverySummary,
    /// The start model.
    pub before: ModelFit,
    /// The extended model (None when nothing was chosen).
    pub after: Option<ModelFit>,
    /// Bias voltages, V.
    pub voltage_v: Vec<f64>,
    /// Measured c12, pF.
    pub c_m_pf: Vec<f64>,
    /// The start model's inputs at its global mode (the surrogate's input order; the exact
    /// solver's detector there is what the probed regions were computed on).
    pub start_inputs: Vec<f64>,
}

/// Progress of the workflow.
pub trait Progress: Sync {
    /// A stage begins (one line).
    fn stage(&self, message: &str);
    /// MCMC progress.
    fn sampling(&self, status: &Status);
}

/// Predictive draws of an MCMC fit: at most `n` thinned draws.
fn mcmc_draws(posterior: &Posterior, fit: &Fit, n: usize) -> PredictiveDraws {
    let all = fit.samples.all();
    let mut draws = PredictiveDraws {
        curves: Vec::new(),
        sigmas: Vec::new(),
    };
    for i in thin_indices(all.len(), n) {
        if let Ok(ev) = posterior.evaluate(all[i]) {
            draws.sigmas.push(posterior.likelihood.sigma(&ev.c_p));
            draws.curves.push(ev.c_p);
        }
    }
    draws
}

/// Draws of the Laplace approximation N(theta*, H^-1) (inside the prior's support) with the
/// curve linearised at the mode: c = c* + J (theta - theta*).
fn laplace_draws(posterior: &Posterior, lf: &LaplaceFit, n: usize, seed: u64) -> PredictiveDraws {
    let d = lf.theta.len();
    let nv = lf.c_p.len();
    let mut rng = StdRng::seed_from_u64(seed);
    let mut draws = PredictiveDraws {
        curves: Vec::new(),
        sigmas: Vec::new(),
    };
    let Some(ch) = Cholesky::new(&lf.covariance, d) else {
        return draws;
    };
    let l = ch.lower();
    let mut tries = 0;
    while draws.curves.len() < n && tries < 100 * n {
        tries += 1;
        let e: Vec<f64> = (0..d).map(|_| StandardNormal.sample(&mut rng)).collect();
        let dt: Vec<f64> = (0..d)
            .map(|p| (0..=p).map(|q| l[p * d + q] * e[q]).sum())
            .collect();
        let theta: Vec<f64> = lf.theta.iter().zip(&dt).map(|(t, s)| t + s).collect();
        if !posterior.prior.ln_density(&theta).is_finite() {
            continue;
        }
        let c: Vec<f64> = (0..nv)
            .map(|k| lf.c_p[k] + (0..d).map(|j| lf.jacobian[k * d + j] * dt[j]).sum::<f64>())
            .collect();
        draws.sigmas.push(posterior.likelihood.sigma(&c));
        draws.curves.push(c);
    }
    draws
}

/// Goodness of fit at a mode.
fn gap(model: &ModelFit, lik: &Likelihood, converged: bool, mode: &[f64], method: &str) -> Gap {
    let chi2 = lik.chi2(&model.c_mode);
    let ndf = lik.len().saturating_sub(model.names.len());
    Gap {
        chi2_ndf: chi2 / ndf.max(1) as f64,
        max_pull: lik
            .pulls(&model.c_mode)
            .iter()
            .fold(0.0f64, |m, p| m.max(p.abs())),
        ppc_p: model.check.ppc_p,
        chi2,
        ndf,
        model: model.model.clone(),
        method: method.into(),
        converged,
        mode: model
            .names
            .iter()
            .cloned()
            .zip(mode.iter().copied())
            .collect(),
    }
}

/// An MCMC fit of `prior` on `model` with its checks.
fn mcmc_fit(
    model: &dyn CvModel,
    prior: &Prior,
    lik: &Likelihood,
    settings: &DiscoverSettings,
    inputs: &BTreeMap<String, String>,
    progress: &dyn Progress,
) -> Result<ModelFit> {
    let posterior = Posterior::new(model, prior, lik)?;
    let f = fit(&posterior, &settings.fit, inputs.clone(), &|s| {
        progress.sampling(s)
    })?;
    let draws = mcmc_draws(&posterior, &f, settings.draws);
    let c_mode = f.predictive.c_mode_pf.clone();
    Ok(ModelFit {
        model: prior.name.clone(),
        names: prior.names(),
        check: residual_check(&lik.c_m, &draws, settings.min_run, settings.seed),
        elpd: leave_window_out(&lik.c_m, &draws, settings.elpd_blocks),
        sigma_mode: lik.sigma(&c_mode),
        c_mode,
        mcmc: Some(f),
        laplace: None,
    })
}

/// A Laplace fit's checks (draws of the linearised Gaussian).
fn laplace_model_fit(
    posterior: &Posterior,
    lf: LaplaceFit,
    settings: &DiscoverSettings,
) -> ModelFit {
    let lik = posterior.likelihood;
    let draws = laplace_draws(posterior, &lf, settings.draws, settings.seed ^ 0x1a9);
    ModelFit {
        model: posterior.prior.name.clone(),
        names: posterior.prior.names(),
        check: residual_check(&lik.c_m, &draws, settings.min_run, settings.seed),
        elpd: leave_window_out(&lik.c_m, &draws, settings.elpd_blocks),
        sigma_mode: lik.sigma(&lf.c_p),
        c_mode: lf.c_p.clone(),
        mcmc: None,
        laplace: Some(lf),
    }
}

/// Start points of the start model's quick fit: the surrogate MCMC mode and, on the exact
/// solver, the prior's centre too (the surrogate's mode may sit at the wrong one of two
/// near-symmetric modes; seen on z-only truths, where B_Z swapped top and bottom).
fn start_points(prior: &Prior, sur_mode: &[f64], centre: bool) -> Vec<Vec<f64>> {
    let mut v = vec![sur_mode.to_vec()];
    if centre {
        v.push(
            prior
                .parameters
                .iter()
                .map(|p| {
                    let m = match p.distribution {
                        PriorDistribution::Uniform { lo, hi } => 0.5 * (lo + hi),
                        PriorDistribution::Normal { mean, .. }
                        | PriorDistribution::TruncatedNormal { mean, .. } => mean,
                    };
                    m.clamp(p.support[0], p.support[1])
                })
                .collect(),
        );
    }
    v
}

/// The best (highest ln p) of the quick fits from `starts`; the first error if all fail.
fn best_laplace(
    posterior: &Posterior,
    starts: &[Vec<f64>],
    settings: &DiscoverSettings,
) -> Result<LaplaceFit> {
    let mut best: Option<LaplaceFit> = None;
    let mut first_err = None;
    for s in starts {
        match laplace_fit(posterior, s, &settings.laplace) {
            Ok(f) => {
                if best
                    .as_ref()
                    .is_none_or(|b| f.ln_posterior > b.ln_posterior)
                {
                    best = Some(f);
                }
            }
            Err(e) => {
                first_err.get_or_insert(e);
            }
        }
    }
    match (best, first_err) {
        (Some(b), _) => Ok(b),
        (None, Some(e)) => Err(e),
        (None, None) => Err(crate::Error::Argument {
            name: "start points".into(),
            message: "none given".into(),
        }),
    }
}

/// A candidate's prior bound to its model.
fn bind(c: &Candidate) -> Result<Prior> {
    Prior::bind(&c.spec, &c.model.inputs(), &c.model.domain())
}

/// Runs the workflow (see the module docs).
pub fn discover(
    inp: &DiscoverInputs,
    settings: &DiscoverSettings,
    progress: &dyn Progress,
) -> Result<Discovery> {
    settings.validate().map_err(|m| crate::Error::Argument {
        name: "discover settings".into(),
        message: m,
    })?;
    let t0 = Instant::now();
    let lik = inp.likelihood;
    let volts = inp.surrogate.voltages().to_vec();
    // 1. The start model: sampled on the surrogate (MCMC); with `exact` (the default) its
    //    mode is then found again on the exact solver, which every later step uses.
    progress.stage(&format!(
        "fitting the start model {} (surrogate, MCMC)",
        inp.start.name
    ));
    let start_prior = Prior::bind(inp.start, &inp.surrogate.inputs(), &inp.surrogate.domain())?;
    let sur_fit = mcmc_fit(
        inp.surrogate.as_ref(),
        &start_prior,
        lik,
        settings,
        &inp.inputs,
        progress,
    )?;
    let sur_mcmc = sur_fit.mcmc.as_ref().expect("an MCMC fit");
    let sur_mode = sur_mcmc.mode.clone();
    let surrogate_gap = gap(&sur_fit, lik, sur_mcmc.summary.converged, &sur_mode, "mcmc");
    let exact_model: Arc<dyn CvModel> = Arc::new(ExactModel::new(inp.exact.clone(), &volts)?);
    // The exact solver's own error is the likelihood's 1% + 1 pF term (sigma_p = 0).
    let lik_exact = lik.with_sigma_rel(0.0);
    let (predictor, model, lik_p) = if settings.exact {
        (Predictor::Exact, exact_model.clone(), &lik_exact)
    } else {
        (Predictor::Surrogate, inp.surrogate.clone(), lik)
    };
    let prior0 = Prior::bind(inp.start, &model.inputs(), &model.domain())?;
    let p0 = Posterior::new(model.as_ref(), &prior0, lik_p)?;
    progress.stage(&format!(
        "quick fit of the start model ({})",
        predictor.as_str()
    ));
    let base_fit = best_laplace(
        &p0,
        &start_points(&prior0, &sur_mode, settings.exact),
        settings,
    )?;
    let (before, before_gap, mode) = if settings.exact {
        let theta = base_fit.theta.clone();
        let mf = laplace_model_fit(&p0, base_fit.clone(), settings);
        let g = gap(&mf, lik_p, true, &theta, "laplace");
        (mf, g, theta)
    } else {
        (sur_fit.clone(), surrogate_gap.clone(), sur_mode.clone())
    };
    // 2. Where it disagrees, and what the windows probe.
    progress.stage("locating the disagreement");
    let mut x_mode = vec![0.0; start_prior.input_names.len()];
    start_prior.expand(&mode, &mut x_mode);
    let det = inp.exact.detector(&x_mode)?;
    let mut disagreement = Vec::new();
    for w in before
        .check
        .windows
        .iter()
        .filter(|w| w.p_value < settings.window_p)
    {
        let lo = (w.first > 0).then(|| volts[w.first - 1]);
        let (region, region_error) =
            match probed_region(&det, &inp.exact.settings, lo, volts[w.last]) {
                Ok(r) => (Some(r), None),
                Err(e) => (None, Some(e.to_string())),
            };
        disagreement.push(Disagreement {
            voltages_v: [volts[w.first], volts[w.last]],
            region,
            p_value: w.p_value,
            window: w.clone(),
            region_error,
        });
    }
    // 3. Quick scores.
    let base = Baseline {
        spec: inp.start,
        mode: &mode,
        model: model.clone(),
        predictor,
        exact: inp.exact,
    };
    let mut not_applicable = Vec::new();
    let mut candidates = Vec::new();
    for ext in catalogue() {
        if !settings.only.is_empty() && !settings.only.iter().any(|n| n == ext.name()) {
            continue;
        }
        match ext.build(&base) {
            Ok(c) => candidates.push(c),
            Err(reason) => not_applicable.push(NotApplicable {
                name: ext.name().into(),
                reason,
            }),
        }
    }
    let exact_prior = Prior::bind(inp.start, &exact_model.inputs(), &exact_model.domain())?;
    let mut base_exact: Option<LaplaceFit> = settings.exact.then(|| base_fit.clone());
    let mut scores = Vec::new();
    let mut quick: Vec<(LaplaceFit, Prior)> = Vec::new();
    for c in &candidates {
        let tc = Instant::now();
        let (baseline, lik_c) = match c.predictor {
            Predictor::Surrogate => (&base_fit, lik),
            Predictor::Exact => {
                if base_exact.is_none() {
                    progress.stage("quick fit of the start model (exact solver)");
                    let p = Posterior::new(exact_model.as_ref(), &exact_prior, &lik_exact)?;
                    base_exact = Some(best_laplace(
                        &p,
                        &start_points(&exact_prior, &sur_mode, true),
                        settings,
                    )?);
                }
                (base_exact.as_ref().expect("set above"), &lik_exact)
            }
        };
        progress.stage(&format!("quick fit: {} ({})", c.name, c.predictor.as_str()));
        let prior = bind(c)?;
        let p = Posterior::new(c.model.as_ref(), &prior, lik_c)?;
        // Start from the baseline's optimum (for the exact solver the surrogate's is ~1% off)
        // with the candidate's own parameters at their null values.
        let mut start = c.start.clone();
        if start.len() == baseline.theta.len() + c.added.len() {
            start[..baseline.theta.len()].copy_from_slice(&baseline.theta);
        }
        let lf = laplace_fit(&p, &start, &settings.laplace)?;
        scores.push(CandidateScore {
            name: c.name.clone(),
            score: lf.ln_evidence - baseline.ln_evidence,
            predictor: c.predictor.as_str().into(),
            delta_chi2: baseline.chi2 - lf.chi2,
            chi2: lf.chi2,
            optimum: prior
                .names()
                .into_iter()
                .zip(lf.theta.iter().copied())
                .collect(),
            added: c.added.clone(),
            description: c.description.clone(),
            signature: c.signature.clone(),
            evaluations: lf.evaluations,
            seconds: tc.elapsed().as_secs_f64(),
        });
        quick.push((lf, prior));
    }
    // 4. The best candidate, if it is good enough, gets a full fit: MCMC on the surrogate, or
    //    (exact solver) the Laplace approximation with the curve linearised at the mode.
    let best = (0..scores.len())
        .filter(|&i| scores[i].score.is_finite())
        .max_by(|&a, &b| scores[a].score.total_cmp(&scores[b].score));
    let chosen = best.filter(|&i| scores[i].score >= settings.min_ln_bayes);
    let mut after = None;
    let mut after_gap = before_gap.clone();
    let (mut d_elpd, mut d_se) = (0.0, 0.0);
    let mut elpd_method = if settings.exact {
        "laplace-psis"
    } else {
        "psis"
    }
    .to_string();
    let mut k_hat = [before.elpd.max_k_hat, before.elpd.max_k_hat];
    if let Some(i) = chosen {
        let c = &candidates[i];
        progress.stage(&format!("full fit: {} + {}", inp.start.name, c.name));
        let prior = &quick[i].1;
        let (af, before_ref) = match c.predictor {
            Predictor::Surrogate => {
                let af = mcmc_fit(
                    c.model.as_ref(),
                    prior,
                    lik,
                    settings,
                    &inp.inputs,
                    progress,
                )?;
                let m = af.mcmc.as_ref().expect("an MCMC fit");
                after_gap = gap(&af, lik, m.summary.converged, &m.mode.clone(), "mcmc");
                (af, before.elpd.clone())
            }
            Predictor::Exact => {
                elpd_method = "laplace-psis".into();
                let p = Posterior::new(c.model.as_ref(), prior, &lik_exact)?;
                let lf = quick[i].0.clone();
                let theta = lf.theta.clone();
                let af = laplace_model_fit(&p, lf, settings);
                after_gap = gap(&af, &lik_exact, true, &theta, "laplace");
                let before_ref = if settings.exact {
                    before.elpd.clone()
                } else {
                    let pe = Posterior::new(exact_model.as_ref(), &exact_prior, &lik_exact)?;
                    let bf = laplace_model_fit(
                        &pe,
                        base_exact
                            .clone()
                            .expect("an exact candidate fitted the exact baseline"),
                        settings,
                    );
                    bf.elpd
                };
                (af, before_ref)
            }
        };
        (d_elpd, d_se) = delta_elpd(&before_ref, &af.elpd);
        k_hat = [before_ref.max_k_hat, af.elpd.max_k_hat];
        after = Some(af);
    }
    let mut order: Vec<usize> = (0..scores.len()).collect();
    order.sort_by(|&a, &b| scores[b].score.total_cmp(&scores[a].score));
    let verdict = verdict(&disagreement, &scores, chosen, settings, &inp.start.name);
    let summary = DiscoverySummary {
        start_model: inp.start.name.clone(),
        disagreement,
        candidates: order.iter().map(|&i| scores[i].clone()).collect(),
        chosen: chosen.map(|i| scores[i].name.clone()),
        before: before_gap,
        after: after_gap,
        delta_elpd: d_elpd,
        delta_elpd_se: d_se,
        seconds: t0.elapsed().as_secs_f64(),
        ln_bayes_factor: chosen.map(|i| scores[i].score),
        elpd_method,
        elpd_blocks: before.elpd.blocks.len(),
        elpd_max_k_hat: k_hat,
        runs: before.check.windows.clone(),
        predictor: predictor.as_str().into(),
        surrogate_start: surrogate_gap,
        not_applicable,
        verdict,
        program_version: env!("CARGO_PKG_VERSION").into(),
        inputs: inp.inputs.clone(),
        settings: settings.clone(),
    };
    Ok(Discovery {
        summary,
        before,
        after,
        voltage_v: volts,
        c_m_pf: lik.c_m.clone(),
        start_inputs: x_mode,
    })
}

/// The decision in words.
fn verdict(
    disagreement: &[Disagreement],
    scores: &[CandidateScore],
    chosen: Option<usize>,
    settings: &DiscoverSettings,
    start: &str,
) -> String {
    let windows = if disagreement.is_empty() {
        format!(
            "{start} shows no window of structured disagreement (p < {})",
            settings.window_p
        )
    } else {
        let w: Vec<String> = disagreement
            .iter()
            .map(|d| {
                let region = d.region.as_ref().map_or(String::new(), |r| {
                    format!(
                        ", probing r = {:.1}-{:.1} mm, z = {:.1}-{:.1} mm",
                        r.r_mm[0], r.r_mm[1], r.z_mm[0], r.z_mm[1]
                    )
                });
                format!(
                    "{:.0}-{:.0} V (p = {:.3}{region})",
                    d.voltages_v[0], d.voltages_v[1], d.p_value
                )
            })
            .collect();
        format!("{start} disagrees with the data at {}", w.join("; "))
    };
    match chosen {
        Some(i) => format!(
            "{windows}. The best extension is `{}` ({}): ln Bayes factor {:.1} (Laplace), chi^2 lower by {:.1}; it was added.",
            scores[i].name, scores[i].description, scores[i].score, scores[i].delta_chi2
        ),
        None => {
            let best = scores
                .iter()
                .max_by(|a, b| a.score.total_cmp(&b.score))
                .map_or("no entry applies".to_string(), |s| {
                    format!("the best entry, `{}`, scores ln B = {:.1}", s.name, s.score)
                });
            format!(
                "{windows}. No extension is supported ({best} < {}): {start} describes the data.",
                settings.min_ln_bayes
            )
        }
    }
}
