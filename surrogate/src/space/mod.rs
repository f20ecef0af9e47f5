//! Parameter spaces: TOML description, maps to the unit hypercube and to standard-normal
//! coordinates.

mod normal;
mod spec;
#[cfg(test)]
mod tests;

pub use normal::{normal_cdf, normal_quantile};
pub use spec::{Dimension, Distribution, ParameterSpace, Target};
