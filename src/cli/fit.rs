//! `hpge-cv fit`: the posterior of an impurity model given a measured C-V curve (paper, section
//! 8), with the files, figures and report a physicist reads.

use std::path::Path;

use anyhow::Result;
use hpge_inference::fit::FitSummary;
use hpge_inference::fit::{FitFiles, FitJob, RefineRound};
use hpge_inference::sampler::Phase;
use hpge_inference::{CvModel, FitSettings, Status};
use hpge_reports::fit::{FitObserver, FitRun, run_fit, summary_text};
use indicatif::{ProgressBar, ProgressStyle};

/// A fit that did not reach its convergence targets (exit code 3).
#[derive(Debug, thiserror::Error)]
#[error(
    "the fit did not converge ({0}); the outputs are written, but treat them with care. Run longer (--max-seconds), or pass --allow-unconverged"
)]
pub struct Unconverged(pub String);

/// A fit whose exact-solver check still fails after refinement (exit code 4).
#[derive(Debug, thiserror::Error)]
#[error(
    "the exact-solver check failed ({0}); the outputs are written, but the surrogate's posterior is not the exact solver's. Refine longer (--refine-rounds), check more draws (--exact-draws), or pass --allow-exact-mismatch"
)]
pub struct ExactMismatch(pub String);

/// A validation study that ran to the end and failed its own criteria (exit code 1; the
/// report, already written, says where).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct StudyFailed(pub String);

pub use hpge_inference::fit::FitOptions;

/// Everything a fit was set up from (the library's fit job).
pub type Setup = FitJob;

/// Reads and checks data, model, prior and detector against each other ([`FitJob::from_files`]),
/// printing the job's warnings.
pub fn setup(
    data: &Path,
    model: &Path,
    prior: &Path,
    detector: &Path,
    noise: hpge_inference::NoiseSettings,
    grid: &super::args::GridArgs,
) -> Result<Setup> {
    let files = FitFiles {
        data: data.to_path_buf(),
        model: model.to_path_buf(),
        prior: prior.to_path_buf(),
        detector: detector.to_path_buf(),
    };
    let job = FitJob::from_files(&files, noise, grid)?;
    for w in &job.warnings {
        eprintln!("warning: {w}");
    }
    Ok(job)
}

/// A progress line on stderr: a spinner on a terminal, one line per update otherwise.
pub fn progress_printer(quiet: bool) -> (ProgressBar, impl Fn(&Status) + Sync) {
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new_spinner()
    };
    bar.set_style(
        ProgressStyle::with_template("{spinner} {elapsed} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    let lines = !quiet && !std::io::IsTerminal::is_terminal(&std::io::stderr());
    let b = bar.clone();
    let f = move |s: &Status| {
        let msg = match s.phase {
            Phase::Tuning => format!(
                "tuning cycle {}: acceptance {:.2}, R-hat {:.3}",
                s.cycle, s.acceptance, s.rhat_max
            ),
            Phase::Sampling => format!(
                "sampling: {} draws per chain, R-hat {:.4}, min ESS {:.0}, acceptance {:.2}",
                s.draws, s.rhat_max, s.ess_min, s.acceptance
            ),
        };
        if lines {
            eprintln!("[{:6.1} s] {msg}", s.seconds);
        } else {
            b.set_message(msg);
            b.tick();
        }
    };
    (bar, f)
}

/// The fit's progress on stderr: the job's warnings and a one-line description, the sampling
/// spinner (one line per update when stderr is not a terminal), the exact check's bar.
/// The sampling spinner and the function that updates it.
type Spinner = (ProgressBar, Box<dyn Fn(&Status) + Sync + Send>);

struct Display {
    sampling: std::sync::Mutex<Option<Spinner>>,
    exact: std::sync::Mutex<Option<ProgressBar>>,
}

impl FitObserver for Display {
    fn setup_done(&self, job: &FitJob, o: &FitOptions, settings: &FitSettings) {
        for w in &job.warnings {
            eprintln!("warning: {w}");
        }
        eprintln!(
            "fitting {} ({} voltages) with {} and the prior {} ({} parameters), {} sampler, {} chains, seed {}",
            o.data.display(),
            job.data.voltage_v.len(),
            job.surrogate.describe(),
            o.prior.display(),
            job.prior.dim(),
            settings.sample.sampler.as_str(),
            settings.sample.chains,
            o.seed
        );
        let (bar, f) = progress_printer(false);
        if let Ok(mut g) = self.sampling.lock() {
            *g = Some((bar, Box::new(f)));
        }
    }
    fn sampling(&self, status: &Status) {
        if let Ok(mut g) = self.sampling.lock() {
            // A refinement round samples again: a new spinner.
            let (_, f) = g.get_or_insert_with(|| {
                let (bar, f) = progress_printer(false);
                (bar, Box::new(f))
            });
            f(status);
        }
    }
    fn sampling_done(&self) {
        if let Ok(mut g) = self.sampling.lock()
            && let Some((bar, _)) = g.take()
        {
            bar.finish_and_clear();
        }
    }
    fn exact_start(&self, draws: usize) {
        let pb = ProgressBar::new(draws as u64 + 1);
        pb.set_style(
            ProgressStyle::with_template("exact check {bar:30} {pos}/{len} curves, {elapsed}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        if let Ok(mut g) = self.exact.lock() {
            *g = Some(pb);
        }
    }
    fn exact_progress(&self, done: usize, _total: usize) {
        if let Ok(g) = self.exact.lock()
            && let Some(pb) = g.as_ref()
        {
            pb.set_position(done as u64);
        }
    }
    fn exact_done(&self) {
        if let Ok(mut g) = self.exact.lock()
            && let Some(pb) = g.take()
        {
            pb.finish_and_clear();
        }
    }
    fn round_done(&self, r: &RefineRound) {
        eprintln!("{}", round_text(r));
    }
}

/// A Pareto k-hat as printed: NaN (fewer draws than PSIS fits a tail to) says why.
fn k_hat(k: f64) -> String {
    if k.is_nan() {
        format!(
            "undefined (PSIS needs at least {} draws, --exact-draws)",
            hpge_inference::summary::PSIS_MIN_DRAWS
        )
    } else {
        format!("{k:.2}")
    }
}

/// One line per refinement round.
fn round_text(r: &RefineRound) -> String {
    let model = if r.round == 0 {
        "surrogate".to_string()
    } else {
        format!("surrogate corrected by {} exact curves", r.training_curves)
    };
    format!(
        "round {} ({model}): exact check k-hat {}, largest mean shift {:.2} sd, {:.2}% off at the mode: {} (sampling {:.1} s, exact check {:.1} s){}",
        r.round,
        k_hat(r.pareto_k),
        r.max_abs_shift_sd,
        100.0 * r.max_rel_diff_at_mode,
        if r.pass { "pass" } else { "fail" },
        r.sampling_seconds,
        r.exact_seconds,
        if r.resumed {
            "; taken back from an interrupted run (OUT/rounds/)"
        } else {
            ""
        }
    ) + &(if r.local_mode_curves > 0 {
        format!(
            "; {} more exact curves at other local modes for the error model",
            r.local_mode_curves
        )
    } else {
        String::new()
    }) + &r.better_basin.as_ref().map_or(String::new(), |b| {
        format!(
            "; an exact ascent from a local mode ended in another basin at {:?}, exact ln p {:.2} above the fit's mode",
            b.theta
                .iter()
                .map(|t| (t * 1e4).round() / 1e4)
                .collect::<Vec<_>>(),
            b.ln_posterior_exact - b.ln_posterior_exact_at_mode
        )
    }) + &r
        .stopped
        .as_ref()
        .map_or(String::new(), |s| format!("; refinement stopped: {s}"))
}

/// Runs `fit` ([`hpge_reports::fit::run_fit`]) with progress on stderr: `print_json` prints
/// the summary as one JSON object; `allow_unconverged` exits with 0 when the convergence
/// targets were not reached.
pub fn run(o: &FitOptions, print_json: bool, allow_unconverged: bool) -> Result<()> {
    let display = Display {
        sampling: std::sync::Mutex::new(None),
        exact: std::sync::Mutex::new(None),
    };
    let run = run_fit(o, &display)?;
    let sm = &run.fit.summary;
    if print_json {
        outln!("{}", serde_json::to_string(&run.summary_json)?);
    } else {
        out!("{}", summary_text(&run.fit, &run.out));
    }
    if !sm.converged {
        let msg = unconverged_text(sm);
        if allow_unconverged {
            eprintln!("warning: the fit did not converge ({msg})");
        } else {
            return Err(Unconverged(msg).into());
        }
    }
    if let Some(c) = &sm.exact_check
        && !c.pass
    {
        let rounds = sm.refinement.as_ref().map_or(1, Vec::len);
        let msg = format!(
            "Pareto k-hat {} against its limit {:.2} for {} draws (log ratios' range {:.2}; \
             near-equal weights, within a range of ln 2, would pass), largest mean shift {:.2} sd \
             after {rounds} round(s)",
            k_hat(c.pareto_k),
            c.k_hat_limit,
            c.draws,
            c.log_ratio_range,
            c.max_abs_shift_sd
        );
        if o.allow_exact_mismatch {
            eprintln!("warning: the exact-solver check failed ({msg})");
        } else {
            return Err(ExactMismatch(msg).into());
        }
    }
    Ok(())
}

/// Why a fit did not converge: the largest R-hat, the smallest bulk ESS, the stop reason.
fn unconverged_text(sm: &FitSummary) -> String {
    let worst = sm
        .parameters
        .iter()
        .max_by(|a, b| a.rhat.total_cmp(&b.rhat))
        .map(|p| {
            format!(
                "largest R-hat {:.4} ({}), smallest bulk ESS {:.0}",
                p.rhat,
                p.name,
                sm.parameters
                    .iter()
                    .map(|p| p.ess_bulk)
                    .fold(f64::INFINITY, f64::min)
            )
        })
        .unwrap_or_default();
    format!("{worst}; stopped: {:?}", sm.stop)
}

/// The display of `report paper`'s fits: the fit's progress, then its summary on stdout and a
/// warning when it did not converge (as `fit --allow-unconverged` prints them).
pub struct ReportDisplay(Display);

impl ReportDisplay {
    /// A display on stderr and stdout.
    pub fn new() -> Self {
        ReportDisplay(Display {
            sampling: std::sync::Mutex::new(None),
            exact: std::sync::Mutex::new(None),
        })
    }
}

impl FitObserver for ReportDisplay {
    fn setup_done(&self, job: &FitJob, o: &FitOptions, settings: &FitSettings) {
        self.0.setup_done(job, o, settings);
    }
    fn sampling(&self, status: &Status) {
        self.0.sampling(status);
    }
    fn sampling_done(&self) {
        self.0.sampling_done();
    }
    fn exact_start(&self, draws: usize) {
        self.0.exact_start(draws);
    }
    fn exact_progress(&self, done: usize, total: usize) {
        self.0.exact_progress(done, total);
    }
    fn exact_done(&self) {
        self.0.exact_done();
    }
    fn round_done(&self, r: &RefineRound) {
        self.0.round_done(r);
    }
    fn finished(&self, run: &FitRun) {
        // An observer cannot fail the report: a stdout that cannot be written is a warning.
        if let Err(e) =
            super::stdout::write_fmt(format_args!("{}", summary_text(&run.fit, &run.out)))
            && !e.broken_pipe()
        {
            eprintln!("warning: {e}");
        }
        if !run.fit.summary.converged {
            eprintln!(
                "warning: the fit did not converge ({})",
                unconverged_text(&run.fit.summary)
            );
        }
    }
}
