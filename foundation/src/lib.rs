//! Small utilities that every hpge-cv library uses and that belong to none of them (issue 62):
//! the standard normal distribution, the chi-squared upper tail (goodness of fit) and quantiles
//! of a sample (priors, diagnostics, held-out
//! figures), a stable hash that names inputs in fingerprints and model files, strided shards of
//! an index range (Slurm array tasks of `generate`, the coverage studies, `depletion`), and the
//! one-writer lock of an output folder, the record of what made a results file ([`Made`]) and
//! the JSON sidecar of a CSV ([`sidecar`]).
//!
//! ```
//! use hpge_foundation::{Shard, fnv1a, normal_cdf, normal_quantile, quantile};
//! assert!((normal_cdf(normal_quantile(0.975)) - 0.975).abs() < 1e-15);
//! assert_eq!(quantile(&[1.0, 2.0, 3.0], 0.5), 2.0);
//! assert_eq!(fnv1a(b""), 0xcbf2_9ce4_8422_2325);
//! let shard = Shard::parse("0/2")?;
//! assert_eq!(shard.indices(10, 4).collect::<Vec<_>>(), [10, 12]);
//! # Ok::<(), hpge_foundation::Error>(())
//! ```

#![warn(missing_docs)]

mod chi_squared;
mod error;
pub mod hash;
mod lock;
mod made;
mod normal;
mod quantile;
mod shard;
pub mod sidecar;

pub use chi_squared::chi_squared_sf;
pub use error::{Error, Result};
pub use hash::fnv1a;
pub use lock::{FolderLock, LOCK_FILE};
pub use made::{MADE_KEY, Made, civil_from_days, today_utc};
pub use normal::{normal_cdf, normal_quantile};
pub use quantile::quantile;
pub use shard::Shard;
