//! The steps of `hpge-cv report paper` that need no command-line code: each draws one group of
//! the paper's figures with this project's numbers and adds the README rows that set them beside
//! the paper's statements.
//!
//! - [`cv`]: Fig. 12, the C-V curve of the manufacturer's model against the data.
//! - [`density`]: Figs. 14 and 15 and the cross-sections (Fig. 9): the parameter transform, the
//!   example density along z and r, the detector with both impurity models.
//! - [`samples`]: Fig. 16, the distributions of the training and test samples.
//! - [`surrogate`]: Figs. 17-19, the learning curves and held-out errors of the surrogate.
//! - [`readme`]: `README.md` and `report.json` of a run.
//! - [`models`]: the impurity models of section 9 as detectors (the manufacturer's model and the
//!   global modes of fits).
//!
//! [`Ctx`] carries a run's state between the steps; the command line owns the order of the steps
//! (and the ones that run fits).

pub mod ctx;
pub mod cv;
pub mod density;
pub mod models;
pub mod readme;
pub mod samples;
pub mod surrogate;

pub use ctx::{Ctx, Inputs, Row, verdict};
pub use models::{ModeDetectors, NamedModel};
