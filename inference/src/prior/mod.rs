//! Priors in TOML (`priors/*.toml`): per fit parameter a distribution (uniform, normal, truncated
//! normal) and the model inputs it sets (several inputs = tied parameters, e.g. B_Z's one y for
//! the four knots of a face); inputs no parameter sets are fixed. Bound to a model, a prior knows
//! each parameter's support and maps it to an unconstrained coordinate for the samplers.

mod bound;
mod distribution;
mod spec;

pub use bound::{Prior, PriorParameter};
pub use distribution::PriorDistribution;
pub use spec::{ParameterSpec, PriorSpec};

#[cfg(test)]
mod tests;
