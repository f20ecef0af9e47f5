//! `hpge-cv validate discovery`: model discovery on data with hidden effects (issue 9). One
//! seeded command generates every data set with the exact solver, runs the workflow on each and
//! checks that it names the hidden effect (none in the null case) and that the fit after adding
//! it has chi^2/ndf consistent with 1.

use std::io::Write as _;
use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{Context, Result};
use hpge_inference::{
    CvModel, DiscoverSettings, FitSettings, PriorSpec, SampleSettings, SamplerKind,
};
use hpge_measurement::write_curve_with_comments;
use hpge_validation::studies::hidden::simulate_hidden;
use hpge_validation::{HiddenOutcome, hidden_effects, run_hidden};
use serde::Serialize;

use super::discover::Printer;
use hpge_inference::fit::noise_settings;

use super::fit::{progress_printer, setup};
use hpge_reports::discover::write_outputs;

/// `hpge-cv validate discovery` arguments.
#[derive(Debug, clap::Args)]
pub struct DiscoveryArgs {
    /// Seed of the noise (data set i uses seed + i) and of the workflow.
    #[arg(long, default_value_t = 7)]
    pub seed: u64,
    /// Output folder: one sub-folder per data set (cv.csv, truth.json, the workflow's outputs),
    /// and summary.json / summary.md.
    #[arg(long, value_name = "DIR", default_value = "reports/discovery/hidden")]
    pub out: PathBuf,
    /// Hidden effects to run, comma-separated (default: all: none, radial, stray-capacitance,
    /// calibration-scale, quadratic-z, li-slope).
    #[arg(long, value_delimiter = ',')]
    pub effects: Vec<String>,
    /// Catalogue entries the workflow tries, comma-separated (default: all).
    #[arg(long, value_delimiter = ',')]
    pub only: Vec<String>,
    /// Target ESS of the workflow's MCMC fits (lower: faster, the CI's reduced run uses 300).
    #[arg(long, default_value_t = 1000.0)]
    pub ess: f64,
    /// The surrogate model.
    #[arg(
        long,
        value_name = "FILE",
        default_value = hpge_inference::fit::DEFAULT_MODEL
    )]
    pub model: PathBuf,
    /// The detector.
    #[arg(
        long,
        value_name = "FILE",
        default_value = hpge_inference::fit::DEFAULT_DETECTOR
    )]
    pub detector: PathBuf,
    /// The start model's prior.
    #[arg(long, value_name = "FILE", default_value = "priors/b-z.toml")]
    pub start_model: PathBuf,
    /// The voltages are those of this curve.
    #[arg(
        long,
        value_name = "FILE",
        default_value = hpge_inference::fit::DEFAULT_DATA
    )]
    pub data: PathBuf,
    /// Print the summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Write no figures.
    #[arg(long)]
    pub no_plots: bool,
    #[command(flatten)]
    pub grid: super::args::GridArgs,
}

/// The study's result.
#[derive(Debug, Serialize)]
struct Study {
    pass: bool,
    seed: u64,
    program_version: String,
    outcomes: Vec<HiddenOutcome>,
    seconds: f64,
}

/// Runs the study; exit code 1 when a data set is misnamed or its chi^2 is inconsistent.
pub fn run(a: &DiscoveryArgs) -> Result<()> {
    let t0 = std::time::Instant::now();
    let all = hidden_effects();
    for e in &a.effects {
        if !all.iter().any(|h| &h.effect == e) {
            let names: Vec<&str> = all.iter().map(|h| h.effect.as_str()).collect();
            anyhow::bail!("--effects {e}: unknown; use {}", names.join(", "));
        }
    }
    let noise = noise_settings("paper")?;
    let s = setup(
        &a.data,
        &a.model,
        &a.start_model,
        &a.detector,
        noise,
        &a.grid,
    )?;
    let start = PriorSpec::from_file(&a.start_model)?;
    let mut sample = SampleSettings::for_sampler(SamplerKind::Metropolis);
    sample.ess_min = a.ess;
    sample.max_seconds = 120.0;
    sample.validate()?;
    let settings = DiscoverSettings {
        fit: FitSettings {
            sample,
            noise,
            ..FitSettings::default()
        },
        seed: a.seed,
        only: a.only.clone(),
        ..DiscoverSettings::default()
    };
    let surrogate: Arc<dyn CvModel> = Arc::new(s.surrogate.clone());
    let volts = s.data.voltage_v.clone();
    let mut outcomes = Vec::new();
    for (i, h) in all.iter().enumerate() {
        if !a.effects.is_empty() && !a.effects.contains(&h.effect) {
            continue;
        }
        let dir = a.out.join(&h.effect);
        std::fs::create_dir_all(&dir)
            .with_context(|| format!("{}: cannot create the folder", dir.display()))?;
        eprintln!(
            "hidden effect {}: generating the data (exact solver)",
            h.effect
        );
        let seed = a.seed + i as u64;
        let data = simulate_hidden(h, &s.exact, &start, &volts, seed)?;
        write_curve_with_comments(
            &dir.join("cv.csv"),
            &data,
            &[format!(
                "hpge-cv {} validate discovery --seed {}: exact solver, hidden effect {} {:?}, paper noise x {} (seed {seed})",
                env!("CARGO_PKG_VERSION"),
                a.seed,
                h.effect,
                h.truth,
                h.noise_scale
            )],
        )?;
        std::fs::write(
            dir.join("truth.json"),
            serde_json::to_string_pretty(h)? + "\n",
        )?;
        let (bar, sampling) = progress_printer(false);
        let printer = Printer::new(bar.clone(), sampling);
        let mut settings = settings.clone();
        settings.seed = seed;
        settings.fit.sample.seed = seed;
        let (d, outcome) = run_hidden(
            h,
            &data,
            surrogate.clone(),
            &s.exact,
            &start,
            &settings,
            &printer,
        )?;
        bar.finish_and_clear();
        write_outputs(&dir, &d, &s.exact, a.no_plots)?;
        eprintln!(
            "hidden effect {}: chose {} ({}, expected {}), chi2/ndf {:.2} -> {:.2} (p {:.3}), {:.0} s",
            h.effect,
            outcome.chosen.as_deref().unwrap_or("nothing"),
            if outcome.correct { "right" } else { "WRONG" },
            outcome.expected.as_deref().unwrap_or("nothing"),
            outcome.chi2_ndf_before,
            outcome.chi2_ndf_after,
            outcome.chi2_p_after,
            outcome.seconds
        );
        outcomes.push(outcome);
    }
    let study = Study {
        pass: outcomes.iter().all(|o| o.correct && o.consistent),
        seed: a.seed,
        program_version: env!("CARGO_PKG_VERSION").into(),
        outcomes,
        seconds: t0.elapsed().as_secs_f64(),
    };
    std::fs::write(
        a.out.join("summary.json"),
        serde_json::to_string_pretty(&study)? + "\n",
    )?;
    let mut md = std::fs::File::create(a.out.join("summary.md"))?;
    writeln!(
        md,
        "# Hidden-effect tests of model discovery\n\n`hpge-cv validate discovery --seed {}` ({:.0} s). Pass: {}.\n",
        a.seed, study.seconds, study.pass
    )?;
    writeln!(
        md,
        "| hidden effect | noise x | expected | chosen | right | chi^2/ndf before | after | chi^2 p after | best scores (ln B) |"
    )?;
    writeln!(md, "|---|---|---|---|---|---|---|---|---|")?;
    for o in &study.outcomes {
        let scores: Vec<String> = o
            .scores
            .iter()
            .take(3)
            .map(|(n, v)| format!("{n} {v:.1}"))
            .collect();
        writeln!(
            md,
            "| {} | {} | {} | {} | {} | {:.2} | {:.2} | {:.3} | {} |",
            o.effect,
            o.noise_scale,
            o.expected.as_deref().unwrap_or("none"),
            o.chosen.as_deref().unwrap_or("none"),
            if o.correct { "yes" } else { "**no**" },
            o.chi2_ndf_before,
            o.chi2_ndf_after,
            o.chi2_p_after,
            scores.join(", ")
        )?;
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&study)?);
    }
    if !study.pass {
        eprintln!(
            "validate discovery: FAILED (see {}/summary.md)",
            a.out.display()
        );
        std::process::exit(1);
    }
    Ok(())
}
