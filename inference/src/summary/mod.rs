//! Posterior summaries: smallest intervals, marginal modes, mixtures over draws (modes), Pareto-k.

mod intervals;
mod mixture;
mod pareto;

#[allow(unused_imports)]
pub use intervals::{interval_contains, marginal_mode, smallest_intervals};
#[allow(unused_imports)]
pub use mixture::{Component, Mixture, find_modes, fit_mixture};
#[allow(unused_imports)]
pub use pareto::{Psis, gpd_fit, psis};
