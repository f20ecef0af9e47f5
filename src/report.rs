//! `hpge-cv report paper`: every figure of the paper this project can produce, made in one run
//! with this project's numbers ([`hpge_reports::paper::run_paper`]), and a README that sets each
//! beside the paper's statement about it.

use anyhow::Result;
use hpge_reports::paper::PaperOptions;

/// `report`: reports made of several commands' results.
#[derive(Debug, clap::Args)]
pub struct ReportArgs {
    #[command(subcommand)]
    what: ReportKind,
}

#[derive(Debug, clap::Subcommand)]
enum ReportKind {
    /// Every paper figure the project can produce, with its own numbers, and README.md listing
    /// each beside the paper's statement and whether this project agrees (about 10 min on 2 cores).
    Paper(PaperOptions),
}

/// Runs `report`.
pub fn run(a: &ReportArgs) -> Result<()> {
    match &a.what {
        ReportKind::Paper(p) => paper(p),
    }
}

/// Runs `report paper` with progress on stderr and the fits' summaries on stdout.
pub fn paper(a: &PaperOptions) -> Result<()> {
    let r = hpge_reports::paper::run_paper(
        a.out.clone(),
        a.quick,
        a.exact_check,
        Box::new(crate::cli::fit::ReportDisplay::new()),
        &|name, k, n, seconds| eprintln!("[report {seconds:6.1} s] step {k}/{n}: {name}"),
    )?;
    eprintln!(
        "[report {:6.1} s] {} figure files in {}; {}",
        r.seconds,
        r.files,
        r.figures_dir.display(),
        r.readme.display()
    );
    println!(
        "report paper: {} figures ({} files) in {:.1} s; see {}",
        r.figures,
        r.files,
        r.seconds,
        r.readme.display()
    );
    Ok(())
}
