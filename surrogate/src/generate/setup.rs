//! What a generation run is: the space, the detector, the solver settings, the sequence and the
//! index range, and the fingerprint that a resumed or merged run must match.

use std::path::{Path, PathBuf};

use hpge_solver::{Detector, FieldSettings, ImpuritySpec, Parameters, solve_point};
use serde::{Deserialize, Serialize};

use crate::sequence::{Sequence, SequenceKind};
use crate::space::{ParameterSpace, Target};
use crate::{Error, Result};

/// FNV-1a 64-bit hash (stable across platforms and versions; identifies inputs, not security).
pub fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

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

    /// Parses `K/M`.
    pub fn parse(s: &str) -> std::result::Result<Shard, String> {
        let (k, m) = s
            .split_once('/')
            .ok_or_else(|| format!("`{s}`: expected K/M, e.g. 0/4"))?;
        let num = |t: &str| {
            t.trim()
                .parse::<u64>()
                .map_err(|e| format!("`{s}`: `{t}` is not a whole number ({e})"))
        };
        let (k, m) = (num(k)?, num(m)?);
        if m == 0 || k >= m {
            return Err(format!("`{s}`: need 0 <= K < M"));
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
    detector_text: String,
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
    targets: Vec<Target>,
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
        settings.validate().map_err(|m| arg("solver settings", m))?;
        let detector_text = std::fs::read_to_string(detector_file).map_err(|e| Error::Io {
            file: detector_file.into(),
            action: "cannot read the detector",
            source: e,
        })?;
        // The detector must load, and the y targets must fit its rz knots.
        let det = Detector::from_toml_str(&detector_text, detector_file, &Parameters::new())?;
        let targets = space.targets();
        let ys: Vec<&Target> = targets
            .iter()
            .filter(|t| matches!(t, Target::YBot(_) | Target::YTop(_)))
            .collect();
        for face in [0, 1] {
            let mut ks: Vec<usize> = targets
                .iter()
                .filter_map(|t| match (t, face) {
                    (Target::YBot(k), 0) | (Target::YTop(k), 1) => Some(*k),
                    _ => None,
                })
                .collect();
            ks.sort_unstable();
            if !ys.is_empty() && ks != (0..ks.len().max(1)).collect::<Vec<_>>() {
                return Err(Error::Invalid {
                    file: space.file.clone(),
                    key: "dimensions".into(),
                    message: format!(
                        "the {} targets must be knots 0, 1, ... without gaps, got {ks:?}",
                        if face == 0 { "y_bot" } else { "y_top" },
                    ),
                });
            }
        }
        for t in &targets {
            if let Target::Parameter(p) = t
                && det.parameters.get(p).is_none()
            {
                return Err(Error::Invalid {
                    file: space.file.clone(),
                    key: "dimensions".into(),
                    message: format!(
                        "target parameter:{p}: {} declares no parameter `{p}`",
                        detector_file.display()
                    ),
                });
            }
        }
        if !targets.contains(&Target::Bias) {
            return Err(Error::Invalid {
                file: space.file.clone(),
                key: "dimensions".into(),
                message: "one dimension must have target = \"bias\"".into(),
            });
        }
        let space_text = toml::to_string(&space).unwrap_or_default();
        let settings_json = toml::to_string(&settings).unwrap_or_default();
        let mut det_bytes = detector_text.as_bytes().to_vec();
        if let Ok(imp) = std::fs::read(det.semiconductor.impurity_file()) {
            det_bytes.extend_from_slice(&imp);
        }
        let fingerprint = Fingerprint {
            space: space.name.clone(),
            space_hash: format!("{:016x}", fnv1a(space_text.as_bytes())),
            detector: detector_file.display().to_string(),
            detector_hash: format!("{:016x}", fnv1a(&det_bytes)),
            settings_hash: format!("{:016x}", fnv1a(settings_json.as_bytes())),
            sequence: kind.as_str().to_string(),
            seed,
            offset,
            n,
        };
        let g = Self {
            space,
            detector_file: detector_file.into(),
            detector_text,
            settings,
            sequence,
            offset,
            n,
            shard,
            fingerprint,
            targets,
        };
        // A dry run at the centre of the space: the detector and impurity model build.
        let centre = g.space.from_unit(&vec![0.5; g.space.dim()]);
        g.configure(&centre)?;
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
        let result = self.solve(&x);
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

    fn solve(&self, x: &[f64]) -> Result<f64> {
        let (det, bias) = self.configure(x)?;
        Ok(solve_point(&det, bias, &self.settings, None)?.c12_pf)
    }

    /// The detector with the sample's parameters and impurity model, and the bias (V).
    fn configure(&self, x: &[f64]) -> Result<(Detector, f64)> {
        let mut params = Parameters::new();
        let mut bias = 0.0;
        let (mut yb, mut yt) = (Vec::new(), Vec::new());
        for (t, &v) in self.targets.iter().zip(x) {
            match t {
                Target::Bias => bias = v,
                Target::Parameter(p) => params.set(p.clone(), v),
                Target::YBot(k) => yb.push((*k, v)),
                Target::YTop(k) => yt.push((*k, v)),
            }
        }
        let mut det = Detector::from_toml_str(&self.detector_text, &self.detector_file, &params)?;
        if !yb.is_empty() {
            yb.sort_by_key(|p| p.0);
            yt.sort_by_key(|p| p.0);
            let list = |v: &[(usize, f64)]| {
                v.iter()
                    .map(|p| format!("{:e}", p.1))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            let text = format!(
                "model = \"rz\"\ny_bot = [{}]\ny_top = [{}]\n",
                list(&yb),
                list(&yt)
            );
            let name = Path::new("(generated sample)");
            let spec = ImpuritySpec::from_toml_str(&text, name)?;
            det.set_impurity(&spec, name)?;
        }
        Ok((det, bias))
    }
}
