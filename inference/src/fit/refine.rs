//! Posterior-adaptive refinement of a fit (issue 21): sample, check the draws with the exact
//! solver, and while the check fails, teach a model of the surrogate's error at those draws
//! ([`GpCorrection`]) and sample again with the corrected surrogate ([`CorrectedModel`]).
//!
//! Round r samples the posterior of model M_r (M_0 the surrogate, M_r the surrogate corrected
//! by every exact curve of rounds 0..r) and re-weights a thinned sample with the exact solver
//! (`exact_check`, the weights ln L_exact - ln L_{M_r}, M_r's own per-point uncertainty in its
//! likelihood). A passing check ends the loop: M_r's posterior is the fit's, and the check is
//! its verification. A failing one adds its exact curves to the error model's training points
//! (each check's curves are solved before they teach the model that the next check tests, so
//! no check ever sees its own training data), and the sampler's other local modes get exact
//! curves too ([`MAX_LOCAL_MODE_CURVES`]). The loop also ends after `max_rounds` rounds, or when
//! too few curves exist for the error model. With a [`Resume`], every finished round is written
//! ([`Checkpoint`]) and a restarted fit takes its finished rounds back.

use std::collections::BTreeMap;
use std::time::Instant;

use super::ascent::{away_from_mode, basin_ascents};
use super::checkpoint::{Checkpoint, SavedRound, fingerprint};
use super::exact_check::{ExactCheckSettings, ExactGrids, add_grid_check, exact_check};
use super::job::FitJob;
pub use super::refine_settings::{
    DEFAULT_HYPER_EVALS, DEFAULT_REFINE_ROUNDS, RefineSettings, RefineVariance,
};
use super::round::RefineRound;
use super::run::{Fit, FitSettings, fit};
use crate::Result;
use crate::model::{CvModel, ExactModel};
use crate::posterior::{Likelihood, Posterior};
use crate::prior::Prior;
use crate::refine::{CorrectedModel, GpCorrection, GpHyper};
use crate::rejection::unless_rejected;
use crate::sampler::{SamplerStop, Status};

/// Of the exact curves `solved` (inputs x, c_exact) and `best` so far, the one of highest exact
/// likelihood ln L_exact (`like` without a surrogate term), as (ln L, x); a curve whose ln L is
/// not finite is passed over, and of equal ones the earlier is kept.
fn best_exact(
    like: &Likelihood,
    best: Option<(f64, Vec<f64>)>,
    solved: &[(Vec<f64>, Vec<f64>)],
) -> Option<(f64, Vec<f64>)> {
    solved.iter().fold(best, |best, (x, ce)| {
        let l = like.ln_likelihood(ce, None);
        if l.is_finite() && best.as_ref().is_none_or(|(b, _)| l > *b) {
            Some((l, x.clone()))
        } else {
            best
        }
    })
}

/// At most this many of the sampler's local modes (best Laplace weight first, the global mode's
/// own basin left out) get an exact curve after a failed check. A posterior the surrogate puts
/// at the wrong one of several maxima (the B_Z fit: the surrogate's mode at d_Li = 0.2 mm, the
/// exact solver's near 2.7 mm, a local mode of weight 0.009 under the surrogate) is only found
/// if the error model learns the surrogate's error at the others too; the check's draws all sit
/// in one basin.
pub const MAX_LOCAL_MODE_CURVES: usize = 8;

/// Exact curves at up to [`MAX_LOCAL_MODE_CURVES`] of `result`'s local modes away from its
/// global mode (farther than 1% of the prior's support in some parameter); a failed solve is
/// left out.
fn local_mode_curves(m: RefineInputs, result: &Fit) -> Result<Vec<(Vec<f64>, Vec<f64>)>> {
    use rayon::prelude::*;
    let nx = m.prior.input_names.len();
    let nv = m.likelihood.len();
    let xs: Vec<Vec<f64>> = result
        .samples
        .local_modes
        .iter()
        .filter(|l| away_from_mode(m.prior, &result.mode, &l.theta))
        .take(MAX_LOCAL_MODE_CURVES)
        .map(|l| {
            let mut x = vec![0.0; nx];
            m.prior.expand(&l.theta, &mut x);
            x
        })
        .collect();
    let curves: Vec<Option<(Vec<f64>, Vec<f64>)>> = xs
        .into_par_iter()
        .map(|x| {
            let mut c = vec![0.0; nv];
            Ok(unless_rejected(m.exact.curve(&x, &mut c))?.map(|()| (x, c)))
        })
        .collect::<Result<_>>()?;
    Ok(curves.into_iter().flatten().collect())
}

/// A refined fit: the last round's fit (its exact check in its summary), the rounds, and the
/// error model it was sampled with (None when the plain surrogate passed or no round ran
/// corrected).
pub struct RefinedFit {
    /// The fit of the last round.
    pub fit: Fit,
    /// Every round, in order.
    pub rounds: Vec<RefineRound>,
    /// The error model of the last round's model.
    pub correction: Option<GpCorrection>,
    /// The error model's training points: model inputs x and ln(c_exact / c_surrogate) at the
    /// voltages (every exact curve of the rounds before the last).
    pub training: Vec<(Vec<f64>, Vec<f64>)>,
}

/// The models and the data a refined fit works with.
#[derive(Clone, Copy)]
pub struct RefineInputs<'a> {
    /// The surrogate (the model of round 0, corrected in the later rounds).
    pub surrogate: &'a dyn CvModel,
    /// The exact solver (the check's reference and the error model's teacher).
    pub exact: &'a dyn CvModel,
    /// The prior.
    pub prior: &'a Prior,
    /// The likelihood of the data.
    pub likelihood: &'a Likelihood,
}

/// What a refined fit reports as it goes: the sampling status, the check's curves (done,
/// total) and each finished round.
#[derive(Clone, Copy)]
pub struct RefineProgress<'a> {
    /// A sampling status update.
    pub sampling: &'a (dyn Fn(&Status) + Sync),
    /// A round's sampling ended and its exact check starts (with the round).
    pub sampled: &'a (dyn Fn(usize) + Sync),
    /// Curves done of the exact check.
    pub exact: &'a (dyn Fn(usize, usize) + Sync),
    /// A round ended.
    pub round: &'a (dyn Fn(&RefineRound) + Sync),
}

impl RefineProgress<'static> {
    /// Reports nothing (a fit inside a study, a test).
    pub fn quiet() -> Self {
        RefineProgress {
            sampling: &|_| {},
            sampled: &|_| {},
            exact: &|_, _| {},
            round: &|_| {},
        }
    }
}

/// Rounds a previous run of the same fit finished, and where this run writes its own
/// ([`Checkpoint`]).
pub struct Resume<'a> {
    /// The finished rounds, from round 0 without a gap.
    pub saved: Vec<SavedRound>,
    /// Where each new round is written.
    pub checkpoint: &'a Checkpoint,
}

/// Adds the exact curves `solved` (inputs x, c_exact) to the error model's training points as
/// r = ln(c_exact / c_surrogate); a point where the surrogate fails or r is not finite is left
/// out.
fn teach(
    surrogate: &dyn CvModel,
    training: &mut Vec<(Vec<f64>, Vec<f64>)>,
    solved: Vec<(Vec<f64>, Vec<f64>)>,
) {
    let nv = surrogate.voltages().len();
    for (x, ce) in solved {
        let mut cs = vec![0.0; nv];
        if surrogate.curve(&x, &mut cs).is_err() {
            continue;
        }
        let r: Vec<f64> = ce.iter().zip(&cs).map(|(e, s)| (e / s).ln()).collect();
        if r.iter().all(|v| v.is_finite()) {
            training.push((x, r));
        }
    }
}

/// Samples and checks with the exact solver, refining while the check fails (see the module
/// text); `inputs` (file names and hashes) go into each round's summary. With `resume`, the
/// rounds a previous run finished are taken back (a failed one's curves teach the error model
/// without sampling; the last one is sampled again, seeded as before, with its saved check) and
/// every new round is written as it finishes.
///
/// # Errors
/// As [`fit`] and [`exact_check`]; an error model that cannot be fitted; a round that cannot be
/// written.
#[allow(clippy::too_many_arguments)]
pub fn refine_fit(
    m: RefineInputs,
    settings: &FitSettings,
    check: &ExactCheckSettings,
    refine: &RefineSettings,
    inputs: &BTreeMap<String, String>,
    progress: RefineProgress,
    resume: Option<Resume>,
) -> Result<RefinedFit> {
    let mut training: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
    let mut rounds = Vec::new();
    let mut hyper: Option<GpHyper> = None;
    let mut correction: Option<GpCorrection> = None;
    let mut error_model_seconds = 0.0;
    // The exact curve of highest exact likelihood so far, as (ln L_exact, x).
    let mut best: Option<(f64, Vec<f64>)> = None;
    let exact_like = m.likelihood.with_sigma_rel(m.exact.sigma_rel());
    let last = refine.max_rounds.max(1) - 1;
    // The error model needs at least d + 2 curves (d inputs): a check of fewer draws cannot
    // teach it, and the refinement stops there.
    let needed = m.surrogate.inputs().len() + 2;
    let stop_reason = |pass: bool, round: usize, curves: usize| -> Option<String> {
        if pass {
            None
        } else if round == last {
            Some(format!(
                "the round limit ({} rounds, --refine-rounds)",
                last + 1
            ))
        } else if curves < needed {
            Some(format!(
                "{curves} exact curves in all, the error model needs at least {needed} (--exact-draws)"
            ))
        } else {
            None
        }
    };
    for round in 0..=last {
        let saved = resume.as_ref().and_then(|r| r.saved.get(round));
        let finished = saved.filter(|s| {
            stop_reason(s.round.pass, round, training.len() + s.solved.len()).is_none()
                && !s.round.pass
        });
        let solved = if let Some(s) = finished {
            // A failed round of a previous run: its curves, no sampling.
            // Not the last round now (a run continued with more --refine-rounds): no stop.
            let info = RefineRound {
                resumed: true,
                stopped: None,
                ..s.round.clone()
            };
            (progress.round)(&info);
            rounds.push(info);
            s.solved.clone()
        } else {
            let variance_at = match (&correction, &best, refine.variance) {
                (Some(_), Some((_, x)), RefineVariance::Best) => Some(x.clone()),
                _ => None,
            };
            let corrected = match &correction {
                Some(gp) => {
                    let c = CorrectedModel::new(m.surrogate, gp.clone())?;
                    Some(match &variance_at {
                        Some(x) => c.variance_fixed_at(x),
                        None => c,
                    })
                }
                None => None,
            };
            let model: &dyn CvModel = match &corrected {
                Some(c) => c,
                None => m.surrogate,
            };
            let posterior = Posterior::new(model, m.prior, m.likelihood)?;
            let t = Instant::now();
            let mut result = fit(&posterior, settings, inputs.clone(), progress.sampling)?;
            let sampling_seconds = t.elapsed().as_secs_f64();
            (progress.sampled)(round);
            if result.samples.stop == SamplerStop::MaxSeconds {
                // The time budget (--max-seconds) ran out while sampling: the draws did not
                // converge, and the exact check (whose cost grows with the voltages) is not run
                // on them; the fit ends here, unconverged (issue 66).
                result.summary.exact_check_skipped = Some(format!(
                    "the time budget ({} s, --max-seconds) ran out while sampling in round {round}",
                    settings.sample.max_seconds
                ));
                result.summary.refinement = (!rounds.is_empty()).then(|| rounds.clone());
                return Ok(RefinedFit {
                    fit: result,
                    rounds,
                    correction,
                    training,
                });
            }
            let (mut chk, info) = match saved {
                Some(s) => {
                    let mut chk = s.check.clone();
                    chk.solved = s.solved.clone();
                    let info = RefineRound {
                        resumed: true,
                        sampling_seconds,
                        stopped: stop_reason(s.round.pass, round, training.len() + s.solved.len()),
                        ..s.round.clone()
                    };
                    (chk, info)
                }
                None => {
                    // The grid check once, on the last round's draws (below).
                    let no_grid_check = ExactCheckSettings {
                        grid_check: 0,
                        ..*check
                    };
                    let mut chk = exact_check(
                        model,
                        m.exact,
                        m.prior,
                        m.likelihood,
                        &result.samples,
                        &result.mode,
                        &no_grid_check,
                        progress.exact,
                    )?;
                    // A passing check also climbs the exact posterior from the sampler's
                    // local modes in other basins; a better basin fails it.
                    if chk.pass && check.ascents > 0 {
                        let t_ascent = Instant::now();
                        // The check's last solved curve is the mode's (when it solved).
                        let mut x_mode = vec![0.0; m.prior.input_names.len()];
                        m.prior.expand(&result.mode, &mut x_mode);
                        let mode_curve = chk
                            .solved
                            .last()
                            .filter(|(x, _)| *x == x_mode)
                            .map(|(_, c)| c.clone());
                        let (ascents, curves) = basin_ascents(
                            m.exact,
                            model,
                            m.prior,
                            m.likelihood,
                            &result,
                            mode_curve.as_deref(),
                            check.ascents,
                        )?;
                        if ascents.iter().any(|a| a.better) {
                            chk.pass = false;
                            chk.solved.extend(curves);
                        }
                        chk.ascents = ascents;
                        chk.seconds += t_ascent.elapsed().as_secs_f64();
                    }
                    let stopped = stop_reason(chk.pass, round, training.len() + chk.solved.len());
                    let done = chk.pass || stopped.is_some();
                    if done && chk.grids == ExactGrids::Mode && check.grid_check > 0 {
                        add_grid_check(&mut chk, m.exact, m.likelihood, check.grid_check)?;
                    }
                    // Before another round: exact curves at the sampler's other local modes too.
                    let t_modes = Instant::now();
                    let extra = if done {
                        Vec::new()
                    } else {
                        local_mode_curves(m, &result)?
                    };
                    let local_mode_curves = extra.len();
                    chk.seconds += t_modes.elapsed().as_secs_f64();
                    chk.solved.extend(extra);
                    let info = RefineRound {
                        round,
                        training_curves: training.len(),
                        pareto_k: chk.pareto_k,
                        max_abs_shift_sd: chk.max_abs_shift_sd,
                        max_rel_diff_at_mode: chk.max_rel_diff_at_mode,
                        pass: chk.pass,
                        sampling_seconds,
                        exact_seconds: chk.seconds,
                        error_model_seconds,
                        resumed: false,
                        stopped,
                        local_mode_curves,
                        better_basin: chk
                            .ascents
                            .iter()
                            .filter(|a| a.better)
                            .max_by(|a, b| a.ln_posterior_exact.total_cmp(&b.ln_posterior_exact))
                            .cloned(),
                        variance_at,
                    };
                    if let Some(r) = &resume {
                        r.checkpoint.save(&SavedRound {
                            fingerprint: r.checkpoint.fingerprint().to_string(),
                            round: info.clone(),
                            check: chk.clone(),
                            solved: chk.solved.clone(),
                        })?;
                    }
                    (chk, info)
                }
            };
            (progress.round)(&info);
            let done = info.pass || info.stopped.is_some() || round == last;
            rounds.push(info);
            let solved = std::mem::take(&mut chk.solved);
            result.summary.seconds += chk.seconds;
            result.summary.exact_check = Some(chk);
            if done {
                result.summary.refinement = Some(rounds.clone());
                return Ok(RefinedFit {
                    fit: result,
                    rounds,
                    correction,
                    training,
                });
            }
            solved
        };
        best = best_exact(&exact_like, best, &solved);
        // Teach the error model the new curves and fit it for the next round.
        teach(m.surrogate, &mut training, solved);
        let t_fit = Instant::now();
        let (xs, rs): (Vec<Vec<f64>>, Vec<Vec<f64>>) = training.iter().cloned().unzip();
        let gp = GpCorrection::fit(&xs, &rs, hyper.as_ref(), refine.hyper_evals)
            .map_err(|e| e.context(format!("the error model of refinement round {}", round + 1)))?;
        error_model_seconds = t_fit.elapsed().as_secs_f64();
        hyper = Some(gp.hyper.clone());
        correction = Some(gp);
    }
    unreachable!("the loop returns in its last round")
}

impl FitJob {
    /// [`refine_fit`] with the job's surrogate, exact solver, prior and likelihood; each
    /// round's check records the exact solver's tolerance, the fit the share of its draws
    /// outside the surrogate's support.
    ///
    /// # Errors
    /// As [`refine_fit`]; the exact model cannot be set up at the data's voltages.
    pub fn run_refined(
        &self,
        settings: &FitSettings,
        check: &ExactCheckSettings,
        refine: &RefineSettings,
        progress: RefineProgress,
        resume: Option<Resume>,
    ) -> Result<RefinedFit> {
        let exact = ExactModel::new(self.exact.clone(), &self.data.voltage_v)?;
        let m = RefineInputs {
            surrogate: &self.surrogate,
            exact: &exact,
            prior: &self.prior,
            likelihood: &self.likelihood,
        };
        let mut r = refine_fit(m, settings, check, refine, &self.inputs, progress, resume)?;
        r.fit.summary.posterior_outside_support = Some(self.outside_support(&r.fit.samples));
        if let Some(c) = r.fit.summary.exact_check.as_mut() {
            c.solver_tolerance = Some(self.exact.settings.grid.tolerance);
        }
        Ok(r)
    }

    /// The fingerprint of a refined fit of this job with these settings
    /// ([`super::checkpoint::fingerprint`]): its inputs with their hashes, the sampler and
    /// likelihood settings, the check's settings, the refinement's and the exact solver's
    /// (its settings and `hpge_solver::field::PHYSICS_REVISION`).
    pub fn fingerprint(
        &self,
        settings: &FitSettings,
        check: &ExactCheckSettings,
        refine: &RefineSettings,
    ) -> String {
        fingerprint(&[
            format!("{:?}", self.inputs),
            format!("{settings:?}"),
            format!("{check:?}"),
            format!("{:?}", refine.hyper_evals),
            format!("{:?}", refine.variance),
            format!("{:?}", self.exact.settings),
            hpge_solver::field::PHYSICS_REVISION.to_string(),
        ])
    }
}
