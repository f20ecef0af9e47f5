//! # hpge-surrogate
//!
//! The machine-learning side of hpge-cv (paper, section 7): parameter spaces and their maps to the
//! unit hypercube and to standard-normal coordinates, quasi-random (golden-sequence) sampling,
//! training-set generation with the exact solver, the network (p_D -> c12) trained with candle-nn,
//! its held-out accuracy, and the prediction path inference uses: [`Surrogate::curve_into`] and
//! [`Surrogate::curve_jacobian_into`] (a whole curve and its Jacobian with respect to the
//! physical parameters, plain f64, no allocation per voltage), guarded by the training domain
//! ([`Error::OutsideDomain`]). This crate depends on `hpge-solver` only (data flows
//! solver <- surrogate <- inference).

mod error;
mod generate;
mod hash;
pub mod job;
mod model;
mod sequence;
mod space;

pub use error::{Error, Result};
pub use generate::{
    ExactSolver, Fingerprint, Generator, MergeReport, RunInfo, RunReport, Sample, Shard,
    format_row, merge, read_rows, run,
};
pub use hash::fnv1a;
pub use model::{
    Architecture, Cycle, DataInfo, DataSet, Dense, DetectorInfo, EpochRecord, FORMAT,
    FORMAT_VERSION, Figures, Loss, Member, ModelInfo, Network, OutputTransform, Polynomial,
    Predictor, RECIPES, Recipe, Surrogate, Trained, U_EDGE, Voltages, candle_outputs, gaussian_fit,
    initial_network, monomials, network_order, output_transform, physical_to_z, quantile, train,
    train_resuming, unit_to_z,
};
pub use sequence::{Sequence, SequenceKind, phi_d};
pub use space::{Dimension, Distribution, ParameterSpace, Target, normal_cdf, normal_quantile};
