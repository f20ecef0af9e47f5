//! `hpge-cv generate` (training rows from quasi-random samples, resumable and sharded) and
//! `hpge-cv merge` (shard folders into one set).

use std::path::{Path, PathBuf};

use anyhow::Result;
use hpge_solver::{Detector, FieldSettings, Parameters};
use hpge_surrogate::generate::label as label_rows;
use hpge_surrogate::job::{GenerateOptions, LabelOptions};
use hpge_surrogate::{ExactSolver, Generator, ParameterSpace, merge, run};
use indicatif::{ProgressBar, ProgressStyle};

/// Runs or resumes a generation.
pub fn generate(o: &GenerateOptions) -> Result<()> {
    let space = ParameterSpace::from_file(&o.space)?;
    let det = Detector::from_file(&o.detector, &Parameters::new())?;
    let settings = o.grid.apply(&FieldSettings::default(), &det)?;
    let g = Generator::new(
        space,
        &o.detector,
        settings,
        o.sequence,
        o.seed,
        o.offset,
        o.n,
        o.shard,
    )?
    .with_curve_points(o.curve_points)?
    .with_retry_failed(o.retry_failed);
    let g = if o.where_models.is_empty() {
        g
    } else {
        let mut models = Vec::new();
        for f in &o.where_models {
            let bytes = std::fs::read(f).map_err(|e| {
                anyhow::anyhow!("--where {}: cannot read the model ({e})", f.display())
            })?;
            let model = hpge_surrogate::model::Surrogate::load(f)?;
            models.push((f.display().to_string(), bytes, model));
        }
        let g = g.with_selection(&models, o.share)?;
        eprintln!(
            "--where: {} of {} candidates chosen by {}",
            g.chosen.as_ref().map_or(0, |c| c.len()),
            o.n,
            g.fingerprint
                .selection
                .as_ref()
                .map_or("", |s| s.score.as_str())
        );
        g
    };
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:40} {pos}/{len} samples, {per_sec}, {elapsed} elapsed, eta {eta}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let start = std::time::Instant::now();
    let report = run(&g, &o.out, o.threads, |done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    });
    bar.finish_and_clear();
    let report = report?;
    let seconds = start.elapsed().as_secs_f64();
    if report.repaired {
        eprintln!("note: cut off a torn last line left by an interrupted run");
    }
    if report.retried > 0 {
        eprintln!(
            "note: solved again {} rows that had failed before (--retry-failed)",
            report.retried
        );
    }
    for (i, status) in &report.failed {
        eprintln!("sample {i}: {status}");
    }
    outln!(
        "{}: {} rows ({} from before, {} now in {seconds:.1} s, {:.2} samples/s), {} failed solves",
        o.out.join("rows.csv").display(),
        report.total,
        report.resumed,
        report.written,
        report.written as f64 / seconds.max(1e-9),
        report.failed.len()
    );
    Ok(())
}

/// Merges shard folders.
pub fn merge_shards(dirs: &[PathBuf], out: &Path) -> Result<()> {
    let r = merge(dirs, out)?;
    outln!(
        "{}: {} rows from {} shards ({} failed solves)",
        out.display(),
        r.rows,
        dirs.len(),
        r.failed
    );
    Ok(())
}

/// Labels rows made before the regime columns existed.
pub fn label(o: &LabelOptions) -> Result<()> {
    let space = ParameterSpace::from_file(&o.space)?;
    let det = Detector::from_file(&o.detector, &Parameters::new())?;
    let settings = o.grid.apply(&FieldSettings::default(), &det)?;
    settings
        .validate()
        .map_err(|e| anyhow::anyhow!("solver settings: {e}"))?;
    let exact = ExactSolver::new(space, &o.detector, settings)?;
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:40} {pos}/{len} rows, {per_sec}, {elapsed} elapsed, eta {eta}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let start = std::time::Instant::now();
    let report = label_rows(&exact, &o.data, &o.out, o.threads, |done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    });
    bar.finish_and_clear();
    let report = report?;
    for (i, reason) in &report.failed {
        eprintln!("row {i}: {reason}");
    }
    outln!(
        "{}: {} rows ({} from before, {} solved and {} copied now in {:.1} s), {} failed solves{}",
        o.out.join("rows.csv").display(),
        report.total,
        report.resumed,
        report.solved,
        report.copied,
        start.elapsed().as_secs_f64(),
        report.failed.len(),
        if report.sorted {
            ", sorted by index"
        } else {
            ""
        }
    );
    Ok(())
}
