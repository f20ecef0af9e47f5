//! The measurement's jobs: one library call per command (`measure`, `synthesize`) with the
//! files it writes, so that the command line and the Python module write the same files
//! (issue 62, item 1). Figures stay with the faces (`hpge-reports` draws them).

mod measure;
mod synthesize;

pub use measure::{FailedFits, MeasureReport, MeasureRun, PointReport, ProblemReport, measure_raw};
pub use synthesize::{SynthRun, check_synthesis_folder, synthesize_folder};
