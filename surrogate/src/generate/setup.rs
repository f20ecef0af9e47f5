//! What a generation run is: the space, the detector, the solver settings, the sequence and the
//! index range, and the fingerprint that a resumed or merged run must match.

use std::path::{Path, PathBuf};

use hpge_solver::FieldSettings;
use serde::{Deserialize, Serialize};

use super::exact::ExactSolver;
use super::regime::{REGIME_COLUMNS, Regime};
use super::select::{SelectionInfo, choose, selection_info};
use crate::error::{Error, Result};
use crate::hash::fnv1a;
use crate::sequence::{Sequence, SequenceKind};
use crate::space::ParameterSpace;
pub use hpge_foundation::Shard;

/// The fingerprint of everything that determines the rows (not the shard: shards of one run
/// share it, so `merge` can check them).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Fingerprint {
    /// Space name and the FNV-1a hash of its file, hex.
    pub space: String,
    /// Space file hash.
    pub space_hash: String,
    /// Detector file and the hash of its text (and of its impurity file, if separate).
    pub detector: String,
    /// Detector hash.
    pub detector_hash: String,
    /// Hash of the solver settings (their JSON).
    pub settings_hash: String,
    /// Sequence name.
    pub sequence: String,
    /// Sequence seed.
    pub seed: u64,
    /// First index of the run.
    pub offset: u64,
    /// Number of samples of the whole run.
    pub n: u64,
    /// Rows per parameter point in curve mode (1: every row its own quasi-random point; see
    /// [`Generator::with_curve_points`]). Absent from the files of point-mode runs, so their
    /// fingerprints are what they were before curve mode existed.
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub curve_points: u64,
    /// Active learning (`generate --where`): the models and share that chose which of the
    /// `n` candidates are solved (`generate::select`). Absent from the files of runs that
    /// solve every index, so their fingerprints are what they were before.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub selection: Option<SelectionInfo>,
}

fn one() -> u64 {
    1
}

#[allow(clippy::trivially_copy_pass_by_ref)] // serde's skip_serializing_if passes a reference
fn is_one(k: &u64) -> bool {
    *k == 1
}

/// A configured run.
#[derive(Debug, Clone)]
pub struct Generator {
    /// The space.
    pub space: ParameterSpace,
    /// The detector file.
    pub detector_file: PathBuf,
    /// Solver settings.
    pub settings: FieldSettings,
    /// The sequence.
    pub sequence: Sequence,
    /// First index.
    pub offset: u64,
    /// Samples in the whole run.
    pub n: u64,
    /// This process's shard.
    pub shard: Shard,
    /// The fingerprint.
    pub fingerprint: Fingerprint,
    /// The space's points solved with the exact solver.
    pub exact: ExactSolver,
    /// On resume, solve again the points whose rows failed (`--retry-failed`; not part of the
    /// fingerprint: a retry adds rows of the same run, e.g. after a solver fix).
    pub retry_failed: bool,
    /// Active learning: the candidate indices chosen to be solved (None: every index).
    pub chosen: Option<std::collections::HashSet<u64>>,
}

/// The outcome of one sample.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Sequence index.
    pub index: u64,
    /// Unit-cube coordinates.
    pub u: Vec<f64>,
    /// Physical values.
    pub x: Vec<f64>,
    /// c12 in pF (NaN when the solve failed).
    pub c12_pf: f64,
    /// `ok`, or what failed (no commas).
    pub status: String,
    /// The solver's estimated absolute error of c12, pF (`|c12_h - c12_H|` of the adaptive
    /// grid; NaN when the solve failed).
    pub c12_err_pf: f64,
    /// The pockets the solve ended with (None when it failed).
    pub regime: Option<Regime>,
    /// Wall time of the solve, s.
    pub seconds: f64,
}

/// The most rows one `generate` run makes (`--n`).
pub const MAX_ROWS: u64 = 100_000_000;

impl Generator {
    /// Sets up a run; checks the arguments against the space, the detector and the sequence.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        space: ParameterSpace,
        detector_file: &Path,
        settings: FieldSettings,
        kind: SequenceKind,
        seed: u64,
        offset: u64,
        n: u64,
        shard: Shard,
    ) -> Result<Self> {
        let arg = |name: &str, message: String| Error::Argument {
            name: name.into(),
            message,
        };
        if n == 0 {
            return Err(arg(
                "--n",
                "the number of samples must be at least 1".into(),
            ));
        }
        // Bounded before anything grows with it (the run's work list, its index set): far
        // above any set the solver can make (each row takes seconds of CPU), far below what
        // would exhaust the memory (issue 66).
        if n > MAX_ROWS {
            return Err(arg(
                "--n",
                format!(
                    "{n}: at most {MAX_ROWS} rows per run (each takes seconds of CPU); split a \
                     larger set into runs with --offset"
                ),
            ));
        }
        let sequence = Sequence::new(kind, space.sampled_dim(), seed);
        if offset
            .checked_add(n)
            .is_none_or(|end| end > sequence.max_points())
        {
            return Err(arg(
                "--n/--offset",
                format!(
                    "indices {offset}..{} exceed the {} points of the {} sequence",
                    offset.saturating_add(n),
                    sequence.max_points(),
                    kind.as_str()
                ),
            ));
        }
        if shard.m == 0 || shard.k >= shard.m {
            return Err(arg("--shard", "need 0 <= K < M".into()));
        }
        settings
            .validate()
            .map_err(|e| arg("solver settings", e.to_string()))?;
        let exact = ExactSolver::new(space.clone(), detector_file, settings.clone())?;
        let space_text = toml::to_string(&space).unwrap_or_default();
        let settings_json = toml::to_string(&settings).unwrap_or_default();
        let fingerprint = Fingerprint {
            space: space.name.clone(),
            space_hash: format!("{:016x}", fnv1a(space_text.as_bytes())),
            detector: detector_file.display().to_string(),
            detector_hash: exact.detector_hash(),
            settings_hash: format!("{:016x}", fnv1a(settings_json.as_bytes())),
            sequence: kind.as_str().to_string(),
            seed,
            offset,
            n,
            curve_points: 1,
            selection: None,
        };
        let g = Self {
            space,
            detector_file: detector_file.into(),
            settings,
            sequence,
            offset,
            n,
            shard,
            fingerprint,
            exact,
            retry_failed: false,
            chosen: None,
        };
        Ok(g)
    }

    /// On resume, drop the rows whose solve failed and solve their points again (see
    /// [`Generator::retry_failed`]).
    pub fn with_retry_failed(mut self, on: bool) -> Self {
        self.retry_failed = on;
        self
    }

    /// Curve mode: every quasi-random parameter point gets `k` rows, its own set of `k` biases
    /// solved as one C-V curve ([`hpge_solver::field::cv_curve_with`], cold continuation: the
    /// weighting stage of fully depleted biases is computed once, each bias otherwise solved as
    /// in point mode, so a row equals the point-mode solve at its x exactly).
    ///
    /// Measured on Super-Siegfried (2-core machine, `curve_vs_points`): no faster than point
    /// mode with the present solver (a row's cost is its own depletion solves), and a seeded
    /// continuation was slower for biases hundreds of volts apart. It is kept for its design:
    /// every parameter point sampled across the whole bias range.
    ///
    /// The biases are a randomly shifted stratification of the bias dimension: with u_b the
    /// point's own quasi-random bias coordinate, row j (0 <= j < k) has the unit coordinate
    /// (j + u_b) / k, mapped to volts by the dimension's distribution. Each stratum is hit
    /// uniformly, so over many points the bias is as uniform as in point mode (its marginal is
    /// the same), while one point's rows share the detector and impurity model. The bias stays
    /// quasi-random (through u_b) rather than a fixed list, so no two curves sample the same
    /// voltages. Rows are numbered p k + j for parameter point p; `n` and `offset` count rows
    /// and must be multiples of `k`. With `k` = 1 this is point mode, unchanged.
    pub fn with_curve_points(mut self, k: u64) -> Result<Self> {
        let arg = |message: String| Error::Argument {
            name: "--curve-points".into(),
            message,
        };
        if k == 0 {
            return Err(arg("must be at least 1".into()));
        }
        if k > 1 && self.bias_dimension().is_none() {
            return Err(arg(format!(
                "the space `{}` has no `bias` dimension to spread along a curve",
                self.space.name
            )));
        }
        if !self.n.is_multiple_of(k) || !self.offset.is_multiple_of(k) {
            return Err(arg(format!(
                "--n ({}) and --offset ({}) count rows and must be multiples of {k}",
                self.n, self.offset
            )));
        }
        self.fingerprint.curve_points = k;
        Ok(self)
    }

    /// Active learning: of the run's `n` candidate indices, solve only the top `share` by the
    /// disagreement of `models` ((file as given, its bytes, the loaded model); see
    /// `generate::select`). Refused for a model of another space or detector (naming both
    /// hashes), a share outside (0, 1], and in curve mode.
    pub fn with_selection(
        mut self,
        models: &[(String, Vec<u8>, crate::model::Surrogate)],
        share: f64,
    ) -> Result<Self> {
        if self.curve_points() > 1 {
            return Err(Error::Argument {
                name: "--where".into(),
                message: "cannot be combined with --curve-points above 1".into(),
            });
        }
        let info = selection_info(&self, models, share)?;
        let loaded: Vec<&crate::model::Surrogate> = models.iter().map(|(_, _, m)| m).collect();
        self.chosen = Some(choose(&self, &loaded, share)?.into_iter().collect());
        self.fingerprint.selection = Some(info);
        Ok(self)
    }

    /// Rows per parameter point (1 in point mode).
    pub fn curve_points(&self) -> u64 {
        self.fingerprint.curve_points
    }

    /// Column of the space's bias dimension.
    fn bias_dimension(&self) -> Option<usize> {
        self.space
            .targets()
            .iter()
            .position(|t| *t == crate::space::Target::Bias)
    }

    /// This shard's work units: sequence indices of the parameter points (point mode: the row
    /// indices themselves). Shards stride over points, so one point's rows stay together.
    pub fn units(&self) -> impl Iterator<Item = u64> + '_ {
        let k = self.curve_points();
        self.shard
            .indices(self.offset / k, self.n / k)
            .filter(|p| self.chosen.as_ref().is_none_or(|c| c.contains(p)))
    }

    /// The row indices of work unit `p`.
    pub fn rows_of(&self, p: u64) -> std::ops::Range<u64> {
        let k = self.curve_points();
        p * k..(p + 1) * k
    }

    /// Solves work unit `p`: one sample in point mode ([`Generator::sample`]), else the `k`
    /// rows of parameter point `p` along one C-V curve. A failed curve gives `k` rows with NaN
    /// c12 and the reason; `seconds` is the curve's wall time shared equally.
    pub fn unit(&self, p: u64) -> Vec<Sample> {
        let k = self.curve_points();
        let Some(b) = self.bias_dimension().filter(|_| k > 1) else {
            return vec![self.sample(p)];
        };
        let start = std::time::Instant::now();
        let v0 = self.sequence.point(p);
        // The bias's place among the sampled dimensions (a bias is never `same_as`).
        let bs = self.space.dimensions[..b]
            .iter()
            .filter(|d| d.same_as.is_none())
            .count();
        let rows: Vec<(Vec<f64>, Vec<f64>)> = (0..k)
            .map(|j| {
                let mut v = v0.clone();
                v[bs] = (j as f64 + v0[bs]) / k as f64;
                self.space.from_sampled_unit(&v)
            })
            .collect();
        let params: Vec<f64> = rows[0]
            .1
            .iter()
            .enumerate()
            .filter(|(d, _)| *d != b)
            .map(|(_, v)| *v)
            .collect();
        let volts: Vec<f64> = rows.iter().map(|(_, x)| x[b]).collect();
        // Cold continuation: the biases lie (range / k) apart, too far for a neighbour's front to
        // help (seeded curves measured 1.7x slower, `validation/examples/curve_vs_points.rs`);
        // a row then equals the point-mode solve at its x bit for bit.
        let result =
            self.exact
                .curve_labelled(&params, &volts, hpge_solver::field::Continuation::Cold);
        let seconds = start.elapsed().as_secs_f64() / k as f64;
        rows.into_iter()
            .enumerate()
            .map(|(j, (u, x))| {
                let (c12_pf, c12_err_pf, regime, status) = match &result {
                    Ok(c) => (c[j].0, c[j].1, Some(c[j].2), "ok".to_string()),
                    Err(e) => (f64::NAN, f64::NAN, None, failure(e)),
                };
                Sample {
                    index: p * k + j as u64,
                    u,
                    x,
                    c12_pf,
                    status,
                    c12_err_pf,
                    regime,
                    seconds,
                }
            })
            .collect()
    }

    /// The CSV header: index, u_NAME..., NAME..., c12_pF, status, c12_err_pF, pockets,
    /// pocket_level_V, pocket_cm3, seconds (`generate::regime`).
    pub fn header(&self) -> String {
        self.header_with(true)
    }

    /// [`Generator::header`], or without the regime columns (`regime` false): the header of
    /// runs started before they existed, which a resume continues in their own format.
    pub fn header_with(&self, regime: bool) -> String {
        let names = self.space.dimensions.iter().map(|d| d.name.as_str());
        let u: Vec<String> = names.clone().map(|n| format!("u_{n}")).collect();
        let x: Vec<&str> = names.collect();
        let regime = if regime {
            format!("{},", REGIME_COLUMNS.join(","))
        } else {
            String::new()
        };
        format!(
            "index,{},{},c12_pF,status,c12_err_pF,{regime}seconds",
            u.join(","),
            x.join(",")
        )
    }

    /// Solves sample `index`: its point of the sequence, mapped to the space, set on the
    /// detector (parameters, rz y values) at its bias. A failed solve is a row with NaN c12 and
    /// the reason in `status`, not an error.
    pub fn sample(&self, index: u64) -> Sample {
        let start = std::time::Instant::now();
        let (u, x) = self.space.from_sampled_unit(&self.sequence.point(index));
        let result = self.exact.solve_labelled(&x);
        let (c12_pf, c12_err_pf, regime, status) = match result {
            Ok((c, err, regime)) => (c, err, Some(regime), "ok".to_string()),
            Err(e) => (f64::NAN, f64::NAN, None, failure(&e)),
        };
        Sample {
            index,
            u,
            x,
            c12_pf,
            status,
            c12_err_pf,
            regime,
            seconds: start.elapsed().as_secs_f64(),
        }
    }
}

/// A failed solve's `status`: `failed: <reason>` on one CSV field (no commas, line breaks,
/// comment marks or quotes).
fn failure(e: &impl std::fmt::Display) -> String {
    format!("failed: {e}")
        .replace([',', '\n', '\r'], ";")
        .replace(['#', '"'], "'")
}
