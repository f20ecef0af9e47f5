//! Samplers: an adaptive Metropolis like BAT.jl's (several chains from dispersed starts, tuning
//! cycles to an acceptance in [0.15, 0.35], burn-in until the chains agree) and NUTS (nuts-rs,
//! with the surrogate's gradient). Both draw the unconstrained z of a [`LogDensity`] and stop
//! when rank-normalised split R-hat and bulk and tail ESS reach their targets, or at a budget.
//!
//! A model evaluation that fails recoverably (a failed solve, a point outside the model's
//! domain) is a rejected proposal; any other error ends the run and [`sample`] returns it.

mod engine;
mod metropolis;
mod modes;
mod nuts;
mod run;
mod samples;
mod settings;
mod start;
mod status;
mod target;

pub use run::sample;
pub use samples::{ChainDraws, LocalMode, SamplerStop, Samples};
pub use settings::{
    DEFAULT_CHAINS, DEFAULT_ESS_MIN, DEFAULT_MAX_SECONDS, DEFAULT_MODE_STARTS, DEFAULT_RHAT_MAX,
    DEFAULT_SEED, MIN_DRAWS_AT_BUDGET, SampleSettings, SamplerKind,
};
pub use status::{Phase, Status};
pub use target::{GaussianTarget, LogDensity};

#[cfg(test)]
mod tests;
