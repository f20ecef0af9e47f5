//! `hpge-cv`: impurity densities of HPGe detectors from capacitance-voltage curves.
//!
//! Every error is printed as one message naming the file, key or value at fault, and the program
//! exits with code 2 (bad input); it never panics on user input. A fit that did not converge
//! exits with code 3.

mod cli;
mod report;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let args = cli::Cli::parse();
    match cli::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) if err.downcast_ref::<cli::Unconverged>().is_some() => {
            eprintln!("error: {err:#}");
            ExitCode::from(3)
        }
        Err(err) => {
            eprintln!("error: {err:#}");
            ExitCode::from(2)
        }
    }
}
