//! What a generation run is: the space, the detector, the solver settings, the sequence and the
//! index range, and the fingerprint that a resumed or merged run must match.

use std::path::{Path, PathBuf};

use hpge_solver::FieldSettings;
use serde::{Deserialize, Serialize};

use super::exact::ExactSolver;
use crate::error::{Error, Result};
use crate::hash::fnv1a;
use crate::sequence::{Sequence, SequenceKind};
use crate::space::ParameterSpace;

/// Shard K of M: indices offset + i with i % M == K (strided, so every shard sees the whole
/// sequence and takes about the same time).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// This shard, 0 <= k < m.
    pub k: u64,
    /// Number of shards.
    pub m: u64,
}

impl Shard {
    /// The whole range in one shard.
    pub const WHOLE: Shard = Shard { k: 0, m: 1 };

    /// Parses `K/M`; the error is an [`Error::Argument`] named by the text.
    pub fn parse(s: &str) -> Result<Shard> {
        let bad = |message: String| Error::Argument {
            name: s.to_string(),
            message,
        };
        let (k, m) = s
            .split_once('/')
            .ok_or_else(|| bad("expected K/M, e.g. 0/4".to_string()))?;
        let num = |t: &str| {
            t.trim()
                .parse::<u64>()
                .map_err(|e| bad(format!("`{t}` is not a whole number ({e})")))
        };
        let (k, m) = (num(k)?, num(m)?);
        if m == 0 || k >= m {
            return Err(bad("need 0 <= K < M".to_string()));
        }
        Ok(Shard { k, m })
    }

    /// The indices of this shard in [offset, offset + n).
    pub fn indices(&self, offset: u64, n: u64) -> impl Iterator<Item = u64> + '_ {
        let (k, m) = (self.k, self.m);
        (0..n).filter(move |i| i % m == k).map(move |i| offset + i)
    }
}

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
    /// Wall time of the solve, s.
    pub seconds: f64,
}

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
        let sequence = Sequence::new(kind, space.dim(), seed);
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
        };
        Ok(g)
    }

    /// The CSV header: index, u_<name>..., <name>..., c12_pF, status, seconds.
    pub fn header(&self) -> String {
        let names = self.space.dimensions.iter().map(|d| d.name.as_str());
        let u: Vec<String> = names.clone().map(|n| format!("u_{n}")).collect();
        let x: Vec<&str> = names.collect();
        format!(
            "index,{},{},c12_pF,status,seconds",
            u.join(","),
            x.join(",")
        )
    }

    /// Solves sample `index`: its point of the sequence, mapped to the space, set on the
    /// detector (parameters, rz y values) at its bias. A failed solve is a row with NaN c12 and
    /// the reason in `status`, not an error.
    pub fn sample(&self, index: u64) -> Sample {
        let start = std::time::Instant::now();
        let u = self.sequence.point(index);
        let x = self.space.from_unit(&u);
        let result = self.exact.solve(&x);
        let (c12_pf, status) = match result {
            Ok(c) => (c, "ok".to_string()),
            Err(e) => (
                f64::NAN,
                format!("failed: {e}").replace([',', '\n', '\r'], ";"),
            ),
        };
        Sample {
            index,
            u,
            x,
            c12_pf,
            status,
            seconds: start.elapsed().as_secs_f64(),
        }
    }
}
