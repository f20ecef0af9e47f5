//! The prior file as written (TOML), before it meets a model.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::PriorDistribution;
use crate::{Error, Result};

/// One fit parameter as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParameterSpec {
    /// Its name in outputs (e.g. `d_li_mm`, `y_bot`).
    pub name: String,
    /// Unit of the value (`mm`, `1`), for labels.
    #[serde(default)]
    pub unit: String,
    /// Free text (what it is, where the prior comes from).
    #[serde(default)]
    pub description: String,
    /// The model inputs it sets (one, or several for a tied parameter); default: its own name.
    #[serde(default)]
    pub inputs: Vec<String>,
    /// The prior.
    pub prior: PriorDistribution,
}

/// A prior file (`priors/b-z.toml`, `priors/b-rz.toml`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PriorSpec {
    /// Name, e.g. `b-rz`.
    pub name: String,
    /// Free text.
    #[serde(default)]
    pub description: String,
    /// The fit parameters, in output order.
    pub parameters: Vec<ParameterSpec>,
    /// Model inputs held at a value (input name -> value in the input's unit).
    #[serde(default)]
    pub fixed: BTreeMap<String, f64>,
    /// The file it came from.
    #[serde(skip)]
    pub file: PathBuf,
}

impl PriorSpec {
    /// Reads a prior file.
    pub fn from_file(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            file: path.into(),
            action: "cannot read the prior",
            source,
        })?;
        Self::from_toml_str(&text, path)
    }

    /// Parses a prior from TOML text (`path` names it in messages) and checks what can be checked
    /// without a model: names unique, bounds ordered, standard deviations positive.
    ///
    /// ```
    /// use std::path::Path;
    /// use hpge_inference::PriorSpec;
    /// let text = r#"
    /// name = "li"
    /// [[parameters]]
    /// name = "d_li_mm"
    /// inputs = ["d_li_mm"]
    /// prior = { distribution = "uniform", lo = 0.2, hi = 5.0 }
    /// "#;
    /// let spec = PriorSpec::from_toml_str(text, Path::new("li.toml"))?;
    /// assert_eq!(spec.parameters.len(), 1);
    /// // Bounds out of order are refused, naming the file.
    /// let bad = text.replace("lo = 0.2, hi = 5.0", "lo = 5.0, hi = 0.2");
    /// let e = PriorSpec::from_toml_str(&bad, Path::new("li.toml")).unwrap_err();
    /// assert!(e.to_string().contains("li.toml"), "{e}");
    /// # Ok::<(), hpge_inference::Error>(())
    /// ```
    pub fn from_toml_str(text: &str, path: &Path) -> Result<Self> {
        let mut spec: PriorSpec =
            toml::from_str(text).map_err(|e| Error::format(path, e.to_string()))?;
        spec.file = path.into();
        spec.validate()?;
        Ok(spec)
    }

    /// Checks the file on its own.
    pub fn validate(&self) -> Result<()> {
        let bad = |key: String, message: String| Error::invalid(&self.file, key, message);
        if self.parameters.is_empty() {
            return Err(bad("parameters".into(), "no parameters to fit".into()));
        }
        for (i, p) in self.parameters.iter().enumerate() {
            let key = format!("parameters[{i}] ({})", p.name);
            if p.name.is_empty() {
                return Err(bad(key, "empty name".into()));
            }
            // The name becomes a column of samples.csv: nothing that breaks a CSV header
            // (issue 66).
            if p.name
                .chars()
                .any(|c| c == ',' || c == '"' || c.is_control())
            {
                return Err(bad(
                    format!("parameters[{i}] ({:?})", p.name),
                    "the name may not hold a comma, a quote or a line break (it is a CSV column)"
                        .into(),
                ));
            }
            if self.parameters[..i].iter().any(|q| q.name == p.name) {
                return Err(bad(key, "the name is used twice".into()));
            }
            match p.prior {
                PriorDistribution::Uniform { lo, hi } => {
                    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                        return Err(bad(
                            key,
                            format!("uniform needs finite lo < hi, got [{lo}, {hi}]"),
                        ));
                    }
                }
                PriorDistribution::Normal { mean, sd } => {
                    if !(mean.is_finite() && sd.is_finite() && sd > 0.0) {
                        return Err(bad(
                            key,
                            format!("normal needs a finite mean and sd > 0, got ({mean}, {sd})"),
                        ));
                    }
                }
                PriorDistribution::TruncatedNormal { mean, sd, lo, hi } => {
                    if !(mean.is_finite() && sd.is_finite() && sd > 0.0) {
                        return Err(bad(
                            key,
                            format!(
                                "truncated-normal needs a finite mean and sd > 0, got ({mean}, {sd})"
                            ),
                        ));
                    }
                    if let (Some(a), Some(b)) = (lo, hi)
                        && a.partial_cmp(&b) != Some(std::cmp::Ordering::Less)
                    {
                        return Err(bad(
                            key,
                            format!("truncated-normal needs lo < hi, got [{a}, {b}]"),
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// The inputs a parameter sets (its `inputs`, or its own name).
    pub fn inputs_of(p: &ParameterSpec) -> Vec<String> {
        if p.inputs.is_empty() {
            vec![p.name.clone()]
        } else {
            p.inputs.clone()
        }
    }
}
