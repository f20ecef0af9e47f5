//! Labelled data sets (the rows written by `generate`, or a subset such as `train.csv`) read
//! against a parameter space: the inputs in the network's order (the non-bias dimensions in space
//! order, then the bias), their unit-cube coordinates and c12.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::transform::unit_to_z;
use crate::error::{Error, Result};
use crate::generate::{REGIME_COLUMNS, Regime, SWITCH_COLUMN};
use crate::hash::fnv1a;
use crate::space::{Dimension, ParameterSpace, Target};

/// A data set of (p, U_B) -> c12 samples.
#[derive(Debug, Clone)]
pub struct DataSet {
    /// The file it came from.
    pub file: PathBuf,
    /// FNV-1a hash (hex) of the file's bytes: the provenance recorded in a model file.
    pub hash: String,
    /// Sample indices (the `index` column).
    pub index: Vec<u64>,
    /// Unit-cube coordinates, row-major n x d, in network order (parameters, then the bias).
    pub unit: Vec<f64>,
    /// Physical values, row-major n x d, in network order.
    pub physical: Vec<f64>,
    /// The solver's c12 (pF) of each sample.
    pub c12_pf: Vec<f64>,
    /// Rows without a c12 (status not `ok`, e.g. an undepleted region joining two contacts):
    /// left out, counted here. A row with status `ok` whose c12 is not a finite positive
    /// number is an error, as is an index that appears twice.
    pub excluded: usize,
    /// Number of input dimensions d.
    pub dim: usize,
    /// Each sample's regime (`pockets`, `pocket_level_V`, `pocket_cm3`), where the file has
    /// those columns (`generate` since they exist, or `hpge-cv label`); else empty.
    pub regime: Vec<Option<Regime>>,
    /// Each sample's nearest bias (V) at which the pocket count changes (`pocket_switch_V`
    /// of `hpge-cv label`; NaN: none within its window); empty where the file has no such
    /// column.
    pub switch_v: Vec<f64>,
    /// The space's bias dimension (the last in network order).
    pub bias: Dimension,
}

impl DataSet {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.c12_pf.len()
    }

    /// True without samples.
    pub fn is_empty(&self) -> bool {
        self.c12_pf.is_empty()
    }

    /// The unit-cube row i.
    pub fn unit_row(&self, i: usize) -> &[f64] {
        &self.unit[i * self.dim..(i + 1) * self.dim]
    }

    /// The network coordinates z = Phi^-1(u) of row i (the input map of every model).
    pub fn z_row(&self, i: usize) -> Vec<f64> {
        self.unit_row(i).iter().map(|&u| unit_to_z(u)).collect()
    }

    /// The physical row i.
    pub fn physical_row(&self, i: usize) -> &[f64] {
        &self.physical[i * self.dim..(i + 1) * self.dim]
    }

    /// Reads a rows file (`index,u_<name>...,<name>...,c12_pF,status[,seconds]`) and checks it
    /// against `space`: the columns must name the space's dimensions in its order, and every
    /// physical value must equal the space's map of its unit coordinate (so a file of another
    /// space with the same names but other ranges is refused too), every index must appear
    /// once, and every row with status `ok` must have a finite c12 above 0.
    pub fn read(path: &Path, space: &ParameterSpace) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::Io {
            file: path.into(),
            action: "cannot read the data set",
            source: e,
        })?;
        let order = network_order(space)?;
        let d = space.dim();
        let invalid = |key: String, message: String| Error::Invalid {
            file: path.into(),
            key,
            message,
        };
        // A byte-order mark (spreadsheet programs write one) is not part of the first column's
        // name.
        let body = text.strip_prefix('\u{feff}').unwrap_or(&text);
        let mut lines = body.lines().enumerate();
        let header: Vec<&str> = match lines.next() {
            Some((_, h)) => h.split(',').collect(),
            None => return Err(invalid("header".into(), "the file is empty".into())),
        };
        let mut expected = vec!["index".to_string()];
        expected.extend(space.dimensions.iter().map(|x| format!("u_{}", x.name)));
        expected.extend(space.dimensions.iter().map(|x| x.name.clone()));
        expected.push("c12_pF".into());
        expected.push("status".into());
        let matches = header.len() >= expected.len()
            && header.iter().zip(&expected).all(|(a, b)| a.trim() == b);
        if !matches {
            return Err(invalid(
                "header".into(),
                format!(
                    "the columns do not match space `{}` ({}): expected `{}`, found `{}` \
                     (a data set of another space?)",
                    space.name,
                    space.file.display(),
                    expected.join(","),
                    header.join(",")
                ),
            ));
        }
        let mut set = DataSet {
            file: path.into(),
            hash: format!("{:016x}", fnv1a(text.as_bytes())),
            index: Vec::new(),
            unit: Vec::new(),
            physical: Vec::new(),
            c12_pf: Vec::new(),
            excluded: 0,
            dim: d,
            regime: Vec::new(),
            switch_v: Vec::new(),
            bias: space.dimensions[order[d - 1]].clone(),
        };
        let column = |name: &str| header.iter().position(|h| h.trim() == name);
        let regime_col = column(REGIME_COLUMNS[0]).filter(|&c| {
            REGIME_COLUMNS[1..]
                .iter()
                .enumerate()
                .all(|(k, n)| header.get(c + 1 + k).map(|h| h.trim()) == Some(*n))
        });
        let switch_col = column(SWITCH_COLUMN);
        let mut u = vec![0.0; d];
        let mut x = vec![0.0; d];
        let mut seen: std::collections::HashMap<u64, usize> = std::collections::HashMap::new();
        for (k, line) in lines {
            if line.trim().is_empty() {
                continue;
            }
            let line_no = k + 1;
            let cols: Vec<&str> = line.split(',').collect();
            if cols.len() < expected.len() {
                return Err(invalid(
                    format!("line {line_no}"),
                    format!("{} columns, expected {}", cols.len(), expected.len()),
                ));
            }
            let num = |c: usize| -> Result<f64> {
                cols[c].trim().parse::<f64>().map_err(|_| {
                    invalid(
                        format!("line {line_no}, column `{}`", expected[c]),
                        format!("`{}` is not a number", cols[c]),
                    )
                })
            };
            let index = cols[0].trim().parse::<u64>().map_err(|_| {
                invalid(
                    format!("line {line_no}, column `index`"),
                    format!("`{}` is not an index", cols[0]),
                )
            })?;
            for j in 0..d {
                u[j] = num(1 + j)?;
                x[j] = num(1 + d + j)?;
            }
            if let Some(first) = seen.insert(index, line_no) {
                return Err(invalid(
                    format!("line {line_no}, column `index`"),
                    format!(
                        "index {index} appears twice (lines {first} and {line_no}): every sample \
                         must appear once (shards merged twice, or files concatenated?)"
                    ),
                ));
            }
            let status = cols[2 + 2 * d].trim();
            if status != "ok" {
                set.excluded += 1;
                continue;
            }
            let c12_text = cols[1 + 2 * d].trim();
            let c12 = c12_text.parse::<f64>().unwrap_or(f64::NAN);
            if !(c12.is_finite() && c12 > 0.0) {
                return Err(invalid(
                    format!("line {line_no}, column `c12_pF`"),
                    format!(
                        "`{c12_text}` with status ok: a solved c12 must be a finite number of pF \
                         above 0 (a corrupted row?)"
                    ),
                ));
            }
            let mapped = space.from_unit(&u);
            for j in 0..d {
                if !(0.0..=1.0).contains(&u[j]) || !u[j].is_finite() {
                    return Err(invalid(
                        format!("line {line_no}, column `u_{}`", space.dimensions[j].name),
                        format!("{} is outside [0, 1]", u[j]),
                    ));
                }
                let tol = 1e-9 * (1.0 + mapped[j].abs());
                if (mapped[j] - x[j]).abs() > tol {
                    let dim = &space.dimensions[j];
                    return Err(invalid(
                        format!("line {line_no}, column `{}`", dim.name),
                        format!(
                            "{} is not the space's value {} for u = {} (range {:?} in {}): a data \
                             set of another space?",
                            x[j],
                            mapped[j],
                            u[j],
                            dim.range,
                            space.file.display()
                        ),
                    ));
                }
            }
            set.index.push(index);
            set.unit.extend(order.iter().map(|&j| u[j]));
            set.physical.extend(order.iter().map(|&j| x[j]));
            set.c12_pf.push(c12);
            if let Some(c) = regime_col {
                let field = |k: usize| cols.get(c + k).copied().unwrap_or("");
                set.regime.push(Regime::parse(field(0), field(1), field(2)));
            }
            if let Some(c) = switch_col {
                let v = cols.get(c).and_then(|t| t.trim().parse().ok());
                set.switch_v.push(v.unwrap_or(f64::NAN));
            }
        }
        if set.is_empty() {
            return Err(invalid(
                "rows".into(),
                format!("no usable sample ({} rows without c12)", set.excluded),
            ));
        }
        Ok(set)
    }
}

/// The network's input order: indices of the space's non-bias dimensions in order, then the
/// bias. A surrogate needs exactly one `bias` dimension.
pub fn network_order(space: &ParameterSpace) -> Result<Vec<usize>> {
    let targets = space.targets();
    let bias: Vec<usize> = (0..targets.len())
        .filter(|&j| targets[j] == Target::Bias)
        .collect();
    if bias.len() != 1 {
        return Err(Error::Invalid {
            file: space.file.clone(),
            key: "dimensions".into(),
            message: format!(
                "a surrogate needs exactly one dimension with target `bias`, found {}",
                bias.len()
            ),
        });
    }
    let mut order: Vec<usize> = (0..targets.len()).filter(|&j| j != bias[0]).collect();
    order.push(bias[0]);
    Ok(order)
}

/// Provenance of a data set used in training.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DataInfo {
    /// File as given.
    pub file: String,
    /// FNV-1a hash (hex) of its bytes.
    pub hash: String,
    /// Samples used.
    pub n: usize,
    /// Rows without c12, left out.
    pub excluded: usize,
}

impl DataInfo {
    /// Of a data set.
    pub fn of(set: &DataSet) -> Self {
        DataInfo {
            file: set.file.display().to_string(),
            hash: set.hash.clone(),
            n: set.len(),
            excluded: set.excluded,
        }
    }
}
