//! # hpge-surrogate
//!
//! The machine-learning side of hpge-cv (paper, section 7): parameter spaces and their maps to the
//! unit hypercube and to standard-normal coordinates, quasi-random (golden-sequence) sampling,
//! training-set generation with the exact solver, the network (p_D -> c12) and its held-out
//! accuracy. Filled in by the training-set and surrogate issues; this crate depends on
//! `hpge-solver` only (data flows solver <- surrogate <- inference).

mod error;
mod generate;
mod sequence;
mod space;

pub use error::{Error, Result};
pub use generate::{
    Fingerprint, Generator, MergeReport, RunInfo, RunReport, Sample, Shard, fnv1a, format_row,
    merge, read_rows, run,
};
pub use sequence::{Sequence, SequenceKind, phi_d};
pub use space::{Dimension, Distribution, ParameterSpace, Target, normal_cdf, normal_quantile};
