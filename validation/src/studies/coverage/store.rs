//! Nothing lost on interruption for a coverage study (issue 21, items 4 and 5): every fitted
//! truth is written to `OUT/truths/truth-NNNNN.json` as it finishes. A study started again with
//! the same arguments takes those truths back and fits only the rest; one with more `--truths`
//! extends it (truth i depends on the seed and i only, never on how many truths there are).
//!
//! A file written with other inputs or settings is removed when the study opens the folder (the
//! fingerprint in each file says which run wrote it), so two runs never mix; a file cut short by
//! a kill is never read (each is written to a temporary name and renamed,
//! [`hpge_inference::fit::write_whole`]).
//!
//! A long study (the exact-data one fits each truth with the full pipeline, a few CPU-minutes a
//! truth) can be split over machines that share the folder: `--shard K/M` fits the truths i with
//! i mod M = K. Each shard holds its own lock (`OUT/coverage-K-of-M.lock`; one for the whole
//! study without shards), so one shard never runs twice at once, while different shards run
//! side by side. Whichever process finds every truth done writes the report.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use hpge_foundation::FolderLock;
use hpge_foundation::Shard;
use hpge_inference::fit::{fingerprint, folder_files, remove_stale, write_whole};
use hpge_inference::sampler::SamplerStop;
use serde::{Deserialize, Serialize};

use super::settings::{CoverageSettings, DataFrom};
use crate::error::Result;

/// The folder inside a study's output folder that holds its truths.
pub const TRUTHS_DIR: &str = "truths";
/// The folder inside a study's output folder that holds, per truth still being fitted with the
/// full pipeline, its finished refinement rounds (`truth-rounds/truth-NNNNN/rounds/`): an
/// interrupted truth takes them back instead of solving them again. A truth's folder is removed
/// once the truth is written.
pub const TRUTH_ROUNDS_DIR: &str = "truth-rounds";

/// What the full pipeline's exact check said about one truth's fit (studies with refinement).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TruthCheck {
    /// Whether the last round's exact check passed.
    pub pass: bool,
    /// Rounds of refinement run (1: the plain surrogate passed or nothing was refined).
    pub rounds: usize,
    /// Pareto k-hat of the last round's check.
    #[serde(deserialize_with = "hpge_inference::fit::f64_or_nan")]
    pub pareto_k: f64,
    /// Its largest |mean shift| in posterior sd.
    #[serde(deserialize_with = "hpge_inference::fit::f64_or_nan")]
    pub max_abs_shift_sd: f64,
    /// Where the fit's wall time went, summed over its rounds: sampling and summaries, exact
    /// solves (checks, ascents, curves at local modes), error-model fits, s. Absent in records
    /// written before 2026-11-29.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seconds_split: Option<SecondsSplit>,
}

/// How one truth's sampler ended: why it stopped and how far its least-mixed parameter got
/// (with the targets, what "unconverged" means for this truth).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TruthSampler {
    /// Why sampling stopped (targets reached, the draw cap or the clock).
    pub stop: SamplerStop,
    /// Kept draws per chain.
    pub draws_per_chain: usize,
    /// The largest rank-normalised split R-hat over the parameters.
    #[serde(deserialize_with = "hpge_inference::fit::f64_or_nan")]
    pub rhat_max: f64,
    /// The smallest of every parameter's bulk and tail ESS.
    #[serde(deserialize_with = "hpge_inference::fit::f64_or_nan")]
    pub ess_min: f64,
}

/// A pipeline fit's wall time by part, s (sums of [`hpge_inference::fit::RefineRound`]'s).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SecondsSplit {
    /// Sampling and summaries.
    pub sampling: f64,
    /// Exact solves.
    pub exact: f64,
    /// Error-model fits.
    pub error_model: f64,
}

impl SecondsSplit {
    /// One refinement round's split.
    pub fn of(r: &hpge_inference::fit::RefineRound) -> Self {
        Self {
            sampling: r.sampling_seconds,
            exact: r.exact_seconds,
            error_model: r.error_model_seconds,
        }
    }
}

impl std::ops::Add for SecondsSplit {
    type Output = Self;

    fn add(self, o: Self) -> Self {
        Self {
            sampling: self.sampling + o.sampling,
            exact: self.exact + o.exact,
            error_model: self.error_model + o.error_model,
        }
    }
}

/// One truth of a study as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TruthFit {
    /// Which run wrote it ([`study_fingerprint`]).
    pub fingerprint: String,
    /// Its index i (seeds: the truth and noise from (seed, i), the fit seed + i + 1).
    pub index: usize,
    /// The truth (the prior's parameters).
    pub truth: Vec<f64>,
    /// Why the data model gave no curve there (the truth then takes no part in the study).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub skipped: Option<String>,
    /// Rank of the truth among the L thinned draws, per parameter.
    pub ranks: Vec<usize>,
    /// Uniform jitter of each rank (the KS test's continuous ranks).
    pub jitter: Vec<f64>,
    /// Per parameter, whether each level's smallest interval contains the truth.
    pub inside: Vec<Vec<bool>>,
    /// Whether the fit reached its R-hat and ESS targets.
    pub converged: bool,
    /// How its sampler ended. Absent in records written before 2026-11-29 (afternoon).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sampler: Option<TruthSampler>,
    /// The exact check of a study with refinement.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub check: Option<TruthCheck>,
    /// Wall time of this truth, s.
    pub seconds: f64,
}

/// The fingerprint of a study: its inputs (files with their hashes), where its data come from
/// (with `hpge_solver::field::PHYSICS_REVISION` for exact data) and its settings without the
/// number of truths (so a study can be extended).
pub fn study_fingerprint(
    inputs: &BTreeMap<String, String>,
    data_from: DataFrom,
    settings: &CoverageSettings,
) -> String {
    let mut parts: Vec<String> = inputs.iter().map(|(k, v)| format!("{k}={v}")).collect();
    parts.push(format!("data_from={}", data_from.as_str()));
    if data_from == DataFrom::Exact {
        // Exact data and exact checks: answers of two solvers never mix.
        parts.push(format!("solver={}", hpge_solver::field::PHYSICS_REVISION));
    }
    let mut s = serde_json::to_value(settings).unwrap_or_default();
    if let Some(o) = s.as_object_mut() {
        o.remove("n_truths");
    }
    parts.push(s.to_string());
    fingerprint(&parts)
}

/// The truths of the study `fingerprint` written so far in `out` (by any shard), by index, read
/// without the lock and without removing anything: safe beside the running study (a truth is
/// written whole, so a file is either there or not). Unreadable files and those of another run
/// are left out; a folder without `truths/` has none.
///
/// # Errors
/// The truths folder exists and cannot be read.
pub fn peek(out: &Path, fingerprint: &str) -> Result<BTreeMap<usize, TruthFit>> {
    let dir = out.join(TRUTHS_DIR);
    if !dir.is_dir() {
        return Ok(BTreeMap::new());
    }
    read_truths(&dir, fingerprint)
}

/// The truth files of `dir` that belong to `fingerprint` and lie under their own index's name.
fn read_truths(dir: &Path, fingerprint: &str) -> Result<BTreeMap<usize, TruthFit>> {
    let mut done = BTreeMap::new();
    for f in folder_files(dir)? {
        if f.extension().is_none_or(|e| e != "json") {
            continue;
        }
        let Some(t) = std::fs::read_to_string(&f)
            .ok()
            .and_then(|t| serde_json::from_str::<TruthFit>(&t).ok())
        else {
            continue;
        };
        if t.fingerprint == fingerprint && f == truth_path(dir, t.index) {
            done.insert(t.index, t);
        }
    }
    Ok(done)
}

/// Truth `index`'s file in the truths folder `dir`.
fn truth_path(dir: &Path, index: usize) -> PathBuf {
    dir.join(format!("truth-{index:05}.json"))
}

/// The truths folder of one study, locked for one shard.
pub struct TruthStore {
    dir: PathBuf,
    fingerprint: String,
    _lock: FolderLock,
}

impl TruthStore {
    /// Takes the lock of `shard` in `out` (which must exist) and opens `out/truths` for the run
    /// `fingerprint`: files another run wrote are removed.
    ///
    /// # Errors
    /// The shard is running elsewhere (its lock is held), or the folder cannot be made, read or
    /// cleared.
    pub fn open(out: &Path, fingerprint: String, shard: Shard) -> Result<Self> {
        let name = if shard.m == 1 {
            "coverage.lock".to_string()
        } else {
            format!("coverage-{}-of-{}.lock", shard.k, shard.m)
        };
        let lock = FolderLock::acquire_named(out, &name).map_err(hpge_inference::Error::from)?;
        let dir = out.join(TRUTHS_DIR);
        // Only files another run wrote: a shard beside this one may be writing its own.
        // Only truth files (`truth-NNNNN.json`): any other file there is left alone.
        let truth_file = |f: &Path| {
            f.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("truth-") && n.ends_with(".json"))
        };
        remove_stale(&dir, truth_file, |f| f.is_some_and(|f| f != fingerprint))?;
        Ok(Self {
            dir,
            fingerprint,
            _lock: lock,
        })
    }

    /// The run's fingerprint.
    pub fn fingerprint(&self) -> &str {
        &self.fingerprint
    }

    /// Where truth `index`'s pipeline fit keeps its finished rounds while it runs
    /// ([`TRUTH_ROUNDS_DIR`]; `hpge_inference::fit::Checkpoint` writes `rounds/` inside).
    pub fn rounds_dir(&self, index: usize) -> PathBuf {
        self.dir
            .parent()
            .unwrap_or(&self.dir)
            .join(TRUTH_ROUNDS_DIR)
            .join(format!("truth-{index:05}"))
    }

    /// Removes truth `index`'s rounds folder (after the truth is written).
    ///
    /// # Errors
    /// The folder exists and cannot be removed.
    pub fn forget_rounds(&self, index: usize) -> Result<()> {
        match std::fs::remove_dir_all(self.rounds_dir(index)) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(hpge_inference::Error::Io {
                file: self.rounds_dir(index),
                action: "cannot remove the folder",
                source: e,
            }
            .into()),
            _ => Ok(()),
        }
    }

    fn path(&self, index: usize) -> PathBuf {
        truth_path(&self.dir, index)
    }

    /// The truths of this run written so far (by any shard), by index; unreadable files and
    /// those of another run are left out.
    ///
    /// # Errors
    /// The folder cannot be read.
    pub fn load(&self) -> Result<BTreeMap<usize, TruthFit>> {
        read_truths(&self.dir, &self.fingerprint)
    }

    /// Writes a finished truth whole (temporary name, then renamed).
    ///
    /// # Errors
    /// The file cannot be written.
    pub fn save(&self, t: &TruthFit) -> Result<()> {
        let text = serde_json::to_string(t).map_err(|e| hpge_inference::Error::Numerical {
            what: "a coverage truth as JSON".into(),
            message: e.to_string(),
        })?;
        Ok(write_whole(&self.path(t.index), &text)?)
    }
}

#[cfg(test)]
mod tests {
    use super::TruthCheck;

    #[test]
    fn a_check_written_before_the_time_split_still_reads() {
        let old = r#"{"pass": true, "rounds": 3, "pareto_k": 0.21, "max_abs_shift_sd": 0.16}"#;
        let c: TruthCheck = serde_json::from_str(old).unwrap();
        assert_eq!((c.pass, c.rounds, c.seconds_split), (true, 3, None));
        let again: TruthCheck = serde_json::from_str(&serde_json::to_string(&c).unwrap()).unwrap();
        assert_eq!(again, c);
    }
}
