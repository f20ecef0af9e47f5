//! The files of a finished coverage study: `coverage.json` (the report with its provenance)
//! and `ranks.csv` (each truth's rank among the draws per parameter). The figures are drawn by
//! `hpge-reports` (`plot::coverage_figures`), downstream of this crate.

use std::collections::BTreeMap;
use std::io::Write as _;
use std::path::Path;

use super::{CoverageReport, CoverageSettings};
use crate::error::{Error, Result};

/// What `coverage.json` records beside the report: the inputs and everything that makes the
/// study reproducible.
#[derive(Debug, Clone, Copy)]
pub struct CoverageProvenance<'a> {
    /// The fit's inputs with their hashes.
    pub inputs: &'a BTreeMap<String, String>,
    /// Where the truths' data came from (`surrogate` or `exact`).
    pub data_from: &'a str,
    /// The shard as given (`K/M`).
    pub shard: &'a str,
    /// The study's settings.
    pub settings: &'a CoverageSettings,
    /// Draws among which a truth is ranked.
    pub ranks: usize,
    /// The prior file.
    pub prior: &'a Path,
    /// The model file.
    pub model: &'a Path,
    /// The study's seed.
    pub seed: u64,
}

/// Writes `coverage.json` and `ranks.csv` of `report` into the folder `out`; returns the JSON
/// object written.
///
/// Errors: a file that cannot be written ([`Error::File`], naming it).
pub fn write_outputs(
    out: &Path,
    report: &CoverageReport,
    p: &CoverageProvenance<'_>,
) -> Result<serde_json::Value> {
    let path = out.join("coverage.json");
    let mut json = serde_json::to_value(report).map_err(|e| Error::cannot_write(&path, &e))?;
    if let Some(obj) = json.as_object_mut() {
        obj.insert("program_version".into(), env!("CARGO_PKG_VERSION").into());
        obj.insert(
            hpge_foundation::MADE_KEY.into(),
            hpge_solver::made().to_json(),
        );
        obj.insert(
            "inputs".into(),
            serde_json::to_value(p.inputs).map_err(|e| Error::cannot_write(&path, &e))?,
        );
        obj.insert("data_from".into(), p.data_from.into());
        obj.insert("shard".into(), p.shard.into());
        obj.insert(
            "settings".into(),
            serde_json::to_value(p.settings).map_err(|e| Error::cannot_write(&path, &e))?,
        );
        // ranks.csv's provenance (it is a plain table: one header row, no comment lines).
        obj.insert(
            "ranks_csv".into(),
            serde_json::json!({
                "file": "ranks.csv",
                "columns": "truth, then each parameter's rank of the truth among the draws",
                "rank_among_draws": p.ranks,
                "prior": p.prior.display().to_string(),
                "model": p.model.display().to_string(),
                "seed": p.seed,
            }),
        );
    }
    let text =
        serde_json::to_string_pretty(&json).map_err(|e| Error::cannot_write(&path, &e))? + "\n";
    hpge_files::write(&path, text).map_err(|e| Error::cannot_write(&path, &e))?;
    let path = out.join("ranks.csv");
    let names: Vec<&str> = report.parameters.iter().map(|p| p.name.as_str()).collect();
    hpge_files::write_with(&path, |w| -> std::io::Result<()> {
        writeln!(w, "truth,{}", names.join(","))?;
        for i in 0..report.n_truths {
            let r: Vec<String> = report
                .parameters
                .iter()
                .map(|p| p.ranks[i].to_string())
                .collect();
            writeln!(w, "{i},{}", r.join(","))?;
        }
        Ok(())
    })
    .map_err(|e| Error::cannot_write(&path, &e))?;
    Ok(json)
}
