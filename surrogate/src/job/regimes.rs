//! A model's accuracy split by depletion regime, as `hpge-cv evaluate` reports it when the data
//! set carries the regime columns (`generate` since they exist, or `hpge-cv label`): the rows
//! within the solver's pinch-off transition against the rest, and the rows with a pocket
//! against those without.
//!
//! The small-signal c12 jumps where the pocket count changes (an undepleted region cut off from
//! its contact, or joined to it again across a barrier of millivolts), and is smooth between.
//! A network smooth in (p, U_B) misses the rows near that switching surface; these groups show
//! how much of the error's tail sits there.

use serde::Serialize;

use super::bands::band;
use crate::model::DataSet;

/// A row is within the pinch-off transition when the pocket count changes within this many
/// volts of its bias (`pocket_switch_V` of `hpge-cv label`, found within +-100 V).
pub const TRANSITION_V: f64 = 25.0;

/// The accuracy of one group of rows.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RegimeGroup {
    /// `transition`, `away` (the labelled rows not within the transition), `pockets` (at
    /// least one pocket at the row's bias) or `no_pockets`.
    pub group: &'static str,
    /// Which rows: the rule in words.
    pub rule: String,
    /// Rows in the group.
    pub n: usize,
    /// Gaussian sigma of the relative error (NaN without rows).
    pub rel_sigma: f64,
    /// Median of |relative error|.
    pub abs_rel_q50: f64,
    /// 90% quantile of |relative error|.
    pub abs_rel_q90: f64,
    /// 99% quantile of |relative error|.
    pub abs_rel_q99: f64,
    /// Fraction within 2 predicted sigma.
    pub coverage_2sigma: f64,
}

/// The groups of `data` with relative errors `rel` and predicted relative sigmas `sigma`:
/// `transition` and `away` where the set has `pocket_switch_V`, `pockets` and `no_pockets`
/// where it has the regime columns; empty for a set with neither.
pub fn regime_groups(data: &DataSet, rel: &[f64], sigma: &[f64]) -> Vec<RegimeGroup> {
    let bias = data.dim - 1;
    let mut out = Vec::new();
    let mut group = |name: &'static str, rule: String, keep: &dyn Fn(usize) -> bool| {
        let rows: Vec<usize> = (0..data.len()).filter(|&i| keep(i)).collect();
        let b = band(
            [f64::NAN, f64::NAN],
            &rows.iter().map(|&i| rel[i]).collect::<Vec<_>>(),
            &rows.iter().map(|&i| sigma[i]).collect::<Vec<_>>(),
        );
        out.push(RegimeGroup {
            group: name,
            rule,
            n: b.n,
            rel_sigma: b.rel_sigma,
            abs_rel_q50: b.abs_rel_q50,
            abs_rel_q90: b.abs_rel_q90,
            abs_rel_q99: b.abs_rel_q99,
            coverage_2sigma: b.coverage_2sigma,
        });
    };
    if data.switch_v.len() == data.len() && !data.is_empty() {
        let near = |i: usize| {
            let s = data.switch_v[i];
            s.is_finite() && (data.physical_row(i)[bias] - s).abs() <= TRANSITION_V
        };
        let labelled = |i: usize| data.regime.get(i).is_some_and(Option::is_some);
        group(
            "transition",
            format!("the pocket count changes within {TRANSITION_V} V of the row's bias"),
            &|i| labelled(i) && near(i),
        );
        group(
            "away",
            format!("no change of the pocket count within {TRANSITION_V} V"),
            &|i| labelled(i) && !near(i),
        );
    }
    if data.regime.len() == data.len() && !data.is_empty() {
        let count = |i: usize| data.regime[i].map(|r| r.pockets);
        group(
            "pockets",
            "at least one trapped-carrier pocket at the row's bias".into(),
            &|i| count(i).is_some_and(|n| n > 0),
        );
        group("no_pockets", "no pocket at the row's bias".into(), &|i| {
            count(i) == Some(0)
        });
    }
    out
}
