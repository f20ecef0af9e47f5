//! How a fit refines ([`RefineSettings`]): the round limit, the error model's hyperparameter
//! search and where a refined round's point variance comes from ([`RefineVariance`]).

use crate::Result;

/// Rounds of refinement at most (the first, with the plain surrogate, included): each costs a
/// sampling run and one exact check (for the shipped B_RZ fit on two cores about 25 s and 90 s
/// in the first round, 10 s and 55 s in the narrower later ones). The shipped B_RZ fit passes
/// in its second round (reports/inference.md, "Posterior-adaptive refinement"); five leave
/// three rounds of margin, at about 20 min for the B_Z fit, which does not pass in five with
/// the shipped network.
pub const DEFAULT_REFINE_ROUNDS: usize = 5;

/// Nelder-Mead evaluations for the error model's hyperparameters per round.
pub const DEFAULT_HYPER_EVALS: usize = 600;

/// Where a refined round's likelihood takes the corrected surrogate's point variance from
/// (sigma_p,k^2 in the paper's eq. 13, one per voltage).
///
/// With the error model's variance at each input ([`RefineVariance::Local`]) the likelihood is
/// wider wherever the exact curves have not taught the correction, and a model that cannot
/// describe the data pays less for its misfit there: the B_Z fit of the shipped curve (chi^2
/// about 295 for 57 degrees of freedom at the exact optimum) ran to d_Li = 0.2-0.9 mm in
/// rounds 1-4, where the variance at 25 V was 100 pF and its 387 pF misfit cheap, and never
/// passed. With the variance of the best exact curve so far at every input
/// ([`RefineVariance::Best`]) no region buys a smaller misfit penalty with its uncertainty; the
/// mean correction still varies with the input, and each round's check and ascents put exact
/// curves wherever the posterior goes (reports/inference.md, "The refined likelihood's
/// variance").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RefineVariance {
    /// The error model's variance at the exact curve of highest exact likelihood so far, the
    /// same at every input (the default).
    #[default]
    Best,
    /// The error model's variance at each input.
    Local,
}

impl RefineVariance {
    /// The name on the command line and in the summary.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Best => "best",
            Self::Local => "local",
        }
    }

    /// Parses `best` or `local`.
    ///
    /// # Errors
    /// [`crate::Error::BadOption`] naming `--refine-variance` and the value.
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "best" => Ok(Self::Best),
            "local" => Ok(Self::Local),
            other => Err(crate::Error::BadOption {
                option: format!("--refine-variance {other}"),
                message: "expected best (the error model's variance at the best exact curve, at every input) or local (its variance at each input)".into(),
            }),
        }
    }
}

/// How a fit refines.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct RefineSettings {
    /// Rounds at most, the first (plain surrogate) included; 1: no refinement.
    pub max_rounds: usize,
    /// Nelder-Mead evaluations of the error model's hyperparameters per round.
    pub hyper_evals: usize,
    /// Where a refined round's point variance comes from.
    #[serde(default)]
    pub variance: RefineVariance,
}

impl Default for RefineSettings {
    fn default() -> Self {
        Self {
            max_rounds: DEFAULT_REFINE_ROUNDS,
            hyper_evals: DEFAULT_HYPER_EVALS,
            variance: RefineVariance::default(),
        }
    }
}
