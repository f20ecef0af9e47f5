//! Posterior summaries: smallest intervals, marginal modes, mixtures over draws (modes), Pareto-k.

mod em;
mod intervals;
mod mixture;
mod pareto;

pub use intervals::{interval_contains, marginal_mode, smallest_intervals};
pub use mixture::{Component, Mixture, find_modes, fit_mixture};
pub use pareto::{Psis, gpd_fit, psis};
