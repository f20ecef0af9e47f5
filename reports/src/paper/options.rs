//! The options of `report paper` (and of the hidden `paper-section9` step) as a user states them.
//! The command line flattens these structs (feature `clap`), so every option and default is
//! declared here once.

use std::path::PathBuf;

/// Where `report paper` writes when not told: the committed report.
pub const PAPER_OUT: &str = "reports/paper";
/// Where the section 9 step alone writes when not told.
pub const SECTION9_OUT: &str = "reports/section9";

/// Everything a user chooses about `report paper` (see [`super::run_paper`]).
#[derive(Debug, Clone, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct PaperOptions {
    /// Output folder (figures/, fits/, section9/, README.md, report.json).
    #[cfg_attr(feature = "clap", arg(long, value_name = "DIR", default_value = PAPER_OUT))]
    pub out: PathBuf,
    /// A fast reduced run (for tests): few voltages and densities, no fits, no section 9.
    #[cfg_attr(feature = "clap", arg(long))]
    pub quick: bool,
    /// Run the fits' exact-solver re-weighting check (100 draws each, a few minutes more).
    #[cfg_attr(feature = "clap", arg(long))]
    pub exact_check: bool,
}

impl Default for PaperOptions {
    /// The full run into [`PAPER_OUT`] without the exact-solver check.
    fn default() -> Self {
        Self {
            out: PAPER_OUT.into(),
            quick: false,
            exact_check: false,
        }
    }
}

/// Where the section 9 step alone writes.
#[derive(Debug, Clone, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct Section9Options {
    /// Output folder.
    #[cfg_attr(feature = "clap", arg(long, value_name = "DIR", default_value = SECTION9_OUT))]
    pub out: PathBuf,
}

impl Default for Section9Options {
    /// [`SECTION9_OUT`].
    fn default() -> Self {
        Self {
            out: SECTION9_OUT.into(),
        }
    }
}
