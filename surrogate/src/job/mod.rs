//! The surrogate's application layer, as the `train`, `evaluate` and `predict` commands use it
//! (and tests and other programs can, without the command line): a training run with its
//! resumable checkpoints and learning curves ([`TrainJob`]), a model's accuracy on a data set
//! ([`Evaluation`]), its calibrated per-point uncertainty ([`CalibrateOptions`]) and parameter lists as a user writes them ([`parse_params`]); the commands'
//! options are declared here once ([`GenerateOptions`], [`TrainJob`], [`EvaluateOptions`],
//! [`PredictOptions`]).

mod bands;
mod calibrate;
mod checkpoint;
mod evaluate;
mod options;
mod params;
mod regimes;
mod train;

#[cfg(test)]
mod tests;

pub use bands::{BIAS_BAND_EDGES_U, BiasBand, bias_bands};
pub use calibrate::CalibrateOptions;
pub use checkpoint::{curves_path, partial_dir, resume_members, save_member, write_curves};
pub use evaluate::{
    EDGE_FRACTION, EdgeFigures, EdgeStats, Evaluation, EvaluationJson, Worst, edge_figures,
    read_for_model,
};
pub use options::{
    DEFAULT_SHARD, DEFAULT_WORST, EvaluateOptions, GenerateOptions, LabelOptions, PredictOptions,
};
pub use params::parse_params;
pub use regimes::{RegimeGroup, TRANSITION_V, regime_groups};
pub use train::{
    DEFAULT_EPOCHS_SCALE, DEFAULT_RECIPE, DEFAULT_SEED, DEFAULT_SPACE, POLYNOMIAL_RECIPE,
    TrainEvent, TrainJob, TrainOutcome, detector_info,
};
