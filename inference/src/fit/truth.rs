//! The truth a stand-in data set may come with (a TOML table `NAME = VALUE`), and whether the
//! fit's smallest intervals contain it.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Serialize;

use super::FitSummary;
use crate::prior::Prior;
use crate::summary::interval_contains;
use crate::{Error, Result};

/// A true value against the fit's intervals.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TruthRecord {
    /// Parameter name.
    pub name: String,
    /// The true value.
    pub value: f64,
    /// Inside the 68.3% smallest interval(s).
    pub inside_683: bool,
    /// Inside the 95.5% smallest interval(s).
    pub inside_955: bool,
}

/// Truth values in the prior's parameter order (`None` where the file does not name one).
///
/// # Errors
/// The file cannot be read, or is not a table of `NAME = number` lines.
pub fn read_truth(path: &Path, prior: &Prior) -> Result<Vec<Option<f64>>> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        file: path.to_path_buf(),
        action: "cannot read the file",
        source,
    })?;
    let table: BTreeMap<String, f64> = toml::from_str(&text).map_err(|e| {
        Error::format(
            path,
            format!("expected NAME = number lines: {}", e.to_string().trim_end()),
        )
    })?;
    let names = prior.names();
    if let Some(unknown) = table.keys().find(|k| !names.iter().any(|n| n == *k)) {
        return Err(Error::Invalid {
            file: path.to_path_buf(),
            key: unknown.clone(),
            message: format!(
                "no parameter of the prior {} has this name; its parameters are {}",
                prior.name,
                names.join(", ")
            ),
        });
    }
    // Checked here, before any sampling: a value the fit's outputs cannot place (NaN, or outside
    // where the prior and the model live) is refused naming the file and the parameter.
    for p in &prior.parameters {
        let Some(&v) = table.get(&p.name) else {
            continue;
        };
        let [lo, hi] = p.support;
        if !v.is_finite() || v < lo || v > hi {
            return Err(Error::Invalid {
                file: path.to_path_buf(),
                key: p.name.clone(),
                message: format!(
                    "{v}: a truth must be a finite number inside the parameter's support \
                     [{lo}, {hi}] (the prior {}'s domain)",
                    prior.name
                ),
            });
        }
    }
    Ok(names.iter().map(|n| table.get(n).copied()).collect())
}

/// One record per parameter with a known truth.
pub fn truth_records(summary: &FitSummary, truth: &[Option<f64>]) -> Vec<TruthRecord> {
    summary
        .parameters
        .iter()
        .zip(truth)
        .filter_map(|(p, v)| {
            v.map(|v| TruthRecord {
                name: p.name.clone(),
                value: v,
                inside_683: interval_contains(&p.smallest_intervals["0.683"], v),
                inside_955: interval_contains(&p.smallest_intervals["0.955"], v),
            })
        })
        .collect()
}
