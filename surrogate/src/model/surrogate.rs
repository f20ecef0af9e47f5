//! A trained surrogate: its metadata, its predictor (networks or the polynomial baseline), the
//! domain guard and the curve path inference calls (values and the Jacobian with respect to the
//! physical parameters).

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::coverage::{Coverage, support_rows};
use super::dataset::{DataInfo, DataSet, network_order};
use super::error_model::ErrorModel;
use super::metrics::Figures;
use super::network::Network;
use super::polynomial::Polynomial;
use super::recipe::{OutputTransform, Recipe};
use super::transform::{dimension_from_unit, dimension_to_unit, physical_to_z};
use crate::error::{Error, Result};
use crate::space::{Dimension, ParameterSpace};

/// Name of the model-file format (safetensors metadata key `format`).
pub const FORMAT: &str = "hpge-cv-surrogate";
/// Version of the model-file layout this program reads and writes.
pub const FORMAT_VERSION: u32 = 1;

/// The detector a model's training rows were simulated for.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct DetectorInfo {
    /// The detector file as given.
    pub file: String,
    /// FNV-1a hash (hex) of its text followed by its impurity file's bytes (as in a generation
    /// run's fingerprint, `ExactSolver::detector_hash`).
    pub hash: String,
}

/// Everything a model file records besides its weights.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelInfo {
    /// Always [`FORMAT`].
    pub format: String,
    /// [`FORMAT_VERSION`] when written.
    pub format_version: u32,
    /// hpge-cv version that trained it.
    pub program_version: String,
    /// The input space (ranges define the domain).
    pub space: ParameterSpace,
    /// Inputs in network order (the parameters, then the bias).
    pub inputs: Vec<String>,
    /// The input normalisation, in words.
    pub input_map: String,
    /// The output transform.
    pub output: OutputTransform,
    /// Recipe name (`paper`, ..., or `poly3`).
    pub recipe_name: String,
    /// The network recipe (none for the polynomial).
    pub recipe: Option<Recipe>,
    /// Seed of initialisation and batch order.
    pub seed: u64,
    /// Training set.
    pub training: DataInfo,
    /// Test set (learning curves, sigma_p).
    pub test: DataInfo,
    /// Training wall time (s) and threads.
    pub train_seconds: f64,
    /// Threads used in training.
    pub threads: usize,
    /// Figures on the test set.
    pub test_figures: Figures,
    /// The detector the training rows were simulated for (`train --detector`); a fit checks it
    /// against the detector it is given. Absent in files trained without it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub detector: Option<DetectorInfo>,
    /// Per input (network order), the range of u its training rows support ([`Coverage`],
    /// issue 24). Absent in files trained before the record existed: [`Surrogate::coverage`]
    /// then estimates it from the number of training rows. It changes no prediction, only which
    /// points `predict` accepts without `--extrapolate`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coverage: Option<Vec<Coverage>>,
    /// The calibrated per-point uncertainty sigma_s(p, U_B) (issue 21; `hpge-cv calibrate`):
    /// when present, inference uses it in place of [`Self::sigma_p`]. Absent in files not
    /// calibrated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error_model: Option<ErrorModel>,
    /// sigma_p: the relative surrogate uncertainty inference uses (sigma_c^p = sigma_p c_p, the
    /// paper's eq. CapUncertaintyDNN): the Gaussian sigma on the test set.
    pub sigma_p: f64,
}

/// What computes the output y.
#[derive(Debug, Clone, PartialEq)]
pub enum Predictor {
    /// Networks (ensemble members; one for a single network).
    Networks(Vec<Network>),
    /// The polynomial baseline.
    Polynomial(Polynomial),
}

/// A surrogate ready to predict.
#[derive(Debug, Clone, PartialEq)]
pub struct Surrogate {
    /// Metadata.
    pub info: ModelInfo,
    /// The predictor.
    pub predictor: Predictor,
    /// Dimensions in network order.
    pub(super) dims: Vec<Dimension>,
}

/// Bias voltages mapped once to the network's coordinates (reuse them for every curve).
#[derive(Debug, Clone, PartialEq)]
pub struct Voltages {
    /// U_B (V).
    pub volts: Vec<f64>,
    pub(super) z: Vec<f64>,
}

impl Surrogate {
    /// Assembles a surrogate (checks that the space has one bias dimension).
    pub fn new(info: ModelInfo, predictor: Predictor) -> Result<Self> {
        let order = network_order(&info.space)?;
        let dims = order
            .iter()
            .map(|&j| info.space.dimensions[j].clone())
            .collect();
        Ok(Surrogate {
            info,
            predictor,
            dims,
        })
    }

    /// Parameter names (network order, without the bias).
    pub fn parameter_names(&self) -> Vec<&str> {
        self.dims[..self.n_params()]
            .iter()
            .map(|d| d.name.as_str())
            .collect()
    }

    /// Number of model parameters.
    pub fn n_params(&self) -> usize {
        self.dims.len() - 1
    }

    /// [lo, hi] of parameter k (network order); k = n_params is the bias.
    pub fn range(&self, k: usize) -> [f64; 2] {
        self.dims[k].range
    }

    /// The relative uncertainty sigma_p recorded with the model.
    pub fn sigma_p(&self) -> f64 {
        self.info.sigma_p
    }

    /// Ensemble members (1 for a single network or the polynomial).
    pub fn members(&self) -> usize {
        match &self.predictor {
            Predictor::Networks(n) => n.len(),
            Predictor::Polynomial(_) => 1,
        }
    }

    fn outside(&self, k: usize, value: f64) -> Error {
        let d = &self.dims[k];
        Error::OutsideDomain {
            name: d.name.clone(),
            value,
            lo: d.range[0],
            hi: d.range[1],
        }
    }

    /// The domain guard: every parameter inside the training space's range (and finite).
    pub fn check_params(&self, params: &[f64]) -> Result<()> {
        if params.len() != self.n_params() {
            return Err(Error::Argument {
                name: "params".into(),
                message: format!(
                    "{} values given, the model takes {} ({})",
                    params.len(),
                    self.n_params(),
                    self.parameter_names().join(", ")
                ),
            });
        }
        for (k, &x) in params.iter().enumerate() {
            let [lo, hi] = self.dims[k].range;
            if !(x >= lo && x <= hi) {
                return Err(self.outside(k, x));
            }
        }
        Ok(())
    }

    /// The support of every input (network order): the model file's record, or for a file
    /// without one the estimate from its training-row count ([`Coverage::estimate`]).
    pub fn coverage(&self) -> Vec<Coverage> {
        match &self.info.coverage {
            Some(c) if c.len() == self.dims.len() => c.clone(),
            _ => self
                .dims
                .iter()
                .map(|d| Coverage::estimate(&d.name, self.info.training.n))
                .collect(),
        }
    }

    /// Whether the record of the support is the model file's own (else estimated).
    pub fn coverage_recorded(&self) -> bool {
        self.info
            .coverage
            .as_ref()
            .is_some_and(|c| c.len() == self.dims.len())
    }

    /// The supported physical range [lo, hi] of input k (network order; k = n_params is the
    /// bias).
    pub fn support(&self, k: usize) -> [f64; 2] {
        let c = &self.coverage()[k];
        let d = &self.dims[k];
        let a = dimension_from_unit(d, c.u_support[0]);
        let b = dimension_from_unit(d, c.u_support[1]);
        [a.min(b), a.max(b)]
    }

    /// The support guard (issue 24): every parameter and voltage inside the range its training
    /// rows support ([`Self::support`]); [`Error::OutsideSupport`] names the first one outside.
    /// Values outside the training range itself are the domain guard's ([`Self::check_params`],
    /// [`Self::voltages`]).
    pub fn check_support(&self, params: &[f64], volts: &[f64]) -> Result<()> {
        let cov = self.coverage();
        let b = self.n_params();
        let values = params
            .iter()
            .enumerate()
            .take(b)
            .map(|(k, &x)| (k, x))
            .chain(volts.iter().map(|&v| (b, v)));
        for (k, x) in values {
            let d = &self.dims[k];
            let u = dimension_to_unit(d, x);
            let [ulo, uhi] = cov[k].u_support;
            if !(u >= ulo - 1e-12 && u <= uhi + 1e-12) {
                let [lo, hi] = self.support(k);
                return Err(Error::OutsideSupport {
                    name: d.name.clone(),
                    value: x,
                    lo,
                    hi,
                    rows: support_rows(cov[k].rows),
                    range_lo: d.range[0],
                    range_hi: d.range[1],
                });
            }
        }
        Ok(())
    }

    /// Maps bias voltages (V) once; each must lie in the training range.
    pub fn voltages(&self, volts: &[f64]) -> Result<Voltages> {
        let b = self.n_params();
        let [lo, hi] = self.dims[b].range;
        let mut z = Vec::with_capacity(volts.len());
        for &v in volts {
            if !(v >= lo && v <= hi) {
                return Err(self.outside(b, v));
            }
            z.push(physical_to_z(&self.dims[b], v).0);
        }
        Ok(Voltages {
            volts: volts.to_vec(),
            z,
        })
    }

    fn to_c(&self, y: f64) -> f64 {
        match self.info.output {
            OutputTransform::Picofarad => y,
            OutputTransform::LogStandardised { mean, sd } => (mean + sd * y).exp(),
        }
    }

    /// dc/dy at c.
    fn dc_dy(&self, c: f64) -> f64 {
        match self.info.output {
            OutputTransform::Picofarad => 1.0,
            OutputTransform::LogStandardised { sd, .. } => c * sd,
        }
    }

    /// c12 (pF) along a curve: the ensemble mean, and the members' standard deviation (zero for
    /// one member). `c` and `spread` have the voltages' length.
    ///
    /// c_p(U_k) = mean_m T(y_m(z(p), z(U_k))), T the output transform.
    pub fn curve_into(
        &self,
        params: &[f64],
        u: &Voltages,
        c: &mut [f64],
        spread: Option<&mut [f64]>,
    ) -> Result<()> {
        self.check_params(params)?;
        let zp: Vec<f64> = params
            .iter()
            .zip(&self.dims)
            .map(|(&x, d)| physical_to_z(d, x).0)
            .collect();
        match &self.predictor {
            Predictor::Networks(nets) => {
                let mut y = vec![0.0; u.z.len()];
                let mut sum2 = vec![0.0; u.z.len()];
                c.fill(0.0);
                for net in nets {
                    net.curve(&zp, &u.z, &mut y);
                    for k in 0..y.len() {
                        let ck = self.to_c(y[k]);
                        c[k] += ck;
                        sum2[k] += ck * ck;
                    }
                }
                let m = nets.len() as f64;
                for ck in c.iter_mut() {
                    *ck /= m;
                }
                if let Some(s) = spread {
                    for k in 0..c.len() {
                        s[k] = (sum2[k] / m - c[k] * c[k]).max(0.0).sqrt();
                    }
                }
            }
            Predictor::Polynomial(p) => {
                let mut z = zp.clone();
                z.push(0.0);
                for (k, &zu) in u.z.iter().enumerate() {
                    z[self.n_params()] = zu;
                    c[k] = self.to_c(p.value(&z));
                }
                if let Some(s) = spread {
                    s.fill(0.0);
                }
            }
        }
        Ok(())
    }

    /// c12 (pF) at parameters `params` (physical units, network order) and voltages (V).
    pub fn curve(&self, params: &[f64], volts: &[f64]) -> Result<Vec<f64>> {
        let u = self.voltages(volts)?;
        let mut c = vec![0.0; volts.len()];
        self.curve_into(params, &u, &mut c, None)?;
        Ok(c)
    }

    /// c12 (pF) and its Jacobian dc_k/dp_j with respect to the physical parameters (row-major,
    /// voltages x n_params): chain rule through the network's exact derivative, the output
    /// transform and dz/dx of the input map.
    pub fn curve_jacobian_into(
        &self,
        params: &[f64],
        u: &Voltages,
        c: &mut [f64],
        jac: &mut [f64],
    ) -> Result<()> {
        self.check_params(params)?;
        let np = self.n_params();
        let (zp, dz): (Vec<f64>, Vec<f64>) = params
            .iter()
            .zip(&self.dims)
            .map(|(&x, d)| physical_to_z(d, x))
            .unzip();
        let nv = u.z.len();
        c.fill(0.0);
        jac.fill(0.0);
        match &self.predictor {
            Predictor::Networks(nets) => {
                let mut y = vec![0.0; nv];
                let mut jy = vec![0.0; nv * np];
                let m = nets.len() as f64;
                for net in nets {
                    net.curve_jacobian(&zp, &u.z, &mut y, &mut jy);
                    for k in 0..nv {
                        let ck = self.to_c(y[k]);
                        c[k] += ck / m;
                        let g = self.dc_dy(ck) / m;
                        for j in 0..np {
                            jac[k * np + j] += g * jy[k * np + j] * dz[j];
                        }
                    }
                }
            }
            Predictor::Polynomial(p) => {
                let mut z = zp.clone();
                z.push(0.0);
                let mut g = vec![0.0; np + 1];
                for k in 0..nv {
                    z[np] = u.z[k];
                    let ck = self.to_c(p.value_gradient(&z, &mut g));
                    c[k] = ck;
                    for j in 0..np {
                        jac[k * np + j] = self.dc_dy(ck) * g[j] * dz[j];
                    }
                }
            }
        }
        Ok(())
    }

    /// Predictions (pF) for every sample of a data set (whose rows are in network order), in
    /// parallel. The data set must have been read with this model's space (`DataSet::read(path,
    /// &model.info.space)` refuses any other).
    pub fn predict_set(&self, set: &DataSet) -> Vec<f64> {
        let np = self.n_params();
        (0..set.len())
            .into_par_iter()
            .map(|i| {
                let z = set.z_row(i);
                match &self.predictor {
                    Predictor::Networks(nets) => {
                        let mut y = [0.0];
                        let mut c = 0.0;
                        for net in nets {
                            net.curve(&z[..np], &z[np..], &mut y);
                            c += self.to_c(y[0]);
                        }
                        c / nets.len() as f64
                    }
                    Predictor::Polynomial(p) => self.to_c(p.value(&z)),
                }
            })
            .collect()
    }
}
