//! Bayesian fits and model discovery from Python.

use std::path::PathBuf;

use hpge_inference::fit::{FitJob, FitOptions, outputs};
use numpy::PyArray3;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::progress::{DiscoverProgress, FitProgress, Progress, progress_arg};
use crate::{HpgeError, array, err, json_to_py, matrix};

/// The posterior of an impurity model given a measured C-V curve, as `hpge-cv fit` (paper,
/// section 8): the same library path (`FitJob`), so the same seed gives the same numbers.
///
/// Arguments (defaults: the command line's, relative to the working directory): `data` (C-V
/// CSV), `model` (surrogate), `prior` (TOML), `detector` (TOML), `seed`, `sampler`
/// ("metropolis" or "nuts"), `likelihood` ("auto", the default: the measured covariance
/// where the curve has one, else "paper"; or "paper", "covariance"), `chains`, `ess`, `rhat`,
/// `max_seconds` (s), `exact_check` (re-weight `exact_draws` draws with the field solver; off by
/// default here, on in the command line; `exact_grids` "mode" or "own" and `exact_grid_check`,
/// as `--exact-grids` and `--exact-grid-check`; while the check fails, up to `refine_rounds`
/// rounds of posterior-adaptive refinement, as `--refine-rounds`, the refined likelihood's
/// variance `refine_variance` "best" or "local", as `--refine-variance`),
/// `out` (a folder: also write every file and figure
/// `hpge-cv fit --out` writes), `progress`, `extrapolate` (fit a curve with voltages outside the
/// surrogate's support, as `--extrapolate`), `constant_sigma` (the model's constant sigma_p in
/// the likelihood even where its file has a calibrated per-point sigma_s, as `--constant-sigma`),
/// `exact_ascents` (after a passing check, climb the exact posterior from this many local modes
/// in other basins, as `--exact-ascents`), `force` (replace the fit of another run in `out`, as
/// `--force`; without it such a folder is refused).
///
/// Returns a dict: `summary` (the `summary.json` object as a dict), `names` (parameters),
/// `draws` (array [chain, draw, parameter] in the prior's units), `ln_posterior` ([chain, draw]),
/// `mode` (the global mode). The GIL is released while sampling.
#[pyfunction]
#[pyo3(signature = (
    data=None, model=None, prior=None, detector=None, seed=None, sampler=None, likelihood=None,
    chains=None, ess=None, rhat=None, max_seconds=None, exact_check=false, exact_draws=None,
    out=None, progress=None, extrapolate=false, exact_grids=None, exact_grid_check=None,
    refine_rounds=None, constant_sigma=false, exact_ascents=None, refine_variance=None,
    force=false
))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn fit<'py>(
    py: Python<'py>,
    data: Option<PathBuf>,
    model: Option<PathBuf>,
    prior: Option<PathBuf>,
    detector: Option<PathBuf>,
    seed: Option<u64>,
    sampler: Option<String>,
    likelihood: Option<String>,
    chains: Option<usize>,
    ess: Option<f64>,
    rhat: Option<f64>,
    max_seconds: Option<f64>,
    exact_check: bool,
    exact_draws: Option<usize>,
    out: Option<PathBuf>,
    progress: Option<Bound<'py, PyAny>>,
    extrapolate: bool,
    exact_grids: Option<String>,
    exact_grid_check: Option<usize>,
    refine_rounds: Option<usize>,
    constant_sigma: bool,
    exact_ascents: Option<usize>,
    refine_variance: Option<String>,
    force: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let d = FitOptions::default();
    let o = FitOptions {
        data: data.unwrap_or(d.data),
        model: model.unwrap_or(d.model),
        prior: prior.unwrap_or(d.prior),
        detector: detector.unwrap_or(d.detector),
        out: out.clone(),
        sampler: sampler.unwrap_or(d.sampler),
        seed: seed.unwrap_or(d.seed),
        no_exact_check: !exact_check,
        exact_draws: exact_draws.unwrap_or(d.exact_draws),
        exact_grids: exact_grids.unwrap_or(d.exact_grids),
        exact_grid_check: exact_grid_check.unwrap_or(d.exact_grid_check),
        exact_ascents: exact_ascents.unwrap_or(d.exact_ascents),
        refine_rounds: refine_rounds.unwrap_or(d.refine_rounds),
        refine_variance: refine_variance.unwrap_or(d.refine_variance),
        likelihood: likelihood.unwrap_or(d.likelihood),
        chains: chains.unwrap_or(d.chains),
        ess: ess.unwrap_or(d.ess),
        rhat: rhat.unwrap_or(d.rhat),
        max_seconds: max_seconds.unwrap_or(d.max_seconds),
        extrapolate,
        constant_sigma,
        force,
        ..d
    };
    let progress = progress_arg(progress, "fit")?;
    let (fit, summary) = if out.is_some() {
        let observer = FitProgress(progress);
        let run = py
            .detach(|| hpge_reports::fit::run_fit(&o, &observer))
            .map_err(err)?;
        (run.fit, run.summary_json)
    } else {
        py.detach(|| -> Result<_, hpge_inference::Error> {
            o.sampler_kind()?;
            let job = FitJob::from_files(&o.files(), o.noise()?, &o.grid)?;
            if let Some(w) = job.voltage_support_guard(o.extrapolate, "extrapolate=True")? {
                eprintln!("hpge_cv: warning: {w}");
            }
            let settings = o.settings()?;
            let sampling = |s: &hpge_inference::Status| {
                if let Progress::Stderr(_) = progress {
                    eprintln!(
                        "hpge_cv: fit [{:6.1} s] {:?}: R-hat {:.4}, min ESS {:.0}, acceptance {:.2}",
                        s.seconds, s.phase, s.rhat_max, s.ess_min, s.acceptance
                    );
                } else {
                    progress.report(s.draws, 0);
                }
            };
            let fit = if o.no_exact_check {
                job.run(&settings, &sampling)?
            } else {
                job.run_refined(
                    &settings,
                    &o.exact_check()?,
                    &o.refine()?,
                    hpge_inference::fit::RefineProgress {
                        sampling: &sampling,
                        sampled: &|_| {},
                        exact: &|done, total| progress.report(done, total),
                        round: &|r| {
                            if let Progress::Stderr(_) = progress {
                                eprintln!(
                                    "hpge_cv: refinement round {}: k-hat {:.2}, largest shift {:.2} sd, {}",
                                    r.round,
                                    r.pareto_k,
                                    r.max_abs_shift_sd,
                                    if r.pass { "pass" } else { "fail" }
                                );
                            }
                        },
                    },
                    None,
                )?
                .fit
            };
            let summary = outputs::summary_json(&fit, None)?;
            Ok((fit, summary))
        })
        .map_err(err)?
    };
    let r = PyDict::new(py);
    r.set_item("summary", json_to_py(py, &summary)?)?;
    r.set_item("names", fit.samples.names.clone())?;
    let draws: Vec<Vec<Vec<f64>>> = fit.samples.chains.iter().map(|c| c.theta.clone()).collect();
    r.set_item(
        "draws",
        PyArray3::from_vec3(py, &draws).map_err(|e| HpgeError::new_err(format!("draws: {e}")))?,
    )?;
    let lp: Vec<Vec<f64>> = fit
        .samples
        .chains
        .iter()
        .map(|c| c.ln_posterior.clone())
        .collect();
    r.set_item("ln_posterior", matrix(py, &lp)?)?;
    r.set_item("mode", array(py, fit.mode.clone()))?;
    Ok(r)
}

/// Model discovery, as `hpge-cv discover` (issue 9): fits the start model, finds windows of
/// same-sign residuals, scores the catalogue of extensions by Laplace Bayes factors, fits the
/// best.
///
/// Arguments (defaults: the command line's, relative to the working directory): `data`,
/// `model`, `detector`, `start_model` (a prior file or a name in priors/, default "b-z"),
/// `only` (catalogue entries, e.g. ["radial"]), `seed`, `ess`, `max_seconds` (sampling budget of
/// each MCMC fit, s: a fit that reaches it stops at a number of draws that depends on the
/// machine's speed; pass a large value for results that depend on the seed alone),
/// `min_ln_bayes` (smallest ln Bayes factor for an extension to be added), `surrogate_only`
/// (leave out the exact-solver extensions, which are slow), `out` (a folder: also write
/// `discovery.json`, `residuals.csv`, `report.md` and the figures there; a folder holding the
/// discovery of another run is refused unless `force`, as `--force`), `progress`.
///
/// Returns the summary (`discovery.json`'s object) as a dict. The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (
    data=None, model=None, detector=None, start_model=None, only=None, seed=None, ess=None,
    max_seconds=None, min_ln_bayes=None, surrogate_only=false, out=None, progress=None,
    force=false
))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn discover<'py>(
    py: Python<'py>,
    data: Option<PathBuf>,
    model: Option<PathBuf>,
    detector: Option<PathBuf>,
    start_model: Option<String>,
    only: Option<Vec<String>>,
    seed: Option<u64>,
    ess: Option<f64>,
    max_seconds: Option<f64>,
    min_ln_bayes: Option<f64>,
    surrogate_only: bool,
    out: Option<PathBuf>,
    progress: Option<Bound<'py, PyAny>>,
    force: bool,
) -> PyResult<Bound<'py, PyAny>> {
    use hpge_inference::discover::DiscoverOptions;
    let mut o = DiscoverOptions::default();
    if let Some(d) = data {
        o.workflow.data = d;
    }
    if let Some(m) = model {
        o.workflow.model = m;
    }
    if let Some(d) = detector {
        o.workflow.detector = d;
    }
    if let Some(s) = start_model {
        o.start_model = s;
    }
    if let Some(v) = only {
        o.workflow.only = v;
    }
    if let Some(s) = seed {
        o.seed = s;
    }
    if let Some(e) = ess {
        o.workflow.ess = e;
    }
    if let Some(s) = max_seconds {
        o.max_seconds = s;
    }
    if let Some(b) = min_ln_bayes {
        o.min_ln_bayes = b;
    }
    o.surrogate_only = surrogate_only;
    o.out = out.clone();
    o.workflow.no_plots = out.is_none();
    let progress = DiscoverProgress(progress_arg(progress, "discover")?);
    let summary = py.detach(|| -> PyResult<serde_json::Value> {
        let w = &o.workflow;
        w.check_only().map_err(err)?;
        let prior_file = o.start_prior().map_err(err)?;
        let noise = hpge_inference::fit::noise_settings(
            hpge_inference::posterior::NoiseKind::Paper.as_str(),
        )
        .map_err(err)?;
        let files = hpge_inference::fit::FitFiles {
            data: w.data.clone(),
            model: w.model.clone(),
            prior: prior_file.clone(),
            detector: w.detector.clone(),
        };
        let s = FitJob::from_files(&files, noise, &w.grid).map_err(err)?;
        let spec = hpge_inference::PriorSpec::from_file(&prior_file).map_err(err)?;
        let settings = o.settings(noise).map_err(err)?;
        let dir = out.as_ref().map(|_| o.out_dir(&prior_file));
        let d = hpge_reports::discover::run_discover(
            &s,
            &spec,
            &prior_file,
            &settings,
            dir.as_deref(),
            w.no_plots,
            force,
            &progress,
        )
        .map_err(err)?;
        serde_json::to_value(&d.summary).map_err(err)
    })?;
    json_to_py(py, &summary)
}
