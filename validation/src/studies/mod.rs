//! Studies that run the solver, the surrogate or the fit many times and summarise the outcome.
//!
//! - [`accuracy`]: c12 on every shipped detector type against a 4x finer reference.
//! - [`coverage`]: simulation-based calibration of the fit (rank uniformity, interval coverage);
//!   [`coverage::store`]: its truths written as they finish (resume, shards).
//! - [`hidden`]: hidden-effect tests of model discovery; [`hidden_summary`]: a study's record
//!   and its summary files.
//! - [`options`]: the options of the coverage and hidden-effect studies as a user states them.
//! - [`stand_in`]: whether a stand-in data set carries the noise its covariance states.

pub mod accuracy;
pub mod coverage;
pub mod hidden;
pub mod hidden_summary;
pub mod options;
pub mod stand_in;
