//! Training-set generation with the exact solver: one row per quasi-random sample, resumable,
//! sharded (Slurm job arrays), merged.

mod exact;
mod lock;
mod merge;
mod run;
mod setup;
#[cfg(test)]
mod tests;

pub use exact::ExactSolver;
pub use lock::{FolderLock, LOCK_FILE};
pub use merge::{MergeReport, merge};
pub use run::{RunInfo, RunReport, format_row, read_rows, run};
pub use setup::{Fingerprint, Generator, Sample, Shard};
