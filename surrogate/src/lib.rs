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
//!
//! # Modules
//!
//! - [`space`]: parameter spaces (TOML), their maps to the unit hypercube and standard normals.
//! - [`sequence`]: quasi-random sequences on [0, 1)^d.
//! - [`generate`]: training-set generation with the exact solver ([`ExactSolver`]), sharded and
//!   resumable, and merging of shards.
//! - [`model`]: data sets, training recipes, candle-nn training, the trained [`Surrogate`] and its
//!   prediction path, model files and accuracy figures.
//! - [`hash`]: the stable hash that fingerprints inputs.
//!
//! The names most users need first are re-exported here; everything else lives at its module
//! path (e.g. [`model::train_resuming`], [`space::Distribution`]).
//!
//! # Example
//!
//! The first points of the golden quasi-random sequence in the shipped parameter space, mapped
//! from the unit hypercube to physical parameters:
//!
//! ```
//! use std::path::Path;
//!
//! use hpge_surrogate::{ParameterSpace, Sequence, SequenceKind};
//!
//! let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../spaces/super-siegfried-rz.toml");
//! let space = ParameterSpace::from_file(&file)?;
//! let sequence = Sequence::new(SequenceKind::Golden, space.dim(), 0);
//! for n in 0..3 {
//!     let p = space.from_unit(&sequence.point(n));
//!     assert_eq!(p.len(), space.dim());
//! }
//! # Ok::<(), hpge_surrogate::Error>(())
//! ```

#![warn(missing_docs)]
mod error;

pub mod generate;
/// The stable hash of inputs (`hpge_foundation::hash`; here for the paths that named it first).
pub mod hash {
    pub use hpge_foundation::hash::fnv1a;
}
pub mod job;
pub mod model;
pub mod sequence;
pub mod space;

pub use error::{Error, Result};
pub use generate::{ExactSolver, Generator, Shard, merge, run};
pub use model::{
    DataSet, Figures, ModelInfo, Predictor, RECIPES, Recipe, Surrogate, network_order, train,
};
pub use sequence::{Sequence, SequenceKind};
pub use space::{Dimension, ParameterSpace, Target, normal_cdf, normal_quantile};
