//! # hpge-inference
//!
//! The statistics side of hpge-cv (paper, sections 4 and 8): priors, the likelihood with
//! parameter-dependent uncertainties, samplers and their diagnostics, posterior summaries and
//! predictive checks, and the model-discovery workflow. It sees a model only through one narrow trait ([`CvModel`]),
//! implemented by both the exact solver and the surrogate, and the measured curve only as a
//! [`CvData`] (from the measurement crate, hpge-measurement).
//!
//! The root names what a fit or a discovery run needs; everything else lives in its module:
//! [`model`] (the trait and its two implementations), [`prior`], [`posterior`] (likelihood and
//! posterior), [`sampler`] (adaptive Metropolis and NUTS), [`diagnostics`] (R-hat, ESS),
//! [`summary`] (intervals, modes, Pareto-smoothed importance sampling), [`mod@fit`] (a whole fit,
//! its predictive and the exact-solver check), [`mod@discover`] (model discovery) and [`numerics`]
//! (the small dense linear algebra and optimiser they share); [`depletion`] fits an impurity
//! scale factor to a measured depletion voltage (`hpge-cv depletion`).
//!
//! A model error at one point (a failed solve, a point outside the model's domain;
//! [`Error::is_recoverable`]) is a rejected proposal of zero posterior density; any other error
//! ends the run.
//!
//! ```
//! use std::path::Path;
//!
//! use hpge_inference::{
//!     CvData, CvModel, Likelihood, NoiseSettings, Posterior, Prior, PriorSpec, Result,
//! };
//!
//! /// c12 = 100 pF / (1 + a U / 100 V), a stand-in for a detector model.
//! struct Toy(Vec<f64>);
//!
//! impl CvModel for Toy {
//!     fn inputs(&self) -> Vec<String> {
//!         vec!["a".into()]
//!     }
//!     fn domain(&self) -> Vec<[f64; 2]> {
//!         vec![[0.0, 2.0]]
//!     }
//!     fn voltages(&self) -> &[f64] {
//!         &self.0
//!     }
//!     fn sigma_rel(&self) -> f64 {
//!         0.0
//!     }
//!     fn curve(&self, x: &[f64], c_pf: &mut [f64]) -> Result<()> {
//!         for (c, u) in c_pf.iter_mut().zip(&self.0) {
//!             *c = 100.0 / (1.0 + x[0] * u / 100.0);
//!         }
//!         Ok(())
//!     }
//!     fn has_jacobian(&self) -> bool {
//!         false
//!     }
//!     fn curve_jacobian(&self, x: &[f64], c_pf: &mut [f64], _jac: &mut [f64]) -> Result<()> {
//!         self.curve(x, c_pf)
//!     }
//!     fn describe(&self) -> String {
//!         "toy".into()
//!     }
//! }
//!
//! # fn main() -> Result<()> {
//! let model = Toy(vec![50.0, 100.0, 200.0]);
//! let spec = PriorSpec::from_toml_str(
//!     "name = \"toy\"\n[[parameters]]\nname = \"a\"\n\
//!      prior = { distribution = \"uniform\", lo = 0.0, hi = 2.0 }\n",
//!     Path::new("toy.toml"),
//! )?;
//! let prior = Prior::bind(&spec, &model.inputs(), &model.domain())?;
//! let mut c12_pf = vec![0.0; 3];
//! model.curve(&[1.0], &mut c12_pf)?;
//! let data = CvData {
//!     voltage_v: model.voltages().to_vec(),
//!     sigma_pf: vec![1.0; 3],
//!     c12_pf,
//!     covariance_pf2: None,
//!     source: "toy.csv".into(),
//! };
//! let likelihood = Likelihood::new(&data, NoiseSettings::default(), model.sigma_rel())?;
//! let posterior = Posterior::new(&model, &prior, &likelihood)?;
//! // The data were made at a = 1: the posterior is higher there than at a = 1.5.
//! let at_truth = posterior.evaluate(&[1.0])?;
//! assert!(at_truth.ln_posterior > posterior.evaluate(&[1.5])?.ln_posterior);
//! # Ok(())
//! # }
//! ```

#![warn(missing_docs)]
pub mod depletion;
pub mod diagnostics;
pub mod discover;
mod error;
pub mod fit;
pub mod model;
pub mod numerics;
pub mod posterior;
pub mod prior;
pub mod refine;
mod rejection;
pub mod sampler;
pub mod summary;

pub use discover::{DiscoverInputs, DiscoverSettings, Discovery, Progress, discover};
pub use error::{Error, Result};
pub use fit::{
    ExactCheckSettings, ExactGrids, Fit, FitFiles, FitJob, FitOptions, FitSettings, exact_check,
    fit,
};
pub use hpge_measurement::CvData;
pub use model::{CvModel, ExactModel, SurrogateModel};
pub use posterior::{Likelihood, NoiseSettings, Posterior};
pub use prior::{Prior, PriorSpec};
pub use sampler::{SampleSettings, SamplerKind, Status};
