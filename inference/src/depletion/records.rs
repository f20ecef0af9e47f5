//! Every LEGEND diode record of a metadata folder through [`super::depletion`] into one table
//! (`hpge-cv depletion --records DIR`).
//!
//! Each record (`*.json`, `*.yaml`, `*.yml`, sorted by name) is converted as `detector
//! --from-legend` converts it (`hpge_solver::detector::legend`), its U_fd and pinch-off voltage
//! searched with their error bars, and, where its `characterization` gives a depletion voltage,
//! the posterior of its impurity scale factor computed with that voltage and `sigma_v`. A file
//! that is not a diode record (a crystal record, a README) or that the converter refuses is a
//! row with its reason, not the end of the run.
//!
//! Resumable and shardable as `generate` is: with an output folder, every finished record is
//! written at once to `rows/NAME.json` with the inputs that made it (the record's text, the
//! settings, the options, the program's version and solver revision); a rerun keeps the rows
//! whose inputs match and solves the rest. `shard` K/M takes the records whose index in the
//! sorted list is K modulo M, so M Slurm array tasks writing to one folder split the work;
//! every run writes the table of all rows present (`table.md`, `table.csv`), so the last one
//! to finish leaves the whole table.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use hpge_foundation::Shard;
use hpge_solver::detector::legend::{LegendOptions, read_file, to_toml};
use hpge_solver::{Detector, FieldSettings, Parameters};

use super::{DepletionOptions, Measured, ScalePrior, TiltPrior, depletion};
use crate::error::{Error, Result};

/// What a records run is asked for.
#[derive(Debug, Clone)]
pub struct RecordsOptions {
    /// The folder of records.
    pub dir: PathBuf,
    /// Folder for the per-record rows and the tables (resumable); none: nothing written.
    pub out: Option<PathBuf>,
    /// This process's share of the records.
    pub shard: Shard,
    /// The measured voltage's standard uncertainty, V (records give none).
    pub sigma_v: f64,
    /// The factor's prior.
    pub prior: ScalePrior,
    /// Fit the tilt of the density's gradient too, with this prior, for every record whose
    /// density varies along z (the others get the factor alone and a note).
    pub tilt: Option<TiltPrior>,
    /// The gate on |simulated - measured|, V.
    pub gate_v: f64,
    /// Search the pinch-off voltage too.
    pub pinch_off: bool,
    /// How records become detectors.
    pub legend: LegendOptions,
    /// Grid overrides (`--tolerance`, `--grid`) applied to every record's detector.
    pub grid: hpge_solver::GridOverrides,
}

/// One record's line of the table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecordRow {
    /// The record's file name.
    pub record: String,
    /// The detector's name (the record's `name`).
    pub name: Option<String>,
    /// Its type (icpc, bege, ppc, coax).
    pub kind: Option<String>,
    /// U_fd, V.
    pub depletion_voltage_v: Option<f64>,
    /// Its error bar, V.
    pub depletion_voltage_err_v: Option<f64>,
    /// U_fd on the reference grid with every interval halved, V (the error bar's check).
    #[serde(default)]
    pub depletion_voltage_halved_v: Option<f64>,
    /// Whether U_fd converges with the grid (`DepletionVoltages::full_depletion_converged`);
    /// false: not to be quoted.
    #[serde(default)]
    pub depletion_voltage_converged: Option<bool>,
    /// Pinch-off voltage, V.
    pub pinch_off_voltage_v: Option<f64>,
    /// Its error bar, V.
    pub pinch_off_voltage_err_v: Option<f64>,
    /// The record's depletion voltage (`characterization`), V.
    pub measured_v: Option<f64>,
    /// Posterior median of the impurity scale factor.
    pub factor: Option<f64>,
    /// Its central 68.3% interval.
    pub factor_68: Option<(f64, f64)>,
    /// Posterior median of the tilt (with `--tilt-range` and a density that varies along z).
    #[serde(default)]
    pub tilt: Option<f64>,
    /// Its central 68.3% interval.
    #[serde(default)]
    pub tilt_68: Option<(f64, f64)>,
    /// |simulated - measured| > gate.
    pub exceeds_gate: Option<bool>,
    /// Why there are no numbers (not a diode record, a conversion or solver failure), or a
    /// remark (factor at a prior bound).
    pub note: Option<String>,
}

/// A row file: the row and the inputs it was made from.
#[derive(Debug, Serialize, Deserialize)]
struct RowFile {
    inputs: serde_json::Value,
    row: RecordRow,
}

/// The record files of `dir`, sorted by name.
///
/// # Errors
/// A folder that cannot be read, or one with no record file.
pub fn record_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let io = |source| Error::Io {
        file: dir.to_path_buf(),
        action: "cannot read the folder (--records)",
        source,
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(io)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.is_file()
                && p.extension().and_then(|e| e.to_str()).is_some_and(|e| {
                    ["json", "yaml", "yml"].contains(&e.to_ascii_lowercase().as_str())
                })
        })
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(Error::Argument {
            name: "--records".into(),
            message: format!(
                "{}: no record file (*.json, *.yaml, *.yml) in the folder",
                dir.display()
            ),
        });
    }
    Ok(files)
}

/// Runs this shard's records (module docs); returns the rows of every record of the folder
/// that has one (this run's and, with an output folder, those other shards or runs left),
/// in file order. `progress(done, total, name)` is called before each record.
///
/// # Errors
/// An unreadable folder or output folder; a record's own failure is its row's note.
pub fn run_records(
    o: &RecordsOptions,
    settings: &FieldSettings,
    mut progress: impl FnMut(usize, usize, &str),
) -> Result<Vec<RecordRow>> {
    let files = record_files(&o.dir)?;
    let rows_dir = o.out.as_ref().map(|d| d.join("rows"));
    if let Some(d) = &rows_dir {
        std::fs::create_dir_all(d).map_err(|source| Error::Io {
            file: d.clone(),
            action: "cannot create the folder (--out)",
            source,
        })?;
    }
    let mine: Vec<usize> = (0..files.len())
        .filter(|&i| i as u64 % o.shard.m == o.shard.k)
        .collect();
    let mut rows: Vec<Option<RecordRow>> = vec![None; files.len()];
    for (done, &i) in mine.iter().enumerate() {
        let file = &files[i];
        let name = file_name(file);
        progress(done, mine.len(), &name);
        let inputs = inputs(file, o, settings)?;
        let row_path = rows_dir.as_ref().map(|d| d.join(format!("{name}.json")));
        if let Some(p) = &row_path
            && let Some(row) = load_row(p, &inputs)
        {
            rows[i] = Some(row);
            continue;
        }
        let row = one_record(file, o, settings);
        if let Some(p) = &row_path {
            let text = serde_json::to_string_pretty(&RowFile {
                inputs,
                row: row.clone(),
            })
            .expect("a row serialises");
            hpge_files::write(p, text).map_err(|source| Error::Io {
                file: p.clone(),
                action: "cannot write the file",
                source,
            })?;
        }
        rows[i] = Some(row);
    }
    progress(mine.len(), mine.len(), "");
    // Rows of the other shards (or earlier runs) with matching inputs.
    if let Some(d) = &rows_dir {
        for (i, file) in files.iter().enumerate() {
            if rows[i].is_none() {
                let p = d.join(format!("{}.json", file_name(file)));
                rows[i] = load_row(&p, &inputs(file, o, settings)?);
            }
        }
    }
    Ok(rows.into_iter().flatten().collect())
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
}

/// The inputs that decide a record's row.
fn inputs(file: &Path, o: &RecordsOptions, settings: &FieldSettings) -> Result<serde_json::Value> {
    let text = std::fs::read_to_string(file).map_err(|source| Error::Io {
        file: file.to_path_buf(),
        action: "cannot read the file",
        source,
    })?;
    let mut v = serde_json::json!({
        "record_text": text,
        "settings": settings,
        "sigma_V": o.sigma_v,
        "prior": o.prior,
        "gate_V": o.gate_v,
        "pinch_off": o.pinch_off,
        "grid": format!("{:?}", o.grid),
        "legend": {
            "n_plus_thickness_mm": o.legend.n_plus_thickness_mm,
            "p_plus_thickness_mm": o.legend.p_plus_thickness_mm,
            "can_gap_mm": o.legend.can_gap_mm,
            "default_impurity_cm3": o.legend.default_impurity_cm3,
        },
        "version": env!("CARGO_PKG_VERSION"),
        "solver_revision": hpge_solver::field::PHYSICS_REVISION,
    });
    // Only with a tilt: rows made without one keep matching.
    if let Some(t) = o.tilt {
        v["tilt_prior"] = serde_json::json!(t);
    }
    Ok(v)
}

fn load_row(path: &Path, inputs: &serde_json::Value) -> Option<RecordRow> {
    let text = std::fs::read_to_string(path).ok()?;
    let f: RowFile = serde_json::from_str(&text).ok()?;
    (f.inputs == *inputs).then_some(f.row)
}

/// One record's row; failures become its note.
fn one_record(file: &Path, o: &RecordsOptions, settings: &FieldSettings) -> RecordRow {
    let mut row = RecordRow {
        record: file_name(file),
        name: None,
        kind: None,
        depletion_voltage_v: None,
        depletion_voltage_err_v: None,
        depletion_voltage_halved_v: None,
        depletion_voltage_converged: None,
        pinch_off_voltage_v: None,
        pinch_off_voltage_err_v: None,
        measured_v: None,
        factor: None,
        factor_68: None,
        tilt: None,
        tilt_68: None,
        exceeds_gate: None,
        note: None,
    };
    if let Err(e) = fill(&mut row, file, o, settings) {
        row.note = Some(e.to_string());
    }
    row
}

fn fill(
    row: &mut RecordRow,
    file: &Path,
    o: &RecordsOptions,
    settings: &FieldSettings,
) -> Result<()> {
    let diode = read_file(file, &o.legend)?;
    row.name = Some(diode.name.clone());
    row.kind = Some(diode.kind.clone());
    row.measured_v = diode.depletion_voltage_v.filter(|&u| u > 0.0);
    let text = to_toml(&diode, file, &o.legend);
    let det = Detector::from_toml_str(&text, &file.with_extension("toml"), &Parameters::new())?;
    let settings = o.grid.apply(settings, &det)?;
    let opts = DepletionOptions {
        measured: row.measured_v.map(|u| Measured {
            voltage_v: u,
            sigma_v: o.sigma_v,
        }),
        prior: o.prior,
        tilt: o.tilt.filter(|_| det.impurity_varies_along_z()),
        pinch_off: o.pinch_off,
        curve: false,
        gate_v: o.gate_v,
    };
    let r = depletion(&det, &settings, &opts, |_| {})?;
    if let Some(u) = r.voltages.full_depletion {
        row.depletion_voltage_v = Some(u.voltage_v);
        row.depletion_voltage_err_v = Some(u.err_v);
    }
    row.depletion_voltage_halved_v = r.voltages.full_depletion_halved_v;
    row.depletion_voltage_converged = r.voltages.full_depletion_converged;
    if let Some(u) = r.voltages.pinch_off {
        row.pinch_off_voltage_v = Some(u.voltage_v);
        row.pinch_off_voltage_err_v = Some(u.err_v);
    }
    row.exceeds_gate = r.exceeds_gate;
    let mut notes = Vec::new();
    if r.voltages.full_depletion.is_none() {
        notes.push(format!(
            "not fully depleted up to {} V",
            hpge_solver::field::CEILING_V
        ));
    }
    if r.voltages.full_depletion_converged == Some(false) {
        notes.push(not_converged(r.voltages.full_depletion_halved_v));
    }
    if let Some(t) = &r.tilt {
        row.tilt = Some(t.marginal.median);
        row.tilt_68 = Some(t.marginal.interval_68);
    } else if o.tilt.is_some() && row.measured_v.is_some() && !det.impurity_varies_along_z() {
        notes.push("the density does not vary along z: no tilt fitted".into());
    }
    if let Some(p) = &r.posterior {
        row.factor = Some(p.median);
        row.factor_68 = Some(p.interval_68);
        if p.at_prior_bound {
            notes.push("the factor's posterior reaches a bound of --factor-range".into());
        }
    }
    if row.measured_v.is_none() {
        notes.push("the record gives no depletion voltage".into());
    }
    if !notes.is_empty() {
        row.note = Some(notes.join("; "));
    }
    Ok(())
}

/// The note of a U_fd that the grid with halved spacings does not confirm.
pub fn not_converged(halved_v: Option<f64>) -> String {
    let there = halved_v.map_or_else(
        || {
            format!(
                "is not fully depleted up to {} V",
                hpge_solver::field::CEILING_V
            )
        },
        |h| format!("gives {h:.0} V"),
    );
    format!(
        "U_fd not converged with the grid (the grid with halved spacings {there}: the step \
         does not shrink): not to be quoted (reports/accuracy/depletion.md)"
    )
}

fn opt(x: Option<f64>, digits: usize) -> String {
    x.map_or_else(|| "-".into(), |v| format!("{v:.digits$}"))
}

/// The rows as a Markdown table: detector, type, U_fd +- err, pinch-off +- err, measured,
/// factor [68% interval], |sim - meas| > gate flag, note.
pub fn markdown_table(rows: &[RecordRow], gate_v: f64) -> String {
    let mut s = format!(
        "| record | detector | type | U_fd (V) | pinch-off (V) | measured (V) | factor [68%] | > {gate_v} V | note |\n|---|---|---|---|---|---|---|---|---|\n"
    );
    for r in rows {
        let pm = |u: Option<f64>, e: Option<f64>| match (u, e) {
            (Some(u), Some(e)) => format!("{u:.0} ± {e:.0}"),
            (Some(u), None) => format!("{u:.0}"),
            _ => "-".into(),
        };
        let factor = match (r.factor, r.factor_68) {
            (Some(f), Some((a, b))) => format!("{f:.3} [{a:.3}, {b:.3}]"),
            _ => "-".into(),
        };
        let factor = match (r.tilt, r.tilt_68) {
            (Some(t), Some((a, b))) => format!("{factor} (tilt {t:.2} [{a:.2}, {b:.2}])"),
            _ => factor,
        };
        let flag = match r.exceeds_gate {
            Some(true) => "**yes**",
            Some(false) => "no",
            None => "-",
        };
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            r.record,
            r.name.as_deref().unwrap_or("-"),
            r.kind.as_deref().unwrap_or("-"),
            pm(r.depletion_voltage_v, r.depletion_voltage_err_v),
            pm(r.pinch_off_voltage_v, r.pinch_off_voltage_err_v),
            opt(r.measured_v, 0),
            factor,
            flag,
            r.note
                .as_deref()
                .unwrap_or("")
                .replace('|', "/")
                .replace('\n', " "),
        ));
    }
    s
}

/// The rows as CSV (one header line; empty cells where a value is missing).
pub fn csv_table(rows: &[RecordRow]) -> String {
    let mut s = String::from(
        "record,detector,type,depletion_voltage_V,depletion_voltage_err_V,pinch_off_voltage_V,pinch_off_voltage_err_V,measured_V,factor,factor_lo_68,factor_hi_68,exceeds_gate,note,depletion_voltage_halved_V,depletion_voltage_converged,tilt,tilt_lo_68,tilt_hi_68\n",
    );
    let c = |x: Option<f64>| x.map_or_else(String::new, |v| format!("{v}"));
    for r in rows {
        let q = |t: &str| format!("\"{}\"", t.replace('"', "\"\""));
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            q(&r.record),
            q(r.name.as_deref().unwrap_or("")),
            q(r.kind.as_deref().unwrap_or("")),
            c(r.depletion_voltage_v),
            c(r.depletion_voltage_err_v),
            c(r.pinch_off_voltage_v),
            c(r.pinch_off_voltage_err_v),
            c(r.measured_v),
            c(r.factor),
            c(r.factor_68.map(|i| i.0)),
            c(r.factor_68.map(|i| i.1)),
            r.exceeds_gate.map_or_else(String::new, |b| b.to_string()),
            q(r.note.as_deref().unwrap_or("")),
            c(r.depletion_voltage_halved_v),
            r.depletion_voltage_converged
                .map_or_else(String::new, |b| b.to_string()),
            c(r.tilt),
            c(r.tilt_68.map(|i| i.0)),
            c(r.tilt_68.map(|i| i.1)),
        ));
    }
    s
}
