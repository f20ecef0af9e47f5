//! Posterior summaries: smallest intervals, marginal modes, mixtures over draws (modes), Pareto-k.

mod bounds;
mod component;
mod em;
mod intervals;
mod mixture;
mod pareto;

pub use bounds::{BOUND_SHARE, bound_flags, near_bound};
pub use component::Component;
pub use intervals::{interval_contains, marginal_mode, smallest_intervals};
pub use mixture::{Mixture, find_modes, fit_mixture};
pub use pareto::{PSIS_MIN_DRAWS, Psis, gpd_fit, psis};
