//! The workflow: fit the start model, locate its disagreement with the data, score every
//! catalogue entry, fit the best, and measure how much of the gap it closes.

use std::sync::Arc;
use std::time::Instant;

use super::catalogue::{Baseline, ExtensionPredictor, catalogue};
use super::checks::delta_elpd;
use super::fits::{best_laplace, bind, gap, laplace_model_fit, mcmc_fit, start_points};
use super::region::probed_region;
use super::resume::{Stages, stage};
use super::settings::{DiscoverInputs, DiscoverSettings, Discovery, Progress};
use super::summary::{CandidateScore, Disagreement, DiscoverySummary, NotApplicable};
use crate::Result;
use crate::model::{CvModel, ExactModel};
use crate::posterior::Posterior;
use crate::posterior::{LaplaceFit, laplace_fit};
use crate::prior::Prior;
use crate::summary::near_bound;

/// Runs the workflow (see the module docs).
pub fn discover(
    inp: &DiscoverInputs,
    settings: &DiscoverSettings,
    progress: &dyn Progress,
) -> Result<Discovery> {
    settings.validate()?;
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
        (ExtensionPredictor::Exact, exact_model.clone(), &lik_exact)
    } else {
        (ExtensionPredictor::Surrogate, inp.surrogate.clone(), lik)
    };
    let prior0 = Prior::bind(inp.start, &model.inputs(), &model.domain())?;
    let p0 = Posterior::new(model.as_ref(), &prior0, lik_p)?;
    progress.stage(&format!(
        "quick fit of the start model ({})",
        predictor.as_str()
    ));
    let starts0 = start_points(&prior0, &sur_mode, settings.exact);
    let base_fit = stage(
        inp.stages,
        progress,
        &format!("start-{}", predictor.as_str()),
        &starts0,
        || best_laplace(&p0, &starts0, settings),
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
            Err(e) => not_applicable.push(NotApplicable {
                name: ext.name().into(),
                reason: e.to_string(),
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
            ExtensionPredictor::Surrogate => (&base_fit, lik),
            ExtensionPredictor::Exact => {
                if base_exact.is_none() {
                    progress.stage("quick fit of the start model (exact solver)");
                    let p = Posterior::new(exact_model.as_ref(), &exact_prior, &lik_exact)?;
                    let starts = start_points(&exact_prior, &sur_mode, true);
                    base_exact = Some(stage(inp.stages, progress, "start-exact", &starts, || {
                        best_laplace(&p, &starts, settings)
                    })?);
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
        let lf = stage(
            inp.stages,
            progress,
            &format!("{}-{}", c.name, c.predictor.as_str()),
            std::slice::from_ref(&start),
            || laplace_fit(&p, &start, &settings.laplace),
        )?;
        // A Laplace evidence is a Gaussian around a stationary point: at a prior bound the mode
        // is the bound, not a maximum, and ln Z (so ln B) is not valid there (issue 63). Such a
        // candidate gets no ln B (null) and the reason, and cannot be chosen.
        let at_prior_bound: Vec<String> = prior
            .parameters
            .iter()
            .zip(&lf.theta)
            .filter_map(|(p, &x)| {
                near_bound(x, p.support)
                    .map(|side| format!("{} = {x:.4} at the {side} bound of the prior", p.name))
            })
            .collect();
        let score = if at_prior_bound.is_empty() {
            lf.ln_evidence - baseline.ln_evidence
        } else {
            f64::NAN
        };
        scores.push(CandidateScore {
            name: c.name.clone(),
            score,
            at_prior_bound,
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
        "laplace-linear"
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
            ExtensionPredictor::Surrogate => {
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
            ExtensionPredictor::Exact => {
                elpd_method = "laplace-linear".into();
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
    // Candidates without a ln B (a mode at a prior bound) after every scored one.
    order.sort_by(|&a, &b| ranked(scores[b].score).total_cmp(&ranked(scores[a].score)));
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
        made: Some(hpge_solver::made()),
        program_version: env!("CARGO_PKG_VERSION").into(),
        inputs: inp.inputs.clone(),
        settings: settings.clone(),
        resumed_stages: inp.stages.map(Stages::taken).unwrap_or_default(),
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
                .filter(|s| s.score.is_finite())
                .max_by(|a, b| a.score.total_cmp(&b.score))
                .map_or("no entry has a valid ln B".to_string(), |s| {
                    format!("the best entry, `{}`, scores ln B = {:.1}", s.name, s.score)
                });
            format!(
                "{windows}. No extension is supported ({best} < {}): {start} describes the data.",
                settings.min_ln_bayes
            )
        }
    }
}

/// A score for ordering: a missing ln B (NaN: the candidate's mode at a prior bound) below
/// every valid one.
fn ranked(score: f64) -> f64 {
    if score.is_finite() {
        score
    } else {
        f64::NEG_INFINITY
    }
}
