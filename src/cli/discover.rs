//! `hpge-cv discover`: from a start model's misfit to the missing effect (issue 9) -- fit the
//! start model, locate where it disagrees with the data and what region of the detector that
//! probes, score the catalogue of extensions, fit the best, and show the gap shrink.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{Context, Result};
use hpge_inference::discover::catalogue;
use hpge_inference::{
    CvModel, DiscoverInputs, DiscoverSettings, Discovery, FitSettings, PriorSpec, Progress,
    SampleSettings, SamplerKind, Status, discover,
};
use indicatif::ProgressBar;

use hpge_inference::fit::noise_settings;

use super::fit::{progress_printer, setup};

/// `hpge-cv discover` arguments.
#[derive(Debug, clap::Args)]
pub struct DiscoverArgs {
    /// The measured C-V curve (CSV with voltage_V, c12_pF, sigma_pF).
    #[arg(
        long,
        value_name = "FILE",
        default_value = hpge_inference::fit::DEFAULT_DATA
    )]
    pub data: PathBuf,
    /// The detector the data were measured with (checked against the model's; the exact solver
    /// runs on it for the extensions outside the surrogate's space and for the probed regions).
    #[arg(
        long,
        value_name = "FILE",
        default_value = hpge_inference::fit::DEFAULT_DETECTOR
    )]
    pub detector: PathBuf,
    /// The start model: a prior file, or the name of one in priors/ (b-z: the paper's B_Z).
    #[arg(long, value_name = "NAME|FILE", default_value = "b-z")]
    pub start_model: String,
    /// The surrogate model (.safetensors); its space must contain the start model.
    #[arg(
        long,
        value_name = "FILE",
        default_value = hpge_inference::fit::DEFAULT_MODEL
    )]
    pub model: PathBuf,
    /// Output folder [default: discoveries/<start model>].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Print the summary as one JSON object on stdout (progress stays on stderr).
    #[arg(long)]
    pub json: bool,
    /// Seed of every random step (sampling, predictive replicates).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Catalogue entries to try, comma-separated (default: all; see --list).
    #[arg(long, value_delimiter = ',')]
    pub only: Vec<String>,
    /// List the catalogue and exit.
    #[arg(long)]
    pub list: bool,
    /// Smallest Laplace ln Bayes factor for an extension to be added.
    #[arg(long, default_value_t = 3.0)]
    pub min_ln_bayes: f64,
    /// Target bulk and tail ESS of the MCMC fits.
    #[arg(long, default_value_t = 1000.0)]
    pub ess: f64,
    /// Stop each MCMC fit after this many seconds even if its targets are not reached.
    #[arg(long, default_value_t = 300.0)]
    pub max_seconds: f64,
    /// Write no figures.
    #[arg(long)]
    pub no_plots: bool,
    /// Fit and score on the surrogate wherever it can (MCMC, fast) instead of the exact solver
    /// (Laplace; the default, because the surrogate is up to 27% off on z-only profiles).
    #[arg(long)]
    pub surrogate_only: bool,
    #[command(flatten)]
    pub grid: super::args::GridArgs,
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

/// The prior file of `--start-model`: a path, or priors/<name>.toml.
fn start_prior(name: &str) -> Result<PathBuf> {
    let p = PathBuf::from(name);
    if p.is_file() {
        return Ok(p);
    }
    let named = Path::new("priors").join(format!("{name}.toml"));
    if named.is_file() {
        return Ok(named);
    }
    anyhow::bail!(
        "--start-model {name}: neither a prior file nor a name in priors/ ({} does not exist)",
        named.display()
    )
}

/// Runs `discover`.
pub fn run(a: &DiscoverArgs) -> Result<()> {
    if a.list {
        for e in catalogue() {
            println!(
                "{:<18} {}\n{:<18} signature: {}",
                e.name(),
                e.description(),
                "",
                e.signature()
            );
        }
        return Ok(());
    }
    let names: Vec<&str> = catalogue().iter().map(|e| e.name()).collect();
    for o in &a.only {
        if !names.contains(&o.as_str()) {
            anyhow::bail!(
                "--only {o}: no such catalogue entry; the entries are {}",
                names.join(", ")
            );
        }
    }
    let prior_file = start_prior(&a.start_model)?;
    let noise = noise_settings("paper")?;
    let s = setup(&a.data, &a.model, &prior_file, &a.detector, noise, &a.grid)?;
    let spec = PriorSpec::from_file(&prior_file)?;
    let out = a.out.clone().unwrap_or_else(|| {
        PathBuf::from("discoveries").join(
            prior_file
                .file_stem()
                .map_or("discovery".into(), |s| s.to_string_lossy().to_string()),
        )
    });
    std::fs::create_dir_all(&out)
        .with_context(|| format!("--out {}: cannot create the folder", out.display()))?;
    let mut sample = SampleSettings::for_sampler(SamplerKind::Metropolis);
    sample.seed = a.seed;
    sample.ess_min = a.ess;
    sample.max_seconds = a.max_seconds;
    sample.validate()?;
    let settings = DiscoverSettings {
        fit: FitSettings {
            sample,
            noise,
            ..FitSettings::default()
        },
        min_ln_bayes: a.min_ln_bayes,
        exact: !a.surrogate_only,
        only: a.only.clone(),
        seed: a.seed,
        ..DiscoverSettings::default()
    };
    eprintln!(
        "discover: {} ({} voltages), start model {} ({} parameters), {}",
        a.data.display(),
        s.data.voltage_v.len(),
        prior_file.display(),
        s.prior.dim(),
        s.surrogate.describe()
    );
    let (bar, sampling) = progress_printer(false);
    let printer = Printer::new(bar.clone(), sampling);
    let surrogate: Arc<dyn CvModel> = Arc::new(s.surrogate.clone());
    let mut inputs = s.inputs.clone();
    inputs.insert("start_model".into(), prior_file.display().to_string());
    let d = discover(
        &DiscoverInputs {
            surrogate,
            exact: &s.exact,
            start: &spec,
            likelihood: &s.likelihood,
            inputs,
        },
        &settings,
        &printer,
    )?;
    bar.finish_and_clear();
    hpge_reports::discover::write_outputs(&out, &d, &s.exact, a.no_plots)?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&d.summary)?);
    } else {
        print_summary(&d, &out);
    }
    Ok(())
}

/// The short summary on stdout.
fn print_summary(d: &Discovery, out: &Path) {
    let s = &d.summary;
    println!("{}", s.verdict);
    println!(
        "before ({}): chi2/ndf {:.2}, max |pull| {:.2}, ppc p {:.3}",
        s.before.model, s.before.chi2_ndf, s.before.max_pull, s.before.ppc_p
    );
    if s.chosen.is_some() {
        println!(
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
        println!(
            "  {:<18} ln B {:>8.2}  delta chi2 {:>8.2}  ({})",
            c.name, c.score, c.delta_chi2, c.predictor
        );
    }
    println!("{:.1} s; outputs in {}", s.seconds, out.display());
}
