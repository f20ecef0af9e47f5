//! `hpge-cv validate coverage`: simulation-based calibration of the fit.

use std::io::Write as _;
use std::path::Path;

use anyhow::{Context, Result, bail};
use hpge_inference::{CvModel, ExactModel, FitSettings, SampleSettings};
use hpge_validation::{CoverageSettings, coverage as run_coverage};
use indicatif::{ProgressBar, ProgressStyle};

use hpge_inference::fit::{noise_settings, sampler_kind};

use super::fit::setup;

/// Options of `validate coverage`.
pub struct CoverageOptions<'a> {
    pub truths: usize,
    pub json: bool,
    pub prior: &'a Path,
    pub model: &'a Path,
    pub data: &'a Path,
    pub detector: &'a Path,
    pub exact: bool,
    pub likelihood: &'a str,
    pub sampler: &'a str,
    pub seed: u64,
    pub ess: f64,
    pub ranks: usize,
    pub mode_starts: usize,
    pub out: &'a Path,
}

/// Runs the study, writes coverage.json, ranks.csv and figures; exit code 1 if it fails.
pub fn coverage(o: &CoverageOptions) -> Result<()> {
    if o.truths < 2 {
        bail!("--truths {}: need at least 2 truths", o.truths);
    }
    if o.ranks < 9 {
        bail!("--ranks {}: need at least 9 draws to rank among", o.ranks);
    }
    let kind = sampler_kind(o.sampler)?;
    let noise = noise_settings(o.likelihood)?;
    let s = setup(
        o.data,
        o.model,
        o.prior,
        o.detector,
        noise,
        &super::args::GridArgs::default(),
    )?;
    let mut sample = SampleSettings::for_sampler(kind);
    sample.ess_min = o.ess;
    // A study needs many fits: a fit that has not reached its ESS after 20 000 kept draws per
    // chain (or a minute) stops there and is counted as unconverged.
    sample.max_seconds = 60.0;
    sample.max_draws = 20_000;
    sample.mode_starts = o.mode_starts;
    sample.validate()?;
    let settings = CoverageSettings {
        n_truths: o.truths,
        seed: o.seed,
        fit: FitSettings {
            sample,
            noise,
            ..FitSettings::default()
        },
        ranks: o.ranks,
    };
    std::fs::create_dir_all(o.out)
        .with_context(|| format!("--out {}: cannot create the folder", o.out.display()))?;
    let exact;
    let (data_model, data_sigma): (&dyn CvModel, f64) = if o.exact {
        exact = ExactModel::new(s.exact.clone(), &s.data.voltage_v)?;
        (&exact, 0.0)
    } else {
        (&s.surrogate, s.surrogate.sigma_rel())
    };
    eprintln!(
        "coverage: {} truths from {}, data from {}, fitted with {} ({} sampler, ESS >= {}), seed {}",
        o.truths,
        o.prior.display(),
        if o.exact {
            "the exact solver"
        } else {
            "the surrogate"
        },
        s.surrogate.describe(),
        kind.as_str(),
        o.ess,
        o.seed
    );
    let bar = ProgressBar::new(o.truths as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} truths, {elapsed} elapsed, eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let lines = !std::io::IsTerminal::is_terminal(&std::io::stderr());
    let report = run_coverage(
        &s.surrogate,
        data_model,
        data_sigma,
        &s.prior,
        &s.likelihood,
        &settings,
        &|done, total| {
            bar.set_position(done as u64);
            if lines && (done % 10 == 0 || done == total) {
                eprintln!("{done}/{total} truths");
            }
        },
    )?;
    bar.finish_and_clear();
    let mut json = serde_json::to_value(&report)?;
    if let Some(obj) = json.as_object_mut() {
        obj.insert("program_version".into(), env!("CARGO_PKG_VERSION").into());
        obj.insert("inputs".into(), serde_json::to_value(&s.inputs)?);
        obj.insert(
            "data_from".into(),
            if o.exact { "exact" } else { "surrogate" }.into(),
        );
        obj.insert("settings".into(), serde_json::to_value(settings)?);
    }
    let path = o.out.join("coverage.json");
    std::fs::write(&path, serde_json::to_string_pretty(&json)? + "\n")
        .with_context(|| format!("cannot write {}", path.display()))?;
    let path = o.out.join("ranks.csv");
    let mut w = std::io::BufWriter::new(
        std::fs::File::create(&path)
            .with_context(|| format!("cannot create {}", path.display()))?,
    );
    writeln!(
        w,
        "# hpge-cv {} validate coverage: prior {} model {} data-from {} seed {}; rank among {} draws",
        env!("CARGO_PKG_VERSION"),
        o.prior.display(),
        o.model.display(),
        if o.exact { "exact" } else { "surrogate" },
        o.seed,
        o.ranks
    )?;
    let names: Vec<&str> = report.parameters.iter().map(|p| p.name.as_str()).collect();
    writeln!(w, "truth,{}", names.join(","))?;
    for i in 0..report.n_truths {
        let r: Vec<String> = report
            .parameters
            .iter()
            .map(|p| p.ranks[i].to_string())
            .collect();
        writeln!(w, "{i},{}", r.join(","))?;
    }
    w.flush()?;
    hpge_reports::plot::coverage_figures(
        &o.out.join("figures"),
        &report,
        &format!("{} coverage", o.prior.display()),
    )?;
    if o.json {
        // The fields first: n_truths, parameters (name, ks_p, coverage_683,
        // coverage_955), pass; the full record is in coverage.json.
        let brief = serde_json::json!({
            "n_truths": report.n_truths,
            "parameters": report.parameters.iter().map(|p| serde_json::json!({
                "name": p.name, "ks_p": p.ks_p, "coverage_683": p.coverage_683, "coverage_955": p.coverage_955,
                "expected_683": p.expected_683, "expected_955": p.expected_955,
            })).collect::<Vec<_>>(),
            "pass": report.pass,
            "unconverged": report.unconverged,
            "skipped": report.skipped,
            "seconds": report.seconds,
        });
        println!("{brief}");
    } else {
        println!(
            "{} truths ({} skipped, {} fits unconverged) in {:.0} s: {}",
            report.n_truths,
            report.skipped,
            report.unconverged,
            report.seconds,
            if report.pass { "PASS" } else { "FAIL" }
        );
        println!(
            "{:<10} {:>8} {:>10} {:>17} {:>10} {:>17}",
            "parameter", "KS p", "cov 68.3%", "99% expected", "cov 95.5%", "99% expected"
        );
        for p in &report.parameters {
            println!(
                "{:<10} {:>8.3} {:>10.3} [{:.3}, {:.3}] {:>10.3} [{:.3}, {:.3}]",
                p.name,
                p.ks_p,
                p.coverage_683,
                p.expected_683[0],
                p.expected_683[1],
                p.coverage_955,
                p.expected_955[0],
                p.expected_955[1]
            );
        }
        println!("outputs in {}", o.out.display());
    }
    if !report.pass {
        std::process::exit(1);
    }
    Ok(())
}
