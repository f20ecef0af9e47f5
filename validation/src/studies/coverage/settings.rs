//! The settings of a coverage study.

use hpge_inference::FitSettings;
use hpge_inference::fit::{ExactCheckSettings, RefineSettings};
use serde::Serialize;

/// Nominal levels of the coverage curve (the 0.683 and 0.955 of the pass test among them).
pub const COVERAGE_LEVELS: [f64; 11] = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.683, 0.8, 0.9, 0.955, 0.99];

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
