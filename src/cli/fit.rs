//! `hpge-cv fit`: the posterior of an impurity model given a measured C-V curve (paper, section
//! 8), with the files, figures and report a physicist reads.

use std::path::Path;

use anyhow::{Context, Result};
use hpge_inference::fit::{FitFiles, FitJob, outputs, read_truth, truth_records};
use hpge_inference::{CvModel, Fit, SamplerKind, Status};
use indicatif::{ProgressBar, ProgressStyle};

use super::fit_outputs::write_outputs;

/// A fit that did not reach its convergence targets (exit code 3).
#[derive(Debug, thiserror::Error)]
#[error(
    "the fit did not converge ({0}); the outputs are written, but treat them with care. Run longer (--max-seconds), or pass --allow-unconverged"
)]
pub struct Unconverged(pub String);

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

/// Parses the sampler name.
pub fn sampler_kind(name: &str) -> Result<SamplerKind> {
    Ok(hpge_inference::fit::sampler_kind(name)?)
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
            hpge_inference::Phase::Tuning => format!(
                "tuning cycle {}: acceptance {:.2}, R-hat {:.3}",
                s.cycle, s.acceptance, s.rhat_max
            ),
            hpge_inference::Phase::Sampling => format!(
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

/// The paper's noise constants with the likelihood named by `--likelihood`.
pub fn noise_settings(likelihood: &str) -> Result<hpge_inference::NoiseSettings> {
    Ok(hpge_inference::fit::noise_settings(likelihood)?)
}

/// Runs `fit`: `json` prints the summary as one JSON object; `allow_unconverged` exits with 0
/// when the convergence targets were not reached.
pub fn run(o: &FitOptions, print_json: bool, allow_unconverged: bool) -> Result<()> {
    let kind = o.sampler_kind()?;
    let noise = o.noise()?;
    let s = setup(&o.data, &o.model, &o.prior, &o.detector, noise, &o.grid)?;
    let truth = match &o.truth {
        Some(p) => Some(read_truth(p, &s.prior)?),
        None => None,
    };
    let settings = o.settings()?;
    let sample = settings.sample;
    let out = o.out_dir();
    std::fs::create_dir_all(&out)
        .with_context(|| format!("--out {}: cannot create the folder", out.display()))?;
    eprintln!(
        "fitting {} ({} voltages) with {} and the prior {} ({} parameters), {} sampler, {} chains, seed {}",
        o.data.display(),
        s.data.voltage_v.len(),
        s.surrogate.describe(),
        o.prior.display(),
        s.prior.dim(),
        kind.as_str(),
        sample.chains,
        o.seed
    );
    let (bar, progress) = progress_printer(false);
    let mut result = s.run(&settings, &progress)?;
    bar.finish_and_clear();
    if !o.no_exact_check {
        let pb = ProgressBar::new(o.exact_draws as u64 + 1);
        pb.set_style(
            ProgressStyle::with_template("exact check {bar:30} {pos}/{len} curves, {elapsed}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        s.check_exact(&mut result, o.exact_draws, &|done, _| {
            pb.set_position(done as u64)
        })?;
        pb.finish_and_clear();
    }
    let truth_records = truth.as_ref().map(|t| truth_records(&result.summary, t));
    write_outputs(
        o,
        &out,
        &s,
        &result,
        truth.as_deref(),
        truth_records.as_deref(),
    )?;
    let sm = &result.summary;
    let json = outputs::summary_json(&result, truth_records.as_deref())?;
    outputs::write_summary(&out.join("summary.json"), &json)?;
    if print_json {
        println!("{}", serde_json::to_string(&json)?);
    } else {
        print_summary(&result, &out);
    }
    if !sm.converged {
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
        let msg = format!("{worst}; stopped: {:?}", sm.stop);
        if allow_unconverged {
            eprintln!("warning: the fit did not converge ({msg})");
        } else {
            return Err(Unconverged(msg).into());
        }
    }
    Ok(())
}

fn print_summary(fit: &Fit, out: &Path) {
    let s = &fit.summary;
    println!(
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
    println!(
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
        println!(
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
    if s.modes.len() > 1 {
        for (i, m) in s.modes.iter().enumerate() {
            let loc: Vec<String> = m.location.iter().map(|v| format!("{v:.4}")).collect();
            println!("mode {i}: weight {:.3} at ({})", m.weight, loc.join(", "));
        }
    }
    if let Some(c) = &s.exact_check {
        println!(
            "exact check ({} draws, {:.1} s): Pareto k {:.2}, largest mean shift {:.2} sd, |c_exact - c_surrogate|/c at the mode <= {:.2}%: {}",
            c.draws,
            c.seconds,
            c.pareto_k,
            c.max_abs_shift_sd,
            100.0 * c.max_rel_diff_at_mode,
            if c.pass { "pass" } else { "FAIL" }
        );
    }
    println!("outputs in {}", out.display());
}
