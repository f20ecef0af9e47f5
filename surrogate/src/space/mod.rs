//! Parameter spaces: TOML description, maps to the unit hypercube and to standard-normal
//! coordinates.

mod spec;
#[cfg(test)]
mod tests;

pub use hpge_foundation::{normal_cdf, normal_quantile};
pub use spec::{Dimension, Distribution, ParameterSpace, Target};
