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
            eprintln!("error: {}", message(&err));
            ExitCode::from(3)
        }
        Err(err) => {
            eprintln!("error: {}", message(&err));
            ExitCode::from(2)
        }
    }
}

/// The error with its causes joined by ": ", each cause once: the libraries' errors often put
/// their source's text into their own message (`file: cannot read the file: No such file or
/// directory (os error 2)`) and also return it as `source()`, which anyhow's `{:#}` would print
/// a second time. A cause whose text is already in the message so far is left out.
fn message(err: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in err.chain() {
        let part = cause.to_string();
        if text.is_empty() {
            text = part;
        } else if !text.contains(&part) {
            text.push_str(": ");
            text.push_str(&part);
        }
    }
    text
}
