//! `hpge-cv report paper`: every figure of the paper this project can produce, made in one run
//! with this project's numbers, and a README that sets each beside the paper's statement about it.
//!
//! Each figure group is one step: the C-V curve against the data (`hpge_reports::paper::cv`), the
//! sensitivity scan (`sensitivity`), the transform, the example density and the cross-sections
//! (`hpge_reports::paper::density`), the training samples (`hpge_reports::paper::samples`), the
//! surrogate (`hpge_reports::paper::surrogate`), the fits (`fits`) and section 9 (`section9`);
//! `hpge_reports::paper::readme` writes `README.md` and `report.json`. The steps that run the
//! command line's fits stay here.

mod fits;
mod section9;
mod sensitivity;

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use hpge_reports::paper::{Ctx, Inputs, cv, density, readme, samples, surrogate};

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
    Paper(PaperArgs),
}

/// Options of `report paper`.
#[derive(Debug, clap::Args)]
pub struct PaperArgs {
    /// Output folder (figures/, fits/, section9/, README.md, report.json).
    #[arg(long, value_name = "DIR", default_value = "reports/paper")]
    pub out: PathBuf,
    /// A fast reduced run (for tests): few voltages and densities, no fits, no section 9.
    #[arg(long)]
    pub quick: bool,
    /// Run the fits' exact-solver re-weighting check (100 draws each, a few minutes more).
    #[arg(long)]
    pub exact_check: bool,
}

/// Runs `report`.
pub fn run(a: &ReportArgs) -> Result<()> {
    match &a.what {
        ReportKind::Paper(p) => paper(p),
    }
}

/// Runs `report paper`.
pub fn paper(a: &PaperArgs) -> Result<()> {
    let start = Instant::now();
    let inputs = Inputs::default();
    for p in inputs.all() {
        if !p.is_file() {
            bail!(
                "{}: a shipped input of `report paper` is missing; run it from the repository root \
                 of a complete checkout",
                p.display()
            );
        }
    }
    let mut ctx = Ctx::new(a.out.clone(), a.quick, a.exact_check, inputs);
    std::fs::create_dir_all(&ctx.figures)
        .with_context(|| format!("--out {}: cannot create the folder", a.out.display()))?;
    type StepFn = fn(&mut Ctx) -> Result<()>;
    let steps: [(&str, StepFn); 8] = [
        ("C-V curve: manufacturer model vs data", |c| Ok(cv::run(c)?)),
        ("sensitivity scan at 25 V", sensitivity::run),
        ("transform, example density, cross-sections", |c| {
            Ok(density::run(c)?)
        }),
        ("training-sample histograms", |c| Ok(samples::run(c)?)),
        ("surrogate: learning curves, held-out accuracy", |c| {
            Ok(surrogate::run(c)?)
        }),
        ("fit B_Z", fits::run_bz),
        ("fit B_RZ", fits::run_brz),
        ("section 9: field and pulses", section9::run),
    ];
    let n = steps.len();
    for (k, (name, step)) in steps.iter().enumerate() {
        eprintln!(
            "[report {:6.1} s] step {}/{n}: {name}",
            start.elapsed().as_secs_f64(),
            k + 1
        );
        let t = Instant::now();
        step(&mut ctx).with_context(|| format!("report paper, step `{name}`"))?;
        ctx.steps
            .push((name.to_string(), t.elapsed().as_secs_f64()));
    }
    let total = start.elapsed().as_secs_f64();
    let written = readme::write(&ctx, total)?;
    eprintln!(
        "[report {total:6.1} s] {} figure files in {}; {}",
        ctx.files.len(),
        ctx.figures.display(),
        written.display()
    );
    println!(
        "report paper: {} figures ({} files) in {:.1} s; see {}",
        ctx.rows
            .iter()
            .filter(|r| !r.verdict.starts_with("not run"))
            .count(),
        ctx.files.len(),
        total,
        written.display()
    );
    Ok(())
}
