//! A parameter space in TOML: per dimension a name, unit, range, distribution and the place it
//! enters the simulation; maps to the unit hypercube [0, 1)^d and to standard-normal
//! coordinates (the paper's T_N) and back.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use hpge_foundation::{normal_cdf, normal_quantile};

/// How a dimension is distributed over its range (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Distribution {
    /// x = lo + u (hi - lo).
    #[default]
    Uniform,
    /// x = lo (hi / lo)^u (lo > 0): uniform in log x.
    LogUniform,
}

/// Where a dimension enters a simulation.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Target {
    /// The bias voltage U_B (V).
    Bias,
    /// A detector parameter from its `[parameters]` table, e.g. `d_li_mm`.
    Parameter(String),
    /// A value of the impurity model: key `key` (element `index` of a list) of the space's
    /// `[impurity]` table, which then replaces the detector's model. Written
    /// `impurity:KEY` or `impurity:KEY[K]`; the paper's spaces write `y_bot[K]` and `y_top[K]`,
    /// the rz model's y at knot K (a space without `[impurity]` then means `model = "rz"`).
    Impurity {
        /// The impurity table's key, e.g. `y_bot` or `z0_cm3`.
        key: String,
        /// The element of a list, or None for a single value.
        index: Option<usize>,
    },
}

impl Target {
    /// Parses `bias`, `parameter:NAME`, `impurity:KEY`, `impurity:KEY[K]`, `y_bot[K]` or
    /// `y_top[K]`.
    pub fn parse(s: &str) -> Option<Target> {
        let s = s.trim();
        if s == "bias" {
            return Some(Target::Bias);
        }
        if let Some(name) = s.strip_prefix("parameter:") {
            return (!name.is_empty()).then(|| Target::Parameter(name.to_string()));
        }
        let index = |rest: &str| rest.strip_prefix('[')?.strip_suffix(']')?.parse().ok();
        let word = |k: &str| {
            let mut c = k.chars();
            matches!(c.next(), Some(x) if x.is_ascii_alphabetic() || x == '_')
                && c.all(|x| x.is_ascii_alphanumeric() || x == '_')
        };
        if let Some(rest) = s.strip_prefix("impurity:") {
            let (key, idx) = match rest.find('[') {
                Some(b) => (&rest[..b], Some(index(&rest[b..])?)),
                None => (rest, None),
            };
            return word(key).then(|| Target::Impurity {
                key: key.to_string(),
                index: idx,
            });
        }
        for key in ["y_bot", "y_top"] {
            if let Some(rest) = s.strip_prefix(key) {
                return index(rest).map(|k| Target::Impurity {
                    key: key.to_string(),
                    index: Some(k),
                });
            }
        }
        None
    }

    /// Whether this is one of the paper's rz y targets (`y_bot[K]`, `y_top[K]`), whose values
    /// must lie in [-1, 1].
    pub fn is_rz_y(&self) -> bool {
        matches!(self, Target::Impurity { key, index: Some(_) } if key == "y_bot" || key == "y_top")
    }
}

/// One dimension as written in the file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Dimension {
    /// Column name, e.g. `d_li_mm` or `y1_bot`.
    pub name: String,
    /// Unit of the physical value (`mm`, `V`, `1`).
    pub unit: String,
    /// [lo, hi] of the physical value.
    pub range: [f64; 2],
    /// Distribution over the range.
    #[serde(default)]
    pub distribution: Distribution,
    /// Where it enters the simulation: `bias`, `parameter:NAME`, `impurity:KEY`,
    /// `impurity:KEY[K]`, `y_bot[K]`, `y_top[K]` ([`Target`]).
    pub target: String,
    /// The name of an earlier dimension whose physical value this one takes instead of being
    /// sampled: a slice of a space that keeps the full space's columns (e.g. the B_Z slice of
    /// the rz space, every knot of a face at one value, `spaces/super-siegfried-bz-slice.toml`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub same_as: Option<String>,
}

/// A parameter space.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParameterSpace {
    /// Name, e.g. `super-siegfried-rz`.
    pub name: String,
    /// Free text.
    #[serde(default)]
    pub description: String,
    /// The dimensions, in column order.
    pub dimensions: Vec<Dimension>,
    /// The impurity model the `impurity:` targets fill in: a table as a detector's
    /// `[semiconductor.impurity]` (any model), with the keys the targets set left out or given
    /// (a list's elements are replaced). It replaces the detector's model at every point.
    /// Without it, `y_bot[K]` and `y_top[K]` targets mean `model = "rz"` with the detector's
    /// default knots (the paper's spaces).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub impurity: Option<toml::Table>,
    /// The file it came from.
    #[serde(skip)]
    pub file: PathBuf,
}

impl ParameterSpace {
    /// Reads and validates a space file.
    pub fn from_file(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::Io {
            file: path.into(),
            action: "cannot read the file",
            source: e,
        })?;
        Self::from_toml_str(&text, path)
    }

    /// Parses and validates TOML text (`path` names it in messages).
    pub fn from_toml_str(text: &str, path: &Path) -> Result<Self> {
        let mut s: Self = toml::from_str(text).map_err(|e| Error::Parse {
            file: path.into(),
            message: e.to_string().trim_end().to_string(),
        })?;
        s.file = path.into();
        s.validate()?;
        Ok(s)
    }

    fn validate(&self) -> Result<()> {
        let bad = |k: usize, key: &str, m: String| Error::Invalid {
            file: self.file.clone(),
            key: format!("dimensions[{k}].{key}"),
            message: m,
        };
        if self.dimensions.is_empty() {
            return Err(Error::Invalid {
                file: self.file.clone(),
                key: "dimensions".into(),
                message: "at least one dimension is needed".into(),
            });
        }
        for (k, d) in self.dimensions.iter().enumerate() {
            let [lo, hi] = d.range;
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(bad(
                    k,
                    "range",
                    format!("need finite lo < hi, got [{lo}, {hi}]"),
                ));
            }
            if d.distribution == Distribution::LogUniform && lo <= 0.0 {
                return Err(bad(
                    k,
                    "range",
                    format!("log-uniform needs lo > 0, got {lo}"),
                ));
            }
            if Target::parse(&d.target) == Some(Target::Bias) && lo <= 0.0 {
                return Err(bad(
                    k,
                    "range",
                    format!(
                        "the bias U_B must be above 0 V (the reverse bias, positive by this \
                         program's convention), got [{lo}, {hi}]"
                    ),
                ));
            }
            let is_y = Target::parse(&d.target).is_some_and(|t| t.is_rz_y());
            if is_y && (lo < -1.0 || hi > 1.0) {
                return Err(bad(
                    k,
                    "range",
                    format!(
                        "[{lo}, {hi}] leaves [-1, 1], the domain of y (`{}`); every sample outside it would fail",
                        d.target
                    ),
                ));
            }
            if Target::parse(&d.target).is_none() {
                return Err(bad(
                    k,
                    "target",
                    format!(
                        "`{}`: expected `bias`, `parameter:NAME`, `impurity:KEY`, `impurity:KEY[K]`, \
                         `y_bot[K]` or `y_top[K]`",
                        d.target
                    ),
                ));
            }
            // The name becomes a column of rows.csv: nothing that breaks a CSV header (a comma,
            // a quote, a line break or another control character; issue 66).
            if d.name.trim().is_empty()
                || d.name
                    .chars()
                    .any(|c| c == ',' || c == '"' || c.is_control())
            {
                return Err(bad(
                    k,
                    "name",
                    format!(
                        "{:?}: must be non-empty and without commas, quotes or line breaks (it \
                         is a CSV column)",
                        d.name
                    ),
                ));
            }
            if self.dimensions[..k].iter().any(|e| e.name == d.name) {
                return Err(bad(k, "name", format!("`{}` appears twice", d.name)));
            }
            if self.dimensions[..k].iter().any(|e| e.target == d.target) {
                return Err(bad(k, "target", format!("`{}` appears twice", d.target)));
            }
            if let Some(name) = &d.same_as {
                if Target::parse(&d.target) == Some(Target::Bias) {
                    return Err(bad(
                        k,
                        "same_as",
                        "the bias is always sampled (a C-V curve runs along it)".into(),
                    ));
                }
                let Some(src) = self.dimensions[..k].iter().find(|e| &e.name == name) else {
                    return Err(bad(
                        k,
                        "same_as",
                        format!("`{name}` is not the name of an earlier dimension"),
                    ));
                };
                if src.same_as.is_some() {
                    return Err(bad(
                        k,
                        "same_as",
                        format!(
                            "`{name}` takes its value from another dimension itself; name that one"
                        ),
                    ));
                }
                let [slo, shi] = src.range;
                if slo < lo || shi > hi {
                    return Err(bad(
                        k,
                        "range",
                        format!(
                            "[{lo}, {hi}] does not hold the range [{slo}, {shi}] of `{name}`, whose values it takes"
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Number of sampled dimensions (those without `same_as`): the dimension of the sequence
    /// a run draws from.
    pub fn sampled_dim(&self) -> usize {
        self.dimensions
            .iter()
            .filter(|d| d.same_as.is_none())
            .count()
    }

    /// Unit-cube and physical coordinates of every dimension from those of the sampled ones
    /// (`v`, in column order): a sampled dimension maps v as [`Self::from_unit`]; one with
    /// `same_as` takes the physical value of its source, and u = `to_unit` of it in its own
    /// range. Without `same_as` anywhere, (v, from_unit(v)).
    pub fn from_sampled_unit(&self, v: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let mut next = v.iter();
        let mut u = Vec::with_capacity(self.dim());
        let mut x: Vec<f64> = Vec::with_capacity(self.dim());
        for d in &self.dimensions {
            let (ud, xd) = match &d.same_as {
                None => {
                    let ud = next.next().copied().unwrap_or(0.5);
                    (ud, map_from_unit(d, ud))
                }
                Some(name) => {
                    let j = self.dimensions.iter().position(|e| &e.name == name);
                    let xd = j.map_or(f64::NAN, |j| x[j]);
                    (map_to_unit(d, xd), xd)
                }
            };
            u.push(ud);
            x.push(xd);
        }
        (u, x)
    }

    /// Number of dimensions d.
    pub fn dim(&self) -> usize {
        self.dimensions.len()
    }

    /// The targets, in column order.
    pub fn targets(&self) -> Vec<Target> {
        self.dimensions
            .iter()
            .map(|d| Target::parse(&d.target).expect("validated"))
            .collect()
    }

    /// Physical values from unit-cube coordinates u in [0, 1]^d (per dimension
    /// x = lo + u (hi - lo), or lo (hi / lo)^u for log-uniform).
    pub fn from_unit(&self, u: &[f64]) -> Vec<f64> {
        self.dimensions
            .iter()
            .zip(u)
            .map(|(d, &u)| map_from_unit(d, u))
            .collect()
    }

    /// Unit-cube coordinates of physical values (the inverse of [`Self::from_unit`]).
    pub fn to_unit(&self, x: &[f64]) -> Vec<f64> {
        self.dimensions
            .iter()
            .zip(x)
            .map(|(d, &x)| map_to_unit(d, x))
            .collect()
    }

    /// Standard-normal coordinates z = Phi^-1(u) of unit-cube coordinates (the paper's T_N).
    pub fn unit_to_normal(u: &[f64]) -> Vec<f64> {
        u.iter().map(|&u| normal_quantile(u)).collect()
    }

    /// Unit-cube coordinates u = Phi(z) of standard-normal ones.
    pub fn normal_to_unit(z: &[f64]) -> Vec<f64> {
        z.iter().map(|&z| normal_cdf(z)).collect()
    }
}

/// x = lo + u (hi - lo), or lo (hi / lo)^u for log-uniform.
fn map_from_unit(d: &Dimension, u: f64) -> f64 {
    let [lo, hi] = d.range;
    match d.distribution {
        Distribution::Uniform => lo + u * (hi - lo),
        Distribution::LogUniform => lo * (hi / lo).powf(u),
    }
}

/// The inverse of [`map_from_unit`].
fn map_to_unit(d: &Dimension, x: f64) -> f64 {
    let [lo, hi] = d.range;
    match d.distribution {
        Distribution::Uniform => (x - lo) / (hi - lo),
        Distribution::LogUniform => (x / lo).ln() / (hi / lo).ln(),
    }
}
