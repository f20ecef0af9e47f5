//! The one error type of the surrogate crate.

use std::path::PathBuf;

/// Errors of the surrogate crate (each names the file and key at fault where there is one).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A solver-side failure (bad detector, failed solve) while building a data set.
    #[error(transparent)]
    Solver(#[from] hpge_solver::Error),
    /// A lock, shard or file error of the foundation's utilities (`hpge_foundation`).
    #[error(transparent)]
    Foundation(#[from] hpge_foundation::Error),
    /// A file could not be read or written.
    #[error("{}: {action}: {source}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// What was attempted.
        action: &'static str,
        /// The operating system's reason.
        #[source]
        source: std::io::Error,
    },
    /// A file does not parse or fit its schema.
    #[error("{}: {message}", file.display())]
    Parse {
        /// The file.
        file: PathBuf,
        /// The parser's message with line, column and key.
        message: String,
    },
    /// A well-formed value that is invalid.
    #[error("{}: `{key}`: {message}", file.display())]
    Invalid {
        /// The file.
        file: PathBuf,
        /// Key path, e.g. `dimensions[3].range`.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// A prediction was asked outside the model's training space (the domain guard; inference
    /// gives such points zero prior mass).
    #[error("`{name}` = {value} is outside the surrogate's training range [{lo}, {hi}]")]
    OutsideDomain {
        /// Dimension name.
        name: String,
        /// The value asked for.
        value: f64,
        /// Lower end of the range.
        lo: f64,
        /// Upper end of the range.
        hi: f64,
    },
    /// A prediction was asked inside the training space but where the training rows thin out
    /// (fewer than `rows` of them lie further out in this dimension): the surrogate extrapolates
    /// there and can be far off (issue 24). `predict --extrapolate` allows it.
    #[error(
        "`{name}` = {value} is outside the range the surrogate's training rows support, \
         [{lo}, {hi}] (fewer than {rows} training rows lie beyond it, so the surrogate \
         extrapolates there and can be far off; the training range is [{range_lo}, {range_hi}])"
    )]
    OutsideSupport {
        /// Dimension name.
        name: String,
        /// The value asked for.
        value: f64,
        /// Lower end of the supported range.
        lo: f64,
        /// Upper end of the supported range.
        hi: f64,
        /// The number of training rows that must lie beyond a supported value.
        rows: usize,
        /// Lower end of the training space's range.
        range_lo: f64,
        /// Upper end of the training space's range.
        range_hi: f64,
    },
    /// Training failed (a non-finite loss, a singular fit, a candle error).
    #[error("training failed: {message}")]
    Training {
        /// What happened.
        message: String,
    },
    /// A value given through the API or the command line is invalid.
    #[error("`{name}`: {message}")]
    Argument {
        /// Name of the argument.
        name: String,
        /// What is wrong.
        message: String,
    },
    /// A file of a training run (learning curves, checkpoints) could not be read, written or
    /// removed. The text names the action and the file; the operating system's reason is the
    /// error's source (error-chain printers add it after a colon).
    #[error("{action} {}", file.display())]
    RunFile {
        /// What was attempted, e.g. `cannot write the learning curves`.
        action: &'static str,
        /// The file or folder.
        file: PathBuf,
        /// The operating system's reason.
        #[source]
        source: std::io::Error,
    },
    /// The path a model file is to be written to is unusable (not `.safetensors`, its folder
    /// missing).
    #[error("{}: {message}", file.display())]
    ModelPath {
        /// The model file asked for.
        file: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A checkpoint of an interrupted training run (`NAME.partial/member-M.safetensors`) that this
    /// run cannot take (another recipe, seed or data; not a network).
    #[error("{}: {message}", file.display())]
    Checkpoint {
        /// The checkpoint file.
        file: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A data set that does not fit the model it is evaluated with (the model's space named).
    #[error("{error}\n(the model {} was trained on space `{space}`)", model.display())]
    DataForModel {
        /// Why the data set was refused.
        error: Box<Error>,
        /// The model file.
        model: PathBuf,
        /// Name of the model's parameter space.
        space: String,
    },
    /// A parameter list (NAME=VALUE pairs, or bare values in the model's order) that does not
    /// fit the model's inputs.
    #[error("{message}")]
    Parameters {
        /// What is wrong (names the item and the model's parameters).
        message: String,
    },
}

/// Result alias of the surrogate crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// Whether a sampler may treat this error as a rejected proposal (zero posterior density):
    /// a point outside the model's domain, or a failed solve of the exact solver. Bad files,
    /// arguments and training failures are not.
    pub fn is_recoverable(&self) -> bool {
        match self {
            Error::Solver(e) => e.is_recoverable(),
            Error::Foundation(e) => e.is_recoverable(),
            Error::OutsideDomain { .. } => true,
            Error::OutsideSupport { .. } => false,
            Error::Io { .. }
            | Error::Parse { .. }
            | Error::Invalid { .. }
            | Error::Training { .. }
            | Error::Argument { .. }
            | Error::RunFile { .. }
            | Error::ModelPath { .. }
            | Error::Checkpoint { .. }
            | Error::DataForModel { .. }
            | Error::Parameters { .. } => false,
        }
    }
}
