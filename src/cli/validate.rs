//! `hpge-cv validate coverage`: simulation-based calibration of the fit.

use anyhow::{Context, Result};
use hpge_inference::{CvModel, ExactModel};
use hpge_validation::studies::coverage::store::{TRUTHS_DIR, TruthStore, study_fingerprint};
use hpge_validation::studies::coverage::{ParameterCoverage, SubsetCoverage, TruthEvent, progress};
use hpge_validation::{
    CoverageModels, CoverageOptions, CoverageOutcome, CoverageReport, CoverageRun,
    coverage as run_coverage,
};
use indicatif::{ProgressBar, ProgressStyle};

use super::fit::setup;

/// Runs the study, writes coverage.json, ranks.csv and figures; exit code 1 if it fails. A
/// folder holding another study is refused unless `force` ([`check_other_study`]).
pub fn coverage(o: &CoverageOptions, as_json: bool, force: bool) -> Result<()> {
    let settings = o.settings()?;
    let kind = settings.fit.sample.sampler;
    let s = setup(
        &o.data,
        &o.model,
        &o.prior,
        &o.detector,
        settings.fit.noise,
        &super::args::GridArgs::default(),
    )?;
    let out = o.out_dir();
    let out = out.as_path();
    let fingerprint = study_fingerprint(&s.inputs, o.data_from(), &settings);
    if o.progress {
        return coverage_progress(out, &fingerprint, &s.prior, &settings, as_json);
    }
    if let Some(w) = check_other_study(out, &s.inputs, o, &settings, &fingerprint, force)? {
        eprintln!("warning: {w}");
    }
    // A folder this study makes is removed again if it fails before a truth is written (a full
    // disk, issue 66); one with finished truths stays, to resume from.
    let _folder =
        hpge_files::NewFolder::create(out, |dir| hpge_files::has_entries(&dir.join("truths")))
            .with_context(|| format!("--out {}: cannot create the folder", out.display()))?;
    eprintln!(
        "coverage: the study's folder is {}{}",
        out.display(),
        if o.out.is_none() {
            " (the default; --out DIR chooses another)"
        } else {
            ""
        }
    );
    let exact;
    let (data_model, data_sigma): (&dyn CvModel, f64) = if o.exact {
        exact = ExactModel::new(s.exact.clone(), &s.data.voltage_v)?;
        (&exact, 0.0)
    } else {
        (&s.surrogate, s.surrogate.sigma_rel())
    };
    let shard = o.shard()?;
    let store = TruthStore::open(out, fingerprint, shard)?;
    eprintln!(
        "coverage: {} truths from {}, data from {}, fitted with {} ({} sampler, ESS >= {}{}), seed {}{}",
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
        match &settings.pipeline {
            Some(p) => format!(
                "; exact check of {} draws, up to {} rounds of refinement",
                p.check.draws, p.refine.max_rounds
            ),
            None => String::new(),
        },
        o.seed,
        if shard.m > 1 {
            format!(", shard {}/{}", shard.k, shard.m)
        } else {
            String::new()
        }
    );
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} truths, {elapsed} elapsed, eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let lines = !std::io::IsTerminal::is_terminal(&std::io::stderr());
    // Without a terminal a line per 10 truths, or per truth where each runs the full pipeline
    // (minutes each).
    let every = if settings.pipeline.is_some() { 1 } else { 10 };
    let outcome = run_coverage(
        CoverageModels {
            fit: &s.surrogate,
            data: data_model,
            data_sigma_rel: data_sigma,
        },
        &s.prior,
        &s.likelihood,
        &settings,
        CoverageRun {
            store: Some(&store),
            shard,
            events: &|i, e| {
                if let Some(line) = truth_event_line(i, &e) {
                    let line = format!("[{:>7.0} s] {line}", bar.elapsed().as_secs_f64());
                    if lines {
                        eprintln!("{line}");
                    } else {
                        bar.println(line);
                    }
                }
            },
        },
        &|done, total| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
            if lines && (done % every == 0 || done == total) {
                eprintln!(
                    "{done}/{total} truths of this run ({:.0} s)",
                    bar.elapsed().as_secs_f64()
                );
            }
        },
    )?;
    bar.finish_and_clear();
    let report = match outcome {
        CoverageOutcome::Done(r) => *r,
        CoverageOutcome::Partial { done, total } => {
            outln!(
                "shard {}/{} done; {done} of {total} truths of the study in {}: the report is \
                 written when every shard has run (run any shard, or the study without --shard, \
                 again then)",
                shard.k,
                shard.m,
                out.join("truths").display()
            );
            return Ok(());
        }
    };
    hpge_validation::studies::coverage::write_outputs(
        out,
        &report,
        &hpge_validation::studies::coverage::CoverageProvenance {
            inputs: &s.inputs,
            data_from: o.data_from().as_str(),
            shard: &o.shard,
            settings: &settings,
            ranks: o.ranks,
            prior: &o.prior,
            model: &o.model,
            seed: o.seed,
        },
    )?;
    hpge_reports::plot::coverage_figures(
        &out.join("figures"),
        &report,
        &hpge_reports::plot::coverage_title(&o.prior.display().to_string(), o.data_from().as_str()),
    )?;
    if as_json {
        outln!("{}", brief_json(&report));
        eprintln!("outputs in {}", out.display());
    } else {
        print_report(&report, true)?;
        outln!("outputs in {}", out.display());
    }
    if !report.pass {
        return Err(super::fit::StudyFailed(format!(
            "validate coverage: FAILED (see {}/coverage.json)",
            out.display()
        ))
        .into());
    }
    Ok(())
}

/// Refuses a study folder that holds another study's results (issue 69), unless `force` (then
/// the warning to print): a `coverage.json` of other inputs (their hashes), data source or
/// settings, or of more truths than `--truths` (a smaller study would replace it; a larger one
/// extends it, as documented), or truth files in `truths/` that another run wrote (other
/// inputs, settings or program version: the study would remove them). The same study again, a
/// resumed one, a larger one and every shard of one go on as before.
fn check_other_study(
    out: &std::path::Path,
    inputs: &std::collections::BTreeMap<String, String>,
    o: &CoverageOptions,
    settings: &hpge_validation::studies::coverage::CoverageSettings,
    fingerprint: &str,
    force: bool,
) -> Result<Option<String>> {
    use hpge_reports::replace::{Existing, differences, existing, refuse_other_run};
    use serde_json::Value;
    let without_truths = |v: &Value| {
        let mut v = v.clone();
        if let Some(s) = v.get_mut("settings").and_then(Value::as_object_mut) {
            s.remove("n_truths");
        }
        v
    };
    let record = without_truths(&serde_json::json!({
        "inputs": inputs,
        "data_from": o.data_from().as_str(),
        "settings": settings,
    }));
    let here = describe_study(&record, o.truths as u64);
    let file = out.join("coverage.json");
    let old = existing(&file);
    let mut diffs = Vec::new();
    let mut there = String::from("unknown");
    if let Some(old) = &old {
        diffs = differences(&without_truths(&old.record), &record);
        if let Some(n) = old.record.get("n_truths").and_then(Value::as_u64) {
            if n > o.truths as u64 {
                diffs.push(format!(
                    "/n_truths ({n} there, {} here: the study would shrink)",
                    o.truths
                ));
            }
            there = describe_study(&old.record, n);
        }
    }
    // Truth files another run wrote (TruthStore::open removes them).
    let stale = std::fs::read_dir(out.join(TRUTHS_DIR))
        .map(|d| {
            d.filter_map(|e| std::fs::read_to_string(e.ok()?.path()).ok())
                .filter_map(|t| serde_json::from_str::<Value>(&t).ok())
                .filter(|v| {
                    v.get("fingerprint")
                        .and_then(Value::as_str)
                        .is_some_and(|f| f != fingerprint)
                })
                .count()
        })
        .unwrap_or(0);
    if stale > 0 {
        diffs.push(format!(
            "{stale} truth file(s) in {} written by another run (other inputs, settings or \
             program version), which this study would remove",
            out.join(TRUTHS_DIR).display()
        ));
        if old.is_none() {
            there = format!("a study whose truths are in {}", out.display());
        }
    }
    let old = match old {
        Some(old) => old,
        None if stale > 0 => Existing {
            file: out.join(TRUTHS_DIR),
            record: Value::Null,
            readable: true,
        },
        None => return Ok(None),
    };
    Ok(refuse_other_run(&old, &diffs, &there, &here, force)?)
}

/// A coverage study's record (`coverage.json`, or this run's) with `n` truths, in a few words.
fn describe_study(v: &serde_json::Value, n: u64) -> String {
    use hpge_reports::replace::{text_at, value_at};
    format!(
        "{n} truths of prior {}, model {} (hash {}), data {} ({} data); seed {}, {} sampler, \
         ESS {}{}",
        text_at(v, "/inputs/prior"),
        text_at(v, "/inputs/model"),
        text_at(v, "/inputs/model_hash"),
        text_at(v, "/inputs/data"),
        text_at(v, "/data_from"),
        value_at(v, "/settings/seed"),
        value_at(v, "/settings/fit/sample/sampler"),
        value_at(v, "/settings/fit/sample/ess_min"),
        match v.pointer("/settings/pipeline") {
            Some(p) if !p.is_null() => ", exact check and refinement",
            _ => "",
        }
    )
}

/// `validate coverage --progress`: the statistics over the truths written so far, nothing run.
fn coverage_progress(
    out: &std::path::Path,
    fingerprint: &str,
    prior: &hpge_inference::Prior,
    settings: &hpge_validation::CoverageSettings,
    as_json: bool,
) -> Result<()> {
    let report = progress(out, fingerprint, prior, settings)?;
    let done = report.as_ref().map_or(0, |r| r.n_truths + r.skipped);
    if as_json {
        let mut j = report.as_ref().map_or(serde_json::json!({}), brief_json);
        if let Some(obj) = j.as_object_mut() {
            obj.insert("partial".into(), true.into());
            obj.insert("done".into(), done.into());
            obj.insert("total".into(), settings.n_truths.into());
        }
        outln!("{j}");
        return Ok(());
    }
    outln!(
        "progress of the study in {}: {done} of {} truths done (nothing run here; the bands \
         below are those of the truths done, and the study's verdict is the one at {})",
        out.display(),
        settings.n_truths,
        settings.n_truths
    );
    if let Some(r) = &report {
        print_report(r, false)?;
    }
    Ok(())
}

/// The fields first: n_truths, parameters (name, ks_p, coverage_683, coverage_955),
/// pass; the full record is in coverage.json.
fn brief_json(report: &CoverageReport) -> serde_json::Value {
    serde_json::json!({
        "n_truths": report.n_truths,
        "parameters": report.parameters.iter().map(|p| serde_json::json!({
            "name": p.name, "ks_p": p.ks_p, "coverage_683": p.coverage_683, "coverage_955": p.coverage_955,
            "expected_683": p.expected_683, "expected_955": p.expected_955,
        })).collect::<Vec<_>>(),
        "pass": report.pass,
        "unconverged": report.unconverged,
        "unconverged_sampler": report.unconverged_sampler,
        "skipped": report.skipped,
        "seconds": report.seconds,
        "resumed": report.resumed,
        "truth_seconds": report.truth_seconds,
        "exact_check": report.exact_check,
        "subsets": report.subsets.iter().map(|s| serde_json::json!({
            "subset": s.subset, "n_truths": s.n_truths, "pass": s.pass, "failures": s.failures,
        })).collect::<Vec<_>>(),
    })
}

/// The report as text: the counts, the exact checks and a table of the parameters; `ran`: this
/// process ran the study (else the truths done so far were only read).
fn print_report(report: &CoverageReport, ran: bool) -> Result<()> {
    let verdict = if report.pass { "PASS" } else { "FAIL" };
    if ran {
        outln!(
            "{} truths ({} skipped, {} fits unconverged, {} taken back from an earlier run) in {:.0} s ({:.0} s of truths' work): {verdict}",
            report.n_truths,
            report.skipped,
            report.unconverged,
            report.resumed,
            report.seconds,
            report.truth_seconds,
        );
    } else {
        outln!(
            "{} truths ({} skipped, {} fits unconverged; {:.0} s of truths' work): so far {verdict}",
            report.n_truths,
            report.skipped,
            report.unconverged,
            report.truth_seconds,
        );
    }
    if let Some(u) = &report.unconverged_sampler {
        outln!(
            "unconverged fits recording their sampler: {} ({} at the draw cap, {} at the clock); smallest ESS {:.0}, largest R-hat {:.4}",
            u.recorded,
            u.max_draws,
            u.max_seconds,
            u.ess_min,
            u.rhat_max
        );
    }
    if let Some(c) = &report.exact_check {
        outln!(
            "exact check of the fits: {} passed, {} failed after refinement; {:.2} rounds per fit on average, at most {}",
            c.passed,
            c.failed,
            c.rounds_mean,
            c.rounds_max
        );
        if let Some(t) = c.seconds_split {
            outln!(
                "their wall time over the {} fits that record it: {:.0} s sampling, {:.0} s exact solves, {:.0} s error models",
                c.split_truths,
                t.sampling,
                t.exact,
                t.error_model
            );
        }
    }
    outln!(
        "{:<10} {:>8} {:>10} {:>17} {:>10} {:>17}",
        "parameter",
        "KS p",
        "cov 68.3%",
        "99% expected",
        "cov 95.5%",
        "99% expected"
    );
    for p in &report.parameters {
        outln!(
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
    for s in &report.subsets {
        outln!("{}", subset_line(s));
    }
    Ok(())
}

/// One line on a subset of the truths: its size, its verdict with its own bands and, where it
/// fails, what; where it passes, its smallest KS p and its coverages' ranges.
fn subset_line(s: &SubsetCoverage) -> String {
    let head = format!(
        "over the {} {} only (a diagnostic; the verdict is the whole set's):",
        s.n_truths,
        s.subset.describe()
    );
    if !s.pass {
        return format!("{head} FAIL ({})", s.failures.join("; "));
    }
    let range = |f: fn(&ParameterCoverage) -> f64| {
        s.parameters
            .iter()
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            })
    };
    let (ks, _) = range(|p| p.ks_p);
    let (a, b) = range(|p| p.coverage_683);
    let (c, e) = range(|p| p.coverage_955);
    let band = |x: [f64; 2]| format!("[{:.3}, {:.3}]", x[0], x[1]);
    let (e683, e955) = s
        .parameters
        .first()
        .map_or((String::new(), String::new()), |p| {
            (band(p.expected_683), band(p.expected_955))
        });
    format!(
        "{head} PASS (smallest KS p {ks:.3}; 68.3% coverage {a:.3}-{b:.3} in {e683}, 95.5% coverage {c:.3}-{e:.3} in {e955})"
    )
}

/// The line a truth's event prints, if any: each round's start of the exact check and its end,
/// and the exact check's curves in steps of a quarter.
fn truth_event_line(i: usize, e: &TruthEvent) -> Option<String> {
    match *e {
        TruthEvent::Sampled { round } => Some(format!(
            "truth {i}: round {round} sampled, exact check running"
        )),
        TruthEvent::Exact { done, total } => {
            let quarter = total.div_ceil(4).max(1);
            (done > 0 && (done % quarter == 0 || done == total))
                .then(|| format!("truth {i}: {done}/{total} exact curves"))
        }
        TruthEvent::Round(r) => Some(format!(
            "truth {i}: round {} {}: k-hat {:.2}, largest shift {:.2} sd, {} (sampling {:.0} s, exact {:.0} s)",
            r.round,
            if r.resumed { "taken back" } else { "ended" },
            r.pareto_k,
            r.max_abs_shift_sd,
            match (r.pass, &r.better_basin) {
                (true, _) => "pass".to_string(),
                (false, Some(b)) => format!(
                    "fail (an exact ascent found a better basin: ln p {:+.1})",
                    b.ln_posterior_exact - b.ln_posterior_exact_at_mode
                ),
                (false, None) => "fail".to_string(),
            },
            r.sampling_seconds,
            r.exact_seconds
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_truth_prints_its_exact_curves_by_quarters_and_each_round() {
        let exact = |done| truth_event_line(7, &TruthEvent::Exact { done, total: 104 });
        let printed: Vec<usize> = (0..=104).filter(|&d| exact(d).is_some()).collect();
        assert_eq!(printed, [26, 52, 78, 104]);
        assert_eq!(exact(52).as_deref(), Some("truth 7: 52/104 exact curves"));
        let r = hpge_inference::fit::RefineRound {
            round: 1,
            training_curves: 104,
            pareto_k: 0.29,
            max_abs_shift_sd: 0.081,
            max_rel_diff_at_mode: 0.0019,
            pass: true,
            sampling_seconds: 74.7,
            exact_seconds: 129.3,
            error_model_seconds: 1.0,
            resumed: true,
            stopped: None,
            local_mode_curves: 3,
            better_basin: None,
            variance_at: None,
        };
        assert_eq!(
            truth_event_line(7, &TruthEvent::Round(&r)).as_deref(),
            Some(
                "truth 7: round 1 taken back: k-hat 0.29, largest shift 0.08 sd, pass (sampling 75 s, exact 129 s)"
            )
        );
        // Inside both limits, failed by a better basin: the line says so.
        let basin = hpge_inference::fit::RefineRound {
            pass: false,
            resumed: false,
            better_basin: Some(hpge_inference::fit::BasinAscent {
                start: vec![0.1],
                theta: vec![0.2],
                ln_posterior_exact: -10.0,
                ln_posterior_exact_at_mode: -13.25,
                evaluations: 40,
                better: true,
            }),
            ..r
        };
        assert_eq!(
            truth_event_line(7, &TruthEvent::Round(&basin)).as_deref(),
            Some(
                "truth 7: round 1 ended: k-hat 0.29, largest shift 0.08 sd, fail (an exact ascent found a better basin: ln p +3.2) (sampling 75 s, exact 129 s)"
            )
        );
    }
}
