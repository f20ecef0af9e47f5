//! Convergence diagnostics of MCMC draws (Vehtari, Gelman, Simpson, Carpenter, Buerkner 2021,
//! "Rank-normalization, folding, and localization: an improved R-hat"): split chains, rank
//! normalisation, folding, the rank-normalised split R-hat, bulk and tail effective sample sizes.

mod ess;
mod rank;
mod rhat;

#[cfg(test)]
mod tests;

pub use ess::{ess, ess_bulk, ess_tail};
pub use rank::{fold, rank_normalise, split_chains};
pub use rhat::{rank_rhat, split_rhat};

use serde::Serialize;

/// The diagnostics of one parameter.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Diagnostics {
    /// max(split R-hat of the rank-normalised draws, of the rank-normalised folded draws).
    pub rhat: f64,
    /// Bulk effective sample size (rank-normalised split chains).
    pub ess_bulk: f64,
    /// Tail effective sample size (min over the 5% and 95% quantile indicators).
    pub ess_tail: f64,
}

impl Diagnostics {
    /// Diagnostics of `chains` (each one chain's draws of one parameter, equal lengths >= 4):
    /// [`rank_rhat`], [`ess_bulk`] and [`ess_tail`], the chains split and rank-normalised once
    /// for all three.
    ///
    /// ```
    /// use hpge_inference::diagnostics::Diagnostics;
    /// // Four well-mixed chains (a Weyl sequence) pass the fit's targets of R-hat <= 1.01 and
    /// // ESS >= 1000; the same chains with one shifted do not.
    /// let mut chains: Vec<Vec<f64>> = (0..4)
    ///     .map(|c| (0..2000).map(|i| ((i * 4 + c) as f64 * 0.618_033_988_75).fract()).collect())
    ///     .collect();
    /// assert!(Diagnostics::of(&chains).converged(1.01, 1000.0));
    /// chains[3].iter_mut().for_each(|x| *x += 0.5);
    /// let d = Diagnostics::of(&chains);
    /// assert!(d.rhat > 1.01 && !d.converged(1.01, 1000.0));
    /// ```
    pub fn of(chains: &[Vec<f64>]) -> Diagnostics {
        let split = split_chains(chains);
        let normalised = rank_normalise(&split);
        Diagnostics {
            rhat: rhat::rank_rhat_of(&split, &normalised),
            ess_bulk: ess(&normalised),
            ess_tail: ess::ess_tail_of(&split),
        }
    }

    /// The smaller of the bulk and tail ESS.
    pub fn ess_min(&self) -> f64 {
        self.ess_bulk.min(self.ess_tail)
    }

    /// The least-mixed figures over parameters: (largest R-hat, smallest bulk or tail ESS);
    /// (0, infinity) for none. NaN entries are passed over (`f64::max`/`f64::min`).
    pub fn worst(all: &[Diagnostics]) -> (f64, f64) {
        all.iter().fold((0.0, f64::INFINITY), |(r, e), d| {
            (r.max(d.rhat), e.min(d.ess_min()))
        })
    }

    /// R-hat <= `rhat_max` and both ESS >= `ess_min`.
    pub fn converged(&self, rhat_max: f64, ess_min: f64) -> bool {
        self.rhat <= rhat_max && self.ess_bulk >= ess_min && self.ess_tail >= ess_min
    }
}
