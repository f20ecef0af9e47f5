//! The `measure` job: raw pulser data to a C-V curve with its covariance and the run's report
//! (`<stem>.measure.json`).

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::circuit::Uncertainties;
use crate::{
    Error, MeasureOptions, MeasureSettings, Measurement, Problem, RawRun, Result, covariance_path,
    curve_texts, measure, read_raw_dir,
};

/// A finished `measure` job.
#[derive(Debug, Clone)]
pub struct MeasureRun {
    /// What was read from the raw folder (the pulse sets and the reading's problems).
    pub read: RawRun,
    /// The measured curve and its points.
    pub measurement: Measurement,
    /// The settings it ran with.
    pub settings: MeasureSettings,
    /// Where the settings came from (a file, or the defaults).
    pub settings_source: String,
    /// The raw folder (or LH5 file) as given.
    pub raw: PathBuf,
}

/// Runs the `measure` job: the settings (`MeasureOptions::measure_settings`), every pulse file
/// of the raw folder (`read_raw_dir`), the tail fits, pulser peaks and c12 per bias with the
/// covariance (`measure`).
///
/// Errors: settings or a raw folder that cannot be read, and a run without any usable bias;
/// problems with single files or biases are collected in the run instead.
pub fn measure_raw(o: &MeasureOptions) -> Result<MeasureRun> {
    let (settings, settings_source) = o.measure_settings()?;
    let read = read_raw_dir(&o.raw, settings.voltages_v.as_deref())?;
    let measurement = measure(&read.sets, &settings, &o.raw)?;
    Ok(MeasureRun {
        read,
        measurement,
        settings,
        settings_source,
        raw: o.raw.clone(),
    })
}

/// Failed tail fits of one reason, in a report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FailedFits {
    /// Why they failed.
    pub reason: &'static str,
    /// How many.
    pub count: usize,
}

/// One bias of a report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PointReport {
    /// Bias, V.
    #[serde(rename = "voltage_V")]
    pub voltage_v: f64,
    /// The pulse file.
    pub file: String,
    /// Pulses in it.
    pub pulses: usize,
    /// Failed tail fits by reason.
    pub failed_fits: Vec<FailedFits>,
    /// Mean Q_t of the pulser peak, pC.
    #[serde(rename = "peak_mean_pC")]
    pub peak_mean_pc: f64,
    /// Its statistical uncertainty, pC.
    #[serde(rename = "peak_mean_err_pC")]
    pub peak_mean_err_pc: f64,
    /// The peak's width, pC.
    #[serde(rename = "peak_width_pC")]
    pub peak_width_pc: f64,
    /// Pulser events in the peak.
    pub peak_events: f64,
}

/// A file or bias that gave no point, in a report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProblemReport {
    /// The file (or folder) concerned.
    pub file: String,
    /// The bias, where known, V.
    #[serde(rename = "voltage_V")]
    pub voltage_v: Option<f64>,
    /// What went wrong.
    pub message: String,
}

/// The report of a `measure` job: `<stem>.measure.json` beside the curve and what `hpge-cv
/// measure --json` prints (the faces add `command`, the command that ran).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeasureReport {
    /// The raw folder.
    pub raw: String,
    /// Where the settings came from.
    pub settings: String,
    /// Biases, V.
    #[serde(rename = "voltage_V")]
    pub voltage_v: Vec<f64>,
    /// c12, pF.
    #[serde(rename = "c12_pF")]
    pub c12_pf: Vec<f64>,
    /// Total standard uncertainty per bias, pF.
    #[serde(rename = "sigma_pF")]
    pub sigma_pf: Vec<f64>,
    /// Statistical part, pF.
    #[serde(rename = "sigma_stat_pF")]
    pub sigma_stat_pf: Vec<f64>,
    /// Where -dc12/dU_B falls to the threshold, V.
    #[serde(rename = "depletion_voltage_V")]
    pub depletion_voltage_v: Option<f64>,
    /// Every bias measured.
    pub points: Vec<PointReport>,
    /// Files and biases that gave no point (reading first, then fitting).
    pub problems: Vec<ProblemReport>,
    /// The program.
    pub program: &'static str,
    /// The program version.
    pub version: &'static str,
    /// What made this file: program, version and date (a measurement has no solver revision).
    pub made: hpge_foundation::Made,
    /// The uncertainty model.
    pub uncertainties: Uncertainties,
    /// The covariance file's name beside the curve (null without a covariance).
    pub covariance_file: Option<String>,
}

impl MeasureRun {
    /// Every problem: the reading's, then the fits'.
    pub fn problems(&self) -> impl Iterator<Item = &Problem> {
        self.read.problems.iter().chain(&self.measurement.problems)
    }

    /// The report, for a curve written to `out` (it names the covariance file beside it).
    pub fn report(&self, out: &Path) -> MeasureReport {
        let m = &self.measurement;
        MeasureReport {
            raw: self.raw.display().to_string(),
            settings: self.settings_source.clone(),
            voltage_v: m.curve.voltage_v.clone(),
            c12_pf: m.curve.c12_pf.clone(),
            sigma_pf: m.curve.sigma_pf.clone(),
            sigma_stat_pf: m.points.iter().map(|p| p.sigma_stat_pf).collect(),
            depletion_voltage_v: m.depletion_voltage_v,
            points: m
                .points
                .iter()
                .map(|p| PointReport {
                    voltage_v: p.bias_v,
                    file: p.source.display().to_string(),
                    pulses: p.n_pulses,
                    failed_fits: p
                        .failed
                        .iter()
                        .map(|(f, n)| FailedFits {
                            reason: f.as_str(),
                            count: *n,
                        })
                        .collect(),
                    peak_mean_pc: p.peak.mean_pc,
                    peak_mean_err_pc: p.peak.mean_err_pc,
                    peak_width_pc: p.peak.sigma_pc,
                    peak_events: p.peak.amplitude,
                })
                .collect(),
            problems: self
                .problems()
                .map(|p| ProblemReport {
                    file: p.file.display().to_string(),
                    voltage_v: p.bias_v,
                    message: p.message.clone(),
                })
                .collect(),
            program: "hpge-cv",
            version: env!("CARGO_PKG_VERSION"),
            made: hpge_foundation::Made::now(None),
            uncertainties: self.settings.uncertainties.clone(),
            covariance_file: m
                .curve
                .covariance_pf2
                .as_ref()
                .map(|_| covariance_name(out)),
        }
    }

    /// Stages the job's files in `staged` (put in place when the face commits them, all or
    /// none): the curve `out`, its covariance `<stem>.covariance.csv` (when there is one) and the
    /// report `<stem>.measure.json` with `command` added. Returns the report as written and,
    /// when the curve has no covariance, the covariance path that the face removes after the
    /// commit if an older one lies there (it would be read with the new curve).
    pub fn stage(
        &self,
        out: &Path,
        command: &[String],
        staged: &mut hpge_files::Staged,
    ) -> Result<(serde_json::Value, Option<PathBuf>)> {
        let (table, covariance) = curve_texts(out, &self.measurement.curve, &[])?;
        staged
            .write(out, table.as_bytes())
            .map_err(Error::io(out, "cannot write the file"))?;
        let covariance_file = covariance_path(out);
        if let Some(text) = &covariance {
            staged
                .write(&covariance_file, text.as_bytes())
                .map_err(Error::io(&covariance_file, "cannot write the file"))?;
        }
        let mut report = serde_json::to_value(self.report(out)).map_err(|e| Error::Numerical {
            what: "the measurement's report".into(),
            message: e.to_string(),
        })?;
        if let Some(obj) = report.as_object_mut() {
            obj.insert("command".into(), command.into());
        }
        let report_path = out.with_extension("measure.json");
        staged
            .write(&report_path, format!("{report:#}\n").as_bytes())
            .map_err(Error::io(&report_path, "cannot write the report"))?;
        Ok((report, covariance.is_none().then_some(covariance_file)))
    }
}

/// The name of the curve's covariance file: `<stem>.covariance.csv`.
fn covariance_name(csv: &Path) -> String {
    format!(
        "{}.covariance.csv",
        csv.file_stem().unwrap_or_default().to_string_lossy()
    )
}
