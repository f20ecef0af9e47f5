//! `hpge-cv validate discovery`: model discovery on data with hidden effects (issue 9). One
//! seeded command generates every data set with the exact solver, runs the workflow on each and
//! checks that it names the hidden effect (none in the null case) and that the fit after adding
//! it has chi^2/ndf consistent with 1.

use std::sync::Arc;

use anyhow::{Context, Result};
use hpge_inference::posterior::NoiseKind;
use hpge_inference::{CvModel, PriorSpec};
use hpge_measurement::write_curve;
use hpge_validation::studies::hidden::simulate_hidden;
use hpge_validation::{HiddenOptions, HiddenStudy, hidden_effects, run_hidden};

use super::discover::Printer;
use hpge_inference::fit::noise_settings;

use super::fit::{progress_printer, setup};
use hpge_reports::discover::write_outputs;

/// `hpge-cv validate discovery` arguments: the library's options, and what to print.
#[derive(Debug, clap::Args)]
pub struct DiscoveryArgs {
    #[command(flatten)]
    pub options: HiddenOptions,
    /// Print the summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Replace a study of another run (other seed, effects, inputs or settings) in --out;
    /// without it such a folder is refused.
    #[arg(long)]
    pub force: bool,
}

/// Runs the study; exit code 1 when a data set is misnamed or its chi^2 is inconsistent.
pub fn run(a: &DiscoveryArgs) -> Result<()> {
    let o = &a.options;
    let t0 = std::time::Instant::now();
    let all = hidden_effects();
    for e in &o.effects {
        if !all.iter().any(|h| &h.effect == e) {
            let names: Vec<&str> = all.iter().map(|h| h.effect.as_str()).collect();
            anyhow::bail!("--effects {e}: unknown; use {}", names.join(", "));
        }
    }
    let noise = noise_settings(NoiseKind::Paper.as_str())?;
    let w = &o.workflow;
    let s = setup(
        &w.data,
        &w.model,
        &o.start_model,
        &w.detector,
        noise,
        &w.grid,
    )?;
    let start = PriorSpec::from_file(&o.start_model)?;
    let settings = o.settings(noise)?;
    let effects: Vec<&str> = all
        .iter()
        .map(|h| h.effect.as_str())
        .filter(|e| o.effects.is_empty() || o.effects.iter().any(|x| x == e))
        .collect();
    let run = serde_json::json!({
        "effects": effects,
        "start_model": o.start_model.display().to_string(),
        "inputs": s.inputs,
        "settings": settings,
    });
    // A folder holding another run's study is refused unless --force (issue 69).
    let record = serde_json::json!({ "seed": o.seed, "run": run });
    if let Some(w) = hpge_reports::replace::check_replace(
        &o.out.join("summary.json"),
        &record,
        &describe_study,
        a.force,
    )? {
        eprintln!("warning: {w}");
    }
    eprintln!(
        "validate discovery: the study's folder is {}",
        o.out.display()
    );
    // A study folder this run makes is removed again when it fails before any effect's curve is
    // written (a full disk, issue 66); one holding curves or a summary stays.
    let _study = hpge_files::NewFolder::create(&o.out, |d| {
        std::fs::read_dir(d).is_ok_and(|entries| {
            entries
                .filter_map(Result::ok)
                .any(|e| e.file_name() == "summary.json" || e.path().join("cv.csv").exists())
        })
    })
    .with_context(|| format!("{}: cannot create the folder", o.out.display()))?;
    let surrogate: Arc<dyn CvModel> = Arc::new(s.surrogate.clone());
    let volts = s.data.voltage_v.clone();
    let mut outcomes = Vec::new();
    for (i, h) in all.iter().enumerate() {
        if !o.effects.is_empty() && !o.effects.contains(&h.effect) {
            continue;
        }
        let dir = o.out.join(&h.effect);
        std::fs::create_dir_all(&dir)
            .with_context(|| format!("{}: cannot create the folder", dir.display()))?;
        eprintln!(
            "hidden effect {}: generating the data (exact solver)",
            h.effect
        );
        let seed = o.seed + i as u64;
        let data = simulate_hidden(h, &s.exact, &start, &volts, seed)?;
        let csv = dir.join("cv.csv");
        // The curve, its sidecar and the truth together, or none of them.
        let mut staged = hpge_files::Staged::new();
        staged.adopt(&csv);
        write_curve(&csv, &data)?;
        hpge_foundation::sidecar::stage(
            &mut staged,
            &csv,
            &hpge_solver::made(),
            serde_json::json!({
                "provenance": format!(
                    "validate discovery --seed {}: exact solver, hidden effect {} {:?}, paper noise x {} (seed {seed})",
                    o.seed, h.effect, h.truth, h.noise_scale
                ),
                "study_seed": o.seed,
                "data_seed": seed,
                "hidden_effect": h.effect,
                "noise_scale": h.noise_scale,
                "truth": "truth.json",
            }),
        )?;
        staged.write(
            &dir.join("truth.json"),
            (serde_json::to_string_pretty(h)? + "\n").as_bytes(),
        )?;
        super::args::commit(staged)?;
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
        write_outputs(&dir, &d, &s.exact, w.no_plots)?;
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
    let study = HiddenStudy::new(o.seed, run, outcomes, t0.elapsed().as_secs_f64());
    study.write(&o.out)?;
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&study)?);
    }
    eprintln!("outputs in {}", o.out.display());
    if !study.pass {
        return Err(super::fit::StudyFailed(format!(
            "validate discovery: FAILED (see {}/summary.md)",
            o.out.display()
        ))
        .into());
    }
    Ok(())
}

/// A hidden-effect study's record (`summary.json`, or this run's) in a few words.
fn describe_study(v: &serde_json::Value) -> String {
    use hpge_reports::replace::{text_at, value_at};
    format!(
        "seed {}, effects {}, start model {}, model {} (hash {})",
        value_at(v, "/seed"),
        value_at(v, "/run/effects"),
        text_at(v, "/run/start_model"),
        text_at(v, "/run/inputs/model"),
        text_at(v, "/run/inputs/model_hash"),
    )
}
