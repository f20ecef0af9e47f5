//! The settings of a coverage study.

use hpge_inference::FitSettings;
use hpge_inference::fit::{ExactCheckSettings, RefineSettings};
use serde::Serialize;

/// Nominal levels of the coverage curve (the 0.683 and 0.955 of the pass test among them).
pub const COVERAGE_LEVELS: [f64; 11] = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.683, 0.8, 0.9, 0.955, 0.99];

/// Where a study's data come from: a closed set, named in `coverage.json` (`data_from`) and in
/// the study's fingerprint by [`DataFrom::as_str`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DataFrom {
    /// Curves of the surrogate itself (checks the sampler and the likelihood).
    Surrogate,
    /// Curves of the exact field solver (`--exact`: checks the whole pipeline).
    Exact,
}

impl DataFrom {
    /// The name: `surrogate` or `exact`.
    pub fn as_str(self) -> &'static str {
        match self {
            DataFrom::Surrogate => "surrogate",
            DataFrom::Exact => "exact",
        }
    }
}

/// Settings of a study.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CoverageSettings {
    /// Number of truths.
    pub n_truths: usize,
    /// Seed of the truths and the noise (fit i uses seed + i).
    pub seed: u64,
    /// The fit (sampling targets lower than a real fit's: ranks need ~L independent draws).
    pub fit: FitSettings,
    /// L: posterior draws each truth is ranked among (evenly thinned).
    pub ranks: usize,
    /// The full pipeline of `fit` (exact check, ascents, refinement) with these settings, the
    /// data model as the exact solver; None: the surrogate fit alone.
    pub pipeline: Option<PipelineSettings>,
}

/// The exact check and refinement of the full pipeline.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PipelineSettings {
    /// The exact check (as `fit`'s defaults: `FitOptions::exact_check`).
    pub check: ExactCheckSettings,
    /// The refinement (as `fit`'s: `FitOptions::refine`).
    pub refine: RefineSettings,
}
