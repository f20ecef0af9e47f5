//! The outputs of `discover`: the summary as JSON, the per-voltage residuals before and after
//! the chosen extension, the figures and the Markdown report.

mod report;

use std::fmt::Write as _;
use std::path::Path;

use hpge_inference::discover::{Stages, lock_output, run_fingerprint};
use hpge_inference::fit::FitJob;
use hpge_inference::{DiscoverInputs, DiscoverSettings, Discovery, PriorSpec, Progress, discover};

pub use report::write_report;

use crate::{Error, Result, plot};

/// The per-voltage table: data, both models at their modes, sigma, standardised residuals; one
/// header row, no comment lines (the provenance is in `discovery.json`: `program_version`,
/// `start_model`, `chosen`).
pub fn write_residuals(path: &Path, d: &Discovery) -> Result<()> {
    let mut f = String::new();
    let _ = writeln!(
        f,
        "voltage_V,c_m_pF,before_c_pF,before_sigma_pF,before_residual,after_c_pF,after_sigma_pF,after_residual"
    );
    let after = d.after.as_ref().unwrap_or(&d.before);
    for k in 0..d.voltage_v.len() {
        let _ = writeln!(
            f,
            "{},{},{},{},{},{},{},{}",
            d.voltage_v[k],
            d.c_m_pf[k],
            d.before.c_mode[k],
            d.before.sigma_mode[k],
            d.before.check.residuals[k],
            after.c_mode[k],
            after.sigma_mode[k],
            after.check.residuals[k]
        );
    }
    hpge_files::write(path, f).map_err(Error::io(path, "cannot write"))
}

/// Writes a discovery's outputs into `out`: `discovery.json`, `residuals.csv`, `report.md` and
/// (unless `no_plots`) the figures, drawn on the start model's detector.
///
/// # Errors
/// A file that cannot be written, a figure that cannot be drawn, a detector that cannot be built.
pub fn write_outputs(
    out: &Path,
    d: &Discovery,
    exact: &hpge_surrogate::ExactSolver,
    no_plots: bool,
) -> Result<()> {
    let json = out.join("discovery.json");
    hpge_files::write(&json, serde_json::to_string_pretty(&d.summary)? + "\n")
        .map_err(Error::io(&json, "cannot write"))?;
    write_residuals(&out.join("residuals.csv"), d)?;
    let figures = if no_plots {
        Vec::new()
    } else {
        let det = exact.detector(&d.start_inputs)?;
        plot::discovery_figures(d, &det, out)?
    };
    write_report(&out.join("report.md"), d, &figures)?;
    Ok(())
}

/// Runs `discover` as the command line and Python do, on `job` (data, surrogate, exact solver;
/// its prior is not used) with the start model `start` read from `start_file`. With `out`, the
/// folder is made and locked for the run ([`lock_output`]; a second `discover` on it is refused,
/// naming the holder), the finished stages are written to `out/stages` as they go and taken back
/// by a rerun with the same arguments ([`Stages`]; a folder of another run is cleared first),
/// and every output is written there at the end (figures unless `no_plots`).
///
/// # Errors
/// An output folder that cannot be made or is locked, or holds the discovery of another run
/// (other inputs or settings: [`Error::OtherRun`], unless `force`), the workflow's errors,
/// writing failures.
#[allow(clippy::too_many_arguments)]
pub fn run_discover(
    job: &FitJob,
    start: &PriorSpec,
    start_file: &Path,
    settings: &DiscoverSettings,
    out: Option<&Path>,
    no_plots: bool,
    force: bool,
    progress: &dyn Progress,
) -> Result<Discovery> {
    let mut inputs = job.inputs.clone();
    inputs.insert("start_model".into(), start_file.display().to_string());
    // A folder this run makes is removed again when it fails before a stage is finished (a
    // full disk, issue 66); one with finished stages stays, to resume from.
    let mut folder = None;
    let (lock, stages) = match out {
        Some(dir) => {
            // A folder holding another run's discovery is refused unless `force` (issue 69).
            let record = serde_json::json!({ "inputs": inputs, "settings": settings });
            if let Some(w) = crate::replace::check_replace(
                &dir.join("discovery.json"),
                &record,
                &describe_run,
                force,
            )? {
                progress.stage(&format!("warning: {w}"));
            }
            folder = Some(
                hpge_files::NewFolder::create(dir, |d| hpge_files::has_entries(&d.join("stages")))
                    .map_err(|e| Error::Output {
                        flag: "--out".into(),
                        file: dir.to_path_buf(),
                        message: format!("cannot create the folder: {e}"),
                    })?,
            );
            let lock = lock_output(dir)?;
            let fp = run_fingerprint(&inputs, settings, &job.exact.settings);
            (Some(lock), Some(Stages::open(dir, fp)?))
        }
        None => (None, None),
    };
    let surrogate: std::sync::Arc<dyn hpge_inference::CvModel> =
        std::sync::Arc::new(job.surrogate.clone());
    let d = discover(
        &DiscoverInputs {
            surrogate,
            exact: &job.exact,
            start,
            likelihood: &job.likelihood,
            inputs,
            stages: stages.as_ref(),
        },
        settings,
        progress,
    )?;
    if let Some(dir) = out {
        write_outputs(dir, &d, &job.exact, no_plots)?;
    }
    drop(lock);
    if let Some(f) = folder.as_mut() {
        f.keep();
    }
    Ok(d)
}

/// A discovery's record (its inputs and settings, as `discovery.json` has them) in a few words.
pub fn describe_run(v: &serde_json::Value) -> String {
    use crate::replace::{text_at, value_at};
    format!(
        "start model {}, model {} (hash {}), data {} (hash {}); seed {}, {}, extensions {}",
        text_at(v, "/inputs/start_model"),
        text_at(v, "/inputs/model"),
        text_at(v, "/inputs/model_hash"),
        text_at(v, "/inputs/data"),
        text_at(v, "/inputs/data_hash"),
        value_at(v, "/settings/seed"),
        if v.pointer("/settings/exact") == Some(&serde_json::Value::Bool(false)) {
            "surrogate only"
        } else {
            "exact solver"
        },
        match v
            .pointer("/settings/only")
            .and_then(serde_json::Value::as_array)
        {
            Some(a) if !a.is_empty() => value_at(v, "/settings/only"),
            _ => "all".into(),
        }
    )
}
