//! Command-line interface: argument definitions and dispatch.

mod args;
mod detector;
mod impurity;

use std::path::PathBuf;

use anyhow::Result;
use clap::{Parser, Subcommand};

pub use args::{parse_param, parse_point};

/// Impurity densities of HPGe detectors from capacitance-voltage curves: field solver, neural
/// surrogate and Bayesian inference (Abt et al., EPJ C 2023).
#[derive(Debug, Parser)]
#[command(name = "hpge-cv", version, about, long_about = None, propagate_version = true)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Evaluate the impurity density (y, x, zeta) at points of a detector.
    Impurity(ImpurityArgs),
    /// Check a detector description, print a summary and draw its r-z cross-section.
    Detector(DetectorArgs),
}

/// Options shared by commands that load a detector.
#[derive(Debug, clap::Args)]
pub struct DetectorInput {
    /// Detector description (TOML), e.g. detectors/super-siegfried-k1.toml.
    #[arg(long, value_name = "FILE")]
    pub detector: PathBuf,
    /// Impurity model file (TOML) replacing the detector's default model.
    #[arg(long, value_name = "FILE")]
    pub impurity: Option<PathBuf>,
    /// Override a parameter declared in the detector's [parameters], e.g. --param d_li_mm=3.
    #[arg(long = "param", value_name = "NAME=VALUE", value_parser = parse_param)]
    pub params: Vec<(String, f64)>,
}

#[derive(Debug, clap::Args)]
struct ImpurityArgs {
    #[command(flatten)]
    input: DetectorInput,
    /// A point "R,Z" in mm (repeatable).
    #[arg(long = "at", value_name = "R,Z", required = true, allow_hyphen_values = true, value_parser = parse_point)]
    at: Vec<(f64, f64)>,
    /// Print exactly one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, clap::Args)]
struct DetectorArgs {
    #[command(flatten)]
    input: DetectorInput,
    /// Write the r-z cross-section to this file (.svg or .png; repeatable).
    #[arg(long, value_name = "FILE")]
    plot: Vec<PathBuf>,
    /// Print the summary as one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

/// Runs the parsed command.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Impurity(a) => impurity::run(&a.input, &a.at, a.json),
        Command::Detector(a) => detector::run(&a.input, &a.plot, a.json),
    }
}
