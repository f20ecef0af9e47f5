//! The accuracy of a model on a data set of its space, as `hpge-cv evaluate` reports it: the
//! figures of the relative errors and the worst samples; [`EvaluationJson`] is its `--json`
//! record.

use std::path::Path;

use serde::Serialize;

use super::bands::{BiasBand, bias_bands};
use super::regimes::{RegimeGroup, regime_groups};
use crate::model::{DataSet, Figures, Surrogate, dimension_from_unit, quantile};
use crate::{Error, Result};

/// One of the worst samples (largest |relative error|).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Worst {
    /// Sample index (the data set's `index` column).
    pub index: u64,
    /// The model's inputs (name, physical value) in network order.
    pub inputs: Vec<(String, f64)>,
    /// The solver's c12 (pF).
    pub c12_solver_pf: f64,
    /// The surrogate's c12 (pF).
    pub c12_surrogate_pf: f64,
    /// (c_p - c_s)/c_s.
    pub rel: f64,
}

/// The fraction of u at each end of an input that counts as its edge in [`EdgeFigures`].
pub const EDGE_FRACTION: f64 = 0.05;

/// |relative error| of the rows at one edge of one input.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EdgeStats {
    /// The edge's physical range [lo, hi] (u in [0, 0.05] or [0.95, 1]).
    pub range: [f64; 2],
    /// Rows at this edge.
    pub n: usize,
    /// Median of |relative error| (NaN without rows).
    pub abs_rel_q50: f64,
    /// 90% quantile of |relative error|.
    pub abs_rel_q90: f64,
    /// Largest |relative error|.
    pub abs_rel_max: f64,
    /// Mean of the relative error (its sign: over- or underestimate).
    pub rel_mean: f64,
}

impl EdgeStats {
    fn of(range: [f64; 2], rel: &[f64]) -> Self {
        let mut abs: Vec<f64> = rel.iter().map(|r| r.abs()).collect();
        abs.sort_by(f64::total_cmp);
        let n = rel.len();
        EdgeStats {
            range,
            n,
            abs_rel_q50: quantile(&abs, 0.5),
            abs_rel_q90: quantile(&abs, 0.9),
            abs_rel_max: abs.last().copied().unwrap_or(f64::NAN),
            rel_mean: if n == 0 {
                f64::NAN
            } else {
                rel.iter().sum::<f64>() / n as f64
            },
        }
    }
}

/// The accuracy at the two edges of one input (issue 24): the rows in the lowest and highest
/// [`EDGE_FRACTION`] of its u, beside the whole set's figures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EdgeFigures {
    /// Input name (network order).
    pub name: String,
    /// Rows with u <= 0.05.
    pub low: EdgeStats,
    /// Rows with u >= 0.95.
    pub high: EdgeStats,
    /// The range the model's training rows support ([`Surrogate::support`]).
    pub support: [f64; 2],
}

/// Edge figures of every input of a data set with predictions `pred`.
pub fn edge_figures(model: &Surrogate, data: &DataSet, pred: &[f64]) -> Vec<EdgeFigures> {
    let space = &model.info.space;
    let order = crate::model::network_order(space).unwrap_or_default();
    let rel: Vec<f64> = pred
        .iter()
        .zip(&data.c12_pf)
        .map(|(p, t)| (p - t) / t)
        .collect();
    order
        .iter()
        .enumerate()
        .map(|(k, &j)| {
            let d = &space.dimensions[j];
            let pick = |keep: &dyn Fn(f64) -> bool| -> Vec<f64> {
                (0..data.len())
                    .filter(|&i| keep(data.unit_row(i)[k]))
                    .map(|i| rel[i])
                    .collect()
            };
            let low = pick(&|u| u <= EDGE_FRACTION);
            let high = pick(&|u| u >= 1.0 - EDGE_FRACTION);
            let edge = |a: f64, b: f64| [dimension_from_unit(d, a), dimension_from_unit(d, b)];
            EdgeFigures {
                name: d.name.clone(),
                low: EdgeStats::of(edge(0.0, EDGE_FRACTION), &low),
                high: EdgeStats::of(edge(1.0 - EDGE_FRACTION, 1.0), &high),
                support: model.support(k),
            }
        })
        .collect()
}

/// A model's accuracy on a data set.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    /// Error figures (relative values as fractions).
    pub figures: Figures,
    /// Rows of the data set without c12, left out.
    pub excluded: usize,
    /// FNV-1a hash (hex) of the data file's bytes.
    pub data_hash: String,
    /// The model's recipe name.
    pub recipe: String,
    /// The model's sigma_p.
    pub sigma_p: f64,
    /// The worst samples, worst first.
    pub worst: Vec<Worst>,
    /// The model's c12 (pF) of every sample (for plots).
    pub predictions: Vec<f64>,
    /// The accuracy at the edges of every input (network order).
    pub edges: Vec<EdgeFigures>,
    /// Fractions of the samples whose relative error lies within 1 and 2 predicted sigma (the
    /// model's calibrated sigma_s(p, U_B), or its constant sigma_p without an error model).
    pub coverage: (f64, f64),
    /// `per-point` (a calibrated error model) or `constant` (sigma_p).
    pub sigma_kind: &'static str,
    /// The accuracy by band of the bias ([`super::bias_bands`]).
    pub bias_bands: Vec<BiasBand>,
    /// The accuracy by depletion regime, where the data set is labelled
    /// ([`super::regime_groups`]).
    pub regimes: Vec<RegimeGroup>,
}

/// `evaluate --json`: the fields first, then the rest (the field order is the JSON's).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EvaluationJson<'a> {
    /// Samples.
    pub n: usize,
    /// Gaussian sigma of the relative error.
    pub rel_sigma: f64,
    /// Its mean.
    pub rel_mean: f64,
    /// Median of |relative error|.
    pub abs_rel_q50: f64,
    /// 90% quantile of |relative error|.
    pub abs_rel_q90: f64,
    /// 99% quantile of |relative error|.
    pub abs_rel_q99: f64,
    /// Largest |relative error|.
    pub abs_rel_max: f64,
    /// 99.9% quantile of |relative error|.
    pub abs_rel_q999: f64,
    /// Root mean square of the relative error.
    pub rel_rms: f64,
    /// Root mean square of c_p - c_s (pF).
    pub abs_rms_pf: f64,
    /// Fraction of samples whose relative error is within 1 predicted sigma (the calibrated
    /// sigma_s(p, U_B), or sigma_p for a model without an error model; issue 21).
    pub coverage_1sigma: f64,
    /// The same within 2 predicted sigma.
    pub coverage_2sigma: f64,
    /// The Gaussian sigma of the relative error (= `rel_sigma`: the core of the distribution,
    /// as the paper defines sigma_p).
    pub rel_sigma_core: f64,
    /// `per-point` (the model file's calibrated sigma_s) or `constant` (sigma_p).
    pub sigma_kind: &'a str,
    /// Rows without c12, left out.
    pub excluded: usize,
    /// The model file as given.
    pub model: String,
    /// The data file as given.
    pub data: String,
    /// FNV-1a hash (hex) of the data file.
    pub data_hash: &'a str,
    /// The model's recipe name.
    pub recipe: &'a str,
    /// The model's sigma_p.
    pub sigma_p: f64,
    /// The worst samples, worst first.
    pub worst: &'a [Worst],
    /// What made this file: program, version, date and the solver's physics revision (the
    /// rows' labels come from the solver).
    pub made: hpge_foundation::Made,
    /// This program's version.
    pub program_version: &'static str,
    /// The accuracy at the edges of every input (issue 24): rows in the lowest and highest 5%
    /// of its u.
    pub edges: &'a [EdgeFigures],
    /// The accuracy by band of the bias voltage, finer at low bias (empty for a space without
    /// one).
    pub bias_bands: &'a [BiasBand],
    /// The accuracy within the solver's pinch-off transition and away from it, and with and
    /// without a pocket (empty for a data set without the regime columns).
    pub regimes: &'a [RegimeGroup],
}

/// Reads a data set against the space of `model` (loaded from `model_file`); a refusal names the
/// model and its space ([`Error::DataForModel`]).
pub fn read_for_model(model: &Surrogate, model_file: &Path, data: &Path) -> Result<DataSet> {
    DataSet::read(data, &model.info.space).map_err(|e| Error::DataForModel {
        error: Box::new(e),
        model: model_file.into(),
        space: model.info.space.name.clone(),
    })
}

impl Evaluation {
    /// The figures of `model` on `data` and its `worst` worst samples (by |relative error|;
    /// ties keep the data set's order).
    pub fn new(model: &Surrogate, data: &DataSet, worst: usize) -> Self {
        let pred = model.predict_set(data);
        let figures = Figures::of(&pred, &data.c12_pf);
        let names = &model.info.inputs;
        let rel = |i: usize| (pred[i] - data.c12_pf[i]) / data.c12_pf[i];
        let mut order: Vec<usize> = (0..data.len()).collect();
        order.sort_by(|&a, &b| rel(b).abs().total_cmp(&rel(a).abs()));
        let worst = order
            .iter()
            .take(worst)
            .map(|&i| Worst {
                index: data.index[i],
                inputs: names
                    .iter()
                    .cloned()
                    .zip(data.physical_row(i).iter().copied())
                    .collect(),
                c12_solver_pf: data.c12_pf[i],
                c12_surrogate_pf: pred[i],
                rel: rel(i),
            })
            .collect();
        let edges = edge_figures(model, data, &pred);
        let rels: Vec<f64> = (0..data.len()).map(rel).collect();
        let sigma = model.sigma_set(data);
        let coverage = crate::model::coverage_of(&rels, sigma.iter().copied());
        let bias_bands = bias_bands(model, data, &rels, &sigma);
        let regimes = regime_groups(data, &rels, &sigma);
        Evaluation {
            figures,
            excluded: data.excluded,
            data_hash: data.hash.clone(),
            recipe: model.info.recipe_name.clone(),
            sigma_p: model.sigma_p(),
            worst,
            predictions: pred,
            edges,
            coverage,
            sigma_kind: model.sigma_kind(),
            bias_bands,
            regimes,
        }
    }

    /// The `--json` record, naming the model and data files as given.
    pub fn json(&self, model_file: &Path, data_file: &Path) -> EvaluationJson<'_> {
        let f = &self.figures;
        EvaluationJson {
            n: f.n,
            rel_sigma: f.rel_sigma,
            rel_mean: f.rel_mean,
            abs_rel_q50: f.abs_rel_q50,
            abs_rel_q90: f.abs_rel_q90,
            abs_rel_q99: f.abs_rel_q99,
            abs_rel_max: f.abs_rel_max,
            abs_rel_q999: f.abs_rel_q999,
            rel_rms: f.rel_rms,
            abs_rms_pf: f.abs_rms_pf,
            coverage_1sigma: self.coverage.0,
            coverage_2sigma: self.coverage.1,
            rel_sigma_core: f.rel_sigma,
            sigma_kind: self.sigma_kind,
            excluded: self.excluded,
            model: model_file.display().to_string(),
            data: data_file.display().to_string(),
            data_hash: &self.data_hash,
            recipe: &self.recipe,
            sigma_p: self.sigma_p,
            worst: &self.worst,
            made: hpge_solver::made(),
            program_version: env!("CARGO_PKG_VERSION"),
            edges: &self.edges,
            bias_bands: &self.bias_bands,
            regimes: &self.regimes,
        }
    }
}
