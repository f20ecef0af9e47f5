//! `hpge-cv discover`: from a start model's misfit to the missing effect (issue 9) -- fit the
//! start model, locate where it disagrees with the data and what region of the detector that
//! probes, score the catalogue of extensions, fit the best, and show the gap shrink.

use std::path::Path;

use anyhow::Result;
use hpge_inference::discover::DiscoverOptions;
use hpge_inference::discover::catalogue;
use hpge_inference::posterior::NoiseKind;
use hpge_inference::{CvModel, Discovery, PriorSpec, Progress, Status};
use indicatif::ProgressBar;

use hpge_inference::fit::noise_settings;

use super::fit::{progress_printer, setup};

/// `hpge-cv discover` arguments: the library's options, and what to print.
#[derive(Debug, clap::Args)]
pub struct DiscoverArgs {
    #[command(flatten)]
    pub options: DiscoverOptions,
    /// Print the summary as one JSON object on stdout (progress stays on stderr).
    #[arg(long)]
    pub json: bool,
    /// List the catalogue and exit.
    #[arg(long)]
    pub list: bool,
}

/// Stage lines and the sampler's progress on stderr.
pub struct Printer<F: Fn(&Status) + Sync> {
    bar: ProgressBar,
    sampling: F,
}

impl<F: Fn(&Status) + Sync> Printer<F> {
    /// Stage lines above `bar`, the sampler's status through `sampling`.
    pub fn new(bar: ProgressBar, sampling: F) -> Self {
        Self { bar, sampling }
    }
}

impl<F: Fn(&Status) + Sync> Progress for Printer<F> {
    fn stage(&self, message: &str) {
        self.bar.suspend(|| eprintln!("discover: {message}"));
    }

    fn sampling(&self, status: &Status) {
        (self.sampling)(status)
    }
}

/// Runs `discover`.
pub fn run(a: &DiscoverArgs) -> Result<()> {
    if a.list {
        for e in catalogue() {
            outln!(
                "{:<18} {}\n{:<18} signature: {}",
                e.name(),
                e.description(),
                "",
                e.signature()
            );
        }
        return Ok(());
    }
    let o = &a.options;
    let w = &o.workflow;
    // Every check before the output folder is made: a refused run leaves nothing behind.
    w.check_only()?;
    let noise = noise_settings(NoiseKind::Paper.as_str())?;
    let settings = o.settings(noise)?;
    let prior_file = o.start_prior()?;
    let s = setup(&w.data, &w.model, &prior_file, &w.detector, noise, &w.grid)?;
    s.posterior()?;
    let spec = PriorSpec::from_file(&prior_file)?;
    let out = o.out_dir(&prior_file);
    eprintln!(
        "discover: {} ({} voltages), start model {} ({} parameters), {}",
        w.data.display(),
        s.data.voltage_v.len(),
        prior_file.display(),
        s.prior.dim(),
        s.surrogate.describe()
    );
    let (bar, sampling) = progress_printer(false);
    let printer = Printer::new(bar.clone(), sampling);
    let d = hpge_reports::discover::run_discover(
        &s,
        &spec,
        &prior_file,
        &settings,
        Some(&out),
        w.no_plots,
        o.force,
        &printer,
    )?;
    bar.finish_and_clear();
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&d.summary)?);
    } else {
        print_summary(&d, &out)?;
    }
    Ok(())
}

/// The short summary on stdout.
fn print_summary(d: &Discovery, out: &Path) -> Result<()> {
    let s = &d.summary;
    outln!("{}", s.verdict);
    outln!(
        "before ({}): chi2/ndf {:.2}, max |pull| {:.2}, ppc p {:.3}",
        s.before.model,
        s.before.chi2_ndf,
        s.before.max_pull,
        s.before.ppc_p
    );
    if s.chosen.is_some() {
        outln!(
            "after ({}): chi2/ndf {:.2}, max |pull| {:.2}, ppc p {:.3}; delta elpd {:.1} +- {:.1}",
            s.after.model,
            s.after.chi2_ndf,
            s.after.max_pull,
            s.after.ppc_p,
            s.delta_elpd,
            s.delta_elpd_se
        );
    }
    for c in &s.candidates {
        if c.at_prior_bound.is_empty() {
            outln!(
                "  {:<18} ln B {:>8.2}  delta chi2 {:>8.2}  ({})",
                c.name,
                c.score,
                c.delta_chi2,
                c.predictor
            );
        } else {
            outln!(
                "  {:<18} ln B     none  delta chi2 {:>8.2}  ({}): its optimum is at a prior bound ({}), where the Laplace evidence does not hold",
                c.name,
                c.delta_chi2,
                c.predictor,
                c.at_prior_bound.join("; ")
            );
        }
    }
    outln!("{:.1} s; outputs in {}", s.seconds, out.display());
    Ok(())
}
