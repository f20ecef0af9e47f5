//! What every solve reports.

use serde::{Deserialize, Serialize};

/// Method for the potential with depletion (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Primal-dual active set (semismooth Newton) with sparse Cholesky solves: the exact
    /// discrete solution in a few refactorisations.
    #[default]
    Fast,
    /// Red-black projected successive over-relaxation (the class of SolidStateDetectors.jl and
    /// fieldgen).
    Sor,
}

impl Method {
    /// Name as on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            Method::Fast => "fast",
            Method::Sor => "sor",
        }
    }
}

/// Where a solve runs (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Backend {
    /// The host's cores (faer and rayon).
    #[default]
    Cpu,
    /// A GPU (or a software rasteriser) through wgpu compute shaders: the SOR method only.
    Wgpu,
}

impl Backend {
    /// Name as on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            Backend::Cpu => "cpu",
            Backend::Wgpu => "wgpu",
        }
    }
}

/// Why an iterative solve stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Termination {
    /// The active (undepleted) set did not change between two iterations: the discrete
    /// complementarity problem is solved exactly (up to round-off).
    ActiveSetStationary,
    /// The largest update fell below the tolerance.
    ToleranceReached,
    /// A linear problem without constraints, solved directly.
    Direct,
    /// The pocket rounds cycled (a hole and an electron pocket pouring into each other at a p-n
    /// junction inside the crystal): the round of the cycle with the shallowest remaining
    /// depression is the answer, its depth in `residual_v`.
    PocketCycle,
    /// The pocket rounds reached `MAX_POCKET_ROUNDS` without repeating (the floods of a large
    /// pocket wandering between nearly equal sets of ties): the round with the shallowest
    /// remaining depression is the answer, as for a cycle, its depth in `residual_v`.
    PocketRoundLimit,
}

/// Report of one solve.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SolveReport {
    /// Method used.
    pub method: Method,
    /// Where it ran.
    #[serde(default)]
    pub backend: Backend,
    /// Iterations (active-set steps or SOR sweeps).
    pub iterations: usize,
    /// Largest projected residual at the end, in V: max_n |phi_n - clamp(phi_n - g_n / A_nn)|,
    /// g the gradient of the discrete energy.
    pub residual_v: f64,
    /// Why it stopped.
    pub termination: Termination,
    /// Pocket rounds (a solve with fixed ties, then a new flood; `field::pockets`): 1 where no
    /// pocket formed. A work counter of the `fast` method; 0 in reports written before it.
    #[serde(default)]
    pub pocket_rounds: usize,
    /// Pocket rounds whose active sets cycled, so that the round held every pocket level at
    /// the previous round's pour-point value (`field::active_set::round`): a work counter of the `fast`
    /// method, 0 almost always.
    #[serde(default)]
    pub fixed_level_rounds: usize,
    /// Numeric sparse Cholesky factorisations (`fast`): at most `iterations`, fewer where a
    /// pocket round starts from the active set the previous one ended on. 0 for `sor`.
    #[serde(default)]
    pub factorisations: usize,
    /// Wall time in seconds.
    pub seconds: f64,
}
