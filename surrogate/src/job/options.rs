//! The options of `generate`, `evaluate` and `predict` as a user states them (those of `train`
//! are the [`super::TrainJob`] itself). The command line flattens these structs (feature
//! `clap`), so every option and default is declared here once.

use std::path::PathBuf;

use hpge_solver::GridOverrides;
use hpge_solver::options::VoltageList;

use crate::generate::Shard;
use crate::sequence::SequenceKind;

/// The shard of a run in one process: all of it ([`Shard::WHOLE`]), as `--shard` writes it.
pub const DEFAULT_SHARD: &str = "0/1";

/// Everything a user chooses about a generation run (training rows from the exact solver at
/// quasi-random points of a parameter space).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct GenerateOptions {
    /// Parameter space (TOML), e.g. spaces/super-siegfried-rz.toml.
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub space: PathBuf,
    /// Detector description (TOML).
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub detector: PathBuf,
    /// Number of samples of the whole run (all shards).
    #[cfg_attr(feature = "clap", arg(long, value_name = "N"))]
    pub n: u64,
    /// Output folder (rows.csv + generate.json); rerun with the same arguments to resume.
    #[cfg_attr(feature = "clap", arg(long, value_name = "DIR"))]
    pub out: PathBuf,
    /// This process's shard K of M (indices offset + i with i mod M = K).
    #[cfg_attr(
        feature = "clap",
        arg(long, value_name = "K/M", value_parser = Shard::parse, default_value = DEFAULT_SHARD)
    )]
    pub shard: Shard,
    /// First sequence index.
    #[cfg_attr(feature = "clap", arg(long, value_name = "O", default_value_t = 0))]
    pub offset: u64,
    /// Worker threads [default: all cores].
    #[cfg_attr(feature = "clap", arg(long, value_name = "T"))]
    pub threads: Option<usize>,
    /// Sequence seed (golden: 0 starts at 0.5 in every dimension).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = 0))]
    pub seed: u64,
    /// Sequence.
    #[cfg_attr(
        feature = "clap",
        arg(long, value_enum, default_value_t = SequenceKind::default())
    )]
    pub sequence: SequenceKind,
    /// Curve mode: K rows per quasi-random parameter point, its biases a shifted stratification
    /// of the bias range solved as one C-V curve (faster per row; --n and --offset count rows
    /// and must be multiples of K). 1: every row its own point.
    #[cfg_attr(feature = "clap", arg(long, value_name = "K", default_value_t = 1))]
    pub curve_points: u64,
    /// On resume, solve again the samples whose rows say the solve failed (e.g. after a solver
    /// fix); the other rows are kept.
    #[cfg_attr(feature = "clap", arg(long))]
    pub retry_failed: bool,
    /// Active learning: the --n indices are candidates, scored by the disagreement of these
    /// surrogates (repeat the flag for a committee; one model alone: its sigma_s), and only the
    /// top --share of them is solved. The models must be of this space and detector.
    #[cfg_attr(feature = "clap", arg(long = "where", value_name = "MODEL"))]
    pub where_models: Vec<PathBuf>,
    /// With --where: the share of the candidates to solve, in (0, 1].
    #[cfg_attr(feature = "clap", arg(long, value_name = "F", default_value_t = 0.1))]
    pub share: f64,
    /// The exact solver's grid and accuracy.
    #[cfg_attr(feature = "clap", command(flatten))]
    pub grid: GridOverrides,
}

/// Everything a user chooses about labelling rows made before the regime columns existed
/// (`hpge-cv label`, [`crate::generate::label`]): the rows, their space and detector, the solver
/// settings they were made with.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct LabelOptions {
    /// The rows to label (a `generate` rows file, or a set such as data/training/heldout.csv).
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub data: PathBuf,
    /// The rows' parameter space (TOML).
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub space: PathBuf,
    /// The rows' detector description (TOML).
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub detector: PathBuf,
    /// Output folder (rows.csv + label.json); rerun with the same arguments to resume.
    #[cfg_attr(feature = "clap", arg(long, value_name = "DIR"))]
    pub out: PathBuf,
    /// Worker threads [default: all cores].
    #[cfg_attr(feature = "clap", arg(long, value_name = "T"))]
    pub threads: Option<usize>,
    /// The exact solver's grid and accuracy (those the rows were made with).
    #[cfg_attr(feature = "clap", command(flatten))]
    pub grid: GridOverrides,
}

/// The command line's names and one-line descriptions of the sequences (the names are
/// [`SequenceKind::as_str`]).
#[cfg(feature = "clap")]
impl clap::ValueEnum for SequenceKind {
    fn value_variants<'a>() -> &'a [Self] {
        &[SequenceKind::Golden, SequenceKind::Sobol]
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(
            clap::builder::PossibleValue::new(self.as_str()).help(match self {
                SequenceKind::Golden => "The golden R_d sequence (the paper's)",
                SequenceKind::Sobol => "Owen-scrambled Sobol (at most 65536 points)",
            }),
        )
    }
}

/// How many of the worst samples `evaluate` lists when not told.
pub const DEFAULT_WORST: usize = 10;

/// Everything a user chooses about a model's evaluation on a data set.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct EvaluateOptions {
    /// The model file.
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub model: PathBuf,
    /// Rows of the model's space (e.g. data/training/heldout.csv).
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub data: PathBuf,
    /// How many of the worst samples to list.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = DEFAULT_WORST))]
    pub worst: usize,
}

/// Everything a user chooses about a prediction along a curve.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct PredictOptions {
    /// The model file.
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub model: PathBuf,
    /// Parameters: NAME=VALUE pairs (comma-separated or repeated) or all values in the model's
    /// order, e.g. --params d_li_mm=2.6,y1_bot=0.5,...
    #[cfg_attr(
        feature = "clap",
        arg(long, value_name = "LIST", required = true, allow_hyphen_values = true)
    )]
    pub params: Vec<String>,
    /// Bias voltages: START:STOP:STEP (inclusive) or a comma list.
    #[cfg_attr(
        feature = "clap",
        arg(
            long,
            value_name = "LIST",
            value_parser = hpge_solver::options::parse_voltages,
            allow_hyphen_values = true
        )
    )]
    pub voltages: VoltageList,
    /// Also give dc12/dp for every parameter (exact derivative of the network).
    #[cfg_attr(feature = "clap", arg(long))]
    pub jacobian: bool,
    /// Predict also where the training rows thin out (fewer than 50 of them lie beyond the value
    /// in its dimension, e.g. below 13.4 V or above 2996.6 V of the shipped models' bias): the
    /// surrogate extrapolates there and can be off by tens of percent (+122% at 10 V). Without it
    /// such points are refused (exit 2); with it they are predicted and a warning is printed.
    #[cfg_attr(feature = "clap", arg(long))]
    pub extrapolate: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_shard_is_the_whole_run() {
        assert_eq!(Shard::parse(DEFAULT_SHARD).unwrap(), Shard::WHOLE);
    }
}
