//! The options of `report paper` (and of the hidden `paper-section9` step) as a user states them.
//! The command line flattens these structs (feature `clap`), so every option and default is
//! declared here once.

use std::path::PathBuf;

/// Where `report paper` writes when not told: a folder under the working directory (the
/// committed report, `reports/paper`, is remade with `--out reports/paper`).
pub const PAPER_OUT: &str = "paper-report";
/// Where the section 9 step alone writes when not told (under the working directory).
pub const SECTION9_OUT: &str = "section9";

/// Everything a user chooses about `report paper` (see [`super::run_paper`]).
#[derive(Debug, Clone, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct PaperOptions {
    /// Output folder (figures/, fits/, section9/, README.md, report.json); the committed report
    /// is remade with --out reports/paper.
    #[cfg_attr(feature = "clap", arg(long, value_name = "DIR", default_value = PAPER_OUT))]
    pub out: PathBuf,
    /// A fast reduced run (for tests): few voltages and densities, no fits, no section 9.
    #[cfg_attr(feature = "clap", arg(long))]
    pub quick: bool,
    /// Run the fits' exact-solver re-weighting check (100 draws each, a few minutes more).
    #[cfg_attr(feature = "clap", arg(long))]
    pub exact_check: bool,
    /// Replace a report of another run (other --quick or --exact-check) in --out; without it
    /// such a folder is refused.
    #[cfg_attr(feature = "clap", arg(long))]
    pub force: bool,
}

impl Default for PaperOptions {
    /// The full run into [`PAPER_OUT`] without the exact-solver check.
    fn default() -> Self {
        Self {
            out: PAPER_OUT.into(),
            quick: false,
            exact_check: false,
            force: false,
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
