//! The one error type of the solver crate.

use std::path::PathBuf;

/// Everything that can go wrong in the solver crate.
///
/// Every variant names where the problem is (the file and, where there is one, the key path inside
/// it) so that the command line can print a message a user can act on.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be read.
    #[error("{}: cannot read the file: {source}", file.display())]
    Io {
        /// The file that was asked for.
        file: PathBuf,
        /// The operating system's reason.
        #[source]
        source: std::io::Error,
    },
    /// The TOML text is malformed or does not fit the schema (syntax error, unknown key,
    /// missing key, wrong type). `message` is the parser's message with line and column.
    #[error("{}: {message}", file.display())]
    Parse {
        /// The file being parsed.
        file: PathBuf,
        /// What the parser said, with line, column and key.
        message: String,
    },
    /// A value is well-formed but physically or logically invalid.
    #[error("{}: `{key}`: {message}", file.display())]
    Invalid {
        /// The file the value came from.
        file: PathBuf,
        /// Dotted key path of the offending value, e.g. `contacts[0].geometry.tube.r_mm`.
        key: String,
        /// What is wrong with it.
        message: String,
    },
    /// Two parts of a detector (contacts, passives, the crystal) share space (or touch, where
    /// that is not allowed) in the r-z plane.
    #[error(
        "{}: `{}` ({}) and `{}` ({}) overlap or touch near (r, z) = ({r_mm:.4}, {z_mm:.4}) mm",
        file.display(),
        parts[0].key,
        parts[0].what,
        parts[1].key,
        parts[1].what
    )]
    Overlap {
        /// The detector file.
        file: PathBuf,
        /// The two parts (boxed: keeps the error small).
        parts: Box<[DetectorPart; 2]>,
        /// A point inside both, in mm.
        r_mm: f64,
        /// A point inside both, in mm.
        z_mm: f64,
    },
    /// An iterative field solve did not converge (a caller may treat the point as rejected).
    #[error(
        "the {method} solver did not converge after {iterations} iterations (residual {residual_v:e} V)"
    )]
    NotConverged {
        /// Method name.
        method: &'static str,
        /// Iterations done.
        iterations: usize,
        /// Projected residual at the end, V (NaN if not computed).
        residual_v: f64,
    },
    /// The discrete field problem has no unique solution (e.g. a region with no fixed potential).
    #[error("the field problem is singular: {reason}")]
    Singular {
        /// What went wrong.
        reason: String,
    },
    /// An undepleted region connects two conductors at different potentials (shorted contacts):
    /// conducting material (semiconductor that is not depleted) runs from one to the other.
    #[error(
        "at U_B = {bias_v} V an undepleted region connects {first} and {second} near (r, z) = ({r_mm:.3}, {z_mm:.3}) mm: the crystal does not deplete between them at this bias (the impurity density is too high for this bias there, or a depleted layer is thinner than the grid's min_tick_distance_mm); draw the state with `simulate --field-plot`"
    )]
    UndepletedBridge {
        /// One conductor.
        first: String,
        /// The other.
        second: String,
        /// Bias, V.
        bias_v: f64,
        /// Radius of an undepleted node where the two conductors' regions meet, mm.
        r_mm: f64,
        /// Height of that node, mm.
        z_mm: f64,
    },
    /// The wgpu backend found no usable adapter.
    #[error("no GPU adapter for the wgpu backend ({tried}): {reason}; {hint}")]
    NoGpuAdapter {
        /// The graphics APIs tried and the adapters they offered.
        tried: String,
        /// Why none was usable.
        reason: String,
        /// How to get one (e.g. Mesa's software Vulkan).
        hint: String,
    },
    /// The GPU device failed (shader compilation, out of memory, lost device, read-back).
    #[error("wgpu backend: {message}")]
    Gpu {
        /// What failed, with the adapter's name.
        message: String,
    },
    /// A value given on the command line or through the API (not from a file) is invalid.
    #[error("`{name}`: {message}")]
    Argument {
        /// Name of the argument, e.g. `--param` or `r_mm`.
        name: String,
        /// What is wrong with it.
        message: String,
    },
    /// A grid option (`--grid KEY=VALUE`, `--tolerance`) that the grid settings refuse.
    #[error("{option}: {message}")]
    GridOption {
        /// The option as given, e.g. `--grid` or `--tolerance 0`.
        option: String,
        /// Why the grid settings refuse it.
        message: String,
    },
    /// A value that does not have the expected form (the message says which form).
    #[error("{message}")]
    Syntax {
        /// The text as given.
        text: String,
        /// What was expected, quoting the text.
        message: String,
    },
    /// A solve of the sensitivity scan failed (`scan::sensitivity_scan`); the solver's error is
    /// the source.
    #[error("constant density {zeta_cm3:e} cm^-3 at {voltage_v} V")]
    ScanPointFailed {
        /// The constant net impurity density, cm^-3.
        zeta_cm3: f64,
        /// The bias, V.
        voltage_v: f64,
        /// Why the solve failed.
        #[source]
        source: Box<Error>,
    },
    /// No contact of the detector is held at the bias, so a bias voltage acts on nothing.
    #[error(
        "{}: no contact has potential = \"bias\", so the bias voltage acts on nothing",
        file.display()
    )]
    NoBiasContact {
        /// The detector file.
        file: PathBuf,
    },
    /// An interaction point (the start of a drift) lies inside a contact.
    #[error(
        "(r, z) = ({r_mm}, {z_mm}) mm is inside the contact `{contact}`; an interaction must be in the depleted crystal"
    )]
    InteractionInContact {
        /// Radius of the point, mm.
        r_mm: f64,
        /// Height of the point, mm.
        z_mm: f64,
        /// Name of the contact.
        contact: String,
    },
    /// An interaction point lies in undepleted semiconductor at the bias (no field there).
    #[error(
        "(r, z) = ({r_mm}, {z_mm}) mm is in undepleted volume at U_B = {bias_v} V (no field there); raise --voltage or choose a point in the depleted crystal"
    )]
    InteractionUndepleted {
        /// Radius of the point, mm.
        r_mm: f64,
        /// Height of the point, mm.
        z_mm: f64,
        /// The bias, V.
        bias_v: f64,
    },
    /// An interaction point lies outside the crystal (world medium, a passive, a borehole).
    #[error(
        "(r, z) = ({r_mm}, {z_mm}) mm is outside the crystal `{crystal}` (r in [{r_min_mm}, {r_max_mm}] mm, z in [{z_min_mm}, {z_max_mm}] mm, less any borehole)"
    )]
    InteractionOutside {
        /// Radius of the point, mm.
        r_mm: f64,
        /// Height of the point, mm.
        z_mm: f64,
        /// Name of the semiconductor.
        crystal: String,
        /// The crystal's bounding box: smallest radius, mm.
        r_min_mm: f64,
        /// Largest radius, mm.
        r_max_mm: f64,
        /// Lowest height, mm.
        z_min_mm: f64,
        /// Highest height, mm.
        z_max_mm: f64,
    },
    /// A signal to normalise by ends at (nearly) zero: no net charge reached its contact.
    #[error(
        "the signal of `{contact}` ends at {end_charge:.3e} (no net charge reached it), so it cannot be scaled to end at 1"
    )]
    NoNetCharge {
        /// Name of the contact.
        contact: String,
        /// The signal's end value, units of the pair charge.
        end_charge: f64,
    },
    /// An arithmetic expression (a length in a detector file) or a `NAME=VALUE` assignment does
    /// not evaluate: syntax, unknown parameter, division by zero, non-finite result.
    #[error("{reason}")]
    Expression {
        /// The expression or the assignment as written.
        text: String,
        /// What is wrong (the text the user sees; it quotes the expression where that helps).
        reason: String,
    },
    /// An option of a solver job ([`crate::jobs`]) that the job refuses, named by its library
    /// name (the Python argument's, e.g. `voltage`, `phi_deg`); a face spells it its own way with
    /// [`Error::respell`] (the command line: `--voltage`, `--phi`).
    #[error("{option}{}: {message}", value.as_ref().map_or(String::new(), |v| format!(" {v}")))]
    JobOption {
        /// The option's name.
        option: String,
        /// The value as given, where there is one to quote.
        value: Option<String>,
        /// What is wrong with it.
        message: String,
    },
    /// A value built in code or given through the API is invalid (settings, model parameters,
    /// spline knots, grid ticks) where no file is involved; callers that know the file or the
    /// command-line flag put it in front of the message.
    #[error("{message}")]
    InvalidValue {
        /// What kind of value, e.g. `grid settings` or `ADL parameters`.
        what: &'static str,
        /// What is wrong, naming the field.
        message: String,
    },
}

/// One part of a detector named in an [`Error::Overlap`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DetectorPart {
    /// The key path of its geometry, e.g. `contacts[0].geometry` or `semiconductor.geometry`.
    pub key: String,
    /// What it is, in words, e.g. `contact 1 (n+)`, `passive can`, `the semiconductor`.
    pub what: String,
}

impl DetectorPart {
    /// A part from its key path and description.
    pub fn new(key: impl Into<String>, what: impl Into<String>) -> Self {
        Self {
            key: key.into(),
            what: what.into(),
        }
    }
}

/// Result alias of the solver crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// The error with a job option's name spelt by a face: `spell` maps the library name of an
    /// [`Error::JobOption`] (e.g. `voltage`) to the face's (e.g. `--voltage`); other errors are
    /// returned unchanged.
    pub fn respell(self, spell: impl Fn(&str) -> String) -> Self {
        match self {
            Error::JobOption {
                option,
                value,
                message,
            } => Error::JobOption {
                option: spell(&option),
                value,
                message,
            },
            e => e,
        }
    }

    /// Whether a sampler may treat this error as a rejected proposal (zero posterior density):
    /// a solve at one point that failed (not converged, singular, an undepleted bridge between
    /// contacts). Bad files, settings, arguments and GPU failures are not: they end a run.
    pub fn is_recoverable(&self) -> bool {
        match self {
            Error::NotConverged { .. }
            | Error::Singular { .. }
            | Error::UndepletedBridge { .. } => true,
            Error::Io { .. }
            | Error::Parse { .. }
            | Error::Invalid { .. }
            | Error::Overlap { .. }
            | Error::NoGpuAdapter { .. }
            | Error::Gpu { .. }
            | Error::Argument { .. }
            | Error::GridOption { .. }
            | Error::Syntax { .. }
            | Error::NoBiasContact { .. }
            | Error::InteractionInContact { .. }
            | Error::InteractionUndepleted { .. }
            | Error::InteractionOutside { .. }
            | Error::NoNetCharge { .. }
            | Error::Expression { .. }
            | Error::InvalidValue { .. }
            | Error::JobOption { .. } => false,
            Error::ScanPointFailed { source, .. } => source.is_recoverable(),
        }
    }

    /// Shorthand for [`Error::Invalid`].
    pub fn invalid(
        file: impl Into<PathBuf>,
        key: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Error::Invalid {
            file: file.into(),
            key: key.into(),
            message: message.into(),
        }
    }

    /// Shorthand for [`Error::InvalidValue`].
    pub fn invalid_value(what: &'static str, message: impl Into<String>) -> Self {
        Error::InvalidValue {
            what,
            message: message.into(),
        }
    }

    /// Shorthand for [`Error::Parse`] from a TOML deserialisation error.
    pub fn parse(file: impl Into<PathBuf>, err: &toml::de::Error) -> Self {
        Error::Parse {
            file: file.into(),
            message: err.to_string().trim_end().to_string(),
        }
    }
}
