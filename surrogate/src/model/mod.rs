//! The surrogate of c12(p, U_B) (paper, section 7): data sets, recipes, candle-nn training, the
//! plain f64 prediction path with its Jacobian, model files and accuracy figures.

mod coverage;
mod dataset;
mod error_model;
mod file;
mod gelu;
mod metrics;
mod network;
mod polynomial;
mod predict;
mod recipe;
mod steps;
mod surrogate;
mod train;
mod transform;
mod uncertainty;

#[cfg(test)]
mod error_tests;
#[cfg(test)]
mod tests;

pub use coverage::{Coverage, SUPPORT_ROWS, support_rows};
pub use dataset::{DataInfo, DataSet, network_order};
pub use error_model::{
    ErrorModel, RIDGE_PER_ROW, SIGMA_MAX, SIGMA_MIN, TARGET_COVERAGE_2SIGMA, coverage_of,
};
pub use metrics::{Figures, gaussian_fit, quantile};
pub use network::{Dense, Network};
pub use polynomial::{Polynomial, monomials};
pub use predict::Prediction;
pub use recipe::{Architecture, Cycle, Loss, OutputTransform, RECIPES, Recipe, STEPS};
pub use steps::{BiasMap, StepsHead};
pub use surrogate::{
    DetectorInfo, FORMAT, FORMAT_VERSION, ModelInfo, Predictor, Surrogate, Voltages,
};
pub use train::{
    EpochRecord, Member, Trained, candle_outputs, initial_network, output_transform, train,
    train_resuming,
};
pub use transform::{U_EDGE, dimension_from_unit, dimension_to_unit, physical_to_z, unit_to_z};
