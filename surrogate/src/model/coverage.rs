//! Where the training rows support the surrogate (issue 24): per input, the range of unit
//! coordinates u inside which at least [`SUPPORT_ROWS`] training rows lie further out on either
//! side. The input map z = Phi^-1(u) stretches the last 1e-4 of u over |z| > 3.7, where a
//! quasi-random training set of ~50000 rows has a handful of points: there the network
//! extrapolates (the shipped models give +40% at 10.1 V and more at 10 V, the bias range's
//! lower edge, which maps to z = -4.75 while the training rows reach z = -4.6). `predict`
//! refuses points outside the support unless `--extrapolate` is given.

use serde::{Deserialize, Serialize};

use super::dataset::DataSet;

/// A point is supported in a dimension when at least this many training rows lie beyond it on
/// both sides (in that dimension's u). Chosen from the shipped models' errors at the centre of
/// the parameters: the `split` model is +122% at 10 V, +44% at 10.1 V, +17% at 10.6 V (10 rows
/// beyond), +12% at 11 V, +5% at 12 V and 0.0% at 15 V; 50 rows put the bias support at
/// [13.4, 2996.6] V for 43447 training rows.
pub const SUPPORT_ROWS: usize = 50;

/// The rows that must lie beyond a supported value in a set of n training rows:
/// [`SUPPORT_ROWS`], or 1% of the rows (at least one) for sets under 5000 rows (test models).
pub fn support_rows(n: usize) -> usize {
    SUPPORT_ROWS.min((n / 100).max(1))
}

/// The support of one input, recorded in the model file at training.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Coverage {
    /// Input name (network order).
    pub name: String,
    /// u of the [`support_rows`]-th lowest and highest training row: the supported range.
    pub u_support: [f64; 2],
    /// u of the lowest and highest training row.
    pub u_extreme: [f64; 2],
    /// Training rows it was measured on.
    pub rows: usize,
}

impl Coverage {
    /// The support of every input of a training set (`names` in network order).
    pub fn of(set: &DataSet, names: &[String]) -> Vec<Coverage> {
        let n = set.len();
        names
            .iter()
            .enumerate()
            .map(|(k, name)| {
                let mut u: Vec<f64> = (0..n).map(|i| set.unit_row(i)[k]).collect();
                u.sort_by(f64::total_cmp);
                let (lo, hi) = if n == 0 {
                    (0.0, 1.0)
                } else {
                    let j = support_rows(n) - 1;
                    (u[j], u[n - 1 - j])
                };
                Coverage {
                    name: name.clone(),
                    u_support: [lo.min(hi), hi.max(lo)],
                    u_extreme: [
                        u.first().copied().unwrap_or(0.0),
                        u.last().copied().unwrap_or(1.0),
                    ],
                    rows: n,
                }
            })
            .collect()
    }

    /// The support estimated for a model file trained before the record existed, from the number
    /// of training rows n alone: quasi-random rows spread evenly in u, so about n u of them lie
    /// below u, and the support is [k/n, 1 - k/n], k = [`support_rows`] (n).
    pub fn estimate(name: &str, n: usize) -> Coverage {
        let e = (support_rows(n) as f64 / n.max(1) as f64).min(0.5);
        let x = (1.0 / n.max(1) as f64).min(0.5);
        Coverage {
            name: name.into(),
            u_support: [e, 1.0 - e],
            u_extreme: [x, 1.0 - x],
            rows: n,
        }
    }
}
