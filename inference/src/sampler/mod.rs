//! Samplers: an adaptive Metropolis like BAT.jl's (several chains from dispersed starts, tuning
//! cycles to an acceptance in [0.15, 0.35], burn-in until the chains agree) and NUTS (nuts-rs,
//! with the surrogate's gradient). Both draw the unconstrained z of a [`LogDensity`] and stop
//! when rank-normalised split R-hat and bulk and tail ESS reach their targets, or at a budget.

mod metropolis;
mod modes;
mod nuts;
mod run;
mod target;

pub use run::{
    ChainDraws, LocalMode, Phase, SampleSettings, SamplerKind, Samples, Status, StopReason, sample,
};
pub use target::{GaussianTarget, LogDensity};

#[cfg(test)]
mod tests;
