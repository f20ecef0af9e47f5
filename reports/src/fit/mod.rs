//! A whole fit as the command line runs it: the job set up from its files, sampled, checked
//! against the exact solver, and written out (the tables, the figures, `report.md` and
//! `summary.json`), with hooks for progress display.

mod report;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use hpge_inference::fit::{
    Checkpoint, ExactGrids, FitJob, FitOptions, RefineProgress, RefineRound, Resume, TruthRecord,
    outputs, read_truth, truth_records,
};
use hpge_inference::{Fit, FitSettings, Status};

pub use report::write_report;

use crate::{Error, Result, plot};

/// What a display of a running fit sees (every method has an empty default).
pub trait FitObserver: Sync {
    /// The job is set up (its warnings are in `job.warnings`) and sampling starts.
    fn setup_done(&self, _job: &FitJob, _options: &FitOptions, _settings: &FitSettings) {}
    /// A sampling status update.
    fn sampling(&self, _status: &Status) {}
    /// Sampling ended.
    fn sampling_done(&self) {}
    /// The exact-solver check of `draws` draws starts.
    fn exact_start(&self, _draws: usize) {}
    /// Curves done of the exact-solver check.
    fn exact_progress(&self, _done: usize, _total: usize) {}
    /// The exact-solver check ended.
    fn exact_done(&self) {}
    /// A round of refinement ended (its check included); the next samples again unless it
    /// passed or was the last.
    fn round_done(&self, _round: &RefineRound) {}
    /// The fit is written (called by `report paper`'s fit steps, which show the result).
    fn finished(&self, _run: &FitRun) {}
}

/// An observer that shows nothing.
pub struct Quiet;
impl FitObserver for Quiet {}

/// A finished fit with everything it wrote.
pub struct FitRun {
    /// The job it ran.
    pub job: FitJob,
    /// The samples and the summary.
    pub fit: Fit,
    /// The output folder.
    pub out: PathBuf,
    /// `summary.json` as written (with `truth` where a truth file was given).
    pub summary_json: serde_json::Value,
}

/// Runs a fit as `hpge-cv fit` does: set up from the files in `o`, sample, the exact-solver
/// check unless `o.no_exact_check`, then writes every output into `o.out_dir()`.
///
/// # Errors
/// Every input the job refuses (see [`FitJob::from_files`]), an output folder that cannot be
/// made, and writing failures, each naming its file.
pub fn run_fit(o: &FitOptions, observer: &dyn FitObserver) -> Result<FitRun> {
    // Every check before the output folder is made: a refused fit leaves nothing behind.
    let settings = o.settings()?;
    let noise = o.noise()?;
    let mut job = FitJob::from_files(&o.files(), noise, &o.grid)?;
    if let Some(w) = job.voltage_support_guard(o.extrapolate, "--extrapolate")? {
        job.warnings.push(w);
    }
    let truth = match &o.truth {
        Some(p) => Some(read_truth(p, &job.prior).map_err(|e| Error::from(e).context("--truth"))?),
        None => None,
    };
    job.posterior()?;
    if !o.no_exact_check && o.exact_draws < hpge_inference::summary::PSIS_MIN_DRAWS {
        job.warnings.push(format!(
            "--exact-draws {}: PSIS estimates its Pareto k-hat from {} draws or more; with fewer \
             k-hat is undefined and the exact check passes only on near-equal weights (it still \
             reports each mean's shift)",
            o.exact_draws,
            hpge_inference::summary::PSIS_MIN_DRAWS
        ));
    }
    let out = o.out_dir();
    // No output of the fit over one of its inputs (issue 66).
    let mut inputs: Vec<(&str, &Path)> = vec![
        ("--data", o.data.as_path()),
        ("--model", o.model.as_path()),
        ("--prior", o.prior.as_path()),
        ("--detector", o.detector.as_path()),
    ];
    if let Some(t) = &o.truth {
        inputs.push(("--truth", t.as_path()));
    }
    for name in [
        "summary.json",
        "samples.csv",
        "predictive.csv",
        "zeta-mode.csv",
        "report.md",
        outputs::ERROR_MODEL_FILE,
        "figures",
        "rounds",
    ] {
        if let Some((flag, input)) = hpge_files::first_overlap(&out.join(name), &inputs) {
            return Err(Error::Output {
                flag: "--out".into(),
                file: out.clone(),
                message: format!(
                    "the fit's {name} there would be written over the input {flag} {}; choose \
                     another folder",
                    input.display()
                ),
            });
        }
    }
    // A folder holding another run's fit is refused unless `--force` (issue 69).
    if let Some(w) = crate::replace::check_replace(
        &out.join("summary.json"),
        &run_record(o, &job, &settings),
        &describe_run,
        o.force,
    )? {
        job.warnings.push(w);
    }
    // A folder this fit makes is removed again when it fails before its outputs are in place (a
    // full disk, issue 66), unless it holds finished rounds to resume from.
    let mut made =
        hpge_files::NewFolder::create(&out, |d| hpge_files::has_entries(&d.join("rounds")))
            .map_err(|e| Error::Output {
                flag: "--out".into(),
                file: out.clone(),
                message: format!("cannot create the folder: {e}"),
            })?;
    // One writer per folder, until the last file is written.
    let _lock = hpge_inference::fit::lock_output(&out)?;
    observer.setup_done(&job, o, &settings);
    let (fit, correction) = if o.no_exact_check {
        let fit = job.run(&settings, &|s| observer.sampling(s))?;
        observer.sampling_done();
        (fit, None)
    } else {
        let (check, refine) = (o.exact_check()?, o.refine()?);
        // Rounds an interrupted run of the same fit finished (OUT/rounds/), taken back.
        let (checkpoint, saved) =
            Checkpoint::open(&out, job.fingerprint(&settings, &check, &refine))?;
        let refined = job.run_refined(
            &settings,
            &check,
            &refine,
            RefineProgress {
                sampling: &|s| observer.sampling(s),
                sampled: &|_| {
                    observer.sampling_done();
                    observer.exact_start(o.exact_draws);
                },
                exact: &|done, total| observer.exact_progress(done, total),
                round: &|r| {
                    observer.exact_done();
                    observer.round_done(r);
                },
            },
            Some(Resume {
                saved,
                checkpoint: &checkpoint,
            }),
        )?;
        let file = refined.correction.as_ref().map(|_| {
            outputs::ErrorModelFile::new(&job, &refined.training, refined.correction.as_ref())
        });
        (refined.fit, file)
    };
    // The outputs of this run, each written under a temporary name and put in place together
    // at the end (issue 66): a failing step or a kill leaves all of them or none. The rounds
    // (OUT/rounds/) stay, for a rerun to take back.
    let mut staged = hpge_files::Staged::new();
    if let Some(file) = &correction {
        let path = staged.path(&out.join(outputs::ERROR_MODEL_FILE));
        outputs::write_error_model(&path, file)?;
    }
    let records = truth.as_ref().map(|t| truth_records(&fit.summary, t));
    write_outputs(
        o,
        &out,
        &mut staged,
        &job,
        &fit,
        truth.as_deref(),
        records.as_deref(),
    )?;
    let mut summary_json = outputs::summary_json(&fit, records.as_deref())?;
    if let Some(obj) = summary_json.as_object_mut() {
        obj.insert("run".into(), o.run_args().into());
    }
    let path = staged.path(&out.join("summary.json"));
    outputs::write_summary(&path, &summary_json)?;
    staged.commit().map_err(|(file, source)| Error::Io {
        file,
        action: "cannot write",
        source,
    })?;
    made.keep();
    // An error model of an earlier run in this folder that this run did not replace.
    if correction.is_none() {
        let stale = out.join(outputs::ERROR_MODEL_FILE);
        if stale.is_file() {
            std::fs::remove_file(&stale).map_err(Error::io(&stale, "cannot remove"))?;
        }
    }
    Ok(FitRun {
        job,
        fit,
        out,
        summary_json,
    })
}

/// What identifies a fit in its `summary.json`: its inputs with their hashes, the sampler's
/// settings and the command line without the output folder (`run`, [`FitOptions::run_args`]).
pub fn run_record(o: &FitOptions, job: &FitJob, settings: &FitSettings) -> serde_json::Value {
    serde_json::json!({
        "inputs": job.inputs,
        "settings": settings.sample,
        "run": o.run_args(),
    })
}

/// A fit's record ([`run_record`], or a `summary.json`) in a few words.
pub fn describe_run(v: &serde_json::Value) -> String {
    use crate::replace::{text_at, value_at};
    format!(
        "prior {}, model {} (hash {}), data {} (hash {}); {} sampler, seed {}, ESS {}{}",
        text_at(v, "/inputs/prior"),
        text_at(v, "/inputs/model"),
        text_at(v, "/inputs/model_hash"),
        text_at(v, "/inputs/data"),
        text_at(v, "/inputs/data_hash"),
        value_at(v, "/settings/sampler"),
        value_at(v, "/settings/seed"),
        value_at(v, "/settings/ess_min"),
        match v.get("run").and_then(serde_json::Value::as_array) {
            Some(a) if a.iter().any(|x| x == "--no-exact-check") => ", no exact check",
            Some(_) => ", exact check",
            None => "",
        }
    )
}

/// Writes the fit's tables (samples, posterior predictive, zeta at the mode), its figures
/// (unless `o.no_plots`) and `report.md` into `out`.
///
/// # Errors
/// A file that cannot be written, a figure that cannot be drawn.
pub fn write_outputs(
    o: &FitOptions,
    out: &Path,
    staged: &mut hpge_files::Staged,
    s: &FitJob,
    fit: &Fit,
    truth: Option<&[Option<f64>]>,
    truth_records: Option<&[TruthRecord]>,
) -> Result<()> {
    outputs::write_samples(&staged.path(&out.join("samples.csv")), fit)?;
    outputs::write_predictive(&staged.path(&out.join("predictive.csv")), fit)?;
    let zeta = s.zeta_at_mode(fit, truth)?;
    outputs::write_zeta(&staged.path(&out.join("zeta-mode.csv")), &zeta)?;
    let mut figures = Vec::new();
    let final_figures = out.join("figures");
    if !o.no_plots {
        let names = s.prior.names();
        let pairs = default_pairs(&names);
        let truth_vals: Option<Vec<f64>> =
            truth.map(|t| t.iter().map(|v| v.unwrap_or(f64::NAN)).collect());
        let title = format!("{} fit", s.prior.name);
        // Drawn into a temporary folder that replaces `figures/` whole (an earlier run's
        // figures of other pairs do not stay beside this run's).
        let dir = staged
            .replacing_folder(&final_figures)
            .map_err(Error::io(&final_figures, "cannot create the folder"))?;
        figures = plot::fit_figures(&dir, fit, &zeta, &pairs, truth_vals.as_deref(), &title)?
            .into_iter()
            .map(|f| match f.strip_prefix(&dir) {
                Ok(rel) => final_figures.join(rel),
                Err(_) => f,
            })
            .collect();
    }
    write_report(
        &staged.path(&out.join("report.md")),
        o,
        out,
        s,
        fit,
        &figures,
        truth_records.map(|t| {
            t.iter()
                .map(|r| (r.name.clone(), r.value, r.inside_683, r.inside_955))
                .collect::<Vec<_>>()
        }),
    )
}

/// The 2D marginals to draw: the paper's (bottom vs top level) where the names show it.
fn default_pairs(names: &[String]) -> Vec<(usize, usize)> {
    let find = |n: &str| names.iter().position(|x| x == n);
    let mut pairs = Vec::new();
    for (a, b) in [
        ("y_bot", "y_top"),
        ("y1_bot", "y1_top"),
        ("y4_bot", "y4_top"),
        ("d_li_mm", "y1_bot"),
    ] {
        if let (Some(i), Some(j)) = (find(a), find(b)) {
            pairs.push((i, j));
        }
    }
    if pairs.is_empty() && names.len() >= 2 {
        pairs.push((0, 1));
    }
    pairs
}

/// The short summary `hpge-cv fit` prints: convergence, chi^2 at the mode, one line per
/// parameter (mean, sd, modes, 68.3% smallest intervals, R-hat, ESS), the modes, the exact check.
pub fn summary_text(fit: &Fit, out: &Path) -> String {
    let mut t = String::new();
    let s = &fit.summary;
    let _ = writeln!(
        t,
        "{} in {:.1} s: chi2/ndf at the global mode {:.1}/{} , {} draws per chain, max |pull| {:.2}",
        if s.converged {
            "converged"
        } else {
            "NOT converged"
        },
        s.seconds,
        s.chi2,
        s.ndf,
        s.draws_per_chain,
        s.max_abs_pull
    );
    let _ = writeln!(
        t,
        "{:<10} {:>10} {:>9} {:>10} {:>10}  {:<28} {:>7} {:>7} {:>7}",
        "parameter",
        "mean",
        "std",
        "glob.mode",
        "marg.mode",
        "68.3% smallest interval(s)",
        "R-hat",
        "ESS_b",
        "ESS_t"
    );
    for p in &s.parameters {
        let si: Vec<String> = p.smallest_intervals["0.683"]
            .iter()
            .map(|[a, b]| format!("[{a:.4}, {b:.4}]"))
            .collect();
        let _ = writeln!(
            t,
            "{:<10} {:>10.4} {:>9.4} {:>10.4} {:>10.4}  {:<28} {:>7.4} {:>7.0} {:>7.0}",
            p.name,
            p.mean,
            p.std,
            p.global_mode,
            p.marginal_mode,
            si.join(" "),
            p.rhat,
            p.ess_bulk,
            p.ess_tail
        );
    }
    for p in s.parameters.iter().filter(|p| !p.at_prior_bound.is_empty()) {
        let _ = writeln!(
            t,
            "AT A PRIOR BOUND: {}: {} (the posterior presses against the prior there: the mode is the bound, not a maximum)",
            p.name,
            p.at_prior_bound.join("; ")
        );
    }
    if s.modes.len() > 1 {
        for (i, m) in s.modes.iter().enumerate() {
            let loc: Vec<String> = m.location.iter().map(|v| format!("{v:.4}")).collect();
            let _ = writeln!(
                t,
                "mode {i}{}: weight {:.3} at ({})",
                if m.physics.is_empty() {
                    String::new()
                } else {
                    format!(" ({})", m.physics)
                },
                m.weight,
                loc.join(", ")
            );
        }
    }
    if let Some(k) = s.calibration_factor {
        let _ = writeln!(
            t,
            "calibration factor kappa (c_m = kappa c_p, prior sd {:.1}%): {:.4} +- {:.4}",
            100.0 * k.prior_sd,
            k.factor,
            k.factor_sd
        );
    }
    if let Some(why) = &s.exact_check_skipped {
        let _ = writeln!(t, "exact check not run: {why}");
    }
    if let Some(c) = &s.exact_check {
        let rounds = s.refinement.as_ref().map_or(1, Vec::len);
        let _ = writeln!(
            t,
            "exact check{} ({} draws on {}, {:.1} s): Pareto k {} (weights' ESS {:.0}, log ratios' sd {:.3}), largest mean shift {:.2} sd, |c_exact - c_model|/c at the mode <= {:.2}%: {}",
            if rounds > 1 {
                format!(
                    " after {} rounds of refinement (the surrogate corrected by {} exact curves)",
                    rounds - 1,
                    s.refinement
                        .as_ref()
                        .and_then(|r| r.last())
                        .map_or(0, |r| r.training_curves)
                )
            } else {
                String::new()
            },
            c.draws,
            grids_text(c),
            c.seconds,
            if c.pareto_k.is_nan() {
                format!(
                    "undefined (PSIS needs at least {} draws)",
                    hpge_inference::summary::PSIS_MIN_DRAWS
                )
            } else {
                format!("{:.2}", c.pareto_k)
            },
            c.ess,
            c.log_ratio_sd,
            c.max_abs_shift_sd,
            100.0 * c.max_rel_diff_at_mode,
            if c.pass { "pass" } else { "FAIL" }
        );
    }
    let _ = writeln!(t, "outputs in {}", out.display());
    t
}

/// Where the check solved its draws, in words, with the grid check's numbers.
pub(crate) fn grids_text(c: &hpge_inference::fit::ExactCheck) -> String {
    let text = grids_text_plain(c);
    if c.own_grid_retries > 0 {
        format!(
            "{text}; {} that failed there solved again on their own",
            c.own_grid_retries
        )
    } else {
        text
    }
}

fn grids_text_plain(c: &hpge_inference::fit::ExactCheck) -> String {
    match (&c.grids, &c.grid_check) {
        (ExactGrids::Own, _) => "their own grids".into(),
        (ExactGrids::Mode, None) => "the mode's grids".into(),
        (ExactGrids::Mode, Some(g)) => format!(
            "the mode's grids; {} also on their own: c12 within {:.2}%, ln L within {:.2}",
            g.draws,
            100.0 * g.max_rel_diff,
            g.max_abs_delta_ln_l
        ),
    }
}
