//! Training-set generation with the exact solver: one row per quasi-random sample, resumable,
//! sharded (Slurm job arrays), merged.

mod exact;
mod label;
mod merge;
mod regime;
mod run;
mod select;
mod setup;
#[cfg(test)]
mod tests;

pub use exact::{ExactSolver, SWITCH_RESOLUTION_V};
pub use hpge_foundation::{FolderLock, LOCK_FILE};
pub use label::{LABEL_C12_COLUMN, LabelInfo, LabelReport, SWITCH_COLUMN, SWITCH_WINDOW_V, label};
pub use merge::{MergeReport, merge};
pub use regime::{REGIME_COLUMNS, Regime};
pub use run::{RunInfo, RunReport, format_row, format_row_with, read_rows, run};
pub use select::{SelectionInfo, choose, committee_scores};
pub use setup::{Fingerprint, Generator, Sample, Shard};
