//! The steps of `hpge-cv report paper`: each draws one group of
//! the paper's figures with this project's numbers and adds the README rows that set them beside
//! the paper's statements.
//!
//! - [`cv`]: Fig. 12, the C-V curve of the manufacturer's model against the data.
//! - [`depletion`]: Fig. 11, the undepleted volume at biases in steps of 250 V.
//! - [`density`]: Figs. 14 and 15 and the cross-sections (Fig. 9): the parameter transform, the
//!   example density along z and r, the detector with both impurity models.
//! - [`samples`]: Fig. 16, the distributions of the training and test samples.
//! - [`surrogate`]: Figs. 17-19, the learning curves and held-out errors of the surrogate.
//! - [`readme`]: `README.md` and `report.json` of a run.
//! - [`criterion`]: the numeric criteria each verdict is derived from.
//! - [`models`]: the impurity models of section 9 as detectors (the manufacturer's model and the
//!   global modes of fits).
//!
//! - [`sensitivity`]: Fig. 13, the sensitivity scan at 25 V.
//! - [`fits`]: Figs. 20-28, the B_Z and B_RZ fits of the shipped data.
//! - [`section9`]: Fig. 29, the field along r and the n+ pulses at the fits' modes (computed by
//!   [`section9_compute`]).
//!
//! [`run_paper`] runs the steps in order; [`Ctx`] carries a run's state between them;
//! [`PaperOptions`] are the options a user gives it.

pub mod criterion;
pub mod ctx;
pub mod cv;
pub mod density;
pub mod depletion;
pub mod fits;
pub mod models;
mod options;
pub mod readme;
mod run;
pub mod samples;
pub mod section9;
pub mod section9_compute;
pub mod sensitivity;
pub mod surrogate;

pub use criterion::{Cmp, Criterion, Judgement, inconsistent_rows};
pub use ctx::{Ctx, Inputs, Row};
pub use models::{ModeDetectors, NamedModel};
pub use options::{PAPER_OUT, PaperOptions, SECTION9_OUT, Section9Options};
pub use run::{PaperRun, run_paper};
