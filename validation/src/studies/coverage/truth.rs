//! One truth of a coverage study: drawn from the prior, its data simulated, fitted (the plain
//! surrogate fit, or the full pipeline of `fit`: exact check, exact ascents, refinement), and
//! ranked among the posterior draws.

use std::path::Path;
use std::time::Instant;

use hpge_inference::diagnostics::Diagnostics;
use hpge_inference::fit::{
    Checkpoint, RefineInputs, RefineProgress, RefineRound, Resume, draw_range,
    fingerprint as checkpoint_fingerprint, refine_fit,
};
use hpge_inference::summary::{interval_contains, smallest_intervals};
use hpge_inference::{CvModel, Likelihood, Posterior, Prior, fit};
use rand::RngExt;
use rand::SeedableRng;
use rand::rngs::StdRng;

use super::settings::{COVERAGE_LEVELS, CoverageSettings};
use super::store::{SecondsSplit, TruthCheck, TruthFit, TruthSampler};
use crate::error::Result;

/// The models of a study.
#[derive(Clone, Copy)]
pub struct CoverageModels<'a> {
    /// The surrogate that is fitted.
    pub fit: &'a dyn CvModel,
    /// The model that simulates the data; with refinement (`CoverageSettings::pipeline`) also
    /// the exact check's reference (the exact solver).
    pub data: &'a dyn CvModel,
    /// The relative model error drawn into the data: 0 for exact-solver data, the surrogate's
    /// sigma_p for surrogate data (a data model with a per-point uncertainty then draws its
    /// model error with that instead, as the likelihood assumes it).
    pub data_sigma_rel: f64,
}

/// What a truth's full-pipeline fit reports as it goes: with exact data one truth takes minutes
/// to hours, most of it in the exact check's curves.
#[derive(Debug, Clone, Copy)]
pub enum TruthEvent<'a> {
    /// A round's sampling ended and its exact check starts.
    Sampled {
        /// The round (0: the plain surrogate).
        round: usize,
    },
    /// Exact curves of the running check done, of `total`.
    Exact {
        /// Curves done.
        done: usize,
        /// Curves of this check.
        total: usize,
    },
    /// A round ended (taken back from a saved round, or run).
    Round(&'a RefineRound),
}

/// Receives truth `i`'s events ([`TruthEvent`]).
pub type TruthEvents<'a> = &'a (dyn Fn(usize, TruthEvent) + Sync);

/// What a truth's fit is tied to outside itself: the study's fingerprint, the folder its
/// finished rounds go to (None: not written) and where its events go.
#[derive(Clone, Copy)]
pub(super) struct TruthIo<'a> {
    pub(super) fingerprint: &'a str,
    pub(super) rounds: Option<&'a Path>,
    pub(super) events: TruthEvents<'a>,
}

/// The seed of truth `i`'s draw and noise (the fit uses seed + i + 1).
fn truth_seed(seed: u64, i: usize) -> u64 {
    seed.wrapping_mul(0x2545_F491_4F6C_DD1D) ^ i as u64
}

/// Truth `i` of the study: drawn, simulated, fitted and ranked. A truth whose data curve fails
/// recoverably comes back with `skipped` set. With the full pipeline and a `rounds` folder in `io`
/// the fit writes each finished round there and takes back those an interrupted run of the same
/// study and truth left (`hpge_inference::fit::Checkpoint`; the seeded sampler makes the
/// result the same as an uninterrupted fit's); its rounds and exact curves go to `io.events`
/// as they finish.
///
/// # Errors
/// Any other model error, a fit or refinement that fails.
pub(super) fn fit_truth(
    i: usize,
    models: CoverageModels,
    prior: &Prior,
    template: &Likelihood,
    settings: &CoverageSettings,
    io: TruthIo,
) -> Result<TruthFit> {
    let TruthIo {
        fingerprint,
        rounds,
        events,
    } = io;
    let start = Instant::now();
    let nv = template.len();
    let mut rng = StdRng::seed_from_u64(truth_seed(settings.seed, i));
    let truth = prior.sample(&mut rng);
    let mut record = TruthFit {
        fingerprint: fingerprint.to_string(),
        index: i,
        truth: truth.clone(),
        skipped: None,
        ranks: Vec::new(),
        jitter: Vec::new(),
        inside: Vec::new(),
        converged: false,
        sampler: None,
        check: None,
        seconds: 0.0,
    };
    let mut x = vec![0.0; prior.input_names.len()];
    prior.expand(&truth, &mut x);
    let mut c = vec![0.0; nv];
    match models.data.curve(&x, &mut c) {
        Ok(()) => {}
        Err(e) if e.is_recoverable() => {
            record.skipped = Some(e.to_string());
            record.seconds = start.elapsed().as_secs_f64();
            return Ok(record);
        }
        Err(e) => return Err(e.into()),
    }
    let c_m = if models.data_sigma_rel > 0.0 && models.data.has_point_variance() {
        let mut var = vec![0.0; nv];
        models.data.curve_variance(&x, &mut var, None)?;
        template.simulate_var(&c, &var, &mut rng)
    } else {
        template
            .with_sigma_rel(models.data_sigma_rel)
            .simulate(&c, &mut rng)
    };
    let like = template.with_data(c_m);
    let mut fs = settings.fit;
    fs.sample.seed = settings.seed.wrapping_add(i as u64 + 1);
    fs.predictive_draws = 10;
    fs.mode_draws = 200;
    let f = match &settings.pipeline {
        None => {
            let posterior = Posterior::new(models.fit, prior, &like)?;
            fit(&posterior, &fs, Default::default(), &|_| {})?
        }
        Some(p) => {
            let m = RefineInputs {
                surrogate: models.fit,
                exact: models.data,
                prior,
                likelihood: &like,
            };
            // The study's run and the truth: rounds of another run or truth are cleared.
            let checkpoint = match rounds {
                Some(dir) => {
                    std::fs::create_dir_all(dir).map_err(|e| hpge_inference::Error::Io {
                        file: dir.to_path_buf(),
                        action: "cannot create the folder",
                        source: e,
                    })?;
                    let run =
                        checkpoint_fingerprint(&[fingerprint.to_string(), format!("truth {i}")]);
                    Some(Checkpoint::open(dir, run)?)
                }
                None => None,
            };
            let (checkpoint, saved) = checkpoint.unzip();
            let resume = checkpoint.as_ref().map(|checkpoint| Resume {
                saved: saved.unwrap_or_default(),
                checkpoint,
            });
            let sampled = |round| events(i, TruthEvent::Sampled { round });
            let exact = |done, total| events(i, TruthEvent::Exact { done, total });
            let round = |r: &RefineRound| events(i, TruthEvent::Round(r));
            let progress = RefineProgress {
                sampled: &sampled,
                exact: &exact,
                round: &round,
                ..RefineProgress::quiet()
            };
            let r = refine_fit(
                m,
                &fs,
                &p.check,
                &p.refine,
                &Default::default(),
                progress,
                resume,
            )?;
            record.check = r.fit.summary.exact_check.as_ref().map(|c| TruthCheck {
                pass: c.pass,
                rounds: r.rounds.len(),
                pareto_k: c.pareto_k,
                max_abs_shift_sd: c.max_abs_shift_sd,
                seconds_split: r.rounds.iter().map(SecondsSplit::of).reduce(|a, b| a + b),
            });
            r.fit
        }
    };
    let all = f.samples.all();
    let l = settings.ranks;
    let idx: Vec<usize> = (0..l).map(|k| k * all.len() / l).collect();
    for (j, p) in prior.parameters.iter().enumerate() {
        record
            .ranks
            .push(idx.iter().filter(|&&k| all[k][j] < truth[j]).count());
        record.jitter.push(rng.random::<f64>());
        let draws: Vec<f64> = all.iter().map(|t| t[j]).collect();
        let range = draw_range(&draws, p.support);
        // As the fit's summary: the histogram's noise is that of the chains' effective draws.
        let dg = f.samples.diagnostics[j];
        let ess = dg.ess_min();
        let si = smallest_intervals(&draws, None, Some(ess), range, fs.bins, &COVERAGE_LEVELS);
        record.inside.push(
            si.iter()
                .map(|iv| interval_contains(iv, truth[j]))
                .collect(),
        );
    }
    record.converged = f.summary.converged;
    let (rhat_max, ess_min) = Diagnostics::worst(&f.samples.diagnostics);
    record.sampler = Some(TruthSampler {
        stop: f.samples.stop,
        draws_per_chain: f.samples.chains.first().map_or(0, |c| c.theta.len()),
        rhat_max,
        ess_min,
    });
    record.seconds = start.elapsed().as_secs_f64();
    Ok(record)
}
